//! Spectral parameters: `<rgb>`, `<spectrum>` and `<float>` values turned into [`Spectrum`]s
//! with Mitsuba 3's spectral-mode semantics.
//!
//! * `<rgb>` is upsampled (Jakob & Hanika 2019); inside an emitter it is an illuminant, the
//!   upsampled colour times D65 (Mitsuba's `srgb_d65`/`d65` with a colour).
//! * `<spectrum value="v"/>` is the constant v at every wavelength; so is `<float>`, except in an
//!   emitter, where Mitsuba 3 makes it D65 scaled to luminance v (checked against Mitsuba 3.9.1:
//!   a float radiance of 1 renders as XYZ (0.950, 1.000, 1.088), a uniform spectrum as (1, 1, 1)).
//! * `<spectrum value="λ:v, ..."/>` is piecewise linear in λ and zero outside the given range.

use crate::description::{PropertyValue, SpectrumValue};
use crate::params::Params;
use prism_core::error::{Error, Result};
use prism_core::spectrum::{PiecewiseLinear, RgbIntent, Spectrum};

/// How a spectral parameter may be valued.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Range {
    /// A reflectance: every value in [0, 1] (RGB components above 1 are accepted and upsampled
    /// as unbounded colours, as Mitsuba renders them).
    Albedo,
    /// Emitted radiance or intensity: non-negative.
    Emission,
    /// Any non-negative value, such as the real and imaginary parts of an index of refraction;
    /// `<rgb>` is upsampled without bounds ([`RgbIntent::Unbounded`]).
    Unbounded,
}

/// The spectrum given for parameter `name`, or `default` when absent.
pub fn spectrum_param(
    params: &Params,
    name: &'static str,
    default: f32,
    range: Range,
) -> Result<Spectrum> {
    if let Some(child) = params.named_child(name) {
        return Err(Error::input(
            &child.location,
            format!(
                "{} for parameter \"{name}\" of {} is not supported yet",
                child.node.describe(),
                params.node().describe()
            ),
        )
        .with_help("give the value as <rgb>, <spectrum> or <float>"));
    }
    let Some(property) = params.property(name) else {
        return Ok(Spectrum::Constant(default));
    };
    let location = &property.location;
    let negative = || {
        Error::input(
            location,
            format!(
                "parameter \"{name}\" of {} has a negative or non-finite value",
                params.node().describe()
            ),
        )
        .with_help("spectral values must be finite and at least 0")
    };
    let intent = match range {
        Range::Albedo => RgbIntent::Albedo,
        Range::Emission => RgbIntent::Illuminant,
        Range::Unbounded => RgbIntent::Unbounded,
    };
    let spectrum = match &property.value {
        PropertyValue::Float(_) | PropertyValue::Integer(_) => {
            let v = number(&property.value);
            if !(v >= 0.0 && v.is_finite()) {
                return Err(negative());
            }
            match range {
                Range::Albedo | Range::Unbounded => Spectrum::Constant(v as f32),
                Range::Emission => Spectrum::from_rgb([v as f32; 3], RgbIntent::Illuminant),
            }
        }
        PropertyValue::Rgb(rgb) => {
            if !rgb.iter().all(|c| *c >= 0.0 && c.is_finite()) {
                return Err(negative());
            }
            Spectrum::from_rgb(rgb.map(|c| c as f32), intent)
        }
        PropertyValue::Spectrum(SpectrumValue::Uniform(v)) => {
            if !(*v >= 0.0 && v.is_finite()) {
                return Err(negative());
            }
            Spectrum::Constant(*v as f32)
        }
        PropertyValue::Spectrum(SpectrumValue::Samples(samples)) => {
            if !samples
                .iter()
                .all(|(l, v)| *v >= 0.0 && v.is_finite() && l.is_finite())
            {
                return Err(negative());
            }
            let samples: Vec<(f32, f32)> =
                samples.iter().map(|&(l, v)| (l as f32, v as f32)).collect();
            match PiecewiseLinear::new(&samples) {
                Some(table) => Spectrum::PiecewiseLinear(table),
                None => Spectrum::Constant(0.0),
            }
        }
        other => {
            return Err(Error::input(
                location,
                format!(
                    "parameter \"{name}\" of {} must be a colour (<rgb>, <spectrum> or <float>), but a {} was given",
                    params.node().describe(),
                    other.type_name()
                ),
            ));
        }
    };
    if range == Range::Albedo {
        check_reflectance(&spectrum, property)?;
    }
    Ok(spectrum)
}

/// The value of a float or integer property (NaN for other kinds).
fn number(value: &PropertyValue) -> f64 {
    match *value {
        PropertyValue::Float(v) => v,
        PropertyValue::Integer(v) => v as f64,
        _ => f64::NAN,
    }
}

/// Reflectances given as spectra or numbers must lie in [0, 1]: above 1 a surface would create
/// energy. (RGB colours above 1 are let through, scaled, as Mitsuba renders them.)
fn check_reflectance(spectrum: &Spectrum, property: &crate::description::Property) -> Result<()> {
    if matches!(property.value, PropertyValue::Rgb(_)) {
        return Ok(());
    }
    let max = spectrum.max_value();
    if max > 1.0 {
        return Err(Error::input(
            &property.location,
            format!(
                "reflectance \"{}\" reaches {max}, above 1: the surface would reflect more light than it receives",
                property.name
            ),
        )
        .with_help("use values between 0 and 1"));
    }
    Ok(())
}
