//! Mitsuba's "tensor file": named, typed arrays in one file, the format of Mitsuba 3's
//! sun-and-sky tables and of the RGL material database's measured BSDFs.
//!
//! # The format (little-endian)
//! ```text
//! "tensor_file\0"   12 bytes of magic
//! u16               version (1)
//! u32               number of fields
//! per field:        u16 name length, the name (UTF-8), u16 number of dimensions,
//!                   u8 element type (1 = u8, 3 = u16, 10 = f32, 11 = f64), u64 byte offset of the values
//!                   from the start of the file, one u64 per dimension (the shape)
//! ```
//! The values of a field are stored contiguously, row-major (last dimension fastest). Every
//! size is checked against the file's length before anything is allocated. Non-finite values
//! are refused, except by [`parse_tensor_file_with_nans`] for tables that mark missing
//! measurements with NaN.

/// One field of a tensor file: its shape and values (widened to f64).
#[derive(Clone, Debug, PartialEq)]
pub struct TensorField {
    pub name: String,
    pub shape: Vec<usize>,
    pub values: Vec<f64>,
}

const MAGIC: &[u8; 12] = b"tensor_file\0";
const ELEMENT_U8: u8 = 1;
const ELEMENT_U16: u8 = 3;
const ELEMENT_F32: u8 = 10;
const ELEMENT_F64: u8 = 11;
/// More dimensions than any table here has; a bound so that a corrupt count cannot make the
/// reader walk a huge header.
const MAX_DIMENSIONS: usize = 16;

/// A cursor over the header that reports truncation instead of panicking.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], String> {
        let end = self
            .at
            .checked_add(n)
            .filter(|&end| end <= self.bytes.len());
        let Some(end) = end else {
            return Err(format!(
                "the file is truncated: {what} at byte {} runs past its end ({} bytes)",
                self.at,
                self.bytes.len()
            ));
        };
        let slice = &self.bytes[self.at..end];
        self.at = end;
        Ok(slice)
    }

    fn u8(&mut self, what: &str) -> Result<u8, String> {
        Ok(self.take(1, what)?[0])
    }

    fn u16(&mut self, what: &str) -> Result<u16, String> {
        let b = self.take(2, what)?;
        Ok(u16::from_le_bytes([b[0], b[1]]))
    }

    fn u32(&mut self, what: &str) -> Result<u32, String> {
        let b = self.take(4, what)?;
        Ok(u32::from_le_bytes(b.try_into().expect("4 bytes")))
    }

    fn u64(&mut self, what: &str) -> Result<u64, String> {
        let b = self.take(8, what)?;
        Ok(u64::from_le_bytes(b.try_into().expect("8 bytes")))
    }
}

/// Reads every field of a tensor file; the error says what is wrong and where.
pub fn parse_tensor_file(bytes: &[u8]) -> Result<Vec<TensorField>, String> {
    parse(bytes, false)
}

/// [`parse_tensor_file`] for a file whose values may be NaN (missing measurements); infinite
/// values are still refused.
pub fn parse_tensor_file_with_nans(bytes: &[u8]) -> Result<Vec<TensorField>, String> {
    parse(bytes, true)
}

fn parse(bytes: &[u8], nans: bool) -> Result<Vec<TensorField>, String> {
    if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
        return Err("not a Mitsuba tensor file (it does not start with \"tensor_file\")".into());
    }
    let mut reader = Reader {
        bytes,
        at: MAGIC.len(),
    };
    let version = reader.u16("the version")?;
    if version != 1 {
        return Err(format!(
            "unsupported tensor file version {version} (Mitsuba 3 writes version 1)"
        ));
    }
    let count = reader.u32("the number of fields")? as usize;
    // Each field header takes at least 13 bytes: a corrupt count fails here, not in an
    // allocation.
    if count > bytes.len() / 13 {
        return Err(format!(
            "the file is truncated or corrupt: its header declares {count} fields, more \
             than {} bytes can hold",
            bytes.len()
        ));
    }
    let mut fields = Vec::with_capacity(count);
    for index in 0..count {
        let field = |what: &str| format!("{what} of field {index}");
        let name_length = reader.u16(&field("the name length"))? as usize;
        let name = std::str::from_utf8(reader.take(name_length, &field("the name"))?)
            .map_err(|_| format!("the name of field {index} is not UTF-8"))?
            .to_string();
        let dimensions = reader.u16(&format!("the dimension count of \"{name}\""))? as usize;
        if dimensions > MAX_DIMENSIONS {
            return Err(format!(
                "field \"{name}\" declares {dimensions} dimensions (at most {MAX_DIMENSIONS} are read)"
            ));
        }
        let element = reader.u8(&format!("the element type of \"{name}\""))?;
        let element_size = match element {
            ELEMENT_U8 => 1,
            ELEMENT_U16 => 2,
            ELEMENT_F32 => 4,
            ELEMENT_F64 => 8,
            other => {
                return Err(format!(
                    "field \"{name}\" has element type {other}; only 1 (u8), 3 (u16), 10 (f32) and 11 (f64) are read"
                ));
            }
        };
        let offset = reader.u64(&format!("the offset of \"{name}\""))?;
        let mut shape = Vec::with_capacity(dimensions);
        for _ in 0..dimensions {
            let size = reader.u64(&format!("the shape of \"{name}\""))?;
            shape.push(
                usize::try_from(size).map_err(|_| {
                    format!("field \"{name}\" has a dimension of {size}, too large")
                })?,
            );
        }
        let length = shape.iter().try_fold(1usize, |n, &d| n.checked_mul(d));
        let start = usize::try_from(offset).ok();
        let end = length
            .and_then(|n| n.checked_mul(element_size))
            .zip(start)
            .and_then(|(size, start)| start.checked_add(size));
        let (Some(length), Some(start), Some(end)) = (length, start, end) else {
            return Err(format!(
                "field \"{name}\" of shape {shape:?} at offset {offset} does not fit in any file"
            ));
        };
        if end > bytes.len() {
            return Err(format!(
                "the file is truncated: field \"{name}\" of shape {shape:?} needs bytes \
                 {start}..{end}, but the file has {} bytes",
                bytes.len()
            ));
        }
        let raw = &bytes[start..end];
        let values: Vec<f64> = if element == ELEMENT_U8 {
            raw.iter().map(|&b| f64::from(b)).collect()
        } else if element == ELEMENT_U16 {
            raw.chunks_exact(2)
                .map(|c| f64::from(u16::from_le_bytes([c[0], c[1]])))
                .collect()
        } else if element == ELEMENT_F32 {
            raw.chunks_exact(4)
                .map(|c| f64::from(f32::from_le_bytes(c.try_into().expect("4 bytes"))))
                .collect()
        } else {
            raw.chunks_exact(8)
                .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
                .collect()
        };
        debug_assert_eq!(values.len(), length);
        let refused = |v: &f64| !(v.is_finite() || nans && v.is_nan());
        if let Some(position) = values.iter().position(refused) {
            return Err(format!(
                "field \"{name}\" holds a non-finite value at index {position}"
            ));
        }
        fields.push(TensorField {
            name,
            shape,
            values,
        });
    }
    Ok(fields)
}
