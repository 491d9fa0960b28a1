//! Integrator plugins: `path` (with Prism's `emitter_sampling`, see
//! [`prism_core::light::sampler`]), the lecture's `distrib`, and `volpath` and `volpathmis`
//! for media.

use crate::description::{PluginClass, PluginNode};
use crate::params::Params;
use crate::registry::{Default, Origin, ParamKind, ParamSpec, Plugin, Registry};
use prism_core::error::{Error, Result};
use prism_core::integrator::distribution::DirectLights;
use prism_core::integrator::{
    DistributionIntegrator, Integrator, PathIntegrator, Tracking, VolPathIntegrator,
};
use prism_core::light::LightSelection;

type Build = fn(&Params) -> Result<Integrator>;

pub static INTEGRATORS: Registry<Build> = Registry {
    class: PluginClass::Integrator,
    plugins: &[
        Plugin {
            name: "path",
            origin: Origin::Mitsuba3,
            summary: "Path tracing with next-event estimation, multiple importance sampling \
                      (power heuristic) and Russian roulette on the path's potential.",
            params: &[MAX_DEPTH, RR_DEPTH, HIDE_EMITTERS, EMITTER_SAMPLING],
            build: build_path,
        },
        Plugin {
            name: "distrib",
            origin: Origin::Prism,
            summary: "The lecture's distribution ray tracer: at a vertex N = clamp(round(\
                      bounce_samples · potential), 1, bounce_samples) bounce samples and as \
                      many shadow rays per light, Russian roulette with survival \
                      s = min(1, potential / rr_threshold), where the potential is the factor \
                      the vertex's estimate carries into the pixel.",
            params: &[
                MAX_DEPTH,
                BOUNCE_SAMPLES,
                SHADOW_RAYS,
                LIGHTS,
                RR_THRESHOLD,
                HIDE_EMITTERS,
            ],
            build: build_distrib,
        },
        Plugin {
            name: "volpath",
            origin: Origin::Mitsuba3,
            summary: "Volumetric path tracing: `path` with participating media between the \
                      surfaces, free flights by spectral tracking with one majorant for the \
                      path's four wavelengths, shadow rays through media (closed-form or \
                      ratio-tracking transmittance) and `null` boundaries, light and phase \
                      samples in media combined by MIS.",
            params: &[MAX_DEPTH, RR_DEPTH, HIDE_EMITTERS, EMITTER_SAMPLING],
            build: build_volpath,
        },
        Plugin {
            name: "volpathmis",
            origin: Origin::Mitsuba3,
            summary: "Volumetric path tracing with spectral MIS (Miller, Georgiev & Jarosz \
                      2019): `volpath`'s path loop with the hero wavelength's free flights, \
                      combined over the path's four wavelengths and with light samples by the \
                      balance heuristic, so chromatic media stay free of fireflies.",
            params: &[
                MAX_DEPTH,
                RR_DEPTH,
                HIDE_EMITTERS,
                EMITTER_SAMPLING,
                USE_SPECTRAL_MIS,
            ],
            build: build_volpathmis,
        },
    ],
};

const MAX_DEPTH: ParamSpec = ParamSpec::new(
    "max_depth",
    ParamKind::Integer,
    Default::Integer(-1),
    "longest path: −1 unbounded, 1 emitters only, 2 direct light",
);
const RR_DEPTH: ParamSpec = ParamSpec::new(
    "rr_depth",
    ParamKind::Integer,
    Default::Integer(5),
    "depth from which Russian roulette may end paths",
);
const HIDE_EMITTERS: ParamSpec = ParamSpec::new(
    "hide_emitters",
    ParamKind::Boolean,
    Default::Boolean(false),
    "leave emitters seen directly by the camera black",
);
const EMITTER_SAMPLING: ParamSpec = ParamSpec::new(
    "emitter_sampling",
    ParamKind::Choice(&["power", "uniform"]),
    Default::Str("power"),
    "Prism only (Mitsuba rejects it): one light per shading point chosen ∝ its power × \
     `sampling_weight`, or ∝ `sampling_weight` alone (Mitsuba's rule; uniform by default)",
);
const USE_SPECTRAL_MIS: ParamSpec = ParamSpec::new(
    "use_spectral_mis",
    ParamKind::Boolean,
    Default::Boolean(true),
    "combine the four wavelengths' free-flight densities by MIS; false weights every \
     wavelength by the hero's densities alone",
);
const BOUNCE_SAMPLES: ParamSpec = ParamSpec::new(
    "bounce_samples",
    ParamKind::Integer,
    Default::Integer(4),
    "bounce samples at potential 1 (1 to 1024)",
);
const SHADOW_RAYS: ParamSpec = ParamSpec::new(
    "shadow_rays",
    ParamKind::Integer,
    Default::Integer(4),
    "shadow rays per light at potential 1 (1 to 1024)",
);
const LIGHTS: ParamSpec = ParamSpec::new(
    "lights",
    ParamKind::Choice(&["power", "uniform", "all"]),
    Default::Str("power"),
    "one light per vertex chosen ∝ power or uniformly, or every light",
);
const RR_THRESHOLD: ParamSpec = ParamSpec::new(
    "rr_threshold",
    ParamKind::Float,
    Default::Float(0.1),
    "potential below which Russian roulette starts",
);

/// Builds the integrator a node describes.
pub fn build_integrator(node: &PluginNode) -> Result<Integrator> {
    let plugin = INTEGRATORS.find(node)?;
    let params = Params::new(node, plugin.params);
    let integrator = (plugin.build)(&params)?;
    params.finish()?;
    Ok(integrator)
}

/// `max_depth`: −1 (unbounded) or at least 0.
fn max_depth(params: &Params) -> Result<i32> {
    let max_depth = params.integer(&MAX_DEPTH)?;
    if max_depth < -1 || max_depth > i64::from(i32::MAX) {
        return Err(Error::input(
            params.location_of(&MAX_DEPTH),
            format!("max_depth must be -1 (unbounded) or at least 0, not {max_depth}"),
        ));
    }
    Ok(max_depth as i32)
}

/// A count that must be at least 1 (and sensible).
fn count(params: &Params, spec: &ParamSpec) -> Result<u32> {
    let value = params.integer(spec)?;
    if !(1..=1024).contains(&value) {
        return Err(Error::input(
            params.location_of(spec),
            format!("\"{}\" must be between 1 and 1024, not {value}", spec.name),
        ));
    }
    Ok(value as u32)
}

fn build_path(params: &Params) -> Result<Integrator> {
    let max_depth = max_depth(params)?;
    let rr_depth = params.integer(&RR_DEPTH)?;
    if rr_depth < 1 || rr_depth > i64::from(i32::MAX) {
        return Err(Error::input(
            params.location_of(&RR_DEPTH),
            format!("rr_depth must be at least 1, not {rr_depth}"),
        ));
    }
    let light_selection = match params.choice(&EMITTER_SAMPLING)? {
        "uniform" => LightSelection::Uniform,
        _ => LightSelection::Power,
    };
    Ok(Integrator::Path(PathIntegrator {
        max_depth,
        rr_depth: rr_depth as i32,
        hide_emitters: params.boolean(&HIDE_EMITTERS)?,
        light_selection,
    }))
}

fn build_volpath(params: &Params) -> Result<Integrator> {
    let Integrator::Path(path) = build_path(params)? else {
        unreachable!("build_path builds a path integrator");
    };
    Ok(Integrator::VolPath(VolPathIntegrator {
        max_depth: path.max_depth,
        rr_depth: path.rr_depth,
        hide_emitters: path.hide_emitters,
        light_selection: path.light_selection,
        tracking: Tracking::Spectral,
    }))
}

fn build_volpathmis(params: &Params) -> Result<Integrator> {
    let Integrator::VolPath(volpath) = build_volpath(params)? else {
        unreachable!("build_volpath builds a volumetric path integrator");
    };
    Ok(Integrator::VolPath(VolPathIntegrator {
        tracking: Tracking::HeroMis {
            spectral_mis: params.boolean(&USE_SPECTRAL_MIS)?,
        },
        ..volpath
    }))
}

fn build_distrib(params: &Params) -> Result<Integrator> {
    let lights = match params.choice(&LIGHTS)? {
        "uniform" => DirectLights::One(LightSelection::Uniform),
        "all" => DirectLights::All,
        _ => DirectLights::One(LightSelection::Power),
    };
    let rr_threshold = params.float(&RR_THRESHOLD)?;
    if !(rr_threshold > 0.0 && rr_threshold.is_finite()) {
        return Err(Error::input(
            params.location_of(&RR_THRESHOLD),
            format!("rr_threshold must be positive, not {rr_threshold}"),
        ));
    }
    Ok(Integrator::Distribution(DistributionIntegrator {
        max_depth: max_depth(params)?,
        bounce_samples: count(params, &BOUNCE_SAMPLES)?,
        shadow_rays: count(params, &SHADOW_RAYS)?,
        lights,
        rr_threshold: rr_threshold as f32,
        hide_emitters: params.boolean(&HIDE_EMITTERS)?,
    }))
}
