//! Light sources and the choice among them.
//!
//! Direct lighting follows the lecture's split of the reflection integral into a sum over lights
//! ("Direct Light Sampling"): area lights are integrated over their surface (or, for spheres,
//! over the cone they subtend); point, spot and projector lights are single points and directional lights
//! single directions (Dirac deltas, reached only by light sampling); environment lights
//! (`constant`, `envmap`, `sunsky`) surround the scene at infinity and are also found by rays that leave
//! it, so they take part in multiple importance sampling like area lights.
//!
//! | Mitsuba emitter | file | sampled by |
//! | --- | --- | --- |
//! | `area` | [`area`] | the shape: spheres by visible cone, other shapes by area; a textured radiance by the texture through the uv map |
//! | `point` | [`point`] | its position (delta) |
//! | `spot` | [`spot`] | its position (delta) |
//! | `projector` | [`projector`] | its position (delta) |
//! | `directional` | [`directional`] | its direction (delta) |
//! | `constant` | [`constant`] | uniform directions |
//! | `envmap` | [`envmap`] | directions ∝ luminance · sin θ in the lat-long image |
//! | `sunsky` | [`sunsky`] | the sky's luminance over (φ, cos θ), and the sun's cone |

pub mod area;
pub mod bounds;
pub mod constant;
pub mod directional;
pub mod envmap;
pub mod point;
pub mod projector;
pub mod sampler;
pub mod spot;
pub mod sunsky;

use glam::{Vec2, Vec3};

use crate::geometry::Primitive;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
pub use area::AreaLight;
pub use bounds::{LightBounds, Receiver};
pub use constant::ConstantLight;
pub use directional::DirectionalLight;
pub use envmap::EnvironmentMap;
pub use point::PointLight;
pub use projector::Projector;
pub use sampler::{LightSampler, LightSelection};
pub use spot::SpotLight;
pub use sunsky::{Sunsky, SunskySettings};

/// A light source of the scene.
#[derive(Clone, Debug)]
pub enum Light {
    Area(AreaLight),
    Point(PointLight),
    Spot(SpotLight),
    Projector(Projector),
    Directional(DirectionalLight),
    Constant(ConstantLight),
    Envmap(EnvironmentMap),
    Sunsky(Box<Sunsky>),
}

/// Incident light sampled at a point: where it comes from and how much arrives.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// The point on the light; for lights at infinity, a point beyond the scene in direction
    /// `wi`, so that a shadow ray to it crosses the whole scene.
    pub p: Vec3,
    /// Geometric normal at `p` (zero for point, spot and infinite lights), for the shadow ray's
    /// far end.
    pub n: Vec3,
    /// Unit direction from the receiving point towards `p`.
    pub wi: Vec3,
    /// Radiance arriving along `wi` (for a point light: intensity / distance²; for a
    /// directional light: its irradiance).
    pub radiance: SampledSpectrum,
    /// Density of the sample per unit solid angle, or 1 for delta lights.
    pub pdf: f32,
    /// Whether the light is a Dirac delta (a point or a direction): no other strategy can find
    /// it.
    pub is_delta: bool,
}

/// The sphere that bounds the scene's geometry. Lights at infinity use it, as Mitsuba's
/// `set_scene` does, to place shadow-ray end points beyond the scene and to define their power
/// (the flux they send into it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundingSphere {
    pub center: Vec3,
    pub radius: f32,
}

impl BoundingSphere {
    /// The sphere around an axis-aligned box (centre, half diagonal), enlarged by a relative 10⁻⁴
    /// as Mitsuba enlarges it by its ray epsilon; a tiny sphere at the origin for an empty scene.
    pub fn around_box(bounds: Option<(Vec3, Vec3)>) -> BoundingSphere {
        const EPSILON: f32 = 1e-4;
        match bounds {
            Some((min, max)) if min.is_finite() && max.is_finite() => {
                let center = 0.5 * (min + max);
                BoundingSphere {
                    center,
                    radius: ((max - center).length() * (1.0 + EPSILON)).max(EPSILON),
                }
            }
            _ => BoundingSphere {
                center: Vec3::ZERO,
                radius: EPSILON,
            },
        }
    }

    /// A point in direction `wi` from `reference` that is outside the sphere (twice the larger
    /// of the radius and the reference's distance from the centre, as Mitsuba places it).
    pub fn point_beyond(&self, reference: Vec3, wi: Vec3) -> Vec3 {
        let distance = 2.0 * self.radius.max((reference - self.center).length());
        reference + wi * distance
    }
}

impl Default for BoundingSphere {
    fn default() -> Self {
        BoundingSphere::around_box(None)
    }
}

impl Light {
    /// Samples light arriving at `reference` at `time`. `u_choice` and `u` are the random
    /// numbers.
    pub fn sample_incident(
        &self,
        shapes: &[Primitive],
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
            Light::Spot(light) => light.sample_incident(reference, lambda),
            Light::Projector(light) => light.sample_incident(reference, lambda),
            Light::Directional(light) => light.sample_incident(reference, lambda),
            Light::Constant(light) => light.sample_incident(reference, u, lambda),
            Light::Envmap(light) => light.sample_incident(reference, u, lambda),
            Light::Sunsky(light) => light.sample_incident(reference, u, lambda),
        }
    }

    /// Where the light is, for choosing it by importance ([`bounds`]): the box of its shape,
    /// or its position; None for lights at infinity. The power is left 0 (the sampler fills
    /// it in).
    pub fn bounds(&self, shapes: &[Primitive]) -> Option<LightBounds> {
        use crate::geometry::aggregate::AggregateElement;
        match self {
            Light::Area(light) => {
                let (lo, hi) = shapes[light.shape as usize].bounds();
                Some(LightBounds::around_box(lo, hi, 0.0))
            }
            Light::Point(light) => Some(LightBounds::at_point(light.position, 0.0)),
            Light::Spot(light) => Some(LightBounds::at_point(light.position(), 0.0)),
            Light::Projector(light) => Some(LightBounds::at_point(light.position(), 0.0)),
            Light::Directional(_) | Light::Constant(_) | Light::Envmap(_) | Light::Sunsky(_) => {
                None
            }
        }
    }

    /// Emitted power Φ, summarised as a luminance-weighted scalar (watts weighted by ȳ): the
    /// light sampler chooses lights in proportion to it. Lights at infinity count the flux they
    /// send into the scene's bounding sphere, so [`Self::set_scene_bounds`] must come first.
    pub fn power(&self, shapes: &[Primitive]) -> f32 {
        match self {
            Light::Area(light) => light.power(shapes),
            Light::Point(light) => light.power(),
            Light::Spot(light) => light.power(),
            Light::Projector(light) => light.power(),
            Light::Directional(light) => light.power(),
            Light::Constant(light) => light.power(),
            Light::Envmap(light) => light.power(),
            Light::Sunsky(light) => light.power(),
        }
    }

    /// Tells lights at infinity the scene's extent (Mitsuba's `Emitter::set_scene`).
    pub fn set_scene_bounds(&mut self, bounds: BoundingSphere) {
        match self {
            Light::Directional(light) => light.scene = bounds,
            Light::Constant(light) => light.scene = bounds,
            Light::Envmap(light) => light.scene = bounds,
            Light::Sunsky(light) => light.scene = bounds,
            Light::Area(_) | Light::Point(_) | Light::Spot(_) | Light::Projector(_) => {}
        }
    }

    /// Whether this light surrounds the scene and is seen by rays that leave it (Mitsuba's
    /// "environment emitter", of which a scene has at most one).
    pub fn is_environment(&self) -> bool {
        matches!(
            self,
            Light::Constant(_) | Light::Envmap(_) | Light::Sunsky(_)
        )
    }

    /// Radiance arriving along a ray that leaves the scene in direction `d` (unit): the
    /// environment's emission; zero for other lights.
    #[inline]
    pub fn environment_radiance(&self, d: Vec3, lambda: &SampledWavelengths) -> SampledSpectrum {
        match self {
            Light::Constant(light) => light.radiance(lambda),
            Light::Envmap(light) => light.radiance(d, lambda),
            Light::Sunsky(light) => light.radiance(d, lambda),
            _ => SampledSpectrum::ZERO,
        }
    }

    /// Density per unit solid angle with which [`Self::sample_incident`] picks the direction
    /// `d` (unit) of an environment light; zero for other lights.
    #[inline]
    pub fn environment_pdf(&self, d: Vec3) -> f32 {
        match self {
            Light::Constant(light) => light.pdf(),
            Light::Envmap(light) => light.pdf(d),
            Light::Sunsky(light) => light.pdf(d),
            _ => 0.0,
        }
    }
}
