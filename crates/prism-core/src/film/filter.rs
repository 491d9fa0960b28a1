//! Pixel reconstruction filters, importance sampled as the lecture prescribes ("Spatial and
//! Temporal Filtering"): a film sample's offset from the pixel centre is drawn with density
//! p(x, y) ∝ |k(x) k(y)| and weighted by k(x)k(y) / (p(x, y) · (∫k)²).
//!
//! Normalisation: the pixel value is (1/N) Σ wᵢ Lᵢ, dividing by the number of samples N, which is
//! an unbiased estimate of ∫∫ k(x)k(y) L / (∫k)²; pbrt instead divides by Σ wᵢ, which is biased
//! but consistent. For filters without negative lobes sampled exactly, every weight is 1 and the
//! two agree. This is the `pixel` reconstruction, where each sample lands in its own pixel only;
//! the default, filter MIS, lets each sample feed every pixel whose filter covers it, with the
//! same densities ([`super::reconstruction`]).
//!
//! Filters with negative lobes (Mitchell–Netravali, Catmull–Rom, Lanczos) keep them: a sample
//! drawn where k(x)k(y) < 0 gets a negative weight instead of being clipped, so the estimate
//! remains the filtered image itself (and a constant image stays constant).
//!
//! ```xml
//! <rfilter type="box"/>                                 <!-- radius 0.5 -->
//! <rfilter type="tent"/>                                <!-- radius 1 -->
//! <rfilter type="gaussian"><float name="stddev" value="0.5"/></rfilter>   <!-- radius 4σ -->
//! <rfilter type="mitchell"><float name="B" value="0.3333"/><float name="C" value="0.3333"/></rfilter>
//! <rfilter type="catmullrom"/>                          <!-- Mitchell with B = 0, C = 1/2 -->
//! <rfilter type="lanczos"><integer name="lobes" value="3"/></rfilter>
//! ```

use glam::Vec2;

use crate::dispatch::plugin_class;
use crate::math::quadrature::simpson;
use crate::sampling::distribution::PiecewiseConstant1D;

plugin_class! {
    /// What every reconstruction kernel answers: its support and its value, and whether its
    /// density |k|/∫|k| can be sampled in closed form.
    pub trait Kernel {
        /// The radius r of the support [−r, r].
        fn radius(&self) -> f32;

        /// k(x) for |x| ≤ r.
        fn kernel(&self, x: f32) -> f32;

        /// How the density |k|/∫|k| is sampled exactly (the box and the tent, which are
        /// non-negative); None for kernels sampled from a table of |k| ([`FilterSampler`]).
        fn closed_form(&self) -> Option<ClosedForm>;

        /// The 1-D kernel k(x), zero outside the support.
        fn eval(&self, x: f32) -> f32 {
            if x.abs() > self.radius() {
                0.0
            } else {
                self.kernel(x)
            }
        }
    }

    /// A separable reconstruction filter k(x)k(y).
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub enum Filter {
        Box(BoxFilter),
        Tent(TentFilter),
        Gaussian(GaussianFilter),
        Mitchell(MitchellFilter),
        Lanczos(LanczosFilter),
    }
}

/// The exact sampling of a non-negative kernel: ∫k, and the inverse of the CDF of k/∫k on the
/// support scaled to [−1, 1] (x = r · inverse_cdf(u)).
#[derive(Clone, Copy, Debug)]
pub struct ClosedForm {
    pub integral: f32,
    pub inverse_cdf: fn(f32) -> f32,
}

/// k = 1 on [−r, r].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoxFilter {
    pub radius: f32,
}

impl Kernel for BoxFilter {
    fn radius(&self) -> f32 {
        self.radius
    }

    fn kernel(&self, _x: f32) -> f32 {
        1.0
    }

    fn closed_form(&self) -> Option<ClosedForm> {
        Some(ClosedForm {
            integral: 2.0 * self.radius,
            inverse_cdf: |u| 2.0 * u - 1.0,
        })
    }
}

/// k = max(0, 1 − |x|/r).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TentFilter {
    pub radius: f32,
}

impl Kernel for TentFilter {
    fn radius(&self) -> f32 {
        self.radius
    }

    fn kernel(&self, x: f32) -> f32 {
        (1.0 - x.abs() / self.radius).max(0.0)
    }

    fn closed_form(&self) -> Option<ClosedForm> {
        Some(ClosedForm {
            integral: self.radius,
            inverse_cdf: sample_tent,
        })
    }
}

/// Mitsuba 3's truncated Gaussian: k = max(0, exp(−x²/2σ²) − exp(−r²/2σ²)), r = 4σ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GaussianFilter {
    pub stddev: f32,
}

impl Kernel for GaussianFilter {
    fn radius(&self) -> f32 {
        4.0 * self.stddev
    }

    fn kernel(&self, x: f32) -> f32 {
        let r = self.radius();
        let alpha = -1.0 / (2.0 * self.stddev * self.stddev);
        ((alpha * x * x).exp() - (alpha * r * r).exp()).max(0.0)
    }

    fn closed_form(&self) -> Option<ClosedForm> {
        None
    }
}

/// The cubic of Mitchell & Netravali 1988, "Reconstruction Filters in Computer Graphics", eq. 8,
/// on [−2, 2]; Catmull–Rom is B = 0, C = 1/2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MitchellFilter {
    pub b: f32,
    pub c: f32,
}

impl Kernel for MitchellFilter {
    fn radius(&self) -> f32 {
        2.0
    }

    fn kernel(&self, x: f32) -> f32 {
        let (b, c) = (self.b, self.c);
        let x = x.abs();
        let (x2, x3) = (x * x, x * x * x);
        let polynomial = if x < 1.0 {
            (12.0 - 9.0 * b - 6.0 * c) * x3 + (-18.0 + 12.0 * b + 6.0 * c) * x2 + (6.0 - 2.0 * b)
        } else {
            (-b - 6.0 * c) * x3
                + (6.0 * b + 30.0 * c) * x2
                + (-12.0 * b - 48.0 * c) * x
                + (8.0 * b + 24.0 * c)
        };
        polynomial / 6.0
    }

    fn closed_form(&self) -> Option<ClosedForm> {
        None
    }
}

/// Lanczos' windowed sinc, sinc(x) sinc(x/a) on [−a, a] with a = `lobes`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LanczosFilter {
    pub lobes: u32,
}

impl Kernel for LanczosFilter {
    fn radius(&self) -> f32 {
        self.lobes as f32
    }

    fn kernel(&self, x: f32) -> f32 {
        let x = x.abs();
        if x < 1e-6 {
            return 1.0;
        }
        let r = self.radius();
        let (px, pxa) = (std::f32::consts::PI * x, std::f32::consts::PI * x / r);
        (px.sin() * pxa.sin()) / (px * pxa)
    }

    fn closed_form(&self) -> Option<ClosedForm> {
        None
    }
}

/// Cells per unit of filter radius in the tabulated density.
const CELLS_PER_UNIT_RADIUS: f32 = 64.0;

/// Draws film offsets for a filter: the box and the tent by inverting their CDFs exactly
/// ([`Kernel::closed_form`]), other kernels by inverting the CDF of |k| tabulated per axis.
#[derive(Clone, Debug)]
pub struct FilterSampler {
    filter: Filter,
    /// How offsets are drawn: the kernel's closed form, or a table of |k| with ∫ k(x) dx.
    sampling: OffsetSampling,
}

impl FilterSampler {
    pub fn new(filter: Filter) -> FilterSampler {
        let sampling = match filter.closed_form() {
            Some(closed) => OffsetSampling::Exact(closed),
            None => {
                let (table, integral) = Self::table(filter);
                OffsetSampling::Table(table, integral)
            }
        };
        FilterSampler { filter, sampling }
    }

    /// The tabulated density of |k| and the integral of k.
    fn table(filter: Filter) -> (PiecewiseConstant1D, f32) {
        let r = filter.radius();
        let cells = ((CELLS_PER_UNIT_RADIUS * r).ceil() as usize).max(1) * 2;
        let width = 2.0 * r / cells as f32;
        // Each cell's weight is the mean of |k| over it (Simpson's rule on 8 sub-intervals), so
        // the tabulated density follows the kernel closely even where it changes quickly.
        let cell_integral = |i: usize, f: &dyn Fn(f32) -> f32| -> f64 {
            let a = f64::from(-r + i as f32 * width);
            simpson(|x| f64::from(f(x as f32)), a, a + f64::from(width), 8)
        };
        let weights: Vec<f32> = (0..cells)
            .map(|i| (cell_integral(i, &|x| filter.eval(x).abs()) / f64::from(width)) as f32)
            .collect();
        let integral: f64 = (0..cells)
            .map(|i| cell_integral(i, &|x| filter.eval(x)))
            .sum();
        (PiecewiseConstant1D::new(&weights, -r, r), integral as f32)
    }

    pub fn filter(&self) -> Filter {
        self.filter
    }

    /// ∫ k(x) dx over the support (tabulated by Simpson's rule for kernels other than the box
    /// and the tent).
    pub fn integral_1d(&self) -> f32 {
        match &self.sampling {
            OffsetSampling::Exact(closed) => closed.integral,
            OffsetSampling::Table(_, integral) => *integral,
        }
    }

    /// One coordinate of an offset, with density ∝ |k|, and its weight k(x) / (p(x) ∫k): 1 for
    /// kernels sampled in closed form, whose densities are exactly k/∫k.
    #[inline]
    pub fn sample_1d(&self, u: f32) -> (f32, f32) {
        let (distribution, integral) = match &self.sampling {
            OffsetSampling::Exact(closed) => {
                return (self.filter.radius() * (closed.inverse_cdf)(u), 1.0);
            }
            OffsetSampling::Table(distribution, integral) => (distribution, integral),
        };
        let (x, _) = distribution.sample(u);
        let p = distribution.pdf(x);
        let weight = if p > 0.0 {
            self.filter.eval(x) / (p * integral)
        } else {
            0.0
        };
        (x, weight)
    }

    /// An offset from the pixel centre and its weight k(x)k(y) / (p(x)p(y)(∫k)²): the two axes
    /// are sampled independently (the filter is a tensor product).
    #[inline]
    pub fn sample(&self, u: Vec2) -> (Vec2, f32) {
        let (x, wx) = self.sample_1d(u.x);
        let (y, wy) = self.sample_1d(u.y);
        (Vec2::new(x, y), wx * wy)
    }

    /// Density of an offset (per unit area of the film): the product of the per-axis densities.
    pub fn pdf(&self, offset: Vec2) -> f32 {
        self.pdf_1d(offset.x) * self.pdf_1d(offset.y)
    }

    /// Density of one coordinate of an offset (both axes are sampled alike and independently).
    pub fn pdf_1d(&self, x: f32) -> f32 {
        match &self.sampling {
            OffsetSampling::Exact(closed) => self.filter.eval(x) / closed.integral,
            OffsetSampling::Table(distribution, _) => distribution.pdf(x),
        }
    }
}

/// How a [`FilterSampler`] draws offsets.
#[derive(Clone, Debug)]
enum OffsetSampling {
    /// By the kernel's closed form.
    Exact(ClosedForm),
    /// From the tabulated density of |k|, with ∫ k(x) dx over the support.
    Table(PiecewiseConstant1D, f32),
}

/// The tent on [−1, 1], density 1 − |x|, by inverting its CDF: u < ½ is the left half, where
/// the CDF is (1 + x)²/2.
#[inline]
fn sample_tent(u: f32) -> f32 {
    if u < 0.5 {
        (2.0 * u).sqrt() - 1.0
    } else {
        1.0 - (2.0 - 2.0 * u).sqrt()
    }
}

/// The filters the tests of filtering and of its importance sampling run over: one of each
/// smooth kind, with Mitchell–Netravali's recommended (1/3, 1/3), Catmull-Rom's negative lobes
/// and Lanczos's oscillating ones.
#[cfg(test)]
pub(crate) fn filters_under_test() -> [Filter; 5] {
    [
        Filter::Tent(TentFilter { radius: 1.0 }),
        Filter::Gaussian(GaussianFilter { stddev: 0.5 }),
        Filter::Mitchell(MitchellFilter {
            b: 1.0 / 3.0,
            c: 1.0 / 3.0,
        }),
        Filter::Mitchell(MitchellFilter { b: 0.0, c: 0.5 }),
        Filter::Lanczos(LanczosFilter { lobes: 3 }),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::rng::Pcg32;

    #[test]
    fn box_filter_samples_have_unit_weight_and_stay_in_the_pixel() {
        let sampler = FilterSampler::new(Filter::Box(BoxFilter { radius: 0.5 }));
        let mut rng = Pcg32::seeded(2);
        for _ in 0..10_000 {
            let (offset, weight) = sampler.sample(Vec2::new(rng.next_f32(), rng.next_f32()));
            assert!(offset.x.abs() <= 0.5 && offset.y.abs() <= 0.5);
            assert!((weight - 1.0).abs() < 1e-5, "{weight}");
        }
    }

    /// Mitchell–Netravali's cubic is C¹ at |x| = 1 and vanishes at 2 (for any B, C), and the
    /// integer translates of the kernel sum to 1 (Mitchell & Netravali 1988, §4).
    #[test]
    fn mitchell_kernel_is_smooth_and_a_partition_of_unity() {
        for (b, c) in [(1.0 / 3.0, 1.0 / 3.0), (0.0, 0.5), (1.0, 0.0)] {
            let k = Filter::Mitchell(MitchellFilter { b, c });
            assert!((k.eval(1.0 - 1e-4) - k.eval(1.0 + 1e-4)).abs() < 1e-3);
            assert!(k.eval(1.999).abs() < 1e-4);
            for x in [0.0f32, 0.1, 0.37, 0.5, 0.9] {
                let sum: f32 = (-2..=2).map(|i| k.eval(x + i as f32)).sum();
                assert!((sum - 1.0).abs() < 1e-5, "B {b} C {c} x {x}: {sum}");
            }
        }
        assert!(
            Filter::Mitchell(MitchellFilter { b: 0.0, c: 0.5 }).eval(1.5) < 0.0,
            "Catmull-Rom has negative lobes"
        );
        assert_eq!(Filter::Lanczos(LanczosFilter { lobes: 3 }).eval(0.0), 1.0);
        assert!(Filter::Lanczos(LanczosFilter { lobes: 3 }).eval(1.0).abs() < 1e-6);
    }

    /// The weights average to 1 (the filter is normalised) within 4 standard errors.
    #[test]
    fn filter_weights_have_unit_mean() {
        for filter in filters_under_test() {
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
