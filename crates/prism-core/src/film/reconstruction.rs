//! How camera samples become pixel values: every sample feeds every pixel its filter covers
//! (filter MIS, the default), or only the pixel it was drawn for (the lecture's estimator).
//!
//! ## Filter MIS
//!
//! Pixel i (centre cᵢ) estimates Iᵢ = ∫ k(x − cᵢ) f(x) dx, with k the separable filter
//! k(x)k(y) / (∫k)² normalised to unit integral. Every film pixel l draws N samples from its own
//! density pₗ(x), on each axis uniform over its own square, except on the film's first and last
//! columns and rows, which draw from the filter sampler's density (∝ |k|) around their centre so
//! that every point some pixel's filter covers, beyond the film's edge too, is drawn
//! ([`FilterMis::draw_offset`]). Seen from pixel i these are W·H
//! sampling strategies of the image plane, and the balance heuristic combines them (Veach 1997,
//! §9.2): a sample x of any pixel adds
//!
//! ```text
//!     k(x − cᵢ) f(x) / (N · D(x)),   D(x) = Σₗ pₗ(x)   (over the film's pixels),
//! ```
//!
//! to every pixel i whose support contains x. Every point where k(x − cᵢ) ≠ 0 has D(x) > 0, so
//! the estimate is unbiased for any filter, negative lobes included. D is a product of two sums
//! because the pixel grid is: D(x, y) = Dₓ(x) D_y(y) with Dₓ(x) = Σ_{columns l} pₗ(x). Inside the
//! film D = 1 away from the border pixels, and this is splatting k(x − cᵢ) f(x) / N, without
//! the normalisation by Σk that makes Mitsuba's and pbrt's splatting biased; a border pixel's
//! own samples are importance-sampled from its filter. D is taken over the
//! whole film, not the crop window, so a crop renders its pixels exactly as the full film does;
//! the samples of pixels up to [`FilterMis::reach`] outside the crop are drawn for it.
//!
//! Drawing each pixel's samples within its own square, rather than from the filter around its
//! centre, stratifies the samples by pixel as Mitsuba's splatting does: every square holds
//! exactly N samples, so a smooth gradient across a filter's support adds no variance of its
//! own (on a spot-lit floor under the Gaussian filter, 0.89 times the per-pixel variance of
//! filter-shaped draws; docs/performance.md). The sampler's stratification of the film
//! dimensions then stratifies within each square as well. The border rows and columns keep
//! filter-shaped draws, whose tails cover the points beyond the film's edge that the filters
//! of the pixels near it reach.
//!
//! ## The control variate
//!
//! Where the image is flat the plain sum is noisier than the one-pixel estimator: its weights
//! Wᵢ = Σ k(x − cᵢ) / (N D(x)) fluctuate although f does not. But E[Wᵢ] = ∫ k = 1 exactly, so
//! Wᵢ − 1 is a control variate. With Tᵢ the plain estimate, Tᵢ − β (Wᵢ − 1) is unbiased for any β
//! independent of the samples; β = Iᵢ (the ratio Tᵢ / Wᵢ) makes it Mitsuba's normalised splat to
//! first order. Each pixel's samples are split into two independent halves A and B (alternate
//! blocks of the sampler's stratification, which are independently shuffled), β is estimated for
//! each half from the other, and the pixel value is
//!
//! ```text
//!     Î = (Σ_{s} Tₛ − β_B Σ_{s∈A} (Wₛ − 1) − β_A Σ_{s∈B} (Wₛ − 1)) / N,   β_H = Σ_H T / Σ_H W,
//! ```
//!
//! unbiased because each half's correction has mean zero whatever the other half's β is
//! ([`crate::film::PixelSums::mean`]). Its variance is estimated by the delta method from the
//! residuals Tₛ − Î (Wₛ − 1) of whole sample indices: the totals of one index over all source
//! pixels are independent of those of another index (every pixel's samples of one index come
//! from their own random streams), which is why pixel sums are kept per index and not per
//! sample.
//!
//! A box filter of radius ½ covers one pixel: both reconstructions are then the same estimator
//! and the one-pixel path is taken.

use glam::Vec2;

use super::filter::{Filter, FilterSampler, Kernel};

/// How camera samples are turned into pixel values (the film's `reconstruction` parameter).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Reconstruction {
    /// Every sample feeds every pixel its filter covers, by the balance heuristic over the
    /// pixels' sampling densities, with the weight sum as a control variate.
    #[default]
    FilterMis,
    /// Every sample counts for the pixel it was drawn for only (the lecture's estimator).
    Pixel,
}

impl Reconstruction {
    /// Every reconstruction's name, as scenes and the command line give it.
    pub const NAMES: [&'static str; 2] = ["filter_mis", "pixel"];

    pub fn from_name(name: &str) -> Option<Reconstruction> {
        match name {
            "filter_mis" => Some(Reconstruction::FilterMis),
            "pixel" => Some(Reconstruction::Pixel),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Reconstruction::FilterMis => "filter_mis",
            Reconstruction::Pixel => "pixel",
        }
    }

    /// Whether samples are shared between pixels with this filter: only under filter MIS, and
    /// only when the filter reaches beyond its own pixel.
    pub fn shares_samples(self, filter: Filter) -> bool {
        self == Reconstruction::FilterMis && filter.radius() > 0.5
    }
}

/// The weights of filter MIS on a film of `width` × `height` pixels.
#[derive(Clone, Debug)]
pub struct FilterMis {
    sampler: FilterSampler,
    radius: f32,
    /// 1 / (∫k)², the normalisation of the 2-D kernel.
    normalisation: f32,
    width: u32,
    height: u32,
    reach: u32,
}

impl FilterMis {
    pub fn new(filter: Filter, width: u32, height: u32) -> FilterMis {
        let sampler = FilterSampler::new(filter);
        let integral = sampler.integral_1d();
        let radius = filter.radius();
        FilterMis {
            sampler,
            radius,
            normalisation: 1.0 / (integral * integral),
            width,
            height,
            reach: Self::reach_of(radius),
        }
    }

    /// The pixels on each side whose samples can fall inside a pixel's support: a sample of pixel
    /// l lies within r of cₗ, inside pixel i's support if within r of cᵢ, so |i − l| < 2r.
    fn reach_of(radius: f32) -> u32 {
        ((2.0 * radius).ceil() as u32).saturating_sub(1)
    }

    pub fn reach(&self) -> u32 {
        self.reach
    }

    /// Whether column (or row) `pixel` of a film `extent` pixels across is on the film's border,
    /// where samples are drawn from the filter rather than from the pixel's square.
    fn on_border(pixel: u32, extent: u32) -> bool {
        pixel == 0 || pixel + 1 >= extent
    }

    /// The offset from the centre of `pixel` (full-film coordinates) of the sample drawn with
    /// the uniform numbers `u`: on each axis from pₗ, the indicator of the pixel's square,
    /// 𝟙[−½, ½)(x − cₗ), or in a border column or row the filter sampler's density
    /// |k(x − cₗ)| / ∫|k|.
    pub fn draw_offset(&self, pixel: glam::UVec2, u: Vec2) -> Vec2 {
        let axis = |u: f32, pixel: u32, extent: u32| {
            if Self::on_border(pixel, extent) {
                self.sampler.sample_1d(u).0
            } else {
                u.min(1.0f32.next_down()) - 0.5
            }
        };
        Vec2::new(
            axis(u.x, pixel.x, self.width),
            axis(u.y, pixel.y, self.height),
        )
    }

    /// Dₓ at offset `offset` from the centre of column (or row) `pixel` of a film `extent` pixels
    /// across: Σ pₗ over the film's columns l within reach, pₗ the filter sampler's density on the
    /// border and 1 on the column's own square [−½, ½) elsewhere.
    fn density_1d(&self, offset: f32, pixel: u32, extent: u32) -> f32 {
        let reach = self.reach as i64 + 1;
        let first = (i64::from(pixel) - reach).max(0);
        let last = (i64::from(pixel) + reach).min(i64::from(extent) - 1);
        (first..=last)
            .map(|l| {
                let d = offset + (i64::from(pixel) - l) as f32;
                if Self::on_border(l as u32, extent) {
                    self.sampler.pdf_1d(d)
                } else if (-0.5..0.5).contains(&d) {
                    1.0
                } else {
                    0.0
                }
            })
            .sum()
    }

    /// The factor 1 / ((∫k)² D(x)) of a sample drawn at `offset` from the centre of `pixel`
    /// (full-film coordinates): the sample adds k(dx)k(dy) times this times its value to each
    /// pixel at (dx, dy) from it.
    pub fn sample_scale(&self, pixel: glam::UVec2, offset: Vec2) -> f32 {
        let dx = self.density_1d(offset.x, pixel.x, self.width);
        let dy = self.density_1d(offset.y, pixel.y, self.height);
        self.normalisation / (dx * dy)
    }

    /// The filter k(d) on one axis (not normalised), zero outside the support.
    #[inline]
    pub fn kernel(&self, d: f32) -> f32 {
        if d.abs() >= self.radius {
            return 0.0;
        }
        self.sampler.filter().eval(d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::filter::filters_under_test;
    use crate::film::{BoxFilter, TentFilter};
    use crate::sampling::rng::Pcg32;
    use glam::UVec2;

    #[test]
    fn names_round_trip_and_the_box_keeps_one_pixel() {
        for name in Reconstruction::NAMES {
            assert_eq!(Reconstruction::from_name(name).unwrap().name(), name);
        }
        assert_eq!(Reconstruction::default(), Reconstruction::FilterMis);
        assert!(!Reconstruction::FilterMis.shares_samples(Filter::Box(BoxFilter { radius: 0.5 })));
        assert!(Reconstruction::FilterMis.shares_samples(Filter::Tent(TentFilter { radius: 1.0 })));
        assert!(!Reconstruction::Pixel.shares_samples(Filter::Tent(TentFilter { radius: 1.0 })));
        assert_eq!(FilterMis::reach_of(1.0), 1);
        assert_eq!(FilterMis::reach_of(2.0), 3);
        assert_eq!(FilterMis::reach_of(0.75), 1);
    }

    /// Inside the film the tents' densities sum to one, so a tent's weights are k/N exactly:
    /// every sample's scale is 1.
    #[test]
    fn tent_weights_are_the_tent_inside_the_film() {
        let mis = FilterMis::new(Filter::Tent(TentFilter { radius: 1.0 }), 16, 16);
        let mut rng = Pcg32::seeded(5);
        for _ in 0..1000 {
            let offset = Vec2::new(rng.next_f32() * 2.0 - 1.0, rng.next_f32() * 2.0 - 1.0);
            let scale = mis.sample_scale(UVec2::new(7, 9), offset);
            assert!((scale - 1.0).abs() < 1e-5, "{offset}: {scale}");
        }
        // At the film's edge (x = 0) only column 0's tent reaches: D = p(−½) = ½.
        let scale = mis.sample_scale(UVec2::new(0, 8), Vec2::new(-0.5, 0.0));
        assert!((scale - 2.0).abs() < 1e-4, "{scale}");
    }

    /// Chi-square test of D: positions drawn by picking a film column uniformly and a sample from
    /// its density are distributed as Dₓ / W (the mixture of the columns' densities), on films
    /// of 1, 2, 3 and 6 columns.
    #[test]
    fn the_mixture_density_matches_the_samples_of_all_pixels() {
        // Widths 1 and 2 are all border; 3 has one square between two borders.
        for (filter, width) in filters_under_test()
            .into_iter()
            .flat_map(|filter| [1u32, 2, 3, 6].map(|width| (filter, width)))
        {
            let mis = FilterMis::new(filter, width, 1);
            let r = filter.radius();
            let (lo, hi) = (-r, width as f32 + r);
            let bins = 64usize;
            let bin_width = (hi - lo) / bins as f32;
            let n = 400_000usize;
            let mut counts = vec![0u32; bins];
            let mut rng = Pcg32::seeded(11);
            for _ in 0..n {
                let column = ((rng.next_f32() * width as f32) as u32).min(width - 1);
                let u = Vec2::new(rng.next_f32(), 0.5);
                let offset = mis.draw_offset(UVec2::new(column, 0), u).x;
                let x = column as f32 + 0.5 + offset;
                let bin = (((x - lo) / bin_width) as usize).min(bins - 1);
                counts[bin] += 1;
            }
            // Expected counts: D integrated over each bin (midpoint rule on 64 sub-points),
            // with D evaluated from column 0's frame, whose offsets reach every position.
            let density = |x: f32| {
                let column = ((x - 0.5).round().clamp(0.0, width as f32 - 1.0)) as u32;
                mis.density_1d(x - column as f32 - 0.5, column, width) / width as f32
            };
            let mut chi2 = 0.0;
            let mut dof = 0;
            for (b, &count) in counts.iter().enumerate() {
                let a = lo + b as f32 * bin_width;
                let m = 64;
                let p: f64 = (0..m)
                    .map(|j| f64::from(density(a + (j as f32 + 0.5) * bin_width / m as f32)))
                    .sum::<f64>()
                    * f64::from(bin_width)
                    / f64::from(m);
                let expected = p * n as f64;
                if expected < 5.0 {
                    assert!(
                        count < 20,
                        "{filter:?} width {width}: bin {b} expected {expected} got {count}"
                    );
                    continue;
                }
                chi2 += (f64::from(count) - expected).powi(2) / expected;
                dof += 1;
            }
            // The 99.9th percentile of chi-square is below dof + 4.5 √(2 dof) for these dof.
            let limit = dof as f64 + 4.5 * (2.0 * dof as f64).sqrt();
            assert!(
                chi2 < limit,
                "{filter:?} width {width}: chi2 {chi2} over {dof} bins"
            );
        }
    }
}
