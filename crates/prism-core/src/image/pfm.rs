//! Portable Float Map (PFM) decoding, as Mitsuba 3's `Bitmap::read_pfm` reads it.
//!
//! The format (Paul Debevec's HDR Shop; see also the Netpbm documentation of PFM) is a text
//! header of three whitespace-separated tokens followed by one whitespace byte and the raw
//! 32-bit floats:
//!
//! ```text
//! PF | Pf              "PF": RGB, 3 floats per pixel; "Pf": grey, 1 float per pixel
//! <width> <height>
//! <scale>              its sign gives the byte order: negative (or zero) little-endian,
//!                      positive big-endian; every value is multiplied by |scale|
//! <floats>             rows from the bottom of the image to its top
//! ```
//!
//! The values are linear. Mitsuba 3 multiplies by |scale| when it is not 1 and flips the rows to
//! top-first; so does this reader. A zero or non-finite scale, which Mitsuba would turn into an
//! all-black or NaN image, is refused here.

use super::bitmap::{Bitmap, Encoding};

/// Whether `bytes` start like a PFM file ("PF" or "Pf" followed by whitespace).
pub fn is_pfm(bytes: &[u8]) -> bool {
    matches!(bytes, [b'P', b'F' | b'f', c, ..] if c.is_ascii_whitespace())
}

/// Decodes a PFM file of at most `max_pixels` pixels. The error says what is wrong, without the
/// file's name (the caller adds it).
pub fn decode_pfm(bytes: &[u8], max_pixels: u64) -> Result<Bitmap, String> {
    if !is_pfm(bytes) {
        return Err("a PFM file must start with \"PF\" (RGB) or \"Pf\" (grey)".into());
    }
    let channels = if bytes[1] == b'F' { 3 } else { 1 };
    let mut cursor = 2;
    let mut token = |what: &str| -> Result<&str, String> {
        while bytes.get(cursor).is_some_and(u8::is_ascii_whitespace) {
            cursor += 1;
        }
        let start = cursor;
        while bytes.get(cursor).is_some_and(|c| !c.is_ascii_whitespace()) {
            cursor += 1;
        }
        if cursor == start || cursor >= bytes.len() {
            return Err(format!("the PFM header ends before its {what}"));
        }
        std::str::from_utf8(&bytes[start..cursor])
            .map_err(|_| format!("the PFM header's {what} is not text"))
    };
    let width = token("width")?;
    let width: u64 = width
        .parse()
        .map_err(|_| format!("the PFM width \"{width}\" is not a whole number"))?;
    let height = token("height")?;
    let height: u64 = height
        .parse()
        .map_err(|_| format!("the PFM height \"{height}\" is not a whole number"))?;
    let scale = token("scale")?;
    let scale: f32 = scale
        .parse()
        .map_err(|_| format!("the PFM scale \"{scale}\" is not a number"))?;
    // One whitespace byte separates the header from the pixels.
    let data_start = cursor + 1;
    if width == 0 || height == 0 || width.saturating_mul(height) > max_pixels {
        return Err(format!(
            "{width} × {height} pixels is outside the supported size (1 to {max_pixels} pixels)"
        ));
    }
    if scale == 0.0 || !scale.is_finite() {
        return Err(format!(
            "the PFM scale {scale} is not a non-zero finite number (its sign gives the byte order)"
        ));
    }
    let (width, height) = (width as usize, height as usize);
    let row_len = width * channels;
    let expected = row_len * height * 4;
    let pixels = &bytes[data_start.min(bytes.len())..];
    if pixels.len() < expected {
        return Err(format!(
            "the file is truncated: {width} × {height} pixels need {expected} bytes of data, \
             it holds {}",
            pixels.len()
        ));
    }
    let little_endian = scale < 0.0;
    let magnitude = scale.abs();
    let mut data = Vec::with_capacity(row_len * height);
    // Rows are stored bottom first; the bitmap holds the top row first.
    for row in pixels[..expected].chunks_exact(row_len * 4).rev() {
        data.extend(row.chunks_exact(4).map(|b| {
            let b = [b[0], b[1], b[2], b[3]];
            let value = if little_endian {
                f32::from_le_bytes(b)
            } else {
                f32::from_be_bytes(b)
            };
            if magnitude == 1.0 {
                value
            } else {
                value * magnitude
            }
        }));
    }
    Ok(Bitmap {
        width,
        height,
        channels,
        data,
        encoding: Encoding::Linear,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pfm(header: &str, values: &[f32], little_endian: bool) -> Vec<u8> {
        let mut bytes = header.as_bytes().to_vec();
        for v in values {
            bytes.extend(if little_endian {
                v.to_le_bytes()
            } else {
                v.to_be_bytes()
            });
        }
        bytes
    }

    #[test]
    fn rows_are_flipped_and_both_byte_orders_read() {
        // Stored bottom row first: (1, 2, 3) (4, 5, 6) is the bottom row.
        let values = [
            1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0, 12.0,
        ];
        for (scale, little) in [("-1", true), ("1.0", false)] {
            let bytes = pfm(&format!("PF\n2 2\n{scale}\n"), &values, little);
            let bitmap = decode_pfm(&bytes, 100).unwrap();
            assert_eq!((bitmap.width, bitmap.height, bitmap.channels), (2, 2, 3));
            assert_eq!(bitmap.encoding, Encoding::Linear);
            assert_eq!(
                bitmap.data,
                [
                    7.0, 8.0, 9.0, 10.0, 11.0, 12.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0
                ]
            );
        }
    }

    #[test]
    fn grey_values_are_scaled_by_the_magnitude_of_scale() {
        let bytes = pfm("Pf 3 1 -0.5\n", &[2.0, 4.0, 8.0], true);
        let bitmap = decode_pfm(&bytes, 100).unwrap();
        assert_eq!(bitmap.channels, 1);
        assert_eq!(bitmap.data, [1.0, 2.0, 4.0]);
    }

    #[test]
    fn bad_headers_and_truncated_data_are_errors() {
        let cases: [(&[u8], &str); 7] = [
            (b"PF\n", "ends before its width"),
            (b"PF\nx 2\n-1\n", "not a whole number"),
            (b"PF\n2 2\nabc\n", "not a number"),
            (b"PF\n2 2\n0\n", "non-zero finite"),
            (b"PF\n0 2\n-1\n", "outside the supported size"),
            (b"PF\n100000 100000\n-1\n", "outside the supported size"),
            (b"PF\n2 2\n-1\n\0\0\0\0", "truncated"),
        ];
        for (bytes, expected) in cases {
            let error = decode_pfm(bytes, 1 << 20).unwrap_err();
            assert!(error.contains(expected), "{error}");
        }
    }
}
