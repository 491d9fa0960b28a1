//! Texture plugins (`bitmap`, `checkerboard`, `mesh_attribute`, `rawconstant`, `volume`, and
//! pbrt-v4's `scale`, `mix` and `directionmix`) and texture-valued parameters: any colour or
//! number a BSDF takes may be given as a value (`<rgb>`, `<spectrum>`, `<float>`) or as a nested
//! `<texture>` (inline or a `<ref name="..." id="..."/>` to a texture declared at the top level).
//!
//! A texture is built for the way it is read ([`TextureUse`]): colours are upsampled per texel,
//! numbers keep one value per texel, normal maps keep raw RGB. Built textures are cached per
//! (element, use), so a bitmap referenced by many materials is read and stored once.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use super::media::volume_param;
use super::spectra::spectrum_param;
use crate::description::{PluginClass, PluginNode, PropertyValue, SpectrumValue};
use crate::file_cache;
use crate::params::Params;
use crate::registry::Range;
use crate::registry::{
    Bounds, Choice, Default, Origin, ParamKind, ParamSpec, Plugin, Registry, params,
};
use prism_core::error::{Error, Result};
use prism_core::geometry::interaction::MAX_MESH_ATTRIBUTES;
use prism_core::image::{Bitmap, Encoding, decode_bitmap_file};
use prism_core::medium::Volume;
use prism_core::spectrum::{LAMBDA_MAX, LAMBDA_MIN, RgbIntent, Spectrum};
use prism_core::texture::{
    BitmapTexture, Checkerboard, FilterType, TextureUse, UvTransform, WrapMode,
};
use prism_core::texture::{
    DirectionMixTexture, MeshAttributeTexture, MixTexture, ScaledTexture, Texture, VolumeTexture,
};

type Build = fn(&Params, TextureUse, &mut TextureCache) -> Result<Texture>;

pub static TEXTURES: Registry<Build> = Registry {
    class: PluginClass::Texture,
    plugins: &[
        Plugin {
            name: "bitmap",
            origin: Origin::Mitsuba3,
            summary: "An image looked up at the surface's texture coordinates, (0, 0) at its \
                      top-left corner. 8- and 16-bit images are decoded from sRGB unless `raw`; \
                      colours are upsampled per texel; alpha is ignored; a colour image read \
                      as a number gives its luminance.",
            params: &[FILENAME, FILTER_TYPE, WRAP_MODE, RAW, TO_UV, FORMAT, ACCEL],
            build: |params, usage, _| build_bitmap(params, usage),
        },
        Plugin {
            name: "checkerboard",
            origin: Origin::Mitsuba3,
            summary: "Two textures alternating: `color0` where frac(u) > ½ and frac(v) > ½ agree, \
                      `color1` where they differ; read as a number, the opposite phase, as in \
                      Mitsuba 3.",
            params: &[COLOR0, COLOR1, TO_UV],
            build: build_checkerboard,
        },
        Plugin {
            name: "mesh_attribute",
            origin: Origin::Mitsuba3,
            summary: "A colour the shape's mesh carries: `vertex_color` (PLY `red green blue` \
                      or `r g b`, serialized colours) interpolated barycentrically, or \
                      `face_color` (a PLY face's `r g b`) constant over each face, then \
                      upsampled, as Mitsuba 3.9 does, times `scale`. \
                      Read as a colour only (Mitsuba reads a three-channel attribute as nothing \
                      else); a shape whose mesh lacks the attribute is an error.",
            params: &[ATTRIBUTE_NAME, ATTRIBUTE_SCALE],
            build: build_mesh_attribute,
        },
        Plugin {
            name: "rawconstant",
            origin: Origin::Mitsuba3,
            summary: "A constant used as it is, never upsampled: a `<float>` (read as a number, or \
                      as the same value at every wavelength) or a `<vector>` of three values \
                      (read only as raw RGB, as by `normalmap`).",
            params: &[RAW_VALUE],
            build: |params, usage, _| build_rawconstant(params, usage),
        },
        Plugin {
            name: "volume",
            origin: Origin::Mitsuba3,
            summary: "A volume (`constvolume`, `gridvolume`, or a plain value) looked up at the \
                      surface point's world position, for solid textures and surfaces without \
                      a (u, v) map. A three-channel grid gives a colour only, as in Mitsuba 3's \
                      spectral variants; emitters, which look textures up by (u, v) alone, \
                      normal maps and bump maps refuse it.",
            params: &[VOLUME],
            build: build_volume,
        },
        Plugin {
            name: "scale",
            origin: Origin::Prism,
            summary: "pbrt-v4's `scale` texture: `tex` · `scale`, a texture (a colour, or a number \
                      where the texture is read as one) times a number-valued texture.",
            params: &[SCALED_TEX, SCALE_FACTOR],
            build: build_scale,
        },
        Plugin {
            name: "mix",
            origin: Origin::Prism,
            summary: "pbrt-v4's `mix` texture: (1 − `amount`) · `tex1` + `amount` · `tex2`, two \
                      textures blended by a number-valued texture.",
            params: &[TEX1, TEX2, AMOUNT],
            build: build_mix,
        },
        Plugin {
            name: "directionmix",
            origin: Origin::Prism,
            summary: "pbrt-v4's `directionmix` texture: a · `tex1` + (1 − a) · `tex2` with a the \
                      absolute value of n · `dir`, two textures blended by the direction of the \
                      surface's geometric normal n. Emitters, which look textures up by (u, v) \
                      alone, refuse it.",
            params: &[DIRECTION_TEX1, DIRECTION_TEX2, DIRECTION],
            build: build_direction_mix,
        },
    ],
};

params! {
    ATTRIBUTE_NAME = ParamSpec::new("name", ParamKind::String, Default::Required, "the attribute, starting with `vertex_` or `face_`");
    ATTRIBUTE_SCALE = ParamSpec::new("scale", ParamKind::Float, Default::Float(1.0), "a factor applied to the attribute's value");
    FILENAME = ParamSpec::new("filename", ParamKind::String, Default::Required, "the image: PNG, JPEG, BMP, TGA, PPM/PGM (8-bit: sRGB), OpenEXR, Radiance HDR or PFM (linear)");
    FILTER_TYPE = ParamSpec::new("filter_type", ParamKind::Choice(&[Choice::new("bilinear", &FilterType::Bilinear), Choice::new("nearest", &FilterType::Nearest), Choice::new("trilinear", &FilterType::Bilinear), Choice::new("ewa", &FilterType::Bilinear)]), Default::Str("bilinear"), "interpolate the four nearest texels, or take the one containing the point; Mitsuba 0.6's mip-mapped `trilinear` and `ewa` are read as `bilinear` (docs/mitsuba-compatibility.md)");
    WRAP_MODE = ParamSpec::new("wrap_mode", ParamKind::Choice(&[Choice::new("repeat", &WrapMode::Repeat), Choice::new("mirror", &WrapMode::Mirror), Choice::new("clamp", &WrapMode::Clamp)]), Default::Str("repeat"), "how coordinates outside [0, 1] map into the image");
    RAW = ParamSpec::new("raw", ParamKind::Boolean, Default::Boolean(false), "read 8- and 16-bit values as they are, without sRGB decoding (normal maps need it)");
    TO_UV = ParamSpec::new("to_uv", ParamKind::Transform, Default::Text("identity"), "an affine map of the texture coordinates");
    FORMAT = ParamSpec::new("format", ParamKind::Choice(&Choice::accepted(["auto", "variant", "fp16"])), Default::Str("auto"), "accepted; texels are always stored in full precision");
    ACCEL = ParamSpec::new("accel", ParamKind::Boolean, Default::Boolean(true), "accepted; Mitsuba's GPU texture acceleration does not apply");
    COLOR0 = ParamSpec::new("color0", ParamKind::Spectrum { range: Range::Albedo, textured: true, }, Default::Float(0.4), "the first colour (a number when the texture is read as one)");
    COLOR1 = ParamSpec::new("color1", ParamKind::Spectrum { range: Range::Albedo, textured: true, }, Default::Float(0.2), "the second colour");
    RAW_VALUE = ParamSpec::new("value", ParamKind::FloatOrVector, Default::Required, "the value: one number, or three");
    SCALED_TEX = ParamSpec::new("tex", ParamKind::Spectrum { range: Range::Coefficient, textured: true, }, Default::Float(1.0), "the texture scaled (a number when the texture is read as one)");
    SCALE_FACTOR = ParamSpec::new("scale", ParamKind::FloatTexture(Bounds::FINITE_NON_NEGATIVE), Default::Float(1.0), "the factor, a number or a texture read as numbers");
    TEX1 = ParamSpec::new("tex1", ParamKind::Spectrum { range: Range::Coefficient, textured: true, }, Default::Float(0.0), "the texture where `amount` is 0 (a number when the texture is read as one)");
    TEX2 = ParamSpec::new("tex2", ParamKind::Spectrum { range: Range::Coefficient, textured: true, }, Default::Float(1.0), "the texture where `amount` is 1");
    VOLUME = ParamSpec::new("volume", ParamKind::Volume(Range::Coefficient), Default::Float(0.75), "the volume, placed in the world by its own `to_world`");
    DIRECTION_TEX1 = ParamSpec::new("tex1", ParamKind::Spectrum { range: Range::Coefficient, textured: true, }, Default::Float(0.0), "the texture where the normal is parallel to `dir` (a number when the texture is read as one)");
    DIRECTION_TEX2 = ParamSpec::new("tex2", ParamKind::Spectrum { range: Range::Coefficient, textured: true, }, Default::Float(1.0), "the texture where the normal is perpendicular to `dir`");
    DIRECTION = ParamSpec::new("dir", ParamKind::Vector, Default::Text("(0, 1, 0)"), "the direction (world space, any non-zero length)");
    AMOUNT = ParamSpec::new("amount", ParamKind::FloatTexture(Bounds::UNIT), Default::Float(0.5), "the weight of `tex2`, a number or a texture read as numbers");
}

/// Textures built so far, by element and use.
#[derive(Default)]
pub struct TextureCache {
    built: HashMap<(*const PluginNode, TextureUse), Texture>,
    /// The mesh attribute names the textures read, by slot.
    attribute_slots: Vec<String>,
    /// The slots read by the textures built or fetched since [`Self::take_used_slots`].
    used_slots: Vec<u8>,
    /// The mesh attributes (slot, name) each material's textures read, by material index.
    material_attributes: HashMap<u32, Vec<(u8, String)>>,
    /// The names of the mesh attributes some texture reads as a number.
    numeric_attributes: Vec<String>,
}

impl TextureCache {
    /// The mesh attribute slots read by the textures built or fetched since the last call, and
    /// the attribute name of each.
    pub fn take_used_slots(&mut self) -> Vec<(u8, String)> {
        let mut slots = std::mem::take(&mut self.used_slots);
        slots.sort_unstable();
        slots.dedup();
        slots
            .into_iter()
            .map(|slot| (slot, self.attribute_slots[usize::from(slot)].clone()))
            .collect()
    }

    /// Records the mesh attributes that material `index` reads.
    pub fn set_material_attributes(&mut self, index: u32, attributes: Vec<(u8, String)>) {
        if !attributes.is_empty() {
            self.material_attributes.insert(index, attributes);
        }
    }

    /// Whether some texture reads the mesh attribute `name` as a number.
    pub fn reads_as_number(&self, name: &str) -> bool {
        self.numeric_attributes.iter().any(|n| n == name)
    }

    /// The mesh attributes (slot, name) that material `index` reads; none for most.
    pub fn material_attributes(&self, index: u32) -> &[(u8, String)] {
        self.material_attributes
            .get(&index)
            .map_or(&[], |attributes| attributes.as_slice())
    }

    fn note_use(&mut self, texture: &Texture) {
        if let Texture::MeshAttribute(attribute) = texture {
            self.used_slots.push(attribute.slot);
        }
    }

    /// Whether the element has been built for any use.
    pub fn contains(&self, node: &PluginNode) -> bool {
        let key = node as *const PluginNode;
        self.built.keys().any(|(k, _)| *k == key)
    }
}

/// The spectral parameter `spec`: a value as [`spectrum_param`] reads it, or a nested texture
/// read as colours.
pub fn spectrum_texture(
    params: &Params,
    spec: &ParamSpec,
    cache: &mut TextureCache,
) -> Result<Texture> {
    if let Some(child) = params.named_child(spec) {
        return nested_texture(params, spec.name, &child.node, TextureUse::Spectral, cache);
    }
    Ok(Texture::Constant(spectrum_param(params, spec)?))
}

/// The optional spectral parameter `spec` (None when absent).
pub fn optional_spectrum_texture(
    params: &Params,
    spec: &ParamSpec,
    cache: &mut TextureCache,
) -> Result<Option<Texture>> {
    if !params.has(spec) {
        return Ok(None);
    }
    spectrum_texture(params, spec, cache).map(Some)
}

/// The scalar parameter `spec`: a `<float>` (or a uniform `<spectrum>`), an `<rgb>` read as
/// Mitsuba 3 reads a colour where it wants a number, or a nested texture read as numbers.
/// Constants are checked to lie within the declared bounds; textures are clamped where they are
/// used.
pub fn float_texture(
    params: &Params,
    spec: &ParamSpec,
    cache: &mut TextureCache,
) -> Result<Texture> {
    let ParamKind::FloatTexture(bounds) = spec.kind else {
        panic!("\"{}\" is not a float texture", spec.name);
    };
    if let Some(child) = params.named_child(spec) {
        return nested_texture(params, spec.name, &child.node, TextureUse::Scalar, cache);
    }
    if let Some(property) = params.property(spec)
        && let PropertyValue::Rgb(rgb) = &property.value
    {
        let value = rgb_as_number(rgb.map(|c| c as f32));
        if !(rgb.iter().all(|c| c.is_finite() && *c >= 0.0) && bounds.contains(value)) {
            return Err(Error::input(
                &property.location,
                format!(
                    "parameter \"{}\" of {} is the colour {rgb:?}, whose mean {value} must be {}",
                    spec.name,
                    params.node().describe(),
                    bounds.describe()
                ),
            ));
        }
        return Ok(Texture::constant(value));
    }
    float_value(params, spec, bounds).map(Texture::constant)
}

/// The number an `<rgb>` gives where a number is wanted (an opacity, a weight): Mitsuba 3's
/// spectral variants upsample it as a reflectance and take `srgb_model_mean`, the mean of the
/// spectrum at 16 wavelengths spaced evenly over 360–830 nm (`include/mitsuba/render/srgb.h`).
/// Grey gives its value exactly.
fn rgb_as_number(rgb: [f32; 3]) -> f32 {
    const SAMPLES: usize = 16;
    let spectrum = Spectrum::from_rgb(rgb, RgbIntent::Albedo);
    let sum: f32 = (0..SAMPLES)
        .map(|i| {
            let t = i as f32 / (SAMPLES - 1) as f32;
            spectrum.value(LAMBDA_MIN + t * (LAMBDA_MAX - LAMBDA_MIN))
        })
        .sum();
    sum / SAMPLES as f32
}

/// The number given for `spec` as a `<float>` (or a uniform `<spectrum>`), or its declared
/// default; it must lie within `bounds`.
pub fn float_value(params: &Params, spec: &ParamSpec, bounds: Bounds) -> Result<f32> {
    let name = spec.name;
    let Some(property) = params.property(spec) else {
        let Default::Float(default) = spec.default else {
            panic!("\"{name}\" has no numeric default");
        };
        return Ok(default as f32);
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
    if !bounds.contains(value) {
        return Err(Error::input(
            &property.location,
            format!(
                "parameter \"{name}\" of {} is {value}, but it must be {}",
                params.node().describe(),
                bounds.describe()
            ),
        ));
    }
    Ok(value)
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
    if let Some(texture) = cache.built.get(&key).cloned() {
        cache.note_use(&texture);
        return Ok(texture);
    }
    let plugin = TEXTURES.find(node)?;
    let params = Params::new(node, plugin.params);
    let texture = (plugin.build)(&params, usage, cache)?;
    params.finish()?;
    cache.note_use(&texture);
    cache.built.insert(key, texture.clone());
    Ok(texture)
}

/// Mitsuba's `mesh_attribute`: the attribute gets a slot (shared by every texture reading the
/// same name); the shapes are checked to have it when their BSDFs are built.
fn build_mesh_attribute(
    params: &Params,
    usage: TextureUse,
    cache: &mut TextureCache,
) -> Result<Texture> {
    let name = params.string_opt(&ATTRIBUTE_NAME)?.ok_or_else(|| {
        Error::input(
            &params.node().location,
            "a \"mesh_attribute\" texture needs the \"name\" of the attribute",
        )
        .with_help("add <string name=\"name\" value=\"vertex_color\"/>")
    })?;
    let location = params.location_of(&ATTRIBUTE_NAME);
    if !name.starts_with("vertex_") && !name.starts_with("face_") {
        return Err(Error::input(
            location,
            format!(
                "invalid mesh attribute name \"{name}\": it must start with \"vertex_\" or \
                 \"face_\""
            ),
        )
        .with_help(
            "Prism's meshes carry \"vertex_color\" (PLY and serialized vertex colours) and \
             \"face_color\" (PLY face colours)",
        ));
    }
    match usage {
        TextureUse::Spectral => {}
        TextureUse::Scalar => {
            if !cache.reads_as_number(name) {
                cache.numeric_attributes.push(name.to_string());
            }
        }
        TextureUse::Rgb | TextureUse::Emission => {
            return Err(Error::input(
                &params.node().location,
                format!(
                    "the mesh attribute \"{name}\" is read here as an RGB triple or an \
                     emission; Prism reads mesh attributes only as colours and numbers"
                ),
            )
            .with_help("use it for a colour parameter such as a reflectance, or a weight"));
        }
    }
    let scale = params.float(&ATTRIBUTE_SCALE)? as f32;
    let slot = match cache.attribute_slots.iter().position(|n| n == name) {
        Some(slot) => slot,
        None if cache.attribute_slots.len() < MAX_MESH_ATTRIBUTES => {
            cache.attribute_slots.push(name.to_string());
            cache.attribute_slots.len() - 1
        }
        None => {
            return Err(Error::input(
                location,
                format!(
                    "a scene may read at most {MAX_MESH_ATTRIBUTES} different mesh attributes; \
                     this is one more"
                ),
            ));
        }
    };
    Ok(Texture::MeshAttribute(MeshAttributeTexture {
        slot: slot as u8,
        scale,
    }))
}

/// A colour `spec` of a texture that an emitter reads: a value as a reflectance (Mitsuba 3
/// reads an emitter's checkerboard so, without a D65 factor, and refuses values above 1), a
/// nested texture read as emission.
fn emission_texture(
    params: &Params,
    spec: &ParamSpec,
    cache: &mut TextureCache,
) -> Result<Texture> {
    if let Some(child) = params.named_child(spec) {
        return nested_texture(params, spec.name, &child.node, TextureUse::Emission, cache);
    }
    Ok(Texture::Constant(spectrum_param(params, spec)?))
}

params! {
    /// Read as a number, a checkerboard's colours are numbers too.
    SCALAR_COLOR0 = ParamSpec::new("color0", ParamKind::FloatTexture(Bounds::NON_NEGATIVE), Default::Float(0.4), "");
    SCALAR_COLOR1 = ParamSpec::new("color1", ParamKind::FloatTexture(Bounds::NON_NEGATIVE), Default::Float(0.2), "");
}

fn build_checkerboard(
    params: &Params,
    usage: TextureUse,
    cache: &mut TextureCache,
) -> Result<Texture> {
    let (color0, color1) = match usage {
        TextureUse::Scalar => (
            float_texture(params, &SCALAR_COLOR0, cache)?,
            float_texture(params, &SCALAR_COLOR1, cache)?,
        ),
        TextureUse::Spectral | TextureUse::Rgb => (
            spectrum_texture(params, &COLOR0, cache)?,
            spectrum_texture(params, &COLOR1, cache)?,
        ),
        TextureUse::Emission => (
            emission_texture(params, &COLOR0, cache)?,
            emission_texture(params, &COLOR1, cache)?,
        ),
    };
    Ok(Texture::Checkerboard(Box::new(Checkerboard {
        color0,
        color1,
        to_uv: UvTransform::from_matrix(&params.transform(&TO_UV)?),
    })))
}

params! {
    /// Read as a number, the textures `scale` and `mix` combine are numbers too.
    SCALAR_SCALED_TEX = ParamSpec::new("tex", ParamKind::FloatTexture(Bounds::FINITE_NON_NEGATIVE), Default::Float(1.0), "");
    SCALAR_TEX1 = ParamSpec::new("tex1", ParamKind::FloatTexture(Bounds::FINITE_NON_NEGATIVE), Default::Float(0.0), "");
    SCALAR_TEX2 = ParamSpec::new("tex2", ParamKind::FloatTexture(Bounds::FINITE_NON_NEGATIVE), Default::Float(1.0), "");
}

/// The texture `spec` (a colour, or `scalar` where the texture is read as a number) of a
/// texture built for `usage`.
fn operand(
    params: &Params,
    spec: &ParamSpec,
    scalar: &ParamSpec,
    usage: TextureUse,
    cache: &mut TextureCache,
) -> Result<Texture> {
    match usage {
        TextureUse::Scalar => float_texture(params, scalar, cache),
        TextureUse::Spectral | TextureUse::Rgb => spectrum_texture(params, spec, cache),
        TextureUse::Emission => emission_texture(params, spec, cache),
    }
}

fn build_scale(params: &Params, usage: TextureUse, cache: &mut TextureCache) -> Result<Texture> {
    Ok(Texture::Scale(Box::new(ScaledTexture {
        texture: operand(params, &SCALED_TEX, &SCALAR_SCALED_TEX, usage, cache)?,
        scale: float_texture(params, &SCALE_FACTOR, cache)?,
    })))
}

fn build_mix(params: &Params, usage: TextureUse, cache: &mut TextureCache) -> Result<Texture> {
    Ok(Texture::Mix(Box::new(MixTexture {
        tex1: operand(params, &TEX1, &SCALAR_TEX1, usage, cache)?,
        tex2: operand(params, &TEX2, &SCALAR_TEX2, usage, cache)?,
        amount: float_texture(params, &AMOUNT, cache)?,
    })))
}

fn build_direction_mix(
    params: &Params,
    usage: TextureUse,
    cache: &mut TextureCache,
) -> Result<Texture> {
    let node = params.node();
    if usage == TextureUse::Emission {
        return Err(Error::input(
            &node.location,
            format!(
                "{} blends by the surface's normal, but an emitter looks its textures up by \
                 (u, v) alone",
                node.describe()
            ),
        )
        .with_help("give the emitter a bitmap, a pattern or a value"));
    }
    let dir = params
        .vector_opt(&DIRECTION)?
        .unwrap_or(glam::DVec3::Y)
        .as_vec3();
    let tex1 = operand(params, &DIRECTION_TEX1, &SCALAR_TEX1, usage, cache)?;
    let tex2 = operand(params, &DIRECTION_TEX2, &SCALAR_TEX2, usage, cache)?;
    let texture = DirectionMixTexture::new(tex1, tex2, dir).ok_or_else(|| {
        Error::input(
            params.location_of(&DIRECTION),
            format!(
                "the direction \"dir\" of {} is {dir}, which has no direction",
                node.describe()
            ),
        )
        .with_help("give a non-zero, finite vector")
    })?;
    Ok(Texture::DirectionMix(Box::new(texture)))
}

/// Mitsuba's `volume` texture, refused where it would be read without a surface point
/// (emissions) or as what Mitsuba's spectral variants cannot read a volume as: a colour grid as
/// a number, any volume as raw RGB.
fn build_volume(params: &Params, usage: TextureUse, _: &mut TextureCache) -> Result<Texture> {
    let node = params.node();
    let refuse = |message: &str, help: &str| {
        Err(Error::input(&node.location, format!("{} {message}", node.describe())).with_help(help))
    };
    let volume = volume_param(params, &VOLUME)?;
    match (usage, &volume) {
        (TextureUse::Emission, _) => refuse(
            "is looked up at a surface point's position, but an emitter looks its textures up \
             by (u, v) alone",
            "give the emitter a bitmap, a pattern or a value",
        ),
        (TextureUse::Rgb, _) => refuse(
            "is read here as a raw RGB triple (a normal map); Prism reads a volume texture only \
             as a colour or a number",
            "give the normal map a bitmap with raw=\"true\"",
        ),
        (TextureUse::Scalar, Volume::SpectralGrid(_)) => refuse(
            "holds a three-channel grid, a colour, where a number is wanted (Mitsuba 3's spectral \
             variants refuse it too)",
            "store the number in a one-channel grid",
        ),
        _ => Ok(Texture::Volume(Arc::new(VolumeTexture { volume }))),
    }
}

fn build_rawconstant(params: &Params, usage: TextureUse) -> Result<Texture> {
    let node = params.node();
    let Some(property) = params.property(&RAW_VALUE) else {
        return Err(Error::input(
            &node.location,
            format!("{} needs a \"value\"", node.describe()),
        )
        .with_help(
            "add <float name=\"value\" .../> or <vector name=\"value\" x=... y=... z=.../>",
        ));
    };
    let location = &property.location;
    let not_finite = || {
        Error::input(
            location,
            format!("the value of {} must be finite", node.describe()),
        )
    };
    match &property.value {
        PropertyValue::Float(_) | PropertyValue::Integer(_) => {
            let Some(v) = params.float_opt(&RAW_VALUE)? else {
                return Err(not_finite());
            };
            let v = v as f32;
            if !v.is_finite() {
                return Err(not_finite());
            }
            Ok(Texture::constant(v))
        }
        PropertyValue::Vector(v) => {
            let rgb = v.as_vec3().to_array();
            if !rgb.iter().all(|c| c.is_finite()) {
                return Err(not_finite());
            }
            if usage != TextureUse::Rgb {
                return Err(Error::input(
                    location,
                    format!(
                        "{} holds three values, which can only be read as raw RGB (a normal map)",
                        node.describe()
                    ),
                )
                .with_help("give one <float name=\"value\"/> where a colour or a number is wanted, as Mitsuba 3 requires"));
            }
            // A one-texel image of the raw triple.
            let bitmap = Bitmap {
                width: 1,
                height: 1,
                channels: 3,
                data: rgb.to_vec(),
                encoding: Encoding::Linear,
            };
            Ok(Texture::Bitmap(Arc::new(BitmapTexture::new(
                &bitmap,
                usage,
                FilterType::Nearest,
                WrapMode::Clamp,
                UvTransform::IDENTITY,
            ))))
        }
        other => Err(Error::input(
            location,
            format!(
                "the value of {} must be a <float> or a <vector>, but a {} was given",
                node.describe(),
                other.type_name()
            ),
        )),
    }
}

fn build_bitmap(params: &Params, usage: TextureUse) -> Result<Texture> {
    let node = params.node();
    let filename = params.string_opt(&FILENAME)?.ok_or_else(|| {
        Error::input(
            &node.location,
            format!("{} needs a \"filename\"", node.describe()),
        )
        .with_help("add <string name=\"filename\" value=\"image.png\"/>")
    })?;
    let location = params.location_of(&FILENAME);
    let filter = params.choice(&FILTER_TYPE)?;
    let wrap = params.choice(&WRAP_MODE)?;
    params.choice::<()>(&FORMAT)?;
    params.boolean(&ACCEL)?;
    let raw = params.boolean(&RAW)?;
    let to_uv = UvTransform::from_matrix(&params.transform(&TO_UV)?);
    let path = node.resolve_file(filename, location)?;
    let mut bitmap = read_image_file(&path).map_err(|e| e.at(location))?;
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

/// The image file at `path`, decoded (`bitmap` textures and environment maps); its bytes come
/// through the [`file_cache`] in scope, so that a scene built again reads it once.
pub fn read_image_file(path: &Path) -> Result<Bitmap> {
    let bytes = file_cache::read(path).map_err(|e| Error::io(path, &e, "open the image"))?;
    decode_bitmap_file(&bytes, path)
}
