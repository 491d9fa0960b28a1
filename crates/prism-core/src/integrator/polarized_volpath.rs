//! The volumetric path tracers for polarized light, which a scene gets in place of `volpath`
//! and `volpathmis` when it holds a polarizing element or nests them in the `stokes`
//! integrator (Mitsuba 3's `volpath` in its `*_polarized` variants). They are the estimators of
//! [`super::volpath`] and [`super::volpathmis`], with the same step, sampling, random numbers,
//! MIS, depth and Russian roulette, except that the path carries a Mueller matrix per wavelength
//! ([`Throughput`] for [`SampledMueller`]) and its estimate is a Stokes vector per wavelength.
//!
//! As in [`super::polarized_path`], the matrix maps Stokes vectors arriving at the path's last
//! vertex to the one arriving at the camera, in the implicit basis of the camera ray's reversed
//! direction; emitters are unpolarized, and M₀₀ is the unpolarized estimator's weight (Russian
//! roulette and the trackers' collision probabilities read it). What each event does:
//!
//! * a surface (a BSDF sample, or the light sample's BSDF value) multiplies by the BSDF's
//!   Mueller matrix in the implicit bases of the world directions ([`Scattering::polarized`]),
//!   as `polarized_path` does;
//! * a null interaction (a `polarizer`, `retarder` or `circular` sheet, the pass-through of
//!   `thindielectric` or `mask`) multiplies by its lobe's Mueller matrix without a bounce, and a
//!   shadow ray carries the product of the Mueller matrices of the null surfaces it passes, in
//!   the implicit basis of its direction (Mitsuba's `to_world_mueller(eval_null_transmission,
//!   wi, wi)` in `volpath`'s emitter sampling): light samples reach a scattering vertex through
//!   polarizers;
//! * free flights scale each wavelength's matrix by the tracking's weights, which are
//!   unpolarized (σ_s, σ_n and transmittances are scalars per wavelength);
//! * a phase function acts as its value times the identity, between the implicit Stokes bases
//!   of the incident and the scattered direction with no rotation between them: Mitsuba's phase
//!   functions return a scalar value (its `rayleigh` too, which warns that it is unpolarized),
//!   which its polarized variants turn into the diagonal Mueller matrix p·I. The Stokes vector
//!   so keeps its components across a medium scattering, relative to whatever implicit basis
//!   each direction has (Mitsuba's documentation says its phase functions depolarize; its code
//!   does not, and a render through crossed polarizers shows it).

use glam::{Vec3, Vec4};

use crate::bsdf::{BsdfEval, BsdfFlags, BsdfSample, BxdfTree, Scattering};
use crate::integrator::SampleContext;
use crate::integrator::mis::LightSampleTerms;
use crate::integrator::polarized_path::SampledStokes;
use crate::integrator::stepped::SteppedPath;
use crate::integrator::throughput::{Estimate, Throughput};
use crate::integrator::transmittance::{ShadowTransmittance, shadow_transmittance_crossing};
use crate::integrator::volpath::{
    PathWeights, SpectralTracking, Tracking, VolPathIntegrator, VolPathWith,
};
use crate::integrator::volpathmis::SpectralMis;
use crate::light::LightSelection;
use crate::math::Ray;
use crate::polarization::SampledMueller;
use crate::spectrum::{N_SPECTRUM_SAMPLES, SampledSpectrum, SampledWavelengths};

/// The polarized volumetric path tracer: the settings of the `volpath` or `volpathmis` it
/// stands in for.
#[derive(Clone, Debug)]
pub struct PolarizedVolPathIntegrator {
    pub volpath: VolPathIntegrator,
}

impl PolarizedVolPathIntegrator {
    /// How one light is chosen for each light sample.
    pub fn light_selection(&self) -> LightSelection {
        self.volpath.light_selection
    }

    /// The Stokes vector per wavelength arriving at the camera along `ray` (which travels away
    /// from the camera), in the implicit basis of −`ray.d`, for the wavelengths `wavelengths`.
    pub fn stokes(
        &self,
        ctx: &mut SampleContext,
        ray: Ray,
        wavelengths: &SampledWavelengths,
    ) -> SampledStokes {
        let integrator = &self.volpath;
        match integrator.tracking {
            Tracking::Spectral => {
                let weights = SpectralTracking::<SampledMueller>::new();
                trace(
                    &VolPathWith {
                        integrator,
                        weights,
                    },
                    ctx,
                    ray,
                    wavelengths,
                )
            }
            Tracking::HeroMis { spectral_mis } => {
                let weights = SpectralMis::<SampledMueller>::new(spectral_mis);
                trace(
                    &VolPathWith {
                        integrator,
                        weights,
                    },
                    ctx,
                    ray,
                    wavelengths,
                )
            }
        }
    }

    /// The intensity S₀ of [`Self::stokes`]: the image of a polarized render.
    pub(super) fn radiance(
        &self,
        ctx: &mut SampleContext,
        ray: Ray,
        wavelengths: &SampledWavelengths,
    ) -> SampledSpectrum {
        self.stokes(ctx, ray, wavelengths).intensity()
    }
}

/// The Stokes vectors of the path along `ray`, one step after another
/// ([`SteppedPath::radiance`] with the whole estimate).
fn trace<W: PathWeights<Throughput = SampledMueller> + Clone>(
    path: &VolPathWith<'_, W>,
    ctx: &mut SampleContext,
    ray: Ray,
    wavelengths: &SampledWavelengths,
) -> SampledStokes {
    let Some(mut state) = path.start(ctx.world(), ray, wavelengths) else {
        return SampledStokes::ZERO;
    };
    loop {
        let hit = ctx.intersect(VolPathWith::<W>::ray(&state));
        if !path.step(ctx, &mut state, hit) {
            return path.full_estimate(&state);
        }
    }
}

impl Throughput for SampledMueller {
    type Estimate = SampledStokes;
    type LightTransfer = SampledMueller;
    type SurfaceTransfer = SampledMueller;

    const ONE: Self = SampledMueller::IDENTITY;
    const ZERO: Self = SampledMueller::ZERO;

    #[inline]
    fn intensity(&self) -> SampledSpectrum {
        self.m00()
    }

    #[inline]
    fn scale(&mut self, factor: SampledSpectrum) {
        *self = self.scaled(factor);
    }

    #[inline]
    fn scale_all(&mut self, factor: f32) {
        *self = self.scaled(SampledSpectrum::splat(factor));
    }

    #[inline]
    fn then(&mut self, next: Self) {
        *self = *self * next;
    }

    /// The Mueller matrix of the sampled lobe, M₀₀ the sample's weight.
    #[inline]
    fn sampled(scattering: &Scattering, bs: &BsdfSample) -> Self {
        scattering.polarized(bs.wi, bs.flags, bs.weight)
    }

    #[inline]
    fn gathers(&self, radiance: SampledSpectrum) -> SampledStokes {
        self.apply_unpolarized(radiance)
    }

    /// The throughput times the vertex's and the shadow ray's surfaces' matrices (`transfer`),
    /// applied to the unpolarized light Tr_media · Lₑ.
    #[inline]
    fn gathers_light(&self, s: &LightSampleTerms, transfer: &SampledMueller) -> SampledStokes {
        (*self * *transfer).apply_unpolarized(s.transmittance.media * s.radiance)
    }

    /// The product of the null surfaces' Mueller matrices in the order the light crosses them
    /// backwards (the surface nearest `origin` first), each for light travelling from `end`
    /// towards `origin`.
    fn shadow(
        ctx: &mut SampleContext,
        origin: Vec3,
        end: Vec3,
        time: f32,
        medium: Option<u32>,
        lambda: &SampledWavelengths,
    ) -> (ShadowTransmittance, SampledMueller) {
        let mut surfaces = SampledMueller::IDENTITY;
        let transmittance =
            shadow_transmittance_crossing(ctx, origin, end, time, medium, lambda, |m, si, d| {
                let mut lobes = BxdfTree::empty();
                let scattering = m.scattering(si, -d, lambda, &mut lobes);
                let value = scattering.null_transmission();
                surfaces = surfaces * scattering.polarized(d, BsdfFlags::NULL, value);
                value
            });
        (transmittance, surfaces)
    }

    #[inline]
    fn at_surface(
        scattering: &Scattering,
        wi: Vec3,
        f: &BsdfEval,
        surfaces: SampledMueller,
    ) -> SampledMueller {
        scattering.polarized(wi, BsdfFlags::NONE, f.value) * surfaces
    }

    /// The phase function's value times the identity (the module's conventions).
    #[inline]
    fn in_medium(phase_value: f32, surfaces: SampledMueller) -> SampledMueller {
        surfaces.scaled(SampledSpectrum::splat(phase_value))
    }
}

impl Estimate for SampledStokes {
    const ZERO: Self = [Vec4::ZERO; N_SPECTRUM_SAMPLES];

    #[inline]
    fn add(&mut self, other: Self) {
        for (s, o) in self.iter_mut().zip(other) {
            *s += o;
        }
    }

    #[inline]
    fn scaled(self, factor: f32) -> Self {
        self.map(|s| s * factor)
    }

    /// The hero's Stokes vector N times, the companions' zero ([`crate::integrator::vertex::hero_only`]).
    #[inline]
    fn hero_only(self) -> Self {
        let mut hero = Self::ZERO;
        hero[0] = self[0] * N_SPECTRUM_SAMPLES as f32;
        hero
    }

    #[inline]
    fn intensity(&self) -> SampledSpectrum {
        SampledSpectrum::from_fn(|i| self[i].x)
    }
}
