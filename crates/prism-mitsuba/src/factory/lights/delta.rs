//! Emitters without area, from a point or a direction: `point`, `spot`, `projector` and
//! `directional`.

use super::{
    Build, D65, Placement, SAMPLING_WEIGHT, TO_WORLD, emission_param, exclusive, invertible,
};
use crate::description::{NestedPlugin, PluginClass};
use crate::factory::fov::{FOCAL_LENGTH, FOV, FOV_AXIS, horizontal_fov_param};
use crate::factory::textures::{TextureCache, build_texture};
use crate::params::Params;
use crate::registry::{Bounds, Default, Origin, ParamKind, ParamSpec, Plugin, Range, params};
use glam::{DVec3, Vec3};
use prism_core::error::{Error, Result};
use prism_core::light::{DirectionalLight, Light, PointLight, Projector, SpotLight};
use prism_core::texture::{Texture, TextureUse, TextureValues};

pub(super) const POINT: Plugin<Build> = Plugin {
    name: "point",
    origin: Origin::Mitsuba3,
    summary: "A point light.",
    params: &[INTENSITY, POSITION, TO_WORLD, SAMPLING_WEIGHT],
    build: |params, _, _| build_point(params),
};

pub(super) const SPOT: Plugin<Build> = Plugin {
    name: "spot",
    origin: Origin::Mitsuba3,
    summary: "A spot light shining along its +z: full intensity within the beam, linear in \
              angle to zero at the cutoff; optionally projecting a `texture`.",
    params: &[
        INTENSITY,
        CUTOFF_ANGLE,
        BEAM_WIDTH,
        SPOT_TEXTURE,
        TO_WORLD,
        SAMPLING_WEIGHT,
    ],
    build: |params, _, textures| build_spot(params, textures),
};

pub(super) const PROJECTOR: Plugin<Build> = Plugin {
    name: "projector",
    origin: Origin::Mitsuba3,
    summary: "A pinhole projecting `irradiance` (an image) along its +z with the \
              perspective camera's field of view; a plane at distance z facing it \
              receives π · scale · irradiance / z².",
    params: &[
        PROJECTOR_IRRADIANCE,
        PROJECTOR_SCALE,
        FOV,
        FOV_AXIS,
        FOCAL_LENGTH,
        TO_WORLD,
        SAMPLING_WEIGHT,
    ],
    build: |params, _, textures| build_projector(params, textures),
};

pub(super) const DIRECTIONAL: Plugin<Build> = Plugin {
    name: "directional",
    origin: Origin::Mitsuba3,
    summary: "Light from one direction, at infinity.",
    params: &[IRRADIANCE, DIRECTION, TO_WORLD, SAMPLING_WEIGHT],
    build: |params, _, _| build_directional(params),
};

params! {
    INTENSITY = ParamSpec::new("intensity", ParamKind::Spectrum { range: Range::Emission, textured: false, }, D65, "radiant intensity (on the axis, for a spot); or a nested blackbody");
    IRRADIANCE = ParamSpec::new("irradiance", ParamKind::Spectrum { range: Range::Emission, textured: false, }, D65, "irradiance on a surface facing the light; or a nested blackbody");
    SPOT_TEXTURE = ParamSpec::new("texture", ParamKind::Nested(PluginClass::Texture), Default::Text("none"), "a texture projected along the light, spanning the square around the cone at z = 1 (its colours read as for textured emission); needs `cutoff_angle` below 90");
    PROJECTOR_IRRADIANCE = ParamSpec::new("irradiance", ParamKind::Spectrum { range: Range::Emission, textured: true, }, D65, "the image on the plane z = 1 (a `<texture>`, its colours read as for textured emission, which sets the aspect ratio), or a value");
    PROJECTOR_SCALE = ParamSpec::new("scale", ParamKind::FloatIn(Bounds::FINITE_NON_NEGATIVE), Default::Float(1.0), "factor on the irradiance");
    POSITION = ParamSpec::new("position", ParamKind::Point, Default::Text("the origin"), "where the light is (or give `to_world`)");
    DIRECTION = ParamSpec::new("direction", ParamKind::Vector, Default::Text("+z"), "where the light travels (or give `to_world`: its +z)");
    CUTOFF_ANGLE = ParamSpec::new("cutoff_angle", ParamKind::FloatIn(Bounds::between(0.0, 180.0)), Default::Float(20.0), "angle from the axis, in degrees, beyond which there is no light");
    BEAM_WIDTH = ParamSpec::new("beam_width", ParamKind::Float, Default::Text("¾ `cutoff_angle`"), "angle, in degrees, within which the intensity is full");
}

fn build_point(params: &Params) -> Result<Light> {
    let intensity = emission_param(params, &INTENSITY)?;
    let position = match exclusive(params, &POSITION)? {
        Placement::Given(_) => params.point_opt(&POSITION)?.unwrap_or_default(),
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
    Ok(Light::Point(PointLight {
        position,
        intensity,
    }))
}

fn build_spot(params: &Params, textures: &mut TextureCache) -> Result<Light> {
    let intensity = emission_param(params, &INTENSITY)?;
    let cutoff = params.float_in(&CUTOFF_ANGLE)?;
    if cutoff == 0.0 {
        return Err(Error::input(
            params.location_of(&CUTOFF_ANGLE),
            "the spot emitter's cutoff_angle must be greater than 0",
        ));
    }
    let beam = params.float_between(&BEAM_WIDTH, 0.75 * cutoff, 0.0, cutoff)?;
    let to_world = invertible(params, &TO_WORLD)?;
    let light = SpotLight::new(
        to_world,
        intensity,
        cutoff.to_radians() as f32,
        beam.to_radians() as f32,
    );
    let Some(child) = params.named_child(&SPOT_TEXTURE) else {
        return Ok(Light::Spot(light));
    };
    let texture = emission_texture_child(params, &SPOT_TEXTURE, child, textures)?;
    if cutoff >= 90.0 {
        return Err(Error::input(
            params.location_of(&CUTOFF_ANGLE),
            format!(
                "a spot light with a texture projects it onto the plane before it, so its \
                 cutoff_angle must be below 90 degrees, not {cutoff}"
            ),
        ));
    }
    Ok(Light::Spot(light.with_texture(texture)))
}

/// The nested plugin `child` given for parameter `spec`, which must be a texture, read as
/// emission.
fn emission_texture_child(
    params: &Params,
    spec: &ParamSpec,
    child: &NestedPlugin,
    textures: &mut TextureCache,
) -> Result<Texture> {
    if child.node.class != PluginClass::Texture {
        return Err(Error::input(
            &child.node.location,
            format!(
                "{} cannot give parameter \"{}\" of {}",
                child.node.describe(),
                spec.name,
                params.node().describe()
            ),
        )
        .with_help("give a <texture>, such as <texture type=\"bitmap\">"));
    }
    build_texture(&child.node, TextureUse::Emission, textures)
}

/// Mitsuba's `projector`: the irradiance image (or value), its scale, the field of view along
/// the image's aspect ratio (1 for a value), and the placement.
fn build_projector(params: &Params, textures: &mut TextureCache) -> Result<Light> {
    let (irradiance, aspect) = match params.named_child(&PROJECTOR_IRRADIANCE) {
        Some(child) if child.node.class == PluginClass::Texture => {
            let texture = emission_texture_child(params, &PROJECTOR_IRRADIANCE, child, textures)?;
            let aspect = texture.aspect_ratio();
            (texture, aspect)
        }
        _ => (
            Texture::Constant(emission_param(params, &PROJECTOR_IRRADIANCE)?),
            1.0,
        ),
    };
    let scale = params.float_in(&PROJECTOR_SCALE)?;
    let fov_x = horizontal_fov_param(params, aspect)?;
    let to_world = invertible(params, &TO_WORLD)?;
    Ok(Light::Projector(Projector::new(
        to_world,
        irradiance,
        scale as f32,
        fov_x.to_radians() as f32,
        aspect as f32,
    )))
}

fn build_directional(params: &Params) -> Result<Light> {
    let irradiance = emission_param(params, &IRRADIANCE)?;
    let direction = match exclusive(params, &DIRECTION)? {
        Placement::Given(location) => {
            let d = params.vector_opt(&DIRECTION)?.unwrap_or(DVec3::Z);
            if !(d.length() > 0.0 && d.is_finite()) {
                return Err(Error::input(
                    location,
                    "the directional emitter's direction must be a finite, non-zero vector",
                ));
            }
            d
        }
        Placement::Transform(_) => {
            let to_world = invertible(params, &TO_WORLD)?;
            to_world.vector(Vec3::Z).as_dvec3()
        }
        Placement::Default => DVec3::Z,
    };
    Ok(Light::Directional(DirectionalLight::new(
        direction.normalize().as_vec3(),
        irradiance,
    )))
}
