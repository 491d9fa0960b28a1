//! The `linearcurve` shape (round linear curves): ray intersection against closed forms (a
//! capsule, a sphere), against an independent reference (the union of many spheres of the
//! sweep), normals and (u, v) as Mitsuba's, back-face culling, and the hierarchy's
//! per-segment primitives against a brute-force loop over the segments.

use glam::{Vec3, Vec4};
use prism_core::geometry::Shape;
use prism_core::geometry::aggregate::Aggregate;
use prism_core::geometry::shape::LinearCurve;
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
    let phi = 2.0 * std::f32::consts::PI * rng.next_f32();
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// The nearest entry t > 0 of o + t d into the sphere (c, r), in double precision; None from
/// inside or on a miss.
fn sphere_entry(o: Vec3, d: Vec3, c: Vec3, r: f64) -> Option<f64> {
    let (o, d, c) = (o.as_dvec3(), d.as_dvec3(), c.as_dvec3());
    let oc = o - c;
    let a = d.length_squared();
    let b = oc.dot(d);
    let cc = oc.length_squared() - r * r;
    let disc = b * b - a * cc;
    if disc < 0.0 || cc < 0.0 {
        return None;
    }
    let t = (-b - disc.sqrt()) / a;
    (t > 0.0).then_some(t)
}

#[test]
fn a_straight_curve_of_constant_radius_is_a_capsule() {
    // From (0,0,0) to (2,0,0), radius 0.5.
    let curve = LinearCurve::new(
        vec![Vec4::new(0.0, 0.0, 0.0, 0.5), Vec4::new(2.0, 0.0, 0.0, 0.5)],
        &[0],
    )
    .unwrap();
    // Onto the tube from above: t = 3 − 0.5, normal +z, v = s = 0.5 of the single segment.
    let o = Vec3::new(1.0, 0.0, 3.0);
    let (segment, hit) = curve.intersect(o, -Vec3::Z, f32::INFINITY).unwrap();
    assert_eq!(segment, 0);
    assert!((hit.t - 2.5).abs() < 1e-6, "{hit:?}");
    assert!((hit.s - 0.5).abs() < 1e-6, "{hit:?}");
    let si = curve.segment_interaction(o, -Vec3::Z, hit.t, 0, 3);
    assert!(si.n.abs_diff_eq(Vec3::Z, 1e-6), "{}", si.n);
    assert!(si.p.abs_diff_eq(Vec3::new(1.0, 0.0, 0.5), 1e-6), "{}", si.p);
    assert!((si.uv.y - 0.5).abs() < 1e-6, "{}", si.uv);
    // Mitsuba's frame for axis +x: rotation axis +z, radial axis z × x = +y, so the normal +z
    // is at u = 1/4; ∂p/∂u = 2π x̂ × (p − c) = 2π (0, −0.5, 0) and ∂p/∂v = b − a = (2, 0, 0).
    assert!((si.uv.x - 0.25).abs() < 1e-6, "{}", si.uv);
    let two_pi = 2.0 * std::f32::consts::PI;
    assert!(
        si.dp_du
            .abs_diff_eq(Vec3::new(0.0, -0.5 * two_pi, 0.0), 1e-5),
        "{}",
        si.dp_du
    );
    assert!(si.dp_dv.abs_diff_eq(Vec3::new(2.0, 0.0, 0.0), 1e-6));
    assert_eq!(si.shape, 3);
    // Along the axis from x = −3: the spherical end cap around the origin at t = 3 − 0.5.
    let (_, hit) = curve
        .intersect(Vec3::new(-3.0, 0.0, 0.0), Vec3::X, f32::INFINITY)
        .unwrap();
    assert!((hit.t - 2.5).abs() < 1e-6, "{hit:?}");
    assert_eq!(hit.s, 0.0);
    // A slanted ray onto the far cap: closed form of the sphere (2, 0, 0), r = 0.5.
    let o = Vec3::new(4.0, 0.3, 1.0);
    let d = Vec3::new(-1.0, 0.0, -0.45).normalize();
    let expected = sphere_entry(o, d, Vec3::new(2.0, 0.0, 0.0), 0.5).unwrap();
    let (_, hit) = curve.intersect(o, d, f32::INFINITY).unwrap();
    assert!(
        (f64::from(hit.t) - expected).abs() < 1e-5,
        "{hit:?} {expected}"
    );
    // t_max is respected; a ray passing beside the capsule misses.
    assert_eq!(
        curve.intersect(Vec3::new(1.0, 0.0, 3.0), -Vec3::Z, 2.4),
        None
    );
    assert_eq!(
        curve.intersect(Vec3::new(1.0, 0.6, 3.0), -Vec3::Z, f32::INFINITY),
        None
    );
    // Back faces are culled: from inside the tube nothing is hit.
    assert_eq!(
        curve.intersect(Vec3::new(1.0, 0.0, 0.0), Vec3::Z, f32::INFINITY),
        None
    );
}

#[test]
fn capsule_hits_match_the_closed_form_over_random_rays() {
    // Random rays at a capsule of radius r from a to b; the exact entry is the nearest of the
    // two spheres' entries and the cylinder's entry with its foot on the segment.
    let (a, b, r) = (Vec3::new(-0.3, 0.2, 0.1), Vec3::new(0.8, -0.4, 0.5), 0.35);
    let curve = LinearCurve::new(vec![a.extend(r), b.extend(r)], &[0]).unwrap();
    let mut rng = Pcg32::new(21, 7);
    let mut hits = 0;
    for _ in 0..20_000 {
        let o = uniform_direction(&mut rng) * 3.0;
        let target = Vec3::new(
            rng.next_f32() * 2.0 - 1.0,
            rng.next_f32() * 2.0 - 1.0,
            rng.next_f32() * 2.0 - 1.0,
        );
        let d = (target - o).normalize();
        let mut expected = [
            sphere_entry(o, d, a, f64::from(r)),
            sphere_entry(o, d, b, f64::from(r)),
        ]
        .into_iter()
        .flatten()
        .fold(f64::INFINITY, f64::min);
        // Cylinder: |(q − (q·u)u)|² = r² with q = o + t d − a, u the unit axis.
        let (o64, d64, a64) = (o.as_dvec3(), d.as_dvec3(), a.as_dvec3());
        let axis = (b - a).as_dvec3();
        let u = axis.normalize();
        let (oq, dq) = (o64 - a64, d64);
        let (op, dp) = (oq - u * oq.dot(u), dq - u * dq.dot(u));
        let (qa, qb, qc) = (
            dp.length_squared(),
            op.dot(dp),
            op.length_squared() - f64::from(r * r),
        );
        let disc = qb * qb - qa * qc;
        if disc >= 0.0 && qc > 0.0 {
            let t = (-qb - disc.sqrt()) / qa;
            let along = (oq + dq * t).dot(u);
            if t > 0.0 && (0.0..=axis.length()).contains(&along) {
                expected = expected.min(t);
            }
        }
        let got = curve
            .intersect(o, d, f32::INFINITY)
            .map(|(_, h)| f64::from(h.t));
        match got {
            Some(t) => {
                assert!((t - expected).abs() < 1e-5, "{o} {d}: {t} vs {expected}");
                hits += 1;
            }
            None => assert!(
                expected.is_infinite(),
                "{o} {d}: missed, expected {expected}"
            ),
        }
    }
    assert!(
        hits > 5_000,
        "{hits} hits: the rays should often meet the capsule"
    );
}

/// The entry of o + t d into the union of `count` + 1 spheres along the sweep from (a, ra) to
/// (b, rb): the definition of the segment, discretised.
fn sphere_union_entry(o: Vec3, d: Vec3, a: Vec4, b: Vec4, count: usize) -> Option<f64> {
    (0..=count)
        .filter_map(|k| {
            let s = k as f32 / count as f32;
            let c = a.lerp(b, s);
            sphere_entry(o, d, c.truncate(), f64::from(c.w))
        })
        .min_by(f64::total_cmp)
}

#[test]
fn tapered_segments_match_the_union_of_their_spheres() {
    // A cone segment and one where a sphere nearly holds the other. Spheres s apart along the
    // sweep leave between them gaps of depth at most s²/(8 r_min) (the sagitta), so the union's
    // entry lies at most that beyond the hull's, and never before it.
    let count = 2000;
    for (a, b) in [
        (
            Vec4::new(-0.6, 0.1, 0.0, 0.4),
            Vec4::new(0.7, -0.2, 0.3, 0.1),
        ),
        (
            Vec4::new(0.0, 0.0, 0.0, 0.5),
            Vec4::new(0.3, 0.2, -0.1, 0.2),
        ),
    ] {
        let curve = LinearCurve::new(vec![a, b], &[0]).unwrap();
        let spacing = (b - a).truncate().length() / count as f32;
        let r_min = a.w.min(b.w);
        let depth = f64::from(spacing * spacing / (8.0 * r_min));
        let mut rng = Pcg32::new(5, 11);
        let (mut hits, mut disagreements) = (0, 0);
        let rays = 20_000;
        for _ in 0..rays {
            let o = uniform_direction(&mut rng) * 3.0;
            let target = Vec3::new(
                rng.next_f32() - 0.5,
                rng.next_f32() - 0.5,
                rng.next_f32() - 0.5,
            ) * 1.6;
            let d = (target - o).normalize();
            let reference = sphere_union_entry(o, d, a, b, count);
            let got = curve
                .intersect(o, d, f32::INFINITY)
                .map(|(_, h)| f64::from(h.t));
            match (got, reference) {
                (Some(t), Some(t_ref)) => {
                    hits += 1;
                    // The union lies inside the hull: its entry is never nearer.
                    assert!(t <= t_ref + 1e-5, "{o} {d}: {t} beyond the union's {t_ref}");
                    if t_ref - t > depth.max(1e-4) * 100.0 {
                        disagreements += 1;
                    }
                }
                (None, None) => {}
                _ => disagreements += 1,
            }
        }
        assert!(hits > 3_000, "{hits} hits");
        // Only rays grazing the surface within the sagitta band may disagree.
        assert!(
            disagreements * 1000 < rays,
            "{disagreements} of {rays} rays disagree with the union of spheres (depth {depth})"
        );
    }
}

#[test]
fn the_hierarchy_finds_the_segment_a_brute_force_loop_finds() {
    // A zigzag of 40 segments in two curves, intersected through the BVH (one primitive per
    // segment) and by a loop over all segments.
    let mut points = Vec::new();
    let mut rng = Pcg32::new(3, 3);
    for k in 0..42 {
        let x = k as f32 * 0.1 - 2.0;
        let y = if k % 2 == 0 { 0.2 } else { -0.2 };
        points.push(Vec4::new(
            x,
            y,
            rng.next_f32() * 0.3,
            0.02 + 0.05 * rng.next_f32(),
        ));
    }
    let curve = LinearCurve::new(points, &[0, 21]).unwrap();
    assert_eq!(curve.segment_count(), 40);
    let aggregate = Aggregate::new(vec![Shape::LinearCurve(curve.clone())]);
    assert_eq!(aggregate.primitive_count(), 40);
    let mut hits = 0;
    for _ in 0..20_000 {
        let o = Vec3::new(rng.next_f32() * 5.0 - 2.5, 2.0, rng.next_f32() - 0.3);
        let d = (Vec3::new(rng.next_f32() * 5.0 - 2.5, -0.0, 0.15) - o).normalize();
        let expected = curve.intersect(o, d, f32::INFINITY);
        let got = aggregate.closest_hit(&ray(o, d));
        match (got, expected) {
            (Some(hit), Some((_, h))) => {
                // Consecutive segments share their joint sphere, so either may be reported
                // for a hit there; the distance and the reported segment's own hit agree.
                assert_eq!(hit.triangle.t, h.t);
                let own = curve.intersect_segment(hit.primitive as usize, o, d, f32::INFINITY);
                assert_eq!(own.map(|h| h.t), Some(h.t));
                let si = aggregate.intersect(&ray(o, d)).unwrap();
                assert_eq!(si.primitive, hit.primitive);
                hits += 1;
            }
            (None, None) => {}
            other => panic!("{o} {d}: {other:?}"),
        }
    }
    assert!(hits > 1_000, "{hits} hits");
}

#[test]
fn curves_need_two_points_and_valid_radii() {
    let p = |x: f32, r: f32| Vec4::new(x, 0.0, 0.0, r);
    assert!(LinearCurve::new(vec![p(0.0, 1.0)], &[0]).is_none());
    assert!(LinearCurve::new(vec![p(0.0, 1.0), p(1.0, 1.0), p(2.0, 1.0)], &[0, 2]).is_none());
    assert!(LinearCurve::new(vec![p(0.0, -1.0), p(1.0, 1.0)], &[0]).is_none());
    assert!(LinearCurve::new(vec![p(0.0, f32::NAN), p(1.0, 1.0)], &[0]).is_none());
    assert!(LinearCurve::new(vec![p(0.0, 1.0), p(1.0, 1.0)], &[]).is_none());
    assert_eq!(
        LinearCurve::new(vec![p(0.0, 1.0), p(1.0, 1.0), p(2.0, 1.0)], &[0])
            .unwrap()
            .segment_count(),
        2
    );
}
