//! Linear interpolation in tables of regularly spaced samples, one point at a time or four in
//! SIMD with the same numbers: the CIE tables and regular spectra use it.

use wide::f32x4;

/// Linear interpolation in a regular table of at least two values at x = (λ − λ₀)/spacing, for
/// λ inside the table.
#[inline(always)]
pub fn interpolate_regular(values: &[f32], x: f32) -> f32 {
    let i = (x as usize).min(values.len() - 2);
    values[i] + (x - i as f32) * (values[i + 1] - values[i])
}

/// [`interpolate_regular`] at four points at once, with the same numbers. The cell
/// min(⌊x⌋, n − 2) is computed as ⌊min(x, n − 2)⌋ (equal for x ≥ 0); a lane outside the table
/// (or a NaN, which the maximum turns into 0) is clamped into it, for the caller to mask out.
#[inline(always)]
pub fn interpolate_regular4(values: &[f32], x: f32x4) -> f32x4 {
    let last_cell = (values.len() - 2) as f32;
    let cell = x
        .fast_max(f32x4::ZERO)
        .fast_min(f32x4::splat(last_cell))
        .fast_trunc_int();
    let index = cell.to_array().map(|i| i as usize);
    let below = f32x4::from(index.map(|i| values[i]));
    let above = f32x4::from(index.map(|i| values[i + 1]));
    below + (x - cell.round_float()) * (above - below)
}
