//! Pearson's chi-square goodness-of-fit test of a sampling routine against the density it
//! claims, as pbrt-v4 and Mitsuba 3 test theirs (docs/testing.md, chi-square tests).
//!
//! A sampling routine claims a density `pdf` over a domain with a 2D parameterisation (directions
//! on the sphere by cos θ and φ, a rectangle, an interval, or a discrete set). We draw many
//! samples, count them in the cells of a histogram over the parameterisation, and compare the
//! counts O with the expectations E = N ∫pdf over each cell, integrated by a composite Simpson
//! rule. A sampler may fail (return `None`); it must do so with probability 1 − ∫pdf, so the
//! failures form one more cell whose expectation is N (1 − ∫pdf). Cells expected to hold fewer
//! than 5 samples are pooled into one cell, and
//!
//!   χ² = Σ (O − E)² / E,  dof = terms − 1,  p = Q(dof / 2, χ² / 2),
//!
//! where Q is the regularised upper incomplete gamma function. A [`Suite`] of n tests rejects at
//! significance α = 0.01 for the whole suite, each test at Šidák's 1 − (1 − α)^(1/n) (slightly
//! above Bonferroni's α/n, exact for independent tests).
//!
//! Mistakes that make the statistic meaningless fail at once with `Err`: samples outside the
//! domain or NaN, a density integrating to more than 1.1, samples in cells of zero expectation.
//!
//! A unit test beside a sampling routine uses it as an integration test does:
//!
//! ```
//! use prism_core::sampling::chi2::{Suite, chi2_interval};
//!
//! const SUITE: Suite = Suite::new(&["p(x) = 2x by sqrt(u)"]);
//! let by_square_root = |rng: &mut prism_core::sampling::rng::Pcg32| Some(rng.next_f64().sqrt());
//! let outcome = chi2_interval(100_000, 0.0, 1.0, 50, 1, by_square_root, |x| 2.0 * x).unwrap();
//! SUITE.assert_passes("p(x) = 2x by sqrt(u)", &outcome);
//! ```

use std::f64::consts::PI;

use glam::Vec3;

use crate::math::quadrature::simpson;
use crate::math::special::regularized_gamma_q;
use crate::sampling::rng::Pcg32;

/// Cells expected to hold fewer samples than this are pooled (the usual rule of thumb for the
/// chi-square approximation to hold).
const MIN_EXPECTED_COUNT: f64 = 5.0;

/// Family-wise significance of a suite of tests.
const ALPHA: f64 = 0.01;

/// How far from 1 the length of a sampled direction may be.
const UNIT_LENGTH_TOLERANCE: f32 = 1e-4;

/// The result of a chi-square test.
#[derive(Clone, Debug)]
pub struct Chi2Outcome {
    /// χ² = Σ (O − E)² / E over the terms (cells and the pooled cell).
    pub statistic: f64,
    /// Degrees of freedom: terms − 1.
    pub dof: usize,
    /// Probability of a statistic at least this large if the sampler matches the density.
    pub p_value: f64,
    /// Cells of nonzero expectation (cells with neither samples nor expectation do not count).
    pub cells: usize,
    /// How many of them were pooled into one term.
    pub pooled: usize,
    /// The terms that contribute most to the statistic, largest first (for reports).
    pub worst_cells: Vec<CellReport>,
}

/// One term of the statistic.
#[derive(Clone, Debug)]
pub struct CellReport {
    pub label: String,
    pub observed: f64,
    pub expected: f64,
}

impl CellReport {
    fn contribution(&self) -> f64 {
        (self.observed - self.expected).powi(2) / self.expected
    }
}

/// Pools cells with expected count < 5 into one pooled cell, computes χ² = Σ (O − E)² / E,
/// dof = terms − 1 and p = Q(dof / 2, χ² / 2).
///
/// Pooling follows Mitsuba's and pbrt-v3's `chi2`: cells are visited in increasing order of
/// expectation and added to the pooled cell while it holds less than 5 expected samples, so the
/// pooled cell itself reaches 5 whenever the total allows. Cells with neither expectation nor
/// observations are skipped.
///
/// Errors when an observed count falls in a cell of zero expectation, on negative or NaN
/// expectations, and when fewer than two terms remain.
pub fn chi2_from_counts(observed: &[f64], expected: &[f64]) -> Result<Chi2Outcome, String> {
    chi2_labelled(observed, expected, |i| format!("cell {i}"))
}

/// [`chi2_from_counts`] with cells named by `label` in messages.
fn chi2_labelled(
    observed: &[f64],
    expected: &[f64],
    label: impl Fn(usize) -> String,
) -> Result<Chi2Outcome, String> {
    if observed.len() != expected.len() {
        return Err(format!(
            "{} observed counts but {} expected counts",
            observed.len(),
            expected.len()
        ));
    }
    let mut order = Vec::with_capacity(expected.len());
    for (i, (&o, &e)) in observed.iter().zip(expected).enumerate() {
        if !e.is_finite() || e < 0.0 {
            return Err(format!("{}: invalid expected count {e}", label(i)));
        }
        if e == 0.0 {
            if o > 0.0 {
                return Err(format!(
                    "{}: {o} samples where the density integrates to 0",
                    label(i)
                ));
            }
            continue;
        }
        order.push(i);
    }
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));

    let mut terms = Vec::with_capacity(order.len());
    let mut pool = CellReport {
        label: String::new(),
        observed: 0.0,
        expected: 0.0,
    };
    let mut pooled = 0;
    for &i in &order {
        if expected[i] < MIN_EXPECTED_COUNT || (pooled > 0 && pool.expected < MIN_EXPECTED_COUNT) {
            pool.observed += observed[i];
            pool.expected += expected[i];
            pooled += 1;
        } else {
            terms.push(CellReport {
                label: label(i),
                observed: observed[i],
                expected: expected[i],
            });
        }
    }
    if pooled > 0 {
        pool.label = format!("{pooled} pooled cells");
        terms.push(pool);
    }
    if terms.len() < 2 {
        return Err(format!(
            "only {} term(s) after pooling: too few cells or samples for a chi-square test",
            terms.len()
        ));
    }

    let statistic: f64 = terms.iter().map(CellReport::contribution).sum();
    let dof = terms.len() - 1;
    terms.sort_by(|a, b| b.contribution().total_cmp(&a.contribution()));
    terms.truncate(5);
    Ok(Chi2Outcome {
        statistic,
        dof,
        p_value: regularized_gamma_q(dof as f64 / 2.0, statistic / 2.0),
        cells: order.len(),
        pooled,
        worst_cells: terms,
    })
}

/// Significance per test with Šidák's correction, so that a suite of `n_tests` independent
/// tests rejects a correct sampler with probability α = 0.01: 1 − (1 − α)^(1/n).
pub fn sidak_significance(n_tests: usize) -> f64 {
    1.0 - (1.0 - ALPHA).powf(1.0 / n_tests.max(1) as f64)
}

/// Panics with a readable report (statistic, dof, p, worst cells) when p < the Šidák
/// significance for a suite of `n_tests_in_suite` tests; prints a one-line summary otherwise.
///
/// `n_tests_in_suite` must be derived from the suite's cases (the length of its table of
/// cases), never written by hand; a suite of separately written tests is a [`Suite`].
pub fn assert_passes(name: &str, outcome: &Chi2Outcome, n_tests_in_suite: usize) {
    let significance = sidak_significance(n_tests_in_suite);
    let summary = format!(
        "chi^2 = {:.2}, dof = {}, p = {:.3e} ({} cells, {} pooled)",
        outcome.statistic, outcome.dof, outcome.p_value, outcome.cells, outcome.pooled
    );
    if outcome.p_value >= significance {
        println!("chi-square test \"{name}\" passed: {summary}");
        return;
    }
    let mut report = format!(
        "chi-square test \"{name}\" failed: p < {significance:.3e} (alpha {ALPHA} with Šidák \
         correction over {n_tests_in_suite} tests)\n  {summary}\n  worst cells:"
    );
    for cell in &outcome.worst_cells {
        report += &format!(
            "\n    {}: observed {}, expected {:.1}, contributes {:.1}",
            cell.label,
            cell.observed,
            cell.expected,
            cell.contribution()
        );
    }
    panic!("{report}");
}

/// A suite of chi-square tests sharing Šidák's correction: the names of its tests, one per
/// statistic, whose number is the suite's size. A test whose name is not registered fails, so
/// the size cannot fall behind the tests.
#[derive(Clone, Copy, Debug)]
pub struct Suite {
    names: &'static [&'static str],
}

impl Suite {
    pub const fn new(names: &'static [&'static str]) -> Suite {
        Suite { names }
    }

    /// The number of tests in the suite: n of Šidák's correction.
    pub fn size(&self) -> usize {
        self.names.len()
    }

    /// [`assert_passes`] for the suite's test `name`; panics when no test of the suite has that
    /// name.
    pub fn assert_passes(&self, name: &str, outcome: &Chi2Outcome) {
        assert!(
            self.names.contains(&name),
            "chi-square test \"{name}\" is not one of its suite's tests {:?}: register it",
            self.names
        );
        assert_passes(name, outcome, self.size());
    }
}

/// Directions on the unit sphere in cells of equal solid angle: `cos_bins` (odd, such as 101,
/// so that the horizon z = 0 is the middle of a row of cells and a hemispherical density's kink
/// falls on an integration node) equal intervals of cos θ in [−1, 1], times `phi_bins`
/// equal intervals of φ in [0, 2π).
///
/// `sample` draws one direction (None = the sampler failed); `pdf` is the claimed solid-angle
/// density. Expected counts integrate pdf d(cos θ) dφ over each cell with an 8×8
/// composite Simpson rule, exact for densities piecewise cubic in cos θ with breaks on its
/// nodes, such as max(0, cos θ) / π (the horizon z = 0 is the middle node of the middle
/// row). A density that jumps at the horizon (uniform on the hemisphere) is off by up to 1/12 in
/// the middle row, depending on how the horizon node rounds; that is well below the noise at
/// 10⁶ samples on 101 × 202 cells. Fails at once on a non-unit or NaN direction, on a total pdf
/// integral above 1.1, and on samples in cells of zero expectation.
pub fn chi2_sphere(
    samples: usize,
    cos_bins: usize,
    phi_bins: usize,
    seed: u64,
    mut sample: impl FnMut(&mut Pcg32) -> Option<Vec3>,
    pdf: impl Fn(Vec3) -> f64,
) -> Result<Chi2Outcome, String> {
    let dz = 2.0 / cos_bins as f64;
    let dphi = 2.0 * PI / phi_bins as f64;
    let direction = |z: f64, phi: f64| {
        let sin_theta = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(
            (sin_theta * phi.cos()) as f32,
            (sin_theta * phi.sin()) as f32,
            z as f32,
        )
    };
    let probabilities: Vec<f64> = (0..cos_bins * phi_bins)
        .map(|cell| {
            let z0 = -1.0 + (cell / phi_bins) as f64 * dz;
            let phi0 = (cell % phi_bins) as f64 * dphi;
            simpson_2d(
                |z, phi| pdf(direction(z, phi)),
                (z0, z0 + dz),
                (phi0, phi0 + dphi),
                8,
            )
        })
        .collect();
    let label = |cell: usize| {
        let z0 = -1.0 + (cell / phi_bins) as f64 * dz;
        let phi0 = (cell % phi_bins) as f64 * dphi;
        format!(
            "cos theta in [{z0:.4}, {:.4}), phi in [{phi0:.4}, {:.4})",
            z0 + dz,
            phi0 + dphi
        )
    };
    let locate = |v: Vec3| {
        if !v.is_finite() || (v.length() - 1.0).abs() > UNIT_LENGTH_TOLERANCE {
            return Err(format!("sampled direction {v} is not a unit vector"));
        }
        let z = f64::from(v.z).clamp(-1.0, 1.0);
        let phi = f64::from(v.y).atan2(f64::from(v.x)).rem_euclid(2.0 * PI);
        Ok(bin(z + 1.0, dz, cos_bins) * phi_bins + bin(phi, dphi, phi_bins))
    };
    chi2_histogram(
        samples,
        seed,
        &probabilities,
        |rng| sample(rng).map(locate).transpose(),
        label,
    )
}

/// A density on [lo, hi) in `bins` equal bins; expected counts by composite Simpson with 16
/// sub-intervals per bin. Fails at once on samples outside [lo, hi) or NaN, on a total pdf
/// integral above 1.1, and on samples in bins of zero expectation.
pub fn chi2_interval(
    samples: usize,
    lo: f64,
    hi: f64,
    bins: usize,
    seed: u64,
    mut sample: impl FnMut(&mut Pcg32) -> Option<f64>,
    pdf: impl Fn(f64) -> f64,
) -> Result<Chi2Outcome, String> {
    let width = (hi - lo) / bins as f64;
    let probabilities: Vec<f64> = (0..bins)
        .map(|i| {
            let x0 = lo + i as f64 * width;
            simpson(&pdf, x0, x0 + width, 16)
        })
        .collect();
    let label = |i: usize| {
        let x0 = lo + i as f64 * width;
        format!("[{x0:.5}, {:.5})", x0 + width)
    };
    let locate = |x: f64| {
        if !(lo..hi).contains(&x) {
            return Err(format!("sample {x} lies outside [{lo}, {hi})"));
        }
        Ok(bin(x - lo, width, bins))
    };
    chi2_histogram(
        samples,
        seed,
        &probabilities,
        |rng| sample(rng).map(locate).transpose(),
        label,
    )
}

/// The rectangle [x.0, x.1) × [y.0, y.1) cut into nx × ny equal cells.
#[derive(Clone, Copy, Debug)]
pub struct Cells {
    pub x: (f64, f64),
    pub y: (f64, f64),
    pub nx: usize,
    pub ny: usize,
}

/// A density on the rectangle of `cells`; expected counts by an 8×8 composite Simpson rule per
/// cell. Fails at once on samples outside the rectangle or NaN, on a total pdf integral above
/// 1.1, and on samples in cells of zero expectation.
pub fn chi2_rectangle(
    samples: usize,
    cells: Cells,
    seed: u64,
    mut sample: impl FnMut(&mut Pcg32) -> Option<(f64, f64)>,
    pdf: impl Fn(f64, f64) -> f64,
) -> Result<Chi2Outcome, String> {
    let Cells { x, y, nx, ny } = cells;
    let dx = (x.1 - x.0) / nx as f64;
    let dy = (y.1 - y.0) / ny as f64;
    let corner = |cell: usize| (x.0 + (cell % nx) as f64 * dx, y.0 + (cell / nx) as f64 * dy);
    let probabilities: Vec<f64> = (0..nx * ny)
        .map(|cell| {
            let (cx, cy) = corner(cell);
            simpson_2d(&pdf, (cx, cx + dx), (cy, cy + dy), 8)
        })
        .collect();
    let label = |cell: usize| {
        let (cx, cy) = corner(cell);
        format!("[{cx:.4}, {:.4}) x [{cy:.4}, {:.4})", cx + dx, cy + dy)
    };
    let locate = |(px, py): (f64, f64)| {
        if !(x.0..x.1).contains(&px) || !(y.0..y.1).contains(&py) {
            return Err(format!(
                "sample ({px}, {py}) lies outside [{}, {}) x [{}, {})",
                x.0, x.1, y.0, y.1
            ));
        }
        Ok(bin(py - y.0, dy, ny) * nx + bin(px - x.0, dx, nx))
    };
    chi2_histogram(
        samples,
        seed,
        &probabilities,
        |rng| sample(rng).map(locate).transpose(),
        label,
    )
}

/// A discrete distribution: `probabilities` claimed, `sample` returns an index. Fails at once on
/// an index out of range, on probabilities summing to more than 1.1, and on samples of an index
/// of probability zero.
pub fn chi2_discrete(
    samples: usize,
    probabilities: &[f64],
    seed: u64,
    mut sample: impl FnMut(&mut Pcg32) -> usize,
) -> Result<Chi2Outcome, String> {
    let n = probabilities.len();
    let locate = |i: usize| {
        if i < n {
            Ok(Some(i))
        } else {
            Err(format!("sampled index {i} is out of range 0..{n}"))
        }
    };
    chi2_histogram(
        samples,
        seed,
        probabilities,
        |rng| locate(sample(rng)),
        |i| format!("index {i}"),
    )
}

/// The common part of the tests: checks the cell probabilities, draws `samples` samples with
/// `draw` (which gives a cell index, None for a failed sample, or an error for a sample outside
/// the domain) from a generator seeded with `seed`, and compares the histogram with the
/// expectations, failures counting as one more cell of probability 1 − Σ probabilities.
fn chi2_histogram(
    samples: usize,
    seed: u64,
    probabilities: &[f64],
    mut draw: impl FnMut(&mut Pcg32) -> Result<Option<usize>, String>,
    label: impl Fn(usize) -> String,
) -> Result<Chi2Outcome, String> {
    let cells = probabilities.len();
    if let Some(i) = probabilities.iter().position(|p| p.is_nan() || *p < 0.0) {
        return Err(format!(
            "{}: the density integrates to {} (negative or NaN)",
            label(i),
            probabilities[i]
        ));
    }
    let total: f64 = probabilities.iter().sum();
    if total > 1.1 {
        return Err(format!(
            "the density integrates to {total} over the domain (more than 1.1)"
        ));
    }

    let mut observed = vec![0.0; cells + 1];
    let mut rng = Pcg32::seeded(seed);
    for _ in 0..samples {
        match draw(&mut rng)? {
            Some(cell) => observed[cell] += 1.0,
            None => observed[cells] += 1.0,
        }
    }
    let failures = observed[cells];
    if failures > 0.0 && total >= 1.0 {
        return Err(format!(
            "the sampler failed {failures} times, but the density integrates to {total}, which \
             leaves no probability for failures"
        ));
    }
    let n = samples as f64;
    let expected: Vec<f64> = probabilities
        .iter()
        .map(|p| p * n)
        .chain([(1.0 - total).max(0.0) * n])
        .collect();
    chi2_labelled(&observed, &expected, |i| {
        if i == cells {
            "sampler failures".to_string()
        } else {
            label(i)
        }
    })
}

/// The index of the bin of width `width` holding offset `x` ≥ 0, clamped to `bins − 1` (for
/// offsets that round onto the upper edge).
fn bin(x: f64, width: f64, bins: usize) -> usize {
    ((x / width) as usize).min(bins - 1)
}

/// ∫∫ f over [a, b] × [c, d] by the tensor product of composite Simpson rules with `n` (even)
/// sub-intervals per axis: (hx hy / 9) Σᵢ Σⱼ wᵢ wⱼ f(a + i hx, c + j hy), weights 1, 4, 2, 4, …,
/// 4, 1 (Abramowitz and Stegun 25.4.6).
pub fn simpson_2d(
    f: impl Fn(f64, f64) -> f64,
    (a, b): (f64, f64),
    (c, d): (f64, f64),
    n: usize,
) -> f64 {
    let hx = (b - a) / n as f64;
    let hy = (d - c) / n as f64;
    let mut sum = 0.0;
    for i in 0..=n {
        for j in 0..=n {
            sum += simpson_weight(i, n)
                * simpson_weight(j, n)
                * f(a + i as f64 * hx, c + j as f64 * hy);
        }
    }
    sum * hx * hy / 9.0
}

fn simpson_weight(i: usize, n: usize) -> f64 {
    if i == 0 || i == n {
        1.0
    } else if i % 2 == 1 {
        4.0
    } else {
        2.0
    }
}

#[cfg(test)]
mod tests {
    //! Self-tests of the harness: it must pass correct samplers, and it must also be able to
    //! fail (wrong densities give tiny p-values; broken samplers give errors), or it proves
    //! nothing about the samplers it is used on. The samplers here are written out afresh, not
    //! taken from [`crate::sampling::warp`], so that the harness is tested on its own.

    use std::f32::consts::{FRAC_PI_2, FRAC_PI_4};

    use glam::Vec2;

    use super::*;

    /// The unit square in 40 × 40 cells.
    const UNIT_40: Cells = Cells {
        x: (0.0, 1.0),
        y: (0.0, 1.0),
        nx: 40,
        ny: 40,
    };

    /// Samples per test, as docs/testing.md asks of chi-square tests.
    const SAMPLES: usize = 1_000_000;

    /// The tests of correct samplers (the suite of the Šidák correction).
    const SUITE: Suite = Suite::new(&[
        "uniform sphere",
        "cosine hemisphere (Malley)",
        "rejection-sampled hemisphere",
        "p(x) = 2x by sqrt(u)",
        "p(x, y) = 4xy",
        "discrete [0.5, 0.3, 0.2]",
    ]);

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
        let panic = std::panic::catch_unwind(|| assert_passes(name, outcome, SUITE.size()))
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
        let right =
            chi2_sphere(SAMPLES, COS_BINS, PHI_BINS, 1, sample, |_| 1.0 / (4.0 * PI)).unwrap();
        SUITE.assert_passes("uniform sphere", &right);

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
        SUITE.assert_passes("cosine hemisphere (Malley)", &right);

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
        SUITE.assert_passes("rejection-sampled hemisphere", &right);

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
        SUITE.assert_passes("p(x) = 2x by sqrt(u)", &right);

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
        let right = chi2_rectangle(SAMPLES, UNIT_40, 9, sqrt, pdf).unwrap();
        SUITE.assert_passes("p(x, y) = 4xy", &right);

        let uniform = |rng: &mut Pcg32| Some((rng.next_f64(), rng.next_f64()));
        let wrong = chi2_rectangle(SAMPLES, UNIT_40, 9, uniform, pdf).unwrap();
        assert_fails("p(x, y) = 4xy by uniform samples", &wrong);

        let outside = |_: &mut Pcg32| Some((0.5, 1.0));
        let result = chi2_rectangle(
            10,
            Cells {
                nx: 4,
                ny: 4,
                ..UNIT_40
            },
            9,
            outside,
            pdf,
        );
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
        SUITE.assert_passes("discrete [0.5, 0.3, 0.2]", &right);

        let wrong = chi2_discrete(SAMPLES, &probabilities, 10, invert([0.5, 0.81])).unwrap();
        assert_fails("discrete sampled as [0.5, 0.31, 0.19]", &wrong);

        assert_error(chi2_discrete(10, &probabilities, 10, |_| 3), "out of range");
    }

    #[test]
    fn a_test_missing_from_its_suite_fails() {
        let outcome = chi2_from_counts(&[20.0, 20.0], &[20.0, 20.0]).unwrap();
        let panic = std::panic::catch_unwind(|| SUITE.assert_passes("unregistered", &outcome))
            .expect_err("an unregistered test passed");
        let report = panic.downcast_ref::<String>().expect("a formatted report");
        assert!(report.contains("register it"), "{report}");
    }
}
