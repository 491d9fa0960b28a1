//! The `bsplinecurve` shape (round uniform cubic B-spline curves): ray intersection against
//! closed forms (a straight curve of constant radius is an open cylinder, of linear radius an
//! open cone) with normals, (u, v) and derivatives as Mitsuba 3.9.1 reports them, against an
//! independent reference (a dense triangle mesh of the same tube), open ends and back-face
//! culling, and the hierarchy's per-segment primitives against a brute-force loop.

use std::f32::consts::PI;

use glam::{DVec3, Vec3, Vec4};
use prism_core::geometry::Shape;
use prism_core::geometry::aggregate::Aggregate;
use prism_core::geometry::shape::{BSplineCurve, Curve, TriangleMesh};
use prism_core::math::Ray;
use prism_core::sampling::rng::Pcg32;

fn ray(o: Vec3, d: Vec3) -> Ray {
    Ray {
        o,
        d,
        t_max: f32::INFINITY,
        time: 0.0,
    }
}

fn uniform_direction(rng: &mut Pcg32) -> Vec3 {
    let z = 1.0 - 2.0 * rng.next_f32();
    let phi = 2.0 * PI * rng.next_f32();
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// The straight curve along z of `probe.py`'s first file: five points z = −1 … 3, radius 0.5;
/// its two segments run from z = 0 to 1 and 1 to 2.
fn straight_cylinder() -> BSplineCurve {
    let points: Vec<Vec4> = (0..5)
        .map(|k| Vec4::new(0.0, 0.0, k as f32 - 1.0, 0.5))
        .collect();
    BSplineCurve::new(&points, &[0]).unwrap()
}

#[test]
fn a_straight_curve_of_constant_radius_is_an_open_cylinder() {
    let curve = straight_cylinder();
    assert_eq!(curve.segment_count(), 2);
    // Onto the side from +x at z = 0.5: t = 5 − 0.5, segment 0 at s = 1/2, so v = 1/4; Mitsuba
    // 3.9.1 reports n = +x, uv = (0, 0.25), ∂p/∂u = (0, π, 0), ∂p/∂v = (0, 0, 2).
    let o = Vec3::new(5.0, 0.0, 0.5);
    let (segment, hit) = curve.intersect(o, -Vec3::X, f32::INFINITY).unwrap();
    assert_eq!(segment, 0);
    assert!((hit.t - 4.5).abs() < 1e-6, "{hit:?}");
    assert!((hit.s - 0.5).abs() < 1e-6, "{hit:?}");
    let si = curve.hit_interaction(&ray(o, -Vec3::X), 0, hit.t, 7);
    assert!(si.n.abs_diff_eq(Vec3::X, 1e-6), "{}", si.n);
    assert!(si.p.abs_diff_eq(Vec3::new(0.5, 0.0, 0.5), 1e-6), "{}", si.p);
    assert!(
        si.uv.abs_diff_eq(glam::Vec2::new(0.0, 0.25), 1e-6),
        "{}",
        si.uv
    );
    assert!(
        si.dp_du.abs_diff_eq(Vec3::new(0.0, PI, 0.0), 1e-5),
        "{}",
        si.dp_du
    );
    assert!(
        si.dp_dv.abs_diff_eq(Vec3::new(0.0, 0.0, 2.0), 1e-5),
        "{}",
        si.dp_dv
    );
    assert_eq!((si.shape, si.primitive), (7, 0));
    // From +y at z = 1.2 (segment 1, s = 0.2): Mitsuba's u = 1/4 there, ∂p/∂u = (−π, 0, 0).
    let o = Vec3::new(0.0, 5.0, 1.2);
    let (segment, hit) = curve.intersect(o, -Vec3::Y, f32::INFINITY).unwrap();
    assert_eq!(segment, 1);
    assert!((hit.t - 4.5).abs() < 1e-6, "{hit:?}");
    let si = curve.hit_interaction(&ray(o, -Vec3::Y), 1, hit.t, 0);
    assert!(si.n.abs_diff_eq(Vec3::Y, 1e-6), "{}", si.n);
    assert!(
        si.uv.abs_diff_eq(glam::Vec2::new(0.25, 0.6), 1e-6),
        "{}",
        si.uv
    );
    assert!(
        si.dp_du.abs_diff_eq(Vec3::new(-PI, 0.0, 0.0), 1e-5),
        "{}",
        si.dp_du
    );
    // From −y: u = 3/4.
    let o = Vec3::new(0.0, -5.0, 1.2);
    let (_, hit) = curve.intersect(o, Vec3::Y, f32::INFINITY).unwrap();
    let si = curve.hit_interaction(&ray(o, Vec3::Y), 1, hit.t, 0);
    assert!((si.uv.x - 0.75).abs() < 1e-6, "{}", si.uv);
    // Oblique: the exact entry into the cylinder x² + y² = 1/4.
    let o = Vec3::new(2.0, 1.0, -0.5);
    let d = Vec3::new(-1.0, -0.3, 0.4).normalize();
    let (_, hit) = curve.intersect(o, d, f32::INFINITY).unwrap();
    let (a, b, c) = (
        d.x * d.x + d.y * d.y,
        o.x * d.x + o.y * d.y,
        o.x * o.x + o.y * o.y - 0.25,
    );
    let t = (-b - (b * b - a * c).sqrt()) / a;
    assert!((hit.t - t).abs() < 1e-5, "{} vs {t}", hit.t);
    // A hit exactly at the joint of the two segments is found (no crack).
    for k in 0..=200 {
        let z = 0.99 + 0.0001 * k as f32;
        assert!(
            curve
                .intersect(Vec3::new(3.0, 0.2, z), -Vec3::X, f32::INFINITY)
                .is_some(),
            "crack at z = {z}"
        );
    }
}

#[test]
fn the_tube_is_open_at_its_ends_and_culls_back_faces() {
    let curve = straight_cylinder();
    // Along the axis, from beyond either end: no caps (Mitsuba 3.9.1 misses too).
    assert!(
        curve
            .intersect(Vec3::new(0.0, 0.0, 10.0), -Vec3::Z, f32::INFINITY)
            .is_none()
    );
    assert!(
        curve
            .intersect(Vec3::new(0.2, 0.0, -10.0), Vec3::Z, f32::INFINITY)
            .is_none()
    );
    // Beside the tube past its ends (z < 0, z > 2): nothing.
    for z in [-0.2f32, 2.2] {
        assert!(
            curve
                .intersect(Vec3::new(5.0, 0.0, z), -Vec3::X, f32::INFINITY)
                .is_none()
        );
    }
    // From inside, in any direction: the exit is a back face.
    let mut rng = Pcg32::new(9, 1);
    for _ in 0..1000 {
        let d = uniform_direction(&mut rng);
        let o = Vec3::new(0.1, -0.2, 1.0);
        assert!(curve.intersect(o, d, f32::INFINITY).is_none(), "{d}");
    }
    // A ray entering through the open end sees only the far side's outside, never the inside.
    let o = Vec3::new(0.0, 0.0, 4.0);
    let d = Vec3::new(0.3, 0.0, -1.0).normalize();
    assert!(curve.intersect(o, d, f32::INFINITY).is_none());
    // t_max limits the hit.
    let o = Vec3::new(5.0, 0.0, 0.5);
    assert!(curve.intersect(o, -Vec3::X, 4.4).is_none());
    assert!(curve.intersect(o, -Vec3::X, 4.6).is_some());
}

#[test]
fn a_straight_curve_of_linear_radius_is_a_cone_as_in_mitsuba() {
    // `probe.py`'s two-curve file scaled by 2 (points scaled, radii not): a cylinder of radius
    // 0.5 at x = 0 and, at x = 6, a cone whose radius grows 0.2 … 0.6 over points z = −2 … 6,
    // so r(z) = 0.3 + 0.05 z on its segments (z in 0 … 4). Three segments in all.
    let mut points: Vec<Vec4> = (0..4)
        .map(|k| Vec4::new(0.0, 0.0, 2.0 * k as f32 - 2.0, 0.5))
        .collect();
    points.extend((0..5).map(|k| Vec4::new(6.0, 0.0, 2.0 * k as f32 - 2.0, 0.2 + 0.1 * k as f32)));
    let curve = BSplineCurve::new(&points, &[0, 4]).unwrap();
    assert_eq!(curve.segment_count(), 3);
    // Mitsuba 3.9.1 from (16, 0, 1) along −x: t = 9.65, p = (6.35, 0, 1),
    // n = (0.998752, 0, −0.0499377), uv = (0, 0.5), ∂p/∂u = (0, 2.19911, 0),
    // ∂p/∂v = (0.3, 0, 6), primitive 1; from (16, 0, 3): t = 9.55, uv = (0, 0.833333),
    // ∂p/∂u = (0, 2.82743, 0), primitive 2.
    for (z, t, v, dpdu, primitive) in [
        (1.0f32, 9.65f32, 0.5f32, 2.19911f32, 1u32),
        (3.0, 9.55, 0.833333, 2.82743, 2),
    ] {
        let o = Vec3::new(16.0, 0.0, z);
        let (segment, hit) = curve.intersect(o, -Vec3::X, f32::INFINITY).unwrap();
        assert_eq!(segment as u32, primitive);
        // The closed form: x = 6 + r(z).
        assert!((hit.t - (10.0 - (0.3 + 0.05 * z))).abs() < 1e-5, "{hit:?}");
        assert!((hit.t - t).abs() < 1e-5, "{hit:?}");
        let si = curve.hit_interaction(&ray(o, -Vec3::X), segment as u32, hit.t, 0);
        // The cone's normal: (1, 0, −r′) normalised with r′ = dr/dz = 0.05.
        let n = Vec3::new(1.0, 0.0, -0.05).normalize();
        assert!(si.n.abs_diff_eq(n, 1e-5), "{}", si.n);
        assert!(si.n.abs_diff_eq(Vec3::new(0.998752, 0.0, -0.0499377), 1e-5));
        assert!(
            si.uv.abs_diff_eq(glam::Vec2::new(0.0, v), 1e-5),
            "{}",
            si.uv
        );
        assert!(
            si.dp_du.abs_diff_eq(Vec3::new(0.0, dpdu, 0.0), 1e-4),
            "{}",
            si.dp_du
        );
        assert!(
            si.dp_dv.abs_diff_eq(Vec3::new(0.3, 0.0, 6.0), 1e-4),
            "{}",
            si.dp_dv
        );
        assert_eq!(si.primitive, primitive);
    }
    // Oblique rays onto the cone from outside: the exact entry of x'² + y² = (0.3 + 0.05 z)²
    // (x' = x − 6) within its segments' z range.
    let mut rng = Pcg32::new(21, 4);
    let mut hits = 0;
    for _ in 0..2000 {
        let o = Vec3::new(8.0, rng.next_f32() * 2.0 - 1.0, rng.next_f32() * 6.0 - 1.0);
        let target = Vec3::new(6.0, rng.next_f32() - 0.5, rng.next_f32() * 5.0 - 0.5);
        let d = (target - o).normalize();
        let (od, dd) = (o.as_dvec3() - DVec3::new(6.0, 0.0, 0.0), d.as_dvec3());
        // Short of the cylinder at x = 0.
        let t_max = 5.0 / -d.x;
        // (x² + y²) − (0.3 + 0.05 z)² = 0 along o + t d, in front of the apex (r ≥ 0).
        let k = 0.05;
        let (alpha, beta) = (0.3 + k * od.z, k * dd.z);
        let a = dd.x * dd.x + dd.y * dd.y - beta * beta;
        let b = od.x * dd.x + od.y * dd.y - alpha * beta;
        let c = od.x * od.x + od.y * od.y - alpha * alpha;
        let disc = b * b - a * c;
        let expected = (disc >= 0.0)
            .then(|| (-b - disc.sqrt()) / a)
            .filter(|&t| t > 0.0 && (0.0..=4.0).contains(&(od.z + t * dd.z)))
            .filter(|&t| t < f64::from(t_max));
        let got = curve.intersect(o, d, t_max).map(|(_, h)| f64::from(h.t));
        match (got, expected) {
            (Some(t), Some(e)) => {
                assert!((t - e).abs() < 1e-5, "{o} {d}: {t} vs {e}");
                hits += 1;
            }
            (None, None) => {}
            // A ray grazing an open end may go either way within rounding.
            (Some(t), None) | (None, Some(t)) => {
                let z = od.z + t * dd.z;
                assert!(
                    z.abs() < 1e-4 || (z - 4.0).abs() < 1e-4,
                    "{o} {d}: {got:?} {expected:?}"
                );
            }
        }
    }
    assert!(hits > 500, "{hits} hits");
}

/// Control points of a bent, tapering curve of three segments.
fn bent_curve_points() -> Vec<Vec4> {
    vec![
        Vec4::new(-1.2, -0.3, 0.0, 0.12),
        Vec4::new(-0.6, 0.4, 0.3, 0.2),
        Vec4::new(0.0, -0.2, 0.6, 0.3),
        Vec4::new(0.5, 0.3, 0.2, 0.22),
        Vec4::new(1.1, 0.0, -0.3, 0.15),
        Vec4::new(1.4, -0.6, 0.1, 0.1),
    ]
}

/// The centre, tangent and radius of the uniform cubic B-spline over `p` at s, from its basis
/// functions (independently of the shape's Bézier form).
fn bspline(p: &[Vec4], s: f64) -> (DVec3, DVec3, f64) {
    let m = 1.0 - s;
    let w = [
        m * m * m / 6.0,
        (3.0 * s * s * s - 6.0 * s * s + 4.0) / 6.0,
        (-3.0 * s * s * s + 3.0 * s * s + 3.0 * s + 1.0) / 6.0,
        s * s * s / 6.0,
    ];
    let dw = [
        -m * m / 2.0,
        (3.0 * s * s - 4.0 * s) / 2.0,
        (-3.0 * s * s + 2.0 * s + 1.0) / 2.0,
        s * s / 2.0,
    ];
    let mut c = DVec3::ZERO;
    let mut dc = DVec3::ZERO;
    let mut r = 0.0;
    for k in 0..4 {
        c += p[k].truncate().as_dvec3() * w[k];
        dc += p[k].truncate().as_dvec3() * dw[k];
        r += f64::from(p[k].w) * w[k];
    }
    (c, dc, r)
}

/// A triangle mesh of the tube: `along` rings per segment of `around` vertices each, the
/// circles of radius r(s) orthogonal to the tangent; faces wound outwards.
fn tessellate(points: &[Vec4], along: usize, around: usize) -> TriangleMesh {
    let segments = points.len() - 3;
    let mut positions = Vec::new();
    let mut centres = Vec::new();
    let rings = segments * along + 1;
    // A rotation-minimising frame along the rings (the double reflection of Wang et al. 2008,
    // "Computation of rotation minimizing frames"), so that the quads between rings are not
    // twisted.
    let mut previous: Option<(DVec3, DVec3, DVec3)> = None;
    for ring in 0..rings {
        let (segment, s) = if ring == rings - 1 {
            (segments - 1, 1.0)
        } else {
            (ring / along, (ring % along) as f64 / along as f64)
        };
        let (c, dc, r) = bspline(&points[segment..segment + 4], s);
        let t = dc.normalize();
        let e1 = match previous {
            None => (DVec3::Z - t * t.z).normalize(),
            Some((c0, t0, e0)) => {
                let v1 = c - c0;
                let c1 = v1.length_squared();
                let e_l = e0 - v1 * (2.0 / c1 * v1.dot(e0));
                let t_l = t0 - v1 * (2.0 / c1 * v1.dot(t0));
                let v2 = t - t_l;
                let c2 = v2.length_squared();
                if c2 == 0.0 {
                    e_l
                } else {
                    e_l - v2 * (2.0 / c2 * v2.dot(e_l))
                }
            }
        };
        let e2 = t.cross(e1);
        for k in 0..around {
            let phi = std::f64::consts::TAU * k as f64 / around as f64;
            positions.push((c + r * (phi.cos() * e1 + phi.sin() * e2)).as_vec3());
        }
        centres.push(c);
        previous = Some((c, t, e1));
    }
    let mut triangles = Vec::new();
    for ring in 0..rings - 1 {
        for k in 0..around {
            let a = (ring * around + k) as u32;
            let b = (ring * around + (k + 1) % around) as u32;
            let (c, d) = (a + around as u32, b + around as u32);
            for mut tri in [[a, b, d], [a, d, c]] {
                let [p0, p1, p2] = tri.map(|i| positions[i as usize].as_dvec3());
                let n = (p1 - p0).cross(p2 - p0);
                let centre = (centres[ring] + centres[ring + 1]) * 0.5;
                if n.dot((p0 + p1 + p2) / 3.0 - centre) < 0.0 {
                    tri.swap(1, 2);
                }
                triangles.push(tri);
            }
        }
    }
    TriangleMesh::new(positions, None, None, triangles, false)
}

#[test]
fn a_bent_curve_matches_a_dense_tessellation_of_its_tube() {
    // Rings 1/256 of a segment apart and 128 vertices around: the mesh lies within
    // r (1 − cos(π/128)) < 1e-4 of the tube (plus a negligible sagitta along it), so where the
    // ray meets the surface at an angle with cosine c the distances agree within ~1e-4/c,
    // normals within the facets' angle 2π/128; rays grazing the silhouette may disagree.
    let points = bent_curve_points();
    let curve = BSplineCurve::new(&points, &[0]).unwrap();
    assert_eq!(curve.segment_count(), 3);
    let mesh = Aggregate::new(vec![Shape::Mesh(tessellate(&points, 256, 128))]);
    let tube = Aggregate::new(vec![Shape::BSplineCurve(curve.clone())]);
    let mut rng = Pcg32::new(17, 2);
    let rays = 20_000;
    let (mut hits, mut misses, mut disagreements, mut through_ends) = (0, 0, 0, 0);
    for _ in 0..rays {
        let o = uniform_direction(&mut rng) * 4.0;
        let target = Vec3::new(
            rng.next_f32() * 2.8 - 1.4,
            rng.next_f32() * 1.4 - 0.7,
            rng.next_f32() * 1.2 - 0.5,
        );
        let d = (target - o).normalize();
        let reference = mesh.intersect(&ray(o, d));
        if reference.as_ref().is_some_and(|si| si.n.dot(d) > 0.0) {
            // The mesh's first hit is its inside, seen through an open end: the tube culls it.
            through_ends += 1;
            continue;
        }
        let got = tube.intersect(&ray(o, d));
        match (got, reference) {
            (Some(si), Some(reference)) => {
                hits += 1;
                let cos = reference.n.dot(d).abs();
                if cos > 0.2 {
                    assert!(
                        (si.t - reference.t).abs() < 2e-4 / cos,
                        "{o} {d}: t {} vs the mesh's {}",
                        si.t,
                        reference.t
                    );
                    assert!(
                        si.n.dot(reference.n) > (2.0 * PI / 128.0).cos(),
                        "{o} {d}: n {} vs the mesh's {}",
                        si.n,
                        reference.n
                    );
                    assert!(si.n.dot(d) < 0.0);
                } else if (si.t - reference.t).abs() > 1e-2 {
                    disagreements += 1;
                }
            }
            (None, None) => misses += 1,
            (got, reference) => {
                // Only a ray grazing the surface may hit one and miss the other.
                let n = got.or(reference).unwrap().n;
                assert!(n.dot(d).abs() < 0.2, "{o} {d}: tube {got:?}");
                disagreements += 1;
            }
        }
    }
    assert!(
        hits > 4_000 && misses > 4_000,
        "{hits} hits, {misses} misses"
    );
    assert!(
        through_ends < rays / 20,
        "{through_ends} rays through the ends"
    );
    assert!(
        disagreements * 200 < rays,
        "{disagreements} of {rays} rays disagree with the tessellation"
    );
}

#[test]
fn the_hierarchy_finds_the_segment_a_brute_force_loop_finds() {
    // Two wavy curves of 20 and 17 segments, intersected through the BVH (one primitive per
    // segment) and by a loop over all segments.
    let mut points = Vec::new();
    let mut rng = Pcg32::new(3, 3);
    for k in 0..43 {
        let x = (k % 23) as f32 * 0.15 - 1.6;
        let y = if k % 2 == 0 { 0.15 } else { -0.15 } + if k >= 23 { 0.8 } else { 0.0 };
        points.push(Vec4::new(
            x,
            y,
            rng.next_f32() * 0.3,
            0.02 + 0.05 * rng.next_f32(),
        ));
    }
    let curve = BSplineCurve::new(&points, &[0, 23]).unwrap();
    assert_eq!(curve.segment_count(), 37);
    let aggregate = Aggregate::new(vec![Shape::BSplineCurve(curve.clone())]);
    assert_eq!(aggregate.primitive_count(), 37);
    let mut hits = 0;
    for _ in 0..20_000 {
        let o = Vec3::new(rng.next_f32() * 4.0 - 2.0, -2.0, rng.next_f32() - 0.3);
        let d = (Vec3::new(rng.next_f32() * 4.0 - 2.0, 0.4, 0.15) - o).normalize();
        let expected = curve.intersect(o, d, f32::INFINITY);
        let got = aggregate.closest_hit(&ray(o, d));
        match (got, expected) {
            (Some(hit), Some((_, h))) => {
                assert_eq!(hit.triangle.t, h.t);
                let own = curve.intersect_segment(hit.primitive as usize, o, d, f32::INFINITY);
                assert_eq!(own.map(|h| h.t), Some(h.t));
                let si = aggregate.intersect(&ray(o, d)).unwrap();
                assert_eq!(si.primitive, hit.primitive);
                // A hit named without its segment (as Embree's whole-shape path gives it)
                // finds the same one.
                let again = curve.hit_interaction(&ray(o, d), u32::MAX / 2, h.t, 0);
                assert_eq!(again.uv, si.uv);
                hits += 1;
            }
            (None, None) => {}
            other => panic!("{o} {d}: {other:?}"),
        }
    }
    assert!(hits > 1_000, "{hits} hits");
}

#[test]
fn curves_need_four_points_and_valid_radii() {
    let p = |x: f32, r: f32| Vec4::new(x, 0.0, 0.0, r);
    let four = [p(0.0, 1.0), p(1.0, 1.0), p(2.0, 1.0), p(3.0, 1.0)];
    assert_eq!(BSplineCurve::new(&four, &[0]).unwrap().segment_count(), 1);
    assert!(BSplineCurve::new(&four[..3], &[0]).is_none());
    assert!(BSplineCurve::new(&four, &[0, 2]).is_none());
    assert!(BSplineCurve::new(&four, &[]).is_none());
    let mut bad = four;
    bad[2].w = -1.0;
    assert!(BSplineCurve::new(&bad, &[0]).is_none());
    bad[2].w = f32::NAN;
    assert!(BSplineCurve::new(&bad, &[0]).is_none());
    let seven: Vec<Vec4> = (0..7).map(|k| p(k as f32, 0.5)).collect();
    assert_eq!(BSplineCurve::new(&seven, &[0]).unwrap().segment_count(), 4);
}
