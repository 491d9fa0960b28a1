//! Spectral samples carried along a path: four wavelengths (a hero wavelength and three rotated
//! companions, Wilkie et al. 2014, "Hero Wavelength Spectral Sampling") and the values of a
//! spectrum at them.

use std::ops::{Add, AddAssign, Div, Index, IndexMut, Mul, MulAssign, Sub};
use std::sync::OnceLock;

use wide::f32x4;

use super::cie::{CIE_Y_INTEGRAL_F32, cie_xyz, cie_xyz4};
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

/// How the hero wavelength is drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum WavelengthSampling {
    /// p(λ) ∝ x̄(λ) + ȳ(λ) + z̄(λ) on 360–830 nm, the lecture's choice ("Sampling the spectrum"),
    /// tabulated as a piecewise-constant density on 1 nm cells and sampled by its inverse CDF.
    #[default]
    CieSum,
    /// p(λ) ∝ 1 / cosh²(0.0072 (λ − 538)), the "visible" density of Radziszewski et al. 2009
    /// used by Mitsuba 3 and pbrt-v4.
    Visible,
    /// Uniform on 360–830 nm.
    Uniform,
}

/// Constants of the visible-wavelength density (pbrt-v4 `SampleVisibleWavelengths`).
const VISIBLE_CENTER: f32 = 538.0;
const VISIBLE_SLOPE: f32 = 0.0072;
const VISIBLE_NORMALIZATION: f32 = 0.003_939_804;

impl WavelengthSampling {
    /// The table for [`WavelengthSampling::CieSum`]: 470 cells of 1 nm, each weighted by the mean
    /// of x̄+ȳ+z̄ at its ends.
    fn cie_sum_distribution() -> &'static PiecewiseConstant1D {
        static TABLE: OnceLock<PiecewiseConstant1D> = OnceLock::new();
        TABLE.get_or_init(|| {
            let sum = |lambda: f32| cie_xyz(lambda).iter().sum::<f32>();
            let weights: Vec<f32> = (0..470)
                .map(|i| {
                    let lambda = LAMBDA_MIN + i as f32;
                    0.5 * (sum(lambda) + sum(lambda + 1.0))
                })
                .collect();
            PiecewiseConstant1D::new(&weights, LAMBDA_MIN, LAMBDA_MAX)
        })
    }

    /// Draws one wavelength in [360, 830) nm from `u` in [0, 1).
    pub fn sample(self, u: f32) -> f32 {
        self.sample_with_pdf(u).0
    }

    /// [`Self::sample`] and the density of the wavelength drawn: for the tabulated density that
    /// of the cell the inversion chose, which saves looking it up again.
    #[inline]
    pub fn sample_with_pdf(self, u: f32) -> (f32, f32) {
        let clamp = |lambda: f32| lambda.clamp(LAMBDA_MIN, LAMBDA_MAX.next_down());
        match self {
            WavelengthSampling::CieSum => {
                // The table's samples lie in its domain, [LAMBDA_MIN, LAMBDA_MAX).
                let table = Self::cie_sum_distribution();
                let (lambda, cell) = table.sample(u);
                (lambda, table.cell_pdf(cell))
            }
            WavelengthSampling::Visible => {
                let lambda = clamp(
                    VISIBLE_CENTER - (0.856_910_6 - 1.827_502 * u).atanh() * (1.0 / VISIBLE_SLOPE),
                );
                (lambda, self.pdf(lambda))
            }
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
            WavelengthSampling::CieSum => Self::cie_sum_distribution().pdf(lambda),
            WavelengthSampling::Visible => {
                let c = (VISIBLE_SLOPE * (lambda - VISIBLE_CENTER)).cosh();
                VISIBLE_NORMALIZATION / (c * c)
            }
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
        for sampling in [
            WavelengthSampling::CieSum,
            WavelengthSampling::Visible,
            WavelengthSampling::Uniform,
        ] {
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
        for sampling in [
            WavelengthSampling::CieSum,
            WavelengthSampling::Visible,
            WavelengthSampling::Uniform,
        ] {
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
        for sampling in [
            WavelengthSampling::CieSum,
            WavelengthSampling::Visible,
            WavelengthSampling::Uniform,
        ] {
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
}
