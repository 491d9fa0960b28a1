//! Mitsuba's `directional` emitter: a distant source that delivers irradiance E from one
//! direction (the sun, say).
//!
//! ```xml
//! <emitter type="directional">
//!     <vector name="direction" x="0" y="-1" z="0"/>   <!-- where the light travels; or to_world -->
//!     <rgb name="irradiance" value="5"/>              <!-- on a surface facing it -->
//! </emitter>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! Without `direction`, the light travels along the +z axis of `to_world` (default: world +z).
//! A diffuse surface tilted by θ from the light reflects L = ρ E cos θ / π (docs/testing.md, Closed
//! forms).

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::{BoundingSphere, DirectionSample, Environment, LightAtInfinity};
use crate::spectrum::{SampledWavelengths, Spectrum};

#[derive(Clone, Debug)]
pub struct DirectionalLight {
    /// Unit direction in which the light travels.
    pub direction: Vec3,
    pub irradiance: Spectrum,
    /// The scene's bounding sphere (set when the scene is assembled).
    pub scene: BoundingSphere,
}

impl DirectionalLight {
    pub fn new(direction: Vec3, irradiance: Spectrum) -> DirectionalLight {
        DirectionalLight {
            direction,
            irradiance,
            scene: BoundingSphere::default(),
        }
    }
}

impl LightAtInfinity for DirectionalLight {
    const IS_DELTA: bool = true;

    /// The light arrives from −direction at every point; the shadow ray runs to a point beyond
    /// the scene. As a delta in direction, the "radiance" is the irradiance and the pdf 1.
    fn sample_direction(&self, _u: Vec2, lambda: &SampledWavelengths) -> Option<DirectionSample> {
        let wi = -self.direction;
        let irradiance = self.irradiance.sample(lambda);
        Some(DirectionSample {
            wi,
            radiance: irradiance,
            pdf: 1.0,
        })
    }

    fn environment(&self) -> Option<Environment<'_>> {
        None
    }

    /// Φ = π R² E: the flux through the disk the scene's bounding sphere presents to the light
    /// (pbrt-v4's `DistantLight::Phi`).
    fn flux(&self) -> f32 {
        PI * self.scene.radius * self.scene.radius * self.irradiance.luminance()
    }

    fn scene(&self) -> &BoundingSphere {
        &self.scene
    }

    fn scene_mut(&mut self) -> &mut BoundingSphere {
        &mut self.scene
    }
}
