//! Integrators: estimators of the radiance arriving along a camera ray: the path tracer and the
//! lecture's distribution ray tracer with splitting.

pub mod distribution;
pub mod path;

pub use distribution::DistributionIntegrator;
pub use path::PathIntegrator;

use crate::math::Ray;
use crate::sampling::sampler::Sampler;
use crate::scene::Scene;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// The scene's integrator.
#[derive(Clone, Debug)]
pub enum Integrator {
    Path(PathIntegrator),
    Distribution(DistributionIntegrator),
}

impl From<PathIntegrator> for Integrator {
    fn from(integrator: PathIntegrator) -> Integrator {
        Integrator::Path(integrator)
    }
}

impl From<DistributionIntegrator> for Integrator {
    fn from(integrator: DistributionIntegrator) -> Integrator {
        Integrator::Distribution(integrator)
    }
}

/// Rays traced while estimating one sample, for the statistics line.
#[derive(Clone, Copy, Debug, Default)]
pub struct RayCount {
    pub rays: u64,
}

impl Integrator {
    /// An estimate of the radiance arriving at the camera along `ray` at the wavelengths
    /// `lambda`, drawing random numbers from `sampler`.
    pub fn radiance(
        &self,
        scene: &Scene,
        ray: Ray,
        lambda: &SampledWavelengths,
        sampler: &mut Sampler,
        count: &mut RayCount,
    ) -> SampledSpectrum {
        match self {
            Integrator::Path(integrator) => integrator.radiance(scene, ray, lambda, sampler, count),
            Integrator::Distribution(integrator) => {
                integrator.radiance(scene, ray, lambda, sampler, count)
            }
        }
    }
}
