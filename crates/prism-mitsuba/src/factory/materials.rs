//! BSDF plugins: `diffuse`, `roughdiffuse`, `conductor`, `roughconductor`, `dielectric`,
//! `roughdielectric`, `thindielectric`, `plastic`, `roughplastic`, `phong`, `twosided`, `mask`,
//! `blendbsdf`, `bumpmap` and `normalmap`, with Mitsuba 3's parameters and defaults (Mitsuba
//! 0.6's for `roughdiffuse` and `phong`, which Mitsuba 3 dropped). Each BSDF's module documents
//! its parameters; the checks here follow Mitsuba's and add the ones it leaves to chance
//! (non-positive roughness or index, opacity outside [0, 1]).

use super::spectra::Range;
use super::textures::{
    TextureCache, build_texture, float_texture, optional_spectrum_texture, spectrum_texture,
};
use crate::description::{PluginClass, PluginNode, PropertyValue, SpectrumValue};
use crate::params::Params;
use prism_core::bsdf::microfacet::MicrofacetKind;
use prism_core::bsdf::{
    Blend, Bsdf, BsdfFlags, BsdfModel, BumpMap, Conductor, Dielectric, Diffuse, MAX_NODES, Mask,
    Material, NormalMap, Phong, Plastic, RoughConductor, RoughDielectric, RoughDiffuse,
    RoughPlastic, ThinDielectric, TwoSided,
};
use prism_core::error::{Error, Result};
use prism_core::spectrum::conductors::CONDUCTORS;
use prism_core::spectrum::ior::{Ior, NAMED_IORS, RelativeIor, named_ior, sellmeier_glass};
use prism_core::spectrum::{LAMBDA_MAX, LAMBDA_MIN, PiecewiseLinear, RgbIntent, Spectrum};
use prism_core::texture::Texture;
use prism_core::texture::TextureUse;

/// The BSDF types this factory knows.
pub const SUPPORTED_BSDFS: &[&str] = &[
    "blendbsdf",
    "bumpmap",
    "conductor",
    "dielectric",
    "diffuse",
    "mask",
    "normalmap",
    "phong",
    "plastic",
    "roughconductor",
    "roughdielectric",
    "roughdiffuse",
    "roughplastic",
    "thindielectric",
    "twosided",
];

/// Mitsuba's default material for a shape without a BSDF: one-sided diffuse, reflectance 0.5.
pub fn default_material() -> Material {
    Material::new(Diffuse {
        reflectance: Texture::constant(0.5),
    })
}

/// Builds the material a `<bsdf>` element describes: a top-level `twosided` gives the front
/// and back BSDFs, anything else the front one.
pub fn build_material(node: &PluginNode, textures: &mut TextureCache) -> Result<Material> {
    let material = if node.plugin_type == "twosided" {
        let (front, back) = twosided_pair(node, textures)?;
        Material {
            front,
            back: Some(back),
        }
    } else {
        Material::new(build_bsdf(node, textures)?)
    };
    if material.node_count() > MAX_NODES {
        return Err(Error::input(
            &node.location,
            format!(
                "{} nests {} BSDFs and adapters, more than the {MAX_NODES} Prism supports",
                node.describe(),
                material.node_count()
            ),
        )
        .with_help("flatten the nesting: blend fewer BSDFs, or wrap fewer adapters around them"));
    }
    Ok(material)
}

/// The front and back BSDFs of a `twosided` element.
fn twosided_pair(node: &PluginNode, textures: &mut TextureCache) -> Result<(Bsdf, Bsdf)> {
    let params = Params::new(node);
    let nested = params.children(PluginClass::Bsdf);
    let one_sided = |child: &PluginNode, textures: &mut TextureCache| -> Result<Bsdf> {
        if child.plugin_type == "twosided" {
            return Err(Error::input(
                &child.location,
                "a \"twosided\" BSDF cannot be nested in another \"twosided\"",
            )
            .with_help("remove the inner twosided wrapper"));
        }
        let bsdf = build_bsdf(child, textures)?;
        let flags = bsdf.flags();
        if flags.contains(BsdfFlags::TRANSMISSION) || flags.contains(BsdfFlags::NULL) {
            return Err(Error::input(
                &child.location,
                format!(
                    "{} transmits light, so it cannot be nested in \"twosided\"",
                    child.describe()
                ),
            )
            .with_help(
                "dielectrics and masks already work from both sides; as in Mitsuba 3, only \
                 reflecting BSDFs can be made two-sided (put a mask around the twosided BSDF)",
            ));
        }
        Ok(bsdf)
    };
    let pair = match nested.as_slice() {
        [one] => {
            let bsdf = one_sided(&one.node, textures)?;
            (bsdf.clone(), bsdf)
        }
        [front, back] => (
            one_sided(&front.node, textures)?,
            one_sided(&back.node, textures)?,
        ),
        _ => {
            return Err(Error::input(
                &node.location,
                format!(
                    "bsdf \"twosided\" needs one or two nested BSDFs, found {}",
                    nested.len()
                ),
            )
            .with_help(
                "nest the BSDF to use on both sides, or one for the front and one for the back",
            ));
        }
    };
    params.finish()?;
    Ok(pair)
}

/// Builds a BSDF (a `twosided` here is one nested in another adapter).
pub fn build_bsdf(node: &PluginNode, textures: &mut TextureCache) -> Result<Bsdf> {
    if node.plugin_type == "twosided" {
        let (front, back) = twosided_pair(node, textures)?;
        return Ok(Bsdf::TwoSided(TwoSided {
            front: Box::new(front),
            back: Box::new(back),
        }));
    }
    let params = Params::new(node);
    let t = textures;
    let bsdf = match node.plugin_type.as_str() {
        "diffuse" => Bsdf::Diffuse(Diffuse {
            reflectance: spectrum_texture(&params, "reflectance", 0.5, Range::Albedo, t)?,
        }),
        "roughdiffuse" => Bsdf::RoughDiffuse(RoughDiffuse {
            reflectance: spectrum_texture(&params, "reflectance", 0.5, Range::Albedo, t)?,
            alpha: float_texture(&params, "alpha", 0.2, 0.0, false, f32::INFINITY, t)?,
            use_fast_approx: params.boolean("use_fast_approx", false)?,
        }),
        "conductor" => {
            let (eta, k) = conductor_ior(&params, t)?;
            Bsdf::Conductor(Conductor {
                eta,
                k,
                specular_reflectance: spectrum_texture(
                    &params,
                    "specular_reflectance",
                    1.0,
                    Range::Albedo,
                    t,
                )?,
            })
        }
        "roughconductor" => {
            let (eta, k) = conductor_ior(&params, t)?;
            let distribution = distribution(&params)?;
            let (alpha_u, alpha_v) = roughness(&params, t)?;
            Bsdf::RoughConductor(RoughConductor {
                distribution,
                alpha_u,
                alpha_v,
                eta,
                k,
                specular_reflectance: spectrum_texture(
                    &params,
                    "specular_reflectance",
                    1.0,
                    Range::Albedo,
                    t,
                )?,
            })
        }
        "dielectric" => Bsdf::Dielectric(Dielectric {
            eta: relative_ior(&params, "bk7", false)?,
            specular_reflectance: optional_spectrum_texture(
                &params,
                "specular_reflectance",
                Range::Albedo,
                t,
            )?,
            specular_transmittance: optional_spectrum_texture(
                &params,
                "specular_transmittance",
                Range::Albedo,
                t,
            )?,
        }),
        "roughdielectric" => {
            let eta = relative_ior(&params, "bk7", true)?;
            let distribution = distribution(&params)?;
            let (alpha_u, alpha_v) = roughness(&params, t)?;
            Bsdf::RoughDielectric(RoughDielectric {
                eta,
                distribution,
                alpha_u,
                alpha_v,
                specular_reflectance: optional_spectrum_texture(
                    &params,
                    "specular_reflectance",
                    Range::Albedo,
                    t,
                )?,
                specular_transmittance: optional_spectrum_texture(
                    &params,
                    "specular_transmittance",
                    Range::Albedo,
                    t,
                )?,
            })
        }
        "thindielectric" => Bsdf::ThinDielectric(ThinDielectric {
            eta: relative_ior(&params, "bk7", false)?,
            specular_reflectance: optional_spectrum_texture(
                &params,
                "specular_reflectance",
                Range::Albedo,
                t,
            )?,
            specular_transmittance: optional_spectrum_texture(
                &params,
                "specular_transmittance",
                Range::Albedo,
                t,
            )?,
        }),
        "plastic" => {
            let eta = constant_relative_ior(&params, false)?;
            Bsdf::Plastic(Plastic::new(
                eta,
                spectrum_texture(&params, "diffuse_reflectance", 0.5, Range::Albedo, t)?,
                optional_spectrum_texture(&params, "specular_reflectance", Range::Albedo, t)?,
                params.boolean("nonlinear", false)?,
            ))
        }
        "roughplastic" => {
            let eta = constant_relative_ior(&params, true)?;
            let distribution = distribution(&params)?;
            for name in ["alpha_u", "alpha_v"] {
                if params.property(name).is_some() || params.named_child(name).is_some() {
                    return Err(Error::input(
                        params.location_of(name),
                        "bsdf \"roughplastic\" supports only isotropic roughness",
                    )
                    .with_help(
                        "give a single <float name=\"alpha\" .../>, as Mitsuba 3 requires",
                    ));
                }
            }
            let alpha = match params.named_child("alpha") {
                Some(child) => {
                    return Err(Error::input(
                        &child.location,
                        "the roughness of \"roughplastic\" must be a number, not a texture",
                    )
                    .with_help("Mitsuba 3's roughplastic precomputes its tables for one alpha"));
                }
                None => float_texture(&params, "alpha", 0.1, 0.0, true, f32::INFINITY, t)?
                    .eval_1(glam::Vec2::ZERO),
            };
            params.boolean("sample_visible", true)?;
            Bsdf::RoughPlastic(RoughPlastic::new(
                eta,
                distribution,
                alpha,
                spectrum_texture(&params, "diffuse_reflectance", 0.5, Range::Albedo, t)?,
                optional_spectrum_texture(&params, "specular_reflectance", Range::Albedo, t)?,
                params.boolean("nonlinear", false)?,
            ))
        }
        "phong" => {
            let exponent = float_texture(&params, "exponent", 30.0, 0.0, true, f32::INFINITY, t)?;
            let specular =
                spectrum_texture(&params, "specular_reflectance", 0.2, Range::Albedo, t)?;
            let diffuse = spectrum_texture(&params, "diffuse_reflectance", 0.5, Range::Albedo, t)?;
            let total = largest_sum(&specular, &diffuse);
            Bsdf::Phong(Phong {
                exponent,
                specular_reflectance: specular,
                diffuse_reflectance: diffuse,
                scale: if total > 1.0 { 1.0 / total } else { 1.0 },
            })
        }
        "mask" => Bsdf::Mask(Mask {
            opacity: float_texture(&params, "opacity", 0.5, 0.0, false, 1.0, t)?,
            nested: Box::new(single_nested_bsdf(&params, t)?),
        }),
        "blendbsdf" => {
            if params.property("weight").is_none() && params.named_child("weight").is_none() {
                return Err(
                    Error::input(&node.location, "bsdf \"blendbsdf\" needs a \"weight\"")
                        .with_help(
                            "add <float name=\"weight\" value=\"0.5\"/> (the second BSDF's share)",
                        ),
                );
            }
            let weight = float_texture(&params, "weight", 0.5, 0.0, false, 1.0, t)?;
            let nested = params.children(PluginClass::Bsdf);
            let [first, second] = nested.as_slice() else {
                return Err(Error::input(
                    &node.location,
                    format!(
                        "bsdf \"blendbsdf\" needs exactly two nested BSDFs, found {}",
                        nested.len()
                    ),
                ));
            };
            Bsdf::Blend(Blend {
                weight,
                nested: [
                    Box::new(build_bsdf(&first.node, t)?),
                    Box::new(build_bsdf(&second.node, t)?),
                ],
            })
        }
        "bumpmap" => {
            let nested_textures = params.children(PluginClass::Texture);
            let [height] = nested_textures.as_slice() else {
                return Err(Error::input(
                    &node.location,
                    format!(
                        "bsdf \"bumpmap\" needs exactly one nested texture (the heights), found {}",
                        nested_textures.len()
                    ),
                ));
            };
            let scale = params.float("scale", 1.0)? as f32;
            if !scale.is_finite() {
                return Err(Error::input(
                    params.location_of("scale"),
                    "the bump map's scale must be a finite number",
                ));
            }
            Bsdf::BumpMap(BumpMap {
                height: build_texture(&height.node, TextureUse::Scalar, t)?,
                scale,
                nested: Box::new(single_nested_bsdf(&params, t)?),
                flip_invalid_normals: params.boolean("flip_invalid_normals", true)?,
                use_shadowing_function: params.boolean("use_shadowing_function", true)?,
            })
        }
        "normalmap" => {
            let Some(normals) = params.named_child("normalmap") else {
                return Err(Error::input(
                    &node.location,
                    "bsdf \"normalmap\" needs a texture named \"normalmap\"",
                )
                .with_help("nest <texture type=\"bitmap\" name=\"normalmap\"> with raw=\"true\""));
            };
            if normals.node.class != PluginClass::Texture {
                return Err(Error::input(
                    &normals.location,
                    "the \"normalmap\" parameter must be a texture",
                ));
            }
            Bsdf::NormalMap(NormalMap {
                normals: build_texture(&normals.node, TextureUse::Rgb, t)?,
                nested: Box::new(single_nested_bsdf(&params, t)?),
                flip_invalid_normals: params.boolean("flip_invalid_normals", true)?,
                use_shadowing_function: params.boolean("use_shadowing_function", true)?,
            })
        }
        other => return Err(unknown_type(node, other)),
    };
    params.finish()?;
    Ok(bsdf)
}

fn unknown_type(node: &PluginNode, name: &str) -> Error {
    Error::input(&node.location, format!("unknown bsdf type \"{name}\"")).with_help(format!(
        "supported bsdf types: {}",
        SUPPORTED_BSDFS.join(", ")
    ))
}

/// The one BSDF nested in an adapter (`mask`, `bumpmap`, `normalmap`).
fn single_nested_bsdf(params: &Params, textures: &mut TextureCache) -> Result<Bsdf> {
    let nested = params.children(PluginClass::Bsdf);
    match nested.as_slice() {
        [one] => build_bsdf(&one.node, textures),
        _ => Err(Error::input(
            params.location(),
            format!(
                "{} needs exactly one nested BSDF, found {}",
                params.node().describe(),
                nested.len()
            ),
        )),
    }
}

/// The largest value of the sum of two reflectances (Mitsuba 0.6's `ensureEnergyConservation`
/// bound): pointwise over wavelength for constants, the sum of the maxima for textures.
fn largest_sum(a: &Texture, b: &Texture) -> f32 {
    match (a, b) {
        (Texture::Constant(a), Texture::Constant(b)) => (0..=470)
            .map(|i| {
                let lambda = LAMBDA_MIN + i as f32;
                a.value(lambda) + b.value(lambda)
            })
            .fold(0.0, f32::max),
        _ => a.max_value() + b.max_value(),
    }
}

/// Whether a parameter is given as a property or a nested plugin.
fn has(params: &Params, name: &'static str) -> bool {
    params.property(name).is_some() || params.named_child(name).is_some()
}

/// `distribution`: "beckmann" (the default) or "ggx", case-insensitive as in Mitsuba.
fn distribution(params: &Params) -> Result<MicrofacetKind> {
    let name = params.string("distribution", "beckmann")?;
    match name.to_lowercase().as_str() {
        "beckmann" => Ok(MicrofacetKind::Beckmann),
        "ggx" => Ok(MicrofacetKind::Ggx),
        _ => Err(Error::input(
            params.location_of("distribution"),
            format!("unknown microfacet distribution \"{name}\""),
        )
        .with_help("use \"beckmann\" or \"ggx\"")),
    }
}

/// `alpha`, or `alpha_u` and `alpha_v` (both, and not with `alpha`), numbers above 0 or
/// textures; default 0.1. `sample_visible` is accepted: visible normals are always sampled.
fn roughness(params: &Params, textures: &mut TextureCache) -> Result<(Texture, Texture)> {
    params.boolean("sample_visible", true)?;
    let (has_u, has_v) = (has(params, "alpha_u"), has(params, "alpha_v"));
    if has_u || has_v {
        if has(params, "alpha") {
            return Err(Error::input(
                params.location_of("alpha"),
                "give either \"alpha\" or \"alpha_u\" and \"alpha_v\", not both",
            ));
        }
        if !(has_u && has_v) {
            let missing = if has_u { "alpha_v" } else { "alpha_u" };
            return Err(Error::input(
                params.location(),
                format!(
                    "{} has an anisotropic roughness without \"{missing}\"",
                    params.node().describe()
                ),
            )
            .with_help("give both alpha_u and alpha_v"));
        }
        let u = float_texture(params, "alpha_u", 0.1, 0.0, true, f32::INFINITY, textures)?;
        let v = float_texture(params, "alpha_v", 0.1, 0.0, true, f32::INFINITY, textures)?;
        return Ok((u, v));
    }
    let alpha = float_texture(params, "alpha", 0.1, 0.0, true, f32::INFINITY, textures)?;
    Ok((alpha.clone(), alpha))
}

/// A conductor's η and k: `material` (a preset; "none", the default, is a perfect mirror with
/// η = 0, k = 1), or `eta` and `k` as spectra, colours (upsampled without bounds) or textures.
fn conductor_ior(params: &Params, textures: &mut TextureCache) -> Result<(Texture, Texture)> {
    let material = params.string("material", "none")?;
    if material == "none" {
        let eta = spectrum_texture(params, "eta", 0.0, Range::Unbounded, textures)?;
        let k = spectrum_texture(params, "k", 1.0, Range::Unbounded, textures)?;
        return Ok((eta, k));
    }
    if has(params, "eta") || has(params, "k") {
        return Err(Error::input(
            params.location_of("material"),
            "give either a \"material\" preset or \"eta\" and \"k\", not both",
        ));
    }
    let Some(preset) = CONDUCTORS.iter().find(|c| c.name == material) else {
        let names: Vec<&str> = CONDUCTORS.iter().map(|c| c.name).collect();
        return Err(Error::input(
            params.location_of("material"),
            format!("unknown conductor material \"{material}\""),
        )
        .with_help(format!("known materials: none, {}", names.join(", "))));
    };
    let table = |column: usize| {
        let samples: Vec<(f32, f32)> = preset
            .samples
            .iter()
            .map(|s| (s.0, if column == 1 { s.1 } else { s.2 }))
            .collect();
        PiecewiseLinear::new(&samples)
            .map(|table| Texture::Constant(Spectrum::PiecewiseLinear(table)))
            .unwrap_or_else(|| Texture::constant(0.0))
    };
    Ok((table(1), table(2)))
}

/// `int_ior` and `ext_ior` (defaults `default_interior` and "air"). With `must_differ`, equal
/// constant indices are refused (Mitsuba's rule for rough interfaces).
fn relative_ior(params: &Params, default_interior: &str, must_differ: bool) -> Result<RelativeIor> {
    let interior = ior(params, "int_ior", default_interior)?;
    let exterior = ior(params, "ext_ior", "air")?;
    if must_differ && interior == exterior {
        return Err(Error::input(
            params.location_of("int_ior"),
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
fn constant_relative_ior(params: &Params, must_differ: bool) -> Result<f32> {
    let eta = relative_ior(params, "polypropylene", must_differ)?;
    match (&eta.interior, &eta.exterior) {
        (Ior::Constant(i), Ior::Constant(e)) => Ok(i / e),
        _ => Err(Error::input(
            params.location_of("int_ior"),
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
fn ior(params: &Params, name: &'static str, default: &str) -> Result<Ior> {
    let (value, location) = if let Some(child) = params.named_child(name) {
        (dispersion_formula(&child.node)?, &child.location)
    } else if let Some(property) = params.property(name) {
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

/// A nested `<spectrum type="sellmeier">` (a `glass` name, or `b1`–`b3`, `c1`–`c3` with C in
/// µm²) or `<spectrum type="cauchy">` (`a`, default 1.5; `b` in µm², `c` in µm⁴, default 0).
fn dispersion_formula(node: &PluginNode) -> Result<Ior> {
    let params = Params::new(node);
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
    let number = |name: &'static str, default: f64| -> Result<f32> {
        let v = params.float(name, default)?;
        if !v.is_finite() {
            return Err(Error::input(
                params.location_of(name),
                format!("\"{name}\" must be a finite number"),
            ));
        }
        Ok(v as f32)
    };
    let ior = match node.plugin_type.as_str() {
        "sellmeier" => match params.string_opt("glass")? {
            Some(glass) => {
                let (b, c) = sellmeier_glass(glass).ok_or_else(|| {
                    let names: Vec<&str> = prism_core::spectrum::ior::SELLMEIER_GLASSES
                        .iter()
                        .map(|g| g.0)
                        .collect();
                    Error::input(
                        params.location_of("glass"),
                        format!("unknown glass \"{glass}\""),
                    )
                    .with_help(format!("known glasses: {}", names.join(", ")))
                })?;
                Ior::Sellmeier { b, c }
            }
            None => Ior::Sellmeier {
                b: [number("b1", 0.0)?, number("b2", 0.0)?, number("b3", 0.0)?],
                c: [number("c1", 0.0)?, number("c2", 0.0)?, number("c3", 0.0)?],
            },
        },
        "cauchy" => Ior::Cauchy {
            a: number("a", 1.5)?,
            b: number("b", 0.0)?,
            c: number("c", 0.0)?,
        },
        _ => return Err(unsupported()),
    };
    params.finish()?;
    Ok(ior)
}
