//! Emitters at infinity that surround the scene: `constant`, `envmap`, `equal_area_envmap`
//! (pbrt-v4's image `infinite` light) and `sunsky`.

use super::{Build, D65, SAMPLING_WEIGHT, TO_WORLD, emission_param, invertible};
use crate::factory::spectra::spectrum_param;
use crate::factory::textures::read_image_file;
use crate::params::Params;
use crate::registry::{Bounds, Default, Origin, ParamKind, ParamSpec, Plugin, Range, params};
use glam::Vec3;
use prism_core::error::{Error, Result};
use prism_core::light::sunsky::sun_position::{DateTime, Location, sun_angles};
use prism_core::light::{
    ConstantLight, EnvironmentMap, EqualAreaEnvmap, Light, Sunsky, SunskySettings,
};

pub(super) const CONSTANT: Plugin<Build> = Plugin {
    name: "constant",
    origin: Origin::Mitsuba3,
    summary: "Uniform light from every direction, at infinity.",
    params: &[RADIANCE, SAMPLING_WEIGHT],
    build: |params, _, _| {
        Ok(Light::Constant(ConstantLight::new(emission_param(
            params, &RADIANCE,
        )?)))
    },
};

pub(super) const ENVMAP: Plugin<Build> = Plugin {
    name: "envmap",
    origin: Origin::Mitsuba3,
    summary: "An environment map: a latitude–longitude image with Mitsuba's orientation \
              (+y up, u = 0 looks along −z), pixel-node bilinear lookup and spectral \
              upsampling; importance sampled ∝ luminance · sin θ.",
    params: &[ENVMAP_FILENAME, ENVMAP_SCALE, TO_WORLD, SAMPLING_WEIGHT],
    build: |params, _, _| build_envmap(params),
};

pub(super) const EQUAL_AREA_ENVMAP: Plugin<Build> = Plugin {
    name: "equal_area_envmap",
    origin: Origin::Prism,
    summary: "pbrt-v4's image infinite light: a square image in the equal-area octahedral \
              projection (+z at its centre, +x at the middle of its right edge, +y at the \
              middle of its bottom edge), each direction the colour of the pixel it falls in, \
              upsampled as an illuminant; importance sampled ∝ luminance.",
    params: &[EQUAL_AREA_FILENAME, ENVMAP_SCALE, ROTATION, SAMPLING_WEIGHT],
    build: |params, _, _| build_equal_area_envmap(params),
};

pub(super) const SUNSKY: Plugin<Build> = Plugin {
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
};

params! {
    RADIANCE = ParamSpec::new("radiance", ParamKind::Spectrum { range: Range::Emission, textured: false, }, D65, "emitted radiance; or a nested `<spectrum type=\"blackbody\">`");
    ENVMAP_FILENAME = ParamSpec::new("filename", ParamKind::String, Default::Required, "the image: OpenEXR, Radiance HDR, PFM, PNG, JPEG, BMP, TGA or PPM/PGM, at least 2 × 3 pixels");
    EQUAL_AREA_FILENAME = ParamSpec::new("filename", ParamKind::String, Default::Required, "the square image: OpenEXR, Radiance HDR, PFM, PNG, JPEG, BMP, TGA or PPM/PGM");
    ROTATION = ParamSpec::new("to_world", ParamKind::Transform, Default::Text("identity"), "the map's rotation (or reflection): it must keep lengths and angles");
    ENVMAP_SCALE = ParamSpec::new("scale", ParamKind::Float, Default::Float(1.0), "factor on the image's values");
    SUN_DIRECTION = ParamSpec::new("sun_direction", ParamKind::Vector, Default::Text("from the place and time"), "the sun's direction (world space); not together with the place and time");
    LATITUDE = ParamSpec::new("latitude", ParamKind::Float, Default::Float(35.6894), "degrees north (Tokyo by default)");
    LONGITUDE = ParamSpec::new("longitude", ParamKind::Float, Default::Float(139.6917), "degrees east");
    TIMEZONE = ParamSpec::new("timezone", ParamKind::Float, Default::Float(9.0), "hours ahead of UTC");
    YEAR = ParamSpec::new("year", ParamKind::Integer, Default::Integer(2010), "year");
    MONTH = ParamSpec::new("month", ParamKind::Integer, Default::Integer(7), "month");
    DAY = ParamSpec::new("day", ParamKind::Integer, Default::Integer(10), "day");
    HOUR = ParamSpec::new("hour", ParamKind::Float, Default::Float(15.0), "local hour");
    MINUTE = ParamSpec::new("minute", ParamKind::Float, Default::Float(0.0), "minute");
    SECOND = ParamSpec::new("second", ParamKind::Float, Default::Float(0.0), "second");
    TURBIDITY = ParamSpec::new("turbidity", ParamKind::FloatIn(Bounds::between(1.0, 10.0)), Default::Float(3.0), "haziness of the atmosphere");
    SKY_ALBEDO = ParamSpec::new("albedo", ParamKind::Spectrum { range: Range::Albedo, textured: false, }, Default::Float(0.3), "the ground's albedo, in [0, 1] at every wavelength");
    SUN_SCALE = ParamSpec::new("sun_scale", ParamKind::FloatIn(Bounds::FINITE_NON_NEGATIVE), Default::Float(1.0), "factor on the sun's radiance (0 turns the sun off)");
    SKY_SCALE = ParamSpec::new("sky_scale", ParamKind::FloatIn(Bounds::FINITE_NON_NEGATIVE), Default::Float(1.0), "factor on the sky's radiance (0 turns the sky off)");
    SUN_APERTURE = ParamSpec::new("sun_aperture", ParamKind::FloatIn(Bounds::between(0.0, 180.0)), Default::Float(0.5358), "the sun disc's full angle in degrees, in (0, 180); its irradiance stays that of the real sun");
    COMPLEX_SUN = ParamSpec::new("complex_sun", ParamKind::Boolean, Default::Boolean(false), "the solar radiance function with limb darkening instead of a uniform disc");
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
    let bitmap = read_image_file(&path).map_err(|e| e.at(location))?;
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

/// pbrt-v4's image infinite light.
fn build_equal_area_envmap(params: &Params) -> Result<Light> {
    let node = params.node();
    let Some(filename) = params.string_opt(&EQUAL_AREA_FILENAME)? else {
        return Err(Error::input(
            &node.location,
            format!("{} needs a \"filename\"", node.describe()),
        )
        .with_help("add <string name=\"filename\" value=\"sky.exr\"/>"));
    };
    let location = params.location_of(&EQUAL_AREA_FILENAME);
    let path = node.resolve_file(filename, location)?;
    let bitmap = read_image_file(&path).map_err(|e| e.at(location))?;
    if bitmap.width != bitmap.height {
        return Err(Error::input(
            location,
            format!(
                "the environment map \"{filename}\" has {} × {} pixels; an equal-area map is square",
                bitmap.width, bitmap.height
            ),
        )
        .with_help("a latitude-longitude map (twice as wide as high) is read by \"envmap\""));
    }
    if let Some(index) = bitmap
        .data
        .iter()
        .position(|v| !(*v >= 0.0 && v.is_finite()))
    {
        let pixel = index / bitmap.channels;
        return Err(Error::input(
            location,
            format!(
                "pixel ({}, {}) of the environment map \"{filename}\" is {}",
                pixel % bitmap.width,
                pixel / bitmap.width,
                bitmap.data[index]
            ),
        )
        .with_help("radiance must be finite and at least 0"));
    }
    let scale = params.float(&ENVMAP_SCALE)?;
    if !(scale >= 0.0 && scale.is_finite() && scale <= f64::from(f32::MAX)) {
        return Err(Error::input(
            params.location_of(&ENVMAP_SCALE),
            format!("the environment map's scale must be finite and at least 0, not {scale}"),
        ));
    }
    let matrix = params.transform(&ROTATION)?;
    let linear = glam::DMat3::from_mat4(matrix);
    let gram = linear.transpose() * linear;
    if !gram.abs_diff_eq(glam::DMat3::IDENTITY, 1e-6) {
        return Err(Error::input(
            params.location_of(&ROTATION),
            format!(
                "the \"to_world\" transform of {} stretches directions; an equal-area map is \
                 only rotated (or reflected)",
                node.describe()
            ),
        )
        .with_help("remove the scale from the transform"));
    }
    let to_world = invertible(params, &ROTATION)?;
    Ok(Light::EqualAreaEnvmap(EqualAreaEnvmap::new(
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
