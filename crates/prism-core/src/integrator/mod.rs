//! Integrators: estimators of the radiance arriving along a camera ray: the path tracer, direct
//! illumination, the lecture's distribution ray tracer with splitting and the volumetric path
//! tracers; `moment` runs nested integrators and writes their estimates and second moments as
//! extra film channels, `aov` the albedo, normals, depth and other variables of the first hit
//! beside nested integrators' images. `ptracer`, `bdpt`, `sppm` and `vcm` start paths at the
//! lights too; the render driver runs their passes, and the iterations of `guided_path`, the
//! path tracer that learns where light comes from.
//!
//! An [`Integrator`] is what a scene asks for: an estimator and its parameters. Before a render
//! it is prepared for the world ([`Integrator::prepare`]), which builds the light sampler it
//! chooses lights with, so the sampler always follows the integrator's own settings. Each
//! camera sample is estimated in a [`SampleContext`] (the prepared integrator, the sample's
//! random numbers, its ray count).
//!
//! The estimators share one vertex step: [`vertex`] (the scattering at a surface with the
//! dispersion rule, the depth limit, Russian roulette, hero-only estimates), [`mis`] (light
//! sampling with a hook for what shadow rays cross, and the emission a sampled direction finds,
//! weighed against it) and, for media, [`transmittance`].
//!
//! A scene with a polarizing element or the `stokes` integrator gets [`polarized_path`] in place
//! of `path`: the same estimator with a Mueller matrix per wavelength for a throughput, in its
//! own file, so that unpolarized scenes run the path tracer's code unchanged; and
//! [`polarized_volpath`] in place of `volpath` and `volpathmis`: their one step, written over
//! what a path carries ([`throughput::Throughput`]), run with Mueller matrices.

pub mod adjoint;
pub mod aov;
pub mod bdpt;
pub mod context;
pub mod depth;
pub mod direct;
pub mod distribution;
pub mod guided;
pub mod mis;
pub mod moment;
pub mod path;
pub mod photon_map;
pub mod polarized_path;
pub mod polarized_volpath;
pub mod ptracer;
pub mod sppm;
pub mod stepped;
pub mod stokes;
pub mod throughput;
pub mod transmittance;
pub mod vcm;
pub mod vertex;
pub mod volpath;
pub mod volpathmis;

pub use aov::AovIntegrator;
pub use bdpt::BdptIntegrator;
pub use context::{RayCount, SampleContext};
pub use depth::DepthIntegrator;
pub use direct::DirectIntegrator;
pub use distribution::DistributionIntegrator;
pub use guided::GuidedPathIntegrator;
pub use moment::MomentIntegrator;
pub use path::PathIntegrator;
pub use polarized_path::PolarizedPathIntegrator;
pub use polarized_volpath::PolarizedVolPathIntegrator;
pub use ptracer::{LightPathSample, ParticleTracer, Splat};
pub use sppm::SppmIntegrator;
pub use stepped::SteppedPath;
pub use stokes::{PolarizedIntegrator, StokesIntegrator};
pub use vcm::VcmIntegrator;
pub use volpath::{Tracking, VolPathIntegrator};

use stepped::SteppedIntegrator;
use volpath::{SpectralTracking, VolPathWith};
use volpathmis::SpectralMis;

use crate::light::{LightSampler, LightSelection};
use crate::math::Ray;
use crate::sampling::sampler::Sampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::world::World;

/// Declares the [`Integrator`] enum with a `From` conversion per variant, so that an
/// integrator's settings become the scene's integrator with `.into()`.
macro_rules! integrator_enum {
    (
        $(#[$meta:meta])*
        pub enum Integrator {
            $($variant:ident($integrator:ty),)+
        }
    ) => {
        $(#[$meta])*
        pub enum Integrator {
            $($variant($integrator),)+
        }

        $(impl From<$integrator> for Integrator {
            fn from(integrator: $integrator) -> Integrator {
                Integrator::$variant(integrator)
            }
        })+
    };
}

integrator_enum! {
    /// The scene's integrator.
    #[derive(Clone, Debug)]
    pub enum Integrator {
        Path(PathIntegrator),
        Direct(DirectIntegrator),
        Distribution(DistributionIntegrator),
        Moment(MomentIntegrator),
        Aov(AovIntegrator),
        VolPath(VolPathIntegrator),
        Depth(DepthIntegrator),
        Particle(ParticleTracer),
        Bdpt(BdptIntegrator),
        Sppm(SppmIntegrator),
        PolarizedPath(PolarizedPathIntegrator),
        PolarizedVolPath(PolarizedVolPathIntegrator),
        Stokes(StokesIntegrator),
        Guided(GuidedPathIntegrator),
        Vcm(VcmIntegrator),
    }
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
            Integrator::PolarizedPath(polarized) => polarized.light_selection(),
            Integrator::PolarizedVolPath(polarized) => polarized.light_selection(),
            Integrator::Stokes(stokes) => stokes.nested.light_selection(),
            Integrator::Moment(_)
            | Integrator::Aov(_)
            | Integrator::Depth(_)
            | Integrator::Particle(_)
            | Integrator::Bdpt(_)
            | Integrator::Sppm(_)
            | Integrator::Vcm(_) => LightSelection::Power,
            Integrator::Guided(_) => LightSelection::Exhaustive,
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
            | Integrator::VolPath(_)
            | Integrator::Depth(_)
            | Integrator::Particle(_)
            | Integrator::Bdpt(_)
            | Integrator::Sppm(_)
            | Integrator::PolarizedPath(_)
            | Integrator::PolarizedVolPath(_)
            | Integrator::Stokes(_)
            | Integrator::Guided(_)
            | Integrator::Vcm(_) => &[],
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
            Integrator::Depth(_) => false,
            Integrator::Particle(ptracer) => ptracer.hide_emitters,
            Integrator::Bdpt(bdpt) => bdpt.hide_emitters,
            Integrator::Sppm(_) => false,
            Integrator::Vcm(vcm) => vcm.hide_emitters,
            Integrator::PolarizedPath(polarized) => polarized.path.hide_emitters,
            Integrator::PolarizedVolPath(polarized) => polarized.volpath.hide_emitters,
            Integrator::Stokes(stokes) => stokes.nested.hides_emitters(),
            Integrator::Guided(guided) => guided.hide_emitters,
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
            | Integrator::VolPath(_)
            | Integrator::Depth(_)
            | Integrator::Particle(_)
            | Integrator::Bdpt(_)
            | Integrator::Sppm(_)
            | Integrator::PolarizedPath(_)
            | Integrator::PolarizedVolPath(_)
            | Integrator::Guided(_)
            | Integrator::Vcm(_) => Vec::new(),
            Integrator::Moment(moment) => moment.aov_names(),
            Integrator::Stokes(stokes) => stokes.aov_names(),
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
    /// The particle tracer, where the integrator is one: its samples are light subpaths
    /// splatted onto the film rather than estimates along camera rays.
    pub fn particle_tracer(&self) -> Option<&ParticleTracer> {
        match self.integrator {
            Integrator::Particle(ptracer) => Some(ptracer),
            _ => None,
        }
    }

    /// Stochastic progressive photon mapping, where the integrator is it: the render driver
    /// runs its passes, which keep statistics per pixel from one pass to the next.
    pub fn sppm(&self) -> Option<&SppmIntegrator> {
        match self.integrator {
            Integrator::Sppm(sppm) => Some(sppm),
            _ => None,
        }
    }

    /// The guided path tracer, where the integrator is it: the render driver runs its
    /// iterations, which learn the SD-tree its paths sample from.
    pub fn guided(&self) -> Option<&GuidedPathIntegrator> {
        match self.integrator {
            Integrator::Guided(guided) => Some(guided),
            _ => None,
        }
    }

    /// Traces one sample of the particle tracer `ptracer` (this integrator's), drawing random
    /// numbers from `sampler` and handing its contributions to `out`.
    pub fn trace_light_paths(
        &self,
        ptracer: &ParticleTracer,
        sample: &LightPathSample,
        sampler: &mut Sampler,
        count: &mut RayCount,
        out: &mut impl Splat,
    ) {
        let ctx = &mut SampleContext {
            prepared: self,
            sampler,
            count,
        };
        ptracer.sample(ctx, sample, out);
    }

    /// Bidirectional path tracing, where the integrator is it: its samples are a camera
    /// subpath's estimate for its pixel and light subpaths' splats.
    pub fn bidirectional(&self) -> Option<&BdptIntegrator> {
        match self.integrator {
            Integrator::Bdpt(bdpt) => Some(bdpt),
            _ => None,
        }
    }

    /// Vertex connection and merging, where the integrator is it: the render driver runs its
    /// iterations, whose camera subpaths read every light subpath's vertices.
    pub fn vcm(&self) -> Option<&VcmIntegrator> {
        match self.integrator {
            Integrator::Vcm(vcm) => Some(vcm),
            _ => None,
        }
    }

    /// Traces one sample of bidirectional path tracing `bdpt` (this integrator's) from the
    /// camera ray `ray`, drawing random numbers from `sampler`: returns the estimate for the
    /// camera sample's pixel and hands the light subpaths' splats to `out`.
    pub fn trace_bidirectional(
        &self,
        bdpt: &BdptIntegrator,
        sample: &LightPathSample,
        ray: Ray,
        sampler: &mut Sampler,
        count: &mut RayCount,
        out: &mut impl Splat,
    ) -> SampledSpectrum {
        let ctx = &mut SampleContext {
            prepared: self,
            sampler,
            count,
        };
        bdpt.sample(ctx, sample, ray, out)
    }

    /// How many extra channels each sample writes.
    pub fn aov_count(&self) -> usize {
        self.aov_count
    }

    /// The integrator as a [`SteppedPath`], where it is one: its camera paths run in lanes (the
    /// render driver's `lanes`).
    pub(crate) fn stepped(&self) -> Option<SteppedIntegrator<'_>> {
        match self.integrator {
            Integrator::Path(path) => Some(SteppedIntegrator::Path(path)),
            Integrator::Direct(direct) => Some(SteppedIntegrator::Direct(direct)),
            Integrator::Distribution(distrib) => Some(SteppedIntegrator::Distribution(distrib)),
            Integrator::VolPath(integrator) => Some(match integrator.tracking {
                Tracking::Spectral => SteppedIntegrator::VolPath(VolPathWith {
                    integrator,
                    weights: SpectralTracking::new(),
                }),
                Tracking::HeroMis { spectral_mis } => SteppedIntegrator::VolPathMis(VolPathWith {
                    integrator,
                    weights: SpectralMis::new(spectral_mis),
                }),
            }),
            _ => None,
        }
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
        let ctx = &mut SampleContext {
            prepared: self,
            sampler,
            count,
        };
        match self.integrator {
            Integrator::Path(_)
            | Integrator::Direct(_)
            | Integrator::Distribution(_)
            | Integrator::VolPath(_) => match self.stepped() {
                Some(stepped) => stepped.radiance(ctx, ray, lambda),
                None => unreachable!("these integrators are stepped"),
            },
            Integrator::Moment(_) => MomentIntegrator::radiance(ctx, ray, lambda, aovs),
            Integrator::Aov(integrator) => integrator.radiance(ctx, ray, lambda, aovs),
            Integrator::Depth(_) => DepthIntegrator::radiance(ctx, &ray),
            Integrator::PolarizedPath(integrator) => integrator.radiance(ctx, ray, lambda),
            Integrator::PolarizedVolPath(integrator) => integrator.radiance(ctx, ray, lambda),
            Integrator::Stokes(integrator) => integrator.radiance(ctx, ray, lambda, aovs),
            // Light subpaths reach the film by splats, not along camera rays: the render driver
            // runs them ([`Self::trace_light_paths`], [`Self::trace_bidirectional`], the
            // iterations of [`Self::vcm`]), and photon mapping's passes and path guiding's
            // iterations run apart ([`Self::sppm`], [`Self::guided`]).
            Integrator::Particle(_)
            | Integrator::Bdpt(_)
            | Integrator::Sppm(_)
            | Integrator::Guided(_)
            | Integrator::Vcm(_) => SampledSpectrum::ZERO,
        }
    }
}
