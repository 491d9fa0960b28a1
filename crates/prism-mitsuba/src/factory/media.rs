//! Participating media, their phase functions and volumes: Mitsuba 3's `homogeneous` and
//! `heterogeneous` media, `isotropic`, `hg`, `rayleigh`, `tabphase`, `blendphase` and `sggx`
//! phase functions, and `constvolume`
//! and `gridvolume` volumes (Mitsuba's binary `.vol` files).

use glam::DMat4;

use super::spectra::spectrum_param;
use crate::description::{PluginClass, PluginNode, PropertyValue};
use crate::params::Params;
use crate::registry::{
    Bounds, Choice, Default, Origin, ParamKind, ParamSpec, Plugin, Range, Registry, params,
};
use prism_core::error::{Error, Result};
use prism_core::math::Transform;
use prism_core::medium::volume::{VolFile, parse_vol};
use prism_core::medium::{
    BlendPhase, ConstantInBox, GridFilter, GridVolume, GridWrap, HenyeyGreenstein, Heterogeneous,
    HeterogeneousAbsorbingScattering, Homogeneous, HomogeneousAbsorbingScattering,
    HomogeneousExtinction, Isotropic, Medium, MediumKind, PhaseFunction, Rayleigh, Sggx,
    SpectralGridVolume, TabulatedPhase, Volume,
};
use prism_core::spectrum::Spectrum;

type BuildMedium = fn(&Params) -> Result<Medium>;
type BuildPhase = fn(&Params) -> Result<PhaseFunction>;
type BuildVolume = fn(&Params, Range) -> Result<Volume>;

pub static MEDIA: Registry<BuildMedium> = Registry {
    class: PluginClass::Medium,
    plugins: &[
        Plugin {
            name: "homogeneous",
            origin: Origin::Mitsuba3,
            summary: "The same extinction σ_t = scale · sigma_t everywhere, with an albedo \
                      that is a value or, as in Mitsuba 3, a volume (so that only the \
                      scattering varies); or, in Mitsuba 0.6's form, σ_a = scale · sigma_a and \
                      σ_s = scale · sigma_s (which Mitsuba 3 refuses). A shape takes it as its \
                      `interior` or `exterior`, the sensor as the medium it sits in.",
            params: &[
                SIGMA_T,
                ALBEDO_VOLUME,
                SIGMA_A,
                SIGMA_S,
                SCALE,
                SAMPLE_EMITTERS,
                PHASE,
            ],
            build: build_homogeneous,
        },
        Plugin {
            name: "heterogeneous",
            origin: Origin::Mitsuba3,
            summary: "σ_t(x) = scale · sigma_t(x) and albedo(x) from volumes (a `gridvolume` is \
                      empty outside its box); or, in Prism's form of pbrt-v4's grid media, \
                      σ_a(x) = scale · density(x) · sigma_a and σ_s(x) = scale · density(x) · \
                      sigma_s with `sigma_a` and `sigma_s` colours or spectra (which Mitsuba 3 \
                      does not read). Free flights by spectral tracking with the grid's maximum \
                      (times the largest σ_a + σ_s of the path's wavelengths) as majorant, \
                      shadow rays by ratio tracking.",
            params: &[
                SIGMA_T_VOLUME,
                ALBEDO_VOLUME,
                DENSITY,
                GRID_SIGMA_A,
                GRID_SIGMA_S,
                SCALE,
                SAMPLE_EMITTERS,
                PHASE,
            ],
            build: build_heterogeneous,
        },
    ],
};

pub static PHASES: Registry<BuildPhase> = Registry {
    class: PluginClass::Phase,
    plugins: &[
        Plugin {
            name: "isotropic",
            origin: Origin::Mitsuba3,
            summary: "Scattering into every direction alike, p = 1/(4π).",
            params: &[],
            build: |_| Ok(PhaseFunction::Isotropic(Isotropic)),
        },
        Plugin {
            name: "hg",
            origin: Origin::Mitsuba3,
            summary: "Henyey–Greenstein, p = (1 − g²)/(4π (1 + g² − 2g cos θ)^{3/2}) with θ the \
                      deflection; sampled exactly.",
            params: &[G],
            build: build_hg,
        },
        Plugin {
            name: "rayleigh",
            origin: Origin::Mitsuba3,
            summary: "Rayleigh scattering by small particles, p = 3 (1 + cos²θ)/(16π); sampled \
                      exactly.",
            params: &[],
            build: |_| Ok(PhaseFunction::Rayleigh(Rayleigh)),
        },
        Plugin {
            name: "tabphase",
            origin: Origin::Mitsuba3,
            summary: "Tabulated over the cosine of the scattering angle (1 = forward), values at \
                      equal steps from −1 to 1, interpolated linearly and normalised; sampled \
                      exactly.",
            params: &[PHASE_VALUES],
            build: build_tabphase,
        },
        Plugin {
            name: "blendphase",
            origin: Origin::Mitsuba3,
            summary: "(1 − weight) · p₀ + weight · p₁ of two nested phase functions.",
            params: &[PHASE_WEIGHT, BLENDED_PHASES],
            build: build_blendphase,
        },
        Plugin {
            name: "sggx",
            origin: Origin::Mitsuba3,
            summary: "The SGGX microflake phase function (Heitz et al. 2015): specular flakes \
                      with the normals of an ellipsoid given by a positive-definite matrix S, \
                      which also scales the medium's coefficients by the flakes' projected area \
                      √(ωᵀSω) along the direction of travel; sampled by visible normals.",
            params: &[SGGX_S],
            build: build_sggx,
        },
    ],
};

pub static VOLUMES: Registry<BuildVolume> = Registry {
    class: PluginClass::Volume,
    plugins: &[
        Plugin {
            name: "constvolume",
            origin: Origin::Mitsuba3,
            summary: "The same value everywhere. As a `heterogeneous` medium's `sigma_t`, it \
                      also bounds the medium, as in Mitsuba 3: the medium is empty outside the \
                      axis-aligned box around the unit cube placed by `to_world` (a plain \
                      `sigma_t` value is the unit cube's).",
            params: &[VALUE, VOLUME_TO_WORLD],
            build: build_constvolume,
        },
        Plugin {
            name: "gridvolume",
            origin: Origin::Mitsuba3,
            summary: "A grid from a Mitsuba `.vol` file (32-bit floats) over the unit cube placed \
                      by `to_world`, interpolated trilinearly between voxel centres, clamped, \
                      repeated or mirrored outside. One channel gives a number; three give a \
                      colour, upsampled to a spectrum per voxel as Mitsuba 3's spectral \
                      variants do (2·max(rgb) times the spectrum of rgb/(2·max(rgb)); the \
                      spectra and the scales are interpolated separately and multiplied).",
            params: &[
                FILENAME,
                FILTER_TYPE,
                WRAP_MODE,
                VOLUME_TO_WORLD,
                USE_GRID_BBOX,
            ],
            build: build_gridvolume,
        },
        super::inline_grid::INLINE_GRID,
    ],
};

params! {
    SIGMA_T = ParamSpec::new("sigma_t", ParamKind::Spectrum { range: Range::Coefficient, textured: false, }, Default::Float(1.0), "extinction coefficient per scene unit");
    SIGMA_A = ParamSpec::new("sigma_a", ParamKind::Spectrum { range: Range::Coefficient, textured: false, }, Default::None, "Mitsuba 0.6: absorption coefficient, with `sigma_s` in place of `sigma_t` and `albedo`");
    SIGMA_S = ParamSpec::new("sigma_s", ParamKind::Spectrum { range: Range::Coefficient, textured: false, }, Default::None, "Mitsuba 0.6: scattering coefficient, with `sigma_a`");
    SIGMA_T_VOLUME = ParamSpec::new("sigma_t", ParamKind::Volume(Range::Coefficient), Default::Float(1.0), "extinction coefficient per scene unit; the medium is empty outside its box (a plain value's is the unit cube, as in Mitsuba 3)");
    DENSITY = ParamSpec::new("density", ParamKind::Volume(Range::Coefficient), Default::None, "Prism: the density d(x), with `sigma_a` and `sigma_s` in place of `sigma_t` and `albedo`; the medium is empty outside its box (a plain value's is the unit cube)");
    GRID_SIGMA_A = ParamSpec::new("sigma_a", ParamKind::Spectrum { range: Range::Coefficient, textured: false, }, Default::None, "Prism, with `density`: the absorption coefficient per unit density");
    GRID_SIGMA_S = ParamSpec::new("sigma_s", ParamKind::Spectrum { range: Range::Coefficient, textured: false, }, Default::None, "Prism, with `density`: the scattering coefficient per unit density");
    ALBEDO_VOLUME = ParamSpec::new("albedo", ParamKind::Volume(Range::Albedo), Default::Float(0.75), "single-scattering albedo σ_s/σ_t, in [0, 1]");
    SCALE = ParamSpec::new("scale", ParamKind::Float, Default::Float(1.0), "factor on the coefficients (a change of units)");
    SAMPLE_EMITTERS = ParamSpec::new("sample_emitters", ParamKind::Boolean, Default::Boolean(true), "sample lights at scattering points in the medium (next-event estimation)");
    PHASE = ParamSpec::nested(PluginClass::Phase, Default::Text("`isotropic`"), "the phase function");
    G = ParamSpec::new("g", ParamKind::Float, Default::Float(0.8), "mean cosine of the deflection, in (−1, 1): > 0 forward, < 0 backward");
    PHASE_VALUES = ParamSpec::new("values", ParamKind::String, Default::Required, "the phase function's values at equally spaced cosines from −1 to 1, separated by commas or spaces (at least two, not negative, not all zero)");
    PHASE_WEIGHT = ParamSpec::new("weight", ParamKind::FloatIn(Bounds::UNIT), Default::Float(0.5), "weight of the second phase function");
    SGGX_S = ParamSpec::new("S", ParamKind::Volume(Range::Coefficient), Default::Required, "a `gridvolume` of six channels, S_xx, S_yy, S_zz, S_xy, S_xz, S_yz, the same in every voxel (Prism reads one matrix per medium; a grid of one voxel, as Mitsuba's tests write it)");
    BLENDED_PHASES = ParamSpec::nested(PluginClass::Phase, Default::Required, "the two phase functions");
    VALUE = ParamSpec::new("value", ParamKind::Spectrum { range: Range::Coefficient, textured: false, }, Default::Float(1.0), "the value");
    FILENAME = ParamSpec::new("filename", ParamKind::String, Default::Required, "the `.vol` file");
    FILTER_TYPE = ParamSpec::new("filter_type", ParamKind::Choice(&[Choice::new("trilinear", &GridFilter::Trilinear), Choice::new("bilinear", &GridFilter::Trilinear), Choice::new("nearest", &GridFilter::Nearest)]), Default::Str("trilinear"), "interpolation between voxels: `trilinear` (Mitsuba 3's name; `bilinear` is read the same) or `nearest`");
    WRAP_MODE = ParamSpec::new("wrap_mode", ParamKind::Choice(&[Choice::new("clamp", &GridWrap::Clamp), Choice::new("repeat", &GridWrap::Repeat), Choice::new("mirror", &GridWrap::Mirror)]), Default::Str("clamp"), "lookups outside the unit cube: `clamp` (the border voxels extend), `repeat` (the grid tiles space) or `mirror` (tiles, every other one mirrored)");
    VOLUME_TO_WORLD = ParamSpec::new("to_world", ParamKind::Transform, Default::Text("identity"), "from the unit cube [0, 1]³ to the world");
    USE_GRID_BBOX = ParamSpec::new("use_grid_bbox", ParamKind::Boolean, Default::Boolean(false), "place the grid in the box its file gives (then transformed by `to_world`)");
}

/// Builds the medium a `<medium>` node describes.
pub fn build_medium(node: &PluginNode) -> Result<Medium> {
    let plugin = MEDIA.find(node)?;
    let params = Params::new(node, plugin.params);
    let medium = (plugin.build)(&params)?;
    params.finish()?;
    Ok(medium)
}

fn build_phase(node: &PluginNode) -> Result<PhaseFunction> {
    let plugin = PHASES.find(node)?;
    let params = Params::new(node, plugin.params);
    let phase = (plugin.build)(&params)?;
    params.finish()?;
    Ok(phase)
}

/// The nested phase function, isotropic when absent.
fn phase(params: &Params) -> Result<PhaseFunction> {
    match params.single_child(&PHASE)? {
        Some(child) => build_phase(&child.node),
        None => Ok(PhaseFunction::Isotropic(Isotropic)),
    }
}

/// `scale`: finite and at least 0.
fn scale(params: &Params) -> Result<f32> {
    let scale = params.float(&SCALE)?;
    if !(scale >= 0.0 && scale.is_finite()) {
        return Err(Error::input(
            params.location_of(&SCALE),
            format!("scale must be a finite number of at least 0, not {scale}"),
        ));
    }
    Ok(scale as f32)
}

/// An albedo above 1 would scatter more light than the medium removes; Mitsuba refuses RGB
/// albedos above 1 too.
fn check_albedo(params: &Params, spec: &ParamSpec, max: f32) -> Result<()> {
    if max > 1.0 {
        return Err(Error::input(
            params.location_of(spec),
            format!(
                "the albedo of {} reaches {max}, above 1: the medium would scatter more light than it removes",
                params.node().describe()
            ),
        )
        .with_help("use values between 0 and 1"));
    }
    Ok(())
}

/// The largest value of an `<rgb>` property, which the spectrum's upsampling may round.
fn given_max(params: &Params, spec: &ParamSpec, spectrum: &Spectrum) -> f32 {
    match params.property(spec).map(|p| &p.value) {
        Some(PropertyValue::Rgb(rgb)) => rgb.iter().copied().fold(0.0, f64::max) as f32,
        _ => spectrum.max_value(),
    }
}

fn build_homogeneous(params: &Params) -> Result<Medium> {
    let scale = scale(params)?;
    let kind = if params.has(&SIGMA_A) || params.has(&SIGMA_S) {
        for spec in [&SIGMA_T, &ALBEDO_VOLUME] {
            if params.has(spec) {
                return Err(Error::input(
                    params.location_of(spec),
                    format!(
                        "{} is given both sigma_a/sigma_s and \"{}\"",
                        params.node().describe(),
                        spec.name
                    ),
                )
                .with_help("give either sigma_t and albedo (Mitsuba 3) or sigma_a and sigma_s"));
            }
        }
        for (spec, other) in [(&SIGMA_A, &SIGMA_S), (&SIGMA_S, &SIGMA_A)] {
            if !params.has(spec) {
                return Err(Error::input(
                    params.location_of(other),
                    format!(
                        "{} gives \"{}\" without \"{}\"",
                        params.node().describe(),
                        other.name,
                        spec.name
                    ),
                )
                .with_help("give both sigma_a and sigma_s, or sigma_t and albedo"));
            }
        }
        MediumKind::HomogeneousAbsorbingScattering(HomogeneousAbsorbingScattering {
            sigma_a: spectrum_param(params, &SIGMA_A)?,
            sigma_s: spectrum_param(params, &SIGMA_S)?,
            scale,
        })
    } else {
        let sigma_t = spectrum_param(params, &SIGMA_T)?;
        match volume_param(params, &ALBEDO_VOLUME)? {
            Volume::Constant(albedo) => MediumKind::Homogeneous(Homogeneous {
                sigma_t,
                albedo,
                scale,
            }),
            Volume::ConstantInBox(constant) => MediumKind::Homogeneous(Homogeneous {
                sigma_t,
                albedo: constant.value,
                scale,
            }),
            albedo => MediumKind::HomogeneousExtinction(HomogeneousExtinction {
                sigma_t,
                albedo,
                scale,
            }),
        }
    };
    Ok(Medium {
        kind,
        phase: phase(params)?,
        sample_emitters: params.boolean(&SAMPLE_EMITTERS)?,
    })
}

/// A volume parameter: a nested `<volume name="...">` or a plain value.
pub(super) fn volume_param(params: &Params, spec: &ParamSpec) -> Result<Volume> {
    let ParamKind::Volume(range) = spec.kind else {
        panic!("\"{}\" is not a volume", spec.name);
    };
    if let Some(child) = params.named_child(spec) {
        if child.node.class != PluginClass::Volume {
            return Err(Error::input(
                &child.location,
                format!(
                    "parameter \"{}\" of {} takes a <volume>, not a {}",
                    spec.name,
                    params.node().describe(),
                    child.node.describe()
                ),
            )
            .with_help("give a <volume type=\"gridvolume\"> or a plain value"));
        }
        let plugin = VOLUMES.find(&child.node)?;
        let volume_params = Params::new(&child.node, plugin.params);
        let volume = (plugin.build)(&volume_params, range)?;
        volume_params.finish()?;
        return Ok(volume);
    }
    let spectrum = spectrum_param(params, spec)?;
    if range == Range::Albedo {
        check_albedo(params, spec, given_max(params, spec, &spectrum))?;
    }
    Ok(Volume::Constant(spectrum))
}

/// A volume that bounds a heterogeneous medium: Mitsuba reads a plain value as a `constvolume`
/// over the unit cube, outside which the medium is empty.
fn bounding_volume(params: &Params, spec: &ParamSpec) -> Result<Volume> {
    Ok(match volume_param(params, spec)? {
        Volume::Constant(value) => {
            Volume::ConstantInBox(Box::new(ConstantInBox::new(value, &Transform::IDENTITY)))
        }
        volume => volume,
    })
}

fn build_heterogeneous(params: &Params) -> Result<Medium> {
    let node = params.node();
    let pbrt_form = [&DENSITY, &GRID_SIGMA_A, &GRID_SIGMA_S];
    let kind = if pbrt_form.iter().any(|spec| params.has(spec)) {
        for spec in [&SIGMA_T_VOLUME, &ALBEDO_VOLUME] {
            if params.has(spec) {
                return Err(Error::input(
                    params.location_of(spec),
                    format!(
                        "{} is given both density/sigma_a/sigma_s and \"{}\"",
                        node.describe(),
                        spec.name
                    ),
                )
                .with_help(
                    "give either sigma_t and albedo (Mitsuba 3) or density, sigma_a and sigma_s",
                ));
            }
        }
        if let Some(missing) = pbrt_form.iter().find(|spec| !params.has(spec)) {
            return Err(Error::input(
                params.location(),
                format!(
                    "{} gives density, sigma_a or sigma_s without \"{}\"",
                    node.describe(),
                    missing.name
                ),
            )
            .with_help("give all three, or sigma_t and albedo"));
        }
        MediumKind::HeterogeneousAbsorbingScattering(HeterogeneousAbsorbingScattering {
            density: bounding_volume(params, &DENSITY)?,
            sigma_a: spectrum_param(params, &GRID_SIGMA_A)?,
            sigma_s: spectrum_param(params, &GRID_SIGMA_S)?,
            scale: scale(params)?,
        })
    } else {
        MediumKind::Heterogeneous(Heterogeneous {
            sigma_t: bounding_volume(params, &SIGMA_T_VOLUME)?,
            albedo: volume_param(params, &ALBEDO_VOLUME)?,
            scale: scale(params)?,
        })
    };
    Ok(Medium {
        kind,
        phase: phase(params)?,
        sample_emitters: params.boolean(&SAMPLE_EMITTERS)?,
    })
}

fn build_hg(params: &Params) -> Result<PhaseFunction> {
    let g = params.float(&G)?;
    if !(g > -1.0 && g < 1.0) {
        return Err(Error::input(
            params.location_of(&G),
            format!("the asymmetry g of an hg phase function must lie in (-1, 1), not {g}"),
        )
        .with_help("g = 0 is isotropic; values near ±1 scatter almost straight on or back"));
    }
    Ok(PhaseFunction::HenyeyGreenstein(HenyeyGreenstein {
        g: g as f32,
    }))
}

fn build_tabphase(params: &Params) -> Result<PhaseFunction> {
    let node = params.node();
    let text = params.string_opt(&PHASE_VALUES)?.ok_or_else(|| {
        Error::input(
            &node.location,
            format!("{} needs its \"values\"", node.describe()),
        )
        .with_help("add <string name=\"values\" value=\"0.5, 1, 2\"/>: the phase function at equally spaced cosines from -1 to 1")
    })?;
    let location = params.location_of(&PHASE_VALUES);
    let mut values = Vec::new();
    for item in text
        .split([',', ' '])
        .filter(|item| !item.trim().is_empty())
    {
        let value: f32 = item.trim().parse().map_err(|_| {
            Error::input(
                location,
                format!("the tabphase value \"{}\" is not a number", item.trim()),
            )
        })?;
        values.push(value);
    }
    TabulatedPhase::new(&values)
        .map(PhaseFunction::Tabulated)
        .ok_or_else(|| {
            Error::input(
                location,
                format!(
                    "a tabphase needs at least two finite values, none negative and not all zero; \
                     {} were given",
                    values.len()
                ),
            )
            .with_help("list the phase function at equally spaced cosines from -1 to 1, such as \"0.5, 1, 2\"")
        })
}

fn build_blendphase(params: &Params) -> Result<PhaseFunction> {
    let weight = params.float_in(&PHASE_WEIGHT)? as f32;
    let children = params.children(&BLENDED_PHASES);
    let [first, second] = children.as_slice() else {
        return Err(Error::input(
            params.location(),
            format!(
                "{} needs exactly two nested phase functions, but {} were given",
                params.node().describe(),
                children.len()
            ),
        )
        .with_help("nest two <phase> elements"));
    };
    Ok(PhaseFunction::Blend(BlendPhase {
        weight,
        first: Box::new(build_phase(&first.node)?),
        second: Box::new(build_phase(&second.node)?),
    }))
}

fn build_constvolume(params: &Params, range: Range) -> Result<Volume> {
    let value = spectrum_param(params, &VALUE)?;
    if range == Range::Albedo {
        check_albedo(params, &VALUE, given_max(params, &VALUE, &value))?;
    }
    let to_world = Transform::new(params.transform(&VOLUME_TO_WORLD)?).ok_or_else(|| {
        Error::input(
            params.location_of(&VOLUME_TO_WORLD),
            format!(
                "{} is placed by a singular transform",
                params.node().describe()
            ),
        )
        .with_help("give to_world a non-zero scale on every axis")
    })?;
    Ok(Volume::ConstantInBox(Box::new(ConstantInBox::new(
        value, &to_world,
    ))))
}

/// The `.vol` file a `gridvolume`'s `filename` names, read and parsed.
fn read_grid(params: &Params) -> Result<(VolFile, std::path::PathBuf)> {
    let node = params.node();
    let filename = params.string_opt(&FILENAME)?.ok_or_else(|| {
        Error::input(
            &node.location,
            format!("{} needs a \"filename\"", node.describe()),
        )
        .with_help("add <string name=\"filename\" value=\"density.vol\"/>")
    })?;
    let location = params.location_of(&FILENAME);
    let path = node.resolve_file(filename, location)?;
    let bytes = crate::file_cache::read(&path).map_err(|e| {
        Error::input(
            location,
            format!("cannot read the grid \"{}\": {e}", path.display()),
        )
    })?;
    let file = parse_vol(&bytes).map_err(|message| {
        Error::input(
            location,
            format!("the grid \"{}\" is unreadable: {message}", path.display()),
        )
        .with_help("write the grid in Mitsuba's .vol format (version 3, 32-bit floats)")
    })?;
    Ok((file, path))
}

fn build_gridvolume(params: &Params, range: Range) -> Result<Volume> {
    let node = params.node();
    let (file, path) = read_grid(params)?;
    let location = params.location_of(&FILENAME);
    if file.channels != 1 && file.channels != 3 {
        return Err(Error::input(
            location,
            format!(
                "the grid \"{}\" has {} channels; a gridvolume holds one (a number) or three (a colour)",
                path.display(),
                file.channels
            ),
        )
        .with_help("store a density or a scalar albedo in one channel, an RGB colour in three"));
    }
    if let Some(bad) = file.data.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
        return Err(Error::input(
            location,
            format!(
                "the grid \"{}\" holds the value {bad}: coefficients must be finite and at least 0",
                path.display()
            ),
        ));
    }
    let mut to_world = params.transform(&VOLUME_TO_WORLD)?;
    if params.boolean(&USE_GRID_BBOX)? {
        let min = file.bbox_min.as_dvec3();
        let extent = (file.bbox_max - file.bbox_min).as_dvec3();
        to_world *= DMat4::from_translation(min) * DMat4::from_scale(extent);
    }
    let singular = || {
        Error::input(
            params.location_of(&VOLUME_TO_WORLD),
            format!(
                "the grid of {} is placed by a singular transform",
                node.describe()
            ),
        )
        .with_help("check to_world (and the grid's bounding box with use_grid_bbox)")
    };
    let to_world = Transform::new(to_world).ok_or_else(singular)?;
    let filter = params.choice(&FILTER_TYPE)?;
    let wrap = params.choice(&WRAP_MODE)?;
    let (volume, largest) = if file.channels == 3 {
        let grid = SpectralGridVolume::new(file.resolution, &file.data, to_world, filter)
            .expect("a parsed grid holds its voxels")
            .with_wrap(wrap);
        let largest = grid.max_component();
        (Volume::SpectralGrid(Box::new(grid)), largest)
    } else {
        let grid = GridVolume::new(file.resolution, file.data, to_world, filter)
            .expect("a parsed grid holds its voxels")
            .with_wrap(wrap);
        let largest = grid.max_value();
        (Volume::Grid(Box::new(grid)), largest)
    };
    if range == Range::Albedo && largest > 1.0 {
        return Err(Error::input(
            location,
            format!(
                "the albedo grid \"{}\" reaches {largest}, above 1: the medium would scatter more light than it removes",
                path.display(),
            ),
        )
        .with_help("use values between 0 and 1"));
    }
    Ok(volume)
}

/// Mitsuba's `sggx`: S from a six-channel `gridvolume` whose voxels all hold the same matrix.
fn build_sggx(params: &Params) -> Result<PhaseFunction> {
    let node = params.node();
    let needs = || {
        "give S as <volume type=\"gridvolume\" name=\"S\"> with a .vol file of six channels \
         (S_xx, S_yy, S_zz, S_xy, S_xz, S_yz)"
    };
    let Some(child) = params.named_child(&SGGX_S) else {
        return Err(Error::input(
            &node.location,
            format!("{} needs its matrix \"S\"", node.describe()),
        )
        .with_help(needs()));
    };
    if child.node.class != PluginClass::Volume || child.node.plugin_type != "gridvolume" {
        return Err(Error::input(
            &child.location,
            format!(
                "\"S\" of {} is {}, not a gridvolume",
                node.describe(),
                child.node.describe()
            ),
        )
        .with_help(needs()));
    }
    let grid = Params::new(
        &child.node,
        &[
            FILENAME,
            FILTER_TYPE,
            WRAP_MODE,
            VOLUME_TO_WORLD,
            USE_GRID_BBOX,
        ],
    );
    let (file, path) = read_grid(&grid)?;
    // The placement and filtering of a grid that holds one value everywhere change nothing.
    grid.choice::<GridFilter>(&FILTER_TYPE)?;
    grid.choice::<GridWrap>(&WRAP_MODE)?;
    grid.transform(&VOLUME_TO_WORLD)?;
    grid.boolean(&USE_GRID_BBOX)?;
    let location = grid.location_of(&FILENAME);
    if file.channels != 6 {
        return Err(Error::input(
            location,
            format!(
                "the grid \"{}\" has {} channel(s); the SGGX matrix needs six",
                path.display(),
                file.channels
            ),
        )
        .with_help(needs()));
    }
    let mut voxels = file.data.chunks_exact(6);
    let first: [f32; 6] = voxels
        .next()
        .expect("a parsed grid holds a voxel")
        .try_into()
        .expect("six channels");
    if voxels.any(|voxel| voxel != first) {
        return Err(Error::input(
            location,
            format!(
                "the SGGX matrix in \"{}\" varies from voxel to voxel; Prism reads one matrix per medium",
                path.display()
            ),
        )
        .with_help("store the matrix in a grid of one voxel"));
    }
    let sggx = Sggx::new(first).ok_or_else(|| {
        Error::input(
            location,
            format!(
                "the SGGX matrix {first:?} in \"{}\" is not positive definite",
                path.display()
            ),
        )
        .with_help("S_xx, S_yy, S_zz, S_xy, S_xz, S_yz must form a symmetric positive-definite matrix, such as 1, 1, 1, 0, 0, 0")
    })?;
    grid.finish()?;
    Ok(PhaseFunction::Sggx(sggx))
}
