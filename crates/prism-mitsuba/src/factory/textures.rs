//! Texture plugins (`bitmap`, `checkerboard`) and texture-valued parameters: any colour or
//! number a BSDF takes may be given as a value (`<rgb>`, `<spectrum>`, `<float>`) or as a nested
//! `<texture>` (inline or a `<ref name="..." id="..."/>` to a texture declared at the top level).
//!
//! A texture is built for the way it is read ([`TextureUse`]): colours are upsampled per texel,
//! numbers keep one value per texel, normal maps keep raw RGB. Built textures are cached per
//! (element, use), so a bitmap referenced by many materials is read and stored once.

use std::collections::HashMap;
use std::sync::Arc;

use super::spectra::{Range, spectrum_param};
use crate::description::{PluginClass, PluginNode, PropertyValue, SpectrumValue};
use crate::params::Params;
use prism_core::error::{Error, Result};
use prism_core::image::{Encoding, read_bitmap};
use prism_core::texture::Texture;
use prism_core::texture::{
    BitmapTexture, Checkerboard, FilterType, TextureUse, UvTransform, WrapMode,
};

/// The texture types this factory knows.
pub const SUPPORTED_TEXTURES: &[&str] = &["bitmap", "checkerboard"];

/// Textures built so far, by element and use.
#[derive(Default)]
pub struct TextureCache {
    built: HashMap<(*const PluginNode, TextureUse), Texture>,
}

impl TextureCache {
    /// Whether the element has been built for any use.
    pub fn contains(&self, node: &PluginNode) -> bool {
        let key = node as *const PluginNode;
        self.built.keys().any(|(k, _)| *k == key)
    }
}

/// The spectral parameter `name`: a value as [`spectrum_param`] reads it, or a nested texture
/// read as colours.
pub fn spectrum_texture(
    params: &Params,
    name: &'static str,
    default: f32,
    range: Range,
    cache: &mut TextureCache,
) -> Result<Texture> {
    if let Some(child) = params.named_child(name) {
        return nested_texture(params, name, &child.node, TextureUse::Spectral, cache);
    }
    Ok(Texture::Constant(spectrum_param(
        params, name, default, range,
    )?))
}

/// The optional spectral parameter `name` (None when absent).
pub fn optional_spectrum_texture(
    params: &Params,
    name: &'static str,
    range: Range,
    cache: &mut TextureCache,
) -> Result<Option<Texture>> {
    if params.property(name).is_none() && params.named_child(name).is_none() {
        return Ok(None);
    }
    spectrum_texture(params, name, 1.0, range, cache).map(Some)
}

/// The scalar parameter `name`: a `<float>` (or a uniform `<spectrum>`), or a nested texture
/// read as numbers. Constants are checked to lie in [`min`, `max`] (`min_exclusive`: above
/// `min`); textures are clamped where they are used.
#[allow(clippy::too_many_arguments)]
pub fn float_texture(
    params: &Params,
    name: &'static str,
    default: f32,
    min: f32,
    min_exclusive: bool,
    max: f32,
    cache: &mut TextureCache,
) -> Result<Texture> {
    if let Some(child) = params.named_child(name) {
        return nested_texture(params, name, &child.node, TextureUse::Scalar, cache);
    }
    let Some(property) = params.property(name) else {
        return Ok(Texture::constant(default));
    };
    let value =
        match &property.value {
            PropertyValue::Float(v) => *v,
            PropertyValue::Integer(v) => *v as f64,
            PropertyValue::Spectrum(SpectrumValue::Uniform(v)) => *v,
            other => {
                return Err(Error::input(
                &property.location,
                format!(
                    "parameter \"{name}\" of {} must be a number or a texture, but a {} was given",
                    params.node().describe(),
                    other.type_name()
                ),
            )
            .with_help(format!("write it as <float name=\"{name}\" value=\"...\"/>")));
            }
        } as f32;
    let above_min = if min_exclusive {
        value > min
    } else {
        value >= min
    };
    if !(above_min && value <= max && value.is_finite()) {
        let range = match (min_exclusive, max.is_finite()) {
            (true, true) => format!("({min}, {max}]"),
            (true, false) => format!("greater than {min}"),
            (false, true) => format!("[{min}, {max}]"),
            (false, false) => format!("at least {min}"),
        };
        return Err(Error::input(
            &property.location,
            format!(
                "parameter \"{name}\" of {} is {value}, but it must be {}{range}",
                params.node().describe(),
                if range.starts_with(['(', '[']) {
                    "in "
                } else {
                    ""
                }
            ),
        ));
    }
    Ok(Texture::constant(value))
}

/// A nested plugin given for parameter `name`: it must be a texture.
fn nested_texture(
    params: &Params,
    name: &str,
    node: &PluginNode,
    usage: TextureUse,
    cache: &mut TextureCache,
) -> Result<Texture> {
    if node.class != PluginClass::Texture {
        return Err(Error::input(
            &node.location,
            format!(
                "{} cannot give parameter \"{name}\" of {}",
                node.describe(),
                params.node().describe()
            ),
        )
        .with_help("give a value (<rgb>, <spectrum>, <float>) or a <texture>"));
    }
    build_texture(node, usage, cache)
}

/// Builds (or finds in the cache) the texture an element describes, for a use.
pub fn build_texture(
    node: &PluginNode,
    usage: TextureUse,
    cache: &mut TextureCache,
) -> Result<Texture> {
    let key = (node as *const PluginNode, usage);
    if let Some(texture) = cache.built.get(&key) {
        return Ok(texture.clone());
    }
    let params = Params::new(node);
    let texture = match node.plugin_type.as_str() {
        "bitmap" => build_bitmap(&params, usage)?,
        "checkerboard" => {
            let color = |name, default, cache: &mut TextureCache| match usage {
                TextureUse::Scalar => {
                    float_texture(&params, name, default, 0.0, false, f32::INFINITY, cache)
                }
                _ => spectrum_texture(&params, name, default, Range::Albedo, cache),
            };
            let color0 = color("color0", 0.4, cache)?;
            let color1 = color("color1", 0.2, cache)?;
            Texture::Checkerboard(Box::new(Checkerboard {
                color0,
                color1,
                to_uv: UvTransform::from_matrix(&params.transform("to_uv")?),
            }))
        }
        other => {
            return Err(
                Error::input(&node.location, format!("unknown texture type \"{other}\""))
                    .with_help(format!(
                        "supported texture types: {}",
                        SUPPORTED_TEXTURES.join(", ")
                    )),
            );
        }
    };
    params.finish()?;
    cache.built.insert(key, texture.clone());
    Ok(texture)
}

/// A string parameter that must be one of `choices`.
fn choice<'a>(
    params: &Params<'a>,
    name: &'static str,
    default: &'a str,
    choices: &[&str],
) -> Result<&'a str> {
    let value = params.string(name, default)?;
    if choices.contains(&value) {
        return Ok(value);
    }
    Err(Error::input(
        params.location_of(name),
        format!(
            "parameter \"{name}\" of {} is \"{value}\"",
            params.node().describe()
        ),
    )
    .with_help(format!("use one of: {}", choices.join(", "))))
}

fn build_bitmap(params: &Params, usage: TextureUse) -> Result<Texture> {
    let node = params.node();
    let filename = params.string_opt("filename")?.ok_or_else(|| {
        Error::input(
            &node.location,
            format!("{} needs a \"filename\"", node.describe()),
        )
        .with_help("add <string name=\"filename\" value=\"image.png\"/>")
    })?;
    let location = params.location_of("filename");
    let filter = match choice(params, "filter_type", "bilinear", &["bilinear", "nearest"])? {
        "nearest" => FilterType::Nearest,
        _ => FilterType::Bilinear,
    };
    let wrap = match choice(
        params,
        "wrap_mode",
        "repeat",
        &["repeat", "mirror", "clamp"],
    )? {
        "mirror" => WrapMode::Mirror,
        "clamp" => WrapMode::Clamp,
        _ => WrapMode::Repeat,
    };
    // Storage precision and GPU acceleration do not apply here; accepted for compatibility.
    choice(params, "format", "auto", &["auto", "variant", "fp16"])?;
    params.boolean("accel", true)?;
    let raw = params.boolean("raw", false)?;
    let to_uv = UvTransform::from_matrix(&params.transform("to_uv")?);
    let path = node.resolve_file(filename, location)?;
    let mut bitmap = read_bitmap(&path).map_err(|e| e.at(location))?;
    if usage == TextureUse::Rgb && !raw && bitmap.encoding == Encoding::Srgb {
        return Err(Error::input(
            params.location(),
            format!(
                "the normal map \"{filename}\" would be decoded from sRGB, which bends its normals"
            ),
        )
        .with_help(
            "add <boolean name=\"raw\" value=\"true\"/> to the texture, as Mitsuba requires",
        ));
    }
    if !raw {
        bitmap.linearize();
    }
    Ok(Texture::Bitmap(Arc::new(BitmapTexture::new(
        &bitmap, usage, filter, wrap, to_uv,
    ))))
}
