//! Mitsuba's `spot` emitter: a point source whose intensity falls off away from its axis.
//!
//! ```xml
//! <emitter type="spot">
//!     <transform name="to_world">                   <!-- at the origin, shining along +z -->
//!         <lookat origin="1, 1, 1" target="1, 2, 1"/>
//!     </transform>
//!     <rgb name="intensity" value="10"/>            <!-- on the axis -->
//!     <float name="cutoff_angle" value="20"/>       <!-- degrees -->
//!     <float name="beam_width" value="15"/>         <!-- degrees -->
//!     <texture type="bitmap" name="texture">        <!-- optional, projected -->
//!         <string name="filename" value="gobo.png"/>
//!     </texture>
//! </emitter>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! The falloff is Mitsuba's: the full intensity within `beam_width` of the axis, then linear in
//! the angle down to zero at `cutoff_angle`. An optional `texture` multiplies the intensity,
//! projected as in Mitsuba 3's `direction_to_uv`: the direction (x, y, z) of the light's frame
//! sees (u, v) = (½ + x / (2 z tan c), ½ + y / (2 z tan c)), c the cutoff angle, so the image
//! spans the square around the cone's cross-section at z = 1; its colours are read as Mitsuba
//! reads an emitter's textures (see [`crate::texture::bitmap::Texels::Emission`]).

use glam::{Vec2, Vec3};

use super::{
    BoundingSphere, EmissionQuery, EmissionSample, Environment, LightBounds, LightQuery,
    LightSample, LightSource, towards_point,
};
use crate::geometry::Primitive;
use crate::math::Transform;
use crate::sampling::warp::{sample_uniform_cone, uniform_cone_pdf};
use crate::spectrum::Spectrum;
use crate::texture::Texture;
use crate::texture::TextureValues;

#[derive(Clone, Debug)]
pub struct SpotLight {
    /// Light-to-world transform; the light sits at its origin and shines along its +z.
    to_world: Transform,
    position: Vec3,
    /// Radiant intensity on the axis.
    intensity: Spectrum,
    /// Half-angles in radians: the edge of the cone, and of the full-intensity beam within it.
    cutoff: f32,
    beam: f32,
    cos_cutoff: f32,
    cos_beam: f32,
    /// The projected texture, if any.
    texture: Option<Texture>,
}

impl SpotLight {
    /// A spot light; angles in radians with 0 ≤ beam ≤ cutoff ≤ π (checked by the scene reader).
    pub fn new(to_world: Transform, intensity: Spectrum, cutoff: f32, beam: f32) -> SpotLight {
        SpotLight {
            position: to_world.point(Vec3::ZERO),
            to_world,
            intensity,
            cutoff,
            beam,
            cos_cutoff: cutoff.cos(),
            cos_beam: beam.cos(),
            texture: None,
        }
    }

    /// The spot light projecting `texture` (a cutoff below π/2, checked by the scene reader).
    pub fn with_texture(self, texture: Texture) -> SpotLight {
        SpotLight {
            texture: Some(texture),
            ..self
        }
    }

    /// The texture coordinates that the direction `local` (light frame, z > 0) sees.
    pub fn texture_uv(&self, local: Vec3) -> Vec2 {
        let k = 0.5 / (local.z * self.cutoff.tan());
        Vec2::new(0.5 + local.x * k, 0.5 + local.y * k)
    }

    /// The factor in [0, 1] by which the intensity in direction `local` (light frame) is
    /// reduced: 1 for θ ≤ beam, (cutoff − θ)/(cutoff − beam) up to the cutoff, 0 beyond.
    pub fn falloff(&self, local: Vec3) -> f32 {
        let cos_theta = local.normalize_or_zero().z;
        if !(cos_theta > self.cos_cutoff) {
            0.0
        } else if cos_theta >= self.cos_beam {
            1.0
        } else {
            ((self.cutoff - cos_theta.clamp(-1.0, 1.0).acos()) / (self.cutoff - self.beam))
                .clamp(0.0, 1.0)
        }
    }

    /// Where the light sits.
    pub fn position(&self) -> Vec3 {
        self.position
    }
}

impl LightSource for SpotLight {
    fn sample_incident(&self, query: LightQuery<'_>) -> Option<LightSample> {
        let (wi, dist2) = towards_point(self.position, query.reference)?;
        let local = self.to_world.inverse_vector(-wi);
        let falloff = self.falloff(local);
        if falloff == 0.0 {
            return None;
        }
        let mut radiance = self.intensity.sample(query.lambda) * (falloff / dist2);
        if let Some(texture) = &self.texture {
            radiance *= texture.eval(self.texture_uv(local), query.lambda);
            if radiance.is_black() {
                return None;
            }
        }
        Some(LightSample::from_point(self.position, wi, radiance))
    }

    /// A direction uniform in the cone of the cutoff angle (as Mitsuba's `sample_ray`):
    /// weight I · falloff · texture / p_ω.
    fn sample_emission(&self, query: EmissionQuery<'_>) -> Option<EmissionSample> {
        let local = sample_uniform_cone(query.u_direction, self.cos_cutoff);
        let pdf = uniform_cone_pdf(local, self.cos_cutoff);
        let falloff = self.falloff(local);
        if !(pdf > 0.0) || falloff == 0.0 {
            return None;
        }
        let mut weight = self.intensity.sample(query.lambda) * (falloff / pdf);
        if let Some(texture) = &self.texture {
            weight *= texture.eval(self.texture_uv(local), query.lambda);
        }
        Some(EmissionSample {
            p: self.position,
            n: Vec3::ZERO,
            d: self.to_world.vector(local).normalize(),
            weight,
        })
    }

    /// Φ = I ∫ falloff dω = 2π I [(1 − cos β) + ∫_β^c (c − θ)/(c − β) sin θ dθ]
    ///   = 2π I [1 − (sin c − sin β)/(c − β)]   (integrating the ramp by parts),
    /// which tends to the cone's 2π I (1 − cos c) as the ramp's width c − β goes to 0; with a
    /// texture, times its mean value over the image (a weight for choosing the light).
    fn power(&self, _shapes: &[Primitive]) -> f32 {
        let (c, b) = (f64::from(self.cutoff), f64::from(self.beam));
        let width = c - b;
        let fraction = if width > 1e-4 {
            1.0 - (c.sin() - b.sin()) / width
        } else {
            // The difference quotient is cos at the midpoint to O(width²).
            1.0 - (0.5 * (c + b)).cos()
        };
        let texture_mean = self.texture.as_ref().map_or(1.0, Texture::mean_value);
        (2.0 * std::f64::consts::PI * fraction) as f32 * self.intensity.luminance() * texture_mean
    }

    fn bounds(&self, _shapes: &[Primitive]) -> Option<LightBounds> {
        Some(LightBounds::at_point(self.position(), 0.0))
    }

    fn set_scene_bounds(&mut self, _bounds: BoundingSphere) {}

    fn as_environment(&self) -> Option<Environment<'_>> {
        None
    }
}

#[cfg(test)]
mod tests {
    use std::f32::consts::PI;

    use super::*;

    /// The closed-form power against a midpoint-rule integral of the falloff over the sphere.
    #[test]
    fn power_integrates_the_falloff() {
        for (cutoff, beam) in [(20.0f32, 15.0f32), (60.0, 0.0), (30.0, 30.0), (170.0, 90.0)] {
            let light = SpotLight::new(
                Transform::IDENTITY,
                Spectrum::Constant(2.0),
                cutoff.to_radians(),
                beam.to_radians(),
            );
            let n = 200_000;
            let integral: f64 = (0..n)
                .map(|i| {
                    let theta = PI * (i as f32 + 0.5) / n as f32;
                    let w = Vec3::new(theta.sin(), 0.0, theta.cos());
                    f64::from(light.falloff(w) * theta.sin())
                })
                .sum::<f64>()
                * 2.0
                * std::f64::consts::PI
                * std::f64::consts::PI
                / f64::from(n);
            let expected = 2.0 * integral;
            assert!(
                (f64::from(light.power(&[])) / expected - 1.0).abs() < 1e-4,
                "cutoff {cutoff}, beam {beam}: {} vs {expected}",
                light.power(&[])
            );
        }
    }
}
