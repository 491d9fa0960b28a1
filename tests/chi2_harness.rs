//! Self-tests of the chi-square harness: it must pass correct samplers, and it must also be able
//! to fail (wrong densities give tiny p-values; broken samplers give errors), or it proves
//! nothing about the samplers it is used on.

mod common;

use std::f32::consts::{FRAC_PI_2, FRAC_PI_4};
use std::f64::consts::PI;

use common::chi2::{
    Chi2Outcome, assert_passes, chi2_discrete, chi2_from_counts, chi2_interval, chi2_rectangle,
    chi2_sphere, regularized_gamma_q, sidak_significance,
};
use glam::{Vec2, Vec3};
use prism_core::sampling::rng::Pcg32;

/// Samples per test, as DESIGN.md §6 asks.
const SAMPLES: usize = 1_000_000;

/// Tests in this file that call `assert_passes` (the suite of the Šidák correction).
const SUITE: usize = 6;

/// Sphere resolution: an odd number of cos(theta) bins, twice as many phi bins.
const COS_BINS: usize = 101;
const PHI_BINS: usize = 202;

/// Asserts that `outcome` rejects its sampler decisively and that `assert_passes` would panic
/// with a report naming the test.
fn assert_fails(name: &str, outcome: &Chi2Outcome) {
    assert!(
        outcome.p_value < 1e-9,
        "{name} should fail, but p = {}",
        outcome.p_value
    );
    let panic = std::panic::catch_unwind(|| assert_passes(name, outcome, SUITE))
        .expect_err("assert_passes accepted a failing outcome");
    let report = panic.downcast_ref::<String>().expect("a formatted report");
    assert!(
        report.contains(name) && report.contains("worst cells"),
        "{report}"
    );
}

/// Asserts that `result` is an error whose message contains `expected`.
fn assert_error(result: Result<Chi2Outcome, String>, expected: &str) {
    match result {
        Ok(outcome) => panic!("expected an error about \"{expected}\", got {outcome:?}"),
        Err(message) => assert!(message.contains(expected), "{message}"),
    }
}

/// Uniform direction on the sphere: z = 1 - 2 u1, phi = 2 pi u2 (pbrt-v4 §A.5.2).
fn sample_uniform_sphere(rng: &mut Pcg32) -> Vec3 {
    let z = 1.0 - 2.0 * rng.next_f32();
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * std::f32::consts::PI * rng.next_f32();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Cosine-weighted direction on the hemisphere z >= 0 by Malley's method: a uniform point of the
/// unit disk (Shirley and Chiu's concentric mapping) lifted to (x, y, sqrt(1 - x^2 - y^2)).
fn sample_cosine_hemisphere(rng: &mut Pcg32) -> Vec3 {
    let u = 2.0 * Vec2::new(rng.next_f32(), rng.next_f32()) - 1.0;
    let disk = if u == Vec2::ZERO {
        Vec2::ZERO
    } else if u.x.abs() > u.y.abs() {
        let theta = FRAC_PI_4 * (u.y / u.x);
        u.x * Vec2::new(theta.cos(), theta.sin())
    } else {
        let theta = FRAC_PI_2 - FRAC_PI_4 * (u.x / u.y);
        u.y * Vec2::new(theta.cos(), theta.sin())
    };
    disk.extend((1.0 - disk.length_squared()).max(0.0).sqrt())
}

// The incomplete gamma function.

#[test]
fn q_of_one_is_the_exponential() {
    for x in [0.0f64, 0.1, 0.5, 1.0, 1.99, 2.01, 10.0, 50.0, 300.0] {
        let expected = (-x).exp();
        let q = regularized_gamma_q(1.0, x);
        assert!((q - expected).abs() <= 1e-13 * expected, "Q(1, {x}) = {q}");
    }
}

#[test]
fn q_of_one_half_is_the_complementary_error_function() {
    // Q(1/2, x) = erfc(sqrt x) (A&S 6.5.17); erfc to 16 digits, as mpmath computes it.
    let erfc = [
        (0.5, 0.479_500_122_186_953_5),
        (1.0, 0.157_299_207_050_285_1),
        (2.0, 4.677_734_981_047_266e-3),
        (3.0, 2.209_049_699_858_544e-5),
        (5.0, 1.537_459_794_428_035e-12),
    ];
    for (t, expected) in erfc {
        let q = regularized_gamma_q(0.5, t * t);
        assert!((q - expected).abs() <= 1e-12 * expected, "erfc({t}) = {q}");
    }
}

#[test]
fn chi_square_95_percent_quantiles_have_p_of_five_percent() {
    // Upper 5% points of the chi-square distribution (NIST/SEMATECH e-Handbook table 1.3.6.7.4
    // gives 3.841, 18.307, 124.342; the full digits checked by quadrature of the density).
    for (dof, quantile) in [
        (1, 3.841_458_820_694_124),
        (10, 18.307_038_053_275_146),
        (100, 124.342_113_404_004_07),
    ] {
        let p = regularized_gamma_q(dof as f64 / 2.0, quantile / 2.0);
        assert!((p - 0.05).abs() < 1e-9, "dof {dof}: p = {p}");
    }
}

// Pooling, the statistic and the correction.

#[test]
fn statistic_of_known_counts() {
    // chi^2 = (100 + 0 + 100) / 20 = 10 with 2 degrees of freedom: p = Q(1, 5) = e^-5.
    let outcome = chi2_from_counts(&[10.0, 20.0, 30.0], &[20.0, 20.0, 20.0]).unwrap();
    assert_eq!(
        (outcome.statistic, outcome.dof, outcome.pooled),
        (10.0, 2, 0)
    );
    assert!((outcome.p_value - (-5.0f64).exp()).abs() < 1e-15);
}

#[test]
fn cells_below_five_expected_samples_are_pooled() {
    // The cells expecting 1, 2 and 3 samples form one term expecting 6, observing 9; the empty
    // cell is skipped; terms: pooled, 44, 50.
    let observed = [2.0, 0.0, 4.0, 3.0, 50.0, 44.0];
    let expected = [1.0, 0.0, 3.0, 2.0, 50.0, 44.0];
    let outcome = chi2_from_counts(&observed, &expected).unwrap();
    assert_eq!((outcome.cells, outcome.pooled, outcome.dof), (5, 3, 2));
    assert!((outcome.statistic - 9.0 / 6.0).abs() < 1e-15);
    assert_eq!(outcome.worst_cells[0].label, "3 pooled cells");
}

#[test]
fn observations_in_a_cell_of_zero_expectation_are_an_error() {
    assert_error(
        chi2_from_counts(&[1.0, 9.0, 10.0], &[0.0, 10.0, 10.0]),
        "cell 0",
    );
}

#[test]
fn sidak_correction_keeps_the_suite_significance() {
    assert!((sidak_significance(1) - 0.01).abs() < 1e-15);
    for n in [2, 10, 1000] {
        let per_test = sidak_significance(n);
        assert!(((1.0 - per_test).powi(n as i32) - 0.99).abs() < 1e-12);
    }
}

// Sphere.

#[test]
fn uniform_sphere_passes_with_its_pdf_and_fails_with_a_cosine_pdf() {
    let sample = |rng: &mut Pcg32| Some(sample_uniform_sphere(rng));
    let right = chi2_sphere(SAMPLES, COS_BINS, PHI_BINS, 1, sample, |_| 1.0 / (4.0 * PI)).unwrap();
    assert_passes("uniform sphere", &right, SUITE);

    // |cos theta| / (2 pi) integrates to 1 over the sphere, so only the statistic can tell.
    let cosine = |v: Vec3| f64::from(v.z.abs()) / (2.0 * PI);
    let wrong = chi2_sphere(SAMPLES, COS_BINS, PHI_BINS, 1, sample, cosine).unwrap();
    assert_fails("uniform sphere with a cosine pdf", &wrong);
}

#[test]
fn cosine_hemisphere_passes_with_its_pdf_and_fails_with_a_uniform_pdf() {
    let sample = |rng: &mut Pcg32| Some(sample_cosine_hemisphere(rng));
    let cosine = |v: Vec3| f64::from(v.z.max(0.0)) / PI;
    let right = chi2_sphere(SAMPLES, COS_BINS, PHI_BINS, 2, sample, cosine).unwrap();
    assert_passes("cosine hemisphere (Malley)", &right, SUITE);

    let uniform = |v: Vec3| if v.z >= 0.0 { 1.0 / (2.0 * PI) } else { 0.0 };
    let wrong = chi2_sphere(SAMPLES, COS_BINS, PHI_BINS, 2, sample, uniform).unwrap();
    assert_fails("cosine hemisphere with a uniform pdf", &wrong);
}

#[test]
fn failed_samples_count_against_the_pdf_integral() {
    // Uniform sphere samples below the horizon rejected: the sampler fails with probability 1/2,
    // which a density of 1/(4 pi) on the upper hemisphere (integral 1/2) accounts for.
    let sample = |rng: &mut Pcg32| Some(sample_uniform_sphere(rng)).filter(|v| v.z >= 0.0);
    let upper = |v: Vec3| if v.z >= 0.0 { 1.0 / (4.0 * PI) } else { 0.0 };
    let right = chi2_sphere(SAMPLES, COS_BINS, PHI_BINS, 3, sample, upper).unwrap();
    assert_passes("rejection-sampled hemisphere", &right, SUITE);

    // Claiming that it fails only a quarter of the time (the density integrates to 3/4).
    let three_quarters = |v: Vec3| 1.5 * upper(v);
    let wrong = chi2_sphere(SAMPLES, COS_BINS, PHI_BINS, 3, sample, three_quarters).unwrap();
    assert_fails("rejection-sampled hemisphere with too large a pdf", &wrong);

    // A density integrating to 1 or more claims that the sampler never fails.
    let whole_sphere = |_: Vec3| 1.05 / (4.0 * PI);
    let result = chi2_sphere(1000, 11, 22, 3, sample, whole_sphere);
    assert_error(result, "leaves no probability for failures");
}

#[test]
fn nan_or_non_unit_directions_are_errors() {
    let nan = |_: &mut Pcg32| Some(Vec3::new(f32::NAN, 0.0, 1.0));
    let uniform = |_: Vec3| 1.0 / (4.0 * PI);
    assert_error(
        chi2_sphere(10, 11, 22, 4, nan, uniform),
        "not a unit vector",
    );
    let outside = |_: &mut Pcg32| Some(Vec3::new(0.0, 0.0, 2.0));
    assert_error(
        chi2_sphere(10, 11, 22, 4, outside, uniform),
        "not a unit vector",
    );
}

// Interval.

#[test]
fn linear_density_passes_by_square_root_and_fails_by_identity() {
    let pdf = |x: f64| 2.0 * x;
    let sqrt = |rng: &mut Pcg32| Some(rng.next_f64().sqrt());
    let right = chi2_interval(SAMPLES, 0.0, 1.0, 100, 5, sqrt, pdf).unwrap();
    assert_passes("p(x) = 2x by sqrt(u)", &right, SUITE);

    let identity = |rng: &mut Pcg32| Some(rng.next_f64());
    let wrong = chi2_interval(SAMPLES, 0.0, 1.0, 100, 5, identity, pdf).unwrap();
    assert_fails("p(x) = 2x by u", &wrong);
}

#[test]
fn samples_where_the_density_vanishes_are_errors() {
    // The density lives on [0, 1/2) only; uniform samples land on [1/2, 1) too.
    let half = |x: f64| if x < 0.5 { 2.0 } else { 0.0 };
    let uniform = |rng: &mut Pcg32| Some(rng.next_f64());
    assert_error(
        chi2_interval(1000, 0.0, 1.0, 10, 6, uniform, half),
        "where the density integrates to 0",
    );
}

#[test]
fn samples_outside_the_interval_are_errors() {
    let beyond = |rng: &mut Pcg32| Some(1.0 + rng.next_f64());
    assert_error(
        chi2_interval(10, 0.0, 1.0, 10, 7, beyond, |_| 1.0),
        "outside [0, 1)",
    );
    let nan = |_: &mut Pcg32| Some(f64::NAN);
    assert_error(
        chi2_interval(10, 0.0, 1.0, 10, 7, nan, |_| 1.0),
        "outside [0, 1)",
    );
}

#[test]
fn a_density_integrating_to_two_is_an_error() {
    let uniform = |rng: &mut Pcg32| Some(rng.next_f64());
    assert_error(
        chi2_interval(10, 0.0, 1.0, 10, 8, uniform, |_| 2.0),
        "more than 1.1",
    );
}

// Rectangle.

#[test]
fn product_density_on_the_square_passes_and_uniform_samples_fail() {
    let pdf = |x: f64, y: f64| 4.0 * x * y;
    let sqrt = |rng: &mut Pcg32| Some((rng.next_f64().sqrt(), rng.next_f64().sqrt()));
    let right = chi2_rectangle(SAMPLES, (0.0, 1.0), (0.0, 1.0), 40, 40, 9, sqrt, pdf).unwrap();
    assert_passes("p(x, y) = 4xy", &right, SUITE);

    let uniform = |rng: &mut Pcg32| Some((rng.next_f64(), rng.next_f64()));
    let wrong = chi2_rectangle(SAMPLES, (0.0, 1.0), (0.0, 1.0), 40, 40, 9, uniform, pdf).unwrap();
    assert_fails("p(x, y) = 4xy by uniform samples", &wrong);

    let outside = |_: &mut Pcg32| Some((0.5, 1.0));
    let result = chi2_rectangle(10, (0.0, 1.0), (0.0, 1.0), 4, 4, 9, outside, pdf);
    assert_error(result, "outside");
}

// Discrete.

#[test]
fn discrete_distribution_passes_and_a_biased_sampler_fails() {
    let probabilities = [0.5, 0.3, 0.2];
    // Inversion of the cumulative distribution with thresholds `cdf`.
    let invert = |cdf: [f64; 2]| {
        move |rng: &mut Pcg32| {
            let u = rng.next_f64();
            cdf.iter().filter(|&&c| u >= c).count()
        }
    };
    let right = chi2_discrete(SAMPLES, &probabilities, 10, invert([0.5, 0.8])).unwrap();
    assert_passes("discrete [0.5, 0.3, 0.2]", &right, SUITE);

    let wrong = chi2_discrete(SAMPLES, &probabilities, 10, invert([0.5, 0.81])).unwrap();
    assert_fails("discrete sampled as [0.5, 0.31, 0.19]", &wrong);

    assert_error(chi2_discrete(10, &probabilities, 10, |_| 3), "out of range");
}
