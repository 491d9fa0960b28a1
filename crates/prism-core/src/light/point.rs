//! Mitsuba's `point` emitter: an isotropic point source of radiant intensity I.
//!
//! ```xml
//! <emitter type="point">
//!     <point name="position" x="0" y="2" z="0"/>   <!-- or a to_world transform -->
//!     <rgb name="intensity" value="10"/>
//! </emitter>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! Irradiance at distance d on a surface tilted by θ is I cos θ / d² (the lecture's point-light
//! term of "Direct Light Sampling").

use std::f32::consts::PI;

use glam::Vec3;

use super::{
    BoundingSphere, EmissionQuery, EmissionSample, Environment, LightBounds, LightQuery,
    LightSample, LightSource, towards_point,
};
use crate::geometry::Primitive;
use crate::sampling::warp::{sample_uniform_sphere, uniform_sphere_pdf};
use crate::spectrum::Spectrum;

#[derive(Clone, Debug)]
pub struct PointLight {
    pub position: Vec3,
    pub intensity: Spectrum,
}

impl LightSource for PointLight {
    fn sample_incident(&self, query: LightQuery<'_>) -> Option<LightSample> {
        let (wi, dist2) = towards_point(self.position, query.reference)?;
        let radiance = self.intensity.sample(query.lambda) * (1.0 / dist2);
        Some(LightSample::from_point(self.position, wi, radiance))
    }

    /// A uniform direction: weight I / (1/4π).
    fn sample_emission(&self, query: EmissionQuery<'_>) -> Option<EmissionSample> {
        Some(EmissionSample {
            p: self.position,
            n: Vec3::ZERO,
            d: sample_uniform_sphere(query.u_direction),
            weight: self.intensity.sample(query.lambda) * (1.0 / uniform_sphere_pdf()),
        })
    }

    /// Φ = 4π I.
    fn power(&self, _shapes: &[Primitive]) -> f32 {
        4.0 * PI * self.intensity.luminance()
    }

    fn bounds(&self, _shapes: &[Primitive]) -> Option<LightBounds> {
        Some(LightBounds::at_point(self.position, 0.0))
    }

    fn set_scene_bounds(&mut self, _bounds: BoundingSphere) {}

    fn as_environment(&self) -> Option<Environment<'_>> {
        None
    }
}
