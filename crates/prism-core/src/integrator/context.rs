//! What an integrator carries while it estimates one camera sample: the integrator prepared for
//! the world (its settings, the world and the light sampler built for them), the sample's
//! random numbers and the count of the rays it traces. Every routine of the vertex step takes
//! this one context instead of a list of arguments.

use crate::geometry::SurfaceInteraction;
use crate::integrator::PreparedIntegrator;
use crate::light::LightSampler;
use crate::math::Ray;
use crate::sampling::sampler::Sampler;
use crate::world::World;

/// Rays traced while estimating one sample, for the statistics line.
#[derive(Clone, Copy, Debug, Default)]
pub struct RayCount {
    pub rays: u64,
}

/// One camera sample's estimation context.
pub struct SampleContext<'p, 's> {
    /// The integrator being run, prepared for the world.
    pub prepared: &'p PreparedIntegrator<'p>,
    /// The sample's random numbers, keyed by pixel, sample index and dimension.
    pub sampler: &'s mut Sampler,
    /// The rays traced so far.
    pub count: &'s mut RayCount,
}

impl<'p> SampleContext<'p, '_> {
    /// The world being rendered (borrowed for the whole render, not from the context, so that
    /// it can be held while the context draws numbers or traces rays).
    #[inline]
    pub fn world(&self) -> &'p World {
        self.prepared.world
    }

    /// The light sampler the integrator chooses lights with.
    #[inline]
    pub fn light_sampler(&self) -> &'p LightSampler {
        &self.prepared.light_sampler
    }

    /// The nearest surface along `ray`, counting the ray.
    #[inline]
    pub fn intersect(&mut self, ray: &Ray) -> Option<SurfaceInteraction> {
        self.count.rays += 1;
        self.prepared.world.geometry.intersect(ray)
    }

    /// Whether any surface blocks the shadow ray `ray`, counting the ray.
    #[inline]
    pub fn occluded(&mut self, ray: &Ray) -> bool {
        self.count.rays += 1;
        self.prepared.world.geometry.occluded(ray)
    }
}
