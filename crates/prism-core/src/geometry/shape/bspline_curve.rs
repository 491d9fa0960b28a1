//! Mitsuba's `bsplinecurve` shape (`src/shapes/bsplinecurve.cpp`, Embree's "round B-spline"
//! curves): uniform cubic B-splines of control points (position, radius). A curve of n points
//! has n − 3 segments; segment i, over points i … i + 3, has the centre c(s) and radius r(s)
//! of the uniform cubic B-spline at s ∈ [0, 1], and its surface is the sweep of the circle of
//! radius r(s) around c(s) in the plane orthogonal to the tangent c′(s): the points p with
//!
//! (p − c(s)) · c′(s) = 0 and |p − c(s)| = r(s) for some s ∈ [0, 1],
//!
//! the two conditions Embree's sweep intersector solves (`curve_intersector_sweep.h`). The
//! tube is open at the curve's ends (no caps) and, as with Embree and Mitsuba, back faces are
//! culled: only hits where the ray enters the tube count.
//!
//! Intersection (after Embree, and Nakamaru & Ohno 2002, "Ray tracing for curves primitive"):
//! each segment, written as a cubic Bézier curve, is subdivided recursively; a piece whose
//! bounding cylinder the ray misses is dropped; a piece flat enough (or deep enough) is
//! approximated by the truncated cone between its end circles, whose exact ray intersections
//! start a Newton iteration on the two conditions above in (s, t).
//!
//! Positions are in world space (the scene reader applies `to_world` to them); radii are not
//! transformed, as in Mitsuba. Each segment is one primitive of the hierarchy.
//!
//! Normal, (u, v) and derivatives as Mitsuba 3.9.1's: with R = p − c(s),
//! n ∝ (|c′|² − R · c″) R − r r′ c′ (the gradient of |p − c(s(p))| − r(s(p)), s(p) the
//! parameter of p's cross section); v = (s + i)/N over the N segments of the shape and u the
//! angle of R around the tangent over 2π (Mitsuba's frame, as `linearcurve`'s);
//! ∂p/∂u = 2π r t̂ × R̂ and ∂p/∂v = N (c′ + r′ R̂).

use std::f64::consts::TAU;

use glam::{DVec3, DVec4, Vec2, Vec3, Vec4};

pub use super::curve::SegmentHit;
use super::curve::nearest_hit;
use super::linear_curve::local_frame;
use super::{Curve, Segments};
use crate::geometry::interaction::{AttributeValues, SurfaceInteraction};
use crate::math::Frame;
use crate::math::Ray;

/// Subdivision depth at which a piece is intersected whatever its flatness.
const MAX_DEPTH: u32 = 6;
/// Newton iterations per start.
const NEWTON_ITERATIONS: usize = 16;
/// How far past its end a segment's parameter may be to count as a hit at an inner joint, so
/// that the two segments meeting there leave no crack between them.
const JOINT_SLACK: f64 = 1e-7;

/// A set of round uniform cubic B-spline curves, one primitive per segment.
#[derive(Clone, Debug)]
pub struct BSplineCurve {
    /// Each segment's cubic Bézier control points (position in xyz, radius in w).
    segments: Vec<[Vec4; 4]>,
    /// Per segment: whether it starts a curve and whether it ends one (open ends).
    ends: Vec<(bool, bool)>,
}

/// The centre-line of a segment and its derivatives at a parameter, in double precision.
struct Point {
    c: DVec3,
    dc: DVec3,
    ddc: DVec3,
    r: f64,
    dr: f64,
}

/// Bézier control points of one segment (or a piece of it), relative to the ray origin.
#[derive(Clone, Copy)]
struct Bezier([DVec4; 4]);

impl Bezier {
    /// The centre, radius and their derivatives at s (Bernstein form).
    fn eval(&self, s: f64) -> Point {
        let [b0, b1, b2, b3] = self.0;
        let m = 1.0 - s;
        let p =
            b0 * (m * m * m) + b1 * (3.0 * m * m * s) + b2 * (3.0 * m * s * s) + b3 * (s * s * s);
        let dp = ((b1 - b0) * (m * m) + (b2 - b1) * (2.0 * m * s) + (b3 - b2) * (s * s)) * 3.0;
        let ddp = ((b2 - b1 * 2.0 + b0) * m + (b3 - b2 * 2.0 + b1) * s) * 6.0;
        Point {
            c: p.truncate(),
            dc: dp.truncate(),
            ddc: ddp.truncate(),
            r: p.w,
            dr: dp.w,
        }
    }

    /// The two halves (de Casteljau at 1/2).
    fn split(&self) -> (Bezier, Bezier) {
        let [b0, b1, b2, b3] = self.0;
        let (m01, m12, m23) = ((b0 + b1) * 0.5, (b1 + b2) * 0.5, (b2 + b3) * 0.5);
        let (m012, m123) = ((m01 + m12) * 0.5, (m12 + m23) * 0.5);
        let mid = (m012 + m123) * 0.5;
        (Bezier([b0, m01, m012, mid]), Bezier([mid, m123, m23, b3]))
    }
}

/// The uniform cubic B-spline segment over p0 … p3 as a cubic Bézier curve of the same
/// parameter (Prautzsch, Boehm & Paluszny 2002, "Bézier and B-Spline Techniques", §7).
fn bspline_to_bezier(p: [Vec4; 4]) -> [Vec4; 4] {
    [
        (p[0] + 4.0 * p[1] + p[2]) / 6.0,
        (2.0 * p[1] + p[2]) / 3.0,
        (p[1] + 2.0 * p[2]) / 3.0,
        (p[1] + 4.0 * p[2] + p[3]) / 6.0,
    ]
}

impl BSplineCurve {
    /// Curves from their control points, `curves` giving each curve's first point index; each
    /// curve runs to the next one's first point (the last to the end). None when a curve has
    /// fewer than four points, an index is out of order, or a radius is negative or not finite.
    pub fn new(points: &[Vec4], curves: &[u32]) -> Option<BSplineCurve> {
        if points.iter().any(|p| !p.is_finite() || p.w < 0.0) || curves.is_empty() {
            return None;
        }
        let mut segments = Vec::new();
        let mut ends = Vec::new();
        for (i, &first) in curves.iter().enumerate() {
            let end = curves.get(i + 1).copied().unwrap_or(points.len() as u32);
            if end < first.checked_add(4)? || end as usize > points.len() {
                return None;
            }
            for j in first..end - 3 {
                let j = j as usize;
                let control = [points[j], points[j + 1], points[j + 2], points[j + 3]];
                segments.push(bspline_to_bezier(control));
                ends.push((j == first as usize, j + 4 == end as usize));
            }
        }
        Some(BSplineCurve { segments, ends })
    }

    /// The number of segments (primitives of the hierarchy).
    pub fn segment_count(&self) -> usize {
        self.segments.len()
    }

    /// The bounds of segment `i`: the box of its Bézier control points (which holds the
    /// centre-line) grown by the largest Bézier radius (which bounds the radius).
    pub fn segment_bounds(&self, i: usize) -> (Vec3, Vec3) {
        let b = &self.segments[i];
        let r = b.iter().fold(0.0f32, |r, p| r.max(p.w));
        let lo = b.iter().fold(Vec3::INFINITY, |lo, p| lo.min(p.truncate()));
        let hi = b
            .iter()
            .fold(Vec3::NEG_INFINITY, |hi, p| hi.max(p.truncate()));
        (lo - r, hi + r)
    }

    /// Segment `i` relative to the point `o`, in double precision.
    fn relative(&self, i: usize, o: Vec3) -> Bezier {
        let o = o.as_dvec3().extend(0.0);
        Bezier(self.segments[i].map(|p| p.as_dvec4() - o))
    }

    /// The nearest front-face hit in (0, t_max) on segment `i`.
    pub fn intersect_segment(&self, i: usize, o: Vec3, d: Vec3, t_max: f32) -> Option<SegmentHit> {
        let d = d.as_dvec3();
        if d.length_squared() == 0.0 {
            return None;
        }
        let curve = self.relative(i, o);
        let (starts, ends) = self.ends[i];
        let range = (
            if starts { 0.0 } else { -JOINT_SLACK },
            if ends { 1.0 } else { 1.0 + JOINT_SLACK },
        );
        let mut search = Search {
            curve,
            d,
            range,
            best: f64::from(t_max),
            s: 0.0,
        };
        search.piece(&curve, 0.0, 1.0, 0);
        (search.best < f64::from(t_max)).then(|| SegmentHit {
            t: search.best as f32,
            s: search.s.clamp(0.0, 1.0) as f32,
        })
    }

    /// The nearest hit in (0, t_max) over all segments, with its segment.
    pub fn intersect(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<(usize, SegmentHit)> {
        nearest_hit(self.segments.len(), t_max, |i, limit| {
            self.intersect_segment(i, o, d, limit)
        })
    }
}

/// The (unnormalised) normal of the tube at a point `offset` = p − c(s) from the centre of its
/// cross section: (|c′|² − R · c″) R − r r′ c′.
fn normal(at: &Point, offset: DVec3) -> DVec3 {
    (at.dc.length_squared() - offset.dot(at.ddc)) * offset - at.r * at.dr * at.dc
}

/// The search for the nearest hit on one segment, the ray starting at the origin.
struct Search {
    /// The whole segment.
    curve: Bezier,
    d: DVec3,
    /// The parameters that count as on the segment.
    range: (f64, f64),
    /// The nearest hit so far (t_max before any) and its parameter.
    best: f64,
    s: f64,
}

impl Search {
    /// Searches the piece `b` of the segment over parameters [s0, s1].
    fn piece(&mut self, b: &Bezier, s0: f64, s1: f64, depth: u32) {
        let [b0, b1, b2, b3] = b.0;
        let (a, e) = (b0.truncate(), b3.truncate());
        let axis = e - a;
        let length = axis.length();
        // The piece's centre-line lies in the hull of its control points: within `deviation`
        // of the chord's line, between the planes across it at `z_range` along it.
        let unit = if length > 0.0 {
            axis / length
        } else {
            DVec3::X
        };
        let (mut deviation, mut z_range) = (0.0f64, (0.0f64, length));
        for p in [b1, b2] {
            let q = p.truncate() - a;
            let z = q.dot(unit);
            deviation = deviation.max((q - unit * z).length());
            z_range = (z_range.0.min(z), z_range.1.max(z));
        }
        let radius = b0.w.max(b1.w).max(b2.w).max(b3.w);
        let bound = radius + deviation;
        let slab = (z_range.0 - radius, z_range.1 + radius);
        if !meets_cylinder(self.d, a, unit, slab, bound, self.best) {
            return;
        }
        let flat = deviation <= 0.05 * b0.w.min(b3.w).max(1e-6 * length);
        if depth < MAX_DEPTH && !(flat && depth >= 2) {
            let (left, right) = b.split();
            let mid = 0.5 * (s0 + s1);
            // The nearer half first, so that the farther one may be culled.
            let centre = |h: &Bezier| (h.0[0] + h.0[3]).truncate().dot(self.d);
            let near_left = centre(&left) <= centre(&right);
            if near_left {
                self.piece(&left, s0, mid, depth + 1);
                self.piece(&right, mid, s1, depth + 1);
            } else {
                self.piece(&right, mid, s1, depth + 1);
                self.piece(&left, s0, mid, depth + 1);
            }
            return;
        }
        let cone = cone_hits(self.d, a, b0.w, e, b3.w);
        for &(t, z) in cone.iter().flatten() {
            self.newton(s0 + (s1 - s0) * z.clamp(0.0, 1.0), t);
        }
        if cone.iter().all(Option::is_none) {
            // A ray that grazes the tube may miss the cone: start also where it passes closest
            // to the piece's ends and middle.
            for s in [s0, 0.5 * (s0 + s1), s1] {
                let c = self.curve.eval(s).c;
                self.newton(s, c.dot(self.d) / self.d.length_squared());
            }
        }
    }

    /// Newton's iteration from (s, t) on Embree's pair f = R · t̂ = 0 (R = t d − c(s) in the
    /// cross section) and g = √(|R|² − f²) − r = 0 (R as long as the radius); keeps a
    /// converged front-facing root nearer than the best.
    fn newton(&mut self, mut s: f64, mut t: f64) {
        let d = self.d;
        for _ in 0..NEWTON_ITERATIONS {
            let at = self.curve.eval(s);
            let speed = at.dc.length();
            if speed == 0.0 {
                return;
            }
            let tangent = at.dc / speed;
            let dtangent = (at.ddc - tangent * tangent.dot(at.ddc)) / speed;
            let offset = d * t - at.c;
            let f = offset.dot(tangent);
            let (fs, ft) = (offset.dot(dtangent) - speed, d.dot(tangent));
            let k = (offset.length_squared() - f * f).max(0.0);
            if k == 0.0 {
                return;
            }
            let root = k.sqrt();
            let g = root - at.r;
            let gs = (-offset.dot(at.dc) - f * fs) / root - at.dr;
            let gt = (offset.dot(d) - f * ft) / root;
            let det = fs * gt - ft * gs;
            if det == 0.0 || !det.is_finite() {
                return;
            }
            let ds = (f * gt - ft * g) / det;
            let dt = (fs * g - f * gs) / det;
            s -= ds;
            t -= dt;
            if !(t.is_finite() && (-0.5..=1.5).contains(&s)) {
                return;
            }
            if ds.abs() < 1e-12 && dt.abs() <= 1e-12 * t.abs().max(1e-6) {
                break;
            }
        }
        let at = self.curve.eval(s);
        let offset = d * t - at.c;
        let speed = at.dc.length();
        if speed == 0.0 {
            return;
        }
        let along = offset.dot(at.dc) / speed;
        let across = (offset.length_squared() - along * along).max(0.0).sqrt();
        let scale = at.r + speed;
        let on_surface = along.abs() <= 1e-6 * scale && (across - at.r).abs() <= 1e-6 * scale;
        let front = normal(&at, offset).dot(d) < 0.0;
        if on_surface && front && t > 0.0 && t < self.best && s >= self.range.0 && s <= self.range.1
        {
            self.best = t;
            self.s = s;
        }
    }
}

/// Whether the ray t d, t in (0, t_max), meets the cylinder of radius `radius` around the
/// line through `a` along the unit vector `unit`, between the planes across it at `slab` along
/// it.
fn meets_cylinder(
    d: DVec3,
    a: DVec3,
    unit: DVec3,
    slab: (f64, f64),
    radius: f64,
    t_max: f64,
) -> bool {
    let (mut t0, mut t1) = (0.0f64, t_max);
    // The slab: slab.0 ≤ (t d − a) · unit ≤ slab.1.
    let (dz, az) = (d.dot(unit), a.dot(unit));
    if dz == 0.0 {
        if -az < slab.0 || -az > slab.1 {
            return false;
        }
    } else {
        let (ta, tb) = ((az + slab.0) / dz, (az + slab.1) / dz);
        t0 = t0.max(ta.min(tb));
        t1 = t1.min(ta.max(tb));
    }
    // The infinite cylinder: |w(t)|² ≤ radius², w the part of t d − a across the axis.
    let dw = d - unit * dz;
    let aw = a - unit * az;
    let qa = dw.length_squared();
    let qb = -dw.dot(aw);
    let qc = aw.length_squared() - radius * radius;
    if qa == 0.0 {
        if qc > 0.0 {
            return false;
        }
    } else {
        let discriminant = qb * qb - qa * qc;
        if discriminant < 0.0 {
            return false;
        }
        let root = discriminant.sqrt();
        t0 = t0.max((-qb - root) / qa);
        t1 = t1.min((-qb + root) / qa);
    }
    t0 <= t1
}

/// The ray's hits (t, z) with the truncated cone whose cross sections orthogonal to the axis
/// from `a` (radius `ra`) to `b` (radius `rb`) are circles of linearly varying radius, z in
/// [0, 1] the fraction of the axis; open ends.
fn cone_hits(d: DVec3, a: DVec3, ra: f64, b: DVec3, rb: f64) -> [Option<(f64, f64)>; 2] {
    let axis = b - a;
    let length = axis.length();
    if length == 0.0 {
        return [None; 2];
    }
    let unit = axis / length;
    // With q = t d − a and z = q · unit: |q|² − z² = ρ(z)², ρ = ra + k z = α + β t.
    let k = (rb - ra) / length;
    let (dz, az) = (d.dot(unit), a.dot(unit));
    let (alpha, beta) = (ra - k * az, k * dz);
    let qa = d.length_squared() - dz * dz - beta * beta;
    let qb = -d.dot(a) + dz * az - alpha * beta;
    let qc = a.length_squared() - az * az - alpha * alpha;
    let discriminant = qb * qb - qa * qc;
    if qa == 0.0 || discriminant < 0.0 {
        return [None; 2];
    }
    let root = discriminant.sqrt();
    [(-qb - root) / qa, (-qb + root) / qa].map(|t| {
        let z = (t * dz - az) / length;
        (alpha + beta * t >= 0.0 && (-0.5..=1.5).contains(&z)).then_some((t, z))
    })
}

impl Curve for BSplineCurve {
    fn segments(&self) -> Segments<'_> {
        Segments::BSpline(self)
    }

    /// The segment's parameter is found again by intersecting the segment; a hit that names no
    /// segment the ray meets at `t` is found on all of them.
    fn hit_interaction(&self, ray: &Ray, segment: u32, t: f32, index: u32) -> SurfaceInteraction {
        let (o, d) = (ray.o, ray.d);
        let near = |h: &SegmentHit| (h.t - t).abs() <= 1e-4 * t.abs().max(1e-3);
        let named = ((segment as usize) < self.segments.len())
            .then(|| self.intersect_segment(segment as usize, o, d, f32::INFINITY))
            .flatten()
            .filter(near);
        let (i, s) = match named {
            Some(hit) => (segment as usize, hit.s),
            None => (0..self.segments.len())
                .filter_map(|i| {
                    let hit = self.intersect_segment(i, o, d, f32::INFINITY)?;
                    Some((i, hit))
                })
                .min_by(|a, b| (a.1.t - t).abs().total_cmp(&(b.1.t - t).abs()))
                .map_or((0, 0.5), |(i, hit)| (i, hit.s)),
        };
        let curve = self.relative(i, Vec3::ZERO);
        let at = curve.eval(f64::from(s));
        let tangent = at.dc.normalize_or(DVec3::Z);
        let p = (o + d * t).as_dvec3();
        let offset = p - at.c;
        let radial =
            (offset - tangent * offset.dot(tangent)).normalize_or(tangent.any_orthonormal_vector());
        let n = normal(&at, offset).normalize_or(radial);
        let (u_rot, u_rad) = local_frame(tangent);
        let mut phi = radial.dot(u_rot).atan2(radial.dot(u_rad));
        if phi < 0.0 {
            phi += TAU;
        }
        let count = self.segments.len() as f64;
        let dp_du = (TAU * at.r * tangent.cross(radial)).as_vec3();
        let dp_dv = (count * (at.dc + at.dr * radial)).as_vec3();
        let n = n.as_vec3();
        SurfaceInteraction {
            p: (at.c + radial * at.r).as_vec3(),
            t,
            n,
            shading: Frame::from_normal_and_tangent(n, dp_du),
            uv: Vec2::new(
                (phi / TAU) as f32,
                ((f64::from(s) + i as f64) / count) as f32,
            ),
            dp_du,
            dp_dv,
            shape: index,
            primitive: i as u32,
            time: 0.0,
            attributes: AttributeValues::default(),
        }
    }

    /// Bytes of heap memory of the segments.
    fn storage_bytes(&self) -> usize {
        self.segments.capacity() * std::mem::size_of::<[Vec4; 4]>()
            + self.ends.capacity() * std::mem::size_of::<(bool, bool)>()
    }
}
