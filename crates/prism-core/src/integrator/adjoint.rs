//! The BSDF as a light subpath uses it: the adjoint f*(ωi → ωo) = f(ωo → ωi), with the two
//! corrections that light subpaths carrying importance need (Veach 1997, §5.2–5.3): shading
//! normals make the adjoint differ from the BSDF (eq. 5.19), and refraction compresses radiance
//! by η² but not importance. Used by every estimator that traces from the lights: `ptracer`,
//! `sppm`'s photons, `bdpt` and `vcm`.

use glam::Vec3;

use crate::bsdf::{BsdfSample, Scattering};
use crate::geometry::SurfaceInteraction;
use crate::integrator::SampleContext;

/// The adjoint BSDF's shading-normal correction at `si` for light arriving from `w_light` and
/// leaving along `w_out`, |cos_s θ_light| |cos_g θ_out| / (|cos_g θ_light| |cos_s θ_out|)
/// (Veach's eq. 5.19, pbrt-v4's `CorrectShadingNormal`); None where it is not finite.
/// Directions that the geometric and shading normals put on different sides are corrected
/// too: `bdpt` and `vcm` scatter there, as their camera subpaths (the path tracer's) do, so
/// that every strategy sees the same integrand.
pub fn shading_correction(si: &SurfaceInteraction, w_light: Vec3, w_out: Vec3) -> Option<f32> {
    let (light_g, light_s) = (si.n.dot(w_light), si.shading.n.dot(w_light));
    let (out_g, out_s) = (si.n.dot(w_out), si.shading.n.dot(w_out));
    let correction = ((light_s * out_g) / (out_s * light_g)).abs();
    correction.is_finite().then_some(correction)
}

/// [`shading_correction`], but None where the geometric and shading normals put either
/// direction on different sides, so that no light leaks through the surface (Mitsuba's
/// `ptracer`, which ends the subpath there).
pub fn shading_correction_without_leaks(
    si: &SurfaceInteraction,
    w_light: Vec3,
    w_out: Vec3,
) -> Option<f32> {
    let sides_agree = |w: Vec3| si.n.dot(w) * si.shading.n.dot(w) > 0.0;
    if !(sides_agree(w_light) && sides_agree(w_out)) {
        return None;
    }
    shading_correction(si, w_light, w_out)
}

/// The next direction of a light subpath at `si`, reached by light from `w_light`: a sample of
/// the BSDF `scattering` read as the adjoint, with the factor its weight f·cos/p takes on a
/// light subpath, [`shading_correction_without_leaks`] times η² (radiance is compressed by η²
/// across a refraction, importance is not; Veach 1997, §5.2). None where the subpath ends.
pub fn sample_adjoint(
    ctx: &mut SampleContext,
    si: &SurfaceInteraction,
    scattering: &Scattering,
    w_light: Vec3,
) -> Option<(BsdfSample, f32)> {
    let u_lobe = ctx.sampler.next_1d();
    let u = ctx.sampler.next_2d();
    let bs = scattering.sample(u_lobe, u)?;
    let correction = shading_correction_without_leaks(si, w_light, bs.wi)?;
    let factor = correction * bs.eta * bs.eta;
    Some((bs, factor))
}
