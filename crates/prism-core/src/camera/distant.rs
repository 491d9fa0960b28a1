//! Mitsuba 3's `distant` sensor: the radiance leaving the scene in one direction, averaged over
//! a target, the adjoint of the `directional` emitter.
//!
//! ```xml
//! <sensor type="distant">
//!     <vector name="direction" x="0" y="0" z="-1"/>   <!-- or a to_world: its +z axis -->
//!     <point name="target" x="0" y="0" z="0"/>        <!-- or a nested <shape name="target"> -->
//!     <film type="hdrfilm"><integer name="width" value="1"/><integer name="height" value="1"/></film>
//! </sensor>
//! ```
//!
//! Every ray travels along d, the world image of the sensor's +z axis (normalised), so the
//! sensor records the radiance L(x, −d) leaving the scene towards −d. With (c, R) the bounding
//! sphere of the scene's geometry, the ray starts, as in Mitsuba 3's `distant.cpp`:
//! - with a target point t: at t − 2Rd, every ray the same;
//! - with a target shape: at p − 2Rd, p uniform by area on the shape
//!   ([`Shape::sample_position`] of the lens sample), weight 1/(pdf · area) = 1, so that the
//!   measurement is the radiance averaged over the shape's area (the shape is only aimed at:
//!   it is not part of the scene);
//! - with no target: at c + R·(x·s + y·t) − R·d, (x, y) uniform on the unit disk (concentric
//!   map of the lens sample) and s, t the images of the sensor's x and y axes, so that the
//!   measurement is the radiance averaged over the cross-section of the bounding sphere (rays
//!   that miss the geometry see the environment, or nothing).
//!
//! The rays are unbounded; the film is one pixel.

use std::sync::Arc;

use glam::{Vec2, Vec3};

use super::{CameraModel, CameraRay, ImportanceSample};
use crate::geometry::Shape;
use crate::light::BoundingSphere;
use crate::math::{Ray, Transform};
use crate::sampling::warp::sample_uniform_disk_concentric;

/// What a distant sensor's rays aim at.
#[derive(Clone, Debug)]
pub enum DistantTarget {
    /// The cross-section of the scene's bounding sphere.
    Scene,
    /// One point.
    Point(Vec3),
    /// A shape in world space, sampled uniformly by area.
    Shape(Arc<Shape>),
}

#[derive(Clone, Debug)]
pub struct DistantSensor {
    /// Sensor to world: the rays travel along its +z axis.
    pub to_world: Transform,
    pub target: DistantTarget,
    /// The bounding sphere of the scene's geometry, set once the scene is built.
    pub scene: BoundingSphere,
}

impl DistantSensor {
    /// A sensor whose scene bounds are not yet known.
    pub fn new(to_world: Transform, target: DistantTarget) -> DistantSensor {
        DistantSensor {
            to_world,
            target,
            scene: BoundingSphere::default(),
        }
    }
}

impl CameraModel for DistantSensor {
    /// The film position is unused; `lens` places the ray on its target.
    #[inline]
    fn generate_ray(&self, _film: Vec2, lens: Vec2, time: f32) -> CameraRay {
        let d = self.to_world.vector(Vec3::Z).normalize();
        let radius = self.scene.radius;
        let o = match &self.target {
            DistantTarget::Point(target) => *target - 2.0 * radius * d,
            DistantTarget::Shape(shape) => match shape.sample_position(lens) {
                Some(s) => s.p - 2.0 * radius * d,
                None => {
                    return CameraRay {
                        ray: Ray::new(Vec3::ZERO, d, 0.0, time),
                        weight: 0.0,
                    };
                }
            },
            DistantTarget::Scene => {
                let offset = sample_uniform_disk_concentric(lens);
                let across = self.to_world.vector(Vec3::new(offset.x, offset.y, 0.0));
                self.scene.center + radius * (across - d)
            }
        };
        CameraRay::unweighted(Ray::new(o, d, f32::INFINITY, time))
    }

    fn set_scene_bounds(&mut self, bounds: BoundingSphere) {
        self.scene = bounds;
    }

    /// None: rays of one direction, a delta, which no connection from a scene point can find.
    fn sample_importance(&self, _p: Vec3, _u: Vec2, _time: f32) -> Option<ImportanceSample> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DMat4;

    /// Without a target, ray origins cover the disk of radius R through the centre across d,
    /// pushed back by R along d.
    #[test]
    fn scene_target_covers_the_cross_section() {
        let turn = DMat4::from_rotation_x(std::f64::consts::FRAC_PI_2);
        let mut sensor = DistantSensor::new(Transform::new(turn).unwrap(), DistantTarget::Scene);
        sensor.set_scene_bounds(BoundingSphere {
            center: Vec3::new(1.0, 2.0, 3.0),
            radius: 2.0,
        });
        let d = Vec3::new(0.0, -1.0, 0.0);
        for (u, expected) in [
            (Vec2::splat(0.5), Vec3::new(1.0, 4.0, 3.0)),
            (Vec2::new(1.0, 0.5), Vec3::new(3.0, 4.0, 3.0)),
        ] {
            let ray = sensor.generate_ray(Vec2::ZERO, u, 0.0).ray;
            assert!(ray.d.distance(d) < 1e-6, "{}", ray.d);
            assert!(ray.o.distance(expected) < 1e-5, "{u}: {}", ray.o);
        }
    }
}
