//! The sensor and what it carries: the `perspective` and `thinlens` cameras with their shutter,
//! the `hdrfilm` film with its `rfilter`, and the sampler.

use glam::{UVec2, Vec2};

use crate::description::{PluginClass, PluginNode};
use crate::params::Params;
use prism_core::camera::perspective::{FovAxis, focal_length_to_diagonal_fov, horizontal_fov};
use prism_core::camera::{Camera, PerspectiveCamera, Shutter};
use prism_core::error::{Error, Result};
use prism_core::film::{CropWindow, Filter};
use prism_core::scene::{FilmSettings, SamplerKind, SamplerSettings};

pub const SUPPORTED_SENSORS: &[&str] = &["perspective", "thinlens"];
pub const SUPPORTED_FILMS: &[&str] = &["hdrfilm"];
pub const SUPPORTED_FILTERS: &[&str] = &[
    "box",
    "tent",
    "gaussian",
    "mitchell",
    "catmullrom",
    "lanczos",
];
pub const SUPPORTED_SAMPLERS: &[&str] = &["independent", "stratified", "multijitter", "nrooks"];

/// Largest film side, and largest pixel count, accepted (each pixel keeps 112 bytes of sums,
/// twice while a pass is rendered).
const MAX_FILM_SIDE: i64 = 1 << 16;
const MAX_FILM_PIXELS: i64 = 1 << 25;

/// The camera, shutter, film settings, sampler settings and sampler seed of a `<sensor>`.
pub struct SensorSettings {
    pub camera: Camera,
    pub shutter: Shutter,
    pub film: FilmSettings,
    pub sampler: SamplerSettings,
    pub seed: u64,
}

pub fn build_sensor(node: &PluginNode) -> Result<SensorSettings> {
    let params = Params::new(node);
    if node.plugin_type != "perspective" && node.plugin_type != "thinlens" {
        return Err(Error::input(
            &node.location,
            format!("unknown sensor type \"{}\"", node.plugin_type),
        )
        .with_help(format!(
            "supported sensor types: {}",
            SUPPORTED_SENSORS.join(", ")
        )));
    }
    let film = match params.single_child(PluginClass::Film)? {
        Some(child) => build_film(&child.node)?,
        None => default_film(),
    };
    let (sampler, seed) = match params.single_child(PluginClass::Sampler)? {
        Some(child) => build_sampler(&child.node)?,
        None => (
            SamplerSettings {
                kind: SamplerKind::Independent,
                samples_per_pixel: 4,
            },
            0,
        ),
    };

    let aspect = f64::from(film.size.x) / f64::from(film.size.y);
    let fov_x = match (params.float_opt("fov")?, params.string_opt("focal_length")?) {
        (Some(_), Some(_)) => {
            return Err(Error::input(
                params.location_of("focal_length"),
                "give either \"fov\" or \"focal_length\", not both",
            ));
        }
        (Some(fov), None) => {
            let axis_name = params.string("fov_axis", "x")?;
            let axis = match axis_name.to_ascii_lowercase().as_str() {
                "x" => FovAxis::X,
                "y" => FovAxis::Y,
                "diagonal" => FovAxis::Diagonal,
                "smaller" => FovAxis::Smaller,
                "larger" => FovAxis::Larger,
                _ => {
                    return Err(Error::input(
                        params.location_of("fov_axis"),
                        format!("unknown fov_axis \"{axis_name}\""),
                    )
                    .with_help("use one of x, y, diagonal, smaller, larger"));
                }
            };
            horizontal_fov(fov, axis, aspect)
        }
        (None, focal_length) => {
            let text = focal_length.unwrap_or("50mm");
            let mm: f64 = text
                .trim()
                .trim_end_matches("mm")
                .trim()
                .parse()
                .map_err(|_| {
                    Error::input(
                        params.location_of("focal_length"),
                        format!("could not read the focal length \"{text}\""),
                    )
                    .with_help("write it as a number of millimetres, e.g. \"35mm\"")
                })?;
            if !(mm > 0.0) {
                return Err(Error::input(
                    params.location_of("focal_length"),
                    "the focal length must be positive",
                ));
            }
            horizontal_fov(focal_length_to_diagonal_fov(mm), FovAxis::Diagonal, aspect)
        }
    };
    if !(fov_x > 0.0 && fov_x < 180.0) {
        return Err(Error::input(
            params.location_of("fov"),
            format!(
                "the horizontal field of view is {fov_x} degrees; it must lie strictly between 0 and 180"
            ),
        ));
    }
    let near_clip = params.float("near_clip", 1e-2)?;
    let far_clip = params.float("far_clip", 1e4)?;
    if !(near_clip > 0.0) || !(far_clip > near_clip) || !far_clip.is_finite() {
        return Err(Error::input(
            params.location_of("near_clip"),
            format!(
                "near_clip ({near_clip}) must be positive and smaller than far_clip ({far_clip})"
            ),
        ));
    }
    let to_world = params.animated_transform("to_world")?;
    let (lens_radius, focus_distance) = if node.plugin_type == "thinlens" {
        lens(&params, far_clip)?
    } else {
        (0.0, far_clip)
    };
    if lens_radius > 0.0 && !to_world.is_similarity() || to_world.uniform_scale(0.0) > 1.0 + 1e-4 {
        return Err(Error::input(
            params.location_of("to_world"),
            "the camera's \"to_world\" transform scales; a thin lens camera must not be scaled",
        )
        .with_help("use only rotations and translations (lookat) for cameras"));
    }
    let shutter = shutter(&params)?;
    params.finish()?;

    let camera = Camera::Perspective(PerspectiveCamera {
        to_world,
        film_size: Vec2::new(film.size.x as f32, film.size.y as f32),
        tan_half_fov_x: (0.5 * fov_x).to_radians().tan() as f32,
        near_clip: near_clip as f32,
        far_clip: far_clip as f32,
        lens_radius: lens_radius as f32,
        focus_distance: focus_distance as f32,
    });
    Ok(SensorSettings {
        camera,
        shutter,
        film,
        sampler,
        seed,
    })
}

/// The thin lens: `aperture_radius` (Mitsuba) or the lecture's aperture area `aperture_area`
/// (radius √(a/π)), and `focus_distance` (Mitsuba) or the lecture's `focal_distance`
/// (default: the far clipping distance, as Mitsuba).
fn lens(params: &Params, far_clip: f64) -> Result<(f64, f64)> {
    let radius = match (
        params.float_opt("aperture_radius")?,
        params.float_opt("aperture_area")?,
    ) {
        (Some(_), Some(_)) => {
            return Err(Error::input(
                params.location_of("aperture_area"),
                "give either \"aperture_radius\" or \"aperture_area\", not both",
            ));
        }
        (Some(radius), None) => (radius, "aperture_radius"),
        (None, Some(area)) => ((area / std::f64::consts::PI).sqrt(), "aperture_area"),
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
        params.float_opt("focus_distance")?,
        params.float_opt("focal_distance")?,
    ) {
        (Some(_), Some(_)) => {
            return Err(Error::input(
                params.location_of("focal_distance"),
                "give either \"focus_distance\" or \"focal_distance\", not both",
            ));
        }
        (Some(g), None) => (g, "focus_distance"),
        (None, Some(g)) => (g, "focal_distance"),
        (None, None) => (far_clip, "focus_distance"),
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
fn shutter(params: &Params) -> Result<Shutter> {
    let open = params.float("shutter_open", 0.0)?;
    let close = params.float("shutter_close", open)?;
    if !open.is_finite() || !close.is_finite() || close < open {
        return Err(Error::input(
            params.location_of("shutter_close"),
            format!("the shutter closes at {close}, before it opens at {open}"),
        )
        .with_help("shutter_close must be at least shutter_open"));
    }
    let filter = match params.named_child("shutter_filter") {
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

/// Mitsuba's default film: 768 × 576 with a Gaussian filter.
fn default_film() -> FilmSettings {
    let size = UVec2::new(768, 576);
    FilmSettings {
        size,
        crop: CropWindow {
            offset: UVec2::ZERO,
            size,
        },
        filter: Filter::Gaussian { stddev: 0.5 },
    }
}

/// `hdrfilm`: `width` (768), `height` (576), `crop_offset_x/y`, `crop_width/height`, a nested
/// `rfilter` (Gaussian by default). `file_format`, `pixel_format` and `component_format` are
/// accepted for compatibility; Prism always writes 32-bit linear RGB and XYZ to EXR.
fn build_film(node: &PluginNode) -> Result<FilmSettings> {
    let params = Params::new(node);
    if node.plugin_type != "hdrfilm" {
        return Err(Error::input(
            &node.location,
            format!("unknown film type \"{}\"", node.plugin_type),
        )
        .with_help(format!(
            "supported film types: {}",
            SUPPORTED_FILMS.join(", ")
        )));
    }
    let width = params.integer("width", 768)?;
    let height = params.integer("height", 576)?;
    if !(1..=MAX_FILM_SIDE).contains(&width)
        || !(1..=MAX_FILM_SIDE).contains(&height)
        || width * height > MAX_FILM_PIXELS
    {
        return Err(Error::input(
            params.location_of(if (1..=MAX_FILM_SIDE).contains(&width) { "height" } else { "width" }),
            format!("a film of {width} × {height} pixels is not possible"),
        )
        .with_help(format!(
            "width and height must be between 1 and {MAX_FILM_SIDE}, with at most {MAX_FILM_PIXELS} pixels in all"
        )));
    }
    let crop_x = params.integer("crop_offset_x", 0)?;
    let crop_y = params.integer("crop_offset_y", 0)?;
    let crop_width = params.integer("crop_width", width - crop_x)?;
    let crop_height = params.integer("crop_height", height - crop_y)?;
    if crop_x < 0
        || crop_y < 0
        || crop_width < 1
        || crop_height < 1
        || crop_x + crop_width > width
        || crop_y + crop_height > height
    {
        return Err(Error::input(
            params.location_of("crop_width"),
            format!(
                "the crop window at ({crop_x}, {crop_y}) of size {crop_width} × {crop_height} does not fit in the {width} × {height} film"
            ),
        ));
    }
    for (name, allowed) in [
        ("file_format", &["openexr", "exr"][..]),
        (
            "pixel_format",
            &["rgb", "rgba", "xyz", "xyza", "luminance", "luminance_alpha"][..],
        ),
        ("component_format", &["float16", "float32", "uint32"][..]),
    ] {
        if let Some(value) = params.string_opt(name)?
            && !allowed.contains(&value.to_ascii_lowercase().as_str())
        {
            return Err(Error::input(
                params.location_of(name),
                format!("unknown {name} \"{value}\""),
            )
            .with_help(format!("use one of {}", allowed.join(", "))));
        }
    }
    let filter = match params.single_child(PluginClass::Rfilter)? {
        Some(child) => build_filter(&child.node)?,
        None => Filter::Gaussian { stddev: 0.5 },
    };
    params.finish()?;
    let size = UVec2::new(width as u32, height as u32);
    Ok(FilmSettings {
        size,
        crop: CropWindow {
            offset: UVec2::new(crop_x as u32, crop_y as u32),
            size: UVec2::new(crop_width as u32, crop_height as u32),
        },
        filter,
    })
}

fn build_filter(node: &PluginNode) -> Result<Filter> {
    let params = Params::new(node);
    let positive = |name: &'static str, default: f64| -> Result<f32> {
        let v = params.float(name, default)?;
        if !(v > 0.0 && v <= 64.0) {
            return Err(Error::input(
                params.location_of(name),
                format!(
                    "the filter's \"{name}\" must be positive (and at most 64 pixels), not {v}"
                ),
            ));
        }
        Ok(v as f32)
    };
    let filter = match node.plugin_type.as_str() {
        "box" => Filter::Box {
            radius: positive("radius", 0.5)?,
        },
        "tent" => Filter::Tent {
            radius: positive("radius", 1.0)?,
        },
        "gaussian" => Filter::Gaussian {
            stddev: positive("stddev", 0.5)?,
        },
        "mitchell" => Filter::Mitchell {
            b: params.float_in("B", 1.0 / 3.0, 0.0, 1.0)? as f32,
            c: params.float_in("C", 1.0 / 3.0, 0.0, 1.0)? as f32,
        },
        "catmullrom" => Filter::Mitchell { b: 0.0, c: 0.5 },
        "lanczos" => {
            let lobes = params.integer("lobes", 3)?;
            if !(1..=32).contains(&lobes) {
                return Err(Error::input(
                    params.location_of("lobes"),
                    format!("lanczos needs between 1 and 32 lobes, not {lobes}"),
                ));
            }
            Filter::Lanczos {
                lobes: lobes as u32,
            }
        }
        other => {
            return Err(
                Error::input(&node.location, format!("unknown rfilter type \"{other}\""))
                    .with_help(format!(
                        "supported rfilter types: {}",
                        SUPPORTED_FILTERS.join(", ")
                    )),
            );
        }
    };
    params.finish()?;
    Ok(filter)
}

/// The sampler: `independent`, `stratified`, `multijitter` (each with `jitter`, default true) or
/// our `nrooks`; `sample_count` (default 4) and `seed` (default 0). See [`prism_core::sampling::sampler`]
/// for which dimensions each stratifies.
fn build_sampler(node: &PluginNode) -> Result<(SamplerSettings, u64)> {
    let params = Params::new(node);
    let kind = match node.plugin_type.as_str() {
        "independent" => SamplerKind::Independent,
        "stratified" => SamplerKind::Stratified {
            jitter: params.boolean("jitter", true)?,
        },
        "multijitter" => SamplerKind::MultiJitter {
            jitter: params.boolean("jitter", true)?,
        },
        "nrooks" => SamplerKind::NRooks,
        other => {
            return Err(
                Error::input(&node.location, format!("unknown sampler type \"{other}\""))
                    .with_help(format!(
                        "supported sampler types: {}",
                        SUPPORTED_SAMPLERS.join(", ")
                    )),
            );
        }
    };
    let spp = params.integer("sample_count", 4)?;
    if !(1..=(1 << 24)).contains(&spp) {
        return Err(Error::input(
            params.location_of("sample_count"),
            format!("sample_count must be between 1 and {}, not {spp}", 1 << 24),
        ));
    }
    let seed = params.integer("seed", 0)?;
    params.finish()?;
    Ok((
        SamplerSettings {
            kind,
            samples_per_pixel: spp as u32,
        },
        seed as u64,
    ))
}
