//! Mitsuba 3's `orthographic` sensor: parallel rays along the camera's +z axis, leaving from
//! the square [−1, 1] × [−1/a, 1/a] (a = width / height) of its z = `near_clip` plane, which
//! `to_world` places, turns and scales in the scene.
//!
//! ```xml
//! <sensor type="orthographic">
//!     <transform name="to_world">
//!         <scale x="2" y="2"/>                <!-- the film covers 4 × 4/a units -->
//!         <lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/>
//!     </transform>
//!     <float name="near_clip" value="0.01"/>
//!     <float name="far_clip" value="10000"/>
//! </sensor>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! Mitsuba 3's `orthographic.cpp` maps the film position s ∈ [0, 1]² (of the full film) to the
//! camera point ((1 − 2 sₓ), (1 − 2 s_y) / a, near) (+x to the left of the image, +y up, as for
//! `perspective`); the ray leaves the world image of that point along the world image of +z,
//! normalized, and ends `far_clip − near_clip` further on. Every ray has weight one, so a pixel
//! measures the radiance arriving at its patch of the film plane.

use glam::{Vec2, Vec3};

use super::{CameraModel, CameraRay, ImportanceSample, film_position, screen_position};
use crate::light::BoundingSphere;
use crate::math::{AnimatedTransform, Ray};

#[derive(Clone, Debug)]
pub struct OrthographicCamera {
    /// Camera to world, possibly moving over the shutter interval; its scale sets the size of
    /// the film in the scene.
    pub to_world: AnimatedTransform,
    /// Size of the full film in pixels (not the crop window).
    pub film_size: Vec2,
    pub near_clip: f32,
    pub far_clip: f32,
}

impl CameraModel for OrthographicCamera {
    /// The ray through film position `film` (pixels, origin at the top-left of the full film)
    /// at time `time`.
    #[inline]
    fn generate_ray(&self, film: Vec2, _lens: Vec2, time: f32) -> CameraRay {
        let (screen, aspect) = screen_position(film, self.film_size);
        let local = Vec3::new(screen.x, screen.y / aspect, self.near_clip);
        let to_world = self.to_world.at(time);
        let d = to_world.vector(Vec3::Z).normalize();
        CameraRay::unweighted(Ray::new(
            to_world.point(local),
            d,
            self.far_clip - self.near_clip,
            time,
        ))
    }

    fn set_scene_bounds(&mut self, _bounds: BoundingSphere) {}

    /// The point of the near plane straight behind `p` along the view axis, and its film
    /// position: film positions u (pixels) and points of that plane are related by
    /// du = (W·H/A) dA, A the film's area in the scene, so per film of W·H light subpaths the
    /// weight is 1/A (the cosine at `p` is the scattering's).
    fn sample_importance(&self, p: Vec3, _u: Vec2, time: f32) -> Option<ImportanceSample> {
        let to_world = self.to_world.at(time);
        let q = to_world.inverse_point(p);
        if !(q.z >= self.near_clip && q.z <= self.far_clip) {
            return None;
        }
        let aspect = self.film_size.x / self.film_size.y;
        let film = film_position(Vec2::new(q.x, q.y * aspect), self.film_size)?;
        let width = to_world.vector(Vec3::X).length() * 2.0;
        let height = to_world.vector(Vec3::Y).length() * 2.0 / aspect;
        let on_plane = to_world.point(Vec3::new(q.x, q.y, self.near_clip));
        Some(ImportanceSample {
            film,
            p: on_plane,
            wi: -to_world.vector(Vec3::Z).normalize(),
            weight: 1.0 / (width * height),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Transform;
    use glam::DMat4;

    /// The film's corners map to the corners of [−1, 1] × [−1/a, 1/a], scaled by `to_world`;
    /// every ray is parallel to its +z.
    #[test]
    fn film_corners_map_to_the_scaled_square() {
        let scale = DMat4::from_scale(glam::DVec3::new(3.0, 2.0, 1.0));
        let camera = OrthographicCamera {
            to_world: AnimatedTransform::fixed(Transform::new(scale).unwrap()),
            film_size: Vec2::new(200.0, 100.0),
            near_clip: 0.5,
            far_clip: 10.0,
        };
        for (film, expected) in [
            (Vec2::ZERO, Vec3::new(3.0, 1.0, 0.5)),
            (Vec2::new(200.0, 100.0), Vec3::new(-3.0, -1.0, 0.5)),
            (Vec2::new(100.0, 50.0), Vec3::new(0.0, 0.0, 0.5)),
            (Vec2::new(50.0, 0.0), Vec3::new(1.5, 1.0, 0.5)),
        ] {
            let ray = camera.generate_ray(film, Vec2::ZERO, 0.0).ray;
            assert!((ray.o - expected).length() < 1e-6, "{film}: {}", ray.o);
            assert!((ray.d - Vec3::Z).length() < 1e-7);
            assert!((ray.t_max - 9.5).abs() < 1e-6);
        }
    }
}
