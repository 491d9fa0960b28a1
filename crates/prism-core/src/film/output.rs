//! The film written out: an OpenEXR image of its linear RGB and CIE XYZ values and each pixel's
//! estimated error, and an sRGB PNG beside it.

use std::path::Path;

use super::Film;
use super::stats::{pixel_relative_error, variance_of_mean};
use crate::error::Result;
use crate::image::{ChannelImage, write_exr, write_png_srgb};

/// The EXR channels of the image, which the integrator's extra channels may not reuse.
pub const IMAGE_CHANNELS: [&str; 10] = [
    "R",
    "G",
    "B",
    "X",
    "Y",
    "Z",
    "variance.X",
    "variance.Y",
    "variance.Z",
    "relative_error.Y",
];

/// Writes the film as an EXR and as an sRGB PNG. The EXR's channels are `R`, `G`, `B` (linear
/// sRGB), `X`, `Y`, `Z` (CIE 1931), `variance.X`, `variance.Y`, `variance.Z` (the estimated
/// variance of each pixel's mean, see [`super::stats`]) and `relative_error.Y` (the
/// pixel's relative standard error of luminance), then the integrator's extra channels under
/// their own names.
pub fn write_images(film: &Film, exr_path: &Path, png_path: &Path) -> Result<()> {
    let xyz = film.xyz();
    let rgb = film.linear_srgb();
    let channel = |values: &[[f32; 3]], c: usize| values.iter().map(|v| v[c]).collect::<Vec<f32>>();
    let variance = |c: usize| {
        film.pixels
            .iter()
            .map(|p| variance_of_mean(p, c) as f32)
            .collect::<Vec<f32>>()
    };
    let values = [
        channel(&rgb, 0),
        channel(&rgb, 1),
        channel(&rgb, 2),
        channel(&xyz, 0),
        channel(&xyz, 1),
        channel(&xyz, 2),
        variance(0),
        variance(1),
        variance(2),
        film.pixels
            .iter()
            .map(|p| pixel_relative_error(p) as f32)
            .collect(),
    ];
    let mut image = ChannelImage {
        width: film.crop.size.x as usize,
        height: film.crop.size.y as usize,
        channels: IMAGE_CHANNELS
            .iter()
            .map(|name| name.to_string())
            .zip(values)
            .collect(),
    };
    for (c, name) in film.aov_names.iter().enumerate() {
        image.channels.push((name.clone(), film.aov(c)));
    }
    write_exr(exr_path, &image)?;
    let interleaved: Vec<f32> = rgb.iter().flatten().copied().collect();
    write_png_srgb(png_path, image.width, image.height, &interleaved)
}
