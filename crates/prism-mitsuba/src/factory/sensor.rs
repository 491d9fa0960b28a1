//! The sensor and what it carries: the `perspective`, `thinlens` and `orthographic` cameras with
//! their shutter,
//! the `hdrfilm` and `ldrfilm` films with their `rfilter`, and the sampler.

use std::sync::Arc;

use glam::{UVec2, Vec2};

use super::fov::{FOCAL_LENGTH, FOV, FOV_AXIS, horizontal_fov_param};
use crate::description::{PluginClass, PluginNode};
use crate::params::{Params, Warning};
use crate::registry::{Bounds, Choice, Default, Origin, ParamKind, ParamSpec, Plugin, Registry};
use prism_core::camera::{Camera, OrthographicCamera, PerspectiveCamera, Shutter};
use prism_core::error::{Error, Result};
use prism_core::film::{
    BoxFilter, CropWindow, Filter, GaussianFilter, LanczosFilter, LdrFormat, LdrOutput,
    MitchellFilter, Reconstruction, TentFilter, Tonemap, TransferCurve,
};
use prism_core::image::Channels;
use prism_core::sampling::sampler::MAX_ORTHOGONAL_STRENGTH;
use prism_core::scene::{FilmSettings, SamplerKind, SamplerSettings};
use prism_core::spectrum::WavelengthSampling;

/// Builds a sensor; `thinlens` says whether it has a lens.
type SensorBuild = fn(&Params, bool) -> Result<SensorSettings>;

pub static SENSORS: Registry<SensorBuild> = Registry {
    class: PluginClass::Sensor,
    plugins: &[
        Plugin {
            name: "perspective",
            origin: Origin::Mitsuba3,
            summary: "A pinhole camera looking along its +z axis (+y up).",
            params: PERSPECTIVE_PARAMS,
            build: build_sensor_of,
        },
        Plugin {
            name: "thinlens",
            origin: Origin::Mitsuba3,
            summary: "A thin-lens camera: as `perspective`, with depth of field.",
            params: THINLENS_PARAMS,
            build: build_sensor_of,
        },
        Plugin {
            name: "orthographic",
            origin: Origin::Mitsuba3,
            summary: "Parallel rays along +z from the square [−1, 1] × [−1/a, 1/a] (a = width / height) of the camera's near plane, placed and scaled by `to_world`.",
            params: ORTHOGRAPHIC_PARAMS,
            build: build_orthographic,
        },
    ],
};

const NEAR_CLIP: ParamSpec = ParamSpec::new(
    "near_clip",
    ParamKind::Float,
    Default::Float(1e-2),
    "distance before which nothing is seen",
);
const FAR_CLIP: ParamSpec = ParamSpec::new(
    "far_clip",
    ParamKind::Float,
    Default::Float(1e4),
    "distance beyond which nothing is seen",
);
const SENSOR_TO_WORLD: ParamSpec = ParamSpec::new(
    "to_world",
    ParamKind::AnimatedTransform,
    Default::Text("identity"),
    "camera to world: rotations and translations (a `lookat`), or an `<animation>` of them",
);
const SHUTTER_OPEN: ParamSpec = ParamSpec::new(
    "shutter_open",
    ParamKind::Float,
    Default::Float(0.0),
    "time the shutter opens",
);
const SHUTTER_CLOSE: ParamSpec = ParamSpec::new(
    "shutter_close",
    ParamKind::Float,
    Default::Text("`shutter_open`"),
    "time the shutter closes",
);
const SHUTTER_FILTER: ParamSpec = ParamSpec::new(
    "shutter_filter",
    ParamKind::Nested(PluginClass::Rfilter),
    Default::Text("box"),
    "Prism only: a nested `<rfilter name=\"shutter_filter\">` weighting time within the shutter interval",
);
const FILM: ParamSpec = ParamSpec::nested(
    PluginClass::Film,
    Default::Text("`hdrfilm`, 768 × 576, gaussian"),
    "the film",
);
const SAMPLER: ParamSpec = ParamSpec::nested(
    PluginClass::Sampler,
    Default::Text("`independent`, 4 samples"),
    "the sampler",
);
const SENSOR_MEDIUM: ParamSpec = ParamSpec::nested(
    PluginClass::Medium,
    Default::None,
    "the medium the camera sits in (for `volpath`)",
);
const APERTURE_RADIUS: ParamSpec = ParamSpec::new(
    "aperture_radius",
    ParamKind::Float,
    Default::Required,
    "radius of the lens (or give `aperture_area`)",
);
const APERTURE_AREA: ParamSpec = ParamSpec::new(
    "aperture_area",
    ParamKind::Float,
    Default::None,
    "Prism only, the lecture's form: the lens's area a, radius √(a/π)",
);
const FOCUS_DISTANCE: ParamSpec = ParamSpec::new(
    "focus_distance",
    ParamKind::Float,
    Default::Text("`far_clip`"),
    "distance of the plane in focus",
);
const PINHOLE_FOCUS_DISTANCE: ParamSpec = ParamSpec::new(
    "focus_distance",
    ParamKind::Float,
    Default::Text("`far_clip`"),
    "read as Mitsuba 3 reads it on every projective camera; a pinhole has everything in focus",
);
const FOCAL_DISTANCE: ParamSpec = ParamSpec::new(
    "focal_distance",
    ParamKind::Float,
    Default::None,
    "Prism only, the lecture's name for `focus_distance`",
);

const ORTHOGRAPHIC_TO_WORLD: ParamSpec = ParamSpec::new(
    "to_world",
    ParamKind::AnimatedTransform,
    Default::Text("identity"),
    "camera to world, scales included (they set the film's extent in the scene), or an `<animation>` of them",
);
const ORTHOGRAPHIC_PARAMS: &[ParamSpec] = &[
    NEAR_CLIP,
    FAR_CLIP,
    ORTHOGRAPHIC_TO_WORLD,
    SHUTTER_OPEN,
    SHUTTER_CLOSE,
    SHUTTER_FILTER,
    FILM,
    SAMPLER,
    PINHOLE_FOCUS_DISTANCE,
    SENSOR_MEDIUM,
];
const PERSPECTIVE_PARAMS: &[ParamSpec] = &[
    FOV,
    FOV_AXIS,
    FOCAL_LENGTH,
    NEAR_CLIP,
    FAR_CLIP,
    SENSOR_TO_WORLD,
    SHUTTER_OPEN,
    SHUTTER_CLOSE,
    SHUTTER_FILTER,
    FILM,
    SAMPLER,
    PINHOLE_FOCUS_DISTANCE,
    SENSOR_MEDIUM,
];
const THINLENS_PARAMS: &[ParamSpec] = &[
    FOV,
    FOV_AXIS,
    FOCAL_LENGTH,
    NEAR_CLIP,
    FAR_CLIP,
    SENSOR_TO_WORLD,
    SHUTTER_OPEN,
    SHUTTER_CLOSE,
    SHUTTER_FILTER,
    FILM,
    SAMPLER,
    SENSOR_MEDIUM,
    APERTURE_RADIUS,
    APERTURE_AREA,
    FOCUS_DISTANCE,
    FOCAL_DISTANCE,
];

type FilmBuild = fn(&Params) -> Result<(FilmSettings, LdrOutput)>;

pub static FILMS: Registry<FilmBuild> = Registry {
    class: PluginClass::Film,
    plugins: &[
        Plugin {
            name: "hdrfilm",
            origin: Origin::Mitsuba3,
            summary: "A high dynamic range film; Prism writes it as 32-bit OpenEXR (RGB, XYZ, per-pixel \
                      variance and relative error) and an sRGB PNG.",
            params: &[
                WIDTH,
                HEIGHT,
                CROP_OFFSET_X,
                CROP_OFFSET_Y,
                CROP_WIDTH,
                CROP_HEIGHT,
                FILE_FORMAT,
                PIXEL_FORMAT,
                COMPONENT_FORMAT,
                RFILTER,
                RECONSTRUCTION,
                WAVELENGTH_SAMPLING,
                BANNER,
                ATTACH_LOG,
                HIGH_QUALITY_EDGES,
                HDR_GAMMA,
            ],
            build: build_hdrfilm,
        },
        Plugin {
            name: "ldrfilm",
            origin: Origin::Mitsuba06,
            summary: "Mitsuba 0.6's low dynamic range film: Prism writes its usual OpenEXR and, in \
                      place of the sRGB PNG, the 8-bit PNG or JPEG tonemapped as the film asks.",
            params: &[
                WIDTH,
                HEIGHT,
                CROP_OFFSET_X,
                CROP_OFFSET_Y,
                CROP_WIDTH,
                CROP_HEIGHT,
                LDR_FILE_FORMAT,
                LDR_PIXEL_FORMAT,
                TONEMAP_METHOD,
                LDR_GAMMA,
                EXPOSURE,
                KEY,
                BURN,
                RFILTER,
                RECONSTRUCTION,
                WAVELENGTH_SAMPLING,
                BANNER,
                HIGH_QUALITY_EDGES,
            ],
            build: build_ldrfilm,
        },
    ],
};

const WIDTH: ParamSpec = ParamSpec::new(
    "width",
    ParamKind::Integer,
    Default::Integer(768),
    "pixels across",
);
const HEIGHT: ParamSpec = ParamSpec::new(
    "height",
    ParamKind::Integer,
    Default::Integer(576),
    "pixels down",
);
const CROP_OFFSET_X: ParamSpec = ParamSpec::new(
    "crop_offset_x",
    ParamKind::Integer,
    Default::Integer(0),
    "first column rendered",
);
const CROP_OFFSET_Y: ParamSpec = ParamSpec::new(
    "crop_offset_y",
    ParamKind::Integer,
    Default::Integer(0),
    "first row rendered",
);
const CROP_WIDTH: ParamSpec = ParamSpec::new(
    "crop_width",
    ParamKind::Integer,
    Default::Text("`width` − `crop_offset_x`"),
    "columns rendered",
);
const CROP_HEIGHT: ParamSpec = ParamSpec::new(
    "crop_height",
    ParamKind::Integer,
    Default::Text("`height` − `crop_offset_y`"),
    "rows rendered",
);
const FILE_FORMAT: ParamSpec = ParamSpec::new(
    "file_format",
    ParamKind::Choice(&[
        Choice {
            name: "openexr",
            value: &(),
        },
        Choice {
            name: "exr",
            value: &(),
        },
    ]),
    Default::Str("openexr"),
    "accepted; the output is always OpenEXR",
);
const PIXEL_FORMAT: ParamSpec = ParamSpec::new(
    "pixel_format",
    ParamKind::Choice(&[
        Choice {
            name: "rgb",
            value: &(),
        },
        Choice {
            name: "rgba",
            value: &(),
        },
        Choice {
            name: "xyz",
            value: &(),
        },
        Choice {
            name: "xyza",
            value: &(),
        },
        Choice {
            name: "luminance",
            value: &(),
        },
        Choice {
            name: "luminance_alpha",
            value: &(),
        },
    ]),
    Default::Str("rgb"),
    "accepted; the output always holds RGB and XYZ",
);
const RECONSTRUCTION: ParamSpec = ParamSpec::new(
    "reconstruction",
    ParamKind::Choice(&[
        Choice {
            name: "filter_mis",
            value: &Reconstruction::FilterMis,
        },
        Choice {
            name: "pixel",
            value: &Reconstruction::Pixel,
        },
    ]),
    Default::Str("filter_mis"),
    "Prism only (Mitsuba rejects it): how samples become pixels: `filter_mis` (every sample \
     feeds every pixel its filter covers, unbiased, with less noise than Mitsuba's splatting) or \
     `pixel` (each sample counts for its own pixel, the lecture's estimator); the same for a \
     `box` filter; see docs/reconstruction.md",
);
const WAVELENGTH_SAMPLING: ParamSpec = ParamSpec::new(
    "wavelength_sampling",
    ParamKind::Choice(&[
        Choice {
            name: "balanced",
            value: &WavelengthSampling::Balanced,
        },
        Choice {
            name: "cie_sum",
            value: &WavelengthSampling::CieSum,
        },
        Choice {
            name: "visible",
            value: &WavelengthSampling::Visible,
        },
        Choice {
            name: "uniform",
            value: &WavelengthSampling::Uniform,
        },
    ]),
    Default::Str("visible"),
    "Prism only (Mitsuba rejects it): the density wavelengths are drawn from: `visible` \
     (Mitsuba's and pbrt's, the quietest on the Cornell boxes), `balanced` (least error of \
     luminance and linear sRGB under white light), `cie_sum` (∝ x̄+ȳ+z̄, the lecture's), \
     `uniform`; see docs/wavelengths.md",
);
const COMPONENT_FORMAT: ParamSpec = ParamSpec::new(
    "component_format",
    ParamKind::Choice(&[
        Choice {
            name: "float16",
            value: &(),
        },
        Choice {
            name: "float32",
            value: &(),
        },
        Choice {
            name: "uint32",
            value: &(),
        },
    ]),
    Default::Str("float32"),
    "accepted; the output is always 32-bit float",
);
const BANNER: ParamSpec = ParamSpec::new(
    "banner",
    ParamKind::Boolean,
    Default::Ignored,
    "Mitsuba 0.6's \"rendered by Mitsuba\" banner; Prism writes none",
);
const ATTACH_LOG: ParamSpec = ParamSpec::new(
    "attach_log",
    ParamKind::Boolean,
    Default::Ignored,
    "Mitsuba 0.6's render log in the image's metadata; Prism attaches none",
);
const HIGH_QUALITY_EDGES: ParamSpec = ParamSpec::new(
    "high_quality_edges",
    ParamKind::Boolean,
    Default::Ignored,
    "Mitsuba 0.6's sampling of a margin outside the film; Prism samples the film's pixels only",
);
const HDR_GAMMA: ParamSpec = ParamSpec::new(
    "gamma",
    ParamKind::Float,
    Default::Ignored,
    "a gamma on an HDR film, as Mitsuba 0.6 scenes give it; the EXR is linear",
);
const LDR_FILE_FORMAT: ParamSpec = ParamSpec::new(
    "file_format",
    ParamKind::Choice(&[
        Choice {
            name: "png",
            value: &LdrFormat::Png,
        },
        Choice {
            name: "jpeg",
            value: &LdrFormat::Jpeg,
        },
        Choice {
            name: "jpg",
            value: &LdrFormat::Jpeg,
        },
    ]),
    Default::Str("png"),
    "the 8-bit file: PNG, or JPEG of quality 100 (extension `.jpg`)",
);
const LDR_PIXEL_FORMAT: ParamSpec = ParamSpec::new(
    "pixel_format",
    ParamKind::Choice(&[
        Choice {
            name: "rgb",
            value: &Channels::Rgb,
        },
        Choice {
            name: "rgba",
            value: &Channels::Rgba,
        },
        Choice {
            name: "luminance",
            value: &Channels::Luminance,
        },
        Choice {
            name: "luminanceAlpha",
            value: &Channels::LuminanceAlpha,
        },
    ]),
    Default::Str("rgb"),
    "the 8-bit image's channels; Prism's alpha is opaque (its film records no coverage), and a JPEG drops it, as Mitsuba 0.6 does",
);
/// How `ldrfilm` maps radiance to 8-bit values.
#[derive(Clone, Copy)]
enum TonemapMethod {
    /// Scale by 2^`exposure`, then the transfer curve.
    Gamma,
    /// Reinhard et al. 2002's global operator.
    Reinhard,
}
const TONEMAP_METHOD: ParamSpec = ParamSpec::new(
    "tonemap_method",
    ParamKind::Choice(&[
        Choice {
            name: "gamma",
            value: &TonemapMethod::Gamma,
        },
        Choice {
            name: "reinhard",
            value: &TonemapMethod::Reinhard,
        },
    ]),
    Default::Str("gamma"),
    "`gamma`: scale by 2^`exposure`; `reinhard`: Reinhard et al. 2002's global operator with `key` and `burn`",
);
const LDR_GAMMA: ParamSpec = ParamSpec::new(
    "gamma",
    ParamKind::Float,
    Default::Float(-1.0),
    "the transfer curve v^(1/γ) of the 8-bit values; −1 is the sRGB curve",
);
const EXPOSURE: ParamSpec = ParamSpec::new(
    "exposure",
    ParamKind::Float,
    Default::Float(0.0),
    "with `gamma` tonemapping, the exposure in f-stops: values are scaled by 2^exposure",
);
const KEY: ParamSpec = ParamSpec::new(
    "key",
    ParamKind::Float,
    Default::Float(0.18),
    "with `reinhard`, the value the log-average luminance maps to, in (0, 1]",
);
const BURN: ParamSpec = ParamSpec::new(
    "burn",
    ParamKind::Float,
    Default::Float(0.0),
    "with `reinhard`, how much highlights may burn out, in [0, 1]",
);
const RFILTER: ParamSpec = ParamSpec::nested(
    PluginClass::Rfilter,
    Default::Text("`gaussian`"),
    "the reconstruction filter",
);

type FilterBuild = fn(&Params) -> Result<Filter>;

pub static RFILTERS: Registry<FilterBuild> = Registry {
    class: PluginClass::Rfilter,
    plugins: &[
        Plugin {
            name: "box",
            origin: Origin::Mitsuba3,
            summary: "The box filter.",
            params: &[BOX_RADIUS],
            build: |params| {
                Ok(Filter::Box(BoxFilter {
                    radius: filter_size(params, &BOX_RADIUS)?,
                }))
            },
        },
        Plugin {
            name: "tent",
            origin: Origin::Mitsuba3,
            summary: "The tent (triangle) filter.",
            params: &[TENT_RADIUS],
            build: |params| {
                Ok(Filter::Tent(TentFilter {
                    radius: filter_size(params, &TENT_RADIUS)?,
                }))
            },
        },
        Plugin {
            name: "gaussian",
            origin: Origin::Mitsuba3,
            summary: "A Gaussian truncated at 4 standard deviations (Mitsuba's default filter).",
            params: &[STDDEV],
            build: |params| {
                Ok(Filter::Gaussian(GaussianFilter {
                    stddev: filter_size(params, &STDDEV)?,
                }))
            },
        },
        Plugin {
            name: "mitchell",
            origin: Origin::Mitsuba3,
            summary: "The Mitchell–Netravali filter, radius 2.",
            params: &[MITCHELL_B, MITCHELL_C],
            build: |params| {
                Ok(Filter::Mitchell(MitchellFilter {
                    b: params.float_in(&MITCHELL_B)? as f32,
                    c: params.float_in(&MITCHELL_C)? as f32,
                }))
            },
        },
        Plugin {
            name: "catmullrom",
            origin: Origin::Mitsuba3,
            summary: "The Catmull–Rom filter: Mitchell–Netravali with B = 0, C = ½.",
            params: &[],
            build: |_| Ok(Filter::Mitchell(MitchellFilter { b: 0.0, c: 0.5 })),
        },
        Plugin {
            name: "lanczos",
            origin: Origin::Mitsuba3,
            summary: "The windowed sinc filter.",
            params: &[LOBES],
            build: |params| {
                let lobes = params.integer(&LOBES)?;
                if !(1..=32).contains(&lobes) {
                    return Err(Error::input(
                        params.location_of(&LOBES),
                        format!("lanczos needs between 1 and 32 lobes, not {lobes}"),
                    ));
                }
                Ok(Filter::Lanczos(LanczosFilter {
                    lobes: lobes as u32,
                }))
            },
        },
    ],
};

const BOX_RADIUS: ParamSpec = ParamSpec::new(
    "radius",
    ParamKind::Float,
    Default::Float(0.5),
    "half width in pixels",
);
const TENT_RADIUS: ParamSpec = ParamSpec::new(
    "radius",
    ParamKind::Float,
    Default::Float(1.0),
    "half width in pixels",
);
const STDDEV: ParamSpec = ParamSpec::new(
    "stddev",
    ParamKind::Float,
    Default::Float(0.5),
    "standard deviation in pixels",
);
const MITCHELL_B: ParamSpec = ParamSpec::new(
    "B",
    ParamKind::FloatIn(Bounds::UNIT),
    Default::Float(1.0 / 3.0),
    "the blur parameter B",
);
const MITCHELL_C: ParamSpec = ParamSpec::new(
    "C",
    ParamKind::FloatIn(Bounds::UNIT),
    Default::Float(1.0 / 3.0),
    "the ringing parameter C",
);
const LOBES: ParamSpec = ParamSpec::new(
    "lobes",
    ParamKind::Integer,
    Default::Integer(3),
    "lobes of the sinc (1 to 32)",
);

type SamplerBuild = fn(&Params) -> Result<SamplerKind>;

pub static SAMPLERS: Registry<SamplerBuild> = Registry {
    class: PluginClass::Sampler,
    plugins: &[
        Plugin {
            name: "independent",
            origin: Origin::Mitsuba3,
            summary: "Independent uniform random numbers.",
            params: &[SAMPLE_COUNT, SEED],
            build: |_| Ok(SamplerKind::Independent),
        },
        Plugin {
            name: "stratified",
            origin: Origin::Mitsuba3,
            summary: "Every dimension stratified, as Mitsuba does; `sample_count` is rounded up to a square.",
            params: &[SAMPLE_COUNT, SEED, JITTER],
            build: |params| {
                Ok(SamplerKind::Stratified {
                    jitter: params.boolean(&JITTER)?,
                })
            },
        },
        Plugin {
            name: "multijitter",
            origin: Origin::Mitsuba3,
            summary: "Correlated multi-jittered sampling, as Mitsuba does; `sample_count` is rounded up to a near-square product.",
            params: &[SAMPLE_COUNT, SEED, JITTER],
            build: |params| {
                Ok(SamplerKind::MultiJitter {
                    jitter: params.boolean(&JITTER)?,
                })
            },
        },
        Plugin {
            name: "nrooks",
            origin: Origin::Prism,
            summary: "The lecture's N-rooks sampling: each of the six primary dimensions (wavelength,                       time, film x and y, lens u and v) stratified into N strata, shuffled                       independently.",
            params: &[SAMPLE_COUNT, SEED],
            build: |_| Ok(SamplerKind::NRooks),
        },
        Plugin {
            name: "ldsampler",
            origin: Origin::Mitsuba3,
            summary: "Mitsuba 3's low-discrepancy sampler (and Mitsuba 0.6's of the same name): a scrambled (0, 2)-sequence shuffled per dimension; `sample_count` is rounded up to a square of a power of two.",
            params: &[SAMPLE_COUNT, SEED],
            build: |_| Ok(SamplerKind::LowDiscrepancy),
        },
        Plugin {
            name: "orthogonal",
            origin: Origin::Mitsuba3,
            summary: "Orthogonal array sampling (Jarosz et al. 2019), as Mitsuba 3 does: `sample_count` is rounded up to p^`strength` for a prime p.",
            params: &[SAMPLE_COUNT, SEED, JITTER, STRENGTH],
            build: |params| {
                let strength = params.integer(&STRENGTH)?;
                if !(1..=i64::from(MAX_ORTHOGONAL_STRENGTH)).contains(&strength) {
                    return Err(Error::input(
                        params.location_of(&STRENGTH),
                        format!(
                            "the orthogonal array's strength must be between 1 and {MAX_ORTHOGONAL_STRENGTH}, not {strength}"
                        ),
                    ));
                }
                Ok(SamplerKind::Orthogonal {
                    strength: strength as u32,
                    jitter: params.boolean(&JITTER)?,
                })
            },
        },
    ],
};

const STRENGTH: ParamSpec = ParamSpec::new(
    "strength",
    ParamKind::Integer,
    Default::Integer(2),
    "the orthogonal array's strength t: every t dimensions together are stratified (1 to 4)",
);

const SAMPLE_COUNT: ParamSpec = ParamSpec::new(
    "sample_count",
    ParamKind::Integer,
    Default::Integer(4),
    "samples per pixel (1 to 2²⁴)",
);
const SEED: ParamSpec = ParamSpec::new(
    "seed",
    ParamKind::Integer,
    Default::Integer(0),
    "seed of every random number (`--seed` overrides it)",
);
const JITTER: ParamSpec = ParamSpec::new(
    "jitter",
    ParamKind::Boolean,
    Default::Boolean(true),
    "jitter samples within their strata",
);

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
    /// How the 8-bit image is written (`ldrfilm`), or the default sRGB PNG.
    pub ldr_output: LdrOutput,
    /// The parameters read and ignored, one warning each.
    pub warnings: Vec<Warning>,
    /// The nested `<medium>` the camera sits in, built with the scene's other media.
    pub medium: Option<Arc<PluginNode>>,
}

/// Builds the sensor a node describes.
pub fn build_sensor(node: &PluginNode) -> Result<SensorSettings> {
    let plugin = SENSORS.find(node)?;
    let params = Params::new(node, plugin.params);
    let sensor = (plugin.build)(&params, plugin.name == "thinlens")?;
    params.finish()?;
    Ok(sensor)
}

/// What every sensor carries: its film (with the 8-bit output and the warnings of its ignored
/// parameters), its sampler and the sampler's seed.
struct SensorParts {
    film: FilmSettings,
    ldr_output: LdrOutput,
    warnings: Vec<Warning>,
    sampler: SamplerSettings,
    seed: u64,
}

fn sensor_parts(params: &Params) -> Result<SensorParts> {
    let (film, ldr_output, warnings) = match params.single_child(&FILM)? {
        Some(child) => build_film(&child.node)?,
        None => (default_film(), LdrOutput::default(), Vec::new()),
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
    Ok(SensorParts {
        film,
        ldr_output,
        warnings,
        sampler,
        seed,
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
    Ok(SensorSettings {
        camera,
        shutter,
        film: parts.film,
        sampler: parts.sampler,
        seed: parts.seed,
        ldr_output: parts.ldr_output,
        warnings: parts.warnings,
        medium: params.single_child(&SENSOR_MEDIUM)?.map(|c| c.node.clone()),
    })
}

fn build_sensor_of(params: &Params, thinlens: bool) -> Result<SensorSettings> {
    let SensorParts {
        film,
        ldr_output,
        warnings,
        sampler,
        seed,
    } = sensor_parts(params)?;

    let aspect = f64::from(film.size.x) / f64::from(film.size.y);
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
        ldr_output,
        warnings,
        medium: params.single_child(&SENSOR_MEDIUM)?.map(|c| c.node.clone()),
    })
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
fn shutter(params: &Params) -> Result<Shutter> {
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

/// Mitsuba's default film: 768 × 576 with a Gaussian filter.
fn default_film() -> FilmSettings {
    let size = UVec2::new(768, 576);
    FilmSettings {
        size,
        crop: CropWindow {
            offset: UVec2::ZERO,
            size,
        },
        filter: Filter::Gaussian(GaussianFilter { stddev: 0.5 }),
        reconstruction: Reconstruction::default(),
        wavelength_sampling: WavelengthSampling::default(),
    }
}

/// The film a node describes, how its 8-bit image is written, and a warning for each ignored
/// parameter it gives.
fn build_film(node: &PluginNode) -> Result<(FilmSettings, LdrOutput, Vec<Warning>)> {
    let plugin = FILMS.find(node)?;
    let params = Params::new(node, plugin.params);
    let (film, ldr) = (plugin.build)(&params)?;
    let warnings = params.finish_with_warnings()?;
    Ok((film, ldr, warnings))
}

/// `hdrfilm`: `width` (768), `height` (576), `crop_offset_x/y`, `crop_width/height`, a nested
/// `rfilter` (Gaussian by default). `file_format`, `pixel_format` and `component_format` are
/// accepted for compatibility; Prism always writes 32-bit linear RGB and XYZ to EXR.
fn build_hdrfilm(params: &Params) -> Result<(FilmSettings, LdrOutput)> {
    let film = film_settings(params)?;
    for spec in [&FILE_FORMAT, &PIXEL_FORMAT, &COMPONENT_FORMAT] {
        params.choice::<()>(spec)?;
    }
    Ok((film, LdrOutput::default()))
}

/// `ldrfilm` (Mitsuba 0.6's `src/films/ldrfilm.cpp`): the film of `hdrfilm`, and how its 8-bit
/// image is tonemapped ([`prism_core::film::ldr`]).
fn build_ldrfilm(params: &Params) -> Result<(FilmSettings, LdrOutput)> {
    let film = film_settings(params)?;
    let format = params.choice(&LDR_FILE_FORMAT)?;
    // A JPEG has no alpha channel.
    let channels = match (params.choice(&LDR_PIXEL_FORMAT)?, format) {
        (Channels::Rgba, LdrFormat::Jpeg) => Channels::Rgb,
        (Channels::LuminanceAlpha, LdrFormat::Jpeg) => Channels::Luminance,
        (channels, _) => channels,
    };
    let gamma = params.float(&LDR_GAMMA)?;
    let curve = if gamma == -1.0 {
        TransferCurve::Srgb
    } else if gamma > 0.0 && gamma.is_finite() {
        TransferCurve::Gamma(gamma as f32)
    } else {
        return Err(Error::input(
            params.location_of(&LDR_GAMMA),
            format!("the film's gamma must be positive, or −1 for the sRGB curve, not {gamma}"),
        ));
    };
    // Mitsuba 0.6 reads all three whichever the method, so a scene may give them all.
    let exposure = params.float(&EXPOSURE)?;
    let key = params.float(&KEY)?;
    let burn = params.float(&BURN)?;
    let out_of_range = |spec: &ParamSpec, range: &str, value: f64| {
        Error::input(
            params.location_of(spec),
            format!(
                "the film's \"{}\" must lie in {range}, not {value}",
                spec.name
            ),
        )
    };
    if !(exposure.abs() <= 100.0) {
        return Err(out_of_range(&EXPOSURE, "[−100, 100] f-stops", exposure));
    }
    if !(key > 0.0 && key <= 1.0) {
        return Err(out_of_range(&KEY, "(0, 1]", key));
    }
    if !(0.0..=1.0).contains(&burn) {
        return Err(out_of_range(&BURN, "[0, 1]", burn));
    }
    let tonemap = match params.choice(&TONEMAP_METHOD)? {
        TonemapMethod::Reinhard => Tonemap::Reinhard {
            key: key as f32,
            burn: burn as f32,
        },
        TonemapMethod::Gamma => Tonemap::Exposure {
            exposure: exposure as f32,
        },
    };
    Ok((
        film,
        LdrOutput {
            tonemap,
            curve,
            format,
            channels,
        },
    ))
}

/// The size, crop window, filter and wavelength density that `hdrfilm` and `ldrfilm` share.
fn film_settings(params: &Params) -> Result<FilmSettings> {
    let width = params.integer(&WIDTH)?;
    let height = params.integer(&HEIGHT)?;
    if !(1..=MAX_FILM_SIDE).contains(&width)
        || !(1..=MAX_FILM_SIDE).contains(&height)
        || width * height > MAX_FILM_PIXELS
    {
        return Err(Error::input(
            params.location_of(if (1..=MAX_FILM_SIDE).contains(&width) { &HEIGHT } else { &WIDTH }),
            format!("a film of {width} × {height} pixels is not possible"),
        )
        .with_help(format!(
            "width and height must be between 1 and {MAX_FILM_SIDE}, with at most {MAX_FILM_PIXELS} pixels in all"
        )));
    }
    let crop_x = params.integer(&CROP_OFFSET_X)?;
    let crop_y = params.integer(&CROP_OFFSET_Y)?;
    let crop_width = params.integer_opt(&CROP_WIDTH)?.unwrap_or(width - crop_x);
    let crop_height = params.integer_opt(&CROP_HEIGHT)?.unwrap_or(height - crop_y);
    if crop_x < 0
        || crop_y < 0
        || crop_width < 1
        || crop_height < 1
        || crop_x + crop_width > width
        || crop_y + crop_height > height
    {
        return Err(Error::input(
            params.location_of(&CROP_WIDTH),
            format!(
                "the crop window at ({crop_x}, {crop_y}) of size {crop_width} × {crop_height} does not fit in the {width} × {height} film"
            ),
        ));
    }
    let filter = match params.single_child(&RFILTER)? {
        Some(child) => build_filter(&child.node)?,
        None => Filter::Gaussian(GaussianFilter { stddev: 0.5 }),
    };
    let reconstruction = params.choice(&RECONSTRUCTION)?;
    let wavelength_sampling = params.choice(&WAVELENGTH_SAMPLING)?;
    let size = UVec2::new(width as u32, height as u32);
    Ok(FilmSettings {
        size,
        crop: CropWindow {
            offset: UVec2::new(crop_x as u32, crop_y as u32),
            size: UVec2::new(crop_width as u32, crop_height as u32),
        },
        filter,
        reconstruction,
        wavelength_sampling,
    })
}

fn build_filter(node: &PluginNode) -> Result<Filter> {
    let plugin = RFILTERS.find(node)?;
    let params = Params::new(node, plugin.params);
    let filter = (plugin.build)(&params)?;
    params.finish()?;
    Ok(filter)
}

/// A filter's size parameter: positive, and at most 64 pixels.
fn filter_size(params: &Params, spec: &ParamSpec) -> Result<f32> {
    let v = params.float(spec)?;
    if !(v > 0.0 && v <= 64.0) {
        return Err(Error::input(
            params.location_of(spec),
            format!(
                "the filter's \"{}\" must be positive (and at most 64 pixels), not {v}",
                spec.name
            ),
        ));
    }
    Ok(v as f32)
}

/// The sampler a node describes, with its seed.
pub(crate) fn build_sampler(node: &PluginNode) -> Result<(SamplerSettings, u64)> {
    let plugin = SAMPLERS.find(node)?;
    let params = Params::new(node, plugin.params);
    let kind = (plugin.build)(&params)?;
    let spp = params.integer(&SAMPLE_COUNT)?;
    if !(1..=(1 << 24)).contains(&spp) {
        return Err(Error::input(
            params.location_of(&SAMPLE_COUNT),
            format!("sample_count must be between 1 and {}, not {spp}", 1 << 24),
        ));
    }
    if kind.sample_count(spp as u32) > 1 << 24 {
        return Err(Error::input(
            params.location_of(&SAMPLE_COUNT),
            format!(
                "{} sampler rounds {spp} samples up to {}, more than {}",
                plugin.name,
                kind.sample_count(spp as u32),
                1 << 24
            ),
        )
        .with_help("ask for fewer samples, or a lower strength"));
    }
    let seed = params.integer(&SEED)?;
    params.finish()?;
    Ok((
        SamplerSettings {
            kind,
            samples_per_pixel: spp as u32,
        },
        seed as u64,
    ))
}
