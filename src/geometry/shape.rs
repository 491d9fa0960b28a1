//! The shapes a scene is made of, dispatched by `match` (DESIGN.md §3.1).

use glam::{Vec2, Vec3};

use super::disk::Disk;
use super::instance::Instance;
use super::mesh::{SurfaceSample, TriangleMesh};
use super::sphere::{Sphere, area_to_solid_angle};
use crate::math::Ray;

/// A shape of the scene.
#[derive(Clone, Debug)]
pub enum Shape {
    Mesh(TriangleMesh),
    Sphere(Sphere),
    Disk(Disk),
    /// A shape that moves during the exposure.
    Instance(Instance),
}

impl Shape {
    pub fn area(&self) -> f32 {
        match self {
            Shape::Mesh(mesh) => mesh.area(),
            Shape::Sphere(sphere) => sphere.area(),
            Shape::Disk(disk) => disk.area(),
            Shape::Instance(instance) => instance.area(),
        }
    }

    /// Bounds of the shape in its own coordinates (for a moving shape: its sweep).
    pub fn object_bounds(&self) -> (Vec3, Vec3) {
        match self {
            Shape::Mesh(mesh) => mesh.positions().iter().fold(
                (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                |(lo, hi), &p| (lo.min(p), hi.max(p)),
            ),
            Shape::Sphere(sphere) => (sphere.center - sphere.radius, sphere.center + sphere.radius),
            Shape::Disk(disk) => [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                .into_iter()
                .map(|(x, y)| disk.to_world.point(Vec3::new(x, y, 0.0)))
                .fold(
                    (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                    |(lo, hi), p| (lo.min(p), hi.max(p)),
                ),
            Shape::Instance(instance) => instance.swept_bounds,
        }
    }

    /// Distance to the nearest hit in (0, t_max) of an analytic shape (sphere, disk, moving
    /// shape); None for meshes, whose triangles are intersected one by one by the hierarchy.
    pub fn intersect_analytic(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        match self {
            Shape::Sphere(sphere) => sphere.intersect(ray.o, ray.d, t_max),
            Shape::Disk(disk) => disk.intersect(ray.o, ray.d, t_max),
            Shape::Instance(instance) => instance.intersect(ray, t_max),
            Shape::Mesh(_) => None,
        }
    }

    /// A point uniformly distributed over the surface, pdf per unit area; None for a shape of
    /// zero area (and for moving shapes, which are sampled by [`Self::sample_from`] at a time).
    /// `u_choice` picks the triangle of a mesh.
    pub fn sample_area(&self, u_choice: f32, u: Vec2) -> Option<SurfaceSample> {
        match self {
            Shape::Mesh(mesh) => mesh.sample_area(u_choice, u),
            Shape::Sphere(sphere) => Some(sphere.sample_area(u)),
            Shape::Disk(disk) => Some(disk.sample_area(u)),
            Shape::Instance(_) => None,
        }
    }

    /// A point of the surface as seen from `reference` at `time`, with its density per unit
    /// solid angle. Spheres sample the cone they subtend; other shapes sample their area
    /// uniformly.
    pub fn sample_from(
        &self,
        reference: Vec3,
        time: f32,
        u_choice: f32,
        u: Vec2,
    ) -> Option<SurfaceSample> {
        match self {
            Shape::Sphere(sphere) => sphere.sample_from(reference, u),
            Shape::Instance(instance) => instance.sample_from(reference, time, u_choice, u),
            _ => {
                let s = self.sample_area(u_choice, u)?;
                let pdf = area_to_solid_angle(s.pdf, reference, s.p, s.n)?;
                Some(SurfaceSample { pdf, ..s })
            }
        }
    }

    /// Density of [`Self::sample_from`] for the surface point `p` with geometric normal `n`, per
    /// unit solid angle at `reference`, at `time`.
    pub fn pdf_from(&self, reference: Vec3, time: f32, p: Vec3, n: Vec3) -> f32 {
        match self {
            Shape::Sphere(sphere) => sphere.pdf_from(reference, p, n),
            Shape::Instance(instance) => instance.pdf_from(reference, time, p, n),
            _ => area_to_solid_angle(1.0 / self.area(), reference, p, n).unwrap_or(0.0),
        }
    }
}
