//! The Lambertian reflector, Oren–Nayar's rough diffuse reflector and pbrt-v4's Lambertian
//! reflector and transmitter.

use super::{Build, colour};
use crate::factory::textures::{float_texture, spectrum_texture};
use crate::registry::{Bounds, Default, Origin, ParamKind, ParamSpec, Plugin, Range, params};
use prism_core::bsdf::{Bsdf, Diffuse, DiffuseTransmission, RoughDiffuse};

pub(super) const DIFFUSE: Plugin<Build> = Plugin {
    name: "diffuse",
    origin: Origin::Mitsuba3,
    summary: "The ideal Lambertian reflector, f = ρ/π, sampled by the cosine. One-sided.",
    params: &[REFLECTANCE],
    build: |params, t| {
        Ok(Bsdf::Diffuse(Diffuse {
            reflectance: spectrum_texture(params, &REFLECTANCE, t)?,
        }))
    },
};

pub(super) const ROUGHDIFFUSE: Plugin<Build> = Plugin {
    name: "roughdiffuse",
    origin: Origin::Mitsuba06,
    summary: "Oren–Nayar's rough diffuse reflector (σ = α/√2), with its interreflection \
              term. One-sided.",
    params: &[REFLECTANCE, OREN_NAYAR_ALPHA, USE_FAST_APPROX],
    build: |params, t| {
        Ok(Bsdf::RoughDiffuse(RoughDiffuse {
            reflectance: spectrum_texture(params, &REFLECTANCE, t)?,
            alpha: float_texture(params, &OREN_NAYAR_ALPHA, t)?,
            use_fast_approx: params.boolean(&USE_FAST_APPROX)?,
        }))
    },
};

pub(super) const DIFFUSETRANSMISSION: Plugin<Build> = Plugin {
    name: "diffusetransmission",
    origin: Origin::Prism,
    summary: "pbrt-v4's diffuse transmitter: Lambertian reflection R/π on the side of the \
              outgoing direction and Lambertian transmission T/π through the surface. Two-sided.",
    params: &[TRANSLUCENT_REFLECTANCE, TRANSMITTANCE],
    build: |params, t| {
        Ok(Bsdf::DiffuseTransmission(DiffuseTransmission {
            reflectance: spectrum_texture(params, &TRANSLUCENT_REFLECTANCE, t)?,
            transmittance: spectrum_texture(params, &TRANSMITTANCE, t)?,
        }))
    },
};

params! {
    TRANSLUCENT_REFLECTANCE = colour("reflectance", Range::Albedo, 0.25, "the reflectance R");
    TRANSMITTANCE = colour("transmittance", Range::Albedo, 0.25, "the transmittance T");
    REFLECTANCE = colour("reflectance", Range::Albedo, 0.5, "the reflectance ρ");
    OREN_NAYAR_ALPHA = ParamSpec::new("alpha", ParamKind::FloatTexture(Bounds::NON_NEGATIVE), Default::Float(0.2), "RMS slope of the surface; 0 is Lambert's law");
    USE_FAST_APPROX = ParamSpec::new("use_fast_approx", ParamKind::Boolean, Default::Boolean(false), "use the qualitative model of the paper's eq. 30");
}
