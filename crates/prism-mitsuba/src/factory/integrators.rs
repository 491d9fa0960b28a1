//! Integrator plugins: `path` (with Prism's `emitter_sampling`, see [`prism_core::light::sampler`])
//! and the lecture's `distrib`.

use crate::description::PluginNode;
use crate::params::Params;
use prism_core::error::{Error, Result};
use prism_core::integrator::distribution::DirectLights;
use prism_core::integrator::{DistributionIntegrator, Integrator, PathIntegrator};
use prism_core::light::LightSelection;

pub const SUPPORTED_INTEGRATORS: &[&str] = &["path", "distrib"];

/// `max_depth`: −1 (unbounded) or at least 0.
fn max_depth(params: &Params) -> Result<i32> {
    let max_depth = params.integer("max_depth", -1)?;
    if max_depth < -1 || max_depth > i64::from(i32::MAX) {
        return Err(Error::input(
            params.location_of("max_depth"),
            format!("max_depth must be -1 (unbounded) or at least 0, not {max_depth}"),
        ));
    }
    Ok(max_depth as i32)
}

/// A count that must be at least 1 (and sensible).
fn count(params: &Params, name: &'static str, default: i64) -> Result<u32> {
    let value = params.integer(name, default)?;
    if !(1..=1024).contains(&value) {
        return Err(Error::input(
            params.location_of(name),
            format!("\"{name}\" must be between 1 and 1024, not {value}"),
        ));
    }
    Ok(value as u32)
}

pub fn build_integrator(node: &PluginNode) -> Result<Integrator> {
    let params = Params::new(node);
    let integrator = match node.plugin_type.as_str() {
        "path" => {
            let max_depth = max_depth(&params)?;
            let rr_depth = params.integer("rr_depth", 5)?;
            if rr_depth < 1 || rr_depth > i64::from(i32::MAX) {
                return Err(Error::input(
                    params.location_of("rr_depth"),
                    format!("rr_depth must be at least 1, not {rr_depth}"),
                ));
            }
            let hide_emitters = params.boolean("hide_emitters", false)?;
            let light_selection = match params.string("emitter_sampling", "power")? {
                "power" => LightSelection::Power,
                "uniform" => LightSelection::Uniform,
                other => {
                    return Err(Error::input(
                        params.location_of("emitter_sampling"),
                        format!("unknown emitter_sampling \"{other}\""),
                    )
                    .with_help(
                        "use \"power\" (lights chosen in proportion to their power) or \"uniform\"",
                    ));
                }
            };
            Integrator::Path(PathIntegrator {
                max_depth,
                rr_depth: rr_depth as i32,
                hide_emitters,
                light_selection,
            })
        }
        "distrib" => {
            let defaults = DistributionIntegrator::default();
            let lights = match params.string("lights", "power")? {
                "power" => DirectLights::One(LightSelection::Power),
                "uniform" => DirectLights::One(LightSelection::Uniform),
                "all" => DirectLights::All,
                other => {
                    return Err(Error::input(
                        params.location_of("lights"),
                        format!("unknown light selection \"{other}\""),
                    )
                    .with_help(
                        "use \"power\" (one light chosen in proportion to its power), \"uniform\" or \"all\"",
                    ));
                }
            };
            let rr_threshold = params.float("rr_threshold", f64::from(defaults.rr_threshold))?;
            if !(rr_threshold > 0.0 && rr_threshold.is_finite()) {
                return Err(Error::input(
                    params.location_of("rr_threshold"),
                    format!("rr_threshold must be positive, not {rr_threshold}"),
                ));
            }
            Integrator::Distribution(DistributionIntegrator {
                max_depth: max_depth(&params)?,
                bounce_samples: count(
                    &params,
                    "bounce_samples",
                    i64::from(defaults.bounce_samples),
                )?,
                shadow_rays: count(&params, "shadow_rays", i64::from(defaults.shadow_rays))?,
                lights,
                rr_threshold: rr_threshold as f32,
                hide_emitters: params.boolean("hide_emitters", false)?,
            })
        }
        other => {
            return Err(Error::input(
                &node.location,
                format!("unknown integrator type \"{other}\""),
            )
            .with_help(format!(
                "supported integrator types: {}",
                SUPPORTED_INTEGRATORS.join(", ")
            )));
        }
    };
    params.finish()?;
    Ok(integrator)
}
