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
pub type SquareSum = ExactSum<SQUARE_FRACTION_BITS>;
const SQUARE_FRACTION_BITS: i32 = 36;

/// Samples larger than this (or not finite) are rejected as numerical failures, so that no
/// single sample can overflow the sums.
pub const LARGEST_SAMPLE: f64 = (1u64 << 40) as f64;

/// Running sums for one pixel. With N samples of (filter-weighted) XYZ values vᵢ, the pixel is
/// Σvᵢ/N; Σvᵢ² gives the variance of that mean. Under filter MIS a "sample" is the total Tₛ that
/// one sample index brings the pixel from all the pixels around it, and [`ControlSums`] hold
/// what its control variate needs (see [`crate::film::reconstruction`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct PixelSums {
    pub xyz: [ValueSum; 3],
    pub xyz_squared: [SquareSum; 3],
    pub samples: u64,
    /// Samples whose value was NaN, infinite or absurdly large, dropped from the sums.
    pub rejected: u64,
    /// Zero under the one-pixel reconstruction.
    pub control: ControlSums,
}

/// The sums of filter MIS's control variate for one pixel: with Tₛ the pixel's total of sample
/// index s and Wₛ its total filter weight (E[Wₛ] = 1), and the indices split into two
/// independent halves A and B.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ControlSums {
    /// Σ Tₛ over half A.
    pub xyz_first_half: [ValueSum; 3],
    /// Σ (Wₛ − 1) over half A, and over half B.
    pub excess: [ValueSum; 2],
    /// Σ Tₛ (Wₛ − 1) of each channel.
    pub xyz_excess: [SquareSum; 3],
    /// Σ (Wₛ − 1)².
    pub excess_squared: SquareSum,
    /// How many of the samples are in half A.
    pub first_half_samples: u64,
}

/// Whether every value is finite and not absurdly large.
#[inline]
pub fn acceptable_sample(values: &[f32]) -> bool {
    values
        .iter()
        .all(|v| v.is_finite() && f64::from(v.abs()) < LARGEST_SAMPLE)
}

impl PixelSums {
    /// Adds one sample; a non-finite (or absurdly large) value is counted and dropped.
    #[inline]
    pub fn add(&mut self, xyz: [f32; 3]) {
        self.samples += 1;
        if !acceptable_sample(&xyz) {
            self.rejected += 1;
            return;
        }
        for ((sum, squares), v) in self.xyz.iter_mut().zip(&mut self.xyz_squared).zip(xyz) {
            let v = f64::from(v);
            sum.add(v);
            squares.add(v * v);
        }
    }

    /// Adds the total `xyz` that one sample index brings the pixel from everywhere on the film
    /// (the particle tracer's splats): one sample of the pixel, whose mean over sample indices
    /// is the image and whose spread gives its variance by batch means. A total that is not
    /// finite is counted and dropped.
    #[inline]
    pub fn add_total(&mut self, xyz: [f64; 3]) {
        self.samples += 1;
        if !xyz
            .iter()
            .all(|v| v.is_finite() && v.abs() < LARGEST_SAMPLE)
        {
            self.rejected += 1;
            return;
        }
        for (c, v) in xyz.into_iter().enumerate() {
            self.xyz[c].add(v);
            self.xyz_squared[c].add(v * v);
        }
    }

    /// Adds the total `xyz` of one sample index under filter MIS, with its weight's excess
    /// W − 1, to half A (`second_half` false) or B. Its sources were screened already
    /// ([`Self::count_rejected`]); a total that is still not finite is counted and dropped.
    #[inline]
    pub fn add_shared(&mut self, xyz: [f64; 3], excess: f64, second_half: bool) {
        self.samples += 1;
        if !(xyz
            .iter()
            .all(|v| v.is_finite() && v.abs() < LARGEST_SAMPLE)
            && excess.is_finite())
        {
            self.rejected += 1;
            return;
        }
        let control = &mut self.control;
        for (c, v) in xyz.into_iter().enumerate() {
            self.xyz[c].add(v);
            self.xyz_squared[c].add(v * v);
            control.xyz_excess[c].add(v * excess);
            if !second_half {
                control.xyz_first_half[c].add(v);
            }
        }
        control.excess[usize::from(second_half)].add(excess);
        control.excess_squared.add(excess * excess);
        if !second_half {
            control.first_half_samples += 1;
        }
    }

    /// One of the samples drawn in this pixel was rejected: under filter MIS it adds nothing to
    /// any pixel, and is counted here, where it was drawn.
    #[inline]
    pub fn count_rejected(&mut self) {
        self.rejected += 1;
    }

    /// Adds the sums of other samples of the same pixel.
    pub fn merge(&mut self, other: &PixelSums) {
        for c in 0..3 {
            self.xyz[c].merge(other.xyz[c]);
            self.xyz_squared[c].merge(other.xyz_squared[c]);
            self.control.xyz_first_half[c].merge(other.control.xyz_first_half[c]);
            self.control.xyz_excess[c].merge(other.control.xyz_excess[c]);
        }
        for h in 0..2 {
            self.control.excess[h].merge(other.control.excess[h]);
        }
        self.control
            .excess_squared
            .merge(other.control.excess_squared);
        self.control.first_half_samples += other.control.first_half_samples;
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

    /// The estimate of a quantity whose sum over all samples is `sum` and over half A
    /// `first_half`: (sum − β_B Σ_A (W − 1) − β_A Σ_B (W − 1)) / N, where β of a half is its
    /// ratio Σ T / Σ W (its plain mean where Σ W is under half its sample count). Each half's
    /// correction has mean zero given the other half, so this is unbiased; without a control
    /// variate (the excesses are zero) it is sum / N exactly.
    pub fn controlled_mean(&self, sum: f64, first_half: f64) -> f64 {
        if self.samples == 0 {
            return 0.0;
        }
        let n = self.samples as f64;
        let [excess_a, excess_b] = self.control.excess.map(ExactSum::value);
        if excess_a == 0.0 && excess_b == 0.0 {
            return sum / n;
        }
        let n_a = self.control.first_half_samples as f64;
        let ratio = |total: f64, count: f64, excess: f64| {
            if count == 0.0 {
                0.0
            } else if count + excess >= 0.5 * count {
                total / (count + excess)
            } else {
                total / count
            }
        };
        let beta_a = ratio(first_half, n_a, excess_a);
        let beta_b = ratio(sum - first_half, n - n_a, excess_b);
        (sum - beta_b * excess_a - beta_a * excess_b) / n
    }

    /// The pixel's estimate of XYZ: the mean over all samples taken, with filter MIS's control
    /// variate (a rejected sample counts as zero, which keeps the estimate unbiased for
    /// integrands that are finite almost everywhere).
    pub fn mean(&self) -> [f64; 3] {
        [0, 1, 2].map(|c| self.controlled_mean(self.sum(c), self.control.xyz_first_half[c].value()))
    }

    /// The variance of [`Self::mean`] of channel `c`, infinite with fewer than two samples.
    ///
    /// Without a control variate it is the sample variance over N, s²/N with
    /// s² = (Σvₛ² − N m²)/(N − 1). With it, the residuals rₛ = eₛ + Î with eₛ = Tₛ − Î Wₛ take the
    /// place of the vₛ (the delta method for the ratio), and the cross-fitting adds a term: with
    /// halves of N/2, Î − I ≈ (ē_A + ē_B)/2 − (ē_B w̄_A + ē_A w̄_B)/2 (w̄ the halves' mean weight
    /// excess), whose variance is σₑ²/N · (1 + 2 σ_W²/N). Both are unbiased to first order for
    /// independent sample indices.
    ///
    /// It is at least 2⁻³⁷/(N − 1), the most by which rounding each square to the resolution of
    /// its sum ([`SquareSum`]) can change it: a pixel whose values are so small that their
    /// squares round to zero (a dark pixel at the edge of its neighbours' filter support) is
    /// not reported as exact.
    pub fn variance_of_mean(&self, c: usize) -> f64 {
        if self.samples < 2 {
            return f64::INFINITY;
        }
        let n = self.samples as f64;
        let beta = self.mean()[c];
        let control = &self.control;
        let excess: f64 = control.excess.iter().map(|e| e.value()).sum();
        let sum = self.sum(c) - beta * excess;
        let squares = self.sum_of_squares(c) - 2.0 * beta * control.xyz_excess[c].value()
            + beta * beta * control.excess_squared.value();
        let mean = sum / n;
        let residual = ((squares / n - mean * mean) / (n - 1.0)).max(0.0);
        let mean_excess = excess / n;
        let weight_variance =
            (control.excess_squared.value() / n - mean_excess * mean_excess).max(0.0);
        let cross_fitting = 1.0 + 2.0 * weight_variance / n;
        (residual * cross_fitting).max(SQUARE_RESOLUTION / 2.0 / (n - 1.0))
    }
}

/// The resolution of a [`SquareSum`].
const SQUARE_RESOLUTION: f64 = 1.0 / (1u64 << SQUARE_FRACTION_BITS) as f64;

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

/// Adds one sample index's totals of a pixel's K extra channels under filter MIS: `sums` holds
/// the K sums over all samples, then the K over half A ([`Film::aovs`]).
#[inline]
pub fn add_shared_aov_sample(sums: &mut [ValueSum], values: &[f64], second_half: bool) {
    let (all, first_half) = sums.split_at_mut(values.len());
    for ((sum, half), &v) in all.iter_mut().zip(first_half).zip(values) {
        if v.is_finite() && v.abs() < LARGEST_SAMPLE {
            sum.add(v);
            if !second_half {
                half.add(v);
            }
        }
    }
}

/// The sums kept per pixel and extra channel: over all samples, and over half A.
pub const AOV_SUMS_PER_CHANNEL: usize = 2;

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
    /// Sums of the filter-weighted samples of the extra channels, 2K per pixel (K =
    /// `aov_names.len()`): pixel i's K sums over all its samples at 2iK .. 2iK + K, then their K
    /// sums over half A of filter MIS's control variate (zero under the one-pixel
    /// reconstruction). A channel's value is controlled as the image's ([`PixelSums::mean`]).
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
            aovs: vec![ValueSum::default(); pixel_count * AOV_SUMS_PER_CHANNEL * aov_names.len()],
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
                let sums = &self.aovs[i * 2 * k..(i + 1) * 2 * k];
                p.controlled_mean(sums[channel].value(), sums[k + channel].value()) as f32
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
