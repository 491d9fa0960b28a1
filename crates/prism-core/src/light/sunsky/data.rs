//! The Hosek–Wilkie tables Mitsuba 3 ships for its `sunsky` emitter, and the "tensor file"
//! format they are stored in.
//!
//! The two files are Mitsuba 3.9.1's `data/sunsky/sunsky_datasets.bin` and
//! `data/sunsky/sampling_data.bin`, copied unchanged into `assets/sunsky/` (with the licence of
//! Hosek and Wilkie's data, BSD-3) and embedded in the binary, so a scene renders without any
//! file outside the repository.
//!
//! # The tensor file format (little-endian)
//! ```text
//! "tensor_file\0"   12 bytes of magic
//! u16               version (1)
//! u32               number of fields
//! per field:        u16 name length, the name (UTF-8), u16 number of dimensions,
//!                   u8 element type (1 = u8, 10 = f32, 11 = f64), u64 byte offset of the values
//!                   from the start of the file, one u64 per dimension (the shape)
//! ```
//! The values of a field are stored contiguously, row-major (last dimension fastest). Every
//! size is checked against the file's length before anything is allocated.

/// One field of a tensor file: its shape and values (widened to f64).
#[derive(Clone, Debug, PartialEq)]
pub struct TensorField {
    pub name: String,
    pub shape: Vec<usize>,
    pub values: Vec<f64>,
}

const MAGIC: &[u8; 12] = b"tensor_file\0";
const ELEMENT_U8: u8 = 1;
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
            ELEMENT_F32 => 4,
            ELEMENT_F64 => 8,
            other => {
                return Err(format!(
                    "field \"{name}\" has element type {other}; only 1 (u8), 10 (f32) and 11 (f64) are read"
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
        if let Some(position) = values.iter().position(|v| !v.is_finite()) {
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

/// Number of spectral bands of the model: 320, 360, …, 720 nm.
pub const BANDS: usize = 11;
/// The first band's wavelength and the spacing, in nm.
pub const FIRST_BAND: f32 = 320.0;
pub const BAND_STEP: f32 = 40.0;
/// Turbidity levels 1, 2, …, 10 and the two ground albedos 0 and 1.
pub const TURBIDITIES: usize = 10;
pub const ALBEDOS: usize = 2;
/// Control points of the quintic Bézier curve over the sun's elevation.
pub const SKY_CONTROL_POINTS: usize = 6;
/// The nine coefficients A … I of the sky model.
pub const SKY_PARAMS: usize = 9;
/// The solar radiance function: a cubic polynomial in the elevation on each of 45 segments.
pub const SUN_SEGMENTS: usize = 45;
pub const SUN_CONTROL_POINTS: usize = 4;
/// Coefficients of the limb-darkening polynomial.
pub const SUN_LD_PARAMS: usize = 6;
/// Sun elevations of the irradiance tables: 2°, 5°, …, 89°.
pub const IRRADIANCE_ELEVATIONS: usize = 30;

/// The tables the emitter uses, each row-major with the shape given.
#[derive(Clone, Debug)]
pub struct SunskyTables {
    /// Sky coefficients (turbidity, albedo, control point, band, parameter).
    pub sky_params: Vec<f64>,
    /// Sky mean radiance (turbidity, albedo, control point, band).
    pub sky_radiance: Vec<f64>,
    /// Solar radiance polynomials (turbidity, segment, band, power).
    pub sun_radiance: Vec<f64>,
    /// Limb darkening (band, power).
    pub sun_limb_darkening: Vec<f64>,
    /// Solar irradiance (turbidity, elevation, band).
    pub sun_irradiance: Vec<f64>,
}

/// The embedded copies of Mitsuba 3.9.1's files.
pub const DATASETS: &[u8] = include_bytes!("../../../../../assets/sunsky/sunsky_datasets.bin");
pub const SAMPLING_DATA: &[u8] = include_bytes!("../../../../../assets/sunsky/sampling_data.bin");

/// The field `name` of `fields`, which must have `shape`.
fn field(fields: &mut Vec<TensorField>, name: &str, shape: &[usize]) -> Result<Vec<f64>, String> {
    let index = fields
        .iter()
        .position(|f| f.name == name)
        .ok_or_else(|| format!("the dataset has no field \"{name}\""))?;
    let field = fields.swap_remove(index);
    if field.shape != shape {
        return Err(format!(
            "field \"{name}\" has shape {:?}, not {shape:?}",
            field.shape
        ));
    }
    Ok(field.values)
}

impl SunskyTables {
    /// The tables of a datasets file and a sampling-data file (Mitsuba's two files).
    pub fn parse(datasets: &[u8], sampling: &[u8]) -> Result<SunskyTables, String> {
        let mut data = parse_tensor_file(datasets).map_err(|e| format!("sunsky datasets: {e}"))?;
        let mut samp =
            parse_tensor_file(sampling).map_err(|e| format!("sunsky sampling data: {e}"))?;
        let tables = SunskyTables {
            sky_params: field(
                &mut data,
                "sky_params_spec",
                &[TURBIDITIES, ALBEDOS, SKY_CONTROL_POINTS, BANDS, SKY_PARAMS],
            )?,
            sky_radiance: field(
                &mut data,
                "sky_rad_spec",
                &[TURBIDITIES, ALBEDOS, SKY_CONTROL_POINTS, BANDS],
            )?,
            sun_radiance: field(
                &mut data,
                "sun_rad_spec",
                &[TURBIDITIES, SUN_SEGMENTS, BANDS, SUN_CONTROL_POINTS],
            )?,
            sun_limb_darkening: field(&mut data, "sun_ld_spec", &[BANDS, SUN_LD_PARAMS])?,
            sun_irradiance: field(
                &mut samp,
                "sun_irradiance",
                &[TURBIDITIES, IRRADIANCE_ELEVATIONS, BANDS],
            )?,
        };
        Ok(tables)
    }

    /// The tables of the embedded files, parsed once.
    pub fn embedded() -> &'static SunskyTables {
        static TABLES: std::sync::OnceLock<SunskyTables> = std::sync::OnceLock::new();
        TABLES.get_or_init(|| {
            SunskyTables::parse(DATASETS, SAMPLING_DATA)
                .expect("the embedded sunsky tables parse (tested)")
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn embedded_files_parse_with_the_expected_fields() {
        let fields = parse_tensor_file(DATASETS).unwrap();
        let names: Vec<&str> = fields.iter().map(|f| f.name.as_str()).collect();
        assert!(names.contains(&"sky_params_spec") && names.contains(&"sun_ld_spec"));
        let tables = SunskyTables::parse(DATASETS, SAMPLING_DATA).unwrap();
        assert_eq!(tables.sky_params.len(), 10 * 2 * 6 * 11 * 9);
        assert_eq!(tables.sun_irradiance.len(), 10 * 30 * 11);
    }

    /// Every truncation of the embedded files, and a sample of corruptions, is an error and
    /// never a panic.
    #[test]
    fn truncated_and_corrupt_files_are_errors() {
        for cut in [
            0,
            5,
            12,
            13,
            17,
            30,
            100,
            426,
            427,
            1000,
            DATASETS.len() - 1,
        ] {
            let error = SunskyTables::parse(&DATASETS[..cut], SAMPLING_DATA).unwrap_err();
            assert!(
                error.contains("truncated") || error.contains("not a Mitsuba tensor file"),
                "cut at {cut}: {error}"
            );
        }
        for cut in 0..SAMPLING_DATA.len().min(400) {
            assert!(SunskyTables::parse(DATASETS, &SAMPLING_DATA[..cut]).is_err());
        }
        let mut corrupt = DATASETS.to_vec();
        corrupt[14..18].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(parse_tensor_file(&corrupt).unwrap_err().contains("fields"));
        // Each byte of the header set to 0xff in turn: an error or a parse, never a panic.
        for at in 0..427 {
            let mut bytes = DATASETS.to_vec();
            bytes[at] = 0xff;
            let _ = SunskyTables::parse(&bytes, SAMPLING_DATA);
        }
        let mut wrong_type = SAMPLING_DATA.to_vec();
        // The first field's element type follows its name ("sun_irradiance", 14 bytes) and
        // dimension count.
        let type_at = 12 + 2 + 4 + 2 + 14 + 2;
        assert_eq!(wrong_type[type_at], ELEMENT_F32);
        wrong_type[type_at] = 3;
        assert!(
            parse_tensor_file(&wrong_type)
                .unwrap_err()
                .contains("element type 3")
        );
    }
}
