//! Emitter plugins: `area` (nested in a shape), and at the top level of the scene `point`,
//! `spot`, `directional`, `constant` and `envmap` (see each light's module in [`prism_core::light`]
//! for its parameters). Emission may be given as `<rgb>` (an illuminant: the upsampled colour
//! times D65), `<float>` (D65 scaled), `<spectrum>` (as written) or a nested
//! `<spectrum type="blackbody">` with a `temperature` in kelvin.

use glam::{DMat4, DVec3, Vec3};

use super::spectra::{Range, spectrum_param};
use crate::description::{PluginClass, PluginNode};
use crate::params::Params;
use prism_core::bsdf::{Bsdf, Diffuse, Material};
use prism_core::error::{Error, Result, SourceLocation};
use prism_core::image::read_bitmap;
use prism_core::light::{
    AreaLight, ConstantLight, DirectionalLight, EnvironmentMap, Light, PointLight, SpotLight,
};
use prism_core::math::Transform;
use prism_core::spectrum::blackbody::Blackbody;
use prism_core::spectrum::{RgbIntent, Spectrum};

/// The emitter types this factory knows.
pub const SUPPORTED_EMITTERS: &[&str] =
    &["area", "point", "spot", "directional", "constant", "envmap"];

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
    let radiance = emission_param(&params, "radiance")?;
    params.finish()?;
    Ok(Light::Area(AreaLight { shape, radiance }))
}

/// The material of an emitting shape that names no BSDF: Mitsuba 3 gives such shapes a black
/// diffuse BSDF (not the usual 50 % grey), so an area light does not reflect other lights.
pub fn default_emitter_material() -> Material {
    Material {
        front: Bsdf::Diffuse(Diffuse {
            reflectance: prism_core::texture::Texture::constant(0.0),
        }),
        back: None,
    }
}

/// Builds an emitter declared at the top level of the scene.
pub fn build_scene_light(node: &PluginNode) -> Result<Light> {
    let params = Params::new(node);
    let light = match node.plugin_type.as_str() {
        "point" => {
            let intensity = emission_param(&params, "intensity")?;
            let position = match exclusive(&params, "position", "to_world")? {
                Placement::Given(_) => params.point_opt("position")?.unwrap_or_default(),
                Placement::Transform(m) => m.transform_point3(DVec3::ZERO),
                Placement::Default => DVec3::ZERO,
            }
            .as_vec3();
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
        "spot" => {
            let intensity = emission_param(&params, "intensity")?;
            let cutoff = params.float_in("cutoff_angle", 20.0, 0.0, 180.0)?;
            if cutoff == 0.0 {
                return Err(Error::input(
                    params.location_of("cutoff_angle"),
                    "the spot emitter's cutoff_angle must be greater than 0",
                ));
            }
            let beam = params.float_in("beam_width", 0.75 * cutoff, 0.0, cutoff)?;
            let to_world = invertible(&params, "to_world")?;
            Light::Spot(SpotLight::new(
                to_world,
                intensity,
                cutoff.to_radians() as f32,
                beam.to_radians() as f32,
            ))
        }
        "directional" => {
            let irradiance = emission_param(&params, "irradiance")?;
            let direction = match exclusive(&params, "direction", "to_world")? {
                Placement::Given(location) => {
                    let d = params.vector_opt("direction")?.unwrap_or(DVec3::Z);
                    if !(d.length() > 0.0 && d.is_finite()) {
                        return Err(Error::input(
                            location,
                            "the directional emitter's direction must be a finite, non-zero vector",
                        ));
                    }
                    d
                }
                Placement::Transform(_) => {
                    let to_world = invertible(&params, "to_world")?;
                    to_world.vector(Vec3::Z).as_dvec3()
                }
                Placement::Default => DVec3::Z,
            };
            Light::Directional(DirectionalLight::new(
                direction.normalize().as_vec3(),
                irradiance,
            ))
        }
        "constant" => Light::Constant(ConstantLight::new(emission_param(&params, "radiance")?)),
        "envmap" => build_envmap(&params)?,
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

/// Checks that a scene has at most one environment emitter (`constant` or `envmap`), as
/// Mitsuba requires; `lights` are the top-level emitters with their elements' locations.
pub fn check_single_environment(lights: &[(Light, SourceLocation)]) -> Result<()> {
    let mut environments = lights.iter().filter(|(light, _)| light.is_environment());
    if let (Some(_), Some((_, second))) = (environments.next(), environments.next()) {
        return Err(
            Error::input(second, "the scene has more than one environment emitter")
                .with_help("keep one \"constant\" or \"envmap\" emitter; Mitsuba allows only one"),
        );
    }
    Ok(())
}

/// How an emitter is placed: by its own parameter (`position`, `direction`), by `to_world`,
/// or by default.
enum Placement<'a> {
    Given(&'a SourceLocation),
    Transform(DMat4),
    Default,
}

/// Reads the pair of mutually exclusive placement parameters `own` and `to_world`.
fn exclusive<'a>(
    params: &Params<'a>,
    own: &'static str,
    to_world: &'static str,
) -> Result<Placement<'a>> {
    let has_own = params.property(own).is_some();
    let transform = params.transform_opt(to_world)?;
    match (has_own, transform) {
        (true, Some(_)) => Err(Error::input(
            params.location_of(own),
            format!(
                "{} takes either \"{own}\" or \"{to_world}\", not both",
                params.node().describe()
            ),
        )),
        (true, None) => Ok(Placement::Given(params.location_of(own))),
        (false, Some(m)) => Ok(Placement::Transform(m)),
        (false, None) => Ok(Placement::Default),
    }
}

/// An invertible transform parameter (identity when absent).
fn invertible(params: &Params, name: &'static str) -> Result<Transform> {
    Transform::new(params.transform(name)?).ok_or_else(|| {
        Error::input(
            params.location_of(name),
            format!(
                "the \"{name}\" transform of {} is singular or not affine",
                params.node().describe()
            ),
        )
        .with_help("check for a zero scale or a malformed matrix")
    })
}

/// The emitted radiance, intensity or irradiance given for parameter `name` (default: D65 of
/// luminance 1, as Mitsuba's `Texture::D65(1)`): a value, or a nested blackbody spectrum.
fn emission_param(params: &Params, name: &'static str) -> Result<Spectrum> {
    let Some(child) = params.named_child(name) else {
        if params.property(name).is_none() {
            return Ok(Spectrum::from_rgb([1.0; 3], RgbIntent::Illuminant));
        }
        return spectrum_param(params, name, 1.0, Range::Emission);
    };
    if child.node.class != PluginClass::Spectrum || child.node.plugin_type != "blackbody" {
        return Err(Error::input(
            &child.location,
            format!(
                "{} for parameter \"{name}\" of {} is not supported",
                child.node.describe(),
                params.node().describe()
            ),
        )
        .with_help(
            "give the value as <rgb>, <spectrum>, <float> or <spectrum type=\"blackbody\">",
        ));
    }
    let blackbody = Params::new(&child.node);
    let Some(temperature) = blackbody.float_opt("temperature")? else {
        return Err(Error::input(
            &child.node.location,
            "the blackbody spectrum needs a \"temperature\" (in kelvin)",
        )
        .with_help("add <float name=\"temperature\" value=\"5000\"/>"));
    };
    if !(temperature > 0.0 && temperature.is_finite() && temperature < f64::from(f32::MAX)) {
        return Err(Error::input(
            blackbody.location_of("temperature"),
            format!(
                "the blackbody temperature must be a positive number of kelvin, not {temperature}"
            ),
        ));
    }
    blackbody.finish()?;
    Ok(Spectrum::Blackbody(Blackbody {
        temperature: temperature as f32,
    }))
}

/// Mitsuba's `envmap`: `filename` (required), `scale` (1), `to_world` (identity).
fn build_envmap(params: &Params) -> Result<Light> {
    let node = params.node();
    let Some(filename) = params.string_opt("filename")? else {
        return Err(Error::input(
            &node.location,
            format!("{} needs a \"filename\"", node.describe()),
        )
        .with_help("add <string name=\"filename\" value=\"sky.exr\"/>"));
    };
    let location = params.location_of("filename");
    let path = node.resolve_file(filename, location)?;
    let bitmap = read_bitmap(&path).map_err(|e| e.at(location))?;
    if bitmap.width < 2 || bitmap.height < 3 {
        return Err(Error::input(
            location,
            format!(
                "the environment map \"{filename}\" has {} × {} pixels; at least 2 × 3 are needed",
                bitmap.width, bitmap.height
            ),
        ));
    }
    if let Some(index) = bitmap.data.iter().position(|v| *v < 0.0) {
        let pixel = index / bitmap.channels;
        return Err(Error::input(
            location,
            format!(
                "pixel ({}, {}) of the environment map \"{filename}\" is negative",
                pixel % bitmap.width,
                pixel / bitmap.width
            ),
        )
        .with_help("radiance cannot be negative: clamp the image to 0"));
    }
    let scale = params.float("scale", 1.0)?;
    if !(scale >= 0.0 && scale.is_finite() && scale <= f64::from(f32::MAX)) {
        return Err(Error::input(
            params.location_of("scale"),
            format!("the environment map's scale must be finite and at least 0, not {scale}"),
        ));
    }
    let to_world = invertible(params, "to_world")?;
    Ok(Light::Envmap(EnvironmentMap::new(
        bitmap,
        scale as f32,
        to_world,
    )))
}
