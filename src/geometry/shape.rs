//! The shapes a scene is made of, dispatched by `match` (DESIGN.md §3.1).

use glam::{Vec2, Vec3};

use super::disk::Disk;
use super::mesh::{SurfaceSample, TriangleMesh};
use super::sphere::{Sphere, area_to_solid_angle};

/// A shape of the scene.
#[derive(Clone, Debug)]
pub enum Shape {
    Mesh(TriangleMesh),
    Sphere(Sphere),
    Disk(Disk),
}

impl Shape {
    pub fn area(&self) -> f32 {
        match self {
            Shape::Mesh(mesh) => mesh.area(),
            Shape::Sphere(sphere) => sphere.area(),
            Shape::Disk(disk) => disk.area(),
        }
    }

    /// A point uniformly distributed over the surface, pdf per unit area; None for a shape of
    /// zero area. `u_choice` picks the triangle of a mesh.
    pub fn sample_area(&self, u_choice: f32, u: Vec2) -> Option<SurfaceSample> {
        match self {
            Shape::Mesh(mesh) => mesh.sample_area(u_choice, u),
            Shape::Sphere(sphere) => Some(sphere.sample_area(u)),
            Shape::Disk(disk) => Some(disk.sample_area(u)),
        }
    }

    /// A point of the surface as seen from `reference`, with its density per unit solid angle.
    /// Spheres sample the cone they subtend; other shapes sample their area uniformly.
    pub fn sample_from(&self, reference: Vec3, u_choice: f32, u: Vec2) -> Option<SurfaceSample> {
        match self {
            Shape::Sphere(sphere) => sphere.sample_from(reference, u),
            _ => {
                let s = self.sample_area(u_choice, u)?;
                let pdf = area_to_solid_angle(s.pdf, reference, s.p, s.n)?;
                Some(SurfaceSample { pdf, ..s })
            }
        }
    }

    /// Density of [`Self::sample_from`] for the surface point `p` with geometric normal `n`, per
    /// unit solid angle at `reference`.
    pub fn pdf_from(&self, reference: Vec3, p: Vec3, n: Vec3) -> f32 {
        match self {
            Shape::Sphere(sphere) => sphere.pdf_from(reference, p, n),
            _ => area_to_solid_angle(1.0 / self.area(), reference, p, n).unwrap_or(0.0),
        }
    }
}
