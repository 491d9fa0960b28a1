//! How two images differ, channel by channel, and whether the difference is consistent with
//! their noise (what `prism compare` reports).
//!
//! Per channel: the means, the MSE, the relative MSE mean((a − b)² / (b² + 0.01)) (the
//! regularised denominator of pbrt's and Mitsuba's tools) and the largest absolute difference.
//!
//! When the test image carries Prism's `variance.Y` channel (and, optionally, the reference
//! too), a per-pixel z-test on luminance follows, as Mitsuba's image tests do: with
//! zᵢ = (aᵢ − bᵢ)/√(σ²_a + σ²_b), Σ zᵢ² is χ²-distributed over the pixels if the images differ
//! only by noise, and the largest |zᵢ| is judged with a Bonferroni correction.

use std::fmt;

use super::ChannelImage;
use crate::error::{Error, Result};
use crate::math::special::regularized_gamma_q;

/// Added to the squared reference in relative errors: relMSE = (a − b)² / (b² + 0.01).
pub const RELATIVE_EPSILON: f64 = 0.01;

/// Everything [`compare`] finds.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    pub channels: Vec<ChannelDifference>,
    /// The z-test of luminance, when the test image has a `variance.Y` channel.
    pub z_test: Option<ZTest>,
}

impl Comparison {
    /// The MSE averaged over the compared channels.
    pub fn mse(&self) -> f64 {
        self.channels.iter().map(|d| d.mse).sum::<f64>() / self.channels.len().max(1) as f64
    }

    /// The relative MSE averaged over the compared channels.
    pub fn rel_mse(&self) -> f64 {
        self.channels.iter().map(|d| d.rel_mse).sum::<f64>() / self.channels.len().max(1) as f64
    }
}

/// The table `prism compare` prints: per channel the means, their ratio, the MSE, the relative
/// MSE and the largest difference, the averages over channels, and the z-test's verdict.
impl fmt::Display for Comparison {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{:>8} {:>12} {:>12} {:>9} {:>12} {:>12} {:>12}",
            "channel", "mean test", "mean ref", "ratio", "MSE", "relMSE", "max |diff|"
        )?;
        for d in &self.channels {
            writeln!(
                f,
                "{:>8} {:>12.6} {:>12.6} {:>9.5} {:>12.4e} {:>12.4e} {:>12.4e}",
                d.name,
                d.mean_test,
                d.mean_reference,
                d.mean_test / d.mean_reference,
                d.mse,
                d.rel_mse,
                d.max_abs
            )?;
        }
        write!(
            f,
            "{:>8} {:>12} {:>12} {:>9} {:>12.4e} {:>12.4e}",
            "all",
            "",
            "",
            "",
            self.mse(),
            self.rel_mse()
        )?;
        if let Some(z) = &self.z_test {
            write!(f, "\n{z}")?;
        }
        Ok(())
    }
}

/// Compares two images of the same size on `channels` (default: R, G, B if both images have
/// them, else X, Y, Z, else Y), with the z-test where the variances are there.
pub fn compare(
    test: &ChannelImage,
    reference: &ChannelImage,
    channels: Option<&[String]>,
) -> Result<Comparison> {
    if (test.width, test.height) != (reference.width, reference.height) {
        return Err(Error::usage(format!(
            "the test image is {}×{} pixels but the reference is {}×{}",
            test.width, test.height, reference.width, reference.height
        ))
        .with_help("compare images rendered at the same resolution and crop"));
    }
    let names = chosen_channels(channels, test, reference)?;
    let channels = names
        .iter()
        .filter_map(|name| match (test.channel(name), reference.channel(name)) {
            (Some(a), Some(b)) => Some(compare_channel(name, a, b)),
            _ => None,
        })
        .collect();
    let z_test = match (
        test.channel("variance.Y"),
        test.channel("Y"),
        reference.channel("Y"),
    ) {
        (Some(variance), Some(a), Some(b)) => {
            Some(z_test(a, b, variance, reference.channel("variance.Y")))
        }
        _ => None,
    };
    Ok(Comparison { channels, z_test })
}

/// The comparison of one channel.
#[derive(Clone, Debug, PartialEq)]
pub struct ChannelDifference {
    pub name: String,
    pub mean_test: f64,
    pub mean_reference: f64,
    pub mse: f64,
    pub rel_mse: f64,
    pub max_abs: f64,
}

/// Compares channel `name` of two images of the same size.
pub fn compare_channel(name: &str, test: &[f32], reference: &[f32]) -> ChannelDifference {
    let n = test.len().max(1) as f64;
    let (mut sum_t, mut sum_r, mut mse, mut rel, mut max_abs) = (0.0, 0.0, 0.0, 0.0, 0.0f64);
    for (&a, &b) in test.iter().zip(reference) {
        let (a, b) = (f64::from(a), f64::from(b));
        let d = a - b;
        sum_t += a;
        sum_r += b;
        mse += d * d;
        rel += d * d / (b * b + RELATIVE_EPSILON);
        max_abs = max_abs.max(d.abs());
    }
    ChannelDifference {
        name: name.to_string(),
        mean_test: sum_t / n,
        mean_reference: sum_r / n,
        mse: mse / n,
        rel_mse: rel / n,
        max_abs,
    }
}

/// The relative MSE of the R, G, B channels of a film against a reference image's (averaged
/// over channels), for `prism converge`.
pub fn rel_mse_rgb(test: &[[f32; 3]], reference: &ChannelImage) -> Result<f64> {
    let mut total = 0.0;
    for (c, name) in ["R", "G", "B"].iter().enumerate() {
        let channel = reference
            .channel(name)
            .ok_or_else(|| Error::usage(format!("the reference image has no {name} channel")))?;
        let values: Vec<f32> = test.iter().map(|p| p[c]).collect();
        total += compare_channel(name, &values, channel).rel_mse;
    }
    Ok(total / 3.0)
}

/// Outcome of the per-pixel z-test.
#[derive(Clone, Debug, PartialEq)]
pub struct ZTest {
    pub pixels: usize,
    /// Σ zᵢ² and its p-value for a χ² distribution with `pixels` degrees of freedom.
    pub chi2: f64,
    pub p_value: f64,
    /// The largest |zᵢ| and its two-sided p-value times the number of pixels (Bonferroni).
    pub max_z: f64,
    pub max_z_p_value: f64,
    /// Fraction of pixels with |z| > 3 (0.27 % expected under noise alone).
    pub beyond_three: f64,
}

impl ZTest {
    /// Whether both the χ² sum and the largest |z| are consistent with noise at significance
    /// 0.01.
    pub fn consistent_with_noise(&self) -> bool {
        self.p_value > 0.01 && self.max_z_p_value > 0.01
    }
}

impl fmt::Display for ZTest {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let verdict = if self.consistent_with_noise() {
            "consistent with noise"
        } else {
            "NOT consistent with noise"
        };
        write!(
            f,
            "z-test of Y over {} pixels: chi² {:.1} (p = {:.3}), max |z| {:.2} (Bonferroni p = {:.3}), {:.2} % beyond |z| = 3 (0.27 % expected): {verdict}",
            self.pixels,
            self.chi2,
            self.p_value,
            self.max_z,
            self.max_z_p_value,
            100.0 * self.beyond_three
        )
    }
}

/// Two-sided tail probability of a standard normal beyond |z|: erfc(|z|/√2) = Q(1/2, z²/2).
fn normal_tail(z: f64) -> f64 {
    if z.is_infinite() {
        return 0.0;
    }
    regularized_gamma_q(0.5, 0.5 * z * z)
}

/// The z-test of luminance with per-pixel variances of both images' means.
pub fn z_test(
    test: &[f32],
    reference: &[f32],
    variance_test: &[f32],
    variance_reference: Option<&[f32]>,
) -> ZTest {
    let mut chi2 = 0.0;
    let (mut pixels, mut max_z, mut beyond) = (0usize, 0.0f64, 0usize);
    for i in 0..test.len() {
        let variance =
            f64::from(variance_test[i]) + variance_reference.map_or(0.0, |v| f64::from(v[i]));
        let d = f64::from(test[i]) - f64::from(reference[i]);
        if !(variance > 0.0) || !variance.is_finite() {
            if d != 0.0 && variance == 0.0 {
                max_z = f64::INFINITY;
            }
            continue;
        }
        let z = d / variance.sqrt();
        chi2 += z * z;
        max_z = max_z.max(z.abs());
        beyond += usize::from(z.abs() > 3.0);
        pixels += 1;
    }
    let p_value = if pixels > 0 {
        regularized_gamma_q(pixels as f64 / 2.0, chi2 / 2.0)
    } else {
        1.0
    };
    ZTest {
        pixels,
        chi2,
        p_value,
        max_z,
        max_z_p_value: (normal_tail(max_z) * pixels.max(1) as f64).min(1.0),
        beyond_three: beyond as f64 / pixels.max(1) as f64,
    }
}

/// The channels to compare: the requested ones, or R,G,B, or X,Y,Z, or Y (luminance images).
pub fn chosen_channels(
    requested: Option<&[String]>,
    test: &ChannelImage,
    reference: &ChannelImage,
) -> Result<Vec<String>> {
    let both = |name: &str| test.channel(name).is_some() && reference.channel(name).is_some();
    if let Some(names) = requested {
        for name in names {
            if !both(name) {
                return Err(Error::usage(format!(
                    "channel \"{name}\" is not in both images"
                )));
            }
        }
        return Ok(names.to_vec());
    }
    for set in [&["R", "G", "B"][..], &["X", "Y", "Z"], &["Y"]] {
        if set.iter().all(|n| both(n)) {
            return Ok(set.iter().map(|s| s.to_string()).collect());
        }
    }
    Err(
        Error::usage("the images share neither R, G, B nor a Y channel")
            .with_help("name them with --channels"),
    )
}

/// Writes [`difference_image`] of the channels `comparison` compared as an sRGB PNG.
pub fn write_difference_png(
    test: &ChannelImage,
    reference: &ChannelImage,
    comparison: &Comparison,
    path: &std::path::Path,
) -> Result<()> {
    let names: Vec<String> = comparison.channels.iter().map(|d| d.name.clone()).collect();
    let rgb = difference_image(test, reference, &names);
    super::write_png_srgb(path, test.width, test.height, &rgb)
}

/// The signed difference of the channels' mean in false colour, as linear RGB triples: red where
/// the test image is brighter, blue where darker, scaled so that the 99th percentile of |a − b|
/// is full intensity.
pub fn difference_image(
    test: &ChannelImage,
    reference: &ChannelImage,
    names: &[String],
) -> Vec<f32> {
    let pixels = test.width * test.height;
    let mut difference = vec![0.0f32; pixels];
    for name in names {
        if let (Some(a), Some(b)) = (test.channel(name), reference.channel(name)) {
            for i in 0..pixels {
                difference[i] += (a[i] - b[i]) / names.len() as f32;
            }
        }
    }
    let mut magnitudes: Vec<f32> = difference
        .iter()
        .map(|d| d.abs())
        .filter(|d| d.is_finite())
        .collect();
    magnitudes.sort_by(f32::total_cmp);
    let scale = magnitudes
        .get(magnitudes.len().saturating_sub(1) * 99 / 100)
        .copied()
        .filter(|s| *s > 0.0)
        .unwrap_or(1.0);
    difference
        .iter()
        .flat_map(|&d| {
            let t = (d / scale).clamp(-1.0, 1.0);
            if t >= 0.0 {
                [1.0, 1.0 - t, 1.0 - t]
            } else {
                [1.0 + t, 1.0 + t, 1.0]
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn channel_statistics() {
        let d = compare_channel("R", &[1.0, 2.0, 3.0], &[1.0, 1.0, 2.0]);
        assert!((d.mean_test - 2.0).abs() < 1e-12 && (d.mean_reference - 4.0 / 3.0).abs() < 1e-12);
        assert!((d.mse - 2.0 / 3.0).abs() < 1e-12);
        assert!((d.rel_mse - (1.0 / 1.01 + 1.0 / 4.01) / 3.0).abs() < 1e-12);
        assert_eq!(d.max_abs, 1.0);
    }

    #[test]
    fn z_test_accepts_noise_and_rejects_a_shift() {
        use crate::sampling::rng::Pcg32;
        let mut rng = Pcg32::seeded(1);
        let n = 10_000;
        // Gaussian noise of variance 1 by Box-Muller.
        let noise: Vec<f32> = (0..n)
            .map(|_| {
                let (u, v) = (rng.next_f64().max(1e-12), rng.next_f64());
                ((-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()) as f32
            })
            .collect();
        let reference = vec![0.0f32; n];
        let variance = vec![1.0f32; n];
        let z = z_test(&noise, &reference, &variance, None);
        assert!(z.p_value > 0.01 && z.max_z_p_value > 0.01, "{z:?}");
        let shifted: Vec<f32> = noise.iter().map(|v| v + 0.5).collect();
        let z = z_test(&shifted, &reference, &variance, None);
        assert!(z.p_value < 1e-6, "{z:?}");
    }
}
