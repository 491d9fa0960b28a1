//! What a volumetric path carries from one vertex to the next ([`Throughput`]) and what it
//! sums ([`Estimate`]): a spectrum and radiance, or in scenes that polarize a Mueller matrix
//! and a Stokes vector per wavelength ([`super::polarized_volpath`]). `volpath` and `volpathmis`
//! write their step once over these traits; for a spectrum each method is the plain product it
//! stands for, so unpolarized paths run the same arithmetic as a path written for spectra alone.

use glam::Vec3;

use crate::bsdf::{BsdfEval, BsdfSample, Scattering};
use crate::integrator::SampleContext;
use crate::integrator::mis::LightSampleTerms;
use crate::integrator::transmittance::{ShadowTransmittance, shadow_transmittance};
use crate::integrator::vertex::hero_only;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// What a volumetric path carries from one vertex to the next: a spectrum, or in polarized
/// renders a Mueller matrix per wavelength ([`super::polarized_volpath`]). The path's step is
/// written once over this trait; for a spectrum each method is the plain product it stands for.
pub(crate) trait Throughput: Copy {
    /// What the path sums: radiance, or a Stokes vector per wavelength.
    type Estimate: Estimate;
    /// What a light sample's vertex and the surfaces its shadow ray crosses do to the light
    /// beyond the unpolarized values of [`LightSampleTerms`]: nothing for a spectrum.
    type LightTransfer: Copy;
    /// What the null surfaces a shadow ray crosses do to the light beyond their null
    /// transmission ([`ShadowTransmittance::surfaces`]): nothing for a spectrum.
    type SurfaceTransfer;

    const ONE: Self;
    const ZERO: Self;

    /// What the throughput does to unpolarized light: Russian roulette, termination and the
    /// tracking's collision probabilities look at it.
    fn intensity(&self) -> SampledSpectrum;

    /// Multiplies each wavelength's part by its factor.
    fn scale(&mut self, factor: SampledSpectrum);

    /// Multiplies every wavelength's part by `factor`.
    fn scale_all(&mut self, factor: f32);

    /// The throughput followed (towards the light) by the vertex weight `next`.
    fn then(&mut self, next: Self);

    /// The weight of the BSDF sample `bs` of `scattering`.
    fn sampled(scattering: &Scattering, bs: &BsdfSample) -> Self;

    /// What the path gathers of unpolarized radiance `radiance` arriving at its last vertex.
    fn gathers(&self, radiance: SampledSpectrum) -> Self::Estimate;

    /// What the path gathers of the light sample `s`, whose vertex and shadow ray also do
    /// `transfer`: throughput · f · Tr · Lₑ, without MIS weight or density.
    fn gathers_light(&self, s: &LightSampleTerms, transfer: &Self::LightTransfer)
    -> Self::Estimate;

    /// The transmittance from `origin` to `end` ([`shadow_transmittance`]) with what the null
    /// surfaces on the way do to the light.
    fn shadow(
        ctx: &mut SampleContext,
        origin: Vec3,
        end: Vec3,
        time: f32,
        medium: Option<u32>,
        lambda: &SampledWavelengths,
    ) -> (ShadowTransmittance, Self::SurfaceTransfer);

    /// A light sample's transfer at a surface vertex: `scattering`'s value `f` towards `wi`,
    /// then the shadow ray's surfaces.
    fn at_surface(
        scattering: &Scattering,
        wi: Vec3,
        f: &BsdfEval,
        surfaces: Self::SurfaceTransfer,
    ) -> Self::LightTransfer;

    /// A light sample's transfer at a scattering vertex in a medium whose phase function has
    /// the value `phase_value` there, then the shadow ray's surfaces.
    fn in_medium(phase_value: f32, surfaces: Self::SurfaceTransfer) -> Self::LightTransfer;
}

/// What a path sums: radiance, or a Stokes vector per wavelength.
pub(crate) trait Estimate: Copy {
    const ZERO: Self;

    /// Adds `other`.
    fn add(&mut self, other: Self);

    /// Every wavelength's part times `factor`.
    fn scaled(self, factor: f32) -> Self;

    /// The estimate carried by the hero wavelength alone ([`hero_only`]).
    fn hero_only(self) -> Self;

    /// The intensity: the radiance, or S₀ of the Stokes vectors.
    fn intensity(&self) -> SampledSpectrum;
}

impl Throughput for SampledSpectrum {
    type Estimate = SampledSpectrum;
    type LightTransfer = ();
    type SurfaceTransfer = ();

    const ONE: Self = SampledSpectrum::ONE;
    const ZERO: Self = SampledSpectrum::ZERO;

    #[inline]
    fn intensity(&self) -> SampledSpectrum {
        *self
    }

    #[inline]
    fn scale(&mut self, factor: SampledSpectrum) {
        *self *= factor;
    }

    #[inline]
    fn scale_all(&mut self, factor: f32) {
        *self *= factor;
    }

    #[inline]
    fn then(&mut self, next: Self) {
        *self *= next;
    }

    #[inline]
    fn sampled(_scattering: &Scattering, bs: &BsdfSample) -> Self {
        bs.weight
    }

    #[inline]
    fn gathers(&self, radiance: SampledSpectrum) -> SampledSpectrum {
        *self * radiance
    }

    #[inline]
    fn gathers_light(&self, s: &LightSampleTerms, _transfer: &()) -> SampledSpectrum {
        *self * s.value * s.transmittance.total() * s.radiance
    }

    #[inline]
    fn shadow(
        ctx: &mut SampleContext,
        origin: Vec3,
        end: Vec3,
        time: f32,
        medium: Option<u32>,
        lambda: &SampledWavelengths,
    ) -> (ShadowTransmittance, ()) {
        (
            shadow_transmittance(ctx, origin, end, time, medium, lambda),
            (),
        )
    }

    #[inline]
    fn at_surface(_scattering: &Scattering, _wi: Vec3, _f: &BsdfEval, _surfaces: ()) {}

    #[inline]
    fn in_medium(_phase_value: f32, _surfaces: ()) {}
}

impl Estimate for SampledSpectrum {
    const ZERO: Self = SampledSpectrum::ZERO;

    #[inline]
    fn add(&mut self, other: Self) {
        *self += other;
    }

    #[inline]
    fn scaled(self, factor: f32) -> Self {
        self * factor
    }

    #[inline]
    fn hero_only(self) -> Self {
        hero_only(self)
    }

    #[inline]
    fn intensity(&self) -> SampledSpectrum {
        *self
    }
}
