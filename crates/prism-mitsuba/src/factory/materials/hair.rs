//! Mitsuba 3's `hair`: Chiang et al.'s fibre model, coloured by melanin concentrations or by an
//! absorption coefficient.

use super::Build;
use super::ior::{EXT_IOR, relative_ior};
use crate::factory::textures::{TextureCache, float_value, spectrum_texture};
use crate::params::Params;
use crate::registry::{Bounds, Default, Origin, ParamKind, ParamSpec, Plugin, Range, params};
use prism_core::bsdf::{Bsdf, Hair, HairAbsorption, HairLobeShapes};
use prism_core::error::{Error, Result};
use prism_core::spectrum::ior::{Ior, RelativeIor};

pub(super) const HAIR: Plugin<Build> = Plugin {
    name: "hair",
    origin: Origin::Mitsuba3,
    summary: "A hair or fur fibre (Chiang et al. 2016): reflection, transmission and internal \
              reflections, coloured by melanin or an absorption coefficient, as Mitsuba 3. \
              Meant for the curve shapes, whose frame runs along the fibre.",
    params: &[
        EUMELANIN,
        PHEOMELANIN,
        SIGMA_A,
        SCALE,
        HAIR_INT_IOR,
        EXT_IOR,
        LONGITUDINAL_ROUGHNESS,
        AZIMUTHAL_ROUGHNESS,
        SCALE_TILT,
    ],
    build: build_hair,
};

/// Roughness in (0, 1]: 0 would make the lobes Dirac deltas, which the model cannot sample.
const ROUGHNESS: Bounds = Bounds {
    min: 0.0,
    min_exclusive: true,
    max: 1.0,
};

params! {
    EUMELANIN = ParamSpec::new("eumelanin", ParamKind::FloatIn(Bounds::FINITE_NON_NEGATIVE), Default::Float(1.3), "concentration of eumelanin (brown to black)");
    PHEOMELANIN = ParamSpec::new("pheomelanin", ParamKind::FloatIn(Bounds::FINITE_NON_NEGATIVE), Default::Float(0.2), "concentration of pheomelanin (red to blond)");
    SIGMA_A = ParamSpec::new("sigma_a", ParamKind::Spectrum { range: Range::IndexPart, textured: true }, Default::Text("from the melanins"), "absorption coefficient per unit of the fibre's radius, instead of the melanins (an `<rgb>` has its components clamped to [0, 1] before upsampling, as Mitsuba 3's spectral variants read it)");
    SCALE = ParamSpec::new("scale", ParamKind::FloatIn(Bounds::FINITE_NON_NEGATIVE), Default::Float(1.0), "a factor on `sigma_a`");
    HAIR_INT_IOR = ParamSpec::new("int_ior", ParamKind::Ior, Default::Str("amber"), "index of refraction of the fibre: a number or a name");
    LONGITUDINAL_ROUGHNESS = ParamSpec::new("longitudinal_roughness", ParamKind::FloatIn(ROUGHNESS), Default::Float(0.3), "roughness β_m along the fibre, in (0, 1]");
    AZIMUTHAL_ROUGHNESS = ParamSpec::new("azimuthal_roughness", ParamKind::FloatIn(ROUGHNESS), Default::Float(0.3), "roughness β_n around the fibre, in (0, 1]");
    SCALE_TILT = ParamSpec::new("scale_tilt", ParamKind::FloatIn(Bounds::between(-90.0, 90.0)), Default::Float(2.0), "tilt α of the cuticle's scales, in degrees");
}

fn build_hair(params: &Params, t: &mut TextureCache) -> Result<Bsdf> {
    let absorption = if params.has(&SIGMA_A) {
        if let Some(pigment) = [&EUMELANIN, &PHEOMELANIN]
            .into_iter()
            .find(|p| params.has(p))
        {
            return Err(Error::input(
                params.location_of(pigment),
                format!(
                    "{} is given both \"sigma_a\" and \"{}\"",
                    params.node().describe(),
                    pigment.name
                ),
            )
            .with_help("colour the fibre either by its melanins or by sigma_a, as Mitsuba 3"));
        }
        HairAbsorption::Coefficient {
            sigma_a: spectrum_texture(params, &SIGMA_A, t)?,
            scale: float_value(params, &SCALE, Bounds::FINITE_NON_NEGATIVE)?,
        }
    } else {
        HairAbsorption::Pigments {
            eumelanin: float_value(params, &EUMELANIN, Bounds::FINITE_NON_NEGATIVE)?,
            pheomelanin: float_value(params, &PHEOMELANIN, Bounds::FINITE_NON_NEGATIVE)?,
        }
    };
    let eta = match relative_ior(params, &HAIR_INT_IOR, true)? {
        RelativeIor {
            interior: Ior::Constant(interior),
            exterior: Ior::Constant(exterior),
        } => interior / exterior,
        _ => {
            return Err(Error::input(
                params.location_of(&HAIR_INT_IOR),
                format!(
                    "{} takes a constant index of refraction",
                    params.node().describe()
                ),
            )
            .with_help("give a number or a name"));
        }
    };
    Ok(Bsdf::Hair(Hair {
        absorption,
        eta,
        lobes: HairLobeShapes::new(
            float_value(params, &LONGITUDINAL_ROUGHNESS, ROUGHNESS)?,
            float_value(params, &AZIMUTHAL_ROUGHNESS, ROUGHNESS)?,
            float_value(params, &SCALE_TILT, Bounds::between(-90.0, 90.0))?,
        ),
    }))
}
