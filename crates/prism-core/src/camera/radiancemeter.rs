//! Mitsuba 3's `radiancemeter` sensor: the radiance arriving along one ray, the limit of a
//! perspective camera whose field of view tends to zero. The ray leaves the world image of the
//! sensor's origin along the world image of its +z axis (normalised), moved on by Mitsuba's ray
//! epsilon (89 · 2⁻²⁴) so that it cannot hit a surface it starts on, and is unbounded. The film
//! is a single pixel; the film, lens and (for a static sensor) time samples change nothing, so
//! every sample measures L along the same ray at its own wavelengths.
//!
//! ```xml
//! <sensor type="radiancemeter">
//!     <point name="origin" x="0" y="1" z="-3"/>
//!     <vector name="direction" x="0" y="0" z="1"/>
//!     <film type="hdrfilm"><integer name="width" value="1"/><integer name="height" value="1"/></film>
//! </sensor>
//! ```

use glam::{Vec2, Vec3};

use super::{CameraModel, CameraRay, ImportanceSample};
use crate::light::BoundingSphere;
use crate::math::{AnimatedTransform, Ray};

/// Mitsuba's `math::RayEpsilon<float>`: how far along its direction the ray starts.
pub(crate) const RAY_EPSILON: f32 = 89.0 / (1u32 << 24) as f32;

#[derive(Clone, Debug)]
pub struct RadianceMeter {
    /// Sensor to world (possibly moving over the shutter interval): the ray leaves its origin
    /// along its +z axis.
    pub to_world: AnimatedTransform,
}

impl CameraModel for RadianceMeter {
    #[inline]
    fn generate_ray(&self, _film: Vec2, _lens: Vec2, time: f32) -> CameraRay {
        let to_world = self.to_world.at(time);
        let d = to_world.vector(Vec3::Z).normalize();
        let o = to_world.point(Vec3::ZERO) + d * RAY_EPSILON;
        CameraRay::unweighted(Ray::new(o, d, f32::INFINITY, time))
    }

    fn set_scene_bounds(&mut self, _bounds: BoundingSphere) {}

    /// None: one ray from one point, a delta in position and direction, which no connection
    /// from a scene point can find.
    fn sample_importance(&self, _p: Vec3, _u: Vec2, _time: f32) -> Option<ImportanceSample> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Transform;
    use glam::DMat4;

    #[test]
    fn every_sample_is_the_same_ray() {
        // A sensor at (1, 2, 3) turned a quarter turn about y: +z maps to +x.
        let place = DMat4::from_translation(glam::DVec3::new(1.0, 2.0, 3.0))
            * DMat4::from_rotation_y(std::f64::consts::FRAC_PI_2);
        let meter = RadianceMeter {
            to_world: AnimatedTransform::fixed(Transform::new(place).unwrap()),
        };
        let a = meter
            .generate_ray(Vec2::new(0.1, 0.9), Vec2::new(0.3, 0.3), 0.0)
            .ray;
        let b = meter
            .generate_ray(Vec2::new(0.7, 0.2), Vec2::new(0.9, 0.1), 0.0)
            .ray;
        assert_eq!((a.o, a.d), (b.o, b.d));
        assert!(a.d.distance(Vec3::X) < 1e-6, "{}", a.d);
        assert!(a.o.distance(Vec3::new(1.0, 2.0, 3.0)) < 1e-4);
        assert_eq!(a.t_max, f32::INFINITY);
    }
}
