//! Indices of refraction: a number, a named material, a spectrum or a dispersion formula, and
//! the interior and exterior indices of dielectric interfaces.

use crate::description::{PluginClass, PluginNode, PropertyValue, SpectrumValue};
use crate::factory::spectra::{NestedSpectrum, build_nested_spectrum};
use crate::params::Params;
use crate::registry::{Default, ParamKind, ParamSpec, params};
use prism_core::error::{Error, Result};
use prism_core::spectrum::ior::{Ior, NAMED_IORS, RelativeIor, named_ior};
use prism_core::spectrum::{LAMBDA_MAX, LAMBDA_MIN, PiecewiseLinear, RgbIntent, Spectrum};

params! {
    pub(super) INT_IOR = ParamSpec::new("int_ior", ParamKind::Ior, Default::Str("bk7"), "index of refraction inside: a number, a name (`bk7`, `water`, …), a `<spectrum>`, or (Prism) a dispersive `<spectrum type=\"sellmeier\">` or `cauchy`");
    pub(super) COATING_INT_IOR = ParamSpec::new("int_ior", ParamKind::Ior, Default::Str("polypropylene"), "index of refraction of the coating: a number or a name");
    pub(super) EXT_IOR = ParamSpec::new("ext_ior", ParamKind::Ior, Default::Str("air"), "index of refraction outside");
}

/// `int_ior` (as `interior` declares it) and `ext_ior`. With `must_differ`, equal constant
/// indices are refused (Mitsuba's rule for rough interfaces).
pub(super) fn relative_ior(
    params: &Params,
    interior: &ParamSpec,
    must_differ: bool,
) -> Result<RelativeIor> {
    let interior = ior(params, interior)?;
    let exterior = ior(params, &EXT_IOR)?;
    if must_differ && interior == exterior {
        return Err(Error::input(
            params.location_of(&INT_IOR),
            format!(
                "{} has the same index of refraction inside and outside",
                params.node().describe()
            ),
        )
        .with_help("an interface between equal indices does nothing; change int_ior or ext_ior"));
    }
    Ok(RelativeIor { interior, exterior })
}

/// The constant relative index of a coating (`plastic`, `roughplastic`: default polypropylene
/// over air).
pub(super) fn constant_relative_ior(params: &Params, must_differ: bool) -> Result<f32> {
    let eta = relative_ior(params, &COATING_INT_IOR, must_differ)?;
    match (&eta.interior, &eta.exterior) {
        (Ior::Constant(i), Ior::Constant(e)) => Ok(i / e),
        _ => Err(Error::input(
            params.location_of(&INT_IOR),
            format!(
                "{} takes a constant index of refraction",
                params.node().describe()
            ),
        )
        .with_help("give a number or a name; only dielectrics disperse light")),
    }
}

/// An index of refraction: a number, a name of [`NAMED_IORS`], a spectrum (`<spectrum>` values
/// or an `<rgb>` upsampled without bounds), or a nested `<spectrum type="sellmeier">` or
/// `<spectrum type="cauchy">`. Must be positive and finite over 360–830 nm.
pub(super) fn ior(params: &Params, spec: &ParamSpec) -> Result<Ior> {
    let name = spec.name;
    let (value, location) = if let Some(child) = params.named_child(spec) {
        (dispersion_formula(&child.node)?, &child.location)
    } else if let Some(property) = params.property(spec) {
        let location = &property.location;
        let value = match &property.value {
            PropertyValue::Float(v) => Ior::Constant(*v as f32),
            PropertyValue::Integer(v) => Ior::Constant(*v as f32),
            PropertyValue::Spectrum(SpectrumValue::Uniform(v)) => Ior::Constant(*v as f32),
            PropertyValue::String(s) => Ior::Constant(named_ior(s).ok_or_else(|| {
                let names: Vec<&str> = NAMED_IORS.iter().map(|(n, _)| *n).collect();
                Error::input(location, format!("unknown index of refraction \"{s}\""))
                    .with_help(format!("known names: {}", names.join(", ")))
            })?),
            PropertyValue::Spectrum(SpectrumValue::Samples(samples)) => {
                let samples: Vec<(f32, f32)> =
                    samples.iter().map(|&(l, v)| (l as f32, v as f32)).collect();
                match PiecewiseLinear::new(&samples) {
                    Some(table) => Ior::Tabulated(table),
                    None => Ior::Constant(0.0),
                }
            }
            PropertyValue::Rgb(rgb) => {
                let rgb = rgb.map(|c| c as f32);
                if rgb.iter().all(|c| *c > 0.0 && c.is_finite()) {
                    let spectrum = Spectrum::from_rgb(rgb, RgbIntent::Unbounded);
                    let samples: Vec<(f32, f32)> = (0..=94)
                        .map(|i| {
                            let lambda = LAMBDA_MIN + 5.0 * i as f32;
                            (lambda, spectrum.value(lambda))
                        })
                        .collect();
                    PiecewiseLinear::new(&samples).map_or(Ior::Constant(0.0), Ior::Tabulated)
                } else {
                    Ior::Constant(0.0)
                }
            }
            other => {
                return Err(Error::input(
                    location,
                    format!(
                        "parameter \"{name}\" of {} must be a number, a name or a spectrum, but a {} was given",
                        params.node().describe(),
                        other.type_name()
                    ),
                ));
            }
        };
        (value, location)
    } else {
        let Default::Str(default) = spec.default else {
            panic!("\"{name}\" has no named default");
        };
        return Ok(Ior::Constant(named_ior(default).unwrap_or(1.0)));
    };
    let min = value.min_value();
    let max = (0..=470)
        .map(|i| value.at(LAMBDA_MIN + i as f32))
        .fold(0.0f32, f32::max);
    if !(min > 0.0 && max.is_finite()) {
        return Err(Error::input(
            location,
            format!(
                "the index of refraction \"{name}\" of {} must be positive and finite over {LAMBDA_MIN}–{LAMBDA_MAX} nm",
                params.node().describe()
            ),
        )
        .with_help("check the value (and, for a Sellmeier formula, that no pole lies in the visible range)"));
    }
    Ok(value)
}

/// A nested dispersion formula (`<spectrum type="sellmeier">` or `cauchy`) for an index.
fn dispersion_formula(node: &PluginNode) -> Result<Ior> {
    let unsupported = || {
        Error::input(
            &node.location,
            format!("{} cannot give an index of refraction", node.describe()),
        )
        .with_help("use <spectrum type=\"sellmeier\"> or <spectrum type=\"cauchy\">, a number, a name or <spectrum value=\"...\">")
    };
    if node.class != PluginClass::Spectrum {
        return Err(unsupported());
    }
    match build_nested_spectrum(node)? {
        NestedSpectrum::Ior(ior) => Ok(ior),
        NestedSpectrum::Emission(_) => Err(unsupported()),
    }
}
