//! Spectral distributions given by a scene: constants, piecewise-linear tables and upsampled RGB.

use wide::{CmpGe, CmpLe, f32x4};

use super::blackbody::Blackbody;
use super::cie::{cie_y, d65_normalized, d65_normalized4};
use super::interpolation::{interpolate_regular, interpolate_regular4};
use super::rgb::{RgbSigmoidPolynomial, RgbToSpectrumTable};
use super::sampled::{SampledSpectrum, SampledWavelengths};
use super::{LAMBDA_MAX, LAMBDA_MIN};

/// A spectral distribution, evaluated at the wavelengths of a path.
#[derive(Clone, Debug, PartialEq)]
pub enum Spectrum {
    /// The same value at every wavelength.
    Constant(f32),
    /// Linear interpolation of (λ, value) samples, zero outside their range (Mitsuba 3's
    /// `irregular` spectrum semantics).
    PiecewiseLinear(PiecewiseLinear),
    /// An upsampled RGB reflectance, `scale` times a sigmoid polynomial; the scale is 1 for
    /// colours within [0, 1] and 2·max(rgb) for brighter ones (pbrt-v4's unbounded RGB spectrum).
    Rgb {
        polynomial: RgbSigmoidPolynomial,
        scale: f32,
    },
    /// An RGB illuminant: `scale` times a sigmoid polynomial times D65 of luminance 1 (Mitsuba 3's
    /// `srgb_d65`: scale = 2·max(rgb), the polynomial fitted to rgb/scale), so that the emission
    /// (1, 1, 1) is D65 white of luminance 1.
    RgbIlluminant {
        polynomial: RgbSigmoidPolynomial,
        scale: f32,
    },
    /// Planck's law at a temperature, in W m⁻² sr⁻¹ nm⁻¹ (Mitsuba's `blackbody`).
    Blackbody(Blackbody),
}

/// Which physical quantity an RGB triple describes; it decides how the triple is upsampled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RgbIntent {
    /// A reflectance or transmittance, in [0, 1].
    Albedo,
    /// Emitted radiance or intensity: the colour of a light.
    Illuminant,
    /// A quantity without bounds, such as an index of refraction: always upsampled as
    /// 2·max(rgb) times the spectrum of rgb / (2·max(rgb)) (pbrt-v4's `RGBUnboundedSpectrum`),
    /// so that the fitted colour is never saturated.
    Unbounded,
}

impl Spectrum {
    /// The spectrum for an RGB triple (linear sRGB, components ≥ 0), through the shipped table
    /// of fitted coefficients ([`RgbToSpectrumTable::srgb`]).
    pub fn from_rgb(rgb: [f32; 3], intent: RgbIntent) -> Spectrum {
        let table = RgbToSpectrumTable::srgb();
        let max = rgb[0].max(rgb[1]).max(rgb[2]);
        match intent {
            RgbIntent::Albedo if max <= 1.0 => {
                if rgb[0] == rgb[1] && rgb[1] == rgb[2] {
                    Spectrum::Constant(rgb[0])
                } else {
                    Spectrum::Rgb {
                        polynomial: table.fetch(rgb),
                        scale: 1.0,
                    }
                }
            }
            RgbIntent::Albedo => {
                let scale = 2.0 * max;
                Spectrum::Rgb {
                    polynomial: table.fetch(rgb.map(|c| c / scale)),
                    scale,
                }
            }
            RgbIntent::Unbounded => {
                if rgb[0] == rgb[1] && rgb[1] == rgb[2] {
                    return Spectrum::Constant(rgb[0]);
                }
                let scale = 2.0 * max;
                Spectrum::Rgb {
                    polynomial: table.fetch(rgb.map(|c| c / scale)),
                    scale,
                }
            }
            RgbIntent::Illuminant => {
                if max <= 0.0 {
                    return Spectrum::Constant(0.0);
                }
                let scale = 2.0 * max;
                Spectrum::RgbIlluminant {
                    polynomial: table.fetch(rgb.map(|c| c / scale)),
                    scale,
                }
            }
        }
    }

    /// The value at one wavelength in nm.
    #[inline]
    pub fn value(&self, lambda: f32) -> f32 {
        match self {
            Spectrum::Constant(v) => *v,
            Spectrum::PiecewiseLinear(table) => table.value(lambda),
            Spectrum::Rgb { polynomial, scale } => scale * polynomial.eval(lambda),
            Spectrum::RgbIlluminant { polynomial, scale } => {
                scale * polynomial.eval(lambda) * d65_normalized(lambda)
            }
            Spectrum::Blackbody(blackbody) => blackbody.value(lambda),
        }
    }

    /// The values at the wavelengths of a path: tables and RGB models four at once in SIMD, with
    /// the numbers of [`Self::value`].
    #[inline]
    pub fn sample(&self, wavelengths: &SampledWavelengths) -> SampledSpectrum {
        match self {
            Spectrum::Constant(v) => SampledSpectrum::splat(*v),
            Spectrum::PiecewiseLinear(table) => table.sample(wavelengths),
            Spectrum::Rgb { polynomial, scale } => {
                let lambda = f32x4::from(*wavelengths.lambdas());
                SampledSpectrum((f32x4::splat(*scale) * polynomial.eval4(lambda)).to_array())
            }
            Spectrum::RgbIlluminant { polynomial, scale } => {
                let lambda = f32x4::from(*wavelengths.lambdas());
                let value = f32x4::splat(*scale) * polynomial.eval4(lambda);
                SampledSpectrum((value * d65_normalized4(lambda)).to_array())
            }
            Spectrum::Blackbody(_) => {
                SampledSpectrum::from_fn(|i| self.value(wavelengths.lambda(i)))
            }
        }
    }

    /// The largest value over 360–830 nm (sampled at 1 nm), used to bound reflectances.
    pub fn max_value(&self) -> f32 {
        self.constant_value().unwrap_or_else(|| {
            (0..=470)
                .map(|i| self.value(LAMBDA_MIN + i as f32))
                .fold(0.0, f32::max)
        })
    }

    /// The smallest value over 360–830 nm (sampled at 1 nm).
    pub fn min_value(&self) -> f32 {
        self.constant_value().unwrap_or_else(|| {
            (0..=470)
                .map(|i| self.value(LAMBDA_MIN + i as f32))
                .fold(f32::INFINITY, f32::min)
        })
    }

    /// The mean value over 360–830 nm (sampled at 1 nm).
    pub fn mean(&self) -> f32 {
        self.constant_value().unwrap_or_else(|| {
            let sum: f64 = (0..=470)
                .map(|i| f64::from(self.value(LAMBDA_MIN + i as f32)))
                .sum();
            (sum / 471.0) as f32
        })
    }

    /// The value at every wavelength, when the spectrum is constant.
    fn constant_value(&self) -> Option<f32> {
        match self {
            Spectrum::Constant(v) => Some(*v),
            Spectrum::PiecewiseLinear(_)
            | Spectrum::Rgb { .. }
            | Spectrum::RgbIlluminant { .. }
            | Spectrum::Blackbody(_) => None,
        }
    }

    /// Luminance Y = ∫ S ȳ dλ / ∫ ȳ dλ (1 nm trapezoid rule), the brightness of an emission
    /// spectrum as the eye sees it; used to choose lights in proportion to their power.
    pub fn luminance(&self) -> f32 {
        let (mut num, mut den) = (0.0f64, 0.0f64);
        let n = (LAMBDA_MAX - LAMBDA_MIN) as usize;
        for i in 0..=n {
            let lambda = LAMBDA_MIN + i as f32;
            let w = if i == 0 || i == n { 0.5 } else { 1.0 };
            let y = f64::from(cie_y(lambda)) * w;
            num += f64::from(self.value(lambda)) * y;
            den += y;
        }
        (num / den) as f32
    }
}

/// Samples (λᵢ, vᵢ) with strictly increasing λ, linearly interpolated; zero outside [λ₀, λₙ].
/// Regularly spaced samples (the common case: measured data every 1, 4, 5 or 10 nm) are looked
/// up in constant time, others by binary search.
#[derive(Clone, Debug, PartialEq)]
pub struct PiecewiseLinear {
    lambdas: Vec<f32>,
    values: Vec<f32>,
    /// 1 / spacing when the wavelengths are equally spaced (to within 10⁻³ of the spacing, the
    /// tolerance of Mitsuba's `regular` spectrum detection).
    inverse_spacing: Option<f32>,
}

impl PiecewiseLinear {
    /// A table from samples with strictly increasing wavelengths (checked by the caller); None
    /// for an empty list.
    pub fn new(samples: &[(f32, f32)]) -> Option<Self> {
        if samples.is_empty() {
            return None;
        }
        let lambdas: Vec<f32> = samples.iter().map(|s| s.0).collect();
        let steps = lambdas.windows(2).map(|w| w[1] - w[0]);
        let (min, max) = steps.fold((f32::INFINITY, 0.0f32), |(lo, hi), d| {
            (lo.min(d), hi.max(d))
        });
        let inverse_spacing = (lambdas.len() > 1 && max - min <= 1e-3 * min)
            .then(|| (lambdas.len() - 1) as f32 / (lambdas[lambdas.len() - 1] - lambdas[0]));
        Some(PiecewiseLinear {
            lambdas,
            values: samples.iter().map(|s| s.1).collect(),
            inverse_spacing,
        })
    }

    /// The first and last wavelength of the table.
    pub fn range(&self) -> (f32, f32) {
        (self.lambdas[0], self.lambdas[self.lambdas.len() - 1])
    }

    /// The values at the wavelengths of a path: for a regular table, the four lookups are done
    /// at once in SIMD (only the eight loads are one by one); the same numbers as
    /// [`Self::value`].
    #[inline]
    pub fn sample(&self, wavelengths: &SampledWavelengths) -> SampledSpectrum {
        let Some(inverse) = self.inverse_spacing else {
            return SampledSpectrum::from_fn(|i| self.value(wavelengths.lambda(i)));
        };
        let (first, last) = (self.lambdas[0], self.lambdas[self.lambdas.len() - 1]);
        let lambda = f32x4::from(*wavelengths.lambdas());
        let inside = lambda.cmp_ge(f32x4::splat(first)) & lambda.cmp_le(f32x4::splat(last));
        let x = (lambda - f32x4::splat(first)) * f32x4::splat(inverse);
        SampledSpectrum((interpolate_regular4(&self.values, x) & inside).to_array())
    }

    #[inline]
    pub fn value(&self, lambda: f32) -> f32 {
        let n = self.lambdas.len();
        if !(lambda >= self.lambdas[0] && lambda <= self.lambdas[n - 1]) {
            return 0.0;
        }
        if n == 1 {
            return self.values[0];
        }
        if let Some(inverse) = self.inverse_spacing {
            return interpolate_regular(&self.values, (lambda - self.lambdas[0]) * inverse);
        }
        let i = self
            .lambdas
            .partition_point(|&l| l <= lambda)
            .clamp(1, n - 1)
            - 1;
        let t = (lambda - self.lambdas[i]) / (self.lambdas[i + 1] - self.lambdas[i]);
        self.values[i] + t * (self.values[i + 1] - self.values[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::{N_SPECTRUM_SAMPLES, WavelengthSampling};

    #[test]
    fn piecewise_linear_interpolates_and_is_zero_outside() {
        let s = PiecewiseLinear::new(&[(400.0, 0.0), (500.0, 8.0), (600.0, 15.6), (700.0, 18.4)])
            .unwrap();
        assert_eq!(s.value(399.9), 0.0);
        assert_eq!(s.value(450.0), 4.0);
        assert_eq!(s.value(500.0), 8.0);
        assert!((s.value(650.0) - 17.0).abs() < 1e-5);
        assert_eq!(s.value(700.0), 18.4);
        assert_eq!(s.value(700.1), 0.0);
    }

    #[test]
    fn regular_and_irregular_tables_interpolate_alike() {
        let regular: Vec<(f32, f32)> = (0..20)
            .map(|i| (400.0 + 4.0 * i as f32, (i * i % 7) as f32))
            .collect();
        let mut irregular = regular.clone();
        irregular[5].0 += 0.5;
        let a = PiecewiseLinear::new(&regular).unwrap();
        let b = PiecewiseLinear::new(&irregular).unwrap();
        assert!(a.inverse_spacing.is_some() && b.inverse_spacing.is_none());
        for k in 0..=400 {
            let l = 398.0 + 0.2 * k as f32;
            let expected = if !(400.0..=476.0).contains(&l) {
                0.0
            } else {
                let i = (((l - 400.0) / 4.0) as usize).min(18);
                let t = (l - regular[i].0) / 4.0;
                regular[i].1 + t * (regular[i + 1].1 - regular[i].1)
            };
            assert!((a.value(l) - expected).abs() < 1e-5, "{l}");
            if !(416.0..=424.0).contains(&l) {
                assert!((b.value(l) - expected).abs() < 1e-5, "{l}");
            }
        }
        // Four wavelengths at once give exactly the single lookups.
        for k in 0..200 {
            let lambdas = SampledWavelengths::sample(k as f32 / 200.0, WavelengthSampling::Uniform);
            for table in [&a, &b] {
                let values = table.sample(&lambdas);
                for i in 0..N_SPECTRUM_SAMPLES {
                    assert_eq!(values[i], table.value(lambdas.lambda(i)), "{lambdas:?}");
                }
            }
        }
    }

    /// Every kind of spectrum gives at four wavelengths at once exactly its single values, at
    /// random wavelengths and at the ends of the range (the RGB models and the CIE tables are
    /// evaluated in SIMD there).
    #[test]
    fn four_wavelengths_at_once_equal_single_values() {
        let table = PiecewiseLinear::new(&[(360.0, 0.2), (600.0, 0.9), (830.0, 0.4)]).unwrap();
        let spectra = [
            Spectrum::Constant(0.3),
            Spectrum::PiecewiseLinear(table),
            Spectrum::from_rgb([0.8, 0.2, 0.1], RgbIntent::Albedo),
            Spectrum::from_rgb([0.0, 1.0, 0.0], RgbIntent::Albedo),
            Spectrum::from_rgb([3.0, 0.5, 0.2], RgbIntent::Unbounded),
            Spectrum::from_rgb([12048.2, 8605.84, 6196.21], RgbIntent::Illuminant),
            Spectrum::from_rgb([0.2, 0.2, 0.2], RgbIntent::Illuminant),
        ];
        let mut rng = crate::sampling::rng::Pcg32::seeded(3);
        let mut draws: Vec<SampledWavelengths> = (0..500)
            .map(|_| SampledWavelengths::sample(rng.next_f32(), WavelengthSampling::CieSum))
            .collect();
        draws.push(SampledWavelengths::sample(0.0, WavelengthSampling::Uniform));
        draws.push(SampledWavelengths::sample(
            1.0f32.next_down(),
            WavelengthSampling::Uniform,
        ));
        for spectrum in &spectra {
            for lambdas in &draws {
                let values = spectrum.sample(lambdas);
                for i in 0..N_SPECTRUM_SAMPLES {
                    let single = spectrum.value(lambdas.lambda(i));
                    assert_eq!(
                        values[i].to_bits(),
                        single.to_bits(),
                        "{spectrum:?} {lambdas:?}"
                    );
                }
            }
        }
        for lambdas in &draws {
            let four = crate::spectrum::cie::cie_xyz4(f32x4::from(*lambdas.lambdas()));
            for i in 0..N_SPECTRUM_SAMPLES {
                let single = crate::spectrum::cie::cie_xyz(lambdas.lambda(i));
                for c in 0..3 {
                    assert_eq!(four[c].to_array()[i], single[c], "{lambdas:?}");
                }
            }
        }
    }

    #[test]
    fn white_illuminant_has_unit_luminance() {
        let white = Spectrum::from_rgb([1.0, 1.0, 1.0], RgbIntent::Illuminant);
        assert!(
            (white.luminance() - 1.0).abs() < 1e-3,
            "{}",
            white.luminance()
        );
        let bright = Spectrum::from_rgb([17.0, 12.0, 4.0], RgbIntent::Illuminant);
        // Y of linear sRGB (17, 12, 4) is 0.2127·17 + 0.7152·12 + 0.0722·4.
        let expected = 0.212_672_9 * 17.0 + 0.715_152_2 * 12.0 + 0.072_175 * 4.0;
        assert!((bright.luminance() / expected - 1.0).abs() < 2e-3);
    }

    #[test]
    fn albedo_above_one_is_scaled_like_pbrt_unbounded_rgb() {
        let s = Spectrum::from_rgb([1.5, 1.2, 0.9], RgbIntent::Albedo);
        let Spectrum::Rgb { scale, .. } = s else {
            panic!("expected an RGB spectrum, got {s:?}");
        };
        assert_eq!(scale, 3.0);
        assert!(s.max_value() <= 3.0 && s.max_value() > 1.0);
    }
}
