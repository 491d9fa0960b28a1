//! Burley's Disney BSDFs as Mitsuba 3 implements them: `principled` and the thin-sheet
//! `principledthin`.

use super::{Build, colour};
use crate::factory::textures::{TextureCache, float_texture, float_value, spectrum_texture};
use crate::params::Params;
use crate::registry::{Bounds, Default, Origin, ParamKind, ParamSpec, Plugin, Range, params};
use prism_core::bsdf::{Bsdf, Principled, PrincipledThin, principled, principledthin};
use prism_core::error::{Error, Result};
use prism_core::spectrum::Spectrum;
use prism_core::texture::Texture;

pub(super) const PRINCIPLED: Plugin<Build> = Plugin {
    name: "principled",
    origin: Origin::Mitsuba3,
    summary: "Burley's Disney BSDF as Mitsuba 3 implements it: diffuse with retro-reflection \
              and fake subsurface, sheen, a GGX specular lobe blending dielectric and \
              metallic Fresnel, GTR1 clearcoat, and rough transmission (`spec_trans`).",
    params: &[
        BASE_COLOR,
        ROUGHNESS,
        ANISOTROPIC,
        METALLIC,
        SPEC_TRANS,
        PRINCIPLED_ETA,
        SPECULAR,
        SPEC_TINT,
        SHEEN,
        SHEEN_TINT,
        FLATNESS,
        CLEARCOAT,
        CLEARCOAT_GLOSS,
        DIFFUSE_SAMPLING_RATE,
        MAIN_SPECULAR_SAMPLING_RATE,
        CLEARCOAT_SAMPLING_RATE,
    ],
    build: build_principled,
};

pub(super) const PRINCIPLEDTHIN: Plugin<Build> = Plugin {
    name: "principledthin",
    origin: Origin::Mitsuba3,
    summary: "Burley's thin-sheet Disney BSDF as Mitsuba 3 implements it: the same from \
              both sides, with specular and diffuse reflection and transmission.",
    params: &[
        BASE_COLOR,
        ROUGHNESS,
        ANISOTROPIC,
        THIN_SPEC_TRANS,
        THIN_ETA,
        SPEC_TINT,
        SHEEN,
        SHEEN_TINT,
        FLATNESS,
        DIFF_TRANS,
        DIFFUSE_SAMPLING_RATE,
        SPECULAR_REFLECTANCE_SAMPLING_RATE,
        SPECULAR_TRANSMITTANCE_SAMPLING_RATE,
        DIFFUSE_TRANSMITTANCE_SAMPLING_RATE,
    ],
    build: build_principledthin,
};

/// A weight in [0, 1], or a texture of them.
const fn weight(name: &'static str, default: f64, doc: &'static str) -> ParamSpec {
    ParamSpec::new(
        name,
        ParamKind::FloatTexture(Bounds::UNIT),
        Default::Float(default),
        doc,
    )
}

/// A relative sampling rate, 1 by default.
const fn sampling_rate(name: &'static str, doc: &'static str) -> ParamSpec {
    ParamSpec::new(name, ParamKind::Float, Default::Float(1.0), doc)
}

params! {
    BASE_COLOR = colour("base_color", Range::Albedo, 0.5, "the colour c");
    ROUGHNESS = weight("roughness", 0.5, "roughness of the main specular lobes (α = roughness²)");
    ANISOTROPIC = weight("anisotropic", 0.0, "degree of anisotropy: α_u/α_v = 1/(1 − 0.9·anisotropic)");
    METALLIC = weight("metallic", 0.0, "blend from dielectric (0) to metal (1)");
    SPEC_TRANS = weight("spec_trans", 0.0, "share of the dielectric part that transmits (rough glass at 1)");
    PRINCIPLED_ETA = ParamSpec::new("eta", ParamKind::Float, Default::Text("from `specular`"), "relative index of refraction (instead of `specular`)");
    SPECULAR = ParamSpec::new("specular", ParamKind::Float, Default::Float(0.5), "Fresnel reflectance at normal incidence ÷ 0.08: η = 2/(1 − √(0.08·specular)) − 1");
    SPEC_TINT = weight("spec_tint", 0.0, "share of the dielectric reflection tinted by the base colour");
    SHEEN = weight("sheen", 0.0, "weight of the sheen lobe");
    SHEEN_TINT = weight("sheen_tint", 0.0, "tint of the sheen by the base colour");
    FLATNESS = weight("flatness", 0.0, "blend from the diffuse lobe to Hanrahan–Krueger's fake subsurface");
    CLEARCOAT = weight("clearcoat", 0.0, "weight of the clearcoat lobe");
    CLEARCOAT_GLOSS = weight("clearcoat_gloss", 0.0, "gloss of the clearcoat: α from 0.1 (0) to 0.001 (1)");
    DIFFUSE_SAMPLING_RATE = sampling_rate("diffuse_reflectance_sampling_rate", "relative rate of sampling the diffuse lobe");
    MAIN_SPECULAR_SAMPLING_RATE = sampling_rate("main_specular_sampling_rate", "relative rate of sampling the main specular lobes");
    CLEARCOAT_SAMPLING_RATE = sampling_rate("clearcoat_sampling_rate", "relative rate of sampling the clearcoat");
    THIN_SPEC_TRANS = weight("spec_trans", 0.0, "blend from the diffuse (0) to the specular (1) response");
    THIN_ETA = ParamSpec::new("eta", ParamKind::FloatTexture(Bounds::POSITIVE), Default::Float(1.5), "relative index of refraction of the sheet (its Fresnel term and transmitted roughness)");
    DIFF_TRANS = ParamSpec::new("diff_trans", ParamKind::FloatTexture(Bounds { min: 0.0, min_exclusive: false, max: 2.0, }), Default::Float(0.0), "share of the diffuse response transmitted, from 0 (none) to 2 (all)");
    SPECULAR_REFLECTANCE_SAMPLING_RATE = sampling_rate("specular_reflectance_sampling_rate", "relative rate of sampling the specular reflection");
    SPECULAR_TRANSMITTANCE_SAMPLING_RATE = sampling_rate("specular_transmittance_sampling_rate", "relative rate of sampling the specular transmission");
    DIFFUSE_TRANSMITTANCE_SAMPLING_RATE = sampling_rate("diffuse_transmittance_sampling_rate", "relative rate of sampling the diffuse transmission");
}

/// A lobe weight of `principled` or `principledthin`: `None` (the lobe is off) when the scene
/// leaves it out or gives the number 0, as Mitsuba's `get_flag`.
fn optional_lobe(
    params: &Params,
    spec: &ParamSpec,
    t: &mut TextureCache,
) -> Result<Option<Texture>> {
    if !params.has(spec) {
        return Ok(None);
    }
    match float_texture(params, spec, t)? {
        Texture::Constant(Spectrum::Constant(0.0)) => Ok(None),
        texture => Ok(Some(texture)),
    }
}

/// Mitsuba 3's `principled`: a lobe whose weight the scene leaves out, or gives as the number 0,
/// is off (its `m_has_*` flags); `eta` or `specular` (not both) gives the index, raised to 1.001
/// (or `specular` to 10⁻³) when it would make a transmitting interface vanish.
fn build_principled(params: &Params, t: &mut TextureCache) -> Result<Bsdf> {
    let mut optional = |spec: &ParamSpec| optional_lobe(params, spec, t);
    let anisotropic = optional(&ANISOTROPIC)?;
    let metallic = optional(&METALLIC)?;
    let spec_trans = optional(&SPEC_TRANS)?;
    let spec_tint = optional(&SPEC_TINT)?;
    let sheen = optional(&SHEEN)?;
    let sheen_tint = optional(&SHEEN_TINT)?;
    let flatness = optional(&FLATNESS)?;
    let clearcoat = optional(&CLEARCOAT)?;
    let transmits = spec_trans.is_some();
    let eta = if params.has(&PRINCIPLED_ETA) {
        if params.has(&SPECULAR) {
            return Err(Error::input(
                params.location_of(&SPECULAR),
                "give either \"eta\" or \"specular\" for bsdf \"principled\", not both",
            )
            .with_help("they set the same index of refraction, as in Mitsuba 3"));
        }
        let eta = float_value(params, &PRINCIPLED_ETA, Bounds::POSITIVE)?;
        if transmits && eta == 1.0 { 1.001 } else { eta }
    } else {
        let specular = float_value(params, &SPECULAR, Bounds::UNIT)?;
        let specular = if transmits && specular == 0.0 {
            1e-3
        } else {
            specular
        };
        2.0 / (1.0 - (0.08 * specular).sqrt()) - 1.0
    };
    let rate = |spec: &ParamSpec| float_value(params, spec, Bounds::NON_NEGATIVE);
    let rates = principled::SamplingRates {
        main_specular: rate(&MAIN_SPECULAR_SAMPLING_RATE)?,
        clearcoat: rate(&CLEARCOAT_SAMPLING_RATE)?,
        diffuse: rate(&DIFFUSE_SAMPLING_RATE)?,
    };
    if rates.main_specular + rates.clearcoat + rates.diffuse <= 0.0 {
        return Err(Error::input(
            params.location(),
            "bsdf \"principled\" needs a sampling rate above 0",
        )
        .with_help("raise main_specular_sampling_rate (default 1)"));
    }
    Ok(Bsdf::Principled(Principled {
        base_color: spectrum_texture(params, &BASE_COLOR, t)?,
        roughness: float_texture(params, &ROUGHNESS, t)?,
        clearcoat_gloss: float_texture(params, &CLEARCOAT_GLOSS, t)?,
        anisotropic,
        metallic,
        spec_trans,
        spec_tint,
        sheen,
        sheen_tint,
        flatness,
        clearcoat,
        eta,
        rates,
    }))
}

/// Mitsuba 3's `principledthin` (lobes off as in [`optional_lobe`]).
fn build_principledthin(params: &Params, t: &mut TextureCache) -> Result<Bsdf> {
    let mut optional = |spec: &ParamSpec| optional_lobe(params, spec, t);
    let anisotropic = optional(&ANISOTROPIC)?;
    let spec_trans = optional(&THIN_SPEC_TRANS)?;
    let spec_tint = optional(&SPEC_TINT)?;
    let sheen = optional(&SHEEN)?;
    let sheen_tint = optional(&SHEEN_TINT)?;
    let flatness = optional(&FLATNESS)?;
    let diff_trans = optional(&DIFF_TRANS)?;
    let rate = |spec: &ParamSpec| float_value(params, spec, Bounds::NON_NEGATIVE);
    let rates = principledthin::ThinSamplingRates {
        specular_reflectance: rate(&SPECULAR_REFLECTANCE_SAMPLING_RATE)?,
        specular_transmittance: rate(&SPECULAR_TRANSMITTANCE_SAMPLING_RATE)?,
        diffuse_reflectance: rate(&DIFFUSE_SAMPLING_RATE)?,
        diffuse_transmittance: rate(&DIFFUSE_TRANSMITTANCE_SAMPLING_RATE)?,
    };
    if rates.specular_reflectance
        + rates.specular_transmittance
        + rates.diffuse_reflectance
        + rates.diffuse_transmittance
        <= 0.0
    {
        return Err(Error::input(
            params.location(),
            "bsdf \"principledthin\" needs a sampling rate above 0",
        )
        .with_help("raise diffuse_reflectance_sampling_rate (default 1)"));
    }
    Ok(Bsdf::PrincipledThin(PrincipledThin {
        base_color: spectrum_texture(params, &BASE_COLOR, t)?,
        roughness: float_texture(params, &ROUGHNESS, t)?,
        eta: float_texture(params, &THIN_ETA, t)?,
        anisotropic,
        spec_trans,
        spec_tint,
        sheen,
        sheen_tint,
        flatness,
        diff_trans,
        rates,
    }))
}
