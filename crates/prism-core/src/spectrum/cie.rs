//! Evaluation of the CIE tables: colour matching functions and D65 at any wavelength, and the
//! conversions between CIE XYZ and linear sRGB.

use wide::{CmpGe, CmpLe, f32x4};

use super::cie_tables::{
    CIE_X, CIE_Y, CIE_Y_INTEGRAL, CIE_Z, D65, D65_LUMINANCE, TABLE_LAMBDA_MIN, TABLE_STEP,
};
use super::interpolation::interpolate_regular4;

/// Shortest wavelength transported, in nm (the start of the CIE 1931 tables).
pub const LAMBDA_MIN: f32 = 360.0;
/// Longest wavelength transported, in nm (the end of the CIE 1931 tables).
pub const LAMBDA_MAX: f32 = 830.0;

/// Entries of every table.
const TABLE_LEN: usize = 95;

/// Linear interpolation in a table of 5 nm steps starting at 360 nm, as Mitsuba 3 interpolates
/// its CIE tables; zero outside 360..=830 nm.
#[inline]
fn lookup(table: &[f32; TABLE_LEN], lambda: f32) -> f32 {
    let t = (lambda - TABLE_LAMBDA_MIN) * (1.0 / TABLE_STEP);
    if !(0.0..=(TABLE_LEN - 1) as f32).contains(&t) {
        return 0.0;
    }
    let i = (t as usize).min(TABLE_LEN - 2);
    let f = t - i as f32;
    table[i] + f * (table[i + 1] - table[i])
}

/// [`lookup`] at four wavelengths at once, with the same numbers.
#[inline]
fn lookup4(table: &[f32; TABLE_LEN], lambda: f32x4) -> f32x4 {
    let t = (lambda - f32x4::splat(TABLE_LAMBDA_MIN)) * f32x4::splat(1.0 / TABLE_STEP);
    let inside = t.cmp_ge(f32x4::ZERO) & t.cmp_le(f32x4::splat((TABLE_LEN - 1) as f32));
    interpolate_regular4(table, t) & inside
}

/// The CIE 1931 2° colour matching functions (x̄, ȳ, z̄) at `lambda` nm.
#[inline]
pub fn cie_xyz(lambda: f32) -> [f32; 3] {
    [
        lookup(&CIE_X, lambda),
        lookup(&CIE_Y, lambda),
        lookup(&CIE_Z, lambda),
    ]
}

/// [`cie_xyz`] at four wavelengths at once: x̄, ȳ and z̄ each for the four.
#[inline]
pub fn cie_xyz4(lambda: f32x4) -> [f32x4; 3] {
    [
        lookup4(&CIE_X, lambda),
        lookup4(&CIE_Y, lambda),
        lookup4(&CIE_Z, lambda),
    ]
}

/// ȳ at `lambda` nm (the luminous efficiency function).
#[inline]
pub fn cie_y(lambda: f32) -> f32 {
    lookup(&CIE_Y, lambda)
}

/// The integral of ȳ over 360–830 nm: XYZ are divided by it so that a constant spectrum of 1
/// has luminance Y = 1 (the convention of Mitsuba 3 and pbrt-v4).
pub const CIE_Y_INTEGRAL_F32: f32 = CIE_Y_INTEGRAL as f32;

/// CIE D65 scaled to luminance 1: D65(λ) / (∫D65 ȳ / ∫ȳ). An RGB illuminant (1, 1, 1) becomes
/// exactly this spectrum, whose XYZ is the sRGB white point with Y = 1.
#[inline]
pub fn d65_normalized(lambda: f32) -> f32 {
    lookup(&D65, lambda) * (1.0 / D65_LUMINANCE as f32)
}

/// [`d65_normalized`] at four wavelengths at once.
#[inline]
pub fn d65_normalized4(lambda: f32x4) -> f32x4 {
    lookup4(&D65, lambda) * f32x4::splat(1.0 / D65_LUMINANCE as f32)
}

/// XYZ → linear sRGB (IEC 61966-2-1, D65 white), rows applied to (X, Y, Z).
pub const XYZ_TO_LINEAR_SRGB: [[f32; 3]; 3] = [
    [3.240_454_2, -1.537_138_5, -0.498_531_4],
    [-0.969_266, 1.876_010_8, 0.041_556],
    [0.055_643_4, -0.204_025_9, 1.057_225_2],
];

/// Linear sRGB → XYZ (IEC 61966-2-1), the inverse of [`XYZ_TO_LINEAR_SRGB`].
pub const LINEAR_SRGB_TO_XYZ: [[f32; 3]; 3] = [
    [0.412_456_4, 0.357_576_1, 0.180_437_5],
    [0.212_672_9, 0.715_152_2, 0.072_175_0],
    [0.019_333_9, 0.119_192, 0.950_304_1],
];

/// Applies a 3×3 matrix to a colour.
#[inline]
pub fn mul3(m: &[[f32; 3]; 3], v: [f32; 3]) -> [f32; 3] {
    [
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    ]
}

/// CIE XYZ to linear sRGB.
#[inline]
pub fn xyz_to_linear_srgb(xyz: [f32; 3]) -> [f32; 3] {
    mul3(&XYZ_TO_LINEAR_SRGB, xyz)
}

/// Linear sRGB to CIE XYZ.
#[inline]
pub fn linear_srgb_to_xyz(rgb: [f32; 3]) -> [f32; 3] {
    mul3(&LINEAR_SRGB_TO_XYZ, rgb)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫ f dλ by the trapezoid rule on a fine grid (0.25 nm), exact for the linear interpolants.
    fn integrate(f: impl Fn(f32) -> f64) -> f64 {
        let steps = 470 * 4;
        let h = 470.0 / steps as f64;
        (0..=steps)
            .map(|i| {
                let w = if i == 0 || i == steps { 0.5 } else { 1.0 };
                w * f(360.0 + (i as f64 * h) as f32)
            })
            .sum::<f64>()
            * h
    }

    #[test]
    fn tables_are_interpolated_at_integer_and_half_wavelengths() {
        assert_eq!(cie_xyz(555.0)[1], 1.0);
        let mid = cie_y(555.5);
        assert!((mid - 0.5 * (cie_y(555.0) + cie_y(556.0))).abs() < 1e-7);
        assert_eq!(cie_xyz(359.0), [0.0; 3]);
        assert_eq!(cie_xyz(831.0), [0.0; 3]);
    }

    #[test]
    fn normalized_d65_has_unit_luminance_and_srgb_white_chromaticity() {
        let x = integrate(|l| f64::from(d65_normalized(l) * cie_xyz(l)[0]));
        let y = integrate(|l| f64::from(d65_normalized(l) * cie_xyz(l)[1]));
        let z = integrate(|l| f64::from(d65_normalized(l) * cie_xyz(l)[2]));
        let (x, y, z) = (x / CIE_Y_INTEGRAL, y / CIE_Y_INTEGRAL, z / CIE_Y_INTEGRAL);
        assert!((y - 1.0).abs() < 1e-4, "Y = {y}");
        // D65 white point under the interpolated tables: x = 0.31274, y = 0.32904 (data/README.md).
        assert!((x / (x + y + z) - 0.31274).abs() < 2e-5);
        assert!((y / (x + y + z) - 0.32904).abs() < 2e-5);
        // ... which the sRGB matrix maps to (1, 1, 1) within the matrix's rounding.
        let rgb = xyz_to_linear_srgb([x as f32, y as f32, z as f32]);
        for c in rgb {
            assert!((c - 1.0).abs() < 2e-3, "{rgb:?}");
        }
    }

    #[test]
    fn srgb_matrices_are_inverse() {
        let v = [0.3, 0.6, 0.1];
        let back = xyz_to_linear_srgb(linear_srgb_to_xyz(v));
        for i in 0..3 {
            assert!((back[i] - v[i]).abs() < 1e-5);
        }
    }
}
