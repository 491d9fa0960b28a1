//! Mitsuba's `projector` emitter: a pinhole that projects an image into the scene, the
//! reciprocal of a perspective camera.
//!
//! ```xml
//! <emitter type="projector">
//!     <texture type="bitmap" name="irradiance">     <!-- or a value -->
//!         <string name="filename" value="slide.png"/>
//!     </texture>
//!     <float name="scale" value="2"/>
//!     <float name="fov" value="45"/>                <!-- along fov_axis; or focal_length -->
//!     <transform name="to_world">                   <!-- at the origin, shining along +z -->
//!         <lookat origin="1, 1, 1" target="1, 2, 1" up="0, 0, 1"/>
//!     </transform>
//! </emitter>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! As in Mitsuba 3 (`src/emitters/projector.cpp`): a point x of the light's frame (z > 0) sees
//! the image at
//!
//!   (u, v) = (½ − x / (2 z t), ½ − a y / (2 z t)),   t = tan(fov_x / 2), a = width / height,
//!
//! Mitsuba's perspective projection, so the image lies on the plane z = 1 over
//! [−t, t] × [−t/a, t/a], mirrored as a camera's film is. The light arriving at x from the
//! pinhole (at distance d, at angle θ to the axis, with z = d cos θ) is
//!
//!   L = π · scale · E(u, v) / (z² cos θ),
//!
//! so that a plane z = z₀ perpendicular to the axis, which the light meets at the angle θ,
//! receives the irradiance E_plane = L cos θ = π · scale · E(u, v) / z₀²: an image of constant
//! values lights such a plane evenly, and the plane z = 1 with π times the image's values.
//! Textured colours are read as Mitsuba reads an emitter's textures (see
//! [`crate::texture::bitmap::Texels::Emission`]); a value is an emission, D65 for `<rgb>`.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::{
    BoundingSphere, EmissionQuery, EmissionSample, Environment, LightBounds, LightQuery,
    LightSample, LightSource,
};
use crate::geometry::Primitive;
use crate::math::Transform;
use crate::texture::Texture;
use crate::texture::TextureValues;

#[derive(Clone, Debug)]
pub struct Projector {
    /// Light-to-world transform; the pinhole is at its origin, looking along its +z.
    to_world: Transform,
    position: Vec3,
    /// The unit world-space axis (the image of +z).
    axis: Vec3,
    irradiance: Texture,
    scale: f32,
    /// tan(fov_x / 2).
    tan_half_fov: f32,
    /// The image's width over its height.
    aspect: f32,
    /// The mean of the irradiance's values over the image (its luminance for colours).
    mean_irradiance: f32,
}

impl Projector {
    /// A projector of `irradiance` (an image of aspect `aspect` = width / height, or a
    /// constant with aspect 1) times `scale` ≥ 0, with the horizontal field of view `fov_x`
    /// in radians (0 < fov_x < π).
    pub fn new(
        to_world: Transform,
        irradiance: Texture,
        scale: f32,
        fov_x: f32,
        aspect: f32,
    ) -> Projector {
        Projector {
            position: to_world.point(Vec3::ZERO),
            axis: to_world.vector(Vec3::Z).normalize(),
            to_world,
            mean_irradiance: irradiance.mean_value(),
            irradiance,
            scale,
            tan_half_fov: (0.5 * fov_x).tan(),
            aspect,
        }
    }

    /// The image coordinates that the point `local` of the light's frame sees (None behind the
    /// pinhole or outside the image).
    pub fn image_uv(&self, local: Vec3) -> Option<Vec2> {
        if !(local.z > 0.0) {
            return None;
        }
        let k = 0.5 / (local.z * self.tan_half_fov);
        let uv = Vec2::new(0.5 - local.x * k, 0.5 - self.aspect * local.y * k);
        (uv.x >= 0.0 && uv.x <= 1.0 && uv.y >= 0.0 && uv.y <= 1.0).then_some(uv)
    }

    /// Where the light sits.
    pub fn position(&self) -> Vec3 {
        self.position
    }
}

impl LightSource for Projector {
    fn sample_incident(&self, query: LightQuery<'_>) -> Option<LightSample> {
        let local = self.to_world.inverse_point(query.reference);
        let uv = self.image_uv(local)?;
        let d = self.position - query.reference;
        let dist = d.length();
        if !(dist > 0.0) {
            return None;
        }
        let wi = d / dist;
        let cos_theta = self.axis.dot(-wi);
        if !(cos_theta > 0.0) {
            return None;
        }
        let irradiance = self.irradiance.eval(uv, query.lambda);
        if irradiance.is_black() {
            return None;
        }
        let radiance = irradiance * (PI * self.scale / (local.z * local.z * cos_theta));
        Some(LightSample::from_point(self.position, wi, radiance))
    }

    /// A direction through a uniform point (x, y, 1) of the image's rectangle on the plane
    /// z = 1, of area A = 4t²/a: its density per solid angle is 1/(A cos³θ), and the intensity
    /// there is I = π · scale · E / cos³θ (the irradiance π · scale · E on that plane, at
    /// distance 1/cos θ and tilted by θ), so the weight is π · scale · E · A.
    fn sample_emission(&self, query: EmissionQuery<'_>) -> Option<EmissionSample> {
        let uv = query.u_direction;
        let t = self.tan_half_fov;
        let local = Vec3::new(
            (0.5 - uv.x) * 2.0 * t,
            (0.5 - uv.y) * 2.0 * t / self.aspect,
            1.0,
        );
        let irradiance = self.irradiance.eval(uv, query.lambda);
        if irradiance.is_black() {
            return None;
        }
        let area = 4.0 * t * t / self.aspect;
        Some(EmissionSample {
            p: self.position,
            n: Vec3::ZERO,
            d: self.to_world.vector(local).normalize(),
            weight: irradiance * (PI * self.scale * area),
        })
    }

    /// Φ = π · scale · Ē · 4 t² / a: the irradiance π · scale · E on the plane z = 1 over the
    /// image's rectangle there, [−t, t] × [−t/a, t/a] (Ē the mean of the image's values).
    fn power(&self, _shapes: &[Primitive]) -> f32 {
        let t = self.tan_half_fov;
        PI * self.scale * self.mean_irradiance * 4.0 * t * t / self.aspect
    }

    fn bounds(&self, _shapes: &[Primitive]) -> Option<LightBounds> {
        Some(LightBounds::at_point(self.position(), 0.0))
    }

    fn set_scene_bounds(&mut self, _bounds: BoundingSphere) {}

    fn as_environment(&self) -> Option<Environment<'_>> {
        None
    }
}
