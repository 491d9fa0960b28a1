//! Emitter plugins: `area` and `directionalarea` (nested in a shape, or declared with an id and
//! referenced from one),
//! and at the top level of the scene `point`, `spot`, `projector` and `directional` (module
//! `delta`), and `constant`, `envmap`, `equal_area_envmap` and `sunsky` (module `environment`); see each light's
//! module in [`prism_core::light`] for its parameters. Emission may be given as `<rgb>` (an
//! illuminant: the upsampled colour times D65), `<float>` (D65 scaled), `<spectrum>` (as
//! written) or a nested `<spectrum type="blackbody">` with a `temperature` in kelvin; an area
//! emitter's radiance may also be a `<texture>` (as a projector's `irradiance` and a spot's
//! `texture`), whose colours are upsampled as reflectances are, without the D65 factor of an
//! `<rgb>` radiance (as Mitsuba 3 reads them).

mod area;
mod delta;
mod environment;

use crate::description::{PluginClass, PluginNode};
use crate::factory::spectra::{NestedSpectrum, build_nested_spectrum, spectrum_param};
use crate::factory::textures::TextureCache;
use crate::params::Params;
use crate::registry::{Bounds, Default, ParamKind, ParamSpec, Registry, params};
use glam::DMat4;
use prism_core::bsdf::{Diffuse, Material};
use prism_core::error::{Error, Result, SourceLocation};
use prism_core::light::{Light, LightSource};
use prism_core::math::Transform;
use prism_core::spectrum::{RgbIntent, Spectrum};

/// Builds an emitter: nested in the shape with this index (`Some`), or at the top level, with
/// the scene's textures.
type Build = fn(&Params, Option<u32>, &mut TextureCache) -> Result<Light>;

/// Every emitter, each declared in the module of its kind.
pub static EMITTERS: Registry<Build> = Registry {
    class: PluginClass::Emitter,
    plugins: &[
        area::AREA,
        area::DIRECTIONAL_AREA,
        delta::POINT,
        delta::SPOT,
        delta::PROJECTOR,
        delta::DIRECTIONAL,
        environment::CONSTANT,
        environment::ENVMAP,
        environment::EQUAL_AREA_ENVMAP,
        environment::SUNSKY,
    ],
};

params! {
    /// The weight of every emitter in the choice of a light to sample.
    SAMPLING_WEIGHT = ParamSpec::new("sampling_weight", ParamKind::FloatIn(Bounds::FINITE_NON_NEGATIVE), Default::Float(1.0), "relative weight of choosing this emitter for direct light: P ∝ weight (uniform `emitter_sampling`, Mitsuba's rule) or ∝ power × weight (by power); 0 never chooses it");
}

/// The default emission: the illuminant D65 of luminance 1.
const D65: Default = Default::Text("D65 of luminance 1");

params! {
    /// The placement of the emitters that have one.
    TO_WORLD = ParamSpec::new("to_world", ParamKind::Transform, Default::Text("identity"), "the emitter's placement");
}

/// Builds the emitter nested in the shape with index `shape` (`area` or `directionalarea`),
/// with its sampling weight.
pub fn build_area_light(
    node: &PluginNode,
    shape: u32,
    textures: &mut TextureCache,
) -> Result<(Light, f32)> {
    let plugin = EMITTERS.find(node)?;
    if !is_area(node) {
        return Err(Error::input(
            &node.location,
            format!(
                "emitter \"{}\" cannot be attached to a shape",
                node.plugin_type
            ),
        )
        .with_help(
            "a shape holds an \"area\" or \"directionalarea\" emitter, or a point, spot, projector or directional one that lights the scene from its own to_world; declare environment emitters at the top level of the scene",
        ));
    }
    let params = Params::new(node, plugin.params);
    let light = (plugin.build)(&params, Some(shape), textures)?;
    let weight = sampling_weight(&params)?;
    params.finish()?;
    Ok((light, weight))
}

/// The material of an emitting shape that names no BSDF: Mitsuba 3 gives such shapes a black
/// diffuse BSDF (not the usual 50 % grey), so an area light does not reflect other lights.
pub fn default_emitter_material() -> Material {
    Material::new(Diffuse {
        reflectance: prism_core::texture::Texture::constant(0.0),
    })
}

/// Whether `node` is an emitter of a single point or direction (`point`, `spot`, `projector`,
/// `directional`), whose radiance on any surface is zero.
pub fn is_delta(node: &PluginNode) -> bool {
    node.class == PluginClass::Emitter
        && [
            delta::POINT.name,
            delta::SPOT.name,
            delta::PROJECTOR.name,
            delta::DIRECTIONAL.name,
        ]
        .contains(&node.plugin_type.as_str())
}

/// Whether `node` is an emitter that emits from the shape it is attached to (`area`,
/// `directionalarea`).
pub fn is_area(node: &PluginNode) -> bool {
    node.class == PluginClass::Emitter
        && [area::AREA.name, area::DIRECTIONAL_AREA.name].contains(&node.plugin_type.as_str())
}

/// Builds an emitter declared at the top level of the scene, other than `area` and
/// `directionalarea`, with its sampling weight.
pub fn build_scene_light(node: &PluginNode, textures: &mut TextureCache) -> Result<(Light, f32)> {
    let plugin = EMITTERS.find(node)?;
    let params = Params::new(node, plugin.params);
    let light = (plugin.build)(&params, None, textures)?;
    let weight = sampling_weight(&params)?;
    params.finish()?;
    Ok((light, weight))
}

/// The emitter's `sampling_weight`: finite and at least 0.
fn sampling_weight(params: &Params) -> Result<f32> {
    let weight = params.float_in(&SAMPLING_WEIGHT)?;
    Ok(weight as f32)
}

/// Checks that a scene has at most one environment emitter (`constant`, `envmap` or `sunsky`), as
/// Mitsuba requires; `lights` are the top-level emitters with their elements' locations.
pub fn check_single_environment(lights: &[(Light, f32, SourceLocation)]) -> Result<()> {
    let mut environments = lights.iter().filter(|(light, _, _)| light.is_environment());
    if let (Some(_), Some((_, _, second))) = (environments.next(), environments.next()) {
        return Err(
            Error::input(second, "the scene has more than one environment emitter").with_help(
                "keep one \"constant\", \"envmap\" or \"sunsky\" emitter; Mitsuba allows only one",
            ),
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
fn exclusive<'a>(params: &Params<'a>, own: &ParamSpec) -> Result<Placement<'a>> {
    let has_own = params.property(own).is_some();
    let transform = params.transform_opt(&TO_WORLD)?;
    match (has_own, transform) {
        (true, Some(_)) => Err(Error::input(
            params.location_of(own),
            format!(
                "{} takes either \"{}\" or \"to_world\", not both",
                params.node().describe(),
                own.name
            ),
        )),
        (true, None) => Ok(Placement::Given(params.location_of(own))),
        (false, Some(m)) => Ok(Placement::Transform(m)),
        (false, None) => Ok(Placement::Default),
    }
}

/// An invertible transform parameter (identity when absent).
fn invertible(params: &Params, spec: &ParamSpec) -> Result<Transform> {
    Transform::new(params.transform(spec)?).ok_or_else(|| {
        Error::input(
            params.location_of(spec),
            format!(
                "the \"{}\" transform of {} is singular or not affine",
                spec.name,
                params.node().describe()
            ),
        )
        .with_help("check for a zero scale or a malformed matrix")
    })
}

/// The emitted radiance, intensity or irradiance given for parameter `spec` (default: D65 of
/// luminance 1, as Mitsuba's `Texture::D65(1)`): a value, or a nested blackbody spectrum.
fn emission_param(params: &Params, spec: &ParamSpec) -> Result<Spectrum> {
    let Some(child) = params.named_child(spec) else {
        if params.property(spec).is_none() {
            return Ok(Spectrum::from_rgb([1.0; 3], RgbIntent::Illuminant));
        }
        return spectrum_param(params, spec);
    };
    let unsupported = || {
        Error::input(
            &child.location,
            format!(
                "{} for parameter \"{}\" of {} is not supported",
                child.node.describe(),
                spec.name,
                params.node().describe()
            ),
        )
        .with_help(if matches!(spec.kind, ParamKind::Spectrum { textured: true, .. }) {
            "give the value as <rgb>, <spectrum>, <float>, <spectrum type=\"blackbody\"> or <texture>"
        } else {
            "give the value as <rgb>, <spectrum>, <float> or <spectrum type=\"blackbody\">"
        })
    };
    if child.node.class != PluginClass::Spectrum {
        return Err(unsupported());
    }
    match build_nested_spectrum(&child.node)? {
        NestedSpectrum::Emission(spectrum) => Ok(spectrum),
        NestedSpectrum::Ior(_) => Err(unsupported()),
    }
}
