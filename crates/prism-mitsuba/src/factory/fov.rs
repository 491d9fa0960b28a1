//! The field of view of Mitsuba's projective plugins (the `perspective` and `thinlens` cameras,
//! the `projector` emitter): `fov` along `fov_axis`, or a `focal_length` on 35 mm film, read as
//! Mitsuba 3's `parse_fov` reads them, as a horizontal angle for an image of a given aspect.

use crate::params::Params;
use crate::registry::{Choice, Default, ParamKind, ParamSpec, params};
use prism_core::camera::perspective::{FovAxis, focal_length_to_diagonal_fov, horizontal_fov};
use prism_core::error::{Error, Result};

params! {
    pub FOV = ParamSpec::new("fov", ParamKind::Float, Default::Text("from `focal_length`"), "field of view in degrees, along `fov_axis`");
    pub FOV_AXIS = ParamSpec::new("fov_axis", ParamKind::Choice(&[Choice::new("x", &FovAxis::X), Choice::new("y", &FovAxis::Y), Choice::new("diagonal", &FovAxis::Diagonal), Choice::new("smaller", &FovAxis::Smaller), Choice::new("larger", &FovAxis::Larger)]), Default::Str("x"), "the film axis `fov` is measured along");
    pub FOCAL_LENGTH = ParamSpec::new("focal_length", ParamKind::String, Default::Str("50mm"), "the field of view as the focal length of a lens on 35 mm film (diagonal); instead of `fov`");
}
/// The horizontal field of view in degrees, strictly between 0 and 180, of an image of
/// `aspect` = width / height.
pub fn horizontal_fov_param(params: &Params, aspect: f64) -> Result<f64> {
    let fov_x = match (params.float_opt(&FOV)?, params.string_opt(&FOCAL_LENGTH)?) {
        (Some(_), Some(_)) => {
            return Err(Error::input(
                params.location_of(&FOCAL_LENGTH),
                "give either \"fov\" or \"focal_length\", not both",
            ));
        }
        (Some(fov), None) => horizontal_fov(fov, params.choice(&FOV_AXIS)?, aspect),
        (None, focal_length) => {
            let text = focal_length.unwrap_or("50mm");
            let mm: f64 = text
                .trim()
                .trim_end_matches("mm")
                .trim()
                .parse()
                .map_err(|_| {
                    Error::input(
                        params.location_of(&FOCAL_LENGTH),
                        format!("could not read the focal length \"{text}\""),
                    )
                    .with_help("write it as a number of millimetres, e.g. \"35mm\"")
                })?;
            if !(mm > 0.0) {
                return Err(Error::input(
                    params.location_of(&FOCAL_LENGTH),
                    "the focal length must be positive",
                ));
            }
            horizontal_fov(focal_length_to_diagonal_fov(mm), FovAxis::Diagonal, aspect)
        }
    };
    if !(fov_x > 0.0 && fov_x < 180.0) {
        return Err(Error::input(
            params.location_of(&FOV),
            format!(
                "the horizontal field of view is {fov_x} degrees; it must lie strictly between 0 and 180"
            ),
        ));
    }
    Ok(fov_x)
}
