//! 8 lanes on the `wide` crate's `f32x8` (AVX2, two SSE or NEON registers, or an array).

use std::ops::{Neg, Not};

use wide::{CmpEq, CmpGe, CmpGt, CmpLe, CmpLt, f32x8};

use super::{LaneMask, Real, lane_operators, wrapped_binary_operator};

/// 8 floats side by side.
#[derive(Clone, Copy, Debug)]
pub struct F32x8(f32x8);

/// The truth values of a comparison of [`F32x8`]s: all bits of a lane set where it holds.
#[derive(Clone, Copy, Debug)]
pub struct Mask8(f32x8);

wrapped_binary_operator!(F32x8, Add, add, |a, b| a + b);
wrapped_binary_operator!(F32x8, Sub, sub, |a, b| a - b);
wrapped_binary_operator!(F32x8, Mul, mul, |a, b| a * b);
wrapped_binary_operator!(F32x8, Div, div, |a, b| a / b);

impl Neg for F32x8 {
    type Output = F32x8;
    #[inline(always)]
    fn neg(self) -> F32x8 {
        // The sign bit flipped (`wide`'s negation is 0 − x, which turns −0 into +0).
        F32x8(self.0 ^ f32x8::splat(-0.0))
    }
}

lane_operators!(F32x8);

impl Real for F32x8 {
    type Mask = Mask8;
    const LANES: usize = 8;

    #[inline(always)]
    fn splat(v: f32) -> F32x8 {
        F32x8(f32x8::splat(v))
    }

    #[inline(always)]
    fn from_lanes(values: &[f32]) -> F32x8 {
        let values: [f32; 8] = values[..8].try_into().expect("a slice of 8");
        F32x8(f32x8::from(values))
    }

    #[inline(always)]
    fn write_lanes(self, out: &mut [f32]) {
        out[..8].copy_from_slice(&self.0.to_array());
    }

    #[inline(always)]
    fn lane(self, i: usize) -> f32 {
        self.0.to_array()[i]
    }

    #[inline(always)]
    fn abs(self) -> F32x8 {
        F32x8(self.0.abs())
    }

    #[inline(always)]
    fn sqrt(self) -> F32x8 {
        F32x8(self.0.sqrt())
    }

    #[inline(always)]
    fn floor(self) -> F32x8 {
        F32x8(self.0.floor())
    }

    #[inline(always)]
    fn min(self, other: F32x8) -> F32x8 {
        F32x8(self.0.cmp_lt(other.0).blend(self.0, other.0))
    }

    #[inline(always)]
    fn max(self, other: F32x8) -> F32x8 {
        F32x8(self.0.cmp_gt(other.0).blend(self.0, other.0))
    }

    #[inline(always)]
    fn lt(self, other: F32x8) -> Mask8 {
        Mask8(self.0.cmp_lt(other.0))
    }

    #[inline(always)]
    fn le(self, other: F32x8) -> Mask8 {
        Mask8(self.0.cmp_le(other.0))
    }

    #[inline(always)]
    fn gt(self, other: F32x8) -> Mask8 {
        Mask8(self.0.cmp_gt(other.0))
    }

    #[inline(always)]
    fn ge(self, other: F32x8) -> Mask8 {
        Mask8(self.0.cmp_ge(other.0))
    }

    #[inline(always)]
    fn eq(self, other: F32x8) -> Mask8 {
        Mask8(self.0.cmp_eq(other.0))
    }

    #[inline(always)]
    fn select(mask: Mask8, if_true: F32x8, if_false: F32x8) -> F32x8 {
        F32x8(mask.0.blend(if_true.0, if_false.0))
    }
}

wrapped_binary_operator!(Mask8, BitAnd, bitand, |a, b| a & b);
wrapped_binary_operator!(Mask8, BitOr, bitor, |a, b| a | b);

impl Not for Mask8 {
    type Output = Mask8;
    #[inline(always)]
    fn not(self) -> Mask8 {
        Mask8(!self.0)
    }
}

impl LaneMask for Mask8 {
    #[inline(always)]
    fn any(self) -> bool {
        self.0.any()
    }

    #[inline(always)]
    fn all(self) -> bool {
        self.0.all()
    }

    #[inline(always)]
    fn lane(self, i: usize) -> bool {
        self.0.move_mask() >> i & 1 == 1
    }
}
