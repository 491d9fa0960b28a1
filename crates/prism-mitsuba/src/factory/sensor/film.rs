//! Films: `hdrfilm` and Mitsuba 0.6's `ldrfilm`, their size and crop window, their `rfilter`, and
//! how `ldrfilm` tonemaps its 8-bit image.

use super::rfilter::build_filter;
use crate::description::{
    PluginClass, PluginNode, Property, PropertyValue, SpectrumValue, Warning,
};
use crate::params::Params;
use crate::registry::{
    Choice, Default, Origin, ParamKind, ParamSpec, Plugin, Range, Registry, params,
};
use glam::UVec2;
use prism_core::error::{Error, Result};
use prism_core::film::output::{ALPHA_CHANNEL, IMAGE_CHANNELS};
use prism_core::film::{
    ComponentFormat, CropWindow, ExrOutput, Filter, GaussianFilter, LdrFormat, LdrOutput,
    PixelFormat, Reconstruction, SpectralBand, Tonemap, TransferCurve,
};
use prism_core::image::Channels;
use prism_core::scene::FilmSettings;
use prism_core::spectrum::{LAMBDA_MAX, LAMBDA_MIN, PiecewiseLinear, Spectrum, WavelengthSampling};

/// The parameters of a film: the size and crop window every film takes, its own `[format]`
/// parameters, the filter and reconstruction every film takes, and its own `[after]`.
macro_rules! film_params {
    ([$($format:expr),*], [$($after:expr),*]) => {
        &[
            WIDTH,
            HEIGHT,
            CROP_OFFSET_X,
            CROP_OFFSET_Y,
            CROP_WIDTH,
            CROP_HEIGHT,
            $($format,)*
            RFILTER,
            RECONSTRUCTION,
            WAVELENGTH_SAMPLING,
            BANNER,
            $($after,)*
        ]
    };
}

/// A film's settings and how its EXR and 8-bit image are written.
pub struct FilmParts {
    pub film: FilmSettings,
    pub exr: ExrOutput,
    pub ldr: LdrOutput,
}

type FilmBuild = fn(&Params) -> Result<FilmParts>;

pub static FILMS: Registry<FilmBuild> = Registry {
    class: PluginClass::Film,
    plugins: &[
        Plugin {
            name: "hdrfilm",
            origin: Origin::Mitsuba3,
            summary: "A high dynamic range film; Prism writes it as OpenEXR (the colour channels of \
                      `pixel_format`, XYZ, per-pixel variance and relative error) and an sRGB PNG.",
            params: film_params!(
                [FILE_FORMAT, PIXEL_FORMAT, COMPONENT_FORMAT],
                [ATTACH_LOG, HIGH_QUALITY_EDGES, HDR_GAMMA]
            ),
            build: build_hdrfilm,
        },
        Plugin {
            name: "ldrfilm",
            origin: Origin::Mitsuba06,
            summary: "Mitsuba 0.6's low dynamic range film: Prism writes its usual OpenEXR and, in \
                      place of the sRGB PNG, the 8-bit PNG or JPEG tonemapped as the film asks.",
            params: film_params!(
                [
                    LDR_FILE_FORMAT,
                    LDR_PIXEL_FORMAT,
                    TONEMAP_METHOD,
                    LDR_GAMMA,
                    EXPOSURE,
                    KEY,
                    BURN
                ],
                [HIGH_QUALITY_EDGES]
            ),
            build: build_ldrfilm,
        },
        Plugin {
            name: "specfilm",
            origin: Origin::Mitsuba3,
            summary: "A spectral film: one OpenEXR channel per nested `<spectrum name=\"...\">`, \
                      named as it, holding ∫ s(λ) L(λ) dλ, the radiance integrated against that \
                      response (with Y and its statistics).",
            params: film_params!([COMPONENT_FORMAT], [SPECTRAL_BANDS]),
            build: build_specfilm,
        },
    ],
};

params! {
    pub WIDTH = ParamSpec::new("width", ParamKind::Integer, Default::Integer(768), "pixels across");
    pub HEIGHT = ParamSpec::new("height", ParamKind::Integer, Default::Integer(576), "pixels down");
    CROP_OFFSET_X = ParamSpec::new("crop_offset_x", ParamKind::Integer, Default::Integer(0), "first column rendered");
    CROP_OFFSET_Y = ParamSpec::new("crop_offset_y", ParamKind::Integer, Default::Integer(0), "first row rendered");
    CROP_WIDTH = ParamSpec::new("crop_width", ParamKind::Integer, Default::Text("`width` − `crop_offset_x`"), "columns rendered");
    CROP_HEIGHT = ParamSpec::new("crop_height", ParamKind::Integer, Default::Text("`height` − `crop_offset_y`"), "rows rendered");
    FILE_FORMAT = ParamSpec::new("file_format", ParamKind::Choice(&Choice::accepted(["openexr", "exr"])), Default::Str("openexr"), "accepted; the output is always OpenEXR");
    PIXEL_FORMAT = ParamSpec::new("pixel_format", ParamKind::Choice(&[Choice::new("rgb", &PixelFormat::Rgb), Choice::new("rgba", &PixelFormat::Rgba), Choice::new("xyz", &PixelFormat::Xyz), Choice::new("xyza", &PixelFormat::Xyza), Choice::new("luminance", &PixelFormat::Luminance), Choice::new("luminance_alpha", &PixelFormat::LuminanceAlpha)]), Default::Str("rgb"), "the EXR's colour channels: R, G, B (`rgb`), X, Y, Z (`xyz`) or Y (`luminance`), with the coverage alpha A for `rgba`, `xyza` and `luminance_alpha`; X, Y, Z (Y for luminance), their variances and the relative error of Y are always written; see docs/cli.md");
    RECONSTRUCTION = ParamSpec::new("reconstruction", ParamKind::Choice(&[Choice::new("filter_mis", &Reconstruction::FilterMis), Choice::new("pixel", &Reconstruction::Pixel)]), Default::Str("filter_mis"), "Prism only (Mitsuba rejects it): how samples become pixels: `filter_mis` (every sample feeds every pixel its filter covers, unbiased, with less noise than Mitsuba's splatting) or `pixel` (each sample counts for its own pixel, the lecture's estimator); the same for a `box` filter; see docs/reconstruction.md");
    WAVELENGTH_SAMPLING = ParamSpec::new("wavelength_sampling", ParamKind::Choice(&[Choice::new("balanced", &WavelengthSampling::Balanced), Choice::new("cie_sum", &WavelengthSampling::CieSum), Choice::new("visible", &WavelengthSampling::Visible), Choice::new("uniform", &WavelengthSampling::Uniform)]), Default::Str("visible"), "Prism only (Mitsuba rejects it): the density wavelengths are drawn from: `visible` (Mitsuba's and pbrt's, the quietest on the Cornell boxes), `balanced` (least error of luminance and linear sRGB under white light), `cie_sum` (∝ x̄+ȳ+z̄, the lecture's), `uniform`; see docs/wavelengths.md");
    COMPONENT_FORMAT = ParamSpec::new("component_format", ParamKind::Choice(&[Choice::new("float16", &ComponentFormat::Float16), Choice::new("float32", &ComponentFormat::Float32)]), Default::Str("float32"), "how the EXR stores values: `float16` (half floats; the variances and relative error stay 32-bit) or `float32`; Mitsuba's default is `float16`, Prism's `float32`, and `prism render --half` gives `float16`");
    BANNER = ParamSpec::new("banner", ParamKind::Boolean, Default::Ignored, "Mitsuba 0.6's \"rendered by Mitsuba\" banner; Prism writes none");
    ATTACH_LOG = ParamSpec::new("attach_log", ParamKind::Boolean, Default::Ignored, "Mitsuba 0.6's render log in the image's metadata; Prism attaches none");
    HIGH_QUALITY_EDGES = ParamSpec::new("high_quality_edges", ParamKind::Boolean, Default::Ignored, "Mitsuba 0.6's sampling of a margin outside the film; Prism samples the film's pixels only");
    HDR_GAMMA = ParamSpec::new("gamma", ParamKind::Float, Default::Ignored, "a gamma on an HDR film, as Mitsuba 0.6 scenes give it; the EXR is linear");
    LDR_FILE_FORMAT = ParamSpec::new("file_format", ParamKind::Choice(&[Choice::new("png", &LdrFormat::Png), Choice::new("jpeg", &LdrFormat::Jpeg), Choice::new("jpg", &LdrFormat::Jpeg)]), Default::Str("png"), "the 8-bit file: PNG, or JPEG of quality 100 (extension `.jpg`)");
    LDR_PIXEL_FORMAT = ParamSpec::new("pixel_format", ParamKind::Choice(&[Choice::new("rgb", &Channels::Rgb), Choice::new("rgba", &Channels::Rgba), Choice::new("luminance", &Channels::Luminance), Choice::new("luminanceAlpha", &Channels::LuminanceAlpha)]), Default::Str("rgb"), "the 8-bit image's channels; the alpha is the coverage (also written to the EXR as `A`), and a JPEG drops it, as Mitsuba 0.6 does");
}

/// How `ldrfilm` maps radiance to 8-bit values.
#[derive(Clone, Copy)]
enum TonemapMethod {
    /// Scale by 2^`exposure`, then the transfer curve.
    Gamma,
    /// Reinhard et al. 2002's global operator.
    Reinhard,
}

params! {
    TONEMAP_METHOD = ParamSpec::new("tonemap_method", ParamKind::Choice(&[Choice::new("gamma", &TonemapMethod::Gamma), Choice::new("reinhard", &TonemapMethod::Reinhard)]), Default::Str("gamma"), "`gamma`: scale by 2^`exposure`; `reinhard`: Reinhard et al. 2002's global operator with `key` and `burn`");
    LDR_GAMMA = ParamSpec::new("gamma", ParamKind::Float, Default::Float(-1.0), "the transfer curve v^(1/γ) of the 8-bit values; −1 is the sRGB curve");
    EXPOSURE = ParamSpec::new("exposure", ParamKind::Float, Default::Float(0.0), "with `gamma` tonemapping, the exposure in f-stops: values are scaled by 2^exposure");
    KEY = ParamSpec::new("key", ParamKind::Float, Default::Float(0.18), "with `reinhard`, the value the log-average luminance maps to, in (0, 1]");
    BURN = ParamSpec::new("burn", ParamKind::Float, Default::Float(0.0), "with `reinhard`, how much highlights may burn out, in [0, 1]");
    RFILTER = ParamSpec::nested(PluginClass::Rfilter, Default::Text("`gaussian`"), "the reconstruction filter");
    SPECTRAL_BANDS = ParamSpec::new("(any name)", ParamKind::Spectrum { range: Range::Coefficient, textured: false }, Default::Required, "one channel per `<spectrum name=\"...\">` (a response s over 360–830 nm), named as the spectrum");
}

/// Largest film side, and largest pixel count, accepted (each pixel keeps 112 bytes of sums,
/// twice while a pass is rendered).
const MAX_FILM_SIDE: i64 = 1 << 16;

const MAX_FILM_PIXELS: i64 = 1 << 25;

/// Mitsuba's default film: 768 × 576 with a Gaussian filter, written as a 32-bit RGB EXR and
/// an sRGB PNG.
pub(super) fn default_film() -> FilmParts {
    let size = UVec2::new(768, 576);
    let film = FilmSettings {
        size,
        crop: CropWindow {
            offset: UVec2::ZERO,
            size,
        },
        filter: Filter::Gaussian(GaussianFilter { stddev: 0.5 }),
        reconstruction: Reconstruction::default(),
        wavelength_sampling: WavelengthSampling::default(),
        bands: Vec::new(),
        response: None,
    };
    FilmParts {
        film,
        exr: ExrOutput::default(),
        ldr: LdrOutput::default(),
    }
}

/// The film a node describes, how its 8-bit image is written, and a warning for each ignored
/// parameter it gives.
pub(super) fn build_film(node: &PluginNode) -> Result<(FilmParts, Vec<Warning>)> {
    let plugin = FILMS.find(node)?;
    let params = Params::new(node, plugin.params);
    let parts = (plugin.build)(&params)?;
    let warnings = params.finish_with_warnings()?;
    Ok((parts, warnings))
}

/// `hdrfilm`: `width` (768), `height` (576), `crop_offset_x/y`, `crop_width/height`, a nested
/// `rfilter` (Gaussian by default), the EXR's `pixel_format` and `component_format`;
/// `file_format` is accepted for compatibility (the output is always OpenEXR).
fn build_hdrfilm(params: &Params) -> Result<FilmParts> {
    let film = film_settings(params)?;
    params.choice::<()>(&FILE_FORMAT)?;
    let exr = ExrOutput {
        pixel_format: params.choice(&PIXEL_FORMAT)?,
        component_format: params.choice(&COMPONENT_FORMAT)?,
    };
    Ok(FilmParts {
        film,
        exr,
        ldr: LdrOutput::default(),
    })
}

/// `specfilm` (Mitsuba 3's `specfilm.cpp`): the film of `hdrfilm`, whose EXR holds one channel
/// per `<spectrum>` the film names ([`prism_core::film::spectral_bands`]) beside Y and its
/// statistics.
fn build_specfilm(params: &Params) -> Result<FilmParts> {
    let mut film = film_settings(params)?;
    for property in params.undeclared_spectra() {
        film.bands.push(spectral_band(params, property)?);
    }
    if film.bands.is_empty() {
        return Err(Error::input(
            params.location(),
            "a specfilm needs at least one response: a nested <spectrum name=\"...\">",
        )
        .with_help("add <spectrum name=\"band\" value=\"500:1, 600:1\"/>, one per channel"));
    }
    Ok(FilmParts {
        film,
        exr: ExrOutput {
            pixel_format: PixelFormat::Luminance,
            component_format: params.choice(&COMPONENT_FORMAT)?,
        },
        ldr: LdrOutput::default(),
    })
}

/// One band of a `specfilm`: a channel name that is not one of the image's, and a finite
/// response that is zero outside the 360–830 nm Prism draws wavelengths in.
fn spectral_band(params: &Params, property: &Property) -> Result<SpectralBand> {
    let name = &property.name;
    if IMAGE_CHANNELS.contains(&name.as_str()) || name == ALPHA_CHANNEL {
        return Err(Error::input(
            &property.location,
            format!("the spectral film's channel \"{name}\" would replace the image's own"),
        )
        .with_help(format!(
            "rename the spectrum; the image's channels are {}, {ALPHA_CHANNEL}",
            IMAGE_CHANNELS.join(", ")
        )));
    }
    let response = match &property.value {
        PropertyValue::Spectrum(SpectrumValue::Uniform(v)) if v.is_finite() => {
            Spectrum::Constant(*v as f32)
        }
        PropertyValue::Spectrum(SpectrumValue::Samples(samples))
            if samples.iter().all(|(l, v)| l.is_finite() && v.is_finite()) =>
        {
            let outside = samples.iter().find(|(lambda, value)| {
                *value != 0.0 && !(f64::from(LAMBDA_MIN)..=f64::from(LAMBDA_MAX)).contains(lambda)
            });
            if let Some((lambda, _)) = outside {
                return Err(Error::input(
                    &property.location,
                    format!(
                        "the response \"{name}\" is not zero at {lambda} nm, outside the \
                         {LAMBDA_MIN}–{LAMBDA_MAX} nm Prism draws wavelengths in"
                    ),
                )
                .with_help("Prism's spectra end there: cut the response to that range"));
            }
            let samples: Vec<(f32, f32)> =
                samples.iter().map(|&(l, v)| (l as f32, v as f32)).collect();
            match PiecewiseLinear::new(&samples) {
                Some(table) => Spectrum::PiecewiseLinear(table),
                None => Spectrum::Constant(0.0),
            }
        }
        _ => {
            return Err(Error::input(
                &property.location,
                format!(
                    "the response \"{name}\" of {} must be finite",
                    params.node().describe()
                ),
            ));
        }
    };
    Ok(SpectralBand {
        name: name.clone(),
        response,
    })
}

/// `ldrfilm` (Mitsuba 0.6's `src/films/ldrfilm.cpp`): the film of `hdrfilm`, and how its 8-bit
/// image is tonemapped ([`prism_core::film::ldr`]).
fn build_ldrfilm(params: &Params) -> Result<FilmParts> {
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
    // The film records the coverage that the 8-bit alpha holds.
    let pixel_format = match channels {
        Channels::Rgba | Channels::LuminanceAlpha => PixelFormat::Rgba,
        Channels::Rgb | Channels::Luminance => PixelFormat::Rgb,
    };
    Ok(FilmParts {
        film,
        exr: ExrOutput {
            pixel_format,
            ..ExrOutput::default()
        },
        ldr: LdrOutput {
            tonemap,
            curve,
            format,
            channels,
        },
    })
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
        bands: Vec::new(),
        response: None,
    })
}
