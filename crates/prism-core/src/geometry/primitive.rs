//! The scene's primitives: shapes in world space and instances (shapes placed by a moving
//! transform), and the scene's [`Geometry`], the aggregate over them.

use glam::{Vec2, Vec3};

use super::aggregate::{Aggregate, AggregateElement, Hit};
use super::instance::Instance;
use super::interaction::SurfaceInteraction;
use super::shape::{Shape, ShapeGeometry, ShapeSampling, SurfaceSample, TriangleMesh};
use crate::math::Ray;

/// One primitive of the scene, dispatched by `match`.
#[derive(Clone, Debug)]
pub enum Primitive {
    /// A shape in world space.
    Shape(Shape),
    /// A shape that moves during the exposure, or a placed shape group.
    Instance(Instance),
}

/// The scene's primitives and the hierarchy over them.
pub type Geometry = Aggregate<Primitive>;

impl From<Shape> for Primitive {
    fn from(shape: Shape) -> Primitive {
        Primitive::Shape(shape)
    }
}

impl Primitive {
    pub fn area(&self) -> f32 {
        match self {
            Primitive::Shape(shape) => shape.area(),
            Primitive::Instance(instance) => instance.area(),
        }
    }

    /// A point uniformly distributed over the surface at `time`, with its density per unit
    /// area; None for a surface of zero area.
    #[inline]
    pub fn sample_area(&self, time: f32, u_choice: f32, u: Vec2) -> Option<SurfaceSample> {
        match self {
            Primitive::Shape(shape) => shape.sample_area(u_choice, u),
            Primitive::Instance(instance) => instance.sample_area(time, u_choice, u),
        }
    }

    /// A point of the surface as seen from `reference` at `time`, with its density per unit
    /// solid angle (see [`Shape::sample_from`]).
    #[inline]
    pub fn sample_from(
        &self,
        reference: Vec3,
        time: f32,
        u_choice: f32,
        u: Vec2,
        sampling: ShapeSampling,
    ) -> Option<SurfaceSample> {
        match self {
            Primitive::Shape(shape) => shape.sample_from(reference, u_choice, u, sampling),
            Primitive::Instance(instance) => {
                instance.sample_from(reference, time, u_choice, u, sampling)
            }
        }
    }

    /// Density of [`Self::sample_from`] for the surface point `p` with geometric normal `n`, per
    /// unit solid angle at `reference`, at `time`.
    #[inline]
    pub fn pdf_from(
        &self,
        reference: Vec3,
        time: f32,
        p: Vec3,
        n: Vec3,
        sampling: ShapeSampling,
    ) -> f32 {
        match self {
            Primitive::Shape(shape) => shape.pdf_from(reference, p, n, sampling),
            Primitive::Instance(instance) => instance.pdf_from(reference, time, p, n, sampling),
        }
    }
}

impl AggregateElement for Primitive {
    #[inline]
    fn mesh(&self) -> Option<&TriangleMesh> {
        match self {
            Primitive::Shape(shape) => shape.mesh(),
            Primitive::Instance(_) => None,
        }
    }

    fn bounds(&self) -> (Vec3, Vec3) {
        match self {
            Primitive::Shape(shape) => shape.object_bounds(),
            Primitive::Instance(instance) => instance.swept_bounds,
        }
    }

    #[inline]
    fn intersect_whole(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        match self {
            Primitive::Shape(shape) => shape.intersect_analytic(ray, t_max),
            Primitive::Instance(instance) => instance.intersect(ray, t_max),
        }
    }

    #[inline]
    fn interaction(&self, ray: &Ray, hit: &Hit) -> Option<SurfaceInteraction> {
        match self {
            Primitive::Shape(shape) => AggregateElement::interaction(shape, ray, hit),
            // The same query again, now keeping the object's interaction.
            Primitive::Instance(instance) => instance.interaction(ray, ray.t_max, hit.shape),
        }
    }

    fn part_count(&self) -> Option<usize> {
        match self {
            Primitive::Shape(shape) => ShapeGeometry::part_count(shape),
            Primitive::Instance(_) => None,
        }
    }

    fn part_bounds(&self, part: u32) -> (Vec3, Vec3) {
        match self {
            Primitive::Shape(shape) => ShapeGeometry::part_bounds(shape, part),
            Primitive::Instance(instance) => instance.swept_bounds,
        }
    }

    #[inline]
    fn intersect_part(&self, ray: &Ray, part: u32, t_max: f32) -> Option<f32> {
        match self {
            Primitive::Shape(shape) => ShapeGeometry::intersect_part(shape, ray, part, t_max),
            Primitive::Instance(instance) => instance.intersect(ray, t_max),
        }
    }

    fn heap_bytes(&self) -> usize {
        match self {
            Primitive::Shape(shape) => ShapeGeometry::heap_bytes(shape),
            // A group's object is shared by its instances and is not counted in any of them.
            Primitive::Instance(instance) if instance.first_shape.is_some() => 0,
            Primitive::Instance(instance) => instance.object.memory_bytes(),
        }
    }
}
