//! Mitsuba's serialized meshes, as Mitsuba 3 reads them (`src/shapes/serialized.cpp`; the format
//! is Mitsuba 0.6's, described in Mitsuba 3's plugin documentation of `serialized`).
//!
//! A file holds one or more shapes, one after another, and ends with a table of where each
//! starts. Everything is little-endian:
//! ```text
//! per shape:  u16 0x041C (format id), u16 version (3 or 4), then one zlib stream holding
//!               u32 flags           0x0001 vertex normals, 0x0002 texture coordinates,
//!                                   0x0008 vertex colours, 0x0010 face normals,
//!                                   0x1000 single precision, 0x2000 double precision
//!               name                version 4 only: bytes up to a terminating 0
//!               u64 vertex count, u64 triangle count
//!               positions (x y z per vertex), normals (x y z), texture coordinates (u v),
//!               colours (r g b), each present as the flags say, in f32 or f64 (f64 when the
//!               double-precision flag is set)
//!               triangles: three u32 vertex indices each
//! at the end: the byte offset of each shape's header (u64 in version 4, u32 in version 3),
//!             then u32 the number of shapes
//! ```
//! Shape 0 is read from the start of the file; any other is found through the table (Mitsuba
//! reads the table only then). As in Mitsuba 3, the face-normals flag is ignored (the scene's
//! `face_normals` decides), the name is skipped, and texture coordinates are not flipped.
//!
//! Nothing in the file is trusted: before anything is allocated, the counts are checked against
//! what the rest of the file can hold when decompressed (deflate expands at most
//! [`MAX_DEFLATE_RATIO`]-fold), the table's offsets must point at shape headers inside the file,
//! and a stream that is cut short or corrupt is an error saying so.

use std::path::Path;

use glam::{Vec2, Vec3};
use miniz_oxide::inflate::stream::{InflateState, inflate};
use miniz_oxide::{DataFormat, MZError, MZFlush, MZStatus};

use super::{MeshData, file_error};
use prism_core::error::Result;

/// The first two bytes of every shape.
const FORMAT_ID: u16 = 0x041C;
/// The versions Mitsuba 3 reads; version 4 added the shape's name.
const VERSIONS: [u16; 2] = [3, 4];

const HAS_NORMALS: u32 = 0x0001;
const HAS_TEXCOORDS: u32 = 0x0002;
const HAS_COLORS: u32 = 0x0008;
const DOUBLE_PRECISION: u32 = 0x2000;

/// The greatest factor by which deflate can expand: a 258-byte match coded in two bits
/// (RFC 1951, §3.2.5) gives 1032 output bytes per input byte.
pub const MAX_DEFLATE_RATIO: u64 = 1032;

/// Parses shape `shape_index` of the serialized file in `bytes`; `path` only names the file in
/// messages.
pub fn parse_serialized(bytes: &[u8], shape_index: u32, path: &Path) -> Result<MeshData> {
    let version = read_shape_header(bytes, 0, path)?;
    let start = if shape_index == 0 {
        0
    } else {
        shape_offset(bytes, version, shape_index, path)?
    };
    let mut stream = Inflater::new(&bytes[start + 4..]);
    let corrupt = |error: StreamError| match error {
        StreamError::Ended => file_error(
            path,
            format!(
                "the compressed data of shape {shape_index} (at byte {start}) ends before the \
                 data its header declares"
            ),
        ),
        StreamError::Corrupt => file_error(
            path,
            format!("the compressed data of shape {shape_index} (at byte {start}) is corrupt"),
        ),
    };

    let flags = stream.u32().map_err(corrupt)?;
    if version == 4 {
        while stream.u8().map_err(corrupt)? != 0 {}
    }
    let vertex_count = stream.u64().map_err(corrupt)?;
    let triangle_count = stream.u64().map_err(corrupt)?;

    let value_size: u64 = if flags & DOUBLE_PRECISION != 0 { 8 } else { 4 };
    let has = |flag: u32| flags & flag != 0;
    let values_per_vertex = 3
        + 3 * u64::from(has(HAS_NORMALS))
        + 2 * u64::from(has(HAS_TEXCOORDS))
        + 3 * u64::from(has(HAS_COLORS));
    let declared = u128::from(vertex_count) * u128::from(values_per_vertex * value_size)
        + u128::from(triangle_count) * 12;
    let available = u128::from(stream.remaining_bound());
    if vertex_count > u64::from(u32::MAX) + 1 || declared > available {
        return Err(file_error(
            path,
            format!(
                "shape {shape_index} declares {vertex_count} vertices and {triangle_count} \
                 triangles ({declared} bytes), more than the rest of the file can hold"
            ),
        ));
    }
    // Both counts are now bounded by the file's size, so they fit a usize.
    let vertex_count = vertex_count as usize;
    let triangle_count = triangle_count as usize;

    let double = value_size == 8;
    let read_vec3 = |stream: &mut Inflater, count| {
        stream
            .read_vectors::<3>(count, double)
            .map(|v| v.into_iter().map(Vec3::from).collect::<Vec<_>>())
    };
    let positions = read_vec3(&mut stream, vertex_count).map_err(corrupt)?;
    let normals = if has(HAS_NORMALS) {
        Some(read_vec3(&mut stream, vertex_count).map_err(corrupt)?)
    } else {
        None
    };
    let uvs = if has(HAS_TEXCOORDS) {
        let uvs = stream
            .read_vectors::<2>(vertex_count, double)
            .map_err(corrupt)?;
        Some(uvs.into_iter().map(Vec2::from).collect())
    } else {
        None
    };
    let colors = if has(HAS_COLORS) {
        Some(read_vec3(&mut stream, vertex_count).map_err(corrupt)?)
    } else {
        None
    };
    let mut triangles = Vec::with_capacity(triangle_count);
    for _ in 0..triangle_count {
        let mut triangle = [0u32; 3];
        for index in &mut triangle {
            *index = stream.u32().map_err(corrupt)?;
        }
        triangles.push(triangle);
    }

    let mesh = MeshData {
        positions,
        normals,
        uvs,
        colors,
        face_colors: None,
        attributes: Vec::new(),
        triangles,
    };
    mesh.validate(path)?;
    Ok(mesh)
}

/// Checks the format id and version of the shape header at `offset` and returns the version.
fn read_shape_header(bytes: &[u8], offset: usize, path: &Path) -> Result<u16> {
    let Some(header) = bytes.get(offset..offset + 4) else {
        return Err(file_error(
            path,
            format!("the file ends inside the shape header at byte {offset}"),
        ));
    };
    let id = u16::from_le_bytes([header[0], header[1]]);
    let version = u16::from_le_bytes([header[2], header[3]]);
    if id != FORMAT_ID {
        return Err(file_error(
            path,
            format!(
                "not a Mitsuba serialized mesh: the shape header at byte {offset} starts with \
                 {id:#06x}, not the format id {FORMAT_ID:#06x}"
            ),
        ));
    }
    if !VERSIONS.contains(&version) {
        return Err(file_error(
            path,
            format!(
                "the shape header at byte {offset} has version {version}; Mitsuba's serialized \
                 format has versions 3 and 4"
            ),
        ));
    }
    Ok(version)
}

/// Where shape `shape_index` (> 0) starts, from the table at the end of the file; checks that
/// a shape header of the same version is there.
fn shape_offset(bytes: &[u8], version: u16, shape_index: u32, path: &Path) -> Result<usize> {
    let len = bytes.len();
    let count = match bytes.get(len.saturating_sub(4)..).filter(|_| len >= 8) {
        Some(tail) => u32::from_le_bytes(tail.try_into().expect("four bytes")),
        None => {
            return Err(file_error(
                path,
                "the file is too short to end with a table of shapes",
            ));
        }
    };
    if shape_index >= count {
        return Err(file_error(
            path,
            format!(
                "shape_index {shape_index} is out of range: the file holds {count} shapes \
                 (0..{})",
                i64::from(count) - 1
            ),
        ));
    }
    let entry_size: usize = if version == 4 { 8 } else { 4 };
    let table_start = (len - 4).checked_sub(entry_size * count as usize);
    let Some(table_start) = table_start.filter(|&start| start >= 4) else {
        return Err(file_error(
            path,
            format!(
                "the table at the end of the file declares {count} shapes, more than the file \
                 can hold"
            ),
        ));
    };
    let entry = table_start + entry_size * shape_index as usize;
    let offset = if version == 4 {
        u64::from_le_bytes(bytes[entry..entry + 8].try_into().expect("eight bytes"))
    } else {
        u64::from(u32::from_le_bytes(
            bytes[entry..entry + 4].try_into().expect("four bytes"),
        ))
    };
    match usize::try_from(offset) {
        Ok(offset) if offset + 4 <= table_start => {
            let found = read_shape_header(bytes, offset, path)?;
            if found != version {
                return Err(file_error(
                    path,
                    format!(
                        "shape {shape_index} has version {found}, but the file's first shape \
                         has version {version}"
                    ),
                ));
            }
            Ok(offset)
        }
        _ => Err(file_error(
            path,
            format!(
                "the table at the end of the file puts shape {shape_index} at byte {offset}, \
                 outside the shapes (bytes 0 to {table_start})"
            ),
        )),
    }
}

/// Why the compressed stream could not give the bytes asked for.
#[derive(Clone, Copy, Debug)]
enum StreamError {
    /// The stream (or the file) ended first.
    Ended,
    /// The data is not a valid zlib stream.
    Corrupt,
}

/// A zlib stream read in order, decompressed a buffer at a time.
struct Inflater<'a> {
    state: Box<InflateState>,
    input: &'a [u8],
    consumed: usize,
    buffer: Box<[u8]>,
    start: usize,
    end: usize,
    finished: bool,
}

impl<'a> Inflater<'a> {
    const BUFFER_SIZE: usize = 1 << 16;

    fn new(input: &'a [u8]) -> Self {
        Inflater {
            state: InflateState::new_boxed(DataFormat::Zlib),
            input,
            consumed: 0,
            buffer: vec![0; Self::BUFFER_SIZE].into_boxed_slice(),
            start: 0,
            end: 0,
            finished: false,
        }
    }

    /// The most bytes the stream can still give: those decompressed already and not yet read,
    /// and the rest of the input expanded by deflate's greatest ratio.
    fn remaining_bound(&self) -> u64 {
        let unread_input = (self.input.len() - self.consumed) as u64;
        (self.end - self.start) as u64 + MAX_DEFLATE_RATIO * unread_input
    }

    /// Decompresses the next part of the stream into the (fully read) buffer.
    fn refill(&mut self) -> std::result::Result<(), StreamError> {
        if self.finished {
            return Err(StreamError::Ended);
        }
        let result = inflate(
            &mut self.state,
            &self.input[self.consumed..],
            &mut self.buffer,
            MZFlush::None,
        );
        self.consumed += result.bytes_consumed;
        self.start = 0;
        self.end = result.bytes_written;
        match result.status {
            Ok(MZStatus::StreamEnd) => self.finished = true,
            Ok(_) if result.bytes_written > 0 || result.bytes_consumed > 0 => {}
            Ok(_) | Err(MZError::Buf) => return Err(StreamError::Ended),
            Err(_) => return Err(StreamError::Corrupt),
        }
        if self.end == 0 && self.finished {
            return Err(StreamError::Ended);
        }
        Ok(())
    }

    fn read_exact(&mut self, out: &mut [u8]) -> std::result::Result<(), StreamError> {
        let mut filled = 0;
        while filled < out.len() {
            if self.start == self.end {
                self.refill()?;
            }
            let n = (self.end - self.start).min(out.len() - filled);
            out[filled..filled + n].copy_from_slice(&self.buffer[self.start..self.start + n]);
            self.start += n;
            filled += n;
        }
        Ok(())
    }

    fn u8(&mut self) -> std::result::Result<u8, StreamError> {
        let mut bytes = [0; 1];
        self.read_exact(&mut bytes)?;
        Ok(bytes[0])
    }

    fn u32(&mut self) -> std::result::Result<u32, StreamError> {
        let mut bytes = [0; 4];
        self.read_exact(&mut bytes)?;
        Ok(u32::from_le_bytes(bytes))
    }

    fn u64(&mut self) -> std::result::Result<u64, StreamError> {
        let mut bytes = [0; 8];
        self.read_exact(&mut bytes)?;
        Ok(u64::from_le_bytes(bytes))
    }

    /// `count` vectors of `N` numbers, each f64 (narrowed to f32) when `double`, else f32.
    fn read_vectors<const N: usize>(
        &mut self,
        count: usize,
        double: bool,
    ) -> std::result::Result<Vec<[f32; N]>, StreamError> {
        let mut vectors = Vec::with_capacity(count);
        let mut bytes = [0u8; 8];
        for _ in 0..count {
            let mut vector = [0.0f32; N];
            for value in &mut vector {
                *value = if double {
                    self.read_exact(&mut bytes)?;
                    f64::from_le_bytes(bytes) as f32
                } else {
                    self.read_exact(&mut bytes[..4])?;
                    f32::from_le_bytes(bytes[..4].try_into().expect("four bytes"))
                };
            }
            vectors.push(vector);
        }
        Ok(vectors)
    }
}
