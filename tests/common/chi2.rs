//! Pearson's chi-square goodness-of-fit test for sampling routines (DESIGN.md §6), as pbrt-v4
//! and Mitsuba 3 do it.
//!
//! A sampling routine claims a density `pdf`; we draw many samples from it, count them in cells
//! of a partition of the domain, and compare the counts with the expectations obtained by
//! integrating the claimed density over each cell. A sampler may fail (return `None`); it must
//! do so with probability 1 - ∫pdf, so the failures form one more cell whose expectation is
//! N (1 - ∫pdf). Cells expected to hold fewer than 5 samples are pooled into one cell, and
//!
//!   chi^2 = Σ (O - E)^2 / E,  dof = terms - 1,  p = Q(dof / 2, chi^2 / 2),
//!
//! where Q is the regularised upper incomplete gamma function. A test rejects at significance
//! 0.01 with Šidák's correction over the tests in a suite.
//!
//! Mistakes that make the statistic meaningless fail at once with `Err`: samples outside the
//! domain or NaN, a density integrating to more than 1.1, samples in cells of zero expectation.

use std::f64::consts::PI;

use glam::Vec3;
pub use prism_core::math::special::regularized_gamma_q;
use prism_core::sampling::rng::Pcg32;

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
    /// chi^2 = Σ (O - E)^2 / E over the terms (cells and the pooled cell).
    pub statistic: f64,
    /// Degrees of freedom: terms - 1.
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

/// Pools cells with expected count < 5 into one pooled cell, computes chi^2 = Σ (O - E)^2 / E,
/// dof = terms - 1 and p = Q(dof / 2, chi^2 / 2).
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
/// tests rejects a correct sampler with probability ALPHA = 0.01: 1 - (1 - ALPHA)^(1/n).
pub fn sidak_significance(n_tests: usize) -> f64 {
    1.0 - (1.0 - ALPHA).powf(1.0 / n_tests.max(1) as f64)
}

/// Panics with a readable report (statistic, dof, p, worst cells) when p < the Šidák
/// significance for a suite of `n_tests_in_suite` tests; prints a one-line summary otherwise.
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

/// Directions on the unit sphere in cells of equal solid angle: `cos_bins` (odd, such as 101,
/// so that the horizon z = 0 is the middle of a row of cells and a hemispherical density's kink
/// falls on an integration node) equal intervals of cos(theta) in [-1, 1], times `phi_bins`
/// equal intervals of phi in [0, 2 pi).
///
/// `sample` draws one direction (None = the sampler failed); `pdf` is the claimed solid-angle
/// density. Expected counts integrate pdf d(cos theta) d(phi) over each cell with an 8x8
/// composite Simpson rule, exact for densities piecewise cubic in cos theta with breaks on its
/// nodes, such as max(0, cos theta) / pi (the horizon z = 0 is the middle node of the middle
/// row). A density that jumps at the horizon (uniform on the hemisphere) is off by up to 1/12 in
/// the middle row, depending on how the horizon node rounds; that is well below the noise at
/// 10^6 samples on 101 x 202 cells. Fails at once on a non-unit or NaN direction, on a total pdf integral
/// above 1.1, and on samples in cells of zero expectation.
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
            simpson(&pdf, (x0, x0 + width), 16)
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

/// A density on the rectangle [x0, x1) x [y0, y1) in nx x ny equal cells; expected counts by an
/// 8x8 composite Simpson rule per cell. Fails at once on samples outside the rectangle or NaN,
/// on a total pdf integral above 1.1, and on samples in cells of zero expectation.
#[allow(clippy::too_many_arguments)] // the rectangle's bounds and resolution, as for the others
pub fn chi2_rectangle(
    samples: usize,
    x: (f64, f64),
    y: (f64, f64),
    nx: usize,
    ny: usize,
    seed: u64,
    mut sample: impl FnMut(&mut Pcg32) -> Option<(f64, f64)>,
    pdf: impl Fn(f64, f64) -> f64,
) -> Result<Chi2Outcome, String> {
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
/// expectations, failures counting as one more cell of probability 1 - Σ probabilities.
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

/// The index of the bin of width `width` holding offset `x` >= 0, clamped to `bins - 1` (for
/// offsets that round onto the upper edge).
fn bin(x: f64, width: f64, bins: usize) -> usize {
    ((x / width) as usize).min(bins - 1)
}

/// Composite Simpson rule with `n` (even) sub-intervals: (h / 3) Σ w_i f(a + i h) with weights
/// 1, 4, 2, 4, ..., 2, 4, 1 (Abramowitz and Stegun 25.4.6).
fn simpson(f: impl Fn(f64) -> f64, (a, b): (f64, f64), n: usize) -> f64 {
    let h = (b - a) / n as f64;
    (0..=n)
        .map(|i| simpson_weight(i, n) * f(a + i as f64 * h))
        .sum::<f64>()
        * h
        / 3.0
}

/// The tensor product of [`simpson`] on [a, b] x [c, d], `n` sub-intervals per axis.
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
