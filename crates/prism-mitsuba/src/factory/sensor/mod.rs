//! The sensor: the `perspective`, `thinlens` and `orthographic` cameras, the `radiancemeter`,
//! `irradiancemeter` and `distant` meters ([`meters`]) and the `batch` of sensors ([`batch`]),
//! with their shutter, and the film and sampler they carry (each class's registry in its own
//! module).

mod batch;
pub mod film;
mod meters;
pub mod rfilter;
pub mod sampler;

pub use meters::build_shape_sensor;

use crate::description::{PluginClass, PluginNode, Warning};
use crate::factory::fov::{FOCAL_LENGTH, FOV, FOV_AXIS, horizontal_fov_param};
use crate::factory::spectra::spectrum_param;
use crate::params::Params;
use crate::registry::{
    Bounds, Default, Origin, ParamKind, ParamSpec, Plugin, Range, Registry, params,
};
use film::{build_film, default_film};
use glam::{DMat4, DVec3, Vec2};
use prism_core::camera::{Camera, OrthographicCamera, PerspectiveCamera, RadianceMeter, Shutter};
use prism_core::error::{Error, Result};
use prism_core::film::{ExrOutput, Kernel, LdrOutput};
use prism_core::math::{AnimatedTransform, Transform};
use prism_core::scene::{FilmSettings, SamplerKind, SamplerSettings};
use rfilter::build_filter;
use sampler::build_sampler;
use std::sync::Arc;

/// The parameters of a camera: its own `[before]`, then those every camera takes (the clip
/// distances, its placement `to_world`, the shutter, the film and the sampler), then its own
/// `[after]`.
macro_rules! camera_params {
    ([$($before:expr),*], $to_world:expr, [$($after:expr),*]) => {
        &[
            $($before,)*
            NEAR_CLIP,
            FAR_CLIP,
            $to_world,
            SHUTTER_OPEN,
            SHUTTER_CLOSE,
            SHUTTER_FILTER,
            FILM,
            SAMPLER,
            SRF,
            $($after,)*
        ]
    };
}

/// Builds a sensor; `thinlens` says whether it has a lens.
type SensorBuild = fn(&Params, bool) -> Result<SensorSettings>;

pub static SENSORS: Registry<SensorBuild> = Registry {
    class: PluginClass::Sensor,
    plugins: &[
        Plugin {
            name: "perspective",
            origin: Origin::Mitsuba3,
            summary: "A pinhole camera looking along its +z axis (+y up).",
            params: camera_params!(
                [FOV, FOV_AXIS, FOCAL_LENGTH],
                SENSOR_TO_WORLD,
                [
                    PINHOLE_FOCUS_DISTANCE,
                    SENSOR_MEDIUM,
                    PRINCIPAL_POINT_OFFSET_X,
                    PRINCIPAL_POINT_OFFSET_Y
                ]
            ),
            build: build_sensor_of,
        },
        Plugin {
            name: "thinlens",
            origin: Origin::Mitsuba3,
            summary: "A thin-lens camera: as `perspective`, with depth of field.",
            params: camera_params!(
                [FOV, FOV_AXIS, FOCAL_LENGTH],
                SENSOR_TO_WORLD,
                [
                    SENSOR_MEDIUM,
                    APERTURE_RADIUS,
                    APERTURE_AREA,
                    FOCUS_DISTANCE,
                    FOCAL_DISTANCE
                ]
            ),
            build: build_sensor_of,
        },
        Plugin {
            name: "orthographic",
            origin: Origin::Mitsuba3,
            summary: "Parallel rays along +z from the square [−1, 1] × [−1/a, 1/a] (a = width / height) of the camera's near plane, placed and scaled by `to_world`.",
            params: camera_params!(
                [],
                ORTHOGRAPHIC_TO_WORLD,
                [PINHOLE_FOCUS_DISTANCE, SENSOR_MEDIUM]
            ),
            build: build_orthographic,
        },
        Plugin {
            name: "radiancemeter",
            origin: Origin::Mitsuba3,
            summary: "The radiance arriving along one ray, from `origin` along `direction` (or \
                      from `to_world`'s origin along its +z axis), on a film of one pixel.",
            params: &[
                METER_TO_WORLD,
                METER_ORIGIN,
                METER_DIRECTION,
                SHUTTER_OPEN,
                SHUTTER_CLOSE,
                SHUTTER_FILTER,
                FILM,
                SAMPLER,
                SRF,
                SENSOR_MEDIUM,
            ],
            build: build_radiancemeter,
        },
        Plugin {
            name: "irradiancemeter",
            origin: Origin::Mitsuba3,
            summary: "Nested in a `<shape>`: the irradiance on the shape, averaged over its area \
                      (π L along cosine-weighted rays from points uniform by area).",
            params: &[
                IRRADIANCE_TO_WORLD,
                SHUTTER_OPEN,
                SHUTTER_CLOSE,
                SHUTTER_FILTER,
                FILM,
                SAMPLER,
                SRF,
                SENSOR_MEDIUM,
            ],
            build: meters::build_irradiancemeter_alone,
        },
        Plugin {
            name: "distant",
            origin: Origin::Mitsuba3,
            summary: "The radiance leaving the scene along `direction` (or `to_world`'s +z axis), \
                      averaged over a `target` point, shape or the scene's cross-section, on a film \
                      of one pixel.",
            params: &[
                DISTANT_TO_WORLD,
                DISTANT_DIRECTION,
                DISTANT_TARGET,
                SHUTTER_OPEN,
                SHUTTER_CLOSE,
                SHUTTER_FILTER,
                FILM,
                SAMPLER,
                SRF,
                SENSOR_MEDIUM,
            ],
            build: meters::build_distant,
        },
        Plugin {
            name: "batch",
            origin: Origin::Mitsuba3,
            summary: "Several nested sensors rendered side by side into one film, each into a \
                      block of width W/n.",
            params: &[
                BATCH_SENSORS,
                SHUTTER_OPEN,
                SHUTTER_CLOSE,
                SHUTTER_FILTER,
                FILM,
                SAMPLER,
                SRF,
                SENSOR_MEDIUM,
            ],
            build: batch::build_batch,
        },
    ],
};

params! {
    NEAR_CLIP = ParamSpec::new("near_clip", ParamKind::Float, Default::Float(1e-2), "distance before which nothing is seen");
    FAR_CLIP = ParamSpec::new("far_clip", ParamKind::Float, Default::Float(1e4), "distance beyond which nothing is seen");
    SENSOR_TO_WORLD = ParamSpec::new("to_world", ParamKind::AnimatedTransform, Default::Text("identity"), "camera to world: rotations and translations (a `lookat`), or an `<animation>` of them");
    SHUTTER_OPEN = ParamSpec::new("shutter_open", ParamKind::Float, Default::Float(0.0), "time the shutter opens");
    SHUTTER_CLOSE = ParamSpec::new("shutter_close", ParamKind::Float, Default::Text("`shutter_open`"), "time the shutter closes");
    SHUTTER_FILTER = ParamSpec::new("shutter_filter", ParamKind::Nested(PluginClass::Rfilter), Default::Text("box"), "Prism only: a nested `<rfilter name=\"shutter_filter\">` weighting time within the shutter interval");
    FILM = ParamSpec::nested(PluginClass::Film, Default::Text("`hdrfilm`, 768 × 576, gaussian"), "the film");
    SAMPLER = ParamSpec::nested(PluginClass::Sampler, Default::Text("`independent`, 4 samples"), "the sampler");
    SRF = ParamSpec::new("srf", ParamKind::Spectrum { range: Range::Coefficient, textured: false }, Default::Text("1"), "the sensor's spectral response: the radiance is multiplied by it at each wavelength (not with a `specfilm`)");
    SENSOR_MEDIUM = ParamSpec::nested(PluginClass::Medium, Default::None, "the medium the camera sits in (for `volpath`)");
    APERTURE_RADIUS = ParamSpec::new("aperture_radius", ParamKind::Float, Default::Required, "radius of the lens (or give `aperture_area`)");
    APERTURE_AREA = ParamSpec::new("aperture_area", ParamKind::Float, Default::None, "Prism only, the lecture's form: the lens's area a, radius √(a/π)");
    FOCUS_DISTANCE = ParamSpec::new("focus_distance", ParamKind::Float, Default::Text("`far_clip`"), "distance of the plane in focus");
    PRINCIPAL_POINT_OFFSET_X = ParamSpec::new("principal_point_offset_x", ParamKind::FloatIn(Bounds::between(-f32::MAX, f32::MAX)), Default::Float(0.0), "shift of the principal point from the film's centre, in film widths (as the Mitsuba Blender add-on writes a lens shift); the image moves the other way");
    PRINCIPAL_POINT_OFFSET_Y = ParamSpec::new("principal_point_offset_y", ParamKind::FloatIn(Bounds::between(-f32::MAX, f32::MAX)), Default::Float(0.0), "shift of the principal point from the film's centre, in film heights (down the image)");
    PINHOLE_FOCUS_DISTANCE = ParamSpec::new("focus_distance", ParamKind::Float, Default::Text("`far_clip`"), "read as Mitsuba 3 reads it on every projective camera; a pinhole has everything in focus");
    FOCAL_DISTANCE = ParamSpec::new("focal_distance", ParamKind::Float, Default::None, "Prism only, the lecture's name for `focus_distance`");
    METER_TO_WORLD = ParamSpec::new("to_world", ParamKind::AnimatedTransform, Default::Text("identity"), "sensor to world: the ray leaves its origin along its +z axis (wins over `origin` and `direction`)");
    METER_ORIGIN = ParamSpec::new("origin", ParamKind::Point, Default::None, "where the ray starts, with `direction`");
    METER_DIRECTION = ParamSpec::new("direction", ParamKind::Vector, Default::None, "the direction of the ray, with `origin`");
    IRRADIANCE_TO_WORLD = ParamSpec::new("to_world", ParamKind::Transform, Default::None, "not allowed: the meter takes its shape's placement");
    DISTANT_TO_WORLD = ParamSpec::new("to_world", ParamKind::Transform, Default::Text("identity"), "sensor to world: the rays travel along its +z axis (or give `direction`)");
    DISTANT_DIRECTION = ParamSpec::new("direction", ParamKind::Vector, Default::None, "the direction the rays travel in (the radiance leaving the scene towards −`direction` is measured)");
    DISTANT_TARGET = ParamSpec::new("target", ParamKind::Point, Default::Text("the scene's cross-section"), "a point the rays aim at, or a nested `<shape name=\"target\">` they aim at uniformly by area");
    BATCH_SENSORS = ParamSpec::nested(PluginClass::Sensor, Default::Required, "the sensors, left to right; their films, samplers and shutters give way to the batch's");
    ORTHOGRAPHIC_TO_WORLD = ParamSpec::new("to_world", ParamKind::AnimatedTransform, Default::Text("identity"), "camera to world, scales included (they set the film's extent in the scene), or an `<animation>` of them");
}

/// The camera, shutter, film settings, sampler settings and sampler seed of a `<sensor>`.
pub struct SensorSettings {
    pub camera: Camera,
    pub shutter: Shutter,
    pub film: FilmSettings,
    pub sampler: SamplerSettings,
    pub seed: u64,
    /// Which channels the EXR holds and how it stores them (`hdrfilm`'s `pixel_format` and
    /// `component_format`).
    pub exr_output: ExrOutput,
    /// How the 8-bit image is written (`ldrfilm`), or the default sRGB PNG.
    pub ldr_output: LdrOutput,
    /// The parameters read and ignored, one warning each.
    pub warnings: Vec<Warning>,
    /// The nested `<medium>` the camera sits in, built with the scene's other media.
    pub medium: Option<Arc<PluginNode>>,
}

/// Builds the sensor a node describes (a `<sensor>` of the scene or of a `batch`).
pub fn build_sensor(node: &PluginNode) -> Result<SensorSettings> {
    let plugin = SENSORS.find(node)?;
    let params = Params::new(node, plugin.params);
    let sensor = (plugin.build)(&params, plugin.name == "thinlens")?;
    params.finish()?;
    Ok(sensor)
}

/// What every sensor carries: its film (with the 8-bit output and the warnings of its ignored
/// parameters), its sampler and the sampler's seed.
pub(super) struct SensorParts {
    film: FilmSettings,
    exr_output: ExrOutput,
    ldr_output: LdrOutput,
    warnings: Vec<Warning>,
    sampler: SamplerSettings,
    seed: u64,
}

pub(super) fn sensor_parts(params: &Params) -> Result<SensorParts> {
    let (film, warnings) = match params.single_child(&FILM)? {
        Some(child) => build_film(&child.node)?,
        None => (default_film(), Vec::new()),
    };
    let (sampler, seed) = match params.single_child(&SAMPLER)? {
        Some(child) => build_sampler(&child.node)?,
        None => (
            SamplerSettings {
                kind: SamplerKind::Independent,
                samples_per_pixel: 4,
            },
            0,
        ),
    };
    let mut film = film;
    if params.property(&SRF).is_some() {
        if !film.film.bands.is_empty() {
            return Err(Error::input(
                params.location_of(&SRF),
                "a sensor with an \"srf\" cannot have a specfilm, whose bands are its responses",
            )
            .with_help("remove the srf, or use an hdrfilm"));
        }
        film.film.response = Some(spectrum_param(params, &SRF)?);
    }
    Ok(SensorParts {
        film: film.film,
        exr_output: film.exr,
        ldr_output: film.ldr,
        warnings,
        sampler,
        seed,
    })
}

/// The sensor of `camera` and `shutter` with what every sensor carries.
pub(super) fn sensor_settings(
    params: &Params,
    parts: SensorParts,
    camera: Camera,
    shutter: Shutter,
) -> Result<SensorSettings> {
    Ok(SensorSettings {
        camera,
        shutter,
        film: parts.film,
        sampler: parts.sampler,
        seed: parts.seed,
        exr_output: parts.exr_output,
        ldr_output: parts.ldr_output,
        warnings: parts.warnings,
        medium: params.single_child(&SENSOR_MEDIUM)?.map(|c| c.node.clone()),
    })
}

/// `near_clip` and `far_clip`, as Mitsuba 3's projective cameras check them.
fn clip_distances(params: &Params) -> Result<(f64, f64)> {
    let near_clip = params.float(&NEAR_CLIP)?;
    let far_clip = params.float(&FAR_CLIP)?;
    if !(near_clip > 0.0) || !(far_clip > near_clip) || !far_clip.is_finite() {
        return Err(Error::input(
            params.location_of(&NEAR_CLIP),
            format!(
                "near_clip ({near_clip}) must be positive and smaller than far_clip ({far_clip})"
            ),
        ));
    }
    Ok((near_clip, far_clip))
}

/// `orthographic` (Mitsuba 3's `orthographic.cpp`).
fn build_orthographic(params: &Params, _thinlens: bool) -> Result<SensorSettings> {
    let parts = sensor_parts(params)?;
    let (near_clip, far_clip) = clip_distances(params)?;
    params.float_opt(&PINHOLE_FOCUS_DISTANCE)?;
    let to_world = params.animated_transform(&ORTHOGRAPHIC_TO_WORLD)?;
    let shutter = shutter(params)?;
    let camera = Camera::Orthographic(OrthographicCamera {
        to_world,
        film_size: Vec2::new(parts.film.size.x as f32, parts.film.size.y as f32),
        near_clip: near_clip as f32,
        far_clip: far_clip as f32,
    });
    sensor_settings(params, parts, camera, shutter)
}

/// `radiancemeter` (Mitsuba 3's `radiancemeter.cpp`): `to_world` if given, else the frame
/// Mitsuba's `look_at(origin, origin + direction, up)` builds, with `up` the first tangent of
/// the direction's coordinate system; one ray whatever the film position, on a 1 × 1 film.
fn build_radiancemeter(params: &Params, _thinlens: bool) -> Result<SensorSettings> {
    let mut parts = sensor_parts(params)?;
    let origin = params.point_opt(&METER_ORIGIN)?;
    let direction = params.vector_opt(&METER_DIRECTION)?;
    let to_world = if params.has(&METER_TO_WORLD) {
        params.animated_transform(&METER_TO_WORLD)?
    } else {
        match (origin, direction) {
            (None, None) => AnimatedTransform::fixed(Transform::IDENTITY),
            (Some(origin), Some(direction)) => {
                let frame = ray_frame(origin, direction).ok_or_else(|| {
                    Error::input(
                        params.location_of(&METER_DIRECTION),
                        format!("the radiance meter's direction {direction} has no length"),
                    )
                })?;
                AnimatedTransform::fixed(frame)
            }
            (Some(_), None) | (None, Some(_)) => {
                return Err(Error::input(
                    params.location(),
                    "a radiancemeter given by \"origin\" and \"direction\" needs both",
                )
                .with_help("add the missing one, or place the sensor with a to_world transform"));
            }
        }
    };
    check_one_pixel(params, &parts)?;
    warn_wide_filter(params, &mut parts);
    let shutter = shutter(params)?;
    let camera = Camera::RadianceMeter(RadianceMeter { to_world });
    sensor_settings(params, parts, camera, shutter)
}

/// A one-pixel film, which a sensor whose rays do not depend on the film position needs.
pub(super) fn check_one_pixel(params: &Params, parts: &SensorParts) -> Result<()> {
    if parts.film.size == glam::UVec2::ONE {
        return Ok(());
    }
    Err(Error::input(
        params.location(),
        format!(
            "a {} sensor measures one quantity: its film must be 1 × 1 pixels, not {} × {}",
            params.node().plugin_type,
            parts.film.size.x,
            parts.film.size.y
        ),
    )
    .with_help("set the film's width and height to 1"))
}

/// Mitsuba's warning for a one-pixel sensor with a filter wider than the box.
pub(super) fn warn_wide_filter(params: &Params, parts: &mut SensorParts) {
    if parts.film.filter.radius() > 0.5 + 1e-4 {
        parts.warnings.push(Warning {
            location: params.location().clone(),
            message: format!(
                "a {} sensor should have a reconstruction filter of radius 0.5 or less (the box, \
                 Mitsuba's advice): its rays do not depend on the film position",
                params.node().plugin_type
            ),
        });
    }
}

/// Mitsuba 3's `look_at(origin, origin + direction, up)` with `up` the first tangent of
/// `coordinate_system(normalize(direction))` (Duff et al. 2017): columns left, up, direction,
/// origin. None for a direction of no length.
pub(super) fn ray_frame(origin: DVec3, direction: DVec3) -> Option<Transform> {
    let d = direction.try_normalize()?;
    let sign = 1.0f64.copysign(d.z);
    let a = -1.0 / (sign + d.z);
    let b = d.x * d.y * a;
    let tangent = DVec3::new(1.0 + sign * d.x * d.x * a, sign * b, -sign * d.x);
    let left = tangent.cross(d).normalize();
    let up = d.cross(left);
    Transform::new(DMat4::from_cols(
        left.extend(0.0),
        up.extend(0.0),
        d.extend(0.0),
        origin.extend(1.0),
    ))
}

fn build_sensor_of(params: &Params, thinlens: bool) -> Result<SensorSettings> {
    let parts = sensor_parts(params)?;
    let film_size = parts.film.size;
    let aspect = f64::from(film_size.x) / f64::from(film_size.y);
    let fov_x = horizontal_fov_param(params, aspect)?;
    let (near_clip, far_clip) = clip_distances(params)?;
    let to_world = params.animated_transform(&SENSOR_TO_WORLD)?;
    let (lens_radius, focus_distance) = if thinlens {
        lens(params, far_clip)?
    } else {
        let focus_distance = params.float_opt(&PINHOLE_FOCUS_DISTANCE)?;
        (0.0, focus_distance.unwrap_or(far_clip))
    };
    if lens_radius > 0.0 && !to_world.is_similarity() || to_world.uniform_scale(0.0) > 1.0 + 1e-4 {
        return Err(Error::input(
            params.location_of(&SENSOR_TO_WORLD),
            "the camera's \"to_world\" transform scales; a thin lens camera must not be scaled",
        )
        .with_help("use only rotations and translations (lookat) for cameras"));
    }
    let shutter = shutter(params)?;
    let principal_point_offset = if thinlens {
        Vec2::ZERO
    } else {
        Vec2::new(
            params.float_in(&PRINCIPAL_POINT_OFFSET_X)? as f32,
            params.float_in(&PRINCIPAL_POINT_OFFSET_Y)? as f32,
        )
    };

    let camera = Camera::Perspective(PerspectiveCamera {
        to_world,
        film_size: Vec2::new(film_size.x as f32, film_size.y as f32),
        tan_half_fov_x: (0.5 * fov_x).to_radians().tan() as f32,
        near_clip: near_clip as f32,
        far_clip: far_clip as f32,
        lens_radius: lens_radius as f32,
        focus_distance: focus_distance as f32,
        principal_point_offset,
    });
    sensor_settings(params, parts, camera, shutter)
}

/// The thin lens: `aperture_radius` (Mitsuba) or the lecture's aperture area `aperture_area`
/// (radius √(a/π)), and `focus_distance` (Mitsuba) or the lecture's `focal_distance`
/// (default: the far clipping distance, as Mitsuba).
fn lens(params: &Params, far_clip: f64) -> Result<(f64, f64)> {
    let radius = match (
        params.float_opt(&APERTURE_RADIUS)?,
        params.float_opt(&APERTURE_AREA)?,
    ) {
        (Some(_), Some(_)) => {
            return Err(Error::input(
                params.location_of(&APERTURE_AREA),
                "give either \"aperture_radius\" or \"aperture_area\", not both",
            ));
        }
        (Some(radius), None) => (radius, &APERTURE_RADIUS),
        (None, Some(area)) => ((area / std::f64::consts::PI).sqrt(), &APERTURE_AREA),
        (None, None) => {
            return Err(Error::input(
                params.location(),
                "a thinlens sensor needs an \"aperture_radius\" (or the lecture's \"aperture_area\")",
            )
            .with_help("add <float name=\"aperture_radius\" value=\"0.1\"/>"));
        }
    };
    if !(radius.0 > 0.0 && radius.0.is_finite()) {
        return Err(Error::input(
            params.location_of(radius.1),
            format!("the aperture must be positive, not {}", radius.0),
        ));
    }
    let focus = match (
        params.float_opt(&FOCUS_DISTANCE)?,
        params.float_opt(&FOCAL_DISTANCE)?,
    ) {
        (Some(_), Some(_)) => {
            return Err(Error::input(
                params.location_of(&FOCAL_DISTANCE),
                "give either \"focus_distance\" or \"focal_distance\", not both",
            ));
        }
        (Some(g), None) => (g, &FOCUS_DISTANCE),
        (None, Some(g)) => (g, &FOCAL_DISTANCE),
        (None, None) => (far_clip, &FOCUS_DISTANCE),
    };
    if !(focus.0 > 0.0 && focus.0.is_finite()) {
        return Err(Error::input(
            params.location_of(focus.1),
            format!("the focus distance must be positive, not {}", focus.0),
        ));
    }
    Ok((radius.0, focus.0))
}

/// `shutter_open`, `shutter_close` (default 0 and 0) and an optional nested temporal filter
/// `<rfilter name="shutter_filter">`.
pub(super) fn shutter(params: &Params) -> Result<Shutter> {
    let open = params.float(&SHUTTER_OPEN)?;
    let close = params.float_opt(&SHUTTER_CLOSE)?.unwrap_or(open);
    if !open.is_finite() || !close.is_finite() || close < open {
        return Err(Error::input(
            params.location_of(&SHUTTER_CLOSE),
            format!("the shutter closes at {close}, before it opens at {open}"),
        )
        .with_help("shutter_close must be at least shutter_open"));
    }
    let filter = match params.named_child(&SHUTTER_FILTER) {
        Some(child) if child.node.class == PluginClass::Rfilter => Some(build_filter(&child.node)?),
        Some(child) => {
            return Err(Error::input(
                &child.location,
                "\"shutter_filter\" must be an <rfilter>",
            ));
        }
        None => None,
    };
    Ok(Shutter::new(open as f32, close as f32, filter))
}
