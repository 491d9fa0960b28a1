//! Optical elements that change the polarization of light passing straight through them:
//! Mitsuba 3's `polarizer`, `retarder` and `circular`. An unpolarized render sees each as a
//! grey filter (its Mueller matrix's M₀₀); a scene with one renders polarized.

use super::{Build, colour};
use crate::factory::textures::{TextureCache, float_texture, spectrum_texture};
use crate::params::Params;
use crate::registry::{Bounds, Default, Origin, ParamKind, ParamSpec, Plugin, Range, params};
use prism_core::bsdf::{Bsdf, Circular, Polarizer, Retarder};
use prism_core::error::Result;

pub(super) const POLARIZER: Plugin<Build> = Plugin {
    name: "polarizer",
    origin: Origin::Mitsuba3,
    summary: "An ideal linear polarizer that light passes straight through (a null lobe, \
              both sides); its absorbing axis is the surface's v direction turned by \
              `theta`. Unpolarized light keeps half its intensity.",
    params: &[POLARIZER_THETA, TRANSMITTANCE, POLARIZING],
    build: build_polarizer,
};

pub(super) const RETARDER: Plugin<Build> = Plugin {
    name: "retarder",
    origin: Origin::Mitsuba3,
    summary: "An ideal linear retarder (a wave plate) that light passes straight through \
              (a null lobe, both sides): its fast axis is the surface's u direction turned \
              by `theta`; its retardance `delta` shrinks with the cosine of incidence, as \
              Mitsuba 3 approximates it.",
    params: &[RETARDER_THETA, DELTA, TRANSMITTANCE],
    build: build_retarder,
};

pub(super) const CIRCULAR: Plugin<Build> = Plugin {
    name: "circular",
    origin: Origin::Mitsuba3,
    summary: "An ideal circular polarizer that light passes straight through (a null \
              lobe, both sides), passing right (or left) circular light. Unpolarized light \
              keeps half its intensity.",
    params: &[LEFT_HANDED, TRANSMITTANCE],
    build: build_circular,
};

params! {
    POLARIZER_THETA = ParamSpec::new("theta", ParamKind::FloatTexture(Bounds::FINITE), Default::Float(0.0), "the angle in degrees of the absorbing axis from the surface's v direction, towards u");
    RETARDER_THETA = ParamSpec::new("theta", ParamKind::FloatTexture(Bounds::FINITE), Default::Float(0.0), "the angle in degrees of the fast axis from the surface's u direction");
    DELTA = ParamSpec::new("delta", ParamKind::FloatTexture(Bounds::FINITE), Default::Float(90.0), "the retardance in degrees at normal incidence: 90 is a quarter-wave plate, 180 a half-wave plate");
    TRANSMITTANCE = colour("transmittance", Range::Albedo, 1.0, "a factor on the light that passes");
    POLARIZING = ParamSpec::new("polarizing", ParamKind::Boolean, Default::Boolean(true), "false: a neutral filter of ½ · transmittance that leaves the polarization alone");
    LEFT_HANDED = ParamSpec::new("left_handed", ParamKind::Boolean, Default::Boolean(false), "pass left circular light instead of right");
}

fn build_polarizer(params: &Params, t: &mut TextureCache) -> Result<Bsdf> {
    Ok(Bsdf::Polarizer(Polarizer {
        theta: float_texture(params, &POLARIZER_THETA, t)?,
        transmittance: spectrum_texture(params, &TRANSMITTANCE, t)?,
        polarizing: params.boolean(&POLARIZING)?,
    }))
}

fn build_retarder(params: &Params, t: &mut TextureCache) -> Result<Bsdf> {
    Ok(Bsdf::Retarder(Retarder {
        theta: float_texture(params, &RETARDER_THETA, t)?,
        delta: float_texture(params, &DELTA, t)?,
        transmittance: spectrum_texture(params, &TRANSMITTANCE, t)?,
    }))
}

fn build_circular(params: &Params, t: &mut TextureCache) -> Result<Bsdf> {
    Ok(Bsdf::Circular(Circular {
        left_handed: params.boolean(&LEFT_HANDED)?,
        transmittance: spectrum_texture(params, &TRANSMITTANCE, t)?,
    }))
}
