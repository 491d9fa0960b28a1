//! Mitsuba's `linearcurve` shape (`src/shapes/linearcurve.cpp`, Embree's "round linear"
//! curves): polylines of control points (position, radius), each segment the sweep of a sphere
//! whose centre and radius vary linearly from one control point to the next. A segment is the
//! convex hull of its two end spheres, a cone frustum tangent to both closed by the spheres, so
//! consecutive segments join by a spherical joint and each curve ends in a spherical cap.
//!
//! Positions are in world space (the scene reader applies `to_world` to them); radii are not
//! transformed, as in Mitsuba. Each segment is one primitive of the hierarchy. As with Embree
//! and Mitsuba, back faces are culled: a ray whose origin lies inside a segment does not hit it.
//!
//! Parametrisation as Mitsuba's: on segment i of n, at the sweep parameter s (the sphere whose
//! surface the point lies on, centre c(s), radius r(s)), v = (s + i)/n and u is the angle of the
//! normal around the segment's axis over 2π; ∂p/∂u = 2π a × (p − c) with a the unit axis and
//! ∂p/∂v = n ((p₁ − p₀) + (r₁ − r₀) N).

use std::f32::consts::PI;

use glam::{DVec3, Vec2, Vec3, Vec4};

pub use super::curve::SegmentHit;
use super::curve::nearest_hit;
use super::{Curve, Segments};
use crate::geometry::interaction::{AttributeValues, SurfaceInteraction};
use crate::math::Frame;
use crate::math::Ray;

/// A set of round linear curves, one primitive per segment.
#[derive(Clone, Debug)]
pub struct LinearCurve {
    /// Control points: world position in xyz, radius in w.
    points: Vec<Vec4>,
    /// The first control point of each segment (the segment runs to the next point).
    segments: Vec<u32>,
}

impl LinearCurve {
    /// Curves from their control points, `curves` giving each curve's first point index; each
    /// curve runs to the next one's first point (the last to the end). None when a curve has
    /// fewer than two points, an index is out of order, or a radius is negative or not finite.
    pub fn new(points: Vec<Vec4>, curves: &[u32]) -> Option<LinearCurve> {
        if points.iter().any(|p| !p.is_finite() || p.w < 0.0) || curves.is_empty() {
            return None;
        }
        let mut segments = Vec::new();
        for (i, &first) in curves.iter().enumerate() {
            let end = curves.get(i + 1).copied().unwrap_or(points.len() as u32);
            if end < first.checked_add(2)? || end as usize > points.len() {
                return None;
            }
            segments.extend(first..end - 1);
        }
        Some(LinearCurve { points, segments })
    }

    /// The number of segments (primitives of the hierarchy).
    pub fn segment_count(&self) -> usize {
        self.segments.len()
    }

    /// The two control points of segment `i`.
    fn ends(&self, i: usize) -> (Vec4, Vec4) {
        let first = self.segments[i] as usize;
        (self.points[first], self.points[first + 1])
    }

    /// The bounds of segment `i`: the box around its two end spheres, which holds their hull.
    pub fn segment_bounds(&self, i: usize) -> (Vec3, Vec3) {
        let (a, b) = self.ends(i);
        let (ca, cb) = (a.truncate(), b.truncate());
        ((ca - a.w).min(cb - b.w), (ca + a.w).max(cb + b.w))
    }

    /// The nearest front-face hit in (0, t_max) on segment `i`.
    pub fn intersect_segment(&self, i: usize, o: Vec3, d: Vec3, t_max: f32) -> Option<SegmentHit> {
        let (a, b) = self.ends(i);
        let hit = round_cone_entry(
            o.as_dvec3(),
            d.as_dvec3(),
            a.truncate().as_dvec3(),
            f64::from(a.w),
            b.truncate().as_dvec3(),
            f64::from(b.w),
        )?;
        let t = hit.0 as f32;
        (t > 0.0 && t < t_max).then_some(SegmentHit { t, s: hit.1 as f32 })
    }

    /// The nearest hit in (0, t_max) over all segments, with its segment.
    pub fn intersect(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<(usize, SegmentHit)> {
        nearest_hit(self.segments.len(), t_max, |i, limit| {
            self.intersect_segment(i, o, d, limit)
        })
    }

    /// The surface interaction of a hit on segment `segment` at distance `t` (its sweep
    /// parameter is found again from the point).
    pub fn segment_interaction(
        &self,
        o: Vec3,
        d: Vec3,
        t: f32,
        segment: u32,
        shape: u32,
    ) -> SurfaceInteraction {
        let i = segment as usize;
        let (a, b) = self.ends(i);
        let (pa, pb) = (a.truncate().as_dvec3(), b.truncate().as_dvec3());
        let p = (o + d * t).as_dvec3();
        let s = sweep_parameter(p, pa, f64::from(a.w), pb, f64::from(b.w));
        let c = pa.lerp(pb, s);
        let radius = f64::from(a.w) + s * f64::from(b.w - a.w);
        let n = (p - c).normalize_or((pb - pa).any_orthonormal_vector());
        let axis = (pb - pa).normalize_or(DVec3::Z);
        let (u_rot, u_rad) = local_frame(axis);
        let mut phi = n.dot(u_rot).atan2(n.dot(u_rad));
        if phi < 0.0 {
            phi += std::f64::consts::TAU;
        }
        let count = self.segments.len() as f64;
        let on_surface = c + n * radius;
        let dp_du = (std::f64::consts::TAU * axis.cross(on_surface - c)).as_vec3();
        let dp_dv = (count * ((pb - pa) + f64::from(b.w - a.w) * n)).as_vec3();
        let n = n.as_vec3();
        SurfaceInteraction {
            p: on_surface.as_vec3(),
            t,
            n,
            shading: Frame::from_normal_and_tangent(n, dp_du),
            uv: Vec2::new(phi as f32 / (2.0 * PI), ((s + i as f64) / count) as f32),
            dp_du,
            dp_dv,
            shape,
            primitive: segment,
            time: 0.0,
            attributes: AttributeValues::default(),
        }
    }
}

/// Mitsuba's frame around a segment's unit axis: the rotation axis is the projection of +z
/// orthogonal to the axis (+y when the axis is ±z), the radial axis its cross product with
/// the axis.
pub(super) fn local_frame(axis: DVec3) -> (DVec3, DVec3) {
    let guide = DVec3::Z;
    let u_rot = if axis.dot(guide).abs() == 1.0 {
        DVec3::Y
    } else {
        (guide - axis * axis.dot(guide)).normalize()
    };
    (u_rot, u_rot.cross(axis))
}

/// Whether the round cone between spheres (a, ra) and (b, rb) is a single sphere: one end
/// sphere holds the other (|ra − rb| ≥ |b − a|), so there is no cone between them.
fn degenerate(a: DVec3, ra: f64, b: DVec3, rb: f64) -> bool {
    (ra - rb).abs() >= (b - a).length()
}

/// The parameter s in [0, 1] of the sphere of the sweep whose surface touches `p`: on the cone,
/// where (p − c(s)) · (b − a) = r(s) (ra − rb), s = ((p − a)·(b − a) − ra (ra − rb)) / (|b − a|²
/// − (ra − rb)²); clamped to the end spheres.
fn sweep_parameter(p: DVec3, a: DVec3, ra: f64, b: DVec3, rb: f64) -> f64 {
    if degenerate(a, ra, b, rb) {
        return if ra >= rb { 0.0 } else { 1.0 };
    }
    let ba = b - a;
    let rr = ra - rb;
    let d2 = ba.length_squared() - rr * rr;
    (((p - a).dot(ba) - ra * rr) / d2).clamp(0.0, 1.0)
}

/// Whether `p` lies strictly inside the round cone (the hull of spheres (a, ra) and (b, rb)).
fn inside_round_cone(p: DVec3, a: DVec3, ra: f64, b: DVec3, rb: f64) -> bool {
    if (p - a).length_squared() < ra * ra || (p - b).length_squared() < rb * rb {
        return true;
    }
    if degenerate(a, ra, b, rb) {
        return false;
    }
    // Inside the frustum: within its axial range and below the cone, ρ cos θ + x sin θ < ra
    // (x along the axis from a, ρ the distance to the axis, sin θ = (ra − rb)/|b − a|).
    let ba = b - a;
    let length = ba.length();
    let rr = ra - rb;
    let q = p - a;
    let y = q.dot(ba);
    if y < ra * rr || y > ba.length_squared() + rb * rr {
        return false;
    }
    let x = y / length;
    let rho = (q.length_squared() - x * x).max(0.0).sqrt();
    let sin = rr / length;
    let cos = (1.0 - sin * sin).sqrt();
    rho * cos + x * sin < ra
}

/// The nearer root t > 0 of the sphere (c, r) along o + t d, if the ray meets it.
fn sphere_entry(o: DVec3, d: DVec3, c: DVec3, r: f64) -> Option<f64> {
    let a = d.length_squared();
    let oc = o - c;
    let b = oc.dot(d);
    // Discriminant as a (r² − |oc − (b/a) d|²), precise far from the sphere (Haines et al.
    // 2019, "Precision improvements for ray/sphere intersection").
    let closest = oc - d * (b / a);
    let discriminant = a * (r * r - closest.length_squared());
    if discriminant < 0.0 {
        return None;
    }
    let q = -(b + discriminant.sqrt().copysign(b));
    let c = oc.length_squared() - r * r;
    let (t0, t1) = (c / q, q / a);
    Some(t0.min(t1))
}

/// The entry of the ray o + t d into the round cone between spheres (a, ra) and (b, rb), with
/// the sweep parameter of the point; None when the ray misses it or starts inside it.
///
/// The hull is the union of the two spheres and the frustum of the cone tangent to both, so the
/// entry is the nearest of the three entries. With q = o + t d − a, y = q·(b − a), m = |b − a|²
/// and δ = ra − rb, the cone (derived from ρ cos θ + x sin θ = ra) is
/// (m − δ²)(m |q|² − y²) = (ra m − δ y)², ra m − δ y ≥ 0, a quadratic in t; its frustum is
/// ra δ ≤ y ≤ m + rb δ, where it touches the spheres.
fn round_cone_entry(
    o: DVec3,
    d: DVec3,
    a: DVec3,
    ra: f64,
    b: DVec3,
    rb: f64,
) -> Option<(f64, f64)> {
    if d.length_squared() == 0.0 || inside_round_cone(o, a, ra, b, rb) {
        return None;
    }
    let mut best: Option<f64> = None;
    let mut keep = |t: f64| {
        if t > 0.0 && best.is_none_or(|b| t < b) {
            best = Some(t);
        }
    };
    if let Some(t) = sphere_entry(o, d, a, ra) {
        keep(t);
    }
    if let Some(t) = sphere_entry(o, d, b, rb) {
        keep(t);
    }
    if !degenerate(a, ra, b, rb) {
        let ba = b - a;
        let oa = o - a;
        let m0 = ba.length_squared();
        let rr = ra - rb;
        let d2 = m0 - rr * rr;
        let (m1, m2) = (ba.dot(oa), ba.dot(d));
        let (m3, m5, dd) = (d.dot(oa), oa.length_squared(), d.length_squared());
        let e = ra * m0 - m1 * rr;
        let qa = d2 * (m0 * dd - m2 * m2) - m2 * m2 * rr * rr;
        let qb = d2 * (m0 * m3 - m1 * m2) + m2 * rr * e;
        let qc = d2 * (m0 * m5 - m1 * m1) - e * e;
        let discriminant = qb * qb - qa * qc;
        if qa != 0.0 && discriminant >= 0.0 {
            let root = discriminant.sqrt();
            for t in [(-qb - root) / qa, (-qb + root) / qa] {
                let y = m1 + t * m2;
                let on_nappe = e - t * m2 * rr >= 0.0;
                if on_nappe && y >= ra * rr && y <= m0 + rb * rr {
                    keep(t);
                }
            }
        }
    }
    let t = best?;
    Some((t, sweep_parameter(o + d * t, a, ra, b, rb)))
}

impl Curve for LinearCurve {
    fn segments(&self) -> Segments<'_> {
        Segments::Linear(self)
    }

    /// The segment named, if the ray hits it at `t`; else the one the ray hits first.
    fn hit_interaction(&self, ray: &Ray, segment: u32, t: f32, index: u32) -> SurfaceInteraction {
        let (o, d) = (ray.o, ray.d);
        let named = self
            .intersect_segment(segment as usize, o, d, f32::INFINITY)
            .is_some_and(|h| h.t == t);
        let segment = if named {
            segment
        } else {
            self.intersect(o, d, f32::INFINITY)
                .map_or(segment, |(found, _)| found as u32)
        };
        self.segment_interaction(o, d, t, segment, index)
    }

    /// Bytes of heap memory of the control points and segment indices.
    fn storage_bytes(&self) -> usize {
        self.points.capacity() * std::mem::size_of::<Vec4>()
            + self.segments.capacity() * std::mem::size_of::<u32>()
    }
}
