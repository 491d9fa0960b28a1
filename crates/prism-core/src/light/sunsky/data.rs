//! The Hosek–Wilkie tables Mitsuba 3 ships for its `sunsky` emitter, stored in Mitsuba's
//! tensor files ([`crate::tensor_file`]).
//!
//! The two files are Mitsuba 3.9.1's `data/sunsky/sunsky_datasets.bin` and
//! `data/sunsky/sampling_data.bin`, copied unchanged into `assets/sunsky/` (with the licence of
//! Hosek and Wilkie's data, BSD-3) and embedded in the binary, so a scene renders without any
//! file outside the repository.
//!

use crate::tensor_file::{TensorField, parse_tensor_file};

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
        assert_eq!(wrong_type[type_at], 10, "f32");
        wrong_type[type_at] = 2;
        assert!(
            parse_tensor_file(&wrong_type)
                .unwrap_err()
                .contains("element type 2")
        );
    }
}
