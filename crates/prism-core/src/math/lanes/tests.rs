//! Every lane of a lane vector computes what one `f32` computes, bit for bit (the formulas
//! written with them are tested where they are written).

use super::*;

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
    // xorshift64* (Vigna 2016): this layer has no random number generator of its own.
    let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    while values.len() < n {
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        let u = (state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 40) as f32 / (1u32 << 24) as f32;
        values.push(match values.len() % 3 {
            0 => u,
            1 => 8.0 * u - 4.0,
            _ => (u - 0.5) * 1e6,
        });
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

/// Every operation of [`Real`] in `V`'s lanes against `f32`.
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
