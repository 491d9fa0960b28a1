//! The values of `<rgb>` and `<spectrum>` properties, including `.spd` spectrum files.
//!
//! - `<rgb value="r, g, b"/>`, or one value `v` meaning `v, v, v` (Mitsuba 3). We also accept
//!   `value="#rrggbb"`, sRGB-encoded bytes decoded to linear values with the sRGB transfer curve,
//!   as Mitsuba 0.6 did for hexadecimal colours; Mitsuba 3's own parser rejects this form.
//! - `<srgb value="r, g, b"/>`, `<srgb value="v"/>` or `<srgb value="#rrggbb"/>` (Mitsuba 0.6):
//!   sRGB-encoded components, decoded to linear values with the sRGB transfer curve, and then
//!   read as `<rgb>`.
//! - `<spectrum value="0.5"/>` is the same value at every wavelength;
//!   `<spectrum value="400:0.1, 500:0.2"/>` lists (wavelength in nm, value) pairs; and
//!   `<spectrum filename="x.spd"/>` reads such pairs from a text file with one `wavelength value`
//!   pair a line and `#` comments (Mitsuba's `spectrum_from_file`). Exactly one of `value` and
//!   `filename` must be given. Mitsuba only rejects decreasing wavelengths; we require at least
//!   two pairs with positive, strictly increasing wavelengths, since the spectrum is interpolated
//!   between them.
//! - `<spectrum value="0.1 0.4 0.9"/>`, values without wavelengths, is Mitsuba 0.6's form for
//!   the components of its `Spectrum` type (its scene reader requires exactly
//!   `SPECTRUM_SAMPLES` of them, `src/librender/scenehandler.cpp`). Mitsuba 0.6's default build
//!   is RGB (`SPECTRUM_SAMPLES` = 3), where three values are linear RGB: they are read as `<rgb>`.
//!   A spectral build's N values (N = 2 or N > 3) are its N bins of equal width between
//!   `SPECTRUM_MIN_WAVELENGTH` = 360 and `SPECTRUM_MAX_WAVELENGTH` = 830 nm, constant within each
//!   bin and zero outside: they are read as wavelength:value pairs at each bin's two ends, the
//!   end of one bin [`BIN_EDGE`] nm before the start of the next, so that the interpolated
//!   spectrum steps between bins. Mitsuba 3 refuses both forms.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::description::find_file;
use super::description::{PropertyValue, SpectrumValue};
use super::element::{Attribute, Element, parse_finite, quote, tokens};
use prism_core::error::{Error, Result, SourceLocation};
use prism_core::image::srgb;

/// The value of an `<rgb>` element.
pub(super) fn rgb(element: &Element) -> Result<[f64; 3]> {
    let value = element.require("value")?;
    if let Some(hex) = value.value.trim().strip_prefix('#') {
        return hex_rgb(element, value, hex);
    }
    let numbers = element.number_list(value)?;
    match numbers[..] {
        [v] => Ok([v; 3]),
        [r, g, b] => Ok([r, g, b]),
        _ => Err(element.count_error(value, numbers.len(), "1 or 3")),
    }
}

/// The value of an `<srgb>` element: sRGB-encoded components, decoded to linear RGB.
pub(super) fn srgb_color(element: &Element) -> Result<[f64; 3]> {
    let value = element.require("value")?;
    if let Some(hex) = value.value.trim().strip_prefix('#') {
        return hex_rgb(element, value, hex);
    }
    let numbers = element.number_list(value)?;
    let encoded = match numbers[..] {
        [v] => [v; 3],
        [r, g, b] => [r, g, b],
        _ => return Err(element.count_error(value, numbers.len(), "1 or 3")),
    };
    Ok(encoded.map(|v| f64::from(srgb::decode(v as f32))))
}

/// `#rrggbb`, sRGB-encoded, to linear RGB.
fn hex_rgb(element: &Element, value: &Attribute, hex: &str) -> Result<[f64; 3]> {
    let bytes: Option<Vec<u8>> = if hex.len() == 6 && hex.bytes().all(|b| b.is_ascii_hexdigit()) {
        (0..3)
            .map(|i| {
                hex.get(2 * i..2 * i + 2)
                    .and_then(|pair| u8::from_str_radix(pair, 16).ok())
            })
            .collect()
    } else {
        None
    };
    match bytes.as_deref() {
        Some(&[r, g, b]) => {
            Ok([r, g, b].map(|byte| f64::from(srgb::decode(f32::from(byte) / 255.0))))
        }
        _ => Err(element.invalid_value(
            value,
            "is not a colour",
            "write value=\"#rrggbb\" with six hexadecimal digits, or value=\"r, g, b\"",
        )),
    }
}

/// The value of a `<spectrum>` element without a `type` attribute; a `filename` is looked up in
/// `search_paths`.
pub(super) fn spectrum(element: &Element, search_paths: &[PathBuf]) -> Result<PropertyValue> {
    let value = element.get("value").filter(|a| !a.value.trim().is_empty());
    let filename = element.get("filename").filter(|a| !a.value.is_empty());
    match (value, filename) {
        (Some(value), None) => {
            let entries: Vec<&str> = tokens(&value.value).collect();
            if entries.len() > 1 && entries.iter().all(|entry| !entry.contains(':')) {
                mitsuba_06_spectrum(element, value)
            } else {
                inline_spectrum(element, value).map(PropertyValue::Spectrum)
            }
        }
        (None, Some(filename)) => {
            spectrum_file(filename, search_paths).map(PropertyValue::Spectrum)
        }
        _ => Err(Error::input(
            &element.location,
            format!(
                "{} needs either a value or a filename attribute (not both)",
                element.describe()
            ),
        )
        .with_help("write value=\"0.5\", value=\"400:0.1, 700:0.5\" or filename=\"data.spd\"")),
    }
}

/// The wavelength range of Mitsuba 0.6's spectral bins, in nm.
const MITSUBA_06_BINS: (f64, f64) = (360.0, 830.0);
/// How far before the next bin's start a bin's last sample lies, in nm: the interpolated
/// spectrum rises or falls to the next bin's value within this width.
const BIN_EDGE: f64 = 1e-6;

/// Values without wavelengths (see the module's documentation): three are linear RGB, other
/// counts Mitsuba 0.6's spectral bins.
fn mitsuba_06_spectrum(element: &Element, value: &Attribute) -> Result<PropertyValue> {
    let values = element.number_list(value)?;
    if let [r, g, b] = values[..] {
        return Ok(PropertyValue::Rgb([r, g, b]));
    }
    if values.len() > 1024 {
        return Err(element.count_error(value, values.len(), "at most 1024"));
    }
    let (min, max) = MITSUBA_06_BINS;
    let width = (max - min) / values.len() as f64;
    let mut samples = Vec::with_capacity(2 * values.len());
    for (i, &v) in values.iter().enumerate() {
        let start = min + i as f64 * width;
        samples.push((start, v));
        samples.push((
            start + width - if i + 1 < values.len() { BIN_EDGE } else { 0.0 },
            v,
        ));
    }
    Ok(PropertyValue::Spectrum(SpectrumValue::Samples(samples)))
}

fn inline_spectrum(element: &Element, value: &Attribute) -> Result<SpectrumValue> {
    let entries: Vec<&str> = tokens(&value.value).collect();
    if let [single] = entries[..]
        && !single.contains(':')
    {
        return Ok(SpectrumValue::Uniform(element.number(value)?));
    }
    let mut samples = Vec::with_capacity(entries.len());
    for entry in entries {
        let pair = entry
            .split_once(':')
            .and_then(|(wavelength, v)| Some((parse_finite(wavelength)?, parse_finite(v)?)));
        match pair {
            Some(pair) => samples.push(pair),
            None => {
                return Err(element.invalid_value(
                    value,
                    &format!(
                        "contains \"{}\", which is not a wavelength:value pair",
                        quote(entry)
                    ),
                    "write a single value, or pairs such as \"400:0.1, 500:0.4, 600:0.3\" \
                     (wavelengths in nm)",
                ));
            }
        }
    }
    check_samples(&samples)
        .map_err(|problem| element.invalid_value(value, &problem, SAMPLES_HELP))?;
    Ok(SpectrumValue::Samples(samples))
}

const SAMPLES_HELP: &str =
    "give at least two wavelength:value pairs, with wavelengths in nm in increasing order";

/// Checks that `samples` form a spectrum: two or more pairs, positive increasing wavelengths.
/// On failure, returns the problem as a phrase that follows the attribute (or file).
fn check_samples(samples: &[(f64, f64)]) -> std::result::Result<(), String> {
    if samples.len() < 2 {
        return Err(format!(
            "has {} wavelength:value pair{}, but a spectrum needs at least two",
            samples.len(),
            if samples.len() == 1 { "" } else { "s" }
        ));
    }
    if let Some(&(wavelength, _)) = samples.iter().find(|(wavelength, _)| *wavelength <= 0.0) {
        return Err(format!(
            "has the wavelength {wavelength} nm, which is not positive"
        ));
    }
    if let Some(pair) = samples.windows(2).find(|pair| pair[1].0 <= pair[0].0) {
        return Err(format!(
            "has the wavelength {} nm after {} nm, but wavelengths must increase",
            pair[1].0, pair[0].0
        ));
    }
    Ok(())
}

/// Reads `filename`, a `.spd` file of `wavelength value` lines with `#` comments.
fn spectrum_file(filename: &Attribute, search_paths: &[PathBuf]) -> Result<SpectrumValue> {
    let is_spd = Path::new(&filename.value)
        .extension()
        .is_some_and(|extension| extension.eq_ignore_ascii_case("spd"));
    if !is_spd {
        return Err(Error::input(
            &filename.location,
            format!(
                "spectrum file \"{}\" does not have the extension .spd",
                quote(&filename.value)
            ),
        )
        .with_help("Mitsuba reads spectra from .spd text files of \"wavelength value\" lines"));
    }
    let path = find_file(&filename.value, search_paths, &filename.location)?;
    let text = std::fs::read_to_string(&path)
        .map_err(|err| Error::io(&path, &err, "read the spectrum file").at(&filename.location))?;
    let file: Arc<Path> = Arc::from(path.as_path());
    let mut samples = Vec::new();
    let mut last_line = 1;
    for (index, line) in text.lines().enumerate() {
        let line_number = u32::try_from(index + 1).unwrap_or(u32::MAX);
        let content = line.split('#').next().unwrap_or("");
        let entries = tokens_with_columns(content);
        if entries.is_empty() {
            continue;
        }
        let location = |column: u32| SourceLocation {
            file: file.clone(),
            line: line_number,
            column,
        };
        let pair = match entries[..] {
            [(wavelength_column, wavelength), (value_column, value)] => (
                spd_number(wavelength, location(wavelength_column))?,
                spd_number(value, location(value_column))?,
            ),
            _ => {
                let column = entries.first().map_or(1, |(column, _)| *column);
                return Err(Error::input(
                    &location(column),
                    format!(
                        "expected \"wavelength value\", found {} entries",
                        entries.len()
                    ),
                )
                .with_help(SPD_HELP));
            }
        };
        samples.push(pair);
        last_line = line_number;
    }
    check_samples(&samples).map_err(|problem| {
        Error::input(
            &SourceLocation {
                file: file.clone(),
                line: last_line,
                column: 1,
            },
            format!("spectrum file {problem}"),
        )
        .with_help(SAMPLES_HELP)
    })?;
    Ok(SpectrumValue::Samples(samples))
}

const SPD_HELP: &str = "write one wavelength (nm) and one value per line; # starts a comment";

/// A number of a `.spd` file.
fn spd_number(token: &str, location: SourceLocation) -> Result<f64> {
    parse_finite(token).ok_or_else(|| {
        Error::input(
            &location,
            format!("\"{}\" is not a finite number", quote(token)),
        )
        .with_help(SPD_HELP)
    })
}

/// The entries of a line separated by commas and/or whitespace, with their 1-based columns.
fn tokens_with_columns(line: &str) -> Vec<(u32, &str)> {
    let mut entries = Vec::new();
    let mut start: Option<(usize, u32)> = None;
    let mut column = 0u32;
    for (offset, c) in line.char_indices() {
        column = column.saturating_add(1);
        let separator = c == ',' || c.is_whitespace();
        match (separator, start) {
            (true, Some((begin, begin_column))) => {
                entries.push((begin_column, line.get(begin..offset).unwrap_or("")));
                start = None;
            }
            (false, None) => start = Some((offset, column)),
            _ => {}
        }
    }
    if let Some((begin, begin_column)) = start {
        entries.push((begin_column, line.get(begin..).unwrap_or("")));
    }
    entries
}
