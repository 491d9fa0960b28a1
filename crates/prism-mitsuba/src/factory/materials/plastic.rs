//! A diffuse base under a dielectric coating: `plastic`, `roughplastic` and Mitsuba 3's
//! polarised plastic `pplastic`.

use super::ior::{COATING_INT_IOR, EXT_IOR, constant_relative_ior};
use super::microfacet::{ALPHA_U, ALPHA_V, DISTRIBUTION, SAMPLE_VISIBLE, roughness};
use super::{Build, DIFFUSE_REFLECTANCE, SPECULAR_REFLECTANCE};
use crate::factory::textures::{
    TextureCache, float_value, optional_spectrum_texture, spectrum_texture,
};
use crate::params::Params;
use crate::registry::{Bounds, Default, Origin, ParamKind, ParamSpec, Plugin, params};
use prism_core::bsdf::{Bsdf, Plastic, PolarizedPlastic, RoughPlastic};
use prism_core::error::{Error, Result};

/// The parameters of a coated BSDF: the base, the coating's indices and its specular factor,
/// then its own.
macro_rules! coating_params {
    [$($own:expr),* $(,)?] => {
        &[
            DIFFUSE_REFLECTANCE,
            COATING_INT_IOR,
            EXT_IOR,
            SPECULAR_REFLECTANCE,
            $($own,)*
        ]
    };
}

/// The parameters of `plastic`.
const PLASTIC_PARAMS: &[ParamSpec] = coating_params![NONLINEAR];

pub(super) const PLASTIC: Plugin<Build> = Plugin {
    name: "plastic",
    origin: Origin::Mitsuba3,
    summary: "A diffuse base under a smooth dielectric coating (Weidlich & Wilkie 2007). \
              One-sided.",
    params: PLASTIC_PARAMS,
    build: |params, t| {
        let eta = constant_relative_ior(params, false)?;
        Ok(Bsdf::Plastic(Plastic::new(
            eta,
            spectrum_texture(params, &DIFFUSE_REFLECTANCE, t)?,
            optional_spectrum_texture(params, &SPECULAR_REFLECTANCE, t)?,
            params.boolean(&NONLINEAR)?,
        )))
    },
};

pub(super) const ROUGHPLASTIC: Plugin<Build> = Plugin {
    name: "roughplastic",
    origin: Origin::Mitsuba3,
    summary: "A diffuse base under a rough dielectric coating, with Mitsuba 3's tabulated \
              coating transmittance. One-sided.",
    params: coating_params![
        NONLINEAR,
        DISTRIBUTION,
        PLASTIC_ALPHA,
        ALPHA_U,
        ALPHA_V,
        SAMPLE_VISIBLE
    ],
    build: build_roughplastic,
};

pub(super) const PPLASTIC: Plugin<Build> = Plugin {
    name: "pplastic",
    origin: Origin::Mitsuba3,
    summary: "Mitsuba 3's polarised plastic, unpolarised: a rough specular reflection plus \
              a diffuse base attenuated by two smooth refractions (Baek et al. 2018). \
              One-sided.",
    params: microfacet_params![
        DIFFUSE_REFLECTANCE,
        COATING_INT_IOR,
        EXT_IOR,
        SPECULAR_REFLECTANCE
    ],
    build: |params, t| {
        let eta = constant_relative_ior(params, true)?;
        let roughness = roughness(params, t)?;
        Ok(Bsdf::PolarizedPlastic(PolarizedPlastic {
            eta,
            roughness,
            diffuse_reflectance: spectrum_texture(params, &DIFFUSE_REFLECTANCE, t)?,
            specular_reflectance: optional_spectrum_texture(params, &SPECULAR_REFLECTANCE, t)?,
        }))
    },
};

params! {
    NONLINEAR = ParamSpec::new("nonlinear", ParamKind::Boolean, Default::Boolean(false), "let the bounces between base and coating be modulated by the base colour (darker, more saturated colours)");
    PLASTIC_ALPHA = ParamSpec::new("alpha", ParamKind::Float, Default::Float(0.1), "roughness α of the coating: a number greater than 0 (isotropic only, no texture, as Mitsuba)");
}

fn build_roughplastic(params: &Params, t: &mut TextureCache) -> Result<Bsdf> {
    let eta = constant_relative_ior(params, true)?;
    let distribution = params.choice(&DISTRIBUTION)?;
    for spec in [&ALPHA_U, &ALPHA_V] {
        if params.has(spec) {
            return Err(Error::input(
                params.location_of(spec),
                "bsdf \"roughplastic\" supports only isotropic roughness",
            )
            .with_help("give a single <float name=\"alpha\" .../>, as Mitsuba 3 requires"));
        }
    }
    if let Some(child) = params.named_child(&PLASTIC_ALPHA) {
        return Err(Error::input(
            &child.location,
            "the roughness of \"roughplastic\" must be a number, not a texture",
        )
        .with_help("Mitsuba 3's roughplastic precomputes its tables for one alpha"));
    }
    let alpha = float_value(params, &PLASTIC_ALPHA, Bounds::POSITIVE)?;
    params.boolean(&SAMPLE_VISIBLE)?;
    Ok(Bsdf::RoughPlastic(RoughPlastic::new(
        eta,
        distribution,
        alpha,
        spectrum_texture(params, &DIFFUSE_REFLECTANCE, t)?,
        optional_spectrum_texture(params, &SPECULAR_REFLECTANCE, t)?,
        params.boolean(&NONLINEAR)?,
    )))
}
