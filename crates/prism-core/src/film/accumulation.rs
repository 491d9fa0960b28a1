//! The film: per-pixel sums of the CIE XYZ estimates and of their squares, kept exactly, and the
//! sums of the extra channels (AOVs) an integrator may write beside the image.

use glam::UVec2;

use crate::spectrum::cie::xyz_to_linear_srgb;

/// The rectangle of the full film that is rendered (Mitsuba's crop window).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CropWindow {
    pub offset: UVec2,
    pub size: UVec2,
}

/// An exact sum of sample values: fixed point in 128 bits, so that adding is associative and a
/// pixel's sums do not depend on the order of its samples. This makes a render resumed from a
/// checkpoint, or merged from renders of disjoint sample ranges, bit-identical to one render of
/// all the samples. Values are rounded to a multiple of 2^-`FRACTION_BITS`; additions saturate
/// instead of overflowing.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ExactSum<const FRACTION_BITS: i32>(pub i128);

impl<const FRACTION_BITS: i32> ExactSum<FRACTION_BITS> {
    #[inline]
    pub fn add(&mut self, v: f64) {
        let scaled = (v * 2f64.powi(FRACTION_BITS)).round();
        // Through i64 where it fits: the processor converts that in one instruction, whereas a
        // float-to-i128 conversion is a library call. Both give the same integer.
        let scaled = if scaled.abs() < 9.0e18 {
            i128::from(scaled as i64)
        } else {
            scaled as i128
        };
        self.0 = self.0.saturating_add(scaled);
    }

    #[inline]
    pub fn merge(&mut self, other: Self) {
        self.0 = self.0.saturating_add(other.0);
    }

    #[inline]
    pub fn value(self) -> f64 {
        self.0 as f64 * 2f64.powi(-FRACTION_BITS)
    }
}

/// Sums of sample values: resolution 2⁻⁵⁶ (1.4·10⁻¹⁷), range ±2⁷¹ (2.4·10²¹).
pub type ValueSum = ExactSum<56>;
/// Sums of squared sample values: resolution 2⁻³⁶ (1.5·10⁻¹¹), range ±2⁹¹.
pub type SquareSum = ExactSum<36>;

/// Samples larger than this (or not finite) are rejected as numerical failures, so that no
/// single sample can overflow the sums.
pub const LARGEST_SAMPLE: f64 = (1u64 << 40) as f64;

/// Running sums for one pixel. With N samples of (filter-weighted) XYZ values vᵢ, the pixel is
/// Σvᵢ/N; Σvᵢ² gives the variance of that mean.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct PixelSums {
    pub xyz: [ValueSum; 3],
    pub xyz_squared: [SquareSum; 3],
    pub samples: u64,
    /// Samples whose value was NaN, infinite or absurdly large, dropped from the sums.
    pub rejected: u64,
}

impl PixelSums {
    /// Adds one sample; a non-finite (or absurdly large) value is counted and dropped.
    #[inline]
    pub fn add(&mut self, xyz: [f32; 3]) {
        self.samples += 1;
        if !xyz
            .iter()
            .all(|v| v.is_finite() && f64::from(v.abs()) < LARGEST_SAMPLE)
        {
            self.rejected += 1;
            return;
        }
        for ((sum, squares), v) in self.xyz.iter_mut().zip(&mut self.xyz_squared).zip(xyz) {
            let v = f64::from(v);
            sum.add(v);
            squares.add(v * v);
        }
    }

    /// Adds the sums of other samples of the same pixel.
    pub fn merge(&mut self, other: &PixelSums) {
        for c in 0..3 {
            self.xyz[c].merge(other.xyz[c]);
            self.xyz_squared[c].merge(other.xyz_squared[c]);
        }
        self.samples += other.samples;
        self.rejected += other.rejected;
    }

    /// Σvᵢ of channel `c` (0 = X, 1 = Y, 2 = Z).
    pub fn sum(&self, c: usize) -> f64 {
        self.xyz[c].value()
    }

    /// Σvᵢ² of channel `c`.
    pub fn sum_of_squares(&self, c: usize) -> f64 {
        self.xyz_squared[c].value()
    }

    /// The pixel's estimate of XYZ: the mean over all samples taken (a rejected sample counts as
    /// zero, which keeps the estimate unbiased for integrands that are finite almost everywhere).
    pub fn mean(&self) -> [f64; 3] {
        if self.samples == 0 {
            return [0.0; 3];
        }
        [0, 1, 2].map(|c| self.sum(c) / self.samples as f64)
    }
}

/// Adds one sample of a pixel's extra channels to their sums: a value that is not finite (or is
/// absurdly large) adds nothing, so the channel's mean counts it as zero, as the image does with
/// a rejected sample.
#[inline]
pub fn add_aov_sample(sums: &mut [ValueSum], values: &[f32]) {
    for (sum, &v) in sums.iter_mut().zip(values) {
        if v.is_finite() && f64::from(v.abs()) < LARGEST_SAMPLE {
            sum.add(f64::from(v));
        }
    }
}

/// The image being rendered.
#[derive(Clone, Debug)]
pub struct Film {
    /// Size of the full film in pixels.
    pub size: UVec2,
    pub crop: CropWindow,
    /// Pixels of the crop window, row-major, top row first.
    pub pixels: Vec<PixelSums>,
    /// Names of the extra channels (AOVs) beside the image, as the EXR names them.
    pub aov_names: Vec<String>,
    /// Sums of the filter-weighted samples of the extra channels: pixel i's K channels at
    /// i·K .. (i + 1)·K, K = `aov_names.len()`. A channel's value is its sum over the pixel's
    /// sample count, as the image's.
    pub aovs: Vec<ValueSum>,
}

impl Film {
    /// A film without extra channels.
    pub fn new(size: UVec2, crop: CropWindow) -> Film {
        Film::with_aovs(size, crop, Vec::new())
    }

    /// A film with the extra channels `aov_names`.
    pub fn with_aovs(size: UVec2, crop: CropWindow, aov_names: Vec<String>) -> Film {
        let pixel_count = (crop.size.x * crop.size.y) as usize;
        Film {
            size,
            crop,
            pixels: vec![PixelSums::default(); pixel_count],
            aovs: vec![ValueSum::default(); pixel_count * aov_names.len()],
            aov_names,
        }
    }

    /// Every pixel's value of extra channel `channel`, row-major.
    pub fn aov(&self, channel: usize) -> Vec<f32> {
        let k = self.aov_names.len();
        self.pixels
            .iter()
            .enumerate()
            .map(|(i, p)| {
                if p.samples == 0 {
                    0.0
                } else {
                    (self.aovs[i * k + channel].value() / p.samples as f64) as f32
                }
            })
            .collect()
    }

    /// Index in `pixels` of a pixel given relative to the crop window.
    #[inline]
    pub fn index(&self, x: u32, y: u32) -> usize {
        (y * self.crop.size.x + x) as usize
    }

    /// XYZ of every pixel, row-major.
    pub fn xyz(&self) -> Vec<[f32; 3]> {
        self.pixels
            .iter()
            .map(|p| p.mean().map(|v| v as f32))
            .collect()
    }

    /// Linear sRGB of every pixel.
    pub fn linear_srgb(&self) -> Vec<[f32; 3]> {
        self.xyz().into_iter().map(xyz_to_linear_srgb).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::rng::Pcg32;

    /// Sums do not depend on the order or grouping of the samples.
    #[test]
    fn sums_are_order_independent() {
        let mut rng = Pcg32::seeded(8);
        let samples: Vec<[f32; 3]> = (0..1000)
            .map(|_| {
                [0, 1, 2].map(|_| {
                    (rng.next_f32() - 0.3) * 10f32.powi((rng.next_f32() * 12.0) as i32 - 6)
                })
            })
            .collect();
        let mut forward = PixelSums::default();
        samples.iter().for_each(|s| forward.add(*s));
        let mut backward = PixelSums::default();
        samples.iter().rev().for_each(|s| backward.add(*s));
        let (mut first, mut second) = (PixelSums::default(), PixelSums::default());
        samples[..377].iter().for_each(|s| first.add(*s));
        samples[377..].iter().for_each(|s| second.add(*s));
        second.merge(&first);
        assert_eq!(forward, backward);
        assert_eq!(forward, second);
        let exact: f64 = samples.iter().map(|s| f64::from(s[1])).sum();
        assert!((forward.sum(1) - exact).abs() <= 1e-9 * exact.abs().max(1.0));
    }

    #[test]
    fn non_finite_and_huge_samples_are_rejected() {
        let mut pixel = PixelSums::default();
        pixel.add([1.0, f32::NAN, 0.0]);
        pixel.add([1.0, 1e13, 0.0]);
        pixel.add([1.0, 2.0, 3.0]);
        assert_eq!((pixel.samples, pixel.rejected), (3, 2));
        assert_eq!(pixel.mean()[1], 2.0 / 3.0);
    }
}
