//! Emitter plugins: `area` (nested in a shape, or declared with an id and referenced from one),
//! and at the top level of the scene `point`, `spot`, `projector`, `directional`, `constant`,
//! `envmap` and `sunsky` (see each light's module in [`prism_core::light`] for its parameters). Emission may be given as `<rgb>` (an illuminant: the upsampled colour
//! times D65), `<float>` (D65 scaled), `<spectrum>` (as written) or a nested
//! `<spectrum type="blackbody">` with a `temperature` in kelvin; an area emitter's radiance may
//! also be a `<texture>` (as a projector's `irradiance` and a spot's `texture`), whose colours
//! are upsampled as reflectances are, without the D65 factor of an `<rgb>` radiance (as
//! Mitsuba 3 reads them).

use glam::{DMat4, DVec3, Vec3};

use super::fov::{FOCAL_LENGTH, FOV, FOV_AXIS, horizontal_fov_param};
use super::spectra::{NestedSpectrum, build_nested_spectrum, spectrum_param};
use super::textures::{TextureCache, build_texture};
use crate::description::{NestedPlugin, PluginClass, PluginNode};
use crate::params::Params;
use crate::registry::Range;
use crate::registry::{Bounds, Choice, Default, Origin, ParamKind, ParamSpec, Plugin, Registry};
use prism_core::bsdf::{Diffuse, Material};
use prism_core::error::{Error, Result, SourceLocation};
use prism_core::geometry::ShapeSampling;
use prism_core::image::read_bitmap;
use prism_core::light::sunsky::sun_position::{DateTime, Location, sun_angles};
use prism_core::light::{
    AreaLight, ConstantLight, DirectionalLight, EnvironmentMap, Light, LightSource, PointLight,
    Projector, SpotLight, Sunsky, SunskySettings,
};
use prism_core::math::Transform;
use prism_core::spectrum::{RgbIntent, Spectrum};
use prism_core::texture::{Texture, TextureUse};

/// Builds an emitter: nested in the shape with this index (`Some`), or at the top level, with
/// the scene's textures.
type Build = fn(&Params, Option<u32>, &mut TextureCache) -> Result<Light>;

pub static EMITTERS: Registry<Build> = Registry {
    class: PluginClass::Emitter,
    plugins: &[
        Plugin {
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
        },
        Plugin {
            name: "point",
            origin: Origin::Mitsuba3,
            summary: "A point light.",
            params: &[INTENSITY, POSITION, TO_WORLD, SAMPLING_WEIGHT],
            build: |params, _, _| build_point(params),
        },
        Plugin {
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
        },
        Plugin {
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
        },
        Plugin {
            name: "directional",
            origin: Origin::Mitsuba3,
            summary: "Light from one direction, at infinity.",
            params: &[IRRADIANCE, DIRECTION, TO_WORLD, SAMPLING_WEIGHT],
            build: |params, _, _| build_directional(params),
        },
        Plugin {
            name: "constant",
            origin: Origin::Mitsuba3,
            summary: "Uniform light from every direction, at infinity.",
            params: &[RADIANCE, SAMPLING_WEIGHT],
            build: |params, _, _| {
                Ok(Light::Constant(ConstantLight::new(emission_param(
                    params, &RADIANCE,
                )?)))
            },
        },
        Plugin {
            name: "envmap",
            origin: Origin::Mitsuba3,
            summary: "An environment map: a latitude–longitude image with Mitsuba's orientation                       (+y up, u = 0 looks along −z), pixel-node bilinear lookup and spectral                       upsampling; importance sampled ∝ luminance · sin θ.",
            params: &[ENVMAP_FILENAME, ENVMAP_SCALE, TO_WORLD, SAMPLING_WEIGHT],
            build: |params, _, _| build_envmap(params),
        },
        Plugin {
            name: "sunsky",
            origin: Origin::Mitsuba3,
            summary: "The Hosek–Wilkie sky and sun (spectral, W m⁻² sr⁻¹ nm⁻¹, zero outside \
                      320–720 nm), in a +z-up frame; the sun from `sun_direction` or from a \
                      place and time (Blanco-Muriel et al. 2001). Sampled by the sky's \
                      luminance over (φ, cos θ) and the sun's cone.",
            params: &[
                SUN_DIRECTION,
                LATITUDE,
                LONGITUDE,
                TIMEZONE,
                YEAR,
                MONTH,
                DAY,
                HOUR,
                MINUTE,
                SECOND,
                TURBIDITY,
                SKY_ALBEDO,
                SUN_SCALE,
                SKY_SCALE,
                SUN_APERTURE,
                COMPLEX_SUN,
                TO_WORLD,
                SAMPLING_WEIGHT,
            ],
            build: |params, _, _| build_sunsky(params),
        },
    ],
};

const SAMPLING_WEIGHT: ParamSpec = ParamSpec::new(
    "sampling_weight",
    ParamKind::FloatIn(Bounds::FINITE_NON_NEGATIVE),
    Default::Float(1.0),
    "relative weight of choosing this emitter for direct light: P ∝ weight (uniform \
     `emitter_sampling`, Mitsuba's rule) or ∝ power × weight (by power); 0 never chooses it",
);
const AREA_SAMPLING: ParamSpec = ParamSpec::new(
    "sampling",
    ParamKind::Choice(&[
        Choice {
            name: "solid_angle",
            value: &ShapeSampling::SolidAngle,
        },
        Choice {
            name: "area",
            value: &ShapeSampling::Area,
        },
    ]),
    Default::Str("solid_angle"),
    "(Prism) how light samples find the shape: `solid_angle` (spheres by their cone, rectangles \
     by the spherical rectangle from within two diagonals, other shapes by area) or `area` (every \
     shape uniformly by area, the lecture's direct light sampling)",
);
const D65: Default = Default::Text("D65 of luminance 1");
const RADIANCE: ParamSpec = ParamSpec::new(
    "radiance",
    ParamKind::Spectrum {
        range: Range::Emission,
        textured: false,
    },
    D65,
    "emitted radiance; or a nested `<spectrum type=\"blackbody\">`",
);
const AREA_RADIANCE: ParamSpec = ParamSpec::new(
    "radiance",
    ParamKind::Spectrum {
        range: Range::Emission,
        textured: true,
    },
    D65,
    "emitted radiance; or a nested `<spectrum type=\"blackbody\">`, or a `<texture>` (its \
     colours upsampled as reflectances, without D65, as Mitsuba 3 reads them)",
);
const INTENSITY: ParamSpec = ParamSpec::new(
    "intensity",
    ParamKind::Spectrum {
        range: Range::Emission,
        textured: false,
    },
    D65,
    "radiant intensity (on the axis, for a spot); or a nested blackbody",
);
const IRRADIANCE: ParamSpec = ParamSpec::new(
    "irradiance",
    ParamKind::Spectrum {
        range: Range::Emission,
        textured: false,
    },
    D65,
    "irradiance on a surface facing the light; or a nested blackbody",
);
const SPOT_TEXTURE: ParamSpec = ParamSpec::new(
    "texture",
    ParamKind::Nested(PluginClass::Texture),
    Default::Text("none"),
    "a texture projected along the light, spanning the square around the cone at z = 1 (its \
     colours read as for textured emission); needs `cutoff_angle` below 90",
);
const PROJECTOR_IRRADIANCE: ParamSpec = ParamSpec::new(
    "irradiance",
    ParamKind::Spectrum {
        range: Range::Emission,
        textured: true,
    },
    D65,
    "the image on the plane z = 1 (a `<texture>`, its colours read as for textured emission, \
     which sets the aspect ratio), or a value",
);
const PROJECTOR_SCALE: ParamSpec = ParamSpec::new(
    "scale",
    ParamKind::FloatIn(Bounds::FINITE_NON_NEGATIVE),
    Default::Float(1.0),
    "factor on the irradiance",
);
const POSITION: ParamSpec = ParamSpec::new(
    "position",
    ParamKind::Point,
    Default::Text("the origin"),
    "where the light is (or give `to_world`)",
);
const DIRECTION: ParamSpec = ParamSpec::new(
    "direction",
    ParamKind::Vector,
    Default::Text("+z"),
    "where the light travels (or give `to_world`: its +z)",
);
const TO_WORLD: ParamSpec = ParamSpec::new(
    "to_world",
    ParamKind::Transform,
    Default::Text("identity"),
    "the emitter's placement",
);
const CUTOFF_ANGLE: ParamSpec = ParamSpec::new(
    "cutoff_angle",
    ParamKind::FloatIn(Bounds::between(0.0, 180.0)),
    Default::Float(20.0),
    "angle from the axis, in degrees, beyond which there is no light",
);
const BEAM_WIDTH: ParamSpec = ParamSpec::new(
    "beam_width",
    ParamKind::Float,
    Default::Text("¾ `cutoff_angle`"),
    "angle, in degrees, within which the intensity is full",
);
const ENVMAP_FILENAME: ParamSpec = ParamSpec::new(
    "filename",
    ParamKind::String,
    Default::Required,
    "the image: OpenEXR, Radiance HDR, PNG or JPEG, at least 2 × 3 pixels",
);
const ENVMAP_SCALE: ParamSpec = ParamSpec::new(
    "scale",
    ParamKind::Float,
    Default::Float(1.0),
    "factor on the image's values",
);

const SUN_DIRECTION: ParamSpec = ParamSpec::new(
    "sun_direction",
    ParamKind::Vector,
    Default::Text("from the place and time"),
    "the sun's direction (world space); not together with the place and time",
);
const LATITUDE: ParamSpec = ParamSpec::new(
    "latitude",
    ParamKind::Float,
    Default::Float(35.6894),
    "degrees north (Tokyo by default)",
);
const LONGITUDE: ParamSpec = ParamSpec::new(
    "longitude",
    ParamKind::Float,
    Default::Float(139.6917),
    "degrees east",
);
const TIMEZONE: ParamSpec = ParamSpec::new(
    "timezone",
    ParamKind::Float,
    Default::Float(9.0),
    "hours ahead of UTC",
);
const YEAR: ParamSpec = ParamSpec::new("year", ParamKind::Integer, Default::Integer(2010), "year");
const MONTH: ParamSpec = ParamSpec::new("month", ParamKind::Integer, Default::Integer(7), "month");
const DAY: ParamSpec = ParamSpec::new("day", ParamKind::Integer, Default::Integer(10), "day");
const HOUR: ParamSpec =
    ParamSpec::new("hour", ParamKind::Float, Default::Float(15.0), "local hour");
const MINUTE: ParamSpec = ParamSpec::new("minute", ParamKind::Float, Default::Float(0.0), "minute");
const SECOND: ParamSpec = ParamSpec::new("second", ParamKind::Float, Default::Float(0.0), "second");
const TURBIDITY: ParamSpec = ParamSpec::new(
    "turbidity",
    ParamKind::FloatIn(Bounds::between(1.0, 10.0)),
    Default::Float(3.0),
    "haziness of the atmosphere",
);
const SKY_ALBEDO: ParamSpec = ParamSpec::new(
    "albedo",
    ParamKind::Spectrum {
        range: Range::Albedo,
        textured: false,
    },
    Default::Float(0.3),
    "the ground's albedo, in [0, 1] at every wavelength",
);
const SUN_SCALE: ParamSpec = ParamSpec::new(
    "sun_scale",
    ParamKind::FloatIn(Bounds::FINITE_NON_NEGATIVE),
    Default::Float(1.0),
    "factor on the sun's radiance (0 turns the sun off)",
);
const SKY_SCALE: ParamSpec = ParamSpec::new(
    "sky_scale",
    ParamKind::FloatIn(Bounds::FINITE_NON_NEGATIVE),
    Default::Float(1.0),
    "factor on the sky's radiance (0 turns the sky off)",
);
const SUN_APERTURE: ParamSpec = ParamSpec::new(
    "sun_aperture",
    ParamKind::FloatIn(Bounds::between(0.0, 180.0)),
    Default::Float(0.5358),
    "the sun disc's full angle in degrees, in (0, 180); its irradiance stays that of the real sun",
);
const COMPLEX_SUN: ParamSpec = ParamSpec::new(
    "complex_sun",
    ParamKind::Boolean,
    Default::Boolean(false),
    "the solar radiance function with limb darkening instead of a uniform disc",
);

/// Builds the area light nested in the shape with index `shape`, with its sampling weight.
pub fn build_area_light(
    node: &PluginNode,
    shape: u32,
    textures: &mut TextureCache,
) -> Result<(Light, f32)> {
    let plugin = EMITTERS.find(node)?;
    if plugin.name != "area" {
        return Err(Error::input(
            &node.location,
            format!(
                "emitter \"{}\" cannot be attached to a shape",
                node.plugin_type
            ),
        )
        .with_help(
            "only an \"area\" emitter can be nested in a shape; declare other emitters at the top level of the scene",
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

/// Whether `node` is an `area` emitter, which emits from the shape it is attached to.
pub fn is_area(node: &PluginNode) -> bool {
    node.class == PluginClass::Emitter && node.plugin_type == "area"
}

/// Builds an emitter declared at the top level of the scene, other than `area`, with its
/// sampling weight.
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
            let aspect = match &texture {
                Texture::Bitmap(bitmap) => bitmap.width as f64 / bitmap.height as f64,
                _ => 1.0,
            };
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

/// Mitsuba's `envmap`.
fn build_envmap(params: &Params) -> Result<Light> {
    let node = params.node();
    let Some(filename) = params.string_opt(&ENVMAP_FILENAME)? else {
        return Err(Error::input(
            &node.location,
            format!("{} needs a \"filename\"", node.describe()),
        )
        .with_help("add <string name=\"filename\" value=\"sky.exr\"/>"));
    };
    let location = params.location_of(&ENVMAP_FILENAME);
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
    let scale = params.float(&ENVMAP_SCALE)?;
    if !(scale >= 0.0 && scale.is_finite() && scale <= f64::from(f32::MAX)) {
        return Err(Error::input(
            params.location_of(&ENVMAP_SCALE),
            format!("the environment map's scale must be finite and at least 0, not {scale}"),
        ));
    }
    let to_world = invertible(params, &TO_WORLD)?;
    Ok(Light::Envmap(EnvironmentMap::new(
        bitmap,
        scale as f32,
        to_world,
    )))
}

/// Mitsuba's `sunsky`: the sun's direction (given, or from the place and time), the
/// atmosphere's parameters and the frame.
fn build_sunsky(params: &Params) -> Result<Light> {
    let to_world = invertible(params, &TO_WORLD)?;
    let time_params = [
        &LATITUDE, &LONGITUDE, &TIMEZONE, &YEAR, &MONTH, &DAY, &HOUR, &MINUTE, &SECOND,
    ];
    let sun = match params.vector_opt(&SUN_DIRECTION)? {
        Some(direction) => {
            if let Some(spec) = time_params.iter().find(|spec| params.has(spec)) {
                return Err(Error::input(
                    params.location_of(spec),
                    format!(
                        "{} takes either \"sun_direction\" or a place and time, not both",
                        params.node().describe()
                    ),
                )
                .with_help(format!(
                    "remove \"{}\" or \"sun_direction\" (as in Mitsuba 3)",
                    spec.name
                )));
            }
            let direction = direction.as_vec3();
            if !(direction.is_finite() && direction.length() > 0.0) {
                return Err(Error::input(
                    params.location_of(&SUN_DIRECTION),
                    "the sunsky emitter's sun_direction must be a finite, non-zero vector",
                ));
            }
            to_world.inverse_vector(direction.normalize())
        }
        None => {
            let location = Location {
                latitude: params.float(&LATITUDE)?,
                longitude: params.float(&LONGITUDE)?,
                timezone: params.float(&TIMEZONE)?,
            };
            let time = DateTime {
                year: params.integer(&YEAR)?,
                month: params.integer(&MONTH)?,
                day: params.integer(&DAY)?,
                hour: params.float(&HOUR)?,
                minute: params.float(&MINUTE)?,
                second: params.float(&SECOND)?,
            };
            let finite = [
                location.latitude,
                location.longitude,
                location.timezone,
                time.hour,
                time.minute,
                time.second,
            ]
            .iter()
            .all(|v| v.is_finite() && v.abs() < 1e6);
            let dates = [time.year, time.month, time.day]
                .iter()
                .all(|v| v.abs() < 1_000_000);
            if !(finite && dates) {
                return Err(Error::input(
                    params.location(),
                    "the sunsky emitter's place and time must be finite numbers of a \
                     reasonable size",
                ));
            }
            let (theta, phi) = sun_angles(&time, &location);
            Vec3::new(
                (theta.sin() * phi.cos()) as f32,
                (theta.sin() * phi.sin()) as f32,
                theta.cos() as f32,
            )
        }
    };
    if !(sun.is_finite() && sun.length() > 0.0) {
        return Err(Error::input(
            params.location(),
            "the sunsky emitter's sun direction is degenerate in its to_world frame",
        ));
    }
    let turbidity = params.float_in(&TURBIDITY)?;
    let scale = |spec: &ParamSpec| -> Result<f32> { Ok(params.float_in(spec)? as f32) };
    let (sun_scale, sky_scale) = (scale(&SUN_SCALE)?, scale(&SKY_SCALE)?);
    let aperture = params.float_in(&SUN_APERTURE)?;
    if !(aperture > 0.0 && aperture < 180.0) {
        return Err(Error::input(
            params.location_of(&SUN_APERTURE),
            format!("the sun's aperture must be in (0, 180) degrees, not {aperture}"),
        ));
    }
    let albedo_spectrum = spectrum_param(params, &SKY_ALBEDO)?;
    let wavelengths = Sunsky::band_wavelengths();
    let albedo = wavelengths.map(|lambda| albedo_spectrum.value(lambda));
    if let Some(i) = albedo.iter().position(|a| !(0.0..=1.0).contains(a)) {
        return Err(Error::input(
            params.location_of(&SKY_ALBEDO),
            format!(
                "the sunsky emitter's albedo is {} at {} nm; it must be within [0, 1] at every \
                 wavelength (as in Mitsuba 3)",
                albedo[i], wavelengths[i]
            ),
        ));
    }
    let settings = SunskySettings {
        sun,
        turbidity: turbidity as f32,
        albedo,
        sun_scale,
        sky_scale,
        sun_half_aperture: (0.5 * aperture).to_radians() as f32,
        complex_sun: params.boolean(&COMPLEX_SUN)?,
        to_world,
    };
    Ok(Light::Sunsky(Box::new(Sunsky::new(&settings))))
}
