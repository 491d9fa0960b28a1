//! Spectral parameters: `<rgb>`, `<spectrum>` and `<float>` values turned into [`Spectrum`]s
//! with Mitsuba 3's spectral-mode semantics.
//!
//! * `<rgb>` is upsampled (Jakob & Hanika 2019); inside an emitter it is an illuminant, the
//!   upsampled colour times D65 (Mitsuba's `srgb_d65`/`d65` with a colour).
//! * `<spectrum value="v"/>` is the constant v at every wavelength; so is `<float>`, except in an
//!   emitter, where Mitsuba 3 makes it D65 scaled to luminance v (checked against Mitsuba 3.9.1:
//!   a float radiance of 1 renders as XYZ (0.950, 1.000, 1.088), a uniform spectrum as (1, 1, 1)).
//! * `<spectrum value="λ:v, ..."/>` is piecewise linear in λ and zero outside the given range.

use crate::description::{PluginClass, PropertyValue, SpectrumValue};
use crate::params::Params;
use crate::registry::{Default, Origin, ParamKind, ParamSpec, Plugin, Range, Registry, params};
use prism_core::error::{Error, Result};
use prism_core::spectrum::ior::{Ior, SELLMEIER_GLASSES, sellmeier_glass};
use prism_core::spectrum::{PiecewiseLinear, RgbIntent, Spectrum};

/// A spectrum given as a nested plugin: an emission spectrum, or an index of refraction.
pub enum NestedSpectrum {
    Emission(Spectrum),
    Ior(Ior),
}

type Build = fn(&Params) -> Result<NestedSpectrum>;

pub static SPECTRA: Registry<Build> = Registry {
    class: PluginClass::Spectrum,
    plugins: &[
        Plugin {
            name: "blackbody",
            origin: Origin::Mitsuba3,
            summary: "Planck's law in W m⁻² sr⁻¹ nm⁻¹, unnormalised as in Mitsuba 3: an emission.",
            params: &[BLACKBODY_TEMPERATURE],
            build: build_blackbody,
        },
        Plugin {
            name: "sellmeier",
            origin: Origin::Prism,
            summary: "A dispersive index of refraction by Sellmeier's formula \
                      n² = 1 + Σ Bᵢλ²/(λ² − Cᵢ) (λ in µm): a catalogue `glass`, or the coefficients.",
            params: &[GLASS, B1, B2, B3, C1, C2, C3],
            build: build_sellmeier,
        },
        Plugin {
            name: "cauchy",
            origin: Origin::Prism,
            summary: "A dispersive index of refraction by Cauchy's formula n = A + B/λ² + C/λ⁴ \
                      (λ in µm).",
            params: &[CAUCHY_A, CAUCHY_B, CAUCHY_C],
            build: build_cauchy,
        },
    ],
};

params! {
    pub BLACKBODY_TEMPERATURE = ParamSpec::new("temperature", ParamKind::Float, Default::Required, "temperature in kelvin");
    GLASS = ParamSpec::new("glass", ParamKind::String, Default::None, "a catalogue glass: N-BK7, N-SF11, N-F2, fused silica, diamond");
    B1 = ParamSpec::new("b1", ParamKind::Float, Default::Float(0.0), "B₁");
    B2 = ParamSpec::new("b2", ParamKind::Float, Default::Float(0.0), "B₂");
    B3 = ParamSpec::new("b3", ParamKind::Float, Default::Float(0.0), "B₃");
    C1 = ParamSpec::new("c1", ParamKind::Float, Default::Float(0.0), "C₁ in µm²");
    C2 = ParamSpec::new("c2", ParamKind::Float, Default::Float(0.0), "C₂ in µm²");
    C3 = ParamSpec::new("c3", ParamKind::Float, Default::Float(0.0), "C₃ in µm²");
    CAUCHY_A = ParamSpec::new("a", ParamKind::Float, Default::Float(1.5), "A");
    CAUCHY_B = ParamSpec::new("b", ParamKind::Float, Default::Float(0.0), "B in µm²");
    CAUCHY_C = ParamSpec::new("c", ParamKind::Float, Default::Float(0.0), "C in µm⁴");
}

fn build_blackbody(params: &Params) -> Result<NestedSpectrum> {
    let Some(temperature) = params.float_opt(&BLACKBODY_TEMPERATURE)? else {
        return Err(Error::input(
            params.location(),
            "the blackbody spectrum needs a \"temperature\" (in kelvin)",
        )
        .with_help("add <float name=\"temperature\" value=\"5000\"/>"));
    };
    if !(temperature > 0.0 && temperature.is_finite() && temperature < f64::from(f32::MAX)) {
        return Err(Error::input(
            params.location_of(&BLACKBODY_TEMPERATURE),
            format!(
                "the blackbody temperature must be a positive number of kelvin, not {temperature}"
            ),
        ));
    }
    Ok(NestedSpectrum::Emission(Spectrum::Blackbody(
        prism_core::spectrum::blackbody::Blackbody {
            temperature: temperature as f32,
        },
    )))
}

/// A finite number parameter of a dispersion formula.
fn coefficient(params: &Params, spec: &ParamSpec) -> Result<f32> {
    let v = params.float(spec)?;
    if !v.is_finite() {
        return Err(Error::input(
            params.location_of(spec),
            format!("\"{}\" must be a finite number", spec.name),
        ));
    }
    Ok(v as f32)
}

fn build_sellmeier(params: &Params) -> Result<NestedSpectrum> {
    let ior = match params.string_opt(&GLASS)? {
        Some(glass) => {
            let (b, c) = sellmeier_glass(glass).ok_or_else(|| {
                let names: Vec<&str> = SELLMEIER_GLASSES.iter().map(|g| g.0).collect();
                Error::input(
                    params.location_of(&GLASS),
                    format!("unknown glass \"{glass}\""),
                )
                .with_help(format!("known glasses: {}", names.join(", ")))
            })?;
            Ior::Sellmeier { b, c }
        }
        None => Ior::Sellmeier {
            b: [
                coefficient(params, &B1)?,
                coefficient(params, &B2)?,
                coefficient(params, &B3)?,
            ],
            c: [
                coefficient(params, &C1)?,
                coefficient(params, &C2)?,
                coefficient(params, &C3)?,
            ],
        },
    };
    Ok(NestedSpectrum::Ior(ior))
}

fn build_cauchy(params: &Params) -> Result<NestedSpectrum> {
    Ok(NestedSpectrum::Ior(Ior::Cauchy {
        a: coefficient(params, &CAUCHY_A)?,
        b: coefficient(params, &CAUCHY_B)?,
        c: coefficient(params, &CAUCHY_C)?,
    }))
}

/// The spectrum a nested `<spectrum type="...">` describes.
pub fn build_nested_spectrum(node: &crate::description::PluginNode) -> Result<NestedSpectrum> {
    let plugin = SPECTRA.find(node)?;
    let params = Params::new(node, plugin.params);
    let spectrum = (plugin.build)(&params)?;
    params.finish()?;
    Ok(spectrum)
}

/// The spectrum given for parameter `spec` (its declared range), or its declared default when
/// absent.
pub fn spectrum_param(params: &Params, spec: &ParamSpec) -> Result<Spectrum> {
    let name = spec.name;
    let range = match spec.kind {
        ParamKind::Spectrum { range, .. } | ParamKind::Volume(range) => range,
        _ => panic!("\"{name}\" is not a spectrum"),
    };
    if let Some(child) = params.named_child(spec) {
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
    let Some(property) = params.property(spec) else {
        let Default::Float(default) = spec.default else {
            panic!("\"{name}\" has no numeric default");
        };
        return Ok(Spectrum::Constant(default as f32));
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
        Range::Albedo | Range::Coefficient | Range::IndexPart => RgbIntent::Albedo,
        Range::Emission => RgbIntent::Illuminant,
    };
    let spectrum = match &property.value {
        PropertyValue::Float(_) | PropertyValue::Integer(_) => {
            let v = number(&property.value);
            if !(v >= 0.0 && v.is_finite()) {
                return Err(negative());
            }
            match range {
                Range::Albedo | Range::IndexPart | Range::Coefficient => {
                    Spectrum::Constant(v as f32)
                }
                Range::Emission => Spectrum::from_rgb([v as f32; 3], RgbIntent::Illuminant),
            }
        }
        PropertyValue::Rgb(rgb) => {
            if !rgb.iter().all(|c| *c >= 0.0 && c.is_finite()) {
                return Err(negative());
            }
            let rgb = rgb.map(|c| c as f32);
            match range {
                Range::IndexPart => Spectrum::from_rgb(rgb.map(|c| c.min(1.0)), intent),
                _ => Spectrum::from_rgb(rgb, intent),
            }
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
