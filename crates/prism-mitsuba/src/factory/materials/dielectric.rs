//! Interfaces between two dielectrics: smooth, rough (microfacet) and thin.

use super::ior::{EXT_IOR, INT_IOR, relative_ior};
use super::microfacet::roughness;
use super::{Build, SPECULAR_REFLECTANCE, colour};
use crate::factory::textures::{TextureCache, optional_spectrum_texture};
use crate::params::Params;
use crate::registry::{Origin, ParamSpec, Plugin, Range, params};
use prism_core::bsdf::dielectric::{SmoothInterface, SpecularFactorTextures};
use prism_core::bsdf::{Bsdf, Dielectric, RoughDielectric, ThinDielectric};
use prism_core::error::Result;

pub(super) const DIELECTRIC: Plugin<Build> = Plugin {
    name: "dielectric",
    origin: Origin::Mitsuba3,
    summary: "A smooth interface between two dielectrics (glass, water), from both sides. \
              Behind a dispersive index each wavelength refracts its own way.",
    params: SMOOTH_INTERFACE,
    build: |params, t| {
        Ok(Bsdf::Dielectric(Dielectric {
            interface: smooth_interface(params, t)?,
        }))
    },
};

pub(super) const ROUGHDIELECTRIC: Plugin<Build> = Plugin {
    name: "roughdielectric",
    origin: Origin::Mitsuba3,
    summary: "A rough interface between two dielectrics (frosted glass), Walter et al. 2007.",
    params: microfacet_params![
        INT_IOR,
        EXT_IOR,
        SPECULAR_REFLECTANCE,
        SPECULAR_TRANSMITTANCE
    ],
    build: |params, t| {
        let eta = relative_ior(params, &INT_IOR, true)?;
        let roughness = roughness(params, t)?;
        Ok(Bsdf::RoughDielectric(RoughDielectric {
            eta,
            roughness,
            specular: specular_factors(params, t)?,
        }))
    },
};

pub(super) const THINDIELECTRIC: Plugin<Build> = Plugin {
    name: "thindielectric",
    origin: Origin::Mitsuba3,
    summary: "A thin pane of glass: reflects R' = 2R/(1 + R) and lets the rest through \
              undeflected; in `volpath` and `volpathmis` that pass is no bounce and shadow \
              rays pass with weight 1 − R', as in Mitsuba 3.",
    params: SMOOTH_INTERFACE,
    build: |params, t| {
        Ok(Bsdf::ThinDielectric(ThinDielectric {
            interface: smooth_interface(params, t)?,
        }))
    },
};

params! {
    SPECULAR_TRANSMITTANCE = colour("specular_transmittance", Range::Albedo, 1.0, "a factor on the transmitted light");
}

/// The parameters of a smooth interface (`dielectric`, `thindielectric`).
const SMOOTH_INTERFACE: &[ParamSpec] = &[
    INT_IOR,
    EXT_IOR,
    SPECULAR_REFLECTANCE,
    SPECULAR_TRANSMITTANCE,
];

/// The relative index and the specular factors of a smooth interface.
fn smooth_interface(params: &Params, t: &mut TextureCache) -> Result<SmoothInterface> {
    Ok(SmoothInterface {
        eta: relative_ior(params, &INT_IOR, false)?,
        specular: specular_factors(params, t)?,
    })
}

/// The optional factors on an interface's reflection and transmission.
fn specular_factors(params: &Params, t: &mut TextureCache) -> Result<SpecularFactorTextures> {
    Ok(SpecularFactorTextures {
        reflectance: optional_spectrum_texture(params, &SPECULAR_REFLECTANCE, t)?,
        transmittance: optional_spectrum_texture(params, &SPECULAR_TRANSMITTANCE, t)?,
    })
}
