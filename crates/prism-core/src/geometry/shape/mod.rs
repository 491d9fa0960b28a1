//! The shapes a scene is made of: triangle meshes, spheres, disks, cylinders, linear and B-spline curves, in world space (or in the
//! object space of an [`super::instance::Instance`]), dispatched by `match` (DESIGN.md §3.1).
//! Shapes know their own intersection, surface points and sampling; the hierarchies over them
//! ([`super::aggregate`]) and the shapes placed by transforms ([`super::primitive`]) sit above.

pub mod bspline_curve;
pub mod cylinder;
pub mod disk;
pub mod linear_curve;
pub mod mesh;
pub mod sphere;
pub mod uv_grid;

use glam::{Vec2, Vec3};

pub use bspline_curve::BSplineCurve;
pub use cylinder::Cylinder;
pub use disk::Disk;
pub use linear_curve::LinearCurve;
pub use mesh::{MeshAttribute, SurfaceSample, TriangleMesh};
pub use sphere::{Sphere, area_to_solid_angle};

use crate::geometry::interaction::SurfaceInteraction;
use crate::geometry::triangle::TriangleHit;
use crate::math::Ray;

/// A shape of the scene.
#[derive(Clone, Debug)]
pub enum Shape {
    Mesh(TriangleMesh),
    Sphere(Sphere),
    Disk(Disk),
    Cylinder(Cylinder),
    /// Round linear curves; each segment is one primitive of the hierarchy.
    LinearCurve(LinearCurve),
    /// Round uniform cubic B-spline curves; each segment is one primitive of the hierarchy.
    BSplineCurve(BSplineCurve),
}

/// How an area light samples its shape from a reference point (the `area` emitter's
/// `sampling`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ShapeSampling {
    /// By the solid angle the shape subtends where Prism knows how (spheres: their cone;
    /// rectangles: the spherical rectangle, from within two diagonals), else by area.
    #[default]
    SolidAngle,
    /// Uniformly by area, every shape (the lecture's "Direct light sampling").
    Area,
}

impl Shape {
    pub fn area(&self) -> f32 {
        match self {
            Shape::Mesh(mesh) => mesh.area(),
            Shape::Sphere(sphere) => sphere.area(),
            Shape::Disk(disk) => disk.area(),
            Shape::Cylinder(cylinder) => cylinder.area(),
            // Mitsuba gives curves no area or sampling: they cannot be area lights.
            Shape::LinearCurve(_) | Shape::BSplineCurve(_) => 0.0,
        }
    }

    /// Bounds of the shape in its own coordinates.
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
            Shape::Cylinder(cylinder) => (0..8)
                .map(|corner| {
                    let bit = |b: u32| if corner & (1 << b) != 0 { 1.0 } else { 0.0 };
                    let x = 2.0 * bit(0) - 1.0;
                    let y = 2.0 * bit(1) - 1.0;
                    cylinder.to_world.point(Vec3::new(x, y, bit(2)))
                })
                .fold(
                    (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                    |(lo, hi), p| (lo.min(p), hi.max(p)),
                ),
            Shape::LinearCurve(curve) => curve.bounds(),
            Shape::BSplineCurve(curve) => curve.bounds(),
        }
    }

    /// The number of primitives a shape made of parts (curve segments) puts in the hierarchy,
    /// each intersected by [`Self::intersect_part`]; None for other shapes.
    pub fn part_count(&self) -> Option<usize> {
        match self {
            Shape::LinearCurve(curve) => Some(curve.segment_count()),
            Shape::BSplineCurve(curve) => Some(curve.segment_count()),
            _ => None,
        }
    }

    /// The bounds of part `part` of a shape made of parts; the whole shape's bounds otherwise.
    pub fn part_bounds(&self, part: u32) -> (Vec3, Vec3) {
        match self {
            Shape::LinearCurve(curve) => curve.segment_bounds(part as usize),
            Shape::BSplineCurve(curve) => curve.segment_bounds(part as usize),
            _ => self.object_bounds(),
        }
    }

    /// Distance to the nearest hit in (0, t_max) on part `part` of a shape made of parts; the
    /// same as [`Self::intersect_analytic`] for other shapes.
    pub fn intersect_part(&self, ray: &Ray, part: u32, t_max: f32) -> Option<f32> {
        match self {
            Shape::LinearCurve(curve) => curve
                .intersect_segment(part as usize, ray.o, ray.d, t_max)
                .map(|hit| hit.t),
            Shape::BSplineCurve(curve) => curve
                .intersect_segment(part as usize, ray.o, ray.d, t_max)
                .map(|hit| hit.t),
            _ => self.intersect_analytic(ray, t_max),
        }
    }

    /// Distance to the nearest hit in (0, t_max) of an analytic shape (sphere, disk); None for
    /// meshes, whose triangles are intersected one by one by the hierarchy.
    pub fn intersect_analytic(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        match self {
            Shape::Sphere(sphere) => sphere.intersect(ray.o, ray.d, t_max),
            Shape::Disk(disk) => disk.intersect(ray.o, ray.d, t_max),
            Shape::Cylinder(cylinder) => cylinder.intersect(ray.o, ray.d, t_max),
            Shape::LinearCurve(curve) => curve.intersect(ray.o, ray.d, t_max).map(|(_, h)| h.t),
            Shape::BSplineCurve(curve) => curve.intersect(ray.o, ray.d, t_max).map(|(_, h)| h.t),
            Shape::Mesh(_) => None,
        }
    }

    /// The surface interaction of a hit found by the hierarchy: for a mesh, at triangle
    /// `primitive` with the hit's barycentrics; for an analytic shape, at distance `hit.t`.
    /// Recorded as shape `index`.
    #[inline]
    pub fn interaction(
        &self,
        ray: &Ray,
        primitive: u32,
        hit: &TriangleHit,
        index: u32,
    ) -> SurfaceInteraction {
        match self {
            Shape::Mesh(mesh) => mesh.interaction(primitive as usize, hit, index),
            Shape::Sphere(sphere) => sphere.interaction(ray.o, ray.d, hit.t, index),
            Shape::Disk(disk) => disk.interaction(ray.o, ray.d, hit.t, index),
            Shape::Cylinder(cylinder) => cylinder.interaction(ray.o, ray.d, hit.t, index),
            Shape::LinearCurve(curve) => {
                // A structure that intersects the curve as a whole (Embree's, through
                // `intersect_analytic`) does not name the segment: find it again.
                let named = curve
                    .intersect_segment(primitive as usize, ray.o, ray.d, f32::INFINITY)
                    .is_some_and(|h| h.t == hit.t);
                let segment = if named {
                    primitive
                } else {
                    curve
                        .intersect(ray.o, ray.d, f32::INFINITY)
                        .map_or(primitive, |(segment, _)| segment as u32)
                };
                curve.interaction(ray.o, ray.d, hit.t, segment, index)
            }
            // Finds its segment again itself when the named one was not hit.
            Shape::BSplineCurve(curve) => curve.interaction(ray.o, ray.d, hit.t, primitive, index),
        }
    }

    /// A point uniformly distributed over the surface, pdf per unit area; None for a shape of
    /// zero area. `u_choice` picks the triangle of a mesh.
    pub fn sample_area(&self, u_choice: f32, u: Vec2) -> Option<SurfaceSample> {
        match self {
            Shape::Mesh(mesh) => mesh.sample_area(u_choice, u),
            Shape::Sphere(sphere) => Some(sphere.sample_area(u)),
            Shape::Disk(disk) => Some(disk.sample_area(u)),
            Shape::Cylinder(cylinder) => Some(cylinder.sample_area(u)),
            Shape::LinearCurve(_) | Shape::BSplineCurve(_) => None,
        }
    }

    /// A point of the surface as seen from `reference`, with its density per unit solid angle.
    /// By [`ShapeSampling::SolidAngle`], spheres sample the cone they subtend and rectangles
    /// the spherical rectangle; other shapes, and every shape by [`ShapeSampling::Area`],
    /// sample their area uniformly.
    pub fn sample_from(
        &self,
        reference: Vec3,
        u_choice: f32,
        u: Vec2,
        sampling: ShapeSampling,
    ) -> Option<SurfaceSample> {
        if sampling == ShapeSampling::SolidAngle {
            match self {
                Shape::Sphere(sphere) => return sphere.sample_from(reference, u),
                Shape::Mesh(mesh) => {
                    if let Some(s) = mesh.sample_by_solid_angle(reference, u) {
                        return Some(s);
                    }
                }
                _ => {}
            }
        }
        let s = self.sample_area(u_choice, u)?;
        let pdf = area_to_solid_angle(s.pdf, reference, s.p, s.n)?;
        Some(SurfaceSample { pdf, ..s })
    }

    /// Density of [`Self::sample_from`] for the surface point `p` with geometric normal `n`, per
    /// unit solid angle at `reference`.
    pub fn pdf_from(&self, reference: Vec3, p: Vec3, n: Vec3, sampling: ShapeSampling) -> f32 {
        if sampling == ShapeSampling::SolidAngle {
            match self {
                Shape::Sphere(sphere) => return sphere.pdf_from(reference, p, n),
                Shape::Mesh(mesh) => {
                    if let Some(pdf) = mesh.solid_angle_pdf(reference) {
                        return pdf;
                    }
                }
                _ => {}
            }
        }
        match self {
            Shape::LinearCurve(_) | Shape::BSplineCurve(_) => 0.0,
            _ => area_to_solid_angle(1.0 / self.area(), reference, p, n).unwrap_or(0.0),
        }
    }

    /// The surface point with texture coordinates `uv` in [0, 1]² (Mitsuba's
    /// `eval_parameterization`) and |∂p/∂u × ∂p/∂v| there, the area per unit uv area; None
    /// where the uv map does not reach `uv`. A point several mesh triangles share in uv space
    /// lies on the lowest-numbered of them. The sample's pdf is 0.
    pub fn at_uv(&self, uv: Vec2) -> Option<(SurfaceSample, f32)> {
        match self {
            Shape::Mesh(mesh) => mesh.at_uv(uv),
            Shape::Sphere(sphere) => sphere.at_uv(uv),
            Shape::Disk(disk) => disk.at_uv(uv),
            Shape::Cylinder(cylinder) => cylinder.at_uv(uv),
            Shape::LinearCurve(_) | Shape::BSplineCurve(_) => None,
        }
    }

    /// |∂p/∂u × ∂p/∂v| at the point with texture coordinates `uv` on triangle `primitive` (0 for
    /// a sphere or disk), if [`Self::at_uv`] maps `uv` to that point; None otherwise.
    pub fn uv_jacobian_at(&self, primitive: u32, uv: Vec2) -> Option<f32> {
        match self {
            Shape::Mesh(mesh) => {
                let triangle = mesh.triangle_at_uv(uv)?;
                if triangle != primitive as usize {
                    return None;
                }
                mesh.uv_jacobian(triangle)
            }
            Shape::Sphere(sphere) => sphere.at_uv(uv).map(|(_, j)| j),
            Shape::Disk(disk) => disk.at_uv(uv).map(|(_, j)| j),
            Shape::Cylinder(cylinder) => cylinder.at_uv(uv).map(|(_, j)| j),
            Shape::LinearCurve(_) | Shape::BSplineCurve(_) => None,
        }
    }

    /// Bytes of heap memory the shape holds (a mesh's vertex attributes and indices).
    pub fn heap_bytes(&self) -> usize {
        match self {
            Shape::Mesh(mesh) => mesh.heap_bytes(),
            Shape::LinearCurve(curve) => curve.heap_bytes(),
            Shape::BSplineCurve(curve) => curve.heap_bytes(),
            Shape::Sphere(_) | Shape::Disk(_) | Shape::Cylinder(_) => 0,
        }
    }
}
