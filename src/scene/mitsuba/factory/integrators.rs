//! Integrator plugins: `path` (with Prism's `emitter_sampling`, see [`crate::light::sampler`]).

use crate::error::{Error, Result};
use crate::integrator::{Integrator, PathIntegrator};
use crate::light::LightSelection;
use crate::scene::mitsuba::description::PluginNode;
use crate::scene::mitsuba::params::Params;

pub const SUPPORTED_INTEGRATORS: &[&str] = &["path"];

pub fn build_integrator(node: &PluginNode) -> Result<Integrator> {
    let params = Params::new(node);
    let integrator = match node.plugin_type.as_str() {
        "path" => {
            let max_depth = params.integer("max_depth", -1)?;
            if max_depth < -1 || max_depth > i64::from(i32::MAX) {
                return Err(Error::input(
                    params.location_of("max_depth"),
                    format!("max_depth must be -1 (unbounded) or at least 0, not {max_depth}"),
                ));
            }
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
                max_depth: max_depth as i32,
                rr_depth: rr_depth as i32,
                hide_emitters,
                light_selection,
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
