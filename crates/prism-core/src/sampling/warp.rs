//! Warps from the unit square to other domains. Each comes as a triple: `sample_*` maps
//! u in [0,1)^2 to the domain, `*_pdf` is the density of the result, and `invert_*` maps a point
//! back to the u that produces it (used by tests and, later, by stratified path guiding).

use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, PI};

use glam::{Vec2, Vec3};

use crate::math::lanes::Real;

/// Shirley–Chiu concentric map of the square onto the unit disk (Shirley & Chiu 1997, "A
/// Low Distortion Map Between Disk and Square"); uniform density 1/π.
pub fn sample_uniform_disk_concentric(u: Vec2) -> Vec2 {
    let (x, y) = concentric_disk((u.x, u.y));
    Vec2::new(x, y)
}

/// [`sample_uniform_disk_concentric`] for one lane or for lanes ([`Real`]): the point (x, y)
/// of the disk for u = (u₀, u₁).
#[inline]
pub fn concentric_disk<F: Real>((u0, u1): (F, F)) -> (F, F) {
    let (a, b) = (u0 * 2.0 - 1.0, u1 * 2.0 - 1.0);
    // θ = π/4 · b/a in the wedges about ±x, where the point is a (cos θ, sin θ); in those about
    // ±y, θ = π/2 − π/4 · a/b and the point is b (sin(π/4 · a/b), cos(π/4 · a/b)).
    let about_x = a.abs().gt(b.abs());
    let (r, other) = (F::select(about_x, a, b), F::select(about_x, b, a));
    let (cos, sin) = cos_sin_within_quarter_pi(other / r * FRAC_PI_4);
    let x = r * F::select(about_x, cos, sin);
    let y = r * F::select(about_x, sin, cos);
    // The centre (where other / r is 0/0).
    let zero = F::splat(0.0);
    let centre = a.eq(zero) & b.eq(zero);
    (F::select(centre, zero, x), F::select(centre, zero, y))
}

/// (cos a, sin a) for |a| ≤ π/4 by their Taylor series to a⁸ and a⁹, whose remainders there,
/// a¹⁰/10! ≤ 2.5·10⁻⁸ and a¹¹/11! ≤ 1.8·10⁻⁹, are under half an f32 ulp of the results: no range
/// reduction is needed, which makes this several times cheaper than the library's `sin_cos`.
#[inline]
fn cos_sin_within_quarter_pi<F: Real>(a: F) -> (F, F) {
    let a2 = a * a;
    let cos =
        a2 * (a2 * (a2 * (a2 * (1.0 / 40_320.0) + -1.0 / 720.0) + 1.0 / 24.0) + -1.0 / 2.0) + 1.0;
    let sin = a
        * (a2 * (a2 * (a2 * (a2 * (1.0 / 362_880.0) + -1.0 / 5_040.0) + 1.0 / 120.0) + -1.0 / 6.0)
            + 1.0);
    (cos, sin)
}

/// (cos 2πu, sin 2πu) for u in [0, 1]: 2πu is reduced to the nearest multiple kπ/2 (k = ⌊4u +
/// ½⌋, exact in floats, as is u − k/4), the rest, within ±π/4, goes to
/// [`cos_sin_within_quarter_pi`], and the quarter turns swap and negate the results. Within
/// 4·10⁻⁷ of the exact values, and the same in every lane width, unlike the library's `sin_cos`.
#[inline]
pub fn cos_sin_of_turn<F: Real>(u: F) -> (F, F) {
    let k = (u * 4.0 + 0.5).floor();
    let (cos, sin) = cos_sin_within_quarter_pi((u - k * 0.25) * (2.0 * PI));
    let (quarter, half, three_quarters) = (
        k.eq(F::splat(1.0)),
        k.eq(F::splat(2.0)),
        k.eq(F::splat(3.0)),
    );
    (
        F::select(
            quarter,
            -sin,
            F::select(half, -cos, F::select(three_quarters, sin, cos)),
        ),
        F::select(
            quarter,
            cos,
            F::select(half, -sin, F::select(three_quarters, -cos, sin)),
        ),
    )
}

/// Density of [`sample_uniform_disk_concentric`] per unit area.
pub fn uniform_disk_pdf(p: Vec2) -> f32 {
    if p.length_squared() <= 1.0 {
        FRAC_1_PI
    } else {
        0.0
    }
}

/// Inverse of [`sample_uniform_disk_concentric`].
pub fn invert_uniform_disk_concentric(p: Vec2) -> Vec2 {
    let r = p.length();
    if r == 0.0 {
        return Vec2::splat(0.5);
    }
    let mut phi = p.y.atan2(p.x);
    if phi < -FRAC_PI_4 {
        phi += 2.0 * PI;
    }
    // The four wedges of the square, as in the forward map.
    let (a, b) = if phi < FRAC_PI_4 {
        (r, r * phi / FRAC_PI_4)
    } else if phi < 3.0 * FRAC_PI_4 {
        (-r * (phi - FRAC_PI_2) / FRAC_PI_4, r)
    } else if phi < 5.0 * FRAC_PI_4 {
        (-r, -r * (phi - PI) / FRAC_PI_4)
    } else {
        (r * (phi - 3.0 * FRAC_PI_2) / FRAC_PI_4, -r)
    };
    (Vec2::new(a, b) + Vec2::ONE) * 0.5
}

/// Cosine-weighted hemisphere about +z by Nusselt's analogue (Malley's method): a uniform point
/// (x, y) on the unit disk is lifted to (x, y, sqrt(1 - x² - y²)), giving density cos θ / π.
/// (The lecture's slide writes the lift as 1 - sqrt(x² + y²); that is a slip: docs/architecture.md,
/// The lecture's errata.)
pub fn sample_cosine_hemisphere(u: Vec2) -> Vec3 {
    let (x, y, z) = cosine_hemisphere((u.x, u.y));
    Vec3::new(x, y, z)
}

/// [`sample_cosine_hemisphere`] for one lane or for lanes ([`Real`]).
#[inline]
pub fn cosine_hemisphere<F: Real>(u: (F, F)) -> (F, F, F) {
    let (x, y) = concentric_disk(u);
    let z = (F::splat(1.0) - (x * x + y * y)).max(F::splat(0.0)).sqrt();
    (x, y, z)
}

/// Density of [`sample_cosine_hemisphere`] per unit solid angle: cos θ / π, zero below the horizon.
pub fn cosine_hemisphere_pdf(w: Vec3) -> f32 {
    w.z.max(0.0) * FRAC_1_PI
}

/// Inverse of [`sample_cosine_hemisphere`].
pub fn invert_cosine_hemisphere(w: Vec3) -> Vec2 {
    invert_uniform_disk_concentric(Vec2::new(w.x, w.y))
}

/// Uniform direction on the unit sphere (Archimedes: z uniform in [-1, 1]); density 1/(4π).
pub fn sample_uniform_sphere(u: Vec2) -> Vec3 {
    let (x, y, z) = uniform_sphere((u.x, u.y));
    Vec3::new(x, y, z)
}

/// [`sample_uniform_sphere`] for one lane or for lanes ([`Real`]).
#[inline]
pub fn uniform_sphere<F: Real>((u0, u1): (F, F)) -> (F, F, F) {
    let z = F::splat(1.0) - u0 * 2.0;
    let r = (F::splat(1.0) - z * z).max(F::splat(0.0)).sqrt();
    let (cos, sin) = cos_sin_of_turn(u1);
    (r * cos, r * sin, z)
}

/// Density of [`sample_uniform_sphere`] per unit solid angle.
pub fn uniform_sphere_pdf() -> f32 {
    1.0 / (4.0 * PI)
}

/// Inverse of [`sample_uniform_sphere`].
pub fn invert_uniform_sphere(w: Vec3) -> Vec2 {
    let mut phi = w.y.atan2(w.x);
    if phi < 0.0 {
        phi += 2.0 * PI;
    }
    Vec2::new((1.0 - w.z) * 0.5, phi / (2.0 * PI))
}

/// Uniform direction in the cone of half-angle θmax about +z, given cos θmax; density
/// 1 / (2π (1 - cos θmax)). Written with 1 - cos θ computed directly so that very small cones
/// (distant sphere lights) keep their precision.
pub fn sample_uniform_cone(u: Vec2, cos_theta_max: f32) -> Vec3 {
    let (x, y, z) = uniform_cone((u.x, u.y), cos_theta_max);
    Vec3::new(x, y, z)
}

/// [`sample_uniform_cone`] for one lane or for lanes ([`Real`]).
#[inline]
pub fn uniform_cone<F: Real>((u0, u1): (F, F), cos_theta_max: F) -> (F, F, F) {
    let one_minus_cos_max = F::splat(1.0) - cos_theta_max;
    let one_minus_cos = u0 * one_minus_cos_max;
    let cos_theta = F::splat(1.0) - one_minus_cos;
    // sin² θ = (1 - cos θ)(1 + cos θ), exact for small angles.
    let sin_theta = (one_minus_cos * (F::splat(2.0) - one_minus_cos))
        .max(F::splat(0.0))
        .sqrt();
    let (cos, sin) = cos_sin_of_turn(u1);
    (sin_theta * cos, sin_theta * sin, cos_theta)
}

/// Density of [`sample_uniform_cone`] per unit solid angle (zero outside the cone).
pub fn uniform_cone_pdf(w: Vec3, cos_theta_max: f32) -> f32 {
    if w.z >= cos_theta_max {
        1.0 / (2.0 * PI * (1.0 - cos_theta_max))
    } else {
        0.0
    }
}

/// Inverse of [`sample_uniform_cone`].
pub fn invert_uniform_cone(w: Vec3, cos_theta_max: f32) -> Vec2 {
    let mut phi = w.y.atan2(w.x);
    if phi < 0.0 {
        phi += 2.0 * PI;
    }
    Vec2::new((1.0 - w.z) / (1.0 - cos_theta_max), phi / (2.0 * PI))
}

/// Uniform barycentric coordinates (b0, b1) on a triangle, b2 = 1 - b0 - b1 (the square-root
/// parametrisation, Osada et al. 2002, "Shape Distributions", eq. 1).
pub fn sample_uniform_triangle(u: Vec2) -> Vec2 {
    let (b0, b1) = uniform_triangle((u.x, u.y));
    Vec2::new(b0, b1)
}

/// [`sample_uniform_triangle`] for one lane or for lanes ([`Real`]).
#[inline]
pub fn uniform_triangle<F: Real>((u0, u1): (F, F)) -> (F, F) {
    let su = u0.sqrt();
    (F::splat(1.0) - su, u1 * su)
}

/// Inverse of [`sample_uniform_triangle`].
pub fn invert_uniform_triangle(b: Vec2) -> Vec2 {
    let su = 1.0 - b.x;
    Vec2::new(su * su, if su > 0.0 { b.y / su } else { 0.0 })
}

#[cfg(test)]
mod tests {
    use std::f64::consts::TAU;

    use super::*;
    use crate::math::lanes::F32x8;
    use crate::sampling::chi2::{Cells, Suite, chi2_rectangle};
    use crate::sampling::rng::Pcg32;

    /// The polynomial cosine and sine agree with the exact values over the whole range they
    /// serve, |a| ≤ π/4, to the f32 rounding of their five Horner steps (each at most 2⁻²⁴ of
    /// a value ≤ 1) plus the series' remainder, 2.5·10⁻⁸: 3.3·10⁻⁷. Dropping the a⁸ term
    /// (3.6·10⁻⁶ at π/4) or any lower one fails it.
    #[test]
    fn quarter_pi_cosine_and_sine_are_accurate() {
        let n = 100_000;
        let mut worst = 0.0f64;
        for i in 0..=n {
            let a = FRAC_PI_4 * (2.0 * i as f32 / n as f32 - 1.0);
            let (cos, sin) = cos_sin_within_quarter_pi(a);
            let a64 = f64::from(a);
            worst = worst
                .max((f64::from(cos) - a64.cos()).abs())
                .max((f64::from(sin) - a64.sin()).abs());
        }
        assert!(worst < 3.3e-7, "largest error {worst}");
    }

    /// The turn's cosine and sine agree with the exact values over [0, 1] within 4·10⁻⁷ (the
    /// quarter-π polynomials' 3.3·10⁻⁷ and the rounding of the reduced angle); a wrong quarter
    /// fails it by up to 2.
    #[test]
    fn cosine_and_sine_of_a_turn_are_accurate() {
        let n = 1_000_000;
        let mut worst = 0.0f64;
        for i in 0..=n {
            let u = i as f32 / n as f32;
            let (cos, sin) = cos_sin_of_turn(u);
            let angle = TAU * f64::from(u);
            worst = worst
                .max((f64::from(cos) - angle.cos()).abs())
                .max((f64::from(sin) - angle.sin()).abs());
        }
        assert!(worst < 4e-7, "largest error {worst}");
    }

    fn random_points(n: usize) -> Vec<Vec2> {
        let mut rng = Pcg32::seeded(11);
        (0..n)
            .map(|_| Vec2::new(rng.next_f32(), rng.next_f32()))
            .collect()
    }

    #[test]
    fn disk_round_trip() {
        for u in random_points(10_000) {
            let p = sample_uniform_disk_concentric(u);
            assert!(p.length() <= 1.0 + 1e-6);
            let back = invert_uniform_disk_concentric(p);
            assert!(
                (back - u).abs().max_element() < 1e-4,
                "{u} -> {p} -> {back}"
            );
        }
    }

    #[test]
    fn cosine_hemisphere_round_trip_and_unit_length() {
        for u in random_points(10_000) {
            let w = sample_cosine_hemisphere(u);
            assert!((w.length() - 1.0).abs() < 1e-5);
            assert!(w.z >= 0.0);
            let back = invert_cosine_hemisphere(w);
            assert!((back - u).abs().max_element() < 1e-4);
        }
    }

    #[test]
    fn sphere_and_cone_round_trip() {
        for u in random_points(10_000) {
            let w = sample_uniform_sphere(u);
            assert!((w.length() - 1.0).abs() < 1e-5);
            assert!((invert_uniform_sphere(w) - u).abs().max_element() < 1e-4);
            let cos_max = 0.3;
            let c = sample_uniform_cone(u, cos_max);
            assert!((c.length() - 1.0).abs() < 1e-5 && c.z >= cos_max - 1e-6);
            assert!((invert_uniform_cone(c, cos_max) - u).abs().max_element() < 1e-3);
        }
    }

    #[test]
    fn tiny_cone_keeps_its_directions_inside() {
        let cos_max = 1.0 - 1e-7;
        for u in random_points(1000) {
            let c = sample_uniform_cone(u, cos_max);
            assert!((c.length() - 1.0).abs() < 1e-5);
            let sin = (c.x * c.x + c.y * c.y).sqrt();
            assert!(sin <= (2.0 * (1.0 - cos_max)).sqrt() * 1.01);
        }
    }

    /// The cone's directions follow the density the warp claims: a chi-square test in the
    /// coordinates (1 − cos θ, φ), whose measure is solid angle, with the density evaluated by
    /// [`uniform_cone_pdf`] at each point.
    #[test]
    fn uniform_cone_follows_its_density() {
        const SUITE: Suite = Suite::new(&["uniform cone"]);
        let cos_max = 0.5;
        let sample = |rng: &mut Pcg32| {
            let w = sample_uniform_cone(Vec2::new(rng.next_f32(), rng.next_f32()), cos_max);
            let phi = f64::from(w.y).atan2(f64::from(w.x)).rem_euclid(TAU);
            Some((1.0 - f64::from(w.z), phi))
        };
        let pdf = |one_minus_cos: f64, phi: f64| {
            let (cos, sin) = (
                1.0 - one_minus_cos,
                (one_minus_cos * (2.0 - one_minus_cos)).sqrt(),
            );
            let w = Vec3::new(
                (sin * phi.cos()) as f32,
                (sin * phi.sin()) as f32,
                cos as f32,
            );
            f64::from(uniform_cone_pdf(w, cos_max))
        };
        let one_minus_cos_max = f64::from(1.0 - cos_max);
        let outcome = chi2_rectangle(
            1_000_000,
            Cells {
                x: (0.0, one_minus_cos_max),
                y: (0.0, TAU),
                nx: 40,
                ny: 80,
            },
            12,
            sample,
            pdf,
        );
        SUITE.assert_passes("uniform cone", &outcome.unwrap());
    }

    #[test]
    fn triangle_round_trip() {
        for u in random_points(10_000) {
            let b = sample_uniform_triangle(u);
            assert!(b.x >= 0.0 && b.y >= 0.0 && b.x + b.y <= 1.0 + 1e-6);
            assert!((invert_uniform_triangle(b) - u).abs().max_element() < 1e-3);
        }
    }

    /// Numbers in [0, 1): the ends, the centre, points on the diagonals of the square, random.
    fn unit_numbers(n: usize, seed: u64) -> Vec<f32> {
        let mut values = vec![0.0, 0.5, 0.25, 0.75, 1.0 - f32::EPSILON / 2.0, 1e-30, 0.125];
        let mut rng = Pcg32::seeded(seed);
        while values.len() < n {
            values.push(rng.next_f32());
        }
        values
    }

    /// A warp written once, named, as called with lanes and with one `f32`; its up to three
    /// coordinates.
    type Warp<V> = (
        &'static str,
        fn((V, V)) -> [V; 3],
        fn((f32, f32)) -> [f32; 3],
    );

    fn same(got: f32, want: f32) -> bool {
        got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan())
    }

    /// The warps written once ([`Real`]) give in every lane of `V`, bit for bit, what they give
    /// for one `f32`, on random points, the square's centre, corners and diagonals.
    fn warps_in_lanes_compute_what_one_lane_computes<V: Real>() {
        let us = unit_numbers(4096, 3);
        let mut vs = unit_numbers(4096, 4);
        vs.rotate_left(3);
        let mirrored: Vec<f32> = us.iter().map(|u| 1.0 - u).collect();
        for vs in [&vs, &us, &mirrored] {
            let warps: [Warp<V>; 6] = [
                (
                    "concentric disk",
                    |u| {
                        let (x, y) = concentric_disk(u);
                        [x, y, y]
                    },
                    |u| {
                        let (x, y) = concentric_disk(u);
                        [x, y, y]
                    },
                ),
                (
                    "cosine hemisphere",
                    |u| cosine_hemisphere(u).into(),
                    |u| cosine_hemisphere(u).into(),
                ),
                (
                    "uniform sphere",
                    |u| uniform_sphere(u).into(),
                    |u| uniform_sphere(u).into(),
                ),
                (
                    "uniform cone",
                    |u| uniform_cone(u, u.1 * 0.5).into(),
                    |u| uniform_cone(u, u.1 * 0.5).into(),
                ),
                (
                    "turn",
                    |(u, _)| {
                        let (c, s) = cos_sin_of_turn(u);
                        [c, s, s]
                    },
                    |(u, _)| {
                        let (c, s) = cos_sin_of_turn(u);
                        [c, s, s]
                    },
                ),
                (
                    "uniform triangle",
                    |u| {
                        let (a, b) = uniform_triangle(u);
                        [a, b, b]
                    },
                    |u| {
                        let (a, b) = uniform_triangle(u);
                        [a, b, b]
                    },
                ),
            ];
            for (name, lanes, one) in warps {
                for (cu, cv) in us.chunks_exact(V::LANES).zip(vs.chunks_exact(V::LANES)) {
                    let got = lanes((V::from_lanes(cu), V::from_lanes(cv)));
                    for i in 0..V::LANES {
                        let want = one((cu[i], cv[i]));
                        for c in 0..3 {
                            assert!(
                                same(got[c].lane(i), want[c]),
                                "{name}({}, {}), coordinate {c}: lane {i} gives {}, one lane {}",
                                cu[i],
                                cv[i],
                                got[c].lane(i),
                                want[c]
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn warps_in_eight_lanes_compute_what_one_lane_computes() {
        warps_in_lanes_compute_what_one_lane_computes::<F32x8>();
    }

    #[cfg(all(target_arch = "x86_64", target_feature = "avx512f"))]
    #[test]
    fn warps_in_sixteen_lanes_compute_what_one_lane_computes() {
        warps_in_lanes_compute_what_one_lane_computes::<crate::math::lanes::F32x16>();
    }
}
