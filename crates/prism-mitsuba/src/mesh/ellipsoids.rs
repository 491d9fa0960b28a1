//! The PLY file of Mitsuba 3's `ellipsoids` shape (`EllipsoidsData` in
//! `src/shapes/ellipsoids.h`), the layout 3D Gaussian splatting writes: one element (the first
//! of the file, whatever its name), each record `x y z nx ny nz`, extra properties, then
//! `scale_0 scale_1 scale_2 rot_0 rot_1 rot_2 rot_3`, every property a 32-bit float, in ASCII or
//! binary of either byte order.
//!
//! As Mitsuba reads it: the scales are stored as logarithms (scale = max(exp(value), 10⁻⁶)),
//! the rotation as the quaternion (w, x, y, z) = (`rot_0`, `rot_1`, `rot_2`, `rot_3`). A file
//! whose seventh property is `f_dc_0` and whose eighth from the end is `opacity` is a Gaussian
//! splatting file, whose opacities are stored as logits (opacity = sigmoid(value), clamped to
//! [10⁻⁸, 1 − 10⁻⁸]); in another file a property named `opacities` gives them as they are.
//! The normals and the other properties are read past.
//!
//! Errors name the file and, in ASCII, the line and column; in binary, the record. The header's
//! count is checked against the file's size before anything is allocated.

use std::path::Path;

use glam::{Vec3, Vec4};

use super::file_error;
use crate::file_cache;
use prism_core::error::{Error, Result, SourceLocation};

/// The properties that must open each record, in order.
const LEADING: [&str; 6] = ["x", "y", "z", "nx", "ny", "nz"];
/// The properties that must close each record, in order.
const TRAILING: [&str; 7] = [
    "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3",
];

/// The ellipsoids of a file, in object space, before the shape's transform and extent.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EllipsoidsData {
    pub centers: Vec<Vec3>,
    /// The scales, exp(value) clamped below at 10⁻⁶.
    pub scales: Vec<Vec3>,
    /// The quaternions (x, y, z, w) as stored, not normalised (never zero).
    pub quaternions: Vec<Vec4>,
    /// One opacity per ellipsoid, where the file gives them.
    pub opacities: Option<Vec<f32>>,
}

/// Reads an ellipsoids PLY file (see the module's documentation), through the file cache.
pub fn load_ellipsoids(path: &Path) -> Result<EllipsoidsData> {
    file_cache::parsed(path, "ellipsoids", || {
        let bytes =
            file_cache::read(path).map_err(|e| Error::io(path, &e, "read the ellipsoids"))?;
        parse_ellipsoids(&bytes, path)
    })
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Format {
    Ascii,
    BinaryLittleEndian,
    BinaryBigEndian,
}

/// The header: the format, the first element's record count and property names, where the
/// body starts and on which line.
struct Header {
    format: Format,
    count: u64,
    /// 1-based line of the first element's `element` line.
    element_line: usize,
    properties: Vec<String>,
    body_start: usize,
    end_line: usize,
}

fn line_error(path: &Path, line: usize, column: usize, message: impl Into<String>) -> Error {
    let line = u32::try_from(line).unwrap_or(u32::MAX);
    let column = u32::try_from(column).unwrap_or(u32::MAX);
    Error::input(&SourceLocation::new(path, line, column), message)
}

fn parse_header(bytes: &[u8], path: &Path) -> Result<Header> {
    let mut offset = 0;
    let mut number = 0;
    let mut format = None;
    let mut first: Option<(u64, usize)> = None;
    let mut in_first = false;
    let mut properties = Vec::new();
    loop {
        let rest = &bytes[offset..];
        if rest.is_empty() {
            return Err(line_error(
                path,
                number.max(1),
                1,
                "the header ends without an \"end_header\" line",
            ));
        }
        let length = rest
            .iter()
            .position(|&b| b == b'\n')
            .map_or(rest.len(), |i| i + 1);
        let line = String::from_utf8_lossy(&rest[..length]);
        offset += length;
        number += 1;
        let error = |message: String| line_error(path, number, 1, message);
        let words: Vec<&str> = line.split_ascii_whitespace().collect();
        if number == 1 {
            if words != ["ply"] {
                return Err(error(
                    "not a PLY file: the first line must be \"ply\"".into(),
                ));
            }
            continue;
        }
        match words.as_slice() {
            ["format", name, "1.0"] => {
                format = Some(match *name {
                    "ascii" => Format::Ascii,
                    "binary_little_endian" => Format::BinaryLittleEndian,
                    "binary_big_endian" => Format::BinaryBigEndian,
                    other => return Err(error(format!("unknown PLY format \"{other}\""))),
                });
            }
            ["comment", ..] | ["obj_info", ..] | [] => {}
            ["element", _, count] => {
                in_first = first.is_none();
                if in_first {
                    let count = count.parse::<u64>().map_err(|_| {
                        error(format!(
                            "the element count \"{count}\" is not a whole number"
                        ))
                    })?;
                    first = Some((count, number));
                }
            }
            ["property", "list", ..] if in_first => {
                return Err(error(
                    "the ellipsoids' element has a list property; Mitsuba reads one record of \
                     32-bit floats per ellipsoid"
                        .into(),
                ));
            }
            ["property", ty, name] if in_first => {
                if !matches!(*ty, "float" | "float32") {
                    return Err(error(format!(
                        "the property \"{name}\" is of type {ty}; Mitsuba reads the ellipsoids' \
                         properties as 32-bit floats"
                    )));
                }
                properties.push(name.to_string());
            }
            ["property", ..] => {}
            ["end_header"] => break,
            _ => return Err(error(format!("unexpected header line \"{}\"", line.trim()))),
        }
    }
    let format = format.ok_or_else(|| line_error(path, 2, 1, "the header has no format line"))?;
    let (count, element_line) =
        first.ok_or_else(|| line_error(path, number, 1, "the header declares no element"))?;
    let named = |names: &[&str], from: usize| {
        names
            .iter()
            .enumerate()
            .all(|(i, name)| properties.get(from + i).is_some_and(|p| p == name))
    };
    let least = LEADING.len() + TRAILING.len();
    if properties.len() < least
        || !named(&LEADING, 0)
        || !named(&TRAILING, properties.len() - TRAILING.len())
    {
        return Err(line_error(
            path,
            element_line,
            1,
            format!(
                "the ellipsoids' element must have the properties {} first and {} last \
                 (Mitsuba's layout); it has {}",
                LEADING.join(" "),
                TRAILING.join(" "),
                properties.join(" ")
            ),
        ));
    }
    Ok(Header {
        format,
        count,
        element_line,
        properties,
        body_start: offset,
        end_line: number,
    })
}

/// Reads an ellipsoids PLY file from its bytes.
pub fn parse_ellipsoids(bytes: &[u8], path: &Path) -> Result<EllipsoidsData> {
    let header = parse_header(bytes, path)?;
    let width = header.properties.len();
    // A binary record takes four bytes per property, an ASCII one at least two (a digit and a
    // separator; the last number of the file needs none).
    let body = bytes.len() - header.body_start;
    let (per_number, available) = match header.format {
        Format::Ascii => (2, body as u64 + 1),
        _ => (4, body as u64),
    };
    let needed = header.count.saturating_mul(width as u64 * per_number);
    if needed > available {
        return Err(line_error(
            path,
            header.element_line,
            1,
            format!(
                "the header declares {} ellipsoids of {width} properties, but the file is too \
                 short to hold them: they need at least {needed} bytes, and {available} follow \
                 the header",
                header.count
            ),
        ));
    }
    if header.count == 0 {
        return Err(line_error(
            path,
            header.element_line,
            1,
            "the file declares no ellipsoids",
        ));
    }
    let count = header.count as usize;
    let is_3dg = header.properties[6] == "f_dc_0" && header.properties[width - 8] == "opacity";
    let opacity_index = if is_3dg {
        Some(width - 8)
    } else {
        header.properties[6..width - TRAILING.len()]
            .iter()
            .position(|p| p == "opacities")
            .map(|i| i + 6)
    };
    let mut data = EllipsoidsData {
        centers: Vec::with_capacity(count),
        scales: Vec::with_capacity(count),
        quaternions: Vec::with_capacity(count),
        opacities: opacity_index.map(|_| Vec::with_capacity(count)),
    };
    let mut reader = Reader::new(bytes, &header, path);
    let mut record = vec![0.0f32; width];
    let mut positions = vec![(0, 0); width];
    for index in 0..count {
        for (i, value) in record.iter_mut().enumerate() {
            *value = reader.next(&header.properties[i])?;
            positions[i] = reader.last;
        }
        let at = |i: usize| record[i];
        let error = |i: usize, message: &str| reader.error_at(positions[i], index, message);
        let check = |range: std::ops::Range<usize>, what: &str| match range
            .clone()
            .find(|&i| !at(i).is_finite())
        {
            Some(i) => Err(error(i, &format!("its {what} is not finite"))),
            None => Ok(()),
        };
        check(0..3, "centre")?;
        let scale_at = width - 7;
        check(scale_at..scale_at + 3, "scale")?;
        check(scale_at + 3..width, "quaternion")?;
        let quaternion = Vec4::new(at(width - 3), at(width - 2), at(width - 1), at(width - 4));
        if quaternion == Vec4::ZERO {
            return Err(error(width - 1, "its quaternion is zero"));
        }
        data.centers.push(Vec3::new(at(0), at(1), at(2)));
        data.scales.push(
            Vec3::new(at(scale_at), at(scale_at + 1), at(scale_at + 2))
                .exp()
                .max(Vec3::splat(1e-6)),
        );
        data.quaternions.push(quaternion);
        if let (Some(i), Some(opacities)) = (opacity_index, data.opacities.as_mut()) {
            let value = at(i);
            if value.is_nan() {
                return Err(error(i, "its opacity is not a number"));
            }
            opacities.push(if is_3dg {
                (1.0 / (1.0 + (-value).exp())).clamp(1e-8, 1.0 - 1e-8)
            } else {
                value
            });
        }
    }
    Ok(data)
}

/// The body's numbers, one at a time.
struct Reader<'a> {
    bytes: &'a [u8],
    offset: usize,
    format: Format,
    path: &'a Path,
    /// The ASCII body's current line (1-based in the file) and where it starts.
    line: usize,
    line_start: usize,
    /// The position of the number read last, for errors: its line and column in ASCII.
    last: (usize, usize),
}

impl<'a> Reader<'a> {
    fn new(bytes: &'a [u8], header: &Header, path: &'a Path) -> Reader<'a> {
        Reader {
            bytes,
            offset: header.body_start,
            format: header.format,
            path,
            line: header.end_line + 1,
            line_start: header.body_start,
            last: (header.end_line + 1, 1),
        }
    }

    /// The next number, the property `name`.
    fn next(&mut self, name: &str) -> Result<f32> {
        match self.format {
            Format::Ascii => self.next_ascii(name),
            format => {
                let end = self.offset + 4;
                let word: [u8; 4] = self
                    .bytes
                    .get(self.offset..end)
                    .and_then(|b| b.try_into().ok())
                    .ok_or_else(|| {
                        file_error(self.path, "the file ends before the last ellipsoid")
                    })?;
                self.offset = end;
                Ok(match format {
                    Format::BinaryBigEndian => f32::from_be_bytes(word),
                    _ => f32::from_le_bytes(word),
                })
            }
        }
    }

    fn next_ascii(&mut self, name: &str) -> Result<f32> {
        while let Some(&b) = self.bytes.get(self.offset) {
            if b == b'\n' {
                self.line += 1;
                self.line_start = self.offset + 1;
            } else if !b.is_ascii_whitespace() {
                break;
            }
            self.offset += 1;
        }
        let start = self.offset;
        while self
            .bytes
            .get(self.offset)
            .is_some_and(|b| !b.is_ascii_whitespace())
        {
            self.offset += 1;
        }
        self.last = (self.line, start - self.line_start + 1);
        let (line, column) = self.last;
        if start == self.offset {
            return Err(line_error(
                self.path,
                line,
                column,
                "the file ends before the last ellipsoid",
            ));
        }
        let word = String::from_utf8_lossy(&self.bytes[start..self.offset]);
        word.parse::<f32>().map_err(|_| {
            line_error(
                self.path,
                line,
                column,
                format!("\"{word}\" is not a number (property \"{name}\")"),
            )
        })
    }

    /// An error about ellipsoid `index`, at the number read at `position` in ASCII.
    fn error_at(&self, position: (usize, usize), index: usize, message: &str) -> Error {
        let message = format!("ellipsoid {index}: {message}");
        match self.format {
            Format::Ascii => line_error(self.path, position.0, position.1, message),
            _ => file_error(self.path, message),
        }
    }
}
