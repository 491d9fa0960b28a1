//! Triangle meshes: Mitsuba's `obj`, `ply`, `rectangle` and `cube` shapes.

use std::sync::OnceLock;

use glam::{Vec2, Vec3};

use super::uv_grid::UvGrid;
use super::{Segments, ShapeGeometry, SolidAngleSampler};
use crate::geometry::interaction::{AttributeValues, MAX_MESH_ATTRIBUTES, SurfaceInteraction};
use crate::geometry::triangle::TriangleHit;
use crate::math::{Frame, Ray};
use crate::sampling::distribution::AliasTable;
use crate::sampling::spherical_rectangle::{Projection, RectangleFrame};
use crate::sampling::warp::sample_uniform_triangle;

/// A rectangle is sampled by solid angle from points closer to its centre than this many times
/// its diagonal, by area from farther ones: there the 1/r² and the light's cosine vary across
/// it by less than (diagonal / distance)², so the gain would not pay for the cost.
const SOLID_ANGLE_SAMPLING_DISTANCE: f32 = 2.0;

/// A triangle mesh in world space. Positions and triangles are fixed at construction (the face
/// normals are computed from them there).
#[derive(Clone, Debug)]
pub struct TriangleMesh {
    positions: Vec<Vec3>,
    /// Per-vertex shading normals (unit length), if the mesh is smooth.
    pub normals: Option<Vec<Vec3>>,
    pub uvs: Option<Vec<Vec2>>,
    triangles: Vec<[u32; 3]>,
    /// The unit geometric normal of each triangle (see [`Self::face_normal`]), kept because a
    /// hit and a light sample each need one, and computing it (a cross product, a square root
    /// and a division) lies on the path's critical chain.
    face_normals: Vec<Vec3>,
    /// Whether the geometric and shading normals are reversed (Mitsuba's `flip_normals`).
    flip_normals: bool,
    /// What light samples need, built on the first, so that only meshes that are lights pay
    /// for it.
    light_sampling: OnceLock<Box<LightSampling>>,
    /// The triangles by texture coordinates, built on the first uv query (only meshes whose
    /// emission is textured make one).
    uv_grid: OnceLock<UvGrid>,
    area: f32,
    /// The attributes the mesh carries (Mitsuba's `vertex_color`, `face_color`, ...).
    attributes: Vec<MeshAttribute>,
    /// By slot, 1 + the index into `attributes` of the attribute the scene's textures read in
    /// that slot (0: none).
    bound: [u8; MAX_MESH_ATTRIBUTES],
}

/// What a mesh's light samples need.
#[derive(Clone, Debug)]
struct LightSampling {
    /// Triangles chosen in proportion to their area (None when the area is zero).
    area_table: Option<AliasTable>,
    /// The mesh as one rectangle, when it is two triangles that tile one (Mitsuba's
    /// `rectangle`, an OBJ quad): it is sampled by solid angle.
    rectangle: Option<Rectangle>,
}

/// A rectangle a mesh's two triangles tile: a corner a and two orthogonal edges.
#[derive(Clone, Copy, Debug)]
struct Rectangle {
    frame: RectangleFrame,
    center: Vec3,
    /// (SOLID_ANGLE_SAMPLING_DISTANCE × diagonal)².
    near_distance_squared: f32,
    /// For triangle 0 (the one with the corner a) and triangle 1 (with b = a + edge_x +
    /// edge_y), the vertex slots of (its own corner, a + edge_x, a + edge_y).
    slots: [[usize; 3]; 2],
}

/// Values a mesh carries per vertex or per triangle, under a Mitsuba attribute name
/// (`vertex_...` or `face_...`): colours (linear RGB) or numbers.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshAttribute {
    pub name: String,
    /// One value per triangle (else one per vertex).
    pub per_face: bool,
    /// 3 for a colour, 1 for a number (held in all three components of each value).
    pub channels: u8,
    pub values: Vec<Vec3>,
}

/// A point drawn on a surface.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceSample {
    pub p: Vec3,
    /// Unit geometric normal at the point.
    pub n: Vec3,
    /// Unit shading normal at the point (decides the side a one-sided emitter lights).
    pub shading_n: Vec3,
    /// Texture coordinates at the point (as a ray hit there would report them).
    pub uv: Vec2,
    /// The triangle of a mesh the point lies on (0 for other shapes).
    pub primitive: u32,
    /// Density of the point, per unit area or per unit solid angle (said by the method).
    pub pdf: f32,
}

impl SurfaceSample {
    /// The surface point of a ray hit (with pdf 0).
    pub fn at(si: &SurfaceInteraction) -> SurfaceSample {
        SurfaceSample {
            p: si.p,
            n: si.n,
            shading_n: si.shading.n,
            uv: si.uv,
            primitive: si.primitive,
            pdf: 0.0,
        }
    }
}

impl TriangleMesh {
    /// A mesh from world-space data; every index must be in range (the mesh readers validate).
    pub fn new(
        positions: Vec<Vec3>,
        normals: Option<Vec<Vec3>>,
        uvs: Option<Vec<Vec2>>,
        triangles: Vec<[u32; 3]>,
        flip_normals: bool,
    ) -> TriangleMesh {
        let mut mesh = TriangleMesh {
            positions,
            normals,
            uvs,
            triangles,
            face_normals: Vec::new(),
            flip_normals,
            light_sampling: OnceLock::new(),
            uv_grid: OnceLock::new(),
            area: 0.0,
            attributes: Vec::new(),
            bound: [0; MAX_MESH_ATTRIBUTES],
        };
        mesh.area = mesh.triangle_areas().iter().sum::<f64>() as f32;
        mesh.positions.shrink_to_fit();
        mesh.triangles.shrink_to_fit();
        mesh.face_normals = (0..mesh.triangles.len())
            .map(|i| mesh.computed_face_normal(i))
            .collect();
        mesh
    }

    /// Gives the mesh its attributes; each has one value per vertex, or per triangle when
    /// `per_face` (the mesh readers validate the counts).
    pub fn set_attributes(&mut self, attributes: Vec<MeshAttribute>) {
        debug_assert!(attributes.iter().all(|a| {
            a.values.len()
                == if a.per_face {
                    self.triangles.len()
                } else {
                    self.positions.len()
                }
        }));
        self.attributes = attributes;
        self.bound = [0; MAX_MESH_ATTRIBUTES];
    }

    /// The names of the mesh's attributes.
    pub fn attribute_names(&self) -> impl Iterator<Item = &str> {
        self.attributes.iter().map(|a| a.name.as_str())
    }

    /// The attribute `name`, if the mesh has it.
    pub fn attribute(&self, name: &str) -> Option<&MeshAttribute> {
        self.attributes.iter().find(|a| a.name == name)
    }

    /// Makes every hit fill `slot` with the attribute `name`; false when the mesh has none of
    /// that name.
    pub fn bind_attribute(&mut self, name: &str, slot: u8) -> bool {
        let Some(index) = self.attributes.iter().position(|a| a.name == name) else {
            return false;
        };
        self.bound[usize::from(slot)] = index as u8 + 1;
        true
    }

    /// The bound attributes at barycentrics `b` of `triangle`: a vertex attribute interpolated,
    /// a face attribute as it is.
    #[inline]
    fn attributes_at(&self, triangle: usize, b: [f32; 3]) -> AttributeValues {
        let mut values = AttributeValues::default();
        if self.attributes.is_empty() {
            return values;
        }
        for (slot, &bound) in self.bound.iter().enumerate() {
            let Some(index) = usize::from(bound).checked_sub(1) else {
                continue;
            };
            let attribute = &self.attributes[index];
            values.0[slot] = if attribute.per_face {
                attribute.values[triangle]
            } else {
                let [i, j, k] = self.triangles[triangle].map(|v| v as usize);
                attribute.values[i] * b[0] + attribute.values[j] * b[1] + attribute.values[k] * b[2]
            };
        }
        values
    }

    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    fn triangle_areas(&self) -> Vec<f64> {
        (0..self.triangles.len())
            .map(|i| f64::from(self.triangle_area(i)))
            .collect()
    }

    #[inline]
    pub fn vertices(&self, triangle: usize) -> [Vec3; 3] {
        let [a, b, c] = self.triangles[triangle];
        [
            self.positions[a as usize],
            self.positions[b as usize],
            self.positions[c as usize],
        ]
    }

    pub fn triangle_area(&self, triangle: usize) -> f32 {
        let [p0, p1, p2] = self.vertices(triangle);
        0.5 * (p1 - p0).cross(p2 - p0).length()
    }

    /// The unit geometric normal of a triangle: (p1 − p0) × (p2 − p0), counter-clockwise
    /// vertices facing the viewer (Mitsuba's convention), reversed by `flip_normals`; zero for a
    /// degenerate triangle.
    #[inline]
    fn face_normal(&self, triangle: usize) -> Vec3 {
        self.face_normals[triangle]
    }

    fn computed_face_normal(&self, triangle: usize) -> Vec3 {
        let [p0, p1, p2] = self.vertices(triangle);
        let n = (p1 - p0).cross(p2 - p0).normalize_or_zero();
        if self.flip_normals { -n } else { n }
    }

    /// Shading normal at barycentric coordinates (b0, b1, b2) of a triangle.
    fn shading_normal(&self, triangle: usize, b: [f32; 3], geometric: Vec3) -> Vec3 {
        let Some(normals) = &self.normals else {
            return geometric;
        };
        let [a, bb, c] = self.triangles[triangle];
        let n =
            (normals[a as usize] * b[0] + normals[bb as usize] * b[1] + normals[c as usize] * b[2])
                .normalize_or_zero();
        if n == Vec3::ZERO {
            geometric
        } else if self.flip_normals {
            -n
        } else {
            n
        }
    }

    /// The point at barycentric coordinates `b` of a triangle, with its normals, texture
    /// coordinates and the density `pdf`.
    fn surface_sample(&self, triangle: usize, b: [f32; 3], pdf: f32) -> SurfaceSample {
        let [p0, p1, p2] = self.vertices(triangle);
        let n = self.face_normal(triangle);
        let [t0, t1, t2] = self.uv_triangle(triangle);
        SurfaceSample {
            p: p0 * b[0] + p1 * b[1] + p2 * b[2],
            n,
            shading_n: self.shading_normal(triangle, b, n),
            uv: t0 * b[0] + t1 * b[1] + t2 * b[2],
            primitive: triangle as u32,
            pdf,
        }
    }

    /// A point uniformly distributed over the mesh's area from two numbers, as Mitsuba's
    /// `Mesh::sample_position` draws it: `u.y` picks a triangle in proportion to its area and
    /// is reused ([`AliasTable::sample_reuse`]) with `u.x` for a uniform point in it. The pdf is
    /// 1/area. None for a mesh of zero area.
    pub fn sample_position(&self, u: Vec2) -> Option<SurfaceSample> {
        let table = self.light_sampling().area_table.as_ref()?;
        let (triangle, _, reused) = table.sample_reuse(u.y);
        let b = sample_uniform_triangle(Vec2::new(u.x, reused));
        Some(self.surface_sample(triangle, [b.x, b.y, 1.0 - b.x - b.y], 1.0 / self.area))
    }

    /// The mesh's light-sampling tables, built on first use.
    fn light_sampling(&self) -> &LightSampling {
        self.light_sampling.get_or_init(|| {
            Box::new(LightSampling {
                area_table: AliasTable::new(&self.triangle_areas()),
                rectangle: self.find_rectangle(),
            })
        })
    }

    /// The mesh's rectangle, when the mesh is one and `reference` is near enough to sample it
    /// by solid angle ([`SOLID_ANGLE_SAMPLING_DISTANCE`]).
    fn near_rectangle(&self, reference: Vec3) -> Option<&Rectangle> {
        let r = self.light_sampling().rectangle.as_ref()?;
        (reference.distance_squared(r.center) <= r.near_distance_squared).then_some(r)
    }

    /// The rectangle two triangles tile: they share a diagonal (two positions), and with a
    /// and b the corners each has alone and s₀, s₁ the shared ones, s₀ − a ⊥ s₁ − a and
    /// b = a + (s₀ − a) + (s₁ − a), to a relative 10⁻⁴.
    fn find_rectangle(&self) -> Option<Rectangle> {
        if self.triangles.len() != 2 {
            return None;
        }
        let (first, second) = (self.vertices(0), self.vertices(1));
        let lone = |mine: &[Vec3; 3], other: &[Vec3; 3]| {
            let lone: Vec<usize> = (0..3).filter(|&i| !other.contains(&mine[i])).collect();
            (lone.len() == 1).then(|| lone[0])
        };
        let (a_slot, b_slot) = (lone(&first, &second)?, lone(&second, &first)?);
        let (a, b) = (first[a_slot], second[b_slot]);
        let (s0, s1) = (first[(a_slot + 1) % 3], first[(a_slot + 2) % 3]);
        let (edge_x, edge_y) = (s0 - a, s1 - a);
        let (lx, ly) = (edge_x.length(), edge_y.length());
        let tolerance = 1e-4;
        let is_rectangle = lx > 0.0
            && ly > 0.0
            && edge_x.dot(edge_y).abs() <= tolerance * lx * ly
            && (a + edge_x + edge_y - b).length() <= tolerance * (lx + ly);
        if !is_rectangle {
            return None;
        }
        let slot_in_second = |p: Vec3| second.iter().position(|&q| q == p);
        Some(Rectangle {
            frame: RectangleFrame::new(a, edge_x, edge_y)?,
            center: a + 0.5 * (edge_x + edge_y),
            near_distance_squared: SOLID_ANGLE_SAMPLING_DISTANCE.powi(2)
                * (edge_x + edge_y).length_squared(),
            slots: [
                [a_slot, (a_slot + 1) % 3, (a_slot + 2) % 3],
                [b_slot, slot_in_second(s0)?, slot_in_second(s1)?],
            ],
        })
    }

    /// The texture coordinates of a triangle's vertices; without them, (0, 0), (1, 0), (0, 1)
    /// (the barycentrics of p1 and p2, as [`Self::interaction`] reports them).
    #[inline]
    fn uv_triangle(&self, triangle: usize) -> [Vec2; 3] {
        match &self.uvs {
            Some(uvs) => self.triangles[triangle].map(|i| uvs[i as usize]),
            None => [Vec2::ZERO, Vec2::X, Vec2::Y],
        }
    }

    /// |∂p/∂u × ∂p/∂v| on a triangle, the area it covers per unit uv area (its area over its uv
    /// triangle's area); None for a triangle of zero uv area, which the uv map cannot reach.
    pub fn uv_jacobian(&self, triangle: usize) -> Option<f32> {
        let [t0, t1, t2] = self.uv_triangle(triangle);
        let uv_area = 0.5 * (t1 - t0).perp_dot(t2 - t0).abs();
        (uv_area > 0.0).then(|| self.triangle_area(triangle) / uv_area)
    }

    fn uv_grid(&self) -> &UvGrid {
        self.uv_grid.get_or_init(|| {
            let uv_triangles: Vec<[Vec2; 3]> = (0..self.triangles.len())
                .map(|t| self.uv_triangle(t))
                .collect();
            UvGrid::new(&uv_triangles)
        })
    }

    /// The triangle [`Self::at_uv`] maps `uv` to.
    pub fn triangle_at_uv(&self, uv: Vec2) -> Option<usize> {
        self.uv_grid()
            .find(uv, |t| self.uv_triangle(t))
            .map(|hit| hit.triangle)
    }
}

impl ShapeGeometry for TriangleMesh {
    /// Total surface area.
    fn area(&self) -> f32 {
        self.area
    }

    fn object_bounds(&self) -> (Vec3, Vec3) {
        self.positions.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        )
    }

    fn as_segments(&self) -> Option<Segments<'_>> {
        None
    }

    fn intersect_analytic(&self, _ray: &Ray, _t_max: f32) -> Option<f32> {
        None
    }

    /// Bytes of heap memory the mesh holds: vertex attributes, indices and the area table.
    fn heap_bytes(&self) -> usize {
        use std::mem::size_of;
        self.positions.capacity() * size_of::<Vec3>()
            + self
                .normals
                .as_ref()
                .map_or(0, |n| n.capacity() * size_of::<Vec3>())
            + self
                .uvs
                .as_ref()
                .map_or(0, |uv| uv.capacity() * size_of::<Vec2>())
            + self.triangles.capacity() * size_of::<[u32; 3]>()
            + self.face_normals.capacity() * size_of::<Vec3>()
            + self
                .attributes
                .iter()
                .map(|a| a.values.capacity() * size_of::<Vec3>())
                .sum::<usize>()
            + self.light_sampling.get().map_or(0, |l| {
                size_of::<LightSampling>() + l.area_table.as_ref().map_or(0, AliasTable::heap_bytes)
            })
            + self.uv_grid.get().map_or(0, UvGrid::heap_bytes)
    }

    /// The surface interaction of a ray hit on a triangle.
    fn interaction(
        &self,
        _ray: &Ray,
        primitive: u32,
        hit: &TriangleHit,
        index: u32,
    ) -> SurfaceInteraction {
        let (triangle, shape) = (primitive as usize, index);
        let [p0, p1, p2] = self.vertices(triangle);
        let b = [hit.b0, hit.b1, hit.b2];
        // The barycentric combination is closer to the surface than o + t·d.
        let p = p0 * b[0] + p1 * b[1] + p2 * b[2];
        let n = self.face_normal(triangle);
        let shading_n = self.shading_normal(triangle, b, n);
        // Without texture coordinates, (u, v) are the barycentrics of p1 and p2 (as Mitsuba), so
        // ∂p/∂u and ∂p/∂v are the edges from p0.
        let (mut dp_du, mut dp_dv) = (p1 - p0, p2 - p0);
        let uv = match &self.uvs {
            Some(uvs) => {
                let [a, bb, c] = self.triangles[triangle];
                let [uv0, uv1, uv2] = [uvs[a as usize], uvs[bb as usize], uvs[c as usize]];
                // Solve [dp1 dp2] = [∂p/∂u ∂p/∂v] [duv1 duv2] (pbrt-v4 §6.5.3).
                let (duv1, duv2) = (uv1 - uv0, uv2 - uv0);
                let det = duv1.x * duv2.y - duv1.y * duv2.x;
                if det.abs() > 1e-12 {
                    let inv = 1.0 / det;
                    let (dp1, dp2) = (dp_du, dp_dv);
                    dp_du = (dp1 * duv2.y - dp2 * duv1.y) * inv;
                    dp_dv = (dp2 * duv1.x - dp1 * duv2.x) * inv;
                }
                uv0 * b[0] + uv1 * b[1] + uv2 * b[2]
            }
            None => Vec2::new(b[1], b[2]),
        };
        SurfaceInteraction {
            p,
            t: hit.t,
            n,
            shading: Frame::from_normal_and_tangent(shading_n, dp_du),
            uv,
            dp_du,
            dp_dv,
            shape,
            primitive: triangle as u32,
            time: 0.0,
            attributes: self.attributes_at(triangle, b),
        }
    }

    /// From a point near the rectangle the mesh is ([`SOLID_ANGLE_SAMPLING_DISTANCE`]) and out
    /// of its plane, the spherical rectangle; None for other meshes and points, which sample
    /// the area.
    fn solid_angle_sampler(&self, reference: Vec3) -> Option<SolidAngleSampler<'_>> {
        let rectangle = self.near_rectangle(reference)?;
        let projection = rectangle.frame.project(reference)?;
        Some(SolidAngleSampler::Rectangle(RectangleView {
            mesh: self,
            rectangle,
            projection,
        }))
    }

    /// A point uniformly distributed over the mesh's area: a triangle chosen in proportion to its
    /// area by `u_choice`, then a uniform point in it. The pdf is 1/area. None for a mesh of zero
    /// area.
    fn sample_area(&self, u_choice: f32, u: Vec2) -> Option<SurfaceSample> {
        let table = self.light_sampling().area_table.as_ref()?;
        let (triangle, _) = table.sample(u_choice);
        let b = sample_uniform_triangle(u);
        Some(self.surface_sample(triangle, [b.x, b.y, 1.0 - b.x - b.y], 1.0 / self.area))
    }

    fn uv_jacobian_at(&self, primitive: u32, uv: Vec2) -> Option<f32> {
        let triangle = self.triangle_at_uv(uv)?;
        if triangle != primitive as usize {
            return None;
        }
        self.uv_jacobian(triangle)
    }

    /// The surface point with texture coordinates `uv` (Mitsuba's `eval_parameterization`), on
    /// the lowest-numbered triangle whose uv triangle contains it, with that triangle's
    /// [`Self::uv_jacobian`]; None where no triangle covers `uv`. The sample's pdf is 0.
    fn at_uv(&self, uv: Vec2) -> Option<(SurfaceSample, f32)> {
        let hit = self.uv_grid().find(uv, |t| self.uv_triangle(t))?;
        let triangle = hit.triangle;
        let jacobian = self.uv_jacobian(triangle)?;
        let [p0, p1, p2] = self.vertices(triangle);
        let b = hit.barycentrics;
        let n = self.face_normal(triangle);
        let sample = SurfaceSample {
            p: p0 * b[0] + p1 * b[1] + p2 * b[2],
            n,
            shading_n: self.shading_normal(triangle, b, n),
            uv,
            primitive: triangle as u32,
            pdf: 0.0,
        };
        Some((sample, jacobian))
    }
}

/// A rectangle mesh seen from one point near it: its spherical projection, sampled uniformly
/// in solid angle ([`crate::sampling::spherical_rectangle`], Ureña et al. 2013; density 1/S).
#[derive(Clone, Copy, Debug)]
pub struct RectangleView<'a> {
    mesh: &'a TriangleMesh,
    rectangle: &'a Rectangle,
    projection: Projection,
}

impl RectangleView<'_> {
    /// A point whose direction is uniform in the solid angle S the rectangle subtends.
    pub fn sample(&self, u: Vec2) -> SurfaceSample {
        let st = self.rectangle.frame.spherical(&self.projection).sample(u);
        // p = a + s·edge_x + t·edge_y lies on triangle 0 when s + t ≤ 1, else on triangle 1.
        let (s, t) = (st.x, st.y);
        let (triangle, weights) = if s + t <= 1.0 {
            (0, [1.0 - s - t, s, t])
        } else {
            (1, [s + t - 1.0, 1.0 - t, 1.0 - s])
        };
        let mut b = [0.0; 3];
        for (slot, weight) in self.rectangle.slots[triangle].into_iter().zip(weights) {
            b[slot] = weight;
        }
        self.mesh.surface_sample(triangle, b, self.pdf())
    }

    /// The density of [`Self::sample`] per unit solid angle, 1/S.
    pub fn pdf(&self) -> f32 {
        1.0 / self.projection.solid_angle()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_square() -> TriangleMesh {
        TriangleMesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
            None,
            None,
            vec![[0, 1, 2], [2, 3, 0]],
            false,
        )
    }

    #[test]
    fn area_and_normals() {
        let mesh = unit_square();
        assert!((mesh.area() - 1.0).abs() < 1e-6);
        assert_eq!(mesh.face_normal(0), Vec3::Z);
        let square = unit_square();
        let flipped = TriangleMesh::new(square.positions, None, None, square.triangles, true);
        assert_eq!(flipped.face_normal(1), -Vec3::Z);
    }

    #[test]
    fn area_samples_lie_on_the_mesh() {
        let mesh = unit_square();
        for i in 0..100 {
            let u = Vec2::new((i % 10) as f32 / 10.0 + 0.05, (i / 10) as f32 / 10.0 + 0.05);
            let s = mesh.sample_area((i as f32 + 0.5) / 100.0, u).unwrap();
            assert!(s.p.z == 0.0 && (0.0..=1.0).contains(&s.p.x) && (0.0..=1.0).contains(&s.p.y));
            assert_eq!(s.pdf, 1.0);
        }
    }
}
