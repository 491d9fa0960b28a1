//! The channels of Mitsuba 3's `specfilm`: each the integral of the radiance against a sensor
//! response function s_j (an SRF, in the spectrum's own units, unnormalised),
//!
//! C_j = ∫ s_j(λ) L(λ) dλ,
//!
//! estimated from a sample's wavelengths λ_i, drawn with densities p_i, as the image's XYZ are:
//! C_j ≈ (1/N) Σ_i s_j(λ_i) L(λ_i) / p_i (wavelengths of zero density skipped). Mitsuba draws
//! the wavelengths in proportion to the sum of the SRFs; Prism draws them from the film's
//! wavelength density, which is positive over 360–830 nm, so the estimate has the same
//! expectation wherever the SRFs lie in that range.

use crate::spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};

/// One channel of a spectral film: its name in the EXR and its response function.
#[derive(Clone, Debug)]
pub struct SpectralBand {
    pub name: String,
    pub response: Spectrum,
}

/// Writes the estimate of each band's C_j for the radiance `radiance` at the wavelengths
/// `lambda` to `values` (one per band).
pub fn band_values(
    bands: &[SpectralBand],
    lambda: &SampledWavelengths,
    radiance: &SampledSpectrum,
    values: &mut [f32],
) {
    let n = radiance.0.len() as f32;
    for (band, value) in bands.iter().zip(values) {
        let response = band.response.sample(lambda);
        *value = (0..radiance.0.len())
            .filter(|&i| lambda.pdf(i) > 0.0)
            .map(|i| response[i] * radiance[i] / lambda.pdf(i))
            .sum::<f32>()
            / n;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::{PiecewiseLinear, WavelengthSampling};

    /// A box response of 100 nm against a constant radiance 2 integrates to 200: the mean over
    /// stratified wavelength samples, drawn uniformly.
    #[test]
    fn a_box_response_integrates_the_radiance() {
        let band = SpectralBand {
            name: "box".into(),
            response: Spectrum::PiecewiseLinear(
                PiecewiseLinear::new(&[(500.0, 1.0), (600.0, 1.0)]).unwrap(),
            ),
        };
        let samples = 100_000;
        let mut sum = 0.0f64;
        for k in 0..samples {
            let u = (k as f32 + 0.5) / samples as f32;
            let lambda = SampledWavelengths::sample(u, WavelengthSampling::Uniform);
            let mut value = [0.0f32];
            band_values(
                std::slice::from_ref(&band),
                &lambda,
                &SampledSpectrum::splat(2.0),
                &mut value,
            );
            sum += f64::from(value[0]);
        }
        let mean = sum / f64::from(samples);
        assert!((mean - 200.0).abs() < 0.5, "{mean}");
    }
}
