//! Mitsuba 3's `irradiancemeter` sensor: the irradiance on a shape, the power per unit area
//! arriving at its surface from the side its normals point to, averaged over the surface.
//!
//! ```xml
//! <shape type="rectangle">
//!     <sensor type="irradiancemeter">
//!         <film type="hdrfilm">
//!             <integer name="width" value="1"/><integer name="height" value="1"/>
//!             <rfilter type="box"/>
//!         </film>
//!     </sensor>
//! </shape>
//! ```
//!
//! As Mitsuba 3's `irradiancemeter.cpp` draws it, each sample takes a point p uniformly by area
//! on the shape from the film sample ([`Shape::sample_position`]) and a direction ω from the
//! lens sample, cosine-weighted about the shading normal n there (density cos θ / π), and
//! measures the radiance arriving along the ray from p towards ω with weight π:
//!
//! E = (1/A) ∫_A ∫_{H²(n)} L(p, ω) cos θ dω dA, estimated by π L(p, ω).
//!
//! The position sample is the film position over the film's size (Mitsuba's sample of the
//! whole film), uniform over [0, 1)² with a box filter, which the irradiance meter's film
//! always has. Mitsuba uses it with a film of one pixel; on a larger film each pixel averages
//! the part of the shape its positions reach. The ray leaves from p moved off the surface by Prism's
//! robust offset ([`crate::geometry::offset`]) rather than Mitsuba's fixed ray epsilon, so that
//! grazing rays do not hit the shape itself. The shape is part of the scene like any other
//! (its BSDF reflects light onto the rest of it).

use std::f32::consts::PI;
use std::sync::Arc;

use glam::{Vec2, Vec3};

use super::{CameraModel, CameraRay, ImportanceSample};
use crate::geometry::Shape;
use crate::geometry::offset::offset_ray_origin;
use crate::light::BoundingSphere;
use crate::math::{Frame, Ray};
use crate::sampling::warp::sample_cosine_hemisphere;

#[derive(Clone, Debug)]
pub struct IrradianceMeter {
    /// The shape measured on, in world space.
    pub shape: Arc<Shape>,
    /// The size of the film in pixels.
    pub film_size: Vec2,
}

impl CameraModel for IrradianceMeter {
    /// The film position `film` over the film's size is the position sample; `lens` picks the
    /// direction.
    #[inline]
    fn generate_ray(&self, film: Vec2, lens: Vec2, time: f32) -> CameraRay {
        let u = (film / self.film_size).clamp(Vec2::ZERO, Vec2::splat(1.0f32.next_down()));
        let Some(s) = self.shape.sample_position(u) else {
            return CameraRay {
                ray: Ray::new(Vec3::ZERO, Vec3::Z, 0.0, time),
                weight: 0.0,
            };
        };
        let d = Frame::from_normal(s.shading_n).to_world(sample_cosine_hemisphere(lens));
        let side = if s.n.dot(d) < 0.0 { -s.n } else { s.n };
        CameraRay {
            ray: Ray::new(offset_ray_origin(s.p, side), d, f32::INFINITY, time),
            weight: PI,
        }
    }

    fn set_scene_bounds(&mut self, _bounds: BoundingSphere) {}

    /// None: the meter is not connected to; the particle tracer refuses it.
    fn sample_importance(&self, _p: Vec3, _u: Vec2, _time: f32) -> Option<ImportanceSample> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Sphere;

    /// Every ray leaves the surface of a unit sphere outwards, with weight π.
    #[test]
    fn rays_leave_the_sphere_outwards() {
        let meter = IrradianceMeter {
            shape: Arc::new(Shape::Sphere(Sphere {
                center: Vec3::new(1.0, 2.0, 3.0),
                radius: 1.0,
                rotation: glam::Mat3::IDENTITY,
                flip_normals: false,
            })),
            film_size: Vec2::ONE,
        };
        for i in 0..64 {
            let u = |k: u32| ((i * 37 + k * 11) % 64) as f32 / 64.0 + 1.0 / 128.0;
            let sample = meter.generate_ray(Vec2::new(u(0), u(1)), Vec2::new(u(2), u(3)), 0.0);
            let n = sample.ray.o - Vec3::new(1.0, 2.0, 3.0);
            assert!((n.length() - 1.0).abs() < 1e-4, "{n}");
            assert!(n.dot(sample.ray.d) > 0.0);
            assert_eq!(sample.weight, PI);
        }
    }
}
