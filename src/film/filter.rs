//! Pixel reconstruction filters, importance sampled as the lecture prescribes ("Spatial and
//! Temporal Filtering"): a film sample's offset from the pixel centre is drawn with density
//! p(x, y) ∝ |k(x) k(y)| and weighted by k(x)k(y) / (p(x, y) · (∫k)²).
//!
//! Normalisation: the pixel value is (1/N) Σ wᵢ Lᵢ, dividing by the number of samples N, which is
//! an unbiased estimate of ∫∫ k(x)k(y) L / (∫k)²; pbrt instead divides by Σ wᵢ, which is biased
//! but consistent. For filters without negative lobes sampled exactly, every weight is 1 and the
//! two agree. Each sample lands in its own pixel only, so pixels are independent and the image
//! does not depend on the order in which samples are taken.
//!
//! ```xml
//! <rfilter type="box"/>                                 <!-- radius 0.5 -->
//! <rfilter type="tent"/>                                <!-- radius 1 -->
//! <rfilter type="gaussian"><float name="stddev" value="0.5"/></rfilter>   <!-- radius 4σ -->
//! ```

use glam::Vec2;

use crate::sampling::distribution::PiecewiseConstant1D;

/// A separable reconstruction filter k(x)k(y).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Filter {
    /// k = 1 on [−r, r].
    Box { radius: f32 },
    /// k = max(0, 1 − |x|/r).
    Tent { radius: f32 },
    /// Mitsuba 3's truncated Gaussian: k = max(0, exp(−x²/2σ²) − exp(−r²/2σ²)), r = 4σ.
    Gaussian { stddev: f32 },
}

impl Filter {
    pub fn radius(&self) -> f32 {
        match *self {
            Filter::Box { radius } | Filter::Tent { radius } => radius,
            Filter::Gaussian { stddev } => 4.0 * stddev,
        }
    }

    /// The 1-D kernel k(x).
    pub fn eval(&self, x: f32) -> f32 {
        let r = self.radius();
        if x.abs() > r {
            return 0.0;
        }
        match *self {
            Filter::Box { .. } => 1.0,
            Filter::Tent { radius } => (1.0 - x.abs() / radius).max(0.0),
            Filter::Gaussian { stddev } => {
                let alpha = -1.0 / (2.0 * stddev * stddev);
                ((alpha * x * x).exp() - (alpha * r * r).exp()).max(0.0)
            }
        }
    }
}

/// Cells per unit of filter radius in the tabulated density.
const CELLS_PER_UNIT_RADIUS: f32 = 64.0;

/// Draws film offsets for a filter by inverting the CDF of |k| tabulated per axis.
#[derive(Clone, Debug)]
pub struct FilterSampler {
    filter: Filter,
    distribution: PiecewiseConstant1D,
    /// ∫ k(x) dx over the support.
    integral: f32,
}

impl FilterSampler {
    pub fn new(filter: Filter) -> FilterSampler {
        let r = filter.radius();
        let cells = ((CELLS_PER_UNIT_RADIUS * r).ceil() as usize).max(1) * 2;
        let width = 2.0 * r / cells as f32;
        // Each cell's weight is the mean of |k| over it (Simpson's rule on 8 sub-intervals), so
        // the tabulated density follows the kernel closely even where it changes quickly.
        let cell_integral = |i: usize, f: &dyn Fn(f32) -> f32| -> f64 {
            let a = -r + i as f32 * width;
            let m = 8;
            let h = width / m as f32;
            (0..=m)
                .map(|j| {
                    let w = if j == 0 || j == m {
                        1.0
                    } else if j % 2 == 1 {
                        4.0
                    } else {
                        2.0
                    };
                    w * f64::from(f(a + j as f32 * h))
                })
                .sum::<f64>()
                * f64::from(h)
                / 3.0
        };
        let weights: Vec<f32> = (0..cells)
            .map(|i| (cell_integral(i, &|x| filter.eval(x).abs()) / f64::from(width)) as f32)
            .collect();
        let integral: f64 = (0..cells)
            .map(|i| cell_integral(i, &|x| filter.eval(x)))
            .sum();
        FilterSampler {
            filter,
            distribution: PiecewiseConstant1D::new(&weights, -r, r),
            integral: integral as f32,
        }
    }

    pub fn filter(&self) -> Filter {
        self.filter
    }

    /// An offset from the pixel centre and its weight k(x)k(y) / (p(x)p(y)(∫k)²).
    #[inline]
    pub fn sample(&self, u: Vec2) -> (Vec2, f32) {
        let (x, _) = self.distribution.sample(u.x);
        let (y, _) = self.distribution.sample(u.y);
        let k = self.filter.eval(x) * self.filter.eval(y);
        let p = self.distribution.pdf(x) * self.distribution.pdf(y);
        let weight = if p > 0.0 {
            k / (p * self.integral * self.integral)
        } else {
            0.0
        };
        (Vec2::new(x, y), weight)
    }

    /// Density of an offset (per unit area of the film): the product of the per-axis densities.
    pub fn pdf(&self, offset: Vec2) -> f32 {
        self.distribution.pdf(offset.x) * self.distribution.pdf(offset.y)
    }

    /// Density of one coordinate of an offset (both axes are sampled alike and independently).
    pub fn pdf_1d(&self, x: f32) -> f32 {
        self.distribution.pdf(x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::rng::Pcg32;

    #[test]
    fn box_filter_samples_have_unit_weight_and_stay_in_the_pixel() {
        let sampler = FilterSampler::new(Filter::Box { radius: 0.5 });
        let mut rng = Pcg32::seeded(2);
        for _ in 0..10_000 {
            let (offset, weight) = sampler.sample(Vec2::new(rng.next_f32(), rng.next_f32()));
            assert!(offset.x.abs() <= 0.5 && offset.y.abs() <= 0.5);
            assert!((weight - 1.0).abs() < 1e-5, "{weight}");
        }
    }

    /// The weights average to 1 (the filter is normalised) within 4 standard errors.
    #[test]
    fn filter_weights_have_unit_mean() {
        for filter in [
            Filter::Tent { radius: 1.0 },
            Filter::Gaussian { stddev: 0.5 },
        ] {
            let sampler = FilterSampler::new(filter);
            let mut rng = Pcg32::seeded(3);
            let n = 200_000;
            let (mut sum, mut sum2) = (0.0f64, 0.0f64);
            for _ in 0..n {
                let (_, w) = sampler.sample(Vec2::new(rng.next_f32(), rng.next_f32()));
                sum += f64::from(w);
                sum2 += f64::from(w) * f64::from(w);
            }
            let mean = sum / n as f64;
            let se = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
            assert!(
                (mean - 1.0).abs() < 4.0 * se + 1e-6,
                "{filter:?}: {mean} ± {se}"
            );
        }
    }
}
