//! Instances: shapes in their own object space, with their own hierarchy, placed in the world by
//! a transform that may change while the shutter is open (motion blur).
//!
//! Rays are brought into object space at their time, intersected with the object's hierarchy
//! and the hit is carried back to the world; the scene's BVH holds the instance as a single
//! primitive bounded by its sweep over the animation, so that the scene's hierarchy is a BVH
//! over instances above each object's own BVH (two levels, as in pbrt-v4's
//! `TransformedPrimitive` and Mitsuba's `instance`). An instance is either one moving shape
//! (shapes whose transform does not change are baked into world space instead, so static
//! geometry pays nothing for motion blur) or a placement of a shape group (Mitsuba's
//! `shapegroup`), whose shapes and hierarchy every instance of it shares.

use std::sync::Arc;

use glam::{Vec2, Vec3};

use super::aggregate::Aggregate;
use super::interaction::SurfaceInteraction;
use super::shape::{Shape, ShapeGeometry, ShapeSampling, SurfaceSample};
use crate::math::{AnimatedTransform, Frame, Ray};

/// A shape, or a group of shapes, placed by an animated transform.
#[derive(Clone, Debug)]
pub struct Instance {
    /// The shapes in object space, in their own hierarchy, shared by the instances of a group.
    pub object: Arc<Aggregate<Shape>>,
    pub to_world: AnimatedTransform,
    /// World-space bounds of the object over the whole animation.
    pub swept_bounds: (Vec3, Vec3),
    /// How hits are recorded: for one moving shape, as the instance's own primitive; for a
    /// group, as shape `first_shape + k` for the group's k-th shape (a group's shapes take
    /// consecutive shape ids after the scene's primitives, so that each has its material).
    pub first_shape: Option<u32>,
}

impl Instance {
    /// One shape that moves during the exposure.
    pub fn new(shape: Shape, to_world: AnimatedTransform) -> Instance {
        Self::place(Arc::new(Aggregate::new(vec![shape])), to_world, None)
    }

    /// A placement of a shape group whose shapes are known as shapes `first_shape..`.
    pub fn of_group(
        object: Arc<Aggregate<Shape>>,
        to_world: AnimatedTransform,
        first_shape: u32,
    ) -> Instance {
        Self::place(object, to_world, Some(first_shape))
    }

    fn place(
        object: Arc<Aggregate<Shape>>,
        to_world: AnimatedTransform,
        first_shape: Option<u32>,
    ) -> Instance {
        let (lo, hi) = object.bounds().unwrap_or((Vec3::ZERO, Vec3::ZERO));
        let times: Vec<f32> = to_world.key_times().collect();
        let (t0, t1) = (times[0], times[times.len() - 1]);
        let swept_bounds = to_world.swept_bounds(lo, hi, t0, t1);
        Instance {
            object,
            to_world,
            swept_bounds,
            first_shape,
        }
    }

    /// The object's first (for a moving shape, only) shape.
    pub fn shape(&self) -> &Shape {
        &self.object.primitives[0]
    }

    fn local_ray(&self, ray: &Ray) -> Ray {
        let transform = self.to_world.at(ray.time);
        Ray::new(
            transform.inverse_point(ray.o),
            transform.inverse_vector(ray.d),
            ray.t_max,
            ray.time,
        )
    }

    /// Distance to the nearest hit in (0, t_max); t is the same in both spaces (affine map).
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        let local = Ray {
            t_max,
            ..self.local_ray(ray)
        };
        self.object.closest_hit(&local).map(|hit| hit.triangle.t)
    }

    /// The world-space interaction of the nearest hit, recorded as shape `shape` (the instance's
    /// primitive) or as its group's shape.
    pub fn interaction(&self, ray: &Ray, t_max: f32, shape: u32) -> Option<SurfaceInteraction> {
        let local = Ray {
            t_max,
            ..self.local_ray(ray)
        };
        let si = self.object.intersect(&local)?;
        let transform = self.to_world.at(ray.time);
        let shading_n = transform.normal(si.shading.n).normalize();
        Some(SurfaceInteraction {
            p: transform.point(si.p),
            n: transform.normal(si.n).normalize(),
            shading: Frame::from_normal_and_tangent(shading_n, transform.vector(si.shading.s)),
            dp_du: transform.vector(si.dp_du),
            dp_dv: transform.vector(si.dp_dv),
            shape: self.first_shape.map_or(shape, |first| first + si.shape),
            ..si
        })
    }

    /// A point uniformly distributed over the surface at `time`, density per unit area: the
    /// object-space density over the squared scale of the similarity that carries the shape
    /// (the factory only lets such transforms carry emitters).
    pub fn sample_area(&self, time: f32, u_choice: f32, u: Vec2) -> Option<SurfaceSample> {
        let transform = self.to_world.at(time);
        let scale = self.to_world.uniform_scale(time);
        let s = self.shape().sample_area(u_choice, u)?;
        Some(SurfaceSample {
            p: transform.point(s.p),
            n: transform.normal(s.n).normalize(),
            shading_n: transform.normal(s.shading_n).normalize(),
            pdf: s.pdf / (scale * scale),
            ..s
        })
    }

    /// A point of the surface at `time` seen from `reference`, density per unit solid angle. The
    /// density is the object-space one, which is correct for similarities (solid angles do not
    /// change under rotation, translation and uniform scale); the factory only lets such
    /// transforms carry emitters.
    pub fn sample_from(
        &self,
        reference: Vec3,
        time: f32,
        u_choice: f32,
        u: Vec2,
        sampling: ShapeSampling,
    ) -> Option<SurfaceSample> {
        let transform = self.to_world.at(time);
        let s =
            self.shape()
                .sample_from(transform.inverse_point(reference), u_choice, u, sampling)?;
        Some(SurfaceSample {
            p: transform.point(s.p),
            n: transform.normal(s.n).normalize(),
            shading_n: transform.normal(s.shading_n).normalize(),
            uv: s.uv,
            primitive: s.primitive,
            pdf: s.pdf,
        })
    }

    /// Density of [`Self::sample_from`] for the world point `p` with normal `n`.
    pub fn pdf_from(
        &self,
        reference: Vec3,
        time: f32,
        p: Vec3,
        n: Vec3,
        sampling: ShapeSampling,
    ) -> f32 {
        let transform = self.to_world.at(time);
        // n = normalize(M⁻ᵀ n_object), so n_object ∝ Mᵀ n.
        let local_n = Vec3::new(
            transform.matrix.x_axis.truncate().dot(n),
            transform.matrix.y_axis.truncate().dot(n),
            transform.matrix.z_axis.truncate().dot(n),
        )
        .normalize_or(n);
        self.shape().pdf_from(
            transform.inverse_point(reference),
            transform.inverse_point(p),
            local_n,
            sampling,
        )
    }

    /// Surface area at the first key (constant for similarities without scale animation).
    pub fn area(&self) -> f32 {
        let scale = self
            .to_world
            .uniform_scale(self.to_world.key_times().next().unwrap_or(0.0));
        self.shape().area() * scale * scale
    }
}
