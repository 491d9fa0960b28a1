//! 16 lanes in an AVX-512 register.
//!
//! This module is compiled only for targets with AVX-512F (see the `cfg` in the parent module),
//! which is what makes each `unsafe` intrinsic call below sound.

use std::arch::x86_64::*;
use std::ops::{Neg, Not};

use super::{LaneMask, Real, lane_operators, wrapped_binary_operator};

/// 16 floats in one AVX-512 register.
#[derive(Clone, Copy, Debug)]
pub struct F32x16(__m512);

/// The truth values of a comparison of [`F32x16`]s, one bit per lane.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Mask16(__mmask16);

wrapped_binary_operator!(F32x16, Add, add, |a, b| unsafe { _mm512_add_ps(a, b) });
wrapped_binary_operator!(F32x16, Sub, sub, |a, b| unsafe { _mm512_sub_ps(a, b) });
wrapped_binary_operator!(F32x16, Mul, mul, |a, b| unsafe { _mm512_mul_ps(a, b) });
wrapped_binary_operator!(F32x16, Div, div, |a, b| unsafe { _mm512_div_ps(a, b) });

impl Neg for F32x16 {
    type Output = F32x16;
    #[inline(always)]
    fn neg(self) -> F32x16 {
        unsafe {
            F32x16(_mm512_castsi512_ps(_mm512_xor_si512(
                _mm512_castps_si512(self.0),
                _mm512_set1_epi32(i32::MIN),
            )))
        }
    }
}

lane_operators!(F32x16);

impl Real for F32x16 {
    type Mask = Mask16;
    const LANES: usize = 16;

    #[inline(always)]
    fn splat(v: f32) -> F32x16 {
        unsafe { F32x16(_mm512_set1_ps(v)) }
    }

    #[inline(always)]
    fn from_lanes(values: &[f32]) -> F32x16 {
        let values = &values[..16];
        // SAFETY: `values` holds the 16 floats read.
        F32x16(unsafe { _mm512_loadu_ps(values.as_ptr()) })
    }

    #[inline(always)]
    fn write_lanes(self, out: &mut [f32]) {
        let out = &mut out[..16];
        // SAFETY: `out` has room for the 16 floats written.
        unsafe { _mm512_storeu_ps(out.as_mut_ptr(), self.0) };
    }

    #[inline(always)]
    fn lane(self, i: usize) -> f32 {
        let mut values = [0.0; 16];
        self.write_lanes(&mut values);
        values[i]
    }

    #[inline(always)]
    fn abs(self) -> F32x16 {
        unsafe { F32x16(_mm512_abs_ps(self.0)) }
    }

    #[inline(always)]
    fn sqrt(self) -> F32x16 {
        unsafe { F32x16(_mm512_sqrt_ps(self.0)) }
    }

    #[inline(always)]
    fn floor(self) -> F32x16 {
        unsafe {
            F32x16(_mm512_roundscale_ps::<
                { _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC },
            >(self.0))
        }
    }

    #[inline(always)]
    fn min(self, other: F32x16) -> F32x16 {
        unsafe { F32x16(_mm512_min_ps(self.0, other.0)) }
    }

    #[inline(always)]
    fn max(self, other: F32x16) -> F32x16 {
        unsafe { F32x16(_mm512_max_ps(self.0, other.0)) }
    }

    #[inline(always)]
    fn lt(self, other: F32x16) -> Mask16 {
        unsafe { Mask16(_mm512_cmp_ps_mask::<_CMP_LT_OQ>(self.0, other.0)) }
    }

    #[inline(always)]
    fn le(self, other: F32x16) -> Mask16 {
        unsafe { Mask16(_mm512_cmp_ps_mask::<_CMP_LE_OQ>(self.0, other.0)) }
    }

    #[inline(always)]
    fn gt(self, other: F32x16) -> Mask16 {
        unsafe { Mask16(_mm512_cmp_ps_mask::<_CMP_GT_OQ>(self.0, other.0)) }
    }

    #[inline(always)]
    fn ge(self, other: F32x16) -> Mask16 {
        unsafe { Mask16(_mm512_cmp_ps_mask::<_CMP_GE_OQ>(self.0, other.0)) }
    }

    #[inline(always)]
    fn eq(self, other: F32x16) -> Mask16 {
        unsafe { Mask16(_mm512_cmp_ps_mask::<_CMP_EQ_OQ>(self.0, other.0)) }
    }

    #[inline(always)]
    fn select(mask: Mask16, if_true: F32x16, if_false: F32x16) -> F32x16 {
        unsafe { F32x16(_mm512_mask_blend_ps(mask.0, if_false.0, if_true.0)) }
    }
}

wrapped_binary_operator!(Mask16, BitAnd, bitand, |a, b| a & b);
wrapped_binary_operator!(Mask16, BitOr, bitor, |a, b| a | b);

impl Not for Mask16 {
    type Output = Mask16;
    #[inline(always)]
    fn not(self) -> Mask16 {
        Mask16(!self.0)
    }
}

impl LaneMask for Mask16 {
    #[inline(always)]
    fn any(self) -> bool {
        self.0 != 0
    }

    #[inline(always)]
    fn all(self) -> bool {
        self.0 == u16::MAX
    }

    #[inline(always)]
    fn lane(self, i: usize) -> bool {
        self.0 >> i & 1 == 1
    }
}
