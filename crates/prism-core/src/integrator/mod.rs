//! Integrators: estimators of the radiance arriving along a camera ray: the path tracer, direct
//! illumination, the lecture's distribution ray tracer with splitting and the volumetric path
//! tracers; `moment` runs nested
//! integrators and writes their estimates and second moments as extra film channels, `aov` the
//! albedo, normals, depth and other variables of the first hit beside nested integrators'
//! images.
//!
//! An [`Integrator`] is what a scene asks for: an estimator and its parameters. Before a render
//! it is prepared for the world ([`Integrator::prepare`]), which builds the light sampler it
//! chooses lights with, so the sampler always follows the integrator's own settings.

pub mod aov;
pub mod direct;
pub mod distribution;
pub mod mis;
pub mod moment;
pub mod path;
pub mod volpath;
pub mod volpathmis;

pub use aov::AovIntegrator;
pub use direct::DirectIntegrator;
pub use distribution::DistributionIntegrator;
pub use moment::MomentIntegrator;
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
    Direct(DirectIntegrator),
    Distribution(DistributionIntegrator),
    Moment(MomentIntegrator),
    Aov(AovIntegrator),
    VolPath(VolPathIntegrator),
}

impl From<AovIntegrator> for Integrator {
    fn from(integrator: AovIntegrator) -> Integrator {
        Integrator::Aov(integrator)
    }
}

impl From<DirectIntegrator> for Integrator {
    fn from(integrator: DirectIntegrator) -> Integrator {
        Integrator::Direct(integrator)
    }
}

impl From<MomentIntegrator> for Integrator {
    fn from(integrator: MomentIntegrator) -> Integrator {
        Integrator::Moment(integrator)
    }
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
    /// How many extra channels a sample writes.
    aov_count: usize,
    /// The nested integrators (of `moment`), prepared in turn.
    nested: Vec<PreparedIntegrator<'a>>,
}

impl Integrator {
    /// How this integrator chooses one light per shading point.
    fn light_selection(&self) -> LightSelection {
        match self {
            Integrator::Path(path) => path.light_selection,
            Integrator::Direct(_) => LightSelection::Exhaustive,
            Integrator::Distribution(distrib) => distrib.light_selection(),
            Integrator::VolPath(volpath) => volpath.light_selection,
            Integrator::Moment(_) | Integrator::Aov(_) => LightSelection::Power,
        }
    }

    /// The integrators nested in this one.
    fn nested(&self) -> impl Iterator<Item = &Integrator> {
        let nested: &[(String, Integrator)] = match self {
            Integrator::Moment(moment) => &moment.integrators,
            Integrator::Aov(aov) => &aov.integrators,
            Integrator::Path(_)
            | Integrator::Direct(_)
            | Integrator::Distribution(_)
            | Integrator::VolPath(_) => &[],
        };
        nested.iter().map(|(_, integrator)| integrator)
    }

    /// Whether the emitters the camera sees directly are left out of the image.
    pub fn hides_emitters(&self) -> bool {
        match self {
            Integrator::Path(path) => path.hide_emitters,
            Integrator::Direct(direct) => direct.hide_emitters,
            Integrator::Distribution(distrib) => distrib.hide_emitters,
            Integrator::VolPath(volpath) => volpath.hide_emitters,
            Integrator::Moment(_) | Integrator::Aov(_) => match self.nested().next() {
                Some(first) => first.hides_emitters(),
                None => true,
            },
        }
    }

    /// The integrator whose estimate is the image: this one, or the first nested one's.
    pub fn image_integrator(&self) -> &Integrator {
        match self.nested().next() {
            Some(first) => first.image_integrator(),
            None => self,
        }
    }

    /// Names of the extra film channels (AOVs) the integrator writes beside the image, as
    /// Mitsuba names them in its EXR files; none for the plain estimators.
    pub fn aov_names(&self) -> Vec<String> {
        match self {
            Integrator::Path(_)
            | Integrator::Direct(_)
            | Integrator::Distribution(_)
            | Integrator::VolPath(_) => Vec::new(),
            Integrator::Moment(moment) => moment.aov_names(),
            Integrator::Aov(aov) => aov.aov_names(),
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
                &world.light_bounds,
                self.light_selection(),
            ),
            aov_count: self.aov_names().len(),
            nested: self.nested().map(|i| i.prepare(world)).collect(),
        }
    }
}

impl PreparedIntegrator<'_> {
    /// How many extra channels each sample writes.
    pub fn aov_count(&self) -> usize {
        self.aov_count
    }

    /// The light sampler the integrator chooses lights with.
    pub fn light_sampler(&self) -> &LightSampler {
        &self.light_sampler
    }

    /// An estimate of the radiance arriving at the camera along `ray` at the wavelengths
    /// `lambda`, drawing random numbers from `sampler`; the sample's extra channels are written
    /// to `aovs` (as many as [`Integrator::aov_names`] names).
    pub fn radiance(
        &self,
        ray: Ray,
        lambda: &SampledWavelengths,
        sampler: &mut Sampler,
        count: &mut RayCount,
        aovs: &mut [f32],
    ) -> SampledSpectrum {
        debug_assert_eq!(aovs.len(), self.aov_count);
        match self.integrator {
            Integrator::Path(integrator) => integrator.radiance(self, ray, lambda, sampler, count),
            Integrator::Direct(integrator) => {
                integrator.radiance(self, ray, lambda, sampler, count)
            }
            Integrator::Distribution(integrator) => {
                integrator.radiance(self, ray, lambda, sampler, count)
            }
            Integrator::Moment(_) => {
                MomentIntegrator::radiance(self, ray, lambda, sampler, count, aovs)
            }
            Integrator::Aov(integrator) => {
                integrator.radiance(self, ray, lambda, sampler, count, aovs)
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

/// Whether the geometric and the shading normal at `si` put direction `d` on the same side of
/// the surface (Mitsuba 0.6's `strictNormals` test, which stops light leaking through surfaces
/// whose shading normals bend far from the geometry).
#[inline]
fn normals_agree(si: &SurfaceInteraction, d: glam::Vec3) -> bool {
    si.n.dot(d) * si.shading.n.dot(d) > 0.0
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
