//! pbrt-v4's layered BSDFs, `coateddiffuse` and `coatedconductor`: a dielectric coating over a
//! diffuse or conductor base, evaluated and sampled by random walks through the layer (Mitsuba
//! 3 has no such model; the pbrt-v4 reader translates pbrt's materials of those names to them).

use super::conductor::{ETA, K, MATERIAL, conductor_ior};
use super::{Build, colour};
use crate::factory::textures::{TextureCache, spectrum_texture};
use crate::params::Params;
use crate::registry::{Bounds, Default, Origin, ParamKind, ParamSpec, Plugin, Range, params};
use prism_core::bsdf::{Bsdf, CoatedConductor, CoatedDiffuse, Coating};
use prism_core::error::{Error, Result};

pub(super) const COATEDDIFFUSE: Plugin<Build> = Plugin {
    name: "coateddiffuse",
    origin: Origin::Prism,
    summary: "pbrt-v4's coated diffuse material: a Lambertian base under a smooth or rough \
              dielectric coating with an optional scattering slab between them, evaluated and \
              sampled by random walks through the layer. Two-sided.",
    params: &[
        REFLECTANCE,
        ALPHA,
        ALPHA_U,
        ALPHA_V,
        COATING_ETA,
        THICKNESS,
        ALBEDO,
        G,
        MAX_DEPTH,
        SAMPLES,
    ],
    build: |params, t| {
        Ok(Bsdf::CoatedDiffuse(CoatedDiffuse {
            reflectance: spectrum_texture(params, &REFLECTANCE, t)?,
            coating: coating(params, t, &COATING_ETA, [&ALPHA, &ALPHA_U, &ALPHA_V])?,
        }))
    },
};

pub(super) const COATEDCONDUCTOR: Plugin<Build> = Plugin {
    name: "coatedconductor",
    origin: Origin::Prism,
    summary: "pbrt-v4's coated conductor material: a smooth or rough metal under a smooth or \
              rough dielectric coating with an optional scattering slab between them, \
              evaluated and sampled by random walks through the layer. Two-sided.",
    params: &[
        MATERIAL,
        ETA,
        K,
        CONDUCTOR_ALPHA,
        CONDUCTOR_ALPHA_U,
        CONDUCTOR_ALPHA_V,
        INTERFACE_ETA,
        INTERFACE_ALPHA,
        INTERFACE_ALPHA_U,
        INTERFACE_ALPHA_V,
        THICKNESS,
        ALBEDO,
        G,
        MAX_DEPTH,
        SAMPLES,
    ],
    build: |params, t| {
        let (eta, k) = conductor_ior(params, t)?;
        Ok(Bsdf::CoatedConductor(CoatedConductor {
            eta,
            k,
            conductor_alpha: alpha(
                params,
                [&CONDUCTOR_ALPHA, &CONDUCTOR_ALPHA_U, &CONDUCTOR_ALPHA_V],
            )?,
            coating: coating(
                params,
                t,
                &INTERFACE_ETA,
                [&INTERFACE_ALPHA, &INTERFACE_ALPHA_U, &INTERFACE_ALPHA_V],
            )?,
        }))
    },
};

params! {
    REFLECTANCE = colour("reflectance", Range::Albedo, 0.5, "reflectance of the diffuse base");
    ALPHA = ParamSpec::new("alpha", ParamKind::FloatIn(Bounds::FINITE_NON_NEGATIVE), Default::Float(0.0), "the coating's Trowbridge–Reitz roughness α (pbrt's after `remaproughness`); below 0.001 smooth");
    ALPHA_U = ParamSpec::new("alpha_u", ParamKind::FloatIn(Bounds::FINITE_NON_NEGATIVE), Default::Text("`alpha`"), "the coating's roughness along ∂p/∂u (with `alpha_v`, instead of `alpha`)");
    ALPHA_V = ParamSpec::new("alpha_v", ParamKind::FloatIn(Bounds::FINITE_NON_NEGATIVE), Default::Text("`alpha`"), "the coating's roughness along ∂p/∂v");
    COATING_ETA = ParamSpec::new("eta", ParamKind::FloatIn(Bounds::FINITE_NON_NEGATIVE), Default::Float(1.5), "the coating's index of refraction relative to the outside (0 is read as 1, as pbrt reads it)");
    INTERFACE_ETA = ParamSpec::new("interface_eta", ParamKind::FloatIn(Bounds::FINITE_NON_NEGATIVE), Default::Float(1.5), "the coating's index of refraction relative to the outside (0 is read as 1); the conductor's η and k are divided by it");
    INTERFACE_ALPHA = ParamSpec::new("interface_alpha", ParamKind::FloatIn(Bounds::FINITE_NON_NEGATIVE), Default::Float(0.0), "the coating's Trowbridge–Reitz roughness α; below 0.001 smooth");
    INTERFACE_ALPHA_U = ParamSpec::new("interface_alpha_u", ParamKind::FloatIn(Bounds::FINITE_NON_NEGATIVE), Default::Text("`interface_alpha`"), "the coating's roughness along ∂p/∂u");
    INTERFACE_ALPHA_V = ParamSpec::new("interface_alpha_v", ParamKind::FloatIn(Bounds::FINITE_NON_NEGATIVE), Default::Text("`interface_alpha`"), "the coating's roughness along ∂p/∂v");
    CONDUCTOR_ALPHA = ParamSpec::new("conductor_alpha", ParamKind::FloatIn(Bounds::FINITE_NON_NEGATIVE), Default::Float(0.0), "the conductor's Trowbridge–Reitz roughness α; below 0.001 smooth");
    CONDUCTOR_ALPHA_U = ParamSpec::new("conductor_alpha_u", ParamKind::FloatIn(Bounds::FINITE_NON_NEGATIVE), Default::Text("`conductor_alpha`"), "the conductor's roughness along ∂p/∂u");
    CONDUCTOR_ALPHA_V = ParamSpec::new("conductor_alpha_v", ParamKind::FloatIn(Bounds::FINITE_NON_NEGATIVE), Default::Text("`conductor_alpha`"), "the conductor's roughness along ∂p/∂v");
    THICKNESS = ParamSpec::new("thickness", ParamKind::FloatIn(Bounds::FINITE_NON_NEGATIVE), Default::Float(0.01), "the slab's thickness, in mean free paths of its medium");
    ALBEDO = colour("albedo", Range::Albedo, 0.0, "the single-scattering albedo of the slab's medium; 0: the slab only attenuates");
    G = ParamSpec::new("g", ParamKind::FloatIn(Bounds::between(-1.0, 1.0)), Default::Float(0.0), "the Henyey–Greenstein asymmetry of the slab's medium");
    MAX_DEPTH = ParamSpec::new("max_depth", ParamKind::Integer, Default::Integer(10), "the most scattering events a random walk follows (at least 1)");
    SAMPLES = ParamSpec::new("samples", ParamKind::Integer, Default::Integer(1), "how many random walks an evaluation averages (at least 1)");
}

/// The coating and slab: the index `eta`, the roughness `alpha` and the slab's parameters.
fn coating(
    params: &Params,
    textures: &mut TextureCache,
    eta: &ParamSpec,
    alpha_specs: [&ParamSpec; 3],
) -> Result<Coating> {
    Ok(Coating {
        eta: params.float_in(eta)? as f32,
        alpha: alpha(params, alpha_specs)?,
        thickness: params.float_in(&THICKNESS)? as f32,
        albedo: spectrum_texture(params, &ALBEDO, textures)?,
        g: params.float_in(&G)? as f32,
        max_depth: count(params, &MAX_DEPTH)?,
        samples: count(params, &SAMPLES)?,
    })
}

/// (αu, αv) from `alpha`, or from `alpha_u` and `alpha_v` together.
fn alpha(params: &Params, [alpha, u, v]: [&ParamSpec; 3]) -> Result<(f32, f32)> {
    let isotropic = params.float_in(alpha)? as f32;
    match (params.has(u), params.has(v)) {
        (false, false) => Ok((isotropic, isotropic)),
        (true, true) if !params.has(alpha) => {
            let read = |spec: &ParamSpec| {
                params
                    .float_between(spec, 0.0, 0.0, f64::from(f32::MAX))
                    .map(|a| a as f32)
            };
            Ok((read(u)?, read(v)?))
        }
        _ => Err(Error::input(
            params.location(),
            format!(
                "{} needs either \"{}\" or both \"{}\" and \"{}\"",
                params.node().describe(),
                alpha.name,
                u.name,
                v.name
            ),
        )),
    }
}

/// A positive count.
fn count(params: &Params, spec: &ParamSpec) -> Result<u32> {
    let value = params.integer(spec)?;
    u32::try_from(value)
        .ok()
        .filter(|n| (1..=1 << 16).contains(n))
        .ok_or_else(|| {
            Error::input(
                params.location_of(spec),
                format!(
                    "parameter \"{}\" of {} is {value}; it must be between 1 and 65536",
                    spec.name,
                    params.node().describe()
                ),
            )
        })
}
