//! Integrators: estimators of the radiance arriving along a camera ray: the path tracer and the
//! lecture's distribution ray tracer with splitting, and the volumetric path tracers.
//!
//! An [`Integrator`] is what a scene asks for: an estimator and its parameters. Before a render
//! it is prepared for the world ([`Integrator::prepare`]), which builds the light sampler it
//! chooses lights with, so the sampler always follows the integrator's own settings.

pub mod distribution;
pub mod path;
pub mod volpath;
pub mod volpathmis;

pub use distribution::DistributionIntegrator;
pub use path::PathIntegrator;
pub use volpath::{Tracking, VolPathIntegrator};

use volpath::SpectralTracking;
use volpathmis::SpectralMis;

use crate::bsdf::{BsdfEval, Scattering};
use crate::geometry::SurfaceInteraction;
use crate::light::{LightSample, LightSampler, LightSelection};
use crate::math::Ray;
use crate::sampling::sampler::Sampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::world::World;

/// The scene's integrator.
#[derive(Clone, Debug)]
pub enum Integrator {
    Path(PathIntegrator),
    Distribution(DistributionIntegrator),
    VolPath(VolPathIntegrator),
}

impl From<VolPathIntegrator> for Integrator {
    fn from(integrator: VolPathIntegrator) -> Integrator {
        Integrator::VolPath(integrator)
    }
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

/// An integrator ready to estimate radiance in a world: its settings, the world, and the light
/// sampler built for them.
pub struct PreparedIntegrator<'a> {
    integrator: &'a Integrator,
    world: &'a World,
    light_sampler: LightSampler,
}

impl Integrator {
    /// How this integrator chooses one light per shading point.
    fn light_selection(&self) -> LightSelection {
        match self {
            Integrator::Path(path) => path.light_selection,
            Integrator::Distribution(distrib) => distrib.light_selection(),
            Integrator::VolPath(volpath) => volpath.light_selection,
        }
    }

    /// The integrator with its light sampler for `world`.
    pub fn prepare<'a>(&'a self, world: &'a World) -> PreparedIntegrator<'a> {
        PreparedIntegrator {
            integrator: self,
            world,
            light_sampler: LightSampler::with_selection(
                &world.light_powers,
                &world.light_sampling_weights,
                self.light_selection(),
            ),
        }
    }
}

impl PreparedIntegrator<'_> {
    /// The light sampler the integrator chooses lights with.
    pub fn light_sampler(&self) -> &LightSampler {
        &self.light_sampler
    }

    /// An estimate of the radiance arriving at the camera along `ray` at the wavelengths
    /// `lambda`, drawing random numbers from `sampler`.
    pub fn radiance(
        &self,
        ray: Ray,
        lambda: &SampledWavelengths,
        sampler: &mut Sampler,
        count: &mut RayCount,
    ) -> SampledSpectrum {
        match self.integrator {
            Integrator::Path(integrator) => integrator.radiance(self, ray, lambda, sampler, count),
            Integrator::Distribution(integrator) => {
                integrator.radiance(self, ray, lambda, sampler, count)
            }
            Integrator::VolPath(integrator) => match integrator.tracking {
                Tracking::Spectral => {
                    integrator.trace(SpectralTracking::new(), self, ray, lambda, sampler, count)
                }
                Tracking::HeroMis { spectral_mis } => integrator.trace(
                    SpectralMis::new(spectral_mis),
                    self,
                    ray,
                    lambda,
                    sampler,
                    count,
                ),
            },
        }
    }
}

/// The BSDF's value and density towards a light sample, if the light reaches the vertex: zero
/// values are dropped before the shadow ray is traced (and counted).
#[inline]
fn unoccluded(
    world: &World,
    si: &SurfaceInteraction,
    scattering: &Scattering,
    light: &LightSample,
    count: &mut RayCount,
) -> Option<BsdfEval> {
    let f = scattering.eval(light.wi);
    if f.value.is_black() {
        return None;
    }
    count.rays += 1;
    if world.geometry.occluded(&si.spawn_ray_to(light.p, light.n)) {
        return None;
    }
    Some(f)
}

/// A path's estimate for the caller's wavelengths once the path has kept only its hero
/// wavelength: the hero carries the whole estimate with a quarter of its density
/// (`terminate_secondary`); expressed for wavelengths whose `to_xyz` divides by the full
/// density, that is N times its radiance.
#[inline]
fn hero_only(estimate: SampledSpectrum) -> SampledSpectrum {
    let mut hero = SampledSpectrum::ZERO;
    hero[0] = estimate[0] * crate::spectrum::N_SPECTRUM_SAMPLES as f32;
    hero
}
