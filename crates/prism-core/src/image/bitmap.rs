//! Images that scenes reference (bitmap textures, environment maps): PNG, JPEG, OpenEXR and
//! Radiance HDR, decoded with the `image` crate into floating-point pixels.

use std::path::Path;

use image::{DynamicImage, ImageDecoder, ImageReader, Limits};

use super::srgb;
use crate::error::{Error, ErrorKind, Result};

/// Largest image accepted, in pixels; larger declared sizes are refused before decoding.
const MAX_PIXELS: u64 = 1 << 28;

/// How the stored values relate to light.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    /// Linear values (OpenEXR, Radiance HDR).
    Linear,
    /// Values in [0, 1] with the sRGB transfer curve applied (8- and 16-bit PNG and JPEG).
    Srgb,
}

/// Decoded pixels, row-major with the top row first, `channels` values per pixel (1 = grey,
/// 3 = RGB, 4 = RGBA; grey with alpha becomes RGBA).
#[derive(Clone, Debug, PartialEq)]
pub struct Bitmap {
    pub width: usize,
    pub height: usize,
    pub channels: usize,
    pub data: Vec<f32>,
    pub encoding: Encoding,
}

impl Bitmap {
    /// The value of channel `c` of pixel (x, y).
    #[inline]
    pub fn value(&self, x: usize, y: usize, c: usize) -> f32 {
        self.data[(y * self.width + x) * self.channels + c]
    }

    /// Converts sRGB-encoded values to linear ones (IEC 61966-2-1); alpha stays as it is.
    pub fn linearize(&mut self) {
        if self.encoding == Encoding::Linear {
            return;
        }
        let colour_channels = if self.channels == 4 { 3 } else { self.channels };
        for pixel in self.data.chunks_mut(self.channels) {
            for v in &mut pixel[..colour_channels] {
                *v = srgb::decode(*v);
            }
        }
        self.encoding = Encoding::Linear;
    }
}

fn unreadable(path: &Path, reason: impl std::fmt::Display) -> Error {
    Error {
        kind: ErrorKind::Input,
        location: None,
        message: format!("could not read the image \"{}\": {reason}", path.display()),
        help: Some(
            "check that the file is a valid PNG, JPEG, OpenEXR or Radiance HDR image".into(),
        ),
    }
}

/// Reads an image file. Errors (missing, corrupt, absurdly large, non-finite values) carry no
/// location: the caller adds the scene element's with [`Error::at`].
pub fn read_bitmap(path: &Path) -> Result<Bitmap> {
    let reader = ImageReader::open(path)
        .map_err(|e| Error::io(path, &e, "open the image"))?
        .with_guessed_format()
        .map_err(|e| unreadable(path, e))?;
    let mut decoder = reader.into_decoder().map_err(|e| unreadable(path, e))?;
    let (width, height) = decoder.dimensions();
    if u64::from(width) * u64::from(height) > MAX_PIXELS || width == 0 || height == 0 {
        return Err(unreadable(
            path,
            format!(
                "{width} × {height} pixels is outside the supported size (1 to {MAX_PIXELS} pixels)"
            ),
        ));
    }
    let mut limits = Limits::default();
    limits.max_alloc = Some(MAX_PIXELS * 16);
    decoder
        .set_limits(limits)
        .map_err(|e| unreadable(path, e))?;
    let image = DynamicImage::from_decoder(decoder).map_err(|e| unreadable(path, e))?;
    let encoding = match image {
        DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_) => Encoding::Linear,
        _ => Encoding::Srgb,
    };
    let (channels, data): (usize, Vec<f32>) = match image.color().channel_count() {
        1 => (1, image.to_luma32f().into_raw()),
        3 => (3, image.to_rgb32f().into_raw()),
        _ => (4, image.to_rgba32f().into_raw()),
    };
    if let Some(index) = data.iter().position(|v| !v.is_finite()) {
        let pixel = index / channels;
        return Err(unreadable(
            path,
            format!(
                "pixel ({}, {}) holds a value that is not a finite number",
                pixel % width as usize,
                pixel / width as usize
            ),
        ));
    }
    Ok(Bitmap {
        width: width as usize,
        height: height as usize,
        channels,
        data,
        encoding,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::{ChannelImage, write_exr, write_png_srgb};

    fn temp(name: &str) -> std::path::PathBuf {
        std::env::temp_dir().join(format!("prism-image-file-{}-{name}", std::process::id()))
    }

    #[test]
    fn png_is_read_as_srgb_and_linearised() {
        let path = temp("a.png");
        write_png_srgb(&path, 2, 1, &[0.0, 0.5, 1.0, 0.2, 0.2, 0.2]).unwrap();
        let mut bitmap = read_bitmap(&path).unwrap();
        assert_eq!(
            (bitmap.width, bitmap.height, bitmap.encoding),
            (2, 1, Encoding::Srgb)
        );
        assert_eq!(bitmap.channels, 3);
        bitmap.linearize();
        // 8-bit quantisation: within about half a code value of the original after decoding.
        for (value, expected) in bitmap.data.iter().zip([0.0, 0.5, 1.0, 0.2, 0.2, 0.2]) {
            assert!((value - expected).abs() < 0.005, "{value} vs {expected}");
        }
        std::fs::remove_file(&path).ok();
    }

    #[test]
    fn exr_is_read_linear_and_nan_is_refused() {
        let path = temp("b.exr");
        let image = |r: f32| ChannelImage {
            width: 1,
            height: 1,
            channels: vec![
                ("R".into(), vec![r]),
                ("G".into(), vec![2.0]),
                ("B".into(), vec![3.0]),
            ],
        };
        write_exr(&path, &image(1.5)).unwrap();
        let bitmap = read_bitmap(&path).unwrap();
        assert_eq!(bitmap.encoding, Encoding::Linear);
        assert_eq!(&bitmap.data[..3], &[1.5, 2.0, 3.0]);
        write_exr(&path, &image(f32::NAN)).unwrap();
        let error = read_bitmap(&path).unwrap_err();
        assert!(error.message.contains("not a finite number"), "{error}");
        std::fs::remove_file(&path).ok();
    }

    #[test]
    fn corrupt_and_missing_files_are_errors() {
        let path = temp("c.png");
        std::fs::write(&path, b"\x89PNG\r\n\x1a\nnot really").unwrap();
        let error = read_bitmap(&path).unwrap_err();
        assert!(error.message.contains("c.png"), "{error}");
        std::fs::remove_file(&path).ok();
        assert!(read_bitmap(&temp("missing.png")).is_err());
    }
}
