//! Metals: the smooth `conductor` and the microfacet `roughconductor`, with their index η + ik
//! from a measured preset or given spectra.

use super::ior::ior;
use super::microfacet::roughness;
use super::{Build, colour};
use crate::factory::textures::{TextureCache, spectrum_texture};
use crate::params::Params;
use crate::registry::{Default, Origin, ParamKind, ParamSpec, Plugin, Range, params};
use prism_core::bsdf::{Bsdf, Conductor, RoughConductor};
use prism_core::error::{Error, Result};
use prism_core::spectrum::conductors::{conductor_names, conductor_preset};
use prism_core::spectrum::ior::Ior;
use prism_core::spectrum::{PiecewiseLinear, Spectrum};
use prism_core::texture::Texture;

pub(super) const CONDUCTOR: Plugin<Build> = Plugin {
    name: "conductor",
    origin: Origin::Mitsuba3,
    summary: "A smooth metal: a mirror with the Fresnel reflectance of η + ik. One-sided.",
    params: &[MATERIAL, ETA, K, CONDUCTOR_SPECULAR, EXT_ETA],
    build: |params, t| {
        let (eta, k) = conductor_ior(params, t)?;
        Ok(Bsdf::Conductor(Conductor {
            eta,
            k,
            specular_reflectance: spectrum_texture(params, &CONDUCTOR_SPECULAR, t)?,
            ext_eta: exterior_eta(params)?,
        }))
    },
};

pub(super) const ROUGHCONDUCTOR: Plugin<Build> = Plugin {
    name: "roughconductor",
    origin: Origin::Mitsuba3,
    summary: "A rough metal: the microfacet model of Walter et al. 2007, sampled by \
              visible normals. One-sided.",
    params: microfacet_params![MATERIAL, ETA, K, CONDUCTOR_SPECULAR, EXT_ETA],
    build: |params, t| {
        let (eta, k) = conductor_ior(params, t)?;
        let roughness = roughness(params, t)?;
        Ok(Bsdf::RoughConductor(RoughConductor {
            roughness,
            eta,
            k,
            specular_reflectance: spectrum_texture(params, &CONDUCTOR_SPECULAR, t)?,
            ext_eta: exterior_eta(params)?,
        }))
    },
};

params! {
    pub(super) MATERIAL = ParamSpec::new("material", ParamKind::String, Default::Str("none"), "a measured preset (`Au`, `Ag`, `Cu`, `Al`, `Cr`, … the 71 of Mitsuba's table), or `none`: a 100 % mirror");
    pub(super) ETA = colour("eta", Range::IndexPart, 0.0, "real part of the index (instead of `material`); an `<rgb>` is read as Mitsuba 3's spectral variants read it: components clamped to [0, 1], upsampled as a reflectance");
    pub(super) K = colour("k", Range::IndexPart, 1.0, "imaginary part of the index (instead of `material`); an `<rgb>` as for `eta`");
    CONDUCTOR_SPECULAR = colour("specular_reflectance", Range::Albedo, 1.0, "a factor on the reflectance");
    EXT_ETA = ParamSpec::new("ext_eta", ParamKind::Ior, Default::Text("1"), "(Mitsuba 0.6's `extEta`) index of the medium outside, a number or a name: η and k are divided by it. Mitsuba 3 reads no exterior index");
}

/// A conductor's η and k: `material` (a preset; "none", the default, is a perfect mirror with
/// η = 0, k = 1), or `eta` and `k` as spectra, colours (upsampled without bounds) or textures.
pub(super) fn conductor_ior(
    params: &Params,
    textures: &mut TextureCache,
) -> Result<(Texture, Texture)> {
    let material = params.string(&MATERIAL)?;
    if material == "none" {
        let eta = spectrum_texture(params, &ETA, textures)?;
        let k = spectrum_texture(params, &K, textures)?;
        return Ok((eta, k));
    }
    if params.has(&ETA) || params.has(&K) {
        return Err(Error::input(
            params.location_of(&MATERIAL),
            "give either a \"material\" preset or \"eta\" and \"k\", not both",
        ));
    }
    let Some(preset) = conductor_preset(material) else {
        return Err(Error::input(
            params.location_of(&MATERIAL),
            format!("unknown conductor material \"{material}\""),
        )
        .with_help(format!(
            "known materials: none, {}",
            conductor_names().join(", ")
        )));
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

/// A conductor's `ext_eta` (Mitsuba 0.6's `extEta`): a constant index, 1 when absent (Mitsuba 3
/// has no exterior index; Mitsuba 0.6's default, air, differs from 1 by 3·10⁻⁴).
fn exterior_eta(params: &Params) -> Result<f32> {
    if !params.has(&EXT_ETA) {
        return Ok(1.0);
    }
    match ior(params, &EXT_ETA)? {
        Ior::Constant(eta) => Ok(eta),
        _ => Err(Error::input(
            params.location_of(&EXT_ETA),
            format!(
                "the exterior index \"ext_eta\" of {} must be a constant",
                params.node().describe()
            ),
        )
        .with_help("give a number or a name such as \"water\", as Mitsuba 0.6 reads it")),
    }
}
