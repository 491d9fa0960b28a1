//! Mitsuba's `sdfgrid` shape (`src/shapes/sdfgrid.cpp`): the zero set of a signed distance
//! function sampled on a grid of nx × ny × nz points spanning the unit cube of object space
//! (point (i, j, k) at (i/(nx − 1), j/(ny − 1), k/(nz − 1))), trilinearly interpolated in each
//! voxel. Each voxel whose corners do not all have the same strict sign is one primitive of the
//! hierarchy, bounded by Mitsuba's tight box: the corners where the function is zero and the
//! points where it changes sign along the voxel's edges (Hansson-Söderlund & Akenine-Möller
//! 2023, "Tight Bounding Boxes for Voxels and Bricks in a Signed Distance Field Ray Tracer").
//!
//! Along a ray through a voxel the trilinear function is a cubic in t; its first root is found
//! as Mitsuba finds it (Marmitt et al. 2004, "Fast and Accurate Ray-Voxel Intersection
//! Techniques for Iso-Surface Ray Tracing"): the roots of its derivative split the ray's span in
//! the voxel into monotonic pieces, and the first piece whose ends differ in sign is refined by
//! regula falsi. Rays hit the surface from either side.
//!
//! The geometric normal is Mitsuba's gradient of the voxel holding the point: differences of the
//! interpolated function across the voxel's faces, through the point. The `smooth` shading
//! normal blends the normalised gradients of the eight voxels around the point trilinearly
//! (Hansson-Söderlund, Evans & Akenine-Möller 2022, "Ray Tracing of Signed Distance Function
//! Grids", JCGT 11(3)), which is continuous across voxels; `analytic` shades with the
//! geometric normal. As in Mitsuba the shape has no parametrisation (uv = 0) and no area
//! sampling, so it cannot be an area light.

use glam::{DVec3, UVec3, Vec2, Vec3};

use super::{Segments, ShapeGeometry};
use crate::geometry::interaction::{AttributeValues, SurfaceInteraction};
use crate::geometry::triangle::TriangleHit;
use crate::math::{Frame, Ray, Transform};

/// How the shading normal of an SDF grid is found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SdfNormals {
    /// The geometric normal, the gradient of the voxel holding the point.
    Analytic,
    /// The trilinear blend of the eight surrounding voxels' gradients.
    Smooth,
}

/// A signed distance function on a grid, placed by a transform.
#[derive(Clone, Debug)]
pub struct SdfGrid {
    /// Points per axis (x, y, z), each at least 2.
    resolution: UVec3,
    /// The function's values, x varying fastest, then y, then z.
    values: Vec<f32>,
    /// Boxed: a transform and its inverse would double the size of every [`super::Shape`].
    to_world: Box<Transform>,
    normals: SdfNormals,
    /// The occupied voxels (their lowest corners) and their bounds in world space.
    voxels: Vec<UVec3>,
    bounds: Vec<(Vec3, Vec3)>,
}

/// The regula falsi's iterations and its tolerance in the voxel's ray parameter (Mitsuba's).
const SOLVE_ITERATIONS: u32 = 50;
const SOLVE_EPSILON: f64 = 1e-5;

impl SdfGrid {
    /// The grid of `values` (x fastest) at `resolution` points per axis, placed by `to_world`;
    /// None when an axis has fewer than two points, the values are not one per point or not
    /// all finite, or no voxel holds part of the surface.
    pub fn new(
        resolution: UVec3,
        values: Vec<f32>,
        to_world: Transform,
        normals: SdfNormals,
    ) -> Option<SdfGrid> {
        let count = (resolution.x as usize)
            .checked_mul(resolution.y as usize)?
            .checked_mul(resolution.z as usize)?;
        if resolution.min_element() < 2
            || values.len() != count
            || values.iter().any(|v| !v.is_finite())
        {
            return None;
        }
        let mut grid = SdfGrid {
            resolution,
            values,
            to_world: Box::new(to_world),
            normals,
            voxels: Vec::new(),
            bounds: Vec::new(),
        };
        for z in 0..resolution.z - 1 {
            for y in 0..resolution.y - 1 {
                for x in 0..resolution.x - 1 {
                    let voxel = UVec3::new(x, y, z);
                    if let Some(bounds) = grid.tight_bounds(voxel) {
                        grid.voxels.push(voxel);
                        grid.bounds.push(bounds);
                    }
                }
            }
        }
        (!grid.voxels.is_empty()).then_some(grid)
    }

    /// The number of occupied voxels (primitives of the hierarchy).
    pub fn voxel_count(&self) -> usize {
        self.voxels.len()
    }

    /// The world bounds of occupied voxel `i`.
    pub fn voxel_bounds(&self, i: usize) -> (Vec3, Vec3) {
        self.bounds[i]
    }

    /// The value at grid point `p`.
    fn value(&self, p: UVec3) -> f32 {
        let r = self.resolution;
        self.values[(p.x + r.x * (p.y + r.y * p.z)) as usize]
    }

    /// The eight corner values of voxel `v`, corner c at offset (c & 1, c >> 1 & 1, c >> 2 & 1).
    fn corners(&self, v: UVec3) -> [f64; 8] {
        std::array::from_fn(|c| {
            let c = c as u32;
            f64::from(self.value(v + UVec3::new(c & 1, (c >> 1) & 1, (c >> 2) & 1)))
        })
    }

    /// The size of a voxel in object space, 1/(n − 1) per axis.
    fn voxel_size(&self) -> DVec3 {
        (self.resolution - 1).as_dvec3().recip()
    }

    /// Mitsuba's tight bounds of voxel `v` in world space; None when its corners all have the
    /// same strict sign (the voxel is empty).
    fn tight_bounds(&self, v: UVec3) -> Option<(Vec3, Vec3)> {
        let f = self.corners(v);
        if f.iter().all(|&x| x > 0.0) || f.iter().all(|&x| x < 0.0) {
            return None;
        }
        let corner = |c: usize| DVec3::new((c & 1) as f64, ((c >> 1) & 1) as f64, (c >> 2) as f64);
        // Starting empty (min 1, max 0) on each axis, except where a zero corner lies on a face.
        let mut lo = DVec3::ONE;
        let mut hi = DVec3::ZERO;
        for (c, &value) in f.iter().enumerate() {
            if value == 0.0 {
                lo = lo.min(corner(c));
                hi = hi.max(corner(c));
            }
        }
        for (a, &fa) in f.iter().enumerate() {
            for axis in 0..3 {
                if a & (1 << axis) != 0 {
                    continue;
                }
                let b = a | (1 << axis);
                let fb = f[b];
                if fa * fb <= 0.0 && fa != fb {
                    let crossing = corner(a) + (corner(b) - corner(a)) * (fa / (fa - fb));
                    lo = lo.min(crossing);
                    hi = hi.max(crossing);
                }
            }
        }
        let size = self.voxel_size();
        let (lo, hi) = ((v.as_dvec3() + lo) * size, (v.as_dvec3() + hi) * size);
        Some(self.world_box(lo.as_vec3(), hi.as_vec3()))
    }

    /// The world box around the object box (lo, hi) (its eight corners transformed).
    fn world_box(&self, lo: Vec3, hi: Vec3) -> (Vec3, Vec3) {
        (0..8).fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(l, h), c| {
                let p = Vec3::new(
                    if c & 1 == 0 { lo.x } else { hi.x },
                    if c & 2 == 0 { lo.y } else { hi.y },
                    if c & 4 == 0 { lo.z } else { hi.z },
                );
                let p = self.to_world.point(p);
                (l.min(p), h.max(p))
            },
        )
    }

    /// The first t in (0, t_max) where `ray` meets the surface within occupied voxel `i`.
    pub fn intersect_voxel(&self, i: usize, ray: &Ray, t_max: f32) -> Option<f32> {
        let v = self.voxels[i];
        // The ray in voxel coordinates, where the voxel is the unit cube: x ↦ x (n − 1) − v.
        // An affine map keeps the ray parameter.
        let scale = (self.resolution - 1).as_dvec3();
        let o = self.to_world.inverse_point(ray.o).as_dvec3() * scale - v.as_dvec3();
        let d = self.to_world.inverse_vector(ray.d).as_dvec3() * scale;
        let (mut t0, mut t1) = (0.0f64, f64::from(t_max));
        for axis in 0..3 {
            let inv = 1.0 / d[axis];
            let (mut near, mut far) = (-o[axis] * inv, (1.0 - o[axis]) * inv);
            if near > far {
                std::mem::swap(&mut near, &mut far);
            }
            if near.is_nan() || far.is_nan() {
                // A ray in the slab's plane: inside it or not at all.
                if o[axis] < 0.0 || o[axis] > 1.0 {
                    return None;
                }
                continue;
            }
            t0 = t0.max(near);
            t1 = t1.min(far);
        }
        if !(t0 < t1) {
            return None;
        }
        let f = self.corners(v);
        let along = |t: f64| trilinear(&f, o + d * t);
        let t = first_root(along, t0, t1)?;
        (t > 0.0 && t < f64::from(t_max)).then_some(t as f32)
    }

    /// The occupied voxel `ray` hits first in (0, t_max), with the distance.
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<(usize, f32)> {
        let mut best: Option<(usize, f32)> = None;
        for i in 0..self.voxels.len() {
            let limit = best.map_or(t_max, |(_, t)| t);
            if let Some(t) = self.intersect_voxel(i, ray, limit) {
                best = Some((i, t));
            }
        }
        best
    }

    /// The interpolated function at object-space point `p` (clamped to the grid, as Mitsuba's
    /// texture lookup).
    fn eval(&self, p: DVec3) -> f64 {
        let scale = (self.resolution - 1).as_dvec3();
        let x = (p * scale).clamp(DVec3::ZERO, scale);
        let base = x.floor().min(scale - 1.0).max(DVec3::ZERO);
        let f = self.corners(base.as_uvec3());
        trilinear(&f, x - base)
    }

    /// Mitsuba's gradient of voxel `v` at `p`: the differences of the function across the
    /// voxel's faces through `p`, over the voxel's size.
    fn voxel_gradient(&self, p: DVec3, v: DVec3) -> DVec3 {
        let size = self.voxel_size();
        let low = v * size;
        let across = |axis: usize| {
            let (mut a, mut b) = (p, p);
            a[axis] = low[axis] + size[axis];
            b[axis] = low[axis];
            (self.eval(a) - self.eval(b)) / size[axis]
        };
        DVec3::new(across(0), across(1), across(2))
    }

    /// The gradient at object-space point `p`, that of the voxel holding it.
    pub fn gradient(&self, p: DVec3) -> DVec3 {
        let v = (p * (self.resolution - 1).as_dvec3()).trunc();
        self.voxel_gradient(p, v)
    }

    /// Mitsuba's smooth normal at object-space point `p` (not normalised): the normalised
    /// gradients of the eight voxels around the point's nearest grid point, blended
    /// trilinearly; voxels below the grid are left out, and an axis with none on one side
    /// takes the other side's weight.
    pub fn smooth_normal(&self, p: DVec3) -> DVec3 {
        let scaled = p * (self.resolution - 1).as_dvec3();
        let first = scaled.round() - 1.0;
        let mut normals = [DVec3::ZERO; 8];
        let mut valid = [false; 8];
        for (c, (normal, ok)) in normals.iter_mut().zip(valid.iter_mut()).enumerate() {
            let v = first + DVec3::new((c & 1) as f64, ((c >> 1) & 1) as f64, (c >> 2) as f64);
            *ok = v.min_element() >= 0.0;
            if *ok {
                *normal = self.voxel_gradient(p, v).normalize_or_zero();
            }
        }
        let mut w = scaled - (first + 1.0) + 0.5;
        for axis in 0..3 {
            let side = |high: bool| (0..8).any(|c| valid[c] && ((c >> axis) & 1 == 1) == high);
            if !side(false) {
                w[axis] = 1.0;
            }
            if !side(true) {
                w[axis] = 0.0;
            }
        }
        (0..8)
            .map(|c| {
                let pick = |axis: usize| {
                    if (c >> axis) & 1 == 1 {
                        w[axis]
                    } else {
                        1.0 - w[axis]
                    }
                };
                normals[c] * (pick(0) * pick(1) * pick(2))
            })
            .sum()
    }

    /// The surface interaction of a hit at distance `t` in voxel `i`, recorded as shape
    /// `index`.
    fn interaction_on(&self, ray: &Ray, i: u32, t: f32, index: u32) -> SurfaceInteraction {
        let p = ray.at(t);
        let local = self.to_world.inverse_point(p).as_dvec3();
        let n = self
            .to_world
            .normal(self.gradient(local).as_vec3())
            .normalize_or(Vec3::Z);
        let shading_n = match self.normals {
            SdfNormals::Analytic => n,
            SdfNormals::Smooth => self
                .to_world
                .normal(self.smooth_normal(local).as_vec3())
                .normalize_or(n),
        };
        let frame = Frame::from_normal(shading_n);
        SurfaceInteraction {
            p,
            t,
            n,
            shading: frame,
            uv: Vec2::ZERO,
            dp_du: frame.s,
            dp_dv: frame.t,
            shape: index,
            primitive: i,
            time: 0.0,
            attributes: AttributeValues::default(),
        }
    }
}

/// The trilinear interpolation of the corner values `f` at `x` in the unit cube.
fn trilinear(f: &[f64; 8], x: DVec3) -> f64 {
    let lerp = |a: f64, b: f64, s: f64| a + (b - a) * s;
    let y0 = lerp(lerp(f[0], f[1], x.x), lerp(f[2], f[3], x.x), x.y);
    let y1 = lerp(lerp(f[4], f[5], x.x), lerp(f[6], f[7], x.x), x.y);
    lerp(y0, y1, x.z)
}

/// The first root of the cubic `f` (a trilinear function along a line) in [t0, t1]: the
/// roots of its derivative split the span into monotonic pieces, and the first piece whose
/// ends differ in sign is refined by regula falsi.
fn first_root(f: impl Fn(f64) -> f64, t0: f64, t1: f64) -> Option<f64> {
    // The cubic's coefficients from four samples (exact for a cubic): with s = (t − t0)/h,
    // f = a s³ + b s² + c s + e.
    let h = t1 - t0;
    let [f0, f1, f2, f3] = [0.0, 1.0, 2.0, 3.0].map(|k| f(t0 + h * k / 3.0));
    let a = 4.5 * (f3 - 3.0 * f2 + 3.0 * f1 - f0);
    let b = 9.0 * (f0 - 2.5 * f1 + 2.0 * f2 - 0.5 * f3);
    let c = -5.5 * f0 + 9.0 * f1 - 4.5 * f2 + f3;
    // Roots of 3a s² + 2b s + c within (0, 1), in order.
    let mut splits = vec![0.0];
    let (qa, qb, qc) = (3.0 * a, 2.0 * b, c);
    if qa.abs() > 1e-12 * (qb.abs() + qc.abs()) {
        let discriminant = qb * qb - 4.0 * qa * qc;
        if discriminant >= 0.0 {
            let root = discriminant.sqrt();
            let q = -0.5 * (qb + root.copysign(qb));
            let mut roots = [q / qa, if q != 0.0 { qc / q } else { q / qa }];
            roots.sort_by(f64::total_cmp);
            splits.extend(roots.into_iter().filter(|&s| s > 0.0 && s < 1.0));
        }
    } else if qb != 0.0 {
        let s = -qc / qb;
        if s > 0.0 && s < 1.0 {
            splits.push(s);
        }
    }
    splits.push(1.0);
    let at = |s: f64| f(t0 + h * s);
    for pair in splits.windows(2) {
        let (mut near, mut far) = (pair[0], pair[1]);
        let (mut f_near, mut f_far) = (at(near), at(far));
        if f_near * f_far > 0.0 {
            continue;
        }
        let mut s = near;
        for _ in 0..SOLVE_ITERATIONS {
            if f_far == f_near {
                break;
            }
            s = near + (far - near) * (-f_near / (f_far - f_near));
            let f_s = at(s);
            if f_s * f_near <= 0.0 {
                far = s;
                f_far = f_s;
            } else {
                near = s;
                f_near = f_s;
            }
            if (far - near) * h < SOLVE_EPSILON {
                break;
            }
        }
        return Some(t0 + h * s);
    }
    None
}

impl ShapeGeometry for SdfGrid {
    /// No area: Mitsuba's SDF grid has no surface sampling, so it cannot emit.
    fn area(&self) -> f32 {
        0.0
    }

    /// The transformed unit cube.
    fn object_bounds(&self) -> (Vec3, Vec3) {
        self.world_box(Vec3::ZERO, Vec3::ONE)
    }

    fn as_segments(&self) -> Option<Segments<'_>> {
        Some(Segments::SdfVoxels(self))
    }

    fn intersect_analytic(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        self.intersect(ray, t_max).map(|(_, t)| t)
    }

    fn interaction(
        &self,
        ray: &Ray,
        primitive: u32,
        hit: &TriangleHit,
        index: u32,
    ) -> SurfaceInteraction {
        let primitive = primitive.min(self.voxels.len() as u32 - 1);
        self.interaction_on(ray, primitive, hit.t, index)
    }

    fn heap_bytes(&self) -> usize {
        self.values.capacity() * std::mem::size_of::<f32>()
            + self.voxels.capacity() * std::mem::size_of::<UVec3>()
            + self.bounds.capacity() * std::mem::size_of::<(Vec3, Vec3)>()
            + std::mem::size_of::<Transform>()
    }
}
