//! Numbers in SIMD lanes: one type for "a float" that is either one `f32` or L of them side by
//! side in a vector register, so that a formula is written once and runs on one path or on L
//! paths at a time (docs/architecture.md, Paths in lanes).
//!
//! [`Real`] is what a formula may do with its numbers: arithmetic, square roots, comparisons
//! that give a [`Real::Mask`], and [`Real::select`] in place of branches. It is implemented by
//! `f32` (one lane; a mask is a `bool`) and by [`F32s`], the lane vector of the processor the
//! code is compiled for: 16 lanes in an AVX-512 register where the compiler targets AVX-512
//! ([`F32x16`]), otherwise 8 lanes ([`F32x8`], on the `wide` crate, which uses AVX2, pairs of
//! SSE or NEON registers, or plain arrays). A lane of any width computes exactly what the `f32`
//! version computes for its inputs (every operation here is correctly rounded, and none is
//! fused), so an image does not depend on the width. Branches become selects: both sides are
//! computed and each lane keeps its own; a side a lane does not keep may hold NaN or infinity,
//! which the select drops.
//!
//! Measured on one kernel (a cosine-hemisphere sample, a frame rotation, a normalisation and a
//! table lookup): one item at a time 22 ns per item, `[f32; 16]` loops left to the compiler's
//! auto-vectoriser 12.4 ns, `wide::f32x8` 2.07 ns, AVX-512 intrinsics 1.35 ns; hence an explicit
//! vector type rather than arrays.

use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

#[cfg(all(target_arch = "x86_64", target_feature = "avx512f"))]
mod avx512;
mod wide8;

#[cfg(all(target_arch = "x86_64", target_feature = "avx512f"))]
pub use avx512::{F32x16, Mask16};
pub use wide8::{F32x8, Mask8};

/// The lane vector of this build: 16 lanes with AVX-512, else 8.
#[cfg(all(target_arch = "x86_64", target_feature = "avx512f"))]
pub type F32s = F32x16;
/// The lane vector of this build: 16 lanes with AVX-512, else 8.
#[cfg(not(all(target_arch = "x86_64", target_feature = "avx512f")))]
pub type F32s = F32x8;

/// A float, or floats in lanes: what a formula written once for both may use.
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Add<f32, Output = Self>
    + Sub<f32, Output = Self>
    + Mul<f32, Output = Self>
    + Div<f32, Output = Self>
{
    /// Per-lane truth values of a comparison.
    type Mask: LaneMask;
    /// How many numbers side by side.
    const LANES: usize;

    /// Every lane `v`.
    fn splat(v: f32) -> Self;
    /// Lane i holds `values[i]` (the first `LANES` of them).
    fn from_lanes(values: &[f32]) -> Self;
    /// Writes lane i to `out[i]` (the first `LANES` of it).
    fn write_lanes(self, out: &mut [f32]);
    /// The value of lane `i`.
    fn lane(self, i: usize) -> f32;
    fn abs(self) -> Self;
    fn sqrt(self) -> Self;
    /// The largest integer not above each lane.
    fn floor(self) -> Self;
    /// `self` where it is less than `other`, else `other` (so `other` where either is NaN, as
    /// the x86 instruction `minps` has it; `f32::min` would prefer the number to the NaN).
    fn min(self, other: Self) -> Self;
    /// `self` where it is greater than `other`, else `other` (as `maxps`).
    fn max(self, other: Self) -> Self;
    fn lt(self, other: Self) -> Self::Mask;
    fn le(self, other: Self) -> Self::Mask;
    fn gt(self, other: Self) -> Self::Mask;
    fn ge(self, other: Self) -> Self::Mask;
    fn eq(self, other: Self) -> Self::Mask;
    /// `if_true` in the lanes where `mask` holds, `if_false` in the others.
    fn select(mask: Self::Mask, if_true: Self, if_false: Self) -> Self;
}

/// The truth values of a comparison, one per lane.
pub trait LaneMask:
    Copy + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self>
{
    /// Whether any lane holds.
    fn any(self) -> bool;
    /// Whether every lane holds.
    fn all(self) -> bool;
    /// Whether lane `i` holds.
    fn lane(self, i: usize) -> bool;
}

impl LaneMask for bool {
    #[inline(always)]
    fn any(self) -> bool {
        self
    }

    #[inline(always)]
    fn all(self) -> bool {
        self
    }

    #[inline(always)]
    fn lane(self, _: usize) -> bool {
        self
    }
}

impl Real for f32 {
    type Mask = bool;
    const LANES: usize = 1;

    #[inline(always)]
    fn splat(v: f32) -> f32 {
        v
    }

    #[inline(always)]
    fn from_lanes(values: &[f32]) -> f32 {
        values[0]
    }

    #[inline(always)]
    fn write_lanes(self, out: &mut [f32]) {
        out[0] = self;
    }

    #[inline(always)]
    fn lane(self, _: usize) -> f32 {
        self
    }

    #[inline(always)]
    fn abs(self) -> f32 {
        f32::abs(self)
    }

    #[inline(always)]
    fn sqrt(self) -> f32 {
        f32::sqrt(self)
    }

    #[inline(always)]
    fn floor(self) -> f32 {
        f32::floor(self)
    }

    #[inline(always)]
    fn min(self, other: f32) -> f32 {
        if self < other { self } else { other }
    }

    #[inline(always)]
    fn max(self, other: f32) -> f32 {
        if self > other { self } else { other }
    }

    #[inline(always)]
    fn lt(self, other: f32) -> bool {
        self < other
    }

    #[inline(always)]
    fn le(self, other: f32) -> bool {
        self <= other
    }

    #[inline(always)]
    fn gt(self, other: f32) -> bool {
        self > other
    }

    #[inline(always)]
    fn ge(self, other: f32) -> bool {
        self >= other
    }

    #[inline(always)]
    fn eq(self, other: f32) -> bool {
        self == other
    }

    #[inline(always)]
    fn select(mask: bool, if_true: f32, if_false: f32) -> f32 {
        if mask { if_true } else { if_false }
    }
}

/// Implements the operators of a lane vector `$t` with `$f32(a, b)` per operator name, and the
/// mixed ones with a plain `f32` (splat first).
macro_rules! lane_operators {
    ($t:ty) => {
        impl std::ops::Add<f32> for $t {
            type Output = $t;
            #[inline(always)]
            fn add(self, other: f32) -> $t {
                self + <$t as $crate::math::lanes::Real>::splat(other)
            }
        }
        impl std::ops::Sub<f32> for $t {
            type Output = $t;
            #[inline(always)]
            fn sub(self, other: f32) -> $t {
                self - <$t as $crate::math::lanes::Real>::splat(other)
            }
        }
        impl std::ops::Mul<f32> for $t {
            type Output = $t;
            #[inline(always)]
            fn mul(self, other: f32) -> $t {
                self * <$t as $crate::math::lanes::Real>::splat(other)
            }
        }
        impl std::ops::Div<f32> for $t {
            type Output = $t;
            #[inline(always)]
            fn div(self, other: f32) -> $t {
                self / <$t as $crate::math::lanes::Real>::splat(other)
            }
        }
    };
}
use lane_operators;

/// Implements the binary operator `$trait::$method` of the one-field wrapper `$t` by `$op` on
/// the two wrapped values `$a` and `$b`.
macro_rules! wrapped_binary_operator {
    ($t:ident, $trait:ident, $method:ident, |$a:ident, $b:ident| $op:expr) => {
        impl std::ops::$trait for $t {
            type Output = $t;
            #[inline(always)]
            fn $method(self, other: $t) -> $t {
                let ($a, $b) = (self.0, other.0);
                $t($op)
            }
        }
    };
}
use wrapped_binary_operator;

#[cfg(test)]
mod tests;
