//! Chi-square tests of the image-formation sampling routines: every reconstruction filter in one
//! and two dimensions (p ∝ |k|) and the shutter's time sampling.
//!
//! These densities are piecewise constant on fine tables, so cell probabilities are integrated
//! by the midpoint rule on a grid of 1/1024 of a unit, finer than any table and never sampling
//! a table's cell boundary (where the harness' Simpson rule would be off).

use glam::Vec2;
use prism_core::camera::Shutter;
use prism_core::film::{
    BoxFilter, Filter, FilterSampler, GaussianFilter, Kernel, LanczosFilter, MitchellFilter,
    TentFilter,
};
use prism_core::sampling::chi2::{assert_passes, chi2_from_counts};
use prism_core::sampling::rng::Pcg32;

const SAMPLES: usize = 1_000_000;
/// Chi-square tests in this module, for Šidák's correction: each filter in one and two
/// dimensions, and each shutter.
const TESTS: usize = FILTERS.len() * 2 + SHUTTER_FILTERS.len();

const FILTERS: [Filter; 6] = [
    Filter::Box(BoxFilter { radius: 0.5 }),
    Filter::Tent(TentFilter { radius: 1.0 }),
    Filter::Gaussian(GaussianFilter { stddev: 0.5 }),
    Filter::Mitchell(MitchellFilter {
        b: 1.0 / 3.0,
        c: 1.0 / 3.0,
    }),
    Filter::Mitchell(MitchellFilter { b: 0.0, c: 0.5 }),
    Filter::Lanczos(LanczosFilter { lobes: 3 }),
];

/// The shutter's filters: the default box, and a Mitchell filter stretched over the interval.
const SHUTTER_FILTERS: [Option<Filter>; 2] = [
    None,
    Some(Filter::Mitchell(MitchellFilter {
        b: 1.0 / 3.0,
        c: 1.0 / 3.0,
    })),
];

/// Probability of each of `bins` equal bins of [lo, hi) under `pdf`, by the fine midpoint rule.
fn bin_probabilities(lo: f64, hi: f64, bins: usize, pdf: impl Fn(f64) -> f64) -> Vec<f64> {
    let width = (hi - lo) / bins as f64;
    let steps = ((width * 1024.0).round() as usize).max(16);
    let h = width / steps as f64;
    (0..bins)
        .map(|b| {
            (0..steps)
                .map(|i| pdf(lo + b as f64 * width + (i as f64 + 0.5) * h) * h)
                .sum()
        })
        .collect()
}

fn histogram(lo: f64, hi: f64, bins: usize, values: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut counts = vec![0.0; bins];
    for v in values {
        assert!(v >= lo && v <= hi, "sample {v} outside [{lo}, {hi}]");
        let b = (((v - lo) / (hi - lo)) * bins as f64) as usize;
        counts[b.min(bins - 1)] += 1.0;
    }
    counts
}

/// One coordinate of the filter's offsets against the claimed density, which must itself be
/// |k| / ∫|k| averaged over each table cell.
#[test]
fn every_filter_samples_one_coordinate_with_density_proportional_to_abs_k() {
    for (i, filter) in FILTERS.into_iter().enumerate() {
        let sampler = FilterSampler::new(filter);
        let r = f64::from(filter.radius());
        // The claimed density is |k| normalised (cell by cell, within the table's resolution).
        let abs_integral: f64 =
            bin_probabilities(-r, r, 1, |x| f64::from(filter.eval(x as f32).abs()))[0];
        let cells = 64;
        let claimed = bin_probabilities(-r, r, cells, |x| f64::from(sampler.pdf_1d(x as f32)));
        let kernel = bin_probabilities(-r, r, cells, |x| {
            f64::from(filter.eval(x as f32).abs()) / abs_integral
        });
        for (c, k) in claimed.iter().zip(&kernel) {
            assert!(
                (c - k).abs() < 2e-3 * k.max(1e-3),
                "{filter:?}: cell probability {c} vs |k| {k}"
            );
        }
        let mut rng = Pcg32::seeded(100 + i as u64);
        let observed = histogram(
            -r,
            r,
            50,
            (0..SAMPLES).map(|_| f64::from(sampler.sample_1d(rng.next_f32()).0)),
        );
        let expected: Vec<f64> =
            bin_probabilities(-r, r, 50, |x| f64::from(sampler.pdf_1d(x as f32)))
                .iter()
                .map(|p| p * SAMPLES as f64)
                .collect();
        let outcome = chi2_from_counts(&observed, &expected).unwrap();
        assert_passes(&format!("1-D {filter:?}"), &outcome, TESTS);
    }
}

/// Offsets in 2-D against p(x)p(y): the axes are independent.
#[test]
fn every_filter_samples_offsets_with_the_tensor_product_density() {
    for (i, filter) in FILTERS.into_iter().enumerate() {
        let sampler = FilterSampler::new(filter);
        let r = f64::from(filter.radius());
        let bins = 24;
        let marginal = bin_probabilities(-r, r, bins, |x| f64::from(sampler.pdf_1d(x as f32)));
        let mut rng = Pcg32::seeded(200 + i as u64);
        let mut observed = vec![0.0; bins * bins];
        let locate =
            |v: f32| (((f64::from(v) + r) / (2.0 * r) * bins as f64) as usize).min(bins - 1);
        for _ in 0..SAMPLES {
            let (offset, _) = sampler.sample(Vec2::new(rng.next_f32(), rng.next_f32()));
            observed[locate(offset.y) * bins + locate(offset.x)] += 1.0;
        }
        let expected: Vec<f64> = (0..bins * bins)
            .map(|cell| marginal[cell / bins] * marginal[cell % bins] * SAMPLES as f64)
            .collect();
        let outcome = chi2_from_counts(&observed, &expected).unwrap();
        assert_passes(&format!("2-D {filter:?}"), &outcome, TESTS);
    }
}

/// Times over the shutter interval: uniform for the default box, p ∝ |k| for a Mitchell filter
/// stretched over the interval.
#[test]
fn shutter_times_follow_their_density() {
    for (seed, filter) in (300u64..).zip(SHUTTER_FILTERS) {
        let shutter = Shutter::new(0.25, 1.75, filter);
        let mut rng = Pcg32::seeded(seed);
        let observed = histogram(
            0.25,
            1.75,
            60,
            (0..SAMPLES).map(|_| f64::from(shutter.sample(rng.next_f32()).0)),
        );
        let probabilities = bin_probabilities(0.25, 1.75, 60, |t| f64::from(shutter.pdf(t as f32)));
        let total: f64 = probabilities.iter().sum();
        assert!(
            (total - 1.0).abs() < 1e-3,
            "{filter:?}: the time density integrates to {total}"
        );
        let expected: Vec<f64> = probabilities.iter().map(|p| p * SAMPLES as f64).collect();
        let outcome = chi2_from_counts(&observed, &expected).unwrap();
        assert_passes(&format!("shutter {filter:?}"), &outcome, TESTS);
    }
}
