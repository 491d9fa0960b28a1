//! Light sources and the choice among them.
//!
//! Direct lighting follows the lecture's split of the reflection integral into a sum over lights
//! ("Direct Light Sampling"): area lights are integrated over their surface (or, for spheres,
//! over the cone they subtend), point lights are a single point.

pub mod area;
pub mod point;
pub mod sampler;

use glam::{Vec2, Vec3};

use crate::geometry::Shape;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
pub use area::AreaLight;
pub use point::PointLight;
pub use sampler::LightSampler;

/// A light source of the scene.
#[derive(Clone, Debug)]
pub enum Light {
    Area(AreaLight),
    Point(PointLight),
}

/// Incident light sampled at a point: where it comes from and how much arrives.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// The point on the light.
    pub p: Vec3,
    /// Geometric normal at `p` (zero for point lights), for the shadow ray's far end.
    pub n: Vec3,
    /// Unit direction from the receiving point towards `p`.
    pub wi: Vec3,
    /// Radiance arriving along `wi` (for a point light: intensity / distance²).
    pub radiance: SampledSpectrum,
    /// Density of the sample per unit solid angle, or 1 for delta lights.
    pub pdf: f32,
    /// Whether the light is a Dirac delta (a point): no other strategy can find it.
    pub is_delta: bool,
}

impl Light {
    /// Samples light arriving at `reference` at `time`. `u_choice` and `u` are the random
    /// numbers.
    #[allow(clippy::too_many_arguments)]
    pub fn sample_incident(
        &self,
        shapes: &[Shape],
        reference: Vec3,
        time: f32,
        u_choice: f32,
        u: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<LightSample> {
        match self {
            Light::Area(light) => {
                light.sample_incident(shapes, reference, time, u_choice, u, lambda)
            }
            Light::Point(light) => light.sample_incident(reference, lambda),
        }
    }

    /// Emitted power Φ, summarised as a luminance-weighted scalar (watts weighted by ȳ): the
    /// light sampler chooses lights in proportion to it.
    pub fn power(&self, shapes: &[Shape]) -> f32 {
        match self {
            Light::Area(light) => light.power(shapes),
            Light::Point(light) => light.power(),
        }
    }
}
