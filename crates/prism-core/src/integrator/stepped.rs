//! Camera-path estimators written one vertex at a time: the path's state between two ray
//! queries, and the step that takes it from the nearest surface along its ray to its next ray.
//! A driver may so hold many paths at once and trace their rays together (the render driver's
//! lanes, docs/architecture.md, Paths in lanes); the estimate of one path at a time
//! ([`SteppedPath::radiance`]) runs the same step, so the two give the same numbers bit for bit.
//!
//! The path tracer ([`super::path`]), direct illumination ([`super::direct`], one step), the
//! lecture's distribution ray tracer
//! ([`super::distribution`], its tree of rays one ray per step) and the volumetric path tracers
//! ([`super::volpath`], [`super::volpathmis`]) are written so.

use crate::geometry::SurfaceInteraction;
use crate::integrator::volpath::{SpectralTracking, VolPathWith};
use crate::integrator::volpathmis::SpectralMis;
use crate::integrator::{DirectIntegrator, DistributionIntegrator, PathIntegrator, SampleContext};
use crate::math::Ray;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::world::World;

/// An estimator of the radiance along a camera ray whose path advances one ray query per step.
pub trait SteppedPath {
    /// Everything one step of a path hands the next.
    type State;

    /// The path of the camera ray `ray` with `wavelengths` in `world`, before its first query;
    /// None when the path ends before it (its estimate is then zero).
    fn start(
        &self,
        world: &World,
        ray: Ray,
        wavelengths: &SampledWavelengths,
    ) -> Option<Self::State>;

    /// The ray whose nearest surface the next step needs.
    fn ray(state: &Self::State) -> &Ray;

    /// One step of the path `state`, given `hit`, the nearest surface along its ray (None when
    /// the ray leaves the scene). Returns whether the path goes on (along its new ray).
    fn step(
        &self,
        ctx: &mut SampleContext,
        state: &mut Self::State,
        hit: Option<SurfaceInteraction>,
    ) -> bool;

    /// The estimate of a path that has ended, for the wavelengths it started with.
    fn estimate(&self, state: &Self::State) -> SampledSpectrum;

    /// The estimate along the camera ray `ray`, one step after another.
    #[inline]
    fn radiance(
        &self,
        ctx: &mut SampleContext,
        ray: Ray,
        wavelengths: &SampledWavelengths,
    ) -> SampledSpectrum {
        let Some(mut state) = self.start(ctx.world(), ray, wavelengths) else {
            return SampledSpectrum::ZERO;
        };
        loop {
            let hit = ctx.intersect(Self::ray(&state));
            if !self.step(ctx, &mut state, hit) {
                return self.estimate(&state);
            }
        }
    }
}

/// The scene's integrator where it is a [`SteppedPath`], with the weights its paths start with.
pub(crate) enum SteppedIntegrator<'a> {
    Path(&'a PathIntegrator),
    Direct(&'a DirectIntegrator),
    Distribution(&'a DistributionIntegrator),
    VolPath(VolPathWith<'a, SpectralTracking>),
    VolPathMis(VolPathWith<'a, SpectralMis>),
}

impl SteppedIntegrator<'_> {
    /// The estimate along the camera ray `ray` ([`SteppedPath::radiance`]).
    pub(crate) fn radiance(
        &self,
        ctx: &mut SampleContext,
        ray: Ray,
        wavelengths: &SampledWavelengths,
    ) -> SampledSpectrum {
        match self {
            SteppedIntegrator::Path(path) => path.radiance(ctx, ray, wavelengths),
            SteppedIntegrator::Direct(direct) => direct.radiance(ctx, ray, wavelengths),
            SteppedIntegrator::Distribution(distrib) => distrib.radiance(ctx, ray, wavelengths),
            SteppedIntegrator::VolPath(volpath) => volpath.radiance(ctx, ray, wavelengths),
            SteppedIntegrator::VolPathMis(volpath) => volpath.radiance(ctx, ray, wavelengths),
        }
    }
}
