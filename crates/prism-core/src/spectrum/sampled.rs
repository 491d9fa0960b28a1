//! Spectral samples carried along a path: four wavelengths (a hero wavelength and three rotated
//! companions, Wilkie et al. 2014, "Hero Wavelength Spectral Sampling") and the values of a
//! spectrum at them.

use std::ops::{Add, AddAssign, Div, Index, IndexMut, Mul, MulAssign, Sub};
use std::sync::OnceLock;

use wide::f32x4;

use super::cie::{CIE_Y_INTEGRAL_F32, XYZ_TO_LINEAR_SRGB, cie_xyz, cie_xyz4, d65_normalized, mul3};
use super::{LAMBDA_MAX, LAMBDA_MIN};
use crate::sampling::distribution::PiecewiseConstant1D;

/// Number of wavelengths traced together.
pub const N_SPECTRUM_SAMPLES: usize = 4;

/// Values of a spectral quantity at the [`SampledWavelengths`] of a path.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SampledSpectrum(pub [f32; N_SPECTRUM_SAMPLES]);

impl SampledSpectrum {
    pub const ZERO: SampledSpectrum = SampledSpectrum([0.0; N_SPECTRUM_SAMPLES]);
    pub const ONE: SampledSpectrum = SampledSpectrum([1.0; N_SPECTRUM_SAMPLES]);

    pub fn splat(v: f32) -> Self {
        SampledSpectrum([v; N_SPECTRUM_SAMPLES])
    }

    pub fn from_fn(f: impl FnMut(usize) -> f32) -> Self {
        SampledSpectrum(std::array::from_fn(f))
    }

    pub fn max_value(&self) -> f32 {
        self.0.iter().copied().fold(f32::MIN, f32::max)
    }

    pub fn average(&self) -> f32 {
        self.0.iter().sum::<f32>() / N_SPECTRUM_SAMPLES as f32
    }

    pub fn is_black(&self) -> bool {
        self.0.iter().all(|&v| v == 0.0)
    }

    pub fn is_finite(&self) -> bool {
        self.0.iter().all(|v| v.is_finite())
    }
}

impl Index<usize> for SampledSpectrum {
    type Output = f32;
    fn index(&self, i: usize) -> &f32 {
        &self.0[i]
    }
}

impl IndexMut<usize> for SampledSpectrum {
    fn index_mut(&mut self, i: usize) -> &mut f32 {
        &mut self.0[i]
    }
}

macro_rules! componentwise {
    ($trait:ident, $method:ident, $op:tt) => {
        impl $trait for SampledSpectrum {
            type Output = SampledSpectrum;
            #[inline]
            fn $method(self, rhs: SampledSpectrum) -> SampledSpectrum {
                SampledSpectrum::from_fn(|i| self.0[i] $op rhs.0[i])
            }
        }
        impl $trait<f32> for SampledSpectrum {
            type Output = SampledSpectrum;
            #[inline]
            fn $method(self, rhs: f32) -> SampledSpectrum {
                SampledSpectrum::from_fn(|i| self.0[i] $op rhs)
            }
        }
    };
}

componentwise!(Add, add, +);
componentwise!(Sub, sub, -);
componentwise!(Mul, mul, *);
componentwise!(Div, div, /);

impl Mul<SampledSpectrum> for f32 {
    type Output = SampledSpectrum;
    #[inline]
    fn mul(self, rhs: SampledSpectrum) -> SampledSpectrum {
        rhs * self
    }
}

impl AddAssign for SampledSpectrum {
    #[inline]
    fn add_assign(&mut self, rhs: SampledSpectrum) {
        *self = *self + rhs;
    }
}

impl MulAssign for SampledSpectrum {
    #[inline]
    fn mul_assign(&mut self, rhs: SampledSpectrum) {
        *self = *self * rhs;
    }
}

impl MulAssign<f32> for SampledSpectrum {
    #[inline]
    fn mul_assign(&mut self, rhs: f32) {
        *self = *self * rhs;
    }
}

/// How the hero wavelength is drawn: a density p(λ) on 360–830 nm, chosen per scene with the
/// film's `wavelength_sampling` (names in [`WavelengthSampling::NAMES`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum WavelengthSampling {
    /// The density that minimises the error of the image Prism writes, for white light, with
    /// luminance and colour weighted equally (derived below).
    ///
    /// An estimate (1/N) Σ f_c(λ)/p(λ) of channels c with means I_c has relative variance
    /// Σ_c a_c Var_c/I_c² = ∫ (Σ_c a_c f_c²/I_c²)/p − Σ_c a_c, which over densities is smallest,
    /// by Cauchy–Schwarz, at p ∝ sqrt(Σ_c a_c f_c²/I_c²). The image's channels are linear sRGB
    /// (r̄, ḡ, b̄ = M_XYZ→sRGB (x̄, ȳ, z̄)) and the luminance ȳ, by which `--target-error`,
    /// `relative_error.Y` and the eye judge noise first; giving luminance the weight of the three
    /// colour channels together (a_Y = 3, a_R = a_G = a_B = 1) and taking white light, CIE D65:
    ///
    /// p(λ) ∝ D65(λ) · sqrt(3 ȳ(λ)²/I_Y² + r̄(λ)²/I_R² + ḡ(λ)²/I_G² + b̄(λ)²/I_B²),
    /// I_c = ∫ c̄(λ) D65(λ) dλ,
    ///
    /// tabulated on 1 nm cells as [`WavelengthSampling::CieSum`] is. docs/wavelengths.md gives the
    /// measurements against the other densities.
    Balanced,
    /// p(λ) ∝ x̄(λ) + ȳ(λ) + z̄(λ) on 360–830 nm, the lecture's choice ("Sampling the spectrum"),
    /// tabulated as a piecewise-constant density on 1 nm cells and sampled by its inverse CDF.
    CieSum,
    /// p(λ) ∝ 1 / cosh²(0.0072 (λ − 538)), the "visible" density of Radziszewski et al. 2009
    /// used by Mitsuba 3 and pbrt-v4, tabulated on 1 nm cells as the others; the default, which measured quieter than `Balanced` on
    /// the Cornell boxes (docs/wavelengths.md).
    #[default]
    Visible,
    /// Uniform on 360–830 nm.
    Uniform,
}

/// Constants of the visible-wavelength density (pbrt-v4 `SampleVisibleWavelengths`).
const VISIBLE_CENTER: f32 = 538.0;
const VISIBLE_SLOPE: f32 = 0.0072;

impl WavelengthSampling {
    /// Every density, in the order of [`Self::NAMES`].
    pub const ALL: [WavelengthSampling; 4] = [
        WavelengthSampling::Balanced,
        WavelengthSampling::CieSum,
        WavelengthSampling::Visible,
        WavelengthSampling::Uniform,
    ];
    /// The names scenes and the command line give the densities.
    pub const NAMES: [&'static str; 4] = ["balanced", "cie_sum", "visible", "uniform"];

    /// The density called `name` (one of [`Self::NAMES`]).
    pub fn from_name(name: &str) -> Option<WavelengthSampling> {
        Self::NAMES
            .iter()
            .position(|n| *n == name)
            .map(|i| Self::ALL[i])
    }

    /// The name of the density, as [`Self::from_name`] reads it.
    pub fn name(self) -> &'static str {
        Self::NAMES[Self::ALL.iter().position(|s| *s == self).unwrap_or(0)]
    }

    /// The piecewise-constant table of 470 cells of 1 nm of a tabulated density, each cell
    /// weighted by the mean of the density's shape at its ends.
    fn tabulate(shape: impl Fn(f32) -> f32) -> PiecewiseConstant1D {
        let weights: Vec<f32> = (0..470)
            .map(|i| {
                let lambda = LAMBDA_MIN + i as f32;
                0.5 * (shape(lambda) + shape(lambda + 1.0))
            })
            .collect();
        PiecewiseConstant1D::new(&weights, LAMBDA_MIN, LAMBDA_MAX)
    }

    /// The table for [`WavelengthSampling::CieSum`].
    fn cie_sum_distribution() -> &'static PiecewiseConstant1D {
        static TABLE: OnceLock<PiecewiseConstant1D> = OnceLock::new();
        TABLE.get_or_init(|| Self::tabulate(|lambda| cie_xyz(lambda).iter().sum::<f32>()))
    }

    /// The table for [`WavelengthSampling::Visible`]: its closed-form inverse CDF and density
    /// cost an arctanh and a cosh per wavelength, 6 % of a Cornell box sample's time, where
    /// the table's inversion is a binary search.
    fn visible_distribution() -> &'static PiecewiseConstant1D {
        static TABLE: OnceLock<PiecewiseConstant1D> = OnceLock::new();
        TABLE.get_or_init(|| {
            Self::tabulate(|lambda| (VISIBLE_SLOPE * (lambda - VISIBLE_CENTER)).cosh().powi(-2))
        })
    }

    /// The table for [`WavelengthSampling::Balanced`].
    fn balanced_distribution() -> &'static PiecewiseConstant1D {
        static TABLE: OnceLock<PiecewiseConstant1D> = OnceLock::new();
        TABLE.get_or_init(|| {
            // Luminance and linear sRGB responses to a wavelength: ȳ, then M (x̄, ȳ, z̄).
            let responses = |lambda: f32| {
                let xyz = cie_xyz(lambda);
                let [r, g, b] = mul3(&XYZ_TO_LINEAR_SRGB, xyz);
                [xyz[1], r, g, b].map(f64::from)
            };
            // I_c = ∫ c̄ D65 dλ by the trapezoidal rule on a 1 nm grid.
            let mut means = [0.0f64; 4];
            for i in 0..=470 {
                let lambda = LAMBDA_MIN + i as f32;
                let weight = if i == 0 || i == 470 { 0.5 } else { 1.0 };
                let d65 = f64::from(d65_normalized(lambda));
                for (mean, response) in means.iter_mut().zip(responses(lambda)) {
                    *mean += weight * d65 * response;
                }
            }
            const CHANNEL_WEIGHTS: [f64; 4] = [3.0, 1.0, 1.0, 1.0];
            Self::tabulate(|lambda| {
                let sum: f64 = responses(lambda)
                    .iter()
                    .zip(means)
                    .zip(CHANNEL_WEIGHTS)
                    .map(|((response, mean), a)| a * (response / mean).powi(2))
                    .sum();
                (f64::from(d65_normalized(lambda)) * sum.sqrt()) as f32
            })
        })
    }

    /// A wavelength drawn from a table and the density of the cell it lies in.
    #[inline]
    fn sample_table(table: &PiecewiseConstant1D, u: f32) -> (f32, f32) {
        // The table's samples lie in its domain, [LAMBDA_MIN, LAMBDA_MAX).
        let (lambda, cell) = table.sample(u);
        (lambda, table.cell_pdf(cell))
    }

    /// Draws one wavelength in [360, 830) nm from `u` in [0, 1).
    pub fn sample(self, u: f32) -> f32 {
        self.sample_with_pdf(u).0
    }

    /// [`Self::sample`] and the density of the wavelength drawn: for a tabulated density that
    /// of the cell the inversion chose, which saves looking it up again.
    #[inline]
    pub fn sample_with_pdf(self, u: f32) -> (f32, f32) {
        let clamp = |lambda: f32| lambda.clamp(LAMBDA_MIN, LAMBDA_MAX.next_down());
        match self {
            WavelengthSampling::Balanced => Self::sample_table(Self::balanced_distribution(), u),
            WavelengthSampling::CieSum => Self::sample_table(Self::cie_sum_distribution(), u),
            WavelengthSampling::Visible => Self::sample_table(Self::visible_distribution(), u),
            WavelengthSampling::Uniform => {
                let lambda = clamp(LAMBDA_MIN + u * (LAMBDA_MAX - LAMBDA_MIN));
                (lambda, self.pdf(lambda))
            }
        }
    }

    /// Density of [`Self::sample`] at `lambda` (per nm).
    pub fn pdf(self, lambda: f32) -> f32 {
        if !(LAMBDA_MIN..LAMBDA_MAX).contains(&lambda) {
            return 0.0;
        }
        match self {
            WavelengthSampling::Balanced => Self::balanced_distribution().pdf(lambda),
            WavelengthSampling::CieSum => Self::cie_sum_distribution().pdf(lambda),
            WavelengthSampling::Visible => Self::visible_distribution().pdf(lambda),
            WavelengthSampling::Uniform => 1.0 / (LAMBDA_MAX - LAMBDA_MIN),
        }
    }
}

/// The wavelengths of a path and the density each was drawn with.
///
/// The hero λ₀ is drawn from p with the uniform number u; the companions are drawn with the
/// rotated numbers u + k/4 (mod 1), λ_k = P⁻¹(u + k/4), as pbrt-v4 and Mitsuba 3 do. Each λ_k is
/// distributed with density p on its own, so (1/4) Σ_k f(λ_k)/p(λ_k) is unbiased for ∫f, and the
/// four are stratified over the distribution, one in each quarter of its CDF (rotating λ itself
/// instead would put companions where p is small).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampledWavelengths {
    lambda: [f32; N_SPECTRUM_SAMPLES],
    pdf: [f32; N_SPECTRUM_SAMPLES],
}

impl SampledWavelengths {
    /// Four wavelengths from one uniform number `u`.
    pub fn sample(u: f32, sampling: WavelengthSampling) -> Self {
        let drawn: [(f32, f32); N_SPECTRUM_SAMPLES] = std::array::from_fn(|k| {
            let mut uk = u + k as f32 / N_SPECTRUM_SAMPLES as f32;
            if uk >= 1.0 {
                uk -= 1.0;
            }
            sampling.sample_with_pdf(uk)
        });
        SampledWavelengths {
            lambda: drawn.map(|(lambda, _)| lambda),
            pdf: drawn.map(|(_, pdf)| pdf),
        }
    }

    /// A single wavelength with all weight on it (for tests and single-wavelength queries).
    pub fn single(lambda: f32) -> Self {
        SampledWavelengths {
            lambda: [lambda; N_SPECTRUM_SAMPLES],
            pdf: [1.0, 0.0, 0.0, 0.0],
        }
    }

    #[inline]
    pub fn lambda(&self, i: usize) -> f32 {
        self.lambda[i]
    }

    #[inline]
    pub fn lambdas(&self) -> &[f32; N_SPECTRUM_SAMPLES] {
        &self.lambda
    }

    #[inline]
    pub fn pdf(&self, i: usize) -> f32 {
        self.pdf[i]
    }

    /// Keeps only the hero wavelength (at a dispersive interface, where the companions would
    /// follow other directions): its estimate becomes f(λ₀)/p(λ₀), stored as pdf₀ = p(λ₀)/4 so
    /// that the mean over four still gives it.
    pub fn terminate_secondary(&mut self) {
        if self.secondary_terminated() {
            return;
        }
        let hero_pdf = self.pdf[0];
        self.pdf = [0.0; N_SPECTRUM_SAMPLES];
        self.pdf[0] = hero_pdf / N_SPECTRUM_SAMPLES as f32;
    }

    pub fn secondary_terminated(&self) -> bool {
        self.pdf[1..].iter().all(|&p| p == 0.0)
    }

    /// The Monte Carlo estimate of CIE XYZ for radiance `l` at these wavelengths:
    /// X = (1/4) Σ_i L(λ_i) x̄(λ_i) / pdf_i / ∫ȳ (likewise Y, Z).
    pub fn to_xyz(&self, l: &SampledSpectrum) -> [f32; 3] {
        // The matching functions at all four wavelengths at once; the sum over wavelengths
        // in their order, skipping the terminated ones.
        let cmf = cie_xyz4(f32x4::from(self.lambda)).map(f32x4::to_array);
        let mut xyz = [0.0f32; 3];
        for (i, (&radiance, &pdf)) in l.0.iter().zip(&self.pdf).enumerate() {
            if pdf == 0.0 {
                continue;
            }
            let w = radiance / pdf;
            for (sum, matching) in xyz.iter_mut().zip(&cmf) {
                *sum += w * matching[i];
            }
        }
        let scale = 1.0 / (N_SPECTRUM_SAMPLES as f32 * CIE_Y_INTEGRAL_F32);
        xyz.map(|v| v * scale)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::rng::Pcg32;

    #[test]
    fn pdfs_integrate_to_one() {
        for sampling in WavelengthSampling::ALL {
            let steps = 470 * 8;
            let h = 470.0 / steps as f64;
            let integral: f64 = (0..steps)
                .map(|i| f64::from(sampling.pdf(360.0 + ((i as f64 + 0.5) * h) as f32)) * h)
                .sum();
            assert!((integral - 1.0).abs() < 2e-3, "{sampling:?}: {integral}");
        }
    }

    #[test]
    fn companions_are_drawn_with_rotated_uniform_numbers() {
        let sampling = WavelengthSampling::CieSum;
        let w = SampledWavelengths::sample(0.3, sampling);
        for (k, u) in [0.3f32, 0.55, 0.8, 0.05].into_iter().enumerate() {
            assert!((w.lambda(k) - sampling.sample(u)).abs() < 1e-3);
            assert_eq!(w.pdf(k), sampling.pdf(w.lambda(k)));
        }
    }

    /// The density returned with a sample is the density of the wavelength drawn.
    #[test]
    fn samples_carry_their_density() {
        let mut rng = Pcg32::seeded(9);
        for sampling in WavelengthSampling::ALL {
            for _ in 0..10_000 {
                let u = rng.next_f32();
                let (lambda, pdf) = sampling.sample_with_pdf(u);
                assert_eq!(lambda, sampling.sample(u));
                assert_eq!(pdf, sampling.pdf(lambda), "{sampling:?} at {lambda}");
            }
        }
    }

    /// A constant unit spectrum must come out as Y = 1 on average, with the mean estimate
    /// within 4 standard errors (the error is estimated from the samples themselves).
    #[test]
    fn unit_spectrum_has_unit_luminance_in_expectation() {
        for sampling in WavelengthSampling::ALL {
            let mut rng = Pcg32::seeded(5);
            let n = 200_000;
            let (mut sum, mut sum2) = (0.0f64, 0.0f64);
            for _ in 0..n {
                let w = SampledWavelengths::sample(rng.next_f32(), sampling);
                let y = f64::from(w.to_xyz(&SampledSpectrum::ONE)[1]);
                sum += y;
                sum2 += y * y;
            }
            let mean = sum / n as f64;
            let se = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
            assert!(
                (mean - 1.0).abs() < 4.0 * se + 1e-4,
                "{sampling:?}: {mean} ± {se}"
            );
        }
    }

    #[test]
    fn terminated_secondaries_keep_the_hero_estimate_unbiased() {
        let mut rng = Pcg32::seeded(9);
        let n = 200_000;
        let (mut sum, mut sum2) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let mut w = SampledWavelengths::sample(rng.next_f32(), WavelengthSampling::CieSum);
            w.terminate_secondary();
            let y = f64::from(w.to_xyz(&SampledSpectrum::ONE)[1]);
            sum += y;
            sum2 += y * y;
        }
        let mean = sum / n as f64;
        let se = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
        assert!((mean - 1.0).abs() < 4.0 * se, "{mean} ± {se}");
    }

    /// Per-sample relative variances of the white-light (D65) estimates of Y and of linear
    /// sRGB (summed over R, G, B) for a density: the variance over u of the four stratified
    /// wavelengths' estimate, by the midpoint rule on 2¹⁶ values of u (the estimate repeats
    /// with period 1/4 in u).
    fn white_light_relative_variances(sampling: WavelengthSampling) -> (f64, f64) {
        let n = 1 << 16;
        let (mut sum, mut sum2) = ([0.0f64; 4], [0.0f64; 4]);
        for i in 0..n {
            let u = (i as f32 + 0.5) / (4 * n) as f32;
            let w = SampledWavelengths::sample(u, sampling);
            let l = SampledSpectrum::from_fn(|k| d65_normalized(w.lambda(k)));
            let xyz = w.to_xyz(&l);
            let rgb = mul3(&XYZ_TO_LINEAR_SRGB, xyz);
            for (c, v) in [xyz[1], rgb[0], rgb[1], rgb[2]].into_iter().enumerate() {
                sum[c] += f64::from(v);
                sum2[c] += f64::from(v) * f64::from(v);
            }
        }
        let relative = |c: usize| {
            let mean = sum[c] / n as f64;
            (sum2[c] / n as f64 - mean * mean) / (mean * mean)
        };
        (relative(0), relative(1) + relative(2) + relative(3))
    }

    /// The balanced density's claim (docs/wavelengths.md): under white light its estimate of
    /// luminance is less noisy than that of Mitsuba's and pbrt's `visible` density, and its
    /// colour (linear sRGB) far less noisy than `visible`'s and about as quiet as the lecture's
    /// x̄+ȳ+z̄, whose luminance is some 20 times noisier than `visible`'s. The variances are
    /// exact up to the quadrature, so the comparisons have no noise to allow for.
    #[test]
    fn balanced_density_is_quieter_than_visible_under_white_light() {
        let (balanced_y, balanced_rgb) =
            white_light_relative_variances(WavelengthSampling::Balanced);
        let (visible_y, visible_rgb) = white_light_relative_variances(WavelengthSampling::Visible);
        let (cie_y, cie_rgb) = white_light_relative_variances(WavelengthSampling::CieSum);
        assert!(balanced_y < visible_y, "Y: {balanced_y} vs {visible_y}");
        assert!(
            balanced_rgb < 0.6 * visible_rgb,
            "RGB: {balanced_rgb} vs {visible_rgb}"
        );
        assert!(
            balanced_rgb < 1.1 * cie_rgb,
            "RGB: {balanced_rgb} vs {cie_rgb}"
        );
        assert!(cie_y > 15.0 * visible_y, "Y: {cie_y} vs {visible_y}");
    }
}
