//! The film written out: its linear RGB and CIE XYZ values and each pixel's estimated error as
//! interleaved arrays ([`FilmImages`]), an OpenEXR image of them and an 8-bit image beside it
//! ([`super::ldr`]).

use std::path::Path;

use super::Film;
use super::ldr::LdrOutput;
use super::stats::{pixel_relative_error, variance_of_mean};
use crate::error::Result;
use crate::image::{ChannelImage, png_srgb_bytes, write_exr, write_png_srgb};

/// The EXR channels of the image (see [`FilmImages::channels`]), which the integrator's extra
/// channels may not reuse.
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

/// A film's values, row-major with the top row first, each array interleaved per pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct FilmImages {
    pub width: usize,
    pub height: usize,
    /// Linear sRGB (D65 white), three values per pixel.
    pub rgb: Vec<f32>,
    /// CIE 1931 XYZ, three values per pixel.
    pub xyz: Vec<f32>,
    /// The estimated variance of each pixel's mean of X, Y and Z (see [`super::stats`]), three
    /// values per pixel.
    pub variance: Vec<f32>,
    /// The relative standard error of each pixel's luminance, one value per pixel.
    pub relative_error: Vec<f32>,
}

impl FilmImages {
    /// The images of a film's crop window.
    pub fn of(film: &Film) -> FilmImages {
        let xyz = film.xyz();
        let rgb = film.linear_srgb();
        FilmImages {
            width: film.crop.size.x as usize,
            height: film.crop.size.y as usize,
            rgb: rgb.iter().flatten().copied().collect(),
            xyz: xyz.iter().flatten().copied().collect(),
            variance: film
                .pixels
                .iter()
                .flat_map(|p| [0, 1, 2].map(|c| variance_of_mean(p, c) as f32))
                .collect(),
            relative_error: film
                .pixels
                .iter()
                .map(|p| pixel_relative_error(p) as f32)
                .collect(),
        }
    }

    /// The images as named channels: `R`, `G`, `B` (linear sRGB), `X`, `Y`, `Z` (CIE 1931),
    /// `variance.X`, `variance.Y`, `variance.Z` and `relative_error.Y`.
    pub fn channels(&self) -> ChannelImage {
        let channel =
            |values: &[f32], c: usize| values.iter().skip(c).step_by(3).copied().collect();
        let values = [
            channel(&self.rgb, 0),
            channel(&self.rgb, 1),
            channel(&self.rgb, 2),
            channel(&self.xyz, 0),
            channel(&self.xyz, 1),
            channel(&self.xyz, 2),
            channel(&self.variance, 0),
            channel(&self.variance, 1),
            channel(&self.variance, 2),
            self.relative_error.clone(),
        ];
        ChannelImage {
            width: self.width,
            height: self.height,
            channels: IMAGE_CHANNELS
                .iter()
                .map(|name| name.to_string())
                .zip(values)
                .collect(),
        }
    }

    /// The images of channels named as [`FilmImages::channels`] names them (an EXR that Prism
    /// wrote); the error is the name of the first channel missing.
    pub fn from_channels(image: &ChannelImage) -> std::result::Result<FilmImages, &'static str> {
        let channel = |name: &'static str| image.channel(name).ok_or(name);
        let interleave = |names: [&'static str; 3]| -> std::result::Result<Vec<f32>, &'static str> {
            let [a, b, c] = [channel(names[0])?, channel(names[1])?, channel(names[2])?];
            Ok((0..a.len()).flat_map(|i| [a[i], b[i], c[i]]).collect())
        };
        Ok(FilmImages {
            width: image.width,
            height: image.height,
            rgb: interleave(["R", "G", "B"])?,
            xyz: interleave(["X", "Y", "Z"])?,
            variance: interleave(["variance.X", "variance.Y", "variance.Z"])?,
            relative_error: channel("relative_error.Y")?.to_vec(),
        })
    }

    /// Writes the OpenEXR image of [`FilmImages::channels`].
    pub fn write_exr(&self, path: &Path) -> Result<()> {
        write_exr(path, &self.channels())
    }

    /// Writes the RGB image as an 8-bit sRGB PNG.
    pub fn write_png(&self, path: &Path) -> Result<()> {
        write_png_srgb(path, self.width, self.height, &self.rgb)
    }

    /// The bytes of the PNG file [`FilmImages::write_png`] writes.
    pub fn png_bytes(&self) -> std::io::Result<Vec<u8>> {
        png_srgb_bytes(self.width, self.height, &self.rgb)
    }
}

/// Writes the film as an EXR and as an sRGB PNG (see [`FilmImages`]); the EXR also holds the
/// integrator's extra channels under their own names.
pub fn write_images(film: &Film, exr_path: &Path, png_path: &Path) -> Result<()> {
    write_images_with(film, exr_path, png_path, &LdrOutput::default())
}

/// As [`write_images`], with the 8-bit image written to `ldr_path` as `ldr` says.
pub fn write_images_with(
    film: &Film,
    exr_path: &Path,
    ldr_path: &Path,
    ldr: &LdrOutput,
) -> Result<()> {
    let mut image = FilmImages::of(film).channels();
    for (c, name) in film.aov_names.iter().enumerate() {
        image.channels.push((name.clone(), film.aov(c)));
    }
    write_exr(exr_path, &image)?;
    ldr.write(
        ldr_path,
        film.crop.size.x,
        film.crop.size.y,
        &film.linear_srgb(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::CropWindow;
    use glam::UVec2;

    #[test]
    fn channels_read_back_as_the_same_images() {
        let size = UVec2::new(3, 2);
        let mut film = Film::new(
            size,
            CropWindow {
                offset: UVec2::ZERO,
                size,
            },
        );
        for (i, pixel) in film.pixels.iter_mut().enumerate() {
            let v = i as f32;
            pixel.add([v, 2.0 * v, 0.5]);
            pixel.add([v + 1.0, v, 0.25]);
        }
        let images = FilmImages::of(&film);
        assert_eq!(images.rgb.len(), 18);
        assert_eq!(images.relative_error.len(), 6);
        assert_eq!(
            FilmImages::from_channels(&images.channels()),
            Ok(images.clone())
        );
        let mut without_variance = images.channels();
        without_variance
            .channels
            .retain(|(name, _)| name != "variance.Y");
        assert_eq!(
            FilmImages::from_channels(&without_variance),
            Err("variance.Y")
        );
    }
}
