//! Mitsuba's `perspective` sensor, an ideal pinhole camera, and its `thinlens` sensor, which adds
//! a circular aperture for depth of field.
//!
//! ```xml
//! <sensor type="perspective">
//!     <float name="fov" value="39.3"/>          <!-- or focal_length -->
//!     <string name="fov_axis" value="x"/>       <!-- x, y, diagonal, smaller, larger -->
//!     <float name="near_clip" value="0.01"/>
//!     <float name="far_clip" value="10000"/>
//!     <transform name="to_world"> <lookat origin="..." target="..." up="..."/> </transform>
//!     <film .../> <sampler .../>
//! </sensor>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! The camera looks along +z of its frame, with +y up and +x to the left of the image (Mitsuba's
//! convention: `lookat` builds the frame [left, up, forward, origin]).
//!
//! Thin lens (the lecture's "Thin Lens" and "Depth of Field"): every point of the plane in focus
//! at distance g (`focus_distance`, or our `focal_distance`) is imaged sharply; a ray through a
//! film position leaves from a uniformly sampled point of the aperture disk (concentric map) and
//! passes through the point of the focal plane the pinhole ray would reach. The aperture is
//! `aperture_radius`, or, in the lecture's parametrisation, the aperture *area* a
//! (`aperture_area`), so the radius is √(a/π) (docs/architecture.md, The lecture's errata).
//!
//! ```xml
//! <sensor type="thinlens">
//!     <float name="aperture_radius" value="0.05"/>   <!-- or aperture_area -->
//!     <float name="focus_distance" value="4"/>       <!-- or focal_distance -->
//!     <float name="fov" value="40"/>
//! </sensor>
//! ```

use glam::{Vec2, Vec3};

use super::{CameraModel, CameraRay, ImportanceSample, film_position, screen_position};
use crate::light::BoundingSphere;
use crate::math::{AnimatedTransform, Ray};
use crate::sampling::warp::sample_uniform_disk_concentric;

#[derive(Clone, Debug)]
pub struct PerspectiveCamera {
    /// Camera to world, possibly moving over the shutter interval.
    pub to_world: AnimatedTransform,
    /// Size of the full film in pixels (not the crop window).
    pub film_size: Vec2,
    /// tan(fov_x / 2).
    pub tan_half_fov_x: f32,
    pub near_clip: f32,
    pub far_clip: f32,
    /// Radius of the aperture; 0 for a pinhole.
    pub lens_radius: f32,
    /// Distance along the view axis of the plane in focus (irrelevant for a pinhole).
    pub focus_distance: f32,
    /// Where the principal point (the foot of the view axis on the film) lies relative to the
    /// film's centre, in units of the full film's width and height (Mitsuba's
    /// `principal_point_offset_x/y`): film position u sees what u + offset · size would see
    /// without it, as in Mitsuba's `sample_ray`, which shifts its sample so.
    pub principal_point_offset: Vec2,
}

/// Converts a field of view given along `axis` into the horizontal one, for a film of aspect
/// `aspect` = width / height (Mitsuba 3's `parse_fov`). Angles in degrees.
pub fn horizontal_fov(fov: f64, axis: FovAxis, aspect: f64) -> f64 {
    let axis = match axis {
        FovAxis::Smaller => {
            if aspect > 1.0 {
                FovAxis::Y
            } else {
                FovAxis::X
            }
        }
        FovAxis::Larger => {
            if aspect > 1.0 {
                FovAxis::X
            } else {
                FovAxis::Y
            }
        }
        other => other,
    };
    let half = (0.5 * fov).to_radians();
    match axis {
        FovAxis::Y => (2.0 * (half.tan() * aspect).atan()).to_degrees(),
        FovAxis::Diagonal => {
            let diagonal = 2.0 * half.tan();
            let width = diagonal / (1.0 + 1.0 / (aspect * aspect)).sqrt();
            (2.0 * (0.5 * width).atan()).to_degrees()
        }
        _ => fov,
    }
}

/// The axis along which a field of view is measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FovAxis {
    X,
    Y,
    Diagonal,
    Smaller,
    Larger,
}

/// The diagonal field of view of a lens of focal length `mm` on 35 mm film (36 × 24 mm), as
/// Mitsuba computes it for `focal_length` (default "50mm").
pub fn focal_length_to_diagonal_fov(mm: f64) -> f64 {
    (2.0 * ((36.0f64 * 36.0 + 24.0 * 24.0).sqrt() / (2.0 * mm)).atan()).to_degrees()
}

impl CameraModel for PerspectiveCamera {
    /// The ray through film position `film` (pixels, origin at the top-left of the full film),
    /// through lens position `lens` ∈ [0, 1)² (unused by a pinhole) at time `time`. It starts on
    /// the near plane and ends on the far plane, as in Mitsuba.
    #[inline]
    fn generate_ray(&self, film: Vec2, lens: Vec2, time: f32) -> CameraRay {
        let shifted = film + self.principal_point_offset * self.film_size;
        let (screen, aspect) = screen_position(shifted, self.film_size);
        // The pinhole direction, with z = 1.
        let pinhole = Vec3::new(
            screen.x * self.tan_half_fov_x,
            screen.y * self.tan_half_fov_x / aspect,
            1.0,
        );
        let (origin, local) = if self.lens_radius > 0.0 {
            let on_lens = sample_uniform_disk_concentric(lens) * self.lens_radius;
            let aperture = Vec3::new(on_lens.x, on_lens.y, 0.0);
            let in_focus = pinhole * self.focus_distance;
            (aperture, (in_focus - aperture).normalize())
        } else {
            (Vec3::ZERO, pinhole.normalize())
        };
        let inv_z = 1.0 / local.z;
        let near_t = self.near_clip * inv_z;
        let far_t = self.far_clip * inv_z;
        let to_world = self.to_world.at(time);
        let d = to_world.vector(local).normalize();
        let o = to_world.point(origin) + d * near_t;
        CameraRay::unweighted(Ray::new(o, d, far_t - near_t, time))
    }

    fn set_scene_bounds(&mut self, _bounds: BoundingSphere) {}

    /// The pinhole (or, with an aperture, a point a of the lens drawn uniformly with `u`,
    /// whose density 1/(πR²) cancels the lens's share of the measurement) and the film
    /// position of the point q = `p` in the camera's frame: that of the focal-plane point the
    /// line from a through q crosses. Film positions u (pixels) and directions ω from a are
    /// related by du = (W·H/A) dω / cos³θ, with A = 4 tan²(fov_x/2) / aspect the film's area on
    /// the plane z = 1, and dω = |cos θ_p| dA_p / r²; so, per film of W·H light subpaths, the
    /// weight is 1/(A cos³θ r²) (Veach 1997, §10.2; Mitsuba's `importance`).
    fn sample_importance(&self, p: Vec3, u: Vec2, time: f32) -> Option<ImportanceSample> {
        let to_world = self.to_world.at(time);
        let q = to_world.inverse_point(p);
        if !(q.z >= self.near_clip && q.z <= self.far_clip) {
            return None;
        }
        let aperture = if self.lens_radius > 0.0 {
            let on_lens = sample_uniform_disk_concentric(u) * self.lens_radius;
            Vec3::new(on_lens.x, on_lens.y, 0.0)
        } else {
            Vec3::ZERO
        };
        let d = q - aperture;
        if !(d.z > 0.0) {
            return None;
        }
        // The pinhole direction (z = 1) of the focal-plane point on the line.
        let pinhole = if self.lens_radius > 0.0 {
            (aperture + d * (self.focus_distance / d.z)) / self.focus_distance
        } else {
            d / d.z
        };
        let aspect = self.film_size.x / self.film_size.y;
        let tan = self.tan_half_fov_x;
        let screen = Vec2::new(pinhole.x / tan, pinhole.y * aspect / tan);
        let film =
            film_position(screen, self.film_size)? - self.principal_point_offset * self.film_size;
        let lens = to_world.point(aperture);
        let towards = lens - p;
        let r2 = towards.length_squared();
        if !(r2 > 0.0) {
            return None;
        }
        let cos_theta = d.z / d.length();
        let area = 4.0 * tan * tan / aspect;
        Some(ImportanceSample {
            film,
            p: lens,
            wi: towards / r2.sqrt(),
            weight: 1.0 / (area * cos_theta * cos_theta * cos_theta * r2),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Transform;

    #[test]
    fn fov_conversions_match_mitsuba() {
        // Square film: every axis agrees.
        for axis in [FovAxis::X, FovAxis::Y, FovAxis::Smaller, FovAxis::Larger] {
            assert!((horizontal_fov(40.0, axis, 1.0) - 40.0).abs() < 1e-9);
        }
        // 2:1 film, vertical fov 30 degrees: tan(hx) = 2 tan(15 degrees).
        let expected = (2.0 * (2.0 * 15f64.to_radians().tan()).atan()).to_degrees();
        assert!((horizontal_fov(30.0, FovAxis::Y, 2.0) - expected).abs() < 1e-9);
        assert!((horizontal_fov(30.0, FovAxis::Smaller, 2.0) - expected).abs() < 1e-9);
        // The default 50 mm lens on a square film: 34.022 degrees (docs/mitsuba-compatibility.md,
        // Semantics that decide parity).
        let fov = horizontal_fov(focal_length_to_diagonal_fov(50.0), FovAxis::Diagonal, 1.0);
        assert!((fov - 34.022).abs() < 1e-3, "{fov}");
    }

    #[test]
    fn image_corners_map_to_the_left_top_of_the_camera() {
        let camera = PerspectiveCamera {
            to_world: AnimatedTransform::fixed(Transform::IDENTITY),
            film_size: Vec2::new(200.0, 100.0),
            tan_half_fov_x: 1.0,
            near_clip: 0.01,
            far_clip: 100.0,
            lens_radius: 0.0,
            focus_distance: 1.0,
            principal_point_offset: Vec2::ZERO,
        };
        let lens = Vec2::splat(0.5);
        let center = camera.generate_ray(Vec2::new(100.0, 50.0), lens, 0.0).ray;
        assert!((center.d - Vec3::Z).length() < 1e-6);
        let top_left = camera.generate_ray(Vec2::ZERO, lens, 0.0).ray;
        assert!(top_left.d.x > 0.0 && top_left.d.y > 0.0);
        // Horizontal half-angle 45 degrees; vertical half extent 0.5.
        let expected = Vec3::new(1.0, 0.5, 1.0).normalize();
        assert!((top_left.d - expected).length() < 1e-6);
        assert!((center.o - Vec3::new(0.0, 0.0, 0.01)).length() < 1e-7);
    }

    /// With a principal point offset, film position u sees what u + offset · size sees without
    /// it, and the connection of a point back to the camera lands where its ray left.
    #[test]
    fn principal_point_offset_shifts_the_film_both_ways() {
        let plain = PerspectiveCamera {
            to_world: AnimatedTransform::fixed(Transform::IDENTITY),
            film_size: Vec2::new(200.0, 100.0),
            tan_half_fov_x: 1.0,
            near_clip: 0.01,
            far_clip: 100.0,
            lens_radius: 0.0,
            focus_distance: 1.0,
            principal_point_offset: Vec2::ZERO,
        };
        let offset = Vec2::new(0.2, -0.15);
        let shifted = PerspectiveCamera {
            principal_point_offset: offset,
            ..plain.clone()
        };
        let lens = Vec2::splat(0.5);
        for film in [Vec2::new(10.0, 20.0), Vec2::new(150.0, 90.0)] {
            let ray = shifted.generate_ray(film, lens, 0.0).ray;
            let expected = plain
                .generate_ray(film + offset * plain.film_size, lens, 0.0)
                .ray;
            assert!((ray.d - expected.d).length() < 1e-6);
            let back = shifted.sample_importance(ray.at(3.0), lens, 0.0).unwrap();
            assert!(
                (back.film - film).length() < 1e-3,
                "{} vs {film}",
                back.film
            );
        }
    }

    /// Rays of one film position through different lens points meet on the focal plane.
    #[test]
    fn thin_lens_rays_converge_on_the_focal_plane() {
        let camera = PerspectiveCamera {
            to_world: AnimatedTransform::fixed(Transform::IDENTITY),
            film_size: Vec2::new(100.0, 100.0),
            tan_half_fov_x: 0.5,
            near_clip: 0.01,
            far_clip: 100.0,
            lens_radius: 0.2,
            focus_distance: 5.0,
            principal_point_offset: Vec2::ZERO,
        };
        let film = Vec2::new(30.0, 70.0);
        let points: Vec<Vec3> = [(0.1, 0.2), (0.9, 0.5), (0.5, 0.95)]
            .into_iter()
            .map(|(u, v)| {
                let ray = camera.generate_ray(film, Vec2::new(u, v), 0.0).ray;
                ray.at((5.0 - ray.o.z) / ray.d.z)
            })
            .collect();
        for p in &points[1..] {
            assert!((*p - points[0]).length() < 1e-4, "{p} vs {}", points[0]);
        }
    }
}
