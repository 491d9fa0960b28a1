//! 8-bit PNG (and JPEG) files, for viewing renders.

use std::io::{self, Write};
use std::path::Path;

use super::srgb::encode_u8;
use super::write_atomically;
use crate::error::{Error, Result};

/// Writes linear-sRGB RGB (interleaved r, g, b per pixel, top row first) as an 8-bit sRGB PNG
/// file, [`png_srgb_bytes`] written through [`write_atomically`].
pub fn write_png_srgb(path: &Path, width: usize, height: usize, rgb: &[f32]) -> Result<()> {
    let bytes = png_srgb_bytes(width, height, rgb).map_err(|err| Error::io(path, &err, "write"))?;
    write_atomically(path, |writer| writer.write_all(&bytes))
}

/// Encodes linear-sRGB RGB (interleaved r, g, b per pixel, top row first) as an 8-bit sRGB PNG
/// with an sRGB chunk: each value is clamped to [0, 1], encoded by [`super::srgb::encode`] and
/// rounded to the nearest of 0..=255; NaN is written as 0.
pub fn png_srgb_bytes(width: usize, height: usize, rgb: &[f32]) -> io::Result<Vec<u8>> {
    if rgb.len() != 3 * width * height {
        return Err(io::Error::other(format!(
            "{} values given for {width}x{height} RGB pixels",
            rgb.len()
        )));
    }
    let (Ok(png_width), Ok(png_height)) = (u32::try_from(width), u32::try_from(height)) else {
        return Err(io::Error::other(format!(
            "{width}x{height} is too large for PNG"
        )));
    };
    let pixels: Vec<u8> = rgb.iter().map(|&value| encode_u8(value)).collect();
    png_u8_bytes(png_width, png_height, Channels::Rgb, true, &pixels)
}

/// The channels of an 8-bit image, interleaved per pixel in this order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Channels {
    Luminance,
    LuminanceAlpha,
    Rgb,
    Rgba,
}

impl Channels {
    pub fn count(self) -> usize {
        match self {
            Channels::Luminance => 1,
            Channels::LuminanceAlpha => 2,
            Channels::Rgb => 3,
            Channels::Rgba => 4,
        }
    }
}

/// Writes already encoded 8-bit values (`channels` per pixel, top row first) as a PNG; `srgb`
/// adds the chunk saying they are sRGB-encoded.
pub fn write_png_u8(
    path: &Path,
    width: u32,
    height: u32,
    channels: Channels,
    srgb: bool,
    bytes: &[u8],
) -> Result<()> {
    let png = png_u8_bytes(width, height, channels, srgb, bytes)
        .map_err(|err| Error::io(path, &err, "write"))?;
    write_atomically(path, |writer| writer.write_all(&png))
}

/// Encodes already encoded 8-bit values as the PNG file [`write_png_u8`] writes.
fn png_u8_bytes(
    width: u32,
    height: u32,
    channels: Channels,
    srgb: bool,
    bytes: &[u8],
) -> io::Result<Vec<u8>> {
    if bytes.len() != channels.count() * width as usize * height as usize {
        return Err(io::Error::other(format!(
            "{} bytes given for {width}x{height} pixels",
            bytes.len()
        )));
    }
    let mut png = Vec::new();
    let mut encoder = png::Encoder::new(&mut png, width, height);
    encoder.set_color(match channels {
        Channels::Luminance => png::ColorType::Grayscale,
        Channels::LuminanceAlpha => png::ColorType::GrayscaleAlpha,
        Channels::Rgb => png::ColorType::Rgb,
        Channels::Rgba => png::ColorType::Rgba,
    });
    encoder.set_depth(png::BitDepth::Eight);
    if srgb {
        encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    }
    let mut png_writer = encoder.write_header().map_err(png_to_io)?;
    png_writer.write_image_data(bytes).map_err(png_to_io)?;
    png_writer.finish().map_err(png_to_io)?;
    Ok(png)
}

/// Writes 8-bit luminance or RGB values (top row first) as a baseline JPEG of quality 100.
pub fn write_jpeg_u8(
    path: &Path,
    width: u32,
    height: u32,
    channels: Channels,
    bytes: &[u8],
) -> Result<()> {
    let color = match channels {
        Channels::Luminance => image::ExtendedColorType::L8,
        Channels::Rgb => image::ExtendedColorType::Rgb8,
        other => {
            let message = format!("JPEG has no {other:?} layout");
            return Err(Error::io(path, &io::Error::other(message), "write"));
        }
    };
    if bytes.len() != channels.count() * width as usize * height as usize
        || width > 65535
        || height > 65535
    {
        let message = format!(
            "{} bytes given for {width}x{height} JPEG pixels (at most 65535 on a side)",
            bytes.len()
        );
        return Err(Error::io(path, &io::Error::other(message), "write"));
    }
    write_atomically(path, |writer| {
        image::codecs::jpeg::JpegEncoder::new_with_quality(writer, 100)
            .encode(bytes, width, height, color)
            .map_err(io::Error::other)
    })
}

/// A png error as an I/O error.
fn png_to_io(err: png::EncodingError) -> io::Error {
    match err {
        png::EncodingError::IoError(err) => err,
        other => io::Error::other(other.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use std::fs::{self, File};

    use super::*;
    use crate::image::test_support::scratch_dir;

    #[test]
    fn png_holds_the_expected_srgb_bytes() {
        // Expected bytes from the exact formula in f64.
        let encode = |x: f64| {
            let v = if x <= 0.0031308 {
                12.92 * x
            } else {
                1.055 * x.powf(1.0 / 2.4) - 0.055
            };
            (v * 255.0).round() as u8
        };
        assert_eq!(encode(0.5), 188);
        assert_eq!(encode(0.0031308), 10);
        assert_eq!(encode(0.18), 118);

        let linear = [
            0.0,
            1.0,
            0.5,
            0.0031308,
            0.18,
            0.01,
            -1.0,
            7.0,
            f32::NAN,
            f32::INFINITY,
            0.75,
            0.9,
        ];
        let expected = [
            0,
            255,
            188,
            10,
            118,
            encode(0.01),
            0,
            255,
            0,
            255,
            encode(0.75),
            encode(0.9),
        ];
        let dir = scratch_dir("png");
        let path = dir.join("pixels.png");
        write_png_srgb(&path, 2, 2, &linear).unwrap();

        let decoder = png::Decoder::new(io::BufReader::new(File::open(&path).unwrap()));
        let mut reader = decoder.read_info().unwrap();
        let mut buffer = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buffer).unwrap();
        assert_eq!((info.width, info.height), (2, 2));
        assert_eq!(info.color_type, png::ColorType::Rgb);
        assert_eq!(info.bit_depth, png::BitDepth::Eight);
        assert_eq!(&buffer[..info.buffer_size()], &expected);
        fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn png_write_to_a_missing_directory_is_an_error_naming_the_file() {
        let dir = scratch_dir("png-missing");
        let path = dir.join("no-such-dir").join("out.png");
        let err = write_png_srgb(&path, 1, 1, &[0.0; 3]).unwrap_err();
        assert!(err.to_string().contains("out.png"), "{err}");
        fs::remove_dir_all(dir).unwrap();
    }
}
