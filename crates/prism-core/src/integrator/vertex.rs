//! The parts of a path vertex that every integrator takes the same way: the scattering at a
//! surface (pbrt-v4's `GetBSDF`, with the dispersion rule), the depth limit, Russian roulette
//! on the path's potential, and the estimate of a path that has kept only its hero wavelength.
//! Light sampling and the weighing of emission found by BSDF samples are in [`super::mis`].

use glam::Vec3;

use crate::bsdf::{BsdfSample, BxdfTree, Scattering};
use crate::geometry::SurfaceInteraction;
use crate::integrator::SampleContext;
use crate::spectrum::{N_SPECTRUM_SAMPLES, SampledSpectrum, SampledWavelengths};
use crate::world::World;

/// The scattering at the surface hit `si` towards `wo` (world space, unit): the material of the
/// hit shape, the BSDF of the side `wo` sees with its textures evaluated for `lambda`, its
/// lobes written into `lobes`.
///
/// Dispersion: a BSDF that disperses and has a lobe that can be evaluated (roughdielectric)
/// uses the hero wavelength's index of refraction for all its lobes, so from here on the path
/// keeps only its hero (`lambda` loses its companions; see [`hero_only`]). A delta lobe that
/// disperses decides per sample instead (`BsdfSample::terminates_secondary`).
#[inline]
pub fn surface_scattering<'t, 'w>(
    world: &'w World,
    si: &SurfaceInteraction,
    wo: Vec3,
    lambda: &mut SampledWavelengths,
    lobes: &'t mut BxdfTree<'w>,
) -> Scattering<'t, 'w> {
    let scattering = world.material(si).scattering(si, wo, lambda, lobes);
    if scattering.flags().has_smooth_lobe() && scattering.is_dispersive() {
        lambda.terminate_secondary();
    }
    scattering
}

/// The wavelengths that follow the BSDF sample `bs`: those of `lambda`, or its hero alone when
/// the sample is a dispersive delta refraction (which bends each wavelength its own way, so
/// the sampled direction is the hero's only).
#[inline]
pub fn wavelengths_after(lambda: &SampledWavelengths, bs: &BsdfSample) -> SampledWavelengths {
    let mut after = *lambda;
    if bs.terminates_secondary {
        after.terminate_secondary();
    }
    after
}

/// Whether a path whose last vertex has depth `depth` may have another: `max_depth` counts the
/// vertices after the camera (Mitsuba's convention: the camera ray's hit is depth 0, a path of
/// depth d has d bounces, 1 shows emitters only, 2 direct light), negative for no limit.
#[inline]
pub fn allows_next_vertex(max_depth: i32, depth: i32) -> bool {
    max_depth < 0 || depth + 1 < max_depth
}

/// The largest survival probability of Russian roulette, so that every path ends: 0.95, as in
/// Mitsuba 3.
pub const MAX_SURVIVAL: f32 = 0.95;

/// The depth below which an estimator whose roulette is not bounded by [`MAX_SURVIVAL`] (the
/// lecture's potential rule, the guide's weight window) may let a path survive with certainty;
/// from it on, survival is at most [`MAX_SURVIVAL`], so that a path caught between mirrors or
/// in a white furnace ends too.
pub const CERTAIN_SURVIVAL_DEPTH: i32 = 128;

/// Russian roulette on the path's potential (the lecture's "Termination of Recursion"): the
/// path survives with probability s = min(max_λ throughput · η², [`MAX_SURVIVAL`]), η the product of the
/// relative indices of refraction crossed (which undoes the radiance scaling of refractions,
/// so light inside glass is not killed for being compressed, as in Mitsuba 3). Returns the
/// factor 1/s that keeps the estimator unbiased, or None when the path ends.
#[inline]
pub fn russian_roulette(
    ctx: &mut SampleContext,
    throughput: SampledSpectrum,
    eta_scale: f32,
) -> Option<f32> {
    let survival = (throughput.max_value() * eta_scale * eta_scale).min(MAX_SURVIVAL);
    (ctx.sampler.next_1d() < survival).then(|| 1.0 / survival)
}

/// Whether the geometric and the shading normal at `si` put direction `d` on the same side of
/// the surface (Mitsuba 0.6's `strictNormals` test, which stops light leaking through surfaces
/// whose shading normals bend far from the geometry).
#[inline]
pub fn normals_agree(si: &SurfaceInteraction, d: Vec3) -> bool {
    si.n.dot(d) * si.shading.n.dot(d) > 0.0
}

/// A path's estimate for the caller's wavelengths once the path has kept only its hero
/// wavelength: the hero carries the whole estimate with a quarter of its density
/// (`terminate_secondary`); expressed for wavelengths whose `to_xyz` divides by the full
/// density, that is N times its radiance.
#[inline]
pub fn hero_only(estimate: SampledSpectrum) -> SampledSpectrum {
    let mut hero = SampledSpectrum::ZERO;
    hero[0] = estimate[0] * N_SPECTRUM_SAMPLES as f32;
    hero
}

/// The estimate of a path that started with the wavelengths `started` and has `lambda` now:
/// [`hero_only`] when it dropped its companions on the way, as it is otherwise.
#[inline]
pub fn path_estimate(
    estimate: SampledSpectrum,
    started: &SampledWavelengths,
    lambda: &SampledWavelengths,
) -> SampledSpectrum {
    if !started.secondary_terminated() && lambda.secondary_terminated() {
        hero_only(estimate)
    } else {
        estimate
    }
}
