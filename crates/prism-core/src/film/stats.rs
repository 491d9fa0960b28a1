//! The error of a rendered image, estimated from its own samples (the lecture's "Monte Carlo
//! estimation with honest error": the standard deviation of the estimate is σ/√N).
//!
//! For a pixel with n samples vᵢ (filter-weighted luminance Y) the estimate is the mean m and the
//! variance of that mean is estimated by s²/n with s² = (Σvᵢ² − n m²)/(n − 1), unbiased for
//! independent samples. Under filter MIS the vᵢ are the totals of whole sample indices over the
//! pixels around, less the control variate's share ([`crate::film::reconstruction`]). With a stratified sampler the samples of a pixel are negatively
//! correlated and s²/n overestimates the true variance: the error is then conservative.
//!
//! The pixel's relative standard error is √(s²/n / (m² + 0.01)): the same regularised
//! denominator as the relative MSE of `prism compare` (and of Mitsuba's and pbrt's tools), so that
//! black pixels do not dominate. The image's error is the mean over pixels.

use super::{Film, PixelSums};
use crate::image::compare::RELATIVE_EPSILON;

/// Variance of the pixel mean of channel `c` (0 = X, 1 = Y, 2 = Z); infinite with fewer than two
/// samples ([`PixelSums::variance_of_mean`], which also accounts for filter MIS's control
/// variate).
pub fn variance_of_mean(pixel: &PixelSums, c: usize) -> f64 {
    pixel.variance_of_mean(c)
}

/// The relative standard error of a pixel's luminance: √(var / (Y² + 0.01)).
pub fn pixel_relative_error(pixel: &PixelSums) -> f64 {
    let y = pixel.mean()[1];
    (variance_of_mean(pixel, 1) / (y * y + RELATIVE_EPSILON)).sqrt()
}

/// The mean relative standard error over pixels (infinite while some pixel has < 2 samples).
pub fn relative_error<'a>(pixels: impl Iterator<Item = &'a PixelSums>) -> f64 {
    let (sum, count) = pixels.fold((0.0, 0usize), |(s, n), p| {
        (s + pixel_relative_error(p), n + 1)
    });
    if count == 0 { 0.0 } else { sum / count as f64 }
}

/// Says how many samples were dropped as non-finite and in which pixels most of them were.
pub fn rejected_report(film: &Film) -> Option<String> {
    let total: u64 = film.pixels.iter().map(|p| p.rejected).sum();
    if total == 0 {
        return None;
    }
    let width = film.crop.size.x;
    let mut worst: Vec<(u64, u32, u32)> = film
        .pixels
        .iter()
        .enumerate()
        .filter(|(_, p)| p.rejected > 0)
        .map(|(i, p)| {
            let (x, y) = (i as u32 % width, i as u32 / width);
            (p.rejected, film.crop.offset.x + x, film.crop.offset.y + y)
        })
        .collect();
    worst.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    let listed: Vec<String> = worst
        .iter()
        .take(5)
        .map(|(n, x, y)| format!("({x}, {y}) ×{n}"))
        .collect();
    Some(format!(
        "prism: {total} samples were NaN or infinite and were dropped; worst pixels: {}; inspect one with --pixel x,y",
        listed.join(", ")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn variance_of_the_mean_of_known_samples() {
        let mut pixel = PixelSums::default();
        for v in [1.0f32, 2.0, 3.0, 4.0] {
            pixel.add([0.0, v, 0.0]);
        }
        // Sample variance of 1..4 is 5/3; of the mean, 5/12.
        assert!((variance_of_mean(&pixel, 1) - 5.0 / 12.0).abs() < 1e-12);
        assert!(
            (pixel_relative_error(&pixel) - (5.0f64 / 12.0 / (2.5 * 2.5 + 0.01)).sqrt()).abs()
                < 1e-12
        );
        let mut single = PixelSums::default();
        single.add([0.0, 1.0, 0.0]);
        assert!(variance_of_mean(&single, 1).is_infinite());
    }
}
