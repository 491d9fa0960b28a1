//! The 8-bit image written beside the EXR: by default the linear sRGB values through the sRGB
//! curve as PNG; with Mitsuba 0.6's `ldrfilm`, tonemapped as it asks.
//!
//! Mitsuba 0.6's `ldrfilm` (`src/films/ldrfilm.cpp` and `Bitmap::tonemapReinhard`) develops the
//! image in three steps, which [`LdrOutput::encode`] follows:
//!
//! 1. Tonemapping. `gamma`: every value times 2^exposure. `reinhard`: the global operator of
//!    Reinhard et al. 2002, "Photographic Tone Reproduction for Digital Images", §3.1, eq. 4,
//!    applied to luminance with the chromaticity kept: with the log-average luminance
//!    L̄ = exp(mean ln(10⁻³ + L)), the scaled luminance Lp = L · key / L̄, the white point
//!    L_white = max(L) · key / L̄ and b = clamp(1 − burn, 10⁻⁸, 1),
//!    L' = Lp (1 + Lp / (L_white² b⁴)) / (1 + Lp), and every channel is scaled by L'/L.
//! 2. Clamping to [0, 1] and the transfer curve: sRGB for `gamma` = −1, otherwise v^(1/γ).
//! 3. Rounding to 8 bits, as luminance or RGB, with an alpha channel where asked: the film's
//!    coverage alpha (the share of a pixel's camera rays that meet something, as Mitsuba 0.6
//!    writes it), stored linearly.

use std::path::Path;

use crate::error::Result;
use crate::image::{Channels, srgb, write_jpeg_u8, write_png_u8};

/// How radiance becomes a displayable value in [0, 1] before the transfer curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Tonemap {
    /// Every value times 2^`exposure` (f-stops).
    Exposure { exposure: f32 },
    /// Reinhard et al.'s global operator with its `key` (the mid-grey the log-average
    /// luminance maps to) and `burn` (in [0, 1]: how much the highlights may saturate).
    Reinhard { key: f32, burn: f32 },
}

/// The transfer curve of the 8-bit values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TransferCurve {
    Srgb,
    /// v^(1/γ).
    Gamma(f32),
}

/// The 8-bit file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LdrFormat {
    Png,
    Jpeg,
}

impl LdrFormat {
    /// The file's extension, as Mitsuba 0.6 names it.
    pub fn extension(self) -> &'static str {
        match self {
            LdrFormat::Png => "png",
            LdrFormat::Jpeg => "jpg",
        }
    }
}

/// What the 8-bit image holds and how it is encoded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LdrOutput {
    pub tonemap: Tonemap,
    pub curve: TransferCurve,
    pub format: LdrFormat,
    pub channels: Channels,
}

impl std::default::Default for LdrOutput {
    /// The PNG Prism writes for any film: linear sRGB through the sRGB curve.
    fn default() -> Self {
        LdrOutput {
            tonemap: Tonemap::Exposure { exposure: 0.0 },
            curve: TransferCurve::Srgb,
            format: LdrFormat::Png,
            channels: Channels::Rgb,
        }
    }
}

/// Luminance of linear sRGB (ITU-R BT.709 primaries), the Y row of its matrix to XYZ.
fn luminance(rgb: [f32; 3]) -> f32 {
    0.212_671 * rgb[0] + 0.715_160 * rgb[1] + 0.072_169 * rgb[2]
}

impl LdrOutput {
    /// The 8-bit values of an image of linear sRGB pixels (top row first), `channels` per
    /// pixel, with the coverage `alpha` of each pixel where the channels have one (opaque
    /// without it).
    pub fn encode(&self, rgb: &[[f32; 3]], alpha: Option<&[f32]>) -> Vec<u8> {
        let grey = matches!(
            self.channels,
            Channels::Luminance | Channels::LuminanceAlpha
        );
        let has_alpha = matches!(self.channels, Channels::Rgba | Channels::LuminanceAlpha);
        let pixels: Vec<[f32; 3]> = if grey {
            rgb.iter().map(|&p| [luminance(p); 3]).collect()
        } else {
            rgb.to_vec()
        };
        let scale = self.scales(&pixels);
        let mut bytes = Vec::with_capacity(self.channels.count() * pixels.len());
        for (i, (pixel, scale)) in pixels.iter().zip(scale).enumerate() {
            let components = if grey { &pixel[..1] } else { &pixel[..] };
            for &v in components {
                bytes.push(self.encode_value(v * scale));
            }
            if has_alpha {
                let coverage = alpha.map_or(1.0, |alpha| alpha[i].clamp(0.0, 1.0));
                bytes.push((coverage * 255.0).round() as u8);
            }
        }
        bytes
    }

    /// The factor each pixel is multiplied by (step 1).
    fn scales(&self, pixels: &[[f32; 3]]) -> Vec<f32> {
        match self.tonemap {
            Tonemap::Exposure { exposure } => vec![exposure.exp2(); pixels.len()],
            Tonemap::Reinhard { key, burn } => {
                let luminances: Vec<f64> =
                    pixels.iter().map(|&p| f64::from(luminance(p))).collect();
                let max = luminances.iter().copied().fold(0.0f64, f64::max);
                if !(max > 0.0) || luminances.is_empty() {
                    return vec![1.0; pixels.len()];
                }
                let log_sum: f64 = luminances.iter().map(|l| (1e-3 + l.max(0.0)).ln()).sum();
                let log_average = (log_sum / luminances.len() as f64).exp();
                let scale = f64::from(key) / log_average;
                let white = max * scale;
                let b = (1.0 - f64::from(burn)).clamp(1e-8, 1.0);
                let inv_white2 = 1.0 / (white * white * b.powi(4));
                luminances
                    .iter()
                    .map(|&l| {
                        if !(l > 0.0) {
                            return 0.0;
                        }
                        let lp = l * scale;
                        let mapped = lp * (1.0 + lp * inv_white2) / (1.0 + lp);
                        (mapped / l) as f32
                    })
                    .collect()
            }
        }
    }

    /// One tonemapped value clamped, through the curve and rounded (steps 2 and 3).
    fn encode_value(&self, v: f32) -> u8 {
        let clamped = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
        let encoded = match self.curve {
            TransferCurve::Srgb => srgb::encode(clamped),
            TransferCurve::Gamma(gamma) => clamped.powf(1.0 / gamma),
        };
        (encoded * 255.0).round() as u8
    }

    /// Writes the image of `rgb` (`width` × `height` linear sRGB pixels) and their coverage
    /// `alpha` to `path`.
    pub fn write(
        &self,
        path: &Path,
        width: u32,
        height: u32,
        rgb: &[[f32; 3]],
        alpha: Option<&[f32]>,
    ) -> Result<()> {
        let bytes = self.encode(rgb, alpha);
        match self.format {
            LdrFormat::Png => write_png_u8(
                path,
                width,
                height,
                self.channels,
                self.curve == TransferCurve::Srgb,
                &bytes,
            ),
            LdrFormat::Jpeg => write_jpeg_u8(path, width, height, self.channels, &bytes),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The default output is the sRGB PNG of the linear values.
    #[test]
    fn the_default_is_the_srgb_curve() {
        let pixels = [[0.0, 0.5, 1.0], [0.18, 2.0, -1.0]];
        let bytes = LdrOutput::default().encode(&pixels, None);
        let expected: Vec<u8> = pixels
            .iter()
            .flatten()
            .map(|&v| srgb::encode_u8(v))
            .collect();
        assert_eq!(bytes, expected);
    }

    /// Exposure doubles per stop; a gamma of 2 takes the square root; luminance is the Y of the
    /// BT.709 primaries; an alpha channel is the coverage, clamped, or opaque without one.
    #[test]
    fn exposure_gamma_luminance_and_alpha() {
        let output = LdrOutput {
            tonemap: Tonemap::Exposure { exposure: 1.0 },
            curve: TransferCurve::Gamma(2.0),
            format: LdrFormat::Png,
            channels: Channels::LuminanceAlpha,
        };
        let pixels = [[0.32, 0.32, 0.32], [1.0, 0.0, 0.0]];
        let expected_red = ((2.0f32 * 0.212_671).sqrt() * 255.0).round() as u8;
        assert_eq!(
            output.encode(&pixels, None),
            vec![204, 255, expected_red, 255]
        );
        let bytes = output.encode(&pixels, Some(&[0.25, 1.5]));
        assert_eq!(bytes, vec![204, 64, expected_red, 255]);
    }

    /// Reinhard's operator: the log-average luminance maps to `key` · (1 + …)/(1 + key) and the
    /// brightest pixel, with no burn, to exactly 1; hue is kept.
    #[test]
    fn reinhard_maps_the_white_point_to_one() {
        let output = LdrOutput {
            tonemap: Tonemap::Reinhard {
                key: 0.18,
                burn: 0.0,
            },
            curve: TransferCurve::Gamma(1.0),
            format: LdrFormat::Png,
            channels: Channels::Rgb,
        };
        let pixels = [[0.5, 0.25, 0.1], [4.0, 2.0, 0.8], [0.05, 0.05, 0.05]];
        let scales = output.scales(&pixels);
        let l: Vec<f64> = pixels.iter().map(|&p| f64::from(luminance(p))).collect();
        let log_average = (l.iter().map(|v| (1e-3 + v).ln()).sum::<f64>() / 3.0).exp();
        let scale = 0.18 / log_average;
        let white = l[1] * scale;
        for (i, &s) in scales.iter().enumerate() {
            let lp = l[i] * scale;
            let expected = lp * (1.0 + lp / (white * white)) / (1.0 + lp);
            assert!(
                (f64::from(s) * l[i] / expected - 1.0).abs() < 1e-5,
                "pixel {i}"
            );
        }
        assert!((f64::from(scales[1]) * l[1] - 1.0).abs() < 1e-5);
        // A black image stays black.
        assert_eq!(output.encode(&[[0.0; 3]; 2], None), vec![0; 6]);
    }
}
