//! Mitsuba 3's `depth` integrator: the distance from the camera ray's origin to the first
//! surface it meets, returned as a constant spectrum (zero where the ray leaves the scene), so
//! that the film's colour conversion treats it as Mitsuba's spectral variants do (a constant
//! spectrum t becomes X = t ∫x̄/∫ȳ, Y = t, Z = t ∫z̄/∫ȳ). Media and surfaces that let light
//! through (`null`) do not stop it: it reports the first surface of any kind.

use crate::integrator::SampleContext;
use crate::math::Ray;
use crate::spectrum::SampledSpectrum;

/// The distance to the first surface along the camera ray.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DepthIntegrator;

impl DepthIntegrator {
    pub(super) fn radiance(ctx: &mut SampleContext, ray: &Ray) -> SampledSpectrum {
        match ctx.intersect(ray) {
            Some(si) => SampledSpectrum::splat(si.t * ray.d.length()),
            None => SampledSpectrum::ZERO,
        }
    }
}
