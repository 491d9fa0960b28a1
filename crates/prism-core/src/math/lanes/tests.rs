//! Every lane of a lane vector computes what one `f32` computes, bit for bit: the operations,
//! and the formulas written once for both.

use super::*;
use crate::sampling::rng::Pcg32;
use crate::sampling::warp::{
    concentric_disk, cos_sin_of_turn, cosine_hemisphere, uniform_cone, uniform_sphere,
    uniform_triangle,
};

/// Signed zeros, infinities, NaN, tiny, huge and exact values, then random ones.
fn numbers(n: usize, seed: u64) -> Vec<f32> {
    let mut values = vec![
        0.0,
        -0.0,
        1.0,
        -1.0,
        0.5,
        -0.5,
        1.5,
        -2.5,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
        f32::MIN_POSITIVE,
        -f32::MIN_POSITIVE,
        1e-40,
        f32::MAX,
        f32::MIN,
        3.0,
        -7.75,
    ];
    let mut rng = Pcg32::seeded(seed);
    while values.len() < n {
        let u = rng.next_f32();
        values.push(match values.len() % 3 {
            0 => u,
            1 => 8.0 * u - 4.0,
            _ => (u - 0.5) * 1e6,
        });
    }
    values
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

fn same(got: f32, want: f32) -> bool {
    got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan())
}

/// The lanes of `lanes(x)` against `one(x)`, x taken `V::LANES` at a time from `xs`.
fn check_unary<V: Real>(name: &str, xs: &[f32], lanes: impl Fn(V) -> V, one: impl Fn(f32) -> f32) {
    for chunk in xs.chunks_exact(V::LANES) {
        let got = lanes(V::from_lanes(chunk));
        for (i, &x) in chunk.iter().enumerate() {
            let want = one(x);
            assert!(
                same(got.lane(i), want),
                "{name}({x}): lane {i} gives {}, one lane {want}",
                got.lane(i)
            );
        }
    }
}

fn check_binary<V: Real>(
    name: &str,
    xs: &[f32],
    ys: &[f32],
    lanes: impl Fn(V, V) -> V,
    one: impl Fn(f32, f32) -> f32,
) {
    for (cx, cy) in xs.chunks_exact(V::LANES).zip(ys.chunks_exact(V::LANES)) {
        let got = lanes(V::from_lanes(cx), V::from_lanes(cy));
        for i in 0..V::LANES {
            let want = one(cx[i], cy[i]);
            assert!(
                same(got.lane(i), want),
                "{name}({}, {}): lane {i} gives {}, one lane {want}",
                cx[i],
                cy[i],
                got.lane(i)
            );
        }
    }
}

fn check_comparison<V: Real>(
    name: &str,
    xs: &[f32],
    ys: &[f32],
    lanes: impl Fn(V, V) -> V::Mask,
    one: impl Fn(f32, f32) -> bool,
) {
    for (cx, cy) in xs.chunks_exact(V::LANES).zip(ys.chunks_exact(V::LANES)) {
        let mask = lanes(V::from_lanes(cx), V::from_lanes(cy));
        let wants: Vec<bool> = (0..V::LANES).map(|i| one(cx[i], cy[i])).collect();
        for (i, &want) in wants.iter().enumerate() {
            assert_eq!(
                mask.lane(i),
                want,
                "{name}({}, {}) in lane {i}",
                cx[i],
                cy[i]
            );
        }
        assert_eq!(mask.any(), wants.iter().any(|&w| w), "{name}: any");
        assert_eq!(mask.all(), wants.iter().all(|&w| w), "{name}: all");
    }
}

/// A warp written once, named, as called with lanes and with one `f32`; its up to three
/// coordinates.
type Warp<V> = (
    &'static str,
    fn((V, V)) -> [V; 3],
    fn((f32, f32)) -> [f32; 3],
);

/// Every operation of [`Real`], and the warps written with them, in `V`'s lanes against `f32`.
fn lanes_compute_what_one_lane_computes<V: Real>() {
    let xs = numbers(4096, 1);
    let mut ys = numbers(4096, 2);
    ys.rotate_left(5);
    check_unary::<V>("abs", &xs, |x| x.abs(), <f32 as Real>::abs);
    check_unary::<V>("sqrt", &xs, |x| x.sqrt(), <f32 as Real>::sqrt);
    check_unary::<V>("floor", &xs, |x| x.floor(), <f32 as Real>::floor);
    check_unary::<V>("neg", &xs, |x| -x, |x| -x);
    check_unary::<V>("splat", &xs, |_| V::splat(0.3), |_| 0.3);
    check_unary::<V>("x + 0.3", &xs, |x| x + 0.3, |x| x + 0.3);
    check_unary::<V>("x - 0.3", &xs, |x| x - 0.3, |x| x - 0.3);
    check_unary::<V>("x * 0.3", &xs, |x| x * 0.3, |x| x * 0.3);
    check_unary::<V>("x / 0.3", &xs, |x| x / 0.3, |x| x / 0.3);
    for pair in [(&xs, &ys), (&xs, &xs)] {
        let (xs, ys) = pair;
        check_binary::<V>("+", xs, ys, |x, y| x + y, |x, y| x + y);
        check_binary::<V>("-", xs, ys, |x, y| x - y, |x, y| x - y);
        check_binary::<V>("*", xs, ys, |x, y| x * y, |x, y| x * y);
        check_binary::<V>("/", xs, ys, |x, y| x / y, |x, y| x / y);
        check_binary::<V>("min", xs, ys, |x, y| x.min(y), <f32 as Real>::min);
        check_binary::<V>("max", xs, ys, |x, y| x.max(y), <f32 as Real>::max);
        check_comparison::<V>("lt", xs, ys, |x, y| x.lt(y), |x, y| x < y);
        check_comparison::<V>("le", xs, ys, |x, y| x.le(y), |x, y| x <= y);
        check_comparison::<V>("gt", xs, ys, |x, y| x.gt(y), |x, y| x > y);
        check_comparison::<V>("ge", xs, ys, |x, y| x.ge(y), |x, y| x >= y);
        check_comparison::<V>("eq", xs, ys, |x, y| x.eq(y), |x, y| x == y);
        check_comparison::<V>("lt & gt", xs, ys, |x, y| x.lt(y) & y.gt(x), |x, y| x < y);
        check_comparison::<V>("lt | eq", xs, ys, |x, y| x.lt(y) | x.eq(y), |x, y| x <= y);
        check_comparison::<V>("!lt", xs, ys, |x, y| !x.lt(y), |x, y| !(x < y));
        check_binary::<V>(
            "select",
            xs,
            ys,
            |x, y| V::select(x.lt(y), x, y),
            |x, y| if x < y { x } else { y },
        );
    }
    for chunk in xs.chunks_exact(V::LANES) {
        let mut out = vec![0.0; V::LANES];
        V::from_lanes(chunk).write_lanes(&mut out);
        assert!(
            out.iter().zip(chunk).all(|(&a, &b)| same(a, b)),
            "write_lanes"
        );
    }
    // Masks that hold in every lane, and in none.
    let ones = vec![1.0; V::LANES];
    let mask = V::from_lanes(&ones).eq(V::splat(1.0));
    assert!(mask.all() && mask.any() && !(!mask).any());

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
fn eight_lanes_compute_what_one_lane_computes() {
    lanes_compute_what_one_lane_computes::<F32x8>();
}

#[cfg(all(target_arch = "x86_64", target_feature = "avx512f"))]
#[test]
fn sixteen_lanes_compute_what_one_lane_computes() {
    lanes_compute_what_one_lane_computes::<F32x16>();
}
