//! Emitter plugins: `area` (nested in a shape) and `point`.

use glam::Vec3;

use super::spectra::{Range, spectrum_param};
use crate::error::{Error, Result};
use crate::light::{AreaLight, Light, PointLight};
use crate::scene::mitsuba::description::PluginNode;
use crate::scene::mitsuba::params::Params;

/// The emitter types this factory knows.
pub const SUPPORTED_EMITTERS: &[&str] = &["area", "point"];

/// Builds the area light nested in the shape with index `shape`.
pub fn build_area_light(node: &PluginNode, shape: u32) -> Result<Light> {
    if node.plugin_type != "area" {
        let help = if SUPPORTED_EMITTERS.contains(&node.plugin_type.as_str()) {
            "only an \"area\" emitter can be nested in a shape; declare other emitters at the top level of the scene".to_string()
        } else {
            format!("supported emitter types: {}", SUPPORTED_EMITTERS.join(", "))
        };
        return Err(Error::input(
            &node.location,
            format!(
                "emitter \"{}\" cannot be attached to a shape",
                node.plugin_type
            ),
        )
        .with_help(help));
    }
    let params = Params::new(node);
    let radiance = spectrum_param(&params, "radiance", 1.0, Range::Emission)?;
    params.finish()?;
    Ok(Light::Area(AreaLight { shape, radiance }))
}

/// Builds an emitter declared at the top level of the scene.
pub fn build_scene_light(node: &PluginNode) -> Result<Light> {
    let params = Params::new(node);
    let light = match node.plugin_type.as_str() {
        "point" => {
            let intensity = spectrum_param(&params, "intensity", 1.0, Range::Emission)?;
            let position = params.point_opt("position")?;
            let to_world = params.transform_opt("to_world")?;
            let position = match (position, to_world) {
                (Some(_), Some(_)) => {
                    return Err(Error::input(
                        params.location_of("position"),
                        "a point emitter takes either \"position\" or \"to_world\", not both",
                    ));
                }
                (Some(p), None) => p.as_vec3(),
                (None, Some(m)) => m.transform_point3(glam::DVec3::ZERO).as_vec3(),
                (None, None) => Vec3::ZERO,
            };
            if !position.is_finite() {
                return Err(Error::input(
                    params.location(),
                    "the point emitter's position is not finite",
                ));
            }
            Light::Point(PointLight {
                position,
                intensity,
            })
        }
        "area" => {
            return Err(Error::input(
                &node.location,
                "an \"area\" emitter must be nested in a shape",
            )
            .with_help("move it inside the <shape> that should emit light"));
        }
        other => {
            return Err(
                Error::input(&node.location, format!("unknown emitter type \"{other}\""))
                    .with_help(format!(
                        "supported emitter types: {}",
                        SUPPORTED_EMITTERS.join(", ")
                    )),
            );
        }
    };
    params.finish()?;
    Ok(light)
}
