//! Images that scenes reference (bitmap textures, environment maps), in the formats Mitsuba 3's
//! `Bitmap` reads: PNG, JPEG, OpenEXR, Radiance HDR, BMP, TGA and PPM/PGM decoded with the
//! `image` crate, PFM with [`super::pfm`], all into floating-point pixels. As in Mitsuba, 8- and
//! 16-bit formats are sRGB-encoded and the floating-point ones (OpenEXR, HDR, PFM) linear.

use std::io::Cursor;
use std::path::Path;

use image::{DynamicImage, ImageDecoder, ImageError, ImageFormat, ImageReader, Limits};

use super::{pfm, srgb};
use crate::error::{Error, ErrorKind, Result};

/// Largest image accepted, in pixels; larger declared sizes are refused before decoding.
pub const MAX_PIXELS: u64 = 1 << 28;

/// How the stored values relate to light.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    /// Linear values (OpenEXR, Radiance HDR, PFM).
    Linear,
    /// Values in [0, 1] with the sRGB transfer curve applied (8- and 16-bit PNG, JPEG, BMP, TGA,
    /// PPM/PGM).
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

/// The file formats a scene's images may have: those Mitsuba 3's `Bitmap` reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileFormat {
    Png,
    Jpeg,
    OpenExr,
    /// Radiance RGBE (`.hdr`, `.rgbe`, `.pic`): linear.
    RadianceHdr,
    /// Windows bitmap: 8-bit sRGB.
    Bmp,
    /// Truevision Targa: 8-bit sRGB.
    Tga,
    /// Netpbm PBM, PGM, PPM and PAM: 8- or 16-bit sRGB.
    Pnm,
    /// Portable Float Map: linear 32-bit floats (see [`super::pfm`]).
    Pfm,
}

impl FileFormat {
    /// The format of a file from its first bytes, or else (for Targa, which has no signature)
    /// from its extension. The error says why neither gives a supported format.
    pub fn detect(bytes: &[u8], path: &Path) -> std::result::Result<FileFormat, String> {
        if pfm::is_pfm(bytes) {
            return Ok(FileFormat::Pfm);
        }
        let unsupported = |format: ImageFormat| {
            format!("the image format {format:?} is not supported (only {SUPPORTED})")
        };
        if let Ok(format) = image::guess_format(bytes) {
            return Self::from_image_format(format).ok_or_else(|| unsupported(format));
        }
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .unwrap_or_default();
        if extension == "pfm" {
            return Ok(FileFormat::Pfm);
        }
        match ImageFormat::from_extension(&extension) {
            Some(format) => Self::from_image_format(format).ok_or_else(|| unsupported(format)),
            None => Err(format!(
                "its format is recognised neither from its first bytes nor from its \
                 extension \"{extension}\""
            )),
        }
    }

    fn from_image_format(format: ImageFormat) -> Option<FileFormat> {
        Some(match format {
            ImageFormat::Png => FileFormat::Png,
            ImageFormat::Jpeg => FileFormat::Jpeg,
            ImageFormat::OpenExr => FileFormat::OpenExr,
            ImageFormat::Hdr => FileFormat::RadianceHdr,
            ImageFormat::Bmp => FileFormat::Bmp,
            ImageFormat::Tga => FileFormat::Tga,
            ImageFormat::Pnm => FileFormat::Pnm,
            _ => return None,
        })
    }

    fn image_format(self) -> Option<ImageFormat> {
        Some(match self {
            FileFormat::Png => ImageFormat::Png,
            FileFormat::Jpeg => ImageFormat::Jpeg,
            FileFormat::OpenExr => ImageFormat::OpenExr,
            FileFormat::RadianceHdr => ImageFormat::Hdr,
            FileFormat::Bmp => ImageFormat::Bmp,
            FileFormat::Tga => ImageFormat::Tga,
            FileFormat::Pnm => ImageFormat::Pnm,
            FileFormat::Pfm => return None,
        })
    }
}

const SUPPORTED: &str = "PNG, JPEG, OpenEXR, Radiance HDR, BMP, TGA, PPM/PGM or PFM";

fn unreadable(path: &Path, reason: impl std::fmt::Display) -> Error {
    Error {
        kind: ErrorKind::Input,
        location: None,
        message: format!("could not read the image \"{}\": {reason}", path.display()),
        help: Some(format!(
            "check that the file is a valid {SUPPORTED} image, or convert it to one"
        )),
    }
}

/// Reads an image file of any [`FileFormat`]. Errors (missing, corrupt, absurdly large,
/// non-finite values) name the file and carry no location: the caller adds the scene element's
/// with [`Error::at`].
pub fn read_bitmap(path: &Path) -> Result<Bitmap> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, &e, "open the image"))?;
    decode_bitmap_file(&bytes, path)
}

/// Decodes `bytes`, read from the image file at `path`, with [`read_bitmap`]'s errors.
pub fn decode_bitmap_file(bytes: &[u8], path: &Path) -> Result<Bitmap> {
    let format = FileFormat::detect(bytes, path).map_err(|reason| unreadable(path, reason))?;
    decode_bitmap(bytes, format, MAX_PIXELS).map_err(|reason| unreadable(path, reason))
}

/// Decodes the bytes of an image file of the given format, of at most `max_pixels` pixels
/// ([`MAX_PIXELS`] for a scene's files): the size the header declares is checked before any
/// pixel is allocated. The error says what is wrong, without the file's name.
pub fn decode_bitmap(
    bytes: &[u8],
    format: FileFormat,
    max_pixels: u64,
) -> std::result::Result<Bitmap, String> {
    let Some(image_format) = format.image_format() else {
        let bitmap = pfm::decode_pfm(bytes, max_pixels)?;
        check_finite(&bitmap)?;
        return Ok(bitmap);
    };
    let mut decoder = ImageReader::with_format(Cursor::new(bytes), image_format)
        .into_decoder()
        .map_err(describe)?;
    let (width, height) = decoder.dimensions();
    if u64::from(width) * u64::from(height) > max_pixels || width == 0 || height == 0 {
        return Err(format!(
            "{width} × {height} pixels is outside the supported size (1 to {max_pixels} pixels)"
        ));
    }
    // At most 4 channels of 32-bit floats per pixel.
    let mut limits = Limits::default();
    limits.max_alloc = Some(max_pixels * 16);
    decoder.set_limits(limits).map_err(describe)?;
    let image = DynamicImage::from_decoder(decoder).map_err(describe)?;
    let encoding = match image {
        DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_) => Encoding::Linear,
        _ => Encoding::Srgb,
    };
    let (channels, data): (usize, Vec<f32>) = match image.color().channel_count() {
        1 => (1, image.to_luma32f().into_raw()),
        3 => (3, image.to_rgb32f().into_raw()),
        _ => (4, image.to_rgba32f().into_raw()),
    };
    let bitmap = Bitmap {
        width: width as usize,
        height: height as usize,
        channels,
        data,
        encoding,
    };
    check_finite(&bitmap)?;
    Ok(bitmap)
}

/// The `image` crate's error in words; running out of bytes means a truncated file.
fn describe(error: ImageError) -> String {
    match error {
        ImageError::IoError(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
            "the file is truncated: it ends before all its pixels".into()
        }
        e => e.to_string(),
    }
}

fn check_finite(bitmap: &Bitmap) -> std::result::Result<(), String> {
    match bitmap.data.iter().position(|v| !v.is_finite()) {
        Some(index) => {
            let pixel = index / bitmap.channels;
            Err(format!(
                "pixel ({}, {}) holds a value that is not a finite number",
                pixel % bitmap.width,
                pixel / bitmap.width
            ))
        }
        None => Ok(()),
    }
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

    /// A 24-bit uncompressed BMP of `width` × `height` RGB texels given top row first; BMP
    /// stores rows bottom first, as BGR, each padded to 4 bytes.
    fn bmp_bytes(width: u32, height: u32, rgb: &[u8]) -> Vec<u8> {
        let row = (3 * width).next_multiple_of(4);
        let size = 54 + row * height;
        let mut bytes = b"BM".to_vec();
        for v in [size, 0, 54, 40, width, height] {
            bytes.extend(v.to_le_bytes());
        }
        bytes.extend(1u16.to_le_bytes());
        bytes.extend(24u16.to_le_bytes());
        for v in [0u32, row * height, 2835, 2835, 0, 0] {
            bytes.extend(v.to_le_bytes());
        }
        for y in (0..height as usize).rev() {
            let start = bytes.len();
            for x in 0..width as usize {
                let p = &rgb[3 * (y * width as usize + x)..][..3];
                bytes.extend([p[2], p[1], p[0]]);
            }
            bytes.resize(start + row as usize, 0);
        }
        bytes
    }

    fn write(name: &str, bytes: &[u8]) -> std::path::PathBuf {
        let path = temp(name);
        std::fs::write(&path, bytes).unwrap();
        path
    }

    /// Reads `bytes` written to a file `name`, checks its size, channels and encoding, and
    /// returns its values as stored (not linearised).
    fn read(name: &str, bytes: &[u8], size: (usize, usize, usize), encoding: Encoding) -> Vec<f32> {
        let path = write(name, bytes);
        let bitmap = read_bitmap(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        std::fs::remove_file(&path).ok();
        assert_eq!(
            (
                bitmap.width,
                bitmap.height,
                bitmap.channels,
                bitmap.encoding
            ),
            (size.0, size.1, size.2, encoding),
            "{name}"
        );
        bitmap.data
    }

    fn codes(values: &[f32]) -> Vec<u8> {
        values.iter().map(|v| (v * 255.0).round() as u8).collect()
    }

    const TEXELS: [u8; 12] = [255, 0, 0, 0, 128, 0, 0, 0, 64, 10, 20, 30];

    #[test]
    fn eight_bit_formats_are_srgb_and_read_top_row_first() {
        let bmp = read(
            "t.bmp",
            &bmp_bytes(2, 2, &TEXELS),
            (2, 2, 3),
            Encoding::Srgb,
        );
        assert_eq!(codes(&bmp), TEXELS);

        // Uncompressed true-colour Targa, top-left origin (descriptor bit 5), BGR.
        let mut tga = vec![0, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 2, 0, 24, 0x20];
        for p in TEXELS.chunks(3) {
            tga.extend([p[2], p[1], p[0]]);
        }
        assert_eq!(
            codes(&read("t.tga", &tga, (2, 2, 3), Encoding::Srgb)),
            TEXELS
        );

        let mut ppm = b"P6\n# a comment\n2 2\n255\n".to_vec();
        ppm.extend(TEXELS);
        assert_eq!(
            codes(&read("t.ppm", &ppm, (2, 2, 3), Encoding::Srgb)),
            TEXELS
        );

        let pgm = b"P5 3 1 255\n\x00\x80\xff";
        assert_eq!(
            codes(&read("t.pgm", pgm, (3, 1, 1), Encoding::Srgb)),
            [0, 128, 255]
        );
    }

    #[test]
    fn float_formats_are_linear() {
        // Radiance RGBE, flat (a scanline narrower than 8 pixels is never run-length encoded):
        // (m / 256) · 2^(e − 128) for mantissas m and exponent e.
        let mut hdr = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n".to_vec();
        hdr.extend([128, 64, 32, 129, 128, 128, 128, 131]);
        let values = read("t.hdr", &hdr, (2, 1, 3), Encoding::Linear);
        assert_eq!(values, [1.0, 0.5, 0.25, 4.0, 4.0, 4.0]);

        let mut pfm = b"Pf\n1 2\n-2\n".to_vec();
        for v in [1.5f32, -3.0] {
            pfm.extend(v.to_le_bytes());
        }
        // Bottom row first, values times |scale|.
        assert_eq!(
            read("t.pfm", &pfm, (1, 2, 1), Encoding::Linear),
            [-6.0, 3.0]
        );
    }

    #[test]
    fn truncated_oversized_and_unknown_files_are_clear_errors() {
        let bmp = bmp_bytes(2, 2, &TEXELS);
        let huge_ppm = b"P6\n100000 100000\n255\n\0\0\0";
        let huge_pfm = b"PF\n100000 100000\n-1\n\0\0\0\0";
        let cases: [(&str, &[u8], &str); 6] = [
            ("truncated.bmp", &bmp[..bmp.len() - 5], "is truncated"),
            ("truncated.ppm", b"P6\n2 2\n255\n\x01\x02", "is truncated"),
            ("huge.ppm", huge_ppm, "outside the supported size"),
            ("huge.pfm", huge_pfm, "outside the supported size"),
            ("t.gif", b"GIF89a\x01\x00\x01\x00", "Gif is not supported"),
            (
                "t.xyz",
                b"\x00\x01\x02\x03",
                "nor from its extension \"xyz\"",
            ),
        ];
        for (name, bytes, expected) in cases {
            let path = write(name, bytes);
            let error = read_bitmap(&path).unwrap_err();
            std::fs::remove_file(&path).ok();
            let text = error.to_string();
            assert!(
                text.contains(name) && text.contains(expected),
                "{name}: {text}"
            );
        }
    }
}
