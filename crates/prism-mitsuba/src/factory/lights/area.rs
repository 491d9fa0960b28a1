//! The emitters that emit from the shape they are attached to: `area` and `directionalarea`.

use super::{Build, D65, SAMPLING_WEIGHT, emission_param};
use crate::description::PluginClass;
use crate::factory::textures::{TextureCache, build_texture};
use crate::params::Params;
use crate::registry::{Choice, Default, Origin, ParamKind, ParamSpec, Plugin, Range, params};
use prism_core::error::Result;
use prism_core::geometry::ShapeSampling;
use prism_core::light::{AreaLight, DirectionalAreaLight, Light};
use prism_core::texture::{Texture, TextureUse};

pub(super) const AREA: Plugin<Build> = Plugin {
    name: "area",
    origin: Origin::Mitsuba3,
    summary: "Nested in a shape, or declared with an `id` and referenced from one shape: emits \
              `radiance` (a value or a texture) from the side the normal points to. \
              Spheres are sampled by the cone they subtend, rectangles (two triangles \
              tiling one) seen from within two diagonals by the solid angle they subtend, \
              other shapes by area; \
              textured radiance by the texture's luminance mapped through the uv \
              parametrisation.",
    params: &[AREA_RADIANCE, SAMPLING_WEIGHT, AREA_SAMPLING],
    build: build_area,
};

params! {
    AREA_SAMPLING = ParamSpec::new("sampling", ParamKind::Choice(&[Choice::new("solid_angle", &ShapeSampling::SolidAngle), Choice::new("area", &ShapeSampling::Area)]), Default::Str("solid_angle"), "(Prism) how light samples find the shape: `solid_angle` (spheres by their cone, rectangles by the spherical rectangle from within two diagonals, other shapes by area) or `area` (every shape uniformly by area, the lecture's direct light sampling)");
    AREA_RADIANCE = ParamSpec::new("radiance", ParamKind::Spectrum { range: Range::Emission, textured: true, }, D65, "emitted radiance; or a nested `<spectrum type=\"blackbody\">`, or a `<texture>` (its colours upsampled as reflectances, without D65, as Mitsuba 3 reads them)");
}

/// Mitsuba's `area`: a value, a nested spectrum, or a texture read as emission.
fn build_area(params: &Params, shape: Option<u32>, textures: &mut TextureCache) -> Result<Light> {
    let shape = shape.unwrap_or(0);
    let sampling = params.choice(&AREA_SAMPLING)?;
    let light = match params.named_child(&AREA_RADIANCE) {
        Some(child) if child.node.class == PluginClass::Texture => {
            let texture = build_texture(&child.node, TextureUse::Emission, textures)?;
            AreaLight::new(shape, texture)
        }
        _ => AreaLight::uniform(shape, emission_param(params, &AREA_RADIANCE)?),
    };
    Ok(Light::Area(light.sampled_by(sampling)))
}

pub(super) const DIRECTIONAL_AREA: Plugin<Build> = Plugin {
    name: "directionalarea",
    origin: Origin::Mitsuba3,
    summary: "Nested in a shape, or declared with an `id` and referenced from one shape: emits \
              `radiance` (a value or a texture; a flux per unit area) only along the shading \
              normal. No ray or light sample can find a delta direction, so the shape looks \
              black and only `ptracer` renders what it lights (as in Mitsuba 3).",
    params: &[DIRECTIONAL_AREA_RADIANCE, SAMPLING_WEIGHT],
    build: build_directional_area,
};

params! {
    DIRECTIONAL_AREA_RADIANCE = ParamSpec::new("radiance", ParamKind::Spectrum { range: Range::Emission, textured: true, }, D65, "flux per unit area sent along the normal (the irradiance of a surface facing the beam); or a nested `<spectrum type=\"blackbody\">`, or a `<texture>` (its colours upsampled as reflectances, without D65)");
}

/// Mitsuba's `directionalarea`: a value, a nested spectrum, or a texture read as emission.
fn build_directional_area(
    params: &Params,
    shape: Option<u32>,
    textures: &mut TextureCache,
) -> Result<Light> {
    let radiance = match params.named_child(&DIRECTIONAL_AREA_RADIANCE) {
        Some(child) if child.node.class == PluginClass::Texture => {
            build_texture(&child.node, TextureUse::Emission, textures)?
        }
        _ => Texture::Constant(emission_param(params, &DIRECTIONAL_AREA_RADIANCE)?),
    };
    Ok(Light::DirectionalArea(DirectionalAreaLight::new(
        shape.unwrap_or(0),
        radiance,
    )))
}
