//! The shapes a scene is made of: triangle meshes, spheres, disks, cylinders, linear and B-spline curves, ellipsoids, SDF grids, in world space (or in the
//! object space of an [`super::instance::Instance`]). Every shape answers the
//! [`ShapeGeometry`] interface, and the enum [`Shape`] dispatches to it by an exhaustive `match`
//! ([`crate::dispatch`]).
//! Shapes know their own intersection, surface points and sampling; the hierarchies over them
//! ([`super::aggregate`]) and the shapes placed by transforms ([`super::primitive`]) sit above.

pub mod bspline_curve;
pub mod curve;
pub mod cylinder;
pub mod disk;
pub mod ellipsoids;
pub mod linear_curve;
pub mod mesh;
pub mod sdf_grid;
pub mod sphere;
pub mod uv_grid;

use glam::{Vec2, Vec3};

pub use bspline_curve::BSplineCurve;
pub use curve::Curve;
pub use cylinder::Cylinder;
pub use disk::Disk;
pub use ellipsoids::{Ellipsoid, Ellipsoids};
pub use linear_curve::LinearCurve;
pub use mesh::{MeshAttribute, RectangleView, SurfaceSample, TriangleMesh};
pub use sdf_grid::{SdfGrid, SdfNormals};
pub use sphere::{Sphere, SphereCone, area_to_solid_angle};

use crate::dispatch::plugin_class;
use crate::geometry::interaction::SurfaceInteraction;
use crate::geometry::triangle::TriangleHit;
use crate::math::Ray;

plugin_class! {
    /// What every shape answers: its extent, its intersection and surface points, and how it is
    /// sampled as an area light.
    pub trait ShapeGeometry {
        /// The surface area (0 for curves, which Mitsuba gives no area: they cannot emit).
        fn area(&self) -> f32;

        /// Bounds of the shape in its own coordinates.
        fn object_bounds(&self) -> (Vec3, Vec3);

        /// The segments of a shape made of them (curves), each a primitive of the hierarchy;
        /// None for shapes that enter it whole (or, meshes, triangle by triangle).
        fn as_segments(&self) -> Option<Segments<'_>>;

        /// Distance to the nearest hit in (0, t_max) of the shape as a whole; None for meshes,
        /// whose triangles are intersected one by one by the hierarchy.
        fn intersect_analytic(&self, ray: &Ray, t_max: f32) -> Option<f32>;

        /// The surface interaction of a hit found by the hierarchy: for a mesh, at triangle
        /// `primitive` with the hit's barycentrics; for a curve, on segment `primitive`; for
        /// other shapes, at distance `hit.t`. Recorded as shape `index`.
        fn interaction(
            &self,
            ray: &Ray,
            primitive: u32,
            hit: &TriangleHit,
            index: u32,
        ) -> SurfaceInteraction;

        /// A point uniformly distributed over the surface, pdf per unit area; None for a shape
        /// of zero area. `u_choice` picks the triangle of a mesh. By default None: a shape
        /// that cannot be sampled (curves, ellipsoids, SDF grids) cannot be an area light.
        fn sample_area(&self, u_choice: f32, u: Vec2) -> Option<SurfaceSample> {
            let _ = (u_choice, u);
            None
        }

        /// How the shape is sampled by the solid angle it subtends at `reference`, where it
        /// has a way (spheres from outside: their cone; rectangles from near by: the spherical
        /// rectangle); None, the default, where it is sampled by area. The one choice that
        /// [`Self::sample_from`] and [`Self::pdf_from`] both follow.
        fn solid_angle_sampler(&self, reference: Vec3) -> Option<SolidAngleSampler<'_>> {
            let _ = reference;
            None
        }

        /// The surface point with texture coordinates `uv` in [0, 1]² (Mitsuba's
        /// `eval_parameterization`) and |∂p/∂u × ∂p/∂v| there, the area per unit uv area;
        /// None where the uv map does not reach `uv`. A point several mesh triangles share in
        /// uv space lies on the lowest-numbered of them. The sample's pdf is 0. By default
        /// None: a shape without a uv map (curves, ellipsoids, SDF grids) reaches no `uv`.
        fn at_uv(&self, uv: Vec2) -> Option<(SurfaceSample, f32)> {
            let _ = uv;
            None
        }

        /// |∂p/∂u × ∂p/∂v| at the point with texture coordinates `uv` on triangle `primitive`
        /// (0 for other shapes), if [`Self::at_uv`] maps `uv` to that point; None otherwise,
        /// and by default, with the default [`Self::at_uv`].
        fn uv_jacobian_at(&self, primitive: u32, uv: Vec2) -> Option<f32> {
            let _ = (primitive, uv);
            None
        }

        /// Bytes of heap memory the shape holds (a mesh's vertex attributes and indices).
        fn heap_bytes(&self) -> usize;

        /// The number of segments a shape made of them puts in the hierarchy, each
        /// intersected by [`Self::intersect_part`]; None for other shapes.
        fn part_count(&self) -> Option<usize> {
            self.as_segments().map(|segments| segments.count())
        }

        /// The bounds of segment `part` of a shape made of them; the whole shape's otherwise.
        fn part_bounds(&self, part: u32) -> (Vec3, Vec3) {
            match self.as_segments() {
                Some(segments) => segments.bounds(part),
                None => self.object_bounds(),
            }
        }

        /// Distance to the nearest hit in (0, t_max) on segment `part` of a shape made of
        /// them; the same as [`Self::intersect_analytic`] for other shapes.
        fn intersect_part(&self, ray: &Ray, part: u32, t_max: f32) -> Option<f32> {
            match self.as_segments() {
                Some(segments) => segments.intersect(part, ray, t_max),
                None => self.intersect_analytic(ray, t_max),
            }
        }

        /// A point of the surface as seen from `reference`, with its density per unit solid
        /// angle: by [`ShapeSampling::SolidAngle`] through [`Self::solid_angle_sampler`] where
        /// the shape has one, otherwise (and always by [`ShapeSampling::Area`]) uniformly by
        /// area.
        fn sample_from(
            &self,
            reference: Vec3,
            u_choice: f32,
            u: Vec2,
            sampling: ShapeSampling,
        ) -> Option<SurfaceSample> {
            if sampling == ShapeSampling::SolidAngle
                && let Some(sampler) = self.solid_angle_sampler(reference)
            {
                return sampler.sample(u);
            }
            let s = self.sample_area(u_choice, u)?;
            let pdf = area_to_solid_angle(s.pdf, reference, s.p, s.n)?;
            Some(SurfaceSample { pdf, ..s })
        }

        /// Density of [`Self::sample_from`] for the surface point `p` with geometric normal
        /// `n`, per unit solid angle at `reference`.
        fn pdf_from(&self, reference: Vec3, p: Vec3, n: Vec3, sampling: ShapeSampling) -> f32 {
            if sampling == ShapeSampling::SolidAngle
                && let Some(sampler) = self.solid_angle_sampler(reference)
            {
                return sampler.pdf();
            }
            let area = self.area();
            if !(area > 0.0) {
                return 0.0;
            }
            area_to_solid_angle(1.0 / area, reference, p, n).unwrap_or(0.0)
        }
    }

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
        /// A cloud of ellipsoids; each is one primitive of the hierarchy.
        Ellipsoids(Ellipsoids),
        /// A signed distance function on a grid; each voxel the surface crosses is one
        /// primitive of the hierarchy.
        SdfGrid(SdfGrid),
    }
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
    /// A point uniformly distributed over the surface from two numbers (Mitsuba's
    /// `Shape::sample_position`, with which sensors sample the shape they measure on or aim
    /// at): a mesh picks its triangle with `u.y` and reuses it
    /// ([`TriangleMesh::sample_position`]); other shapes map `u` onto their surface. The pdf is
    /// per unit area; None for a shape of zero area (curves).
    pub fn sample_position(&self, u: Vec2) -> Option<SurfaceSample> {
        match self {
            Shape::Mesh(mesh) => mesh.sample_position(u),
            Shape::Sphere(sphere) => sphere.sample_area(0.0, u),
            Shape::Disk(disk) => disk.sample_area(0.0, u),
            Shape::Cylinder(cylinder) => cylinder.sample_area(0.0, u),
            Shape::LinearCurve(curve) => curve.sample_area(0.0, u),
            Shape::BSplineCurve(curve) => curve.sample_area(0.0, u),
            Shape::Ellipsoids(ellipsoids) => ellipsoids.sample_area(0.0, u),
            Shape::SdfGrid(grid) => grid.sample_area(0.0, u),
        }
    }
}

/// The parts of a shape made of them (the segments of a curve, the ellipsoids of a cloud, the
/// occupied voxels of an SDF grid), each a primitive of the hierarchy.
#[derive(Clone, Copy, Debug)]
pub enum Segments<'a> {
    Linear(&'a LinearCurve),
    BSpline(&'a BSplineCurve),
    Ellipsoids(&'a Ellipsoids),
    SdfVoxels(&'a SdfGrid),
}

impl Segments<'_> {
    /// How many segments there are.
    #[inline]
    pub fn count(&self) -> usize {
        match self {
            Segments::Linear(curve) => curve.segment_count(),
            Segments::BSpline(curve) => curve.segment_count(),
            Segments::Ellipsoids(ellipsoids) => ellipsoids.count(),
            Segments::SdfVoxels(grid) => grid.voxel_count(),
        }
    }

    /// The bounds of segment `i`.
    #[inline]
    pub fn bounds(&self, i: u32) -> (Vec3, Vec3) {
        match self {
            Segments::Linear(curve) => curve.segment_bounds(i as usize),
            Segments::BSpline(curve) => curve.segment_bounds(i as usize),
            Segments::Ellipsoids(ellipsoids) => ellipsoids.ellipsoid_bounds(i as usize),
            Segments::SdfVoxels(grid) => grid.voxel_bounds(i as usize),
        }
    }

    /// Distance to the nearest hit of `ray` in (0, t_max) on segment `i`.
    #[inline]
    pub fn intersect(&self, i: u32, ray: &Ray, t_max: f32) -> Option<f32> {
        let i = i as usize;
        match self {
            Segments::Linear(curve) => curve.intersect_segment(i, ray.o, ray.d, t_max).map(|h| h.t),
            Segments::BSpline(curve) => {
                curve.intersect_segment(i, ray.o, ray.d, t_max).map(|h| h.t)
            }
            Segments::Ellipsoids(ellipsoids) => ellipsoids.intersect_ellipsoid(i, ray, t_max),
            Segments::SdfVoxels(grid) => grid.intersect_voxel(i, ray, t_max),
        }
    }
}

/// Sampling by the solid angle a shape subtends at one reference point, chosen once for the
/// point, so that a sample and its density always follow the same strategy.
#[derive(Clone, Copy, Debug)]
pub enum SolidAngleSampler<'a> {
    /// The cone a sphere subtends.
    SphereCone(SphereCone<'a>),
    /// The spherical rectangle a rectangle subtends.
    Rectangle(RectangleView<'a>),
}

impl SolidAngleSampler<'_> {
    /// A point of the shape whose direction is uniform in the solid angle; pdf per unit solid
    /// angle.
    #[inline]
    pub fn sample(&self, u: Vec2) -> Option<SurfaceSample> {
        match self {
            SolidAngleSampler::SphereCone(cone) => cone.sample(u),
            SolidAngleSampler::Rectangle(rectangle) => Some(rectangle.sample(u)),
        }
    }

    /// The density of [`Self::sample`] per unit solid angle, the same for every point it
    /// returns: 1 / the solid angle.
    #[inline]
    pub fn pdf(&self) -> f32 {
        match self {
            SolidAngleSampler::SphereCone(cone) => cone.pdf(),
            SolidAngleSampler::Rectangle(rectangle) => rectangle.pdf(),
        }
    }
}
