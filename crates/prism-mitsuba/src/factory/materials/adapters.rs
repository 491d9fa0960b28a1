//! BSDFs that wrap others: `twosided`, `mask`, `blendbsdf`, `bumpmap` and `normalmap`, and the
//! `null` BSDF that light passes unchanged.

use super::{Build, build_bsdf};
use crate::description::{PluginClass, PluginNode};
use crate::factory::textures::{TextureCache, build_texture, float_texture};
use crate::params::Params;
use crate::registry::{Bounds, Default, Origin, ParamKind, ParamSpec, Plugin, params};
use prism_core::bsdf::perturbed::Perturbed;
use prism_core::bsdf::{
    Blend, Bsdf, BsdfFlags, BsdfModel, BumpMap, Mask, NormalMap, Null, TwoSided,
};
use prism_core::error::{Error, Result};
use prism_core::texture::TextureUse;

pub(super) const TWOSIDED: Plugin<Build> = Plugin {
    name: "twosided",
    origin: Origin::Mitsuba3,
    summary: "A reflecting BSDF on both sides of the surface, or one for the front and one \
              for the back.",
    params: &[TWOSIDED_BSDFS, ALLOW_TRANSMISSION],
    build: |params, t| {
        let (front, back) = twosided_pair(params, t)?;
        Ok(Bsdf::TwoSided(TwoSided {
            sides: [Box::new(front), Box::new(back)],
        }))
    },
};

pub(super) const MASK: Plugin<Build> = Plugin {
    name: "mask",
    origin: Origin::Mitsuba3,
    summary: "A partly transparent surface: light passes straight through with \
              probability 1 − α. In `path` shadow rays see it as opaque; in `volpath` and \
              `volpathmis` the pass is no bounce and shadow rays pass with weight 1 − α, \
              as in Mitsuba 3.",
    params: &[OPACITY, NESTED_BSDF],
    build: |params, t| {
        Ok(Bsdf::Mask(Mask {
            opacity: float_texture(params, &OPACITY, t)?,
            nested: Box::new(single_nested_bsdf(params, t)?),
        }))
    },
};

pub(super) const NULL: Plugin<Build> = Plugin {
    name: "null",
    origin: Origin::Mitsuba3,
    summary: "Light passes straight through, unchanged (an index-matched boundary, the \
              outline of a medium, an invisible shape); in `path` it counts as a bounce \
              and shadow rays see it as opaque, in `volpath` and `volpathmis` it is no \
              bounce and shadow rays pass, as in Mitsuba 3.",
    params: &[],
    build: |_, _| Ok(Bsdf::Null(Null)),
};

pub(super) const BLENDBSDF: Plugin<Build> = Plugin {
    name: "blendbsdf",
    origin: Origin::Mitsuba3,
    summary: "The linear blend (1 − w) f₀ + w f₁ of two nested BSDFs.",
    params: &[WEIGHT, BLENDED_BSDFS],
    build: build_blend,
};

pub(super) const BUMPMAP: Plugin<Build> = Plugin {
    name: "bumpmap",
    origin: Origin::Mitsuba3,
    summary: "The nested BSDF in a shading frame tilted by the gradient of a height \
              texture (Blinn 1978).",
    params: &[
        HEIGHTS,
        BUMP_SCALE,
        FLIP_INVALID_NORMALS,
        USE_SHADOWING_FUNCTION,
        NESTED_BSDF,
    ],
    build: build_bumpmap,
};

pub(super) const NORMALMAP: Plugin<Build> = Plugin {
    name: "normalmap",
    origin: Origin::Mitsuba3,
    summary: "The nested BSDF in a shading frame whose normal is read from an RGB texture, \
              n = 2 rgb − 1.",
    params: &[
        NORMAL_TEXTURE,
        FLIP_INVALID_NORMALS,
        USE_SHADOWING_FUNCTION,
        NESTED_BSDF,
    ],
    build: build_normalmap,
};

params! {
    pub(super) TWOSIDED_BSDFS = ParamSpec::nested(PluginClass::Bsdf, Default::Required, "one reflecting BSDF for both sides, or two: front, then back");
    pub(super) ALLOW_TRANSMISSION = ParamSpec::new("allow_transmission", ParamKind::Boolean, Default::Boolean(false), "accept nested BSDFs that transmit light (a `polarizer`), as Mitsuba 3 does with this flag");
    NESTED_BSDF = ParamSpec::nested(PluginClass::Bsdf, Default::Required, "the BSDF adapted");
    OPACITY = ParamSpec::new("opacity", ParamKind::FloatTexture(Bounds::UNIT), Default::Float(0.5), "the opacity α");
    WEIGHT = ParamSpec::new("weight", ParamKind::FloatTexture(Bounds::UNIT), Default::Required, "the share w of the second BSDF");
    BLENDED_BSDFS = ParamSpec::nested(PluginClass::Bsdf, Default::Required, "two BSDFs: f₀, then f₁");
    HEIGHTS = ParamSpec::nested(PluginClass::Texture, Default::Required, "the height texture (read as numbers; give `raw` for 8-bit images)");
    BUMP_SCALE = ParamSpec::new("scale", ParamKind::Float, Default::Float(1.0), "factor on the heights");
    FLIP_INVALID_NORMALS = ParamSpec::new("flip_invalid_normals", ParamKind::Boolean, Default::Boolean(true), "mirror a normal that the outgoing direction sees from behind");
    USE_SHADOWING_FUNCTION = ParamSpec::new("use_shadowing_function", ParamKind::Boolean, Default::Boolean(true), "attenuate by Conty Estevez et al.'s shadowing term (the bump terminator)");
    NORMAL_TEXTURE = ParamSpec::new("normalmap", ParamKind::Nested(PluginClass::Texture), Default::Required, "a texture named `normalmap`, read raw: the normals in the shading frame");
}

/// The front and back BSDFs of a `twosided` element.
pub(super) fn twosided_pair(params: &Params, textures: &mut TextureCache) -> Result<(Bsdf, Bsdf)> {
    let node = params.node();
    let nested = params.children(&TWOSIDED_BSDFS);
    let allow_transmission = params.boolean(&ALLOW_TRANSMISSION)?;
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
        let transmits = flags.contains(BsdfFlags::TRANSMISSION) || flags.contains(BsdfFlags::NULL);
        if transmits && !allow_transmission {
            return Err(Error::input(
                &child.location,
                format!(
                    "{} transmits light, so it cannot be nested in \"twosided\"",
                    child.describe()
                ),
            )
            .with_help(
                "dielectrics and masks already work from both sides; as in Mitsuba 3, only \
                 reflecting BSDFs can be made two-sided (put a mask around the twosided BSDF), \
                 unless <boolean name=\"allow_transmission\" value=\"true\"/> is given",
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
    Ok(pair)
}

fn build_blend(params: &Params, t: &mut TextureCache) -> Result<Bsdf> {
    let node = params.node();
    if !params.has(&WEIGHT) {
        return Err(
            Error::input(&node.location, "bsdf \"blendbsdf\" needs a \"weight\"")
                .with_help("add <float name=\"weight\" value=\"0.5\"/> (the second BSDF's share)"),
        );
    }
    let weight = float_texture(params, &WEIGHT, t)?;
    let nested = params.children(&BLENDED_BSDFS);
    let [first, second] = nested.as_slice() else {
        return Err(Error::input(
            &node.location,
            format!(
                "bsdf \"blendbsdf\" needs exactly two nested BSDFs, found {}",
                nested.len()
            ),
        ));
    };
    Ok(Bsdf::Blend(Blend {
        weight,
        nested: [
            Box::new(build_bsdf(&first.node, t)?),
            Box::new(build_bsdf(&second.node, t)?),
        ],
    }))
}

fn build_bumpmap(params: &Params, t: &mut TextureCache) -> Result<Bsdf> {
    let node = params.node();
    let nested_textures = params.children(&HEIGHTS);
    let [height] = nested_textures.as_slice() else {
        return Err(Error::input(
            &node.location,
            format!(
                "bsdf \"bumpmap\" needs exactly one nested texture (the heights), found {}",
                nested_textures.len()
            ),
        ));
    };
    let scale = params.float(&BUMP_SCALE)? as f32;
    if !scale.is_finite() {
        return Err(Error::input(
            params.location_of(&BUMP_SCALE),
            "the bump map's scale must be a finite number",
        ));
    }
    let heights = build_texture(&height.node, TextureUse::Scalar, t)?;
    if heights.reads_position() {
        return Err(Error::input(
            &height.location,
            "the bump map's heights are read at the surface point's position (a volume \
             texture), which gives them no (u, v) gradient",
        )
        .with_help("give the heights as a bitmap or a pattern in (u, v)"));
    }
    Ok(Bsdf::BumpMap(BumpMap {
        height: heights,
        scale,
        perturbed: perturbed(params, t)?,
    }))
}

fn build_normalmap(params: &Params, t: &mut TextureCache) -> Result<Bsdf> {
    let node = params.node();
    let Some(normals) = params.named_child(&NORMAL_TEXTURE) else {
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
    Ok(Bsdf::NormalMap(NormalMap {
        normals: build_texture(&normals.node, TextureUse::Rgb, t)?,
        perturbed: perturbed(params, t)?,
    }))
}

/// The nested BSDF of a `bumpmap` or `normalmap` and how its frame is tilted.
fn perturbed(params: &Params, t: &mut TextureCache) -> Result<Perturbed> {
    Ok(Perturbed {
        nested: Box::new(single_nested_bsdf(params, t)?),
        flip_invalid_normals: params.boolean(&FLIP_INVALID_NORMALS)?,
        use_shadowing_function: params.boolean(&USE_SHADOWING_FUNCTION)?,
    })
}

/// The one BSDF nested in an adapter (`mask`, `bumpmap`, `normalmap`).
fn single_nested_bsdf(params: &Params, textures: &mut TextureCache) -> Result<Bsdf> {
    let nested = params.children(&NESTED_BSDF);
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
