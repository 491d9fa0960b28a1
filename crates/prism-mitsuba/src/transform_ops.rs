//! The operations inside a `<transform>` element, as Mitsuba 3 defines them
//! (`parse_transform_node` in `src/core/parser.cpp`, `Transform::look_at` in
//! `include/mitsuba/core/transform.h`).
//!
//! The reader composes them in document order, each new operation on the left (`M = op * M`), so
//! `<scale value="2"/><translate x="1"/>` scales first and then translates. All matrices act on
//! column vectors.
//!
//! Where Mitsuba is silent we decide:
//! - a zero rotation axis is an error (Mitsuba 3.7 does the same);
//! - a scale by 0 is accepted, as in Mitsuba (it flattens a shape); a consumer that needs the
//!   inverse must check it;
//! - `<lookat>` with coinciding origin and target, or with `up` parallel to the viewing direction,
//!   is an error (Mitsuba reports "invalid lookat transformation" when its matrix has NaNs).

use glam::{DMat3, DMat4, DVec3};

use super::element::{Attribute, Element};
use crate::suggest::closest_match;
use prism_core::error::{Error, Result};

/// The transform operation tags.
pub(super) const OPERATIONS: [&str; 5] = ["translate", "rotate", "scale", "matrix", "lookat"];

/// The matrix of one operation element.
pub(super) fn operation_matrix(element: &Element) -> Result<DMat4> {
    match element.tag.as_str() {
        "translate" => {
            element.check_attributes(&["x", "y", "z", "value"])?;
            require_some_attribute(element)?;
            Ok(translation(element.xyz(0.0)?))
        }
        "scale" => {
            element.check_attributes(&["x", "y", "z", "value"])?;
            require_some_attribute(element)?;
            Ok(scaling(element.xyz(1.0)?))
        }
        "rotate" => rotate(element),
        "matrix" => matrix(element),
        "lookat" => look_at_element(element),
        _ => {
            let mut help = format!(
                "a <transform> contains only the operations <{}>",
                OPERATIONS.join(">, <")
            );
            if let Some(close) = closest_match(&element.tag, &OPERATIONS) {
                help = format!("did you mean <{close}>? {help}");
            }
            Err(Error::input(
                &element.location,
                format!("unexpected <{}> inside a <transform>", element.tag),
            )
            .with_help(help))
        }
    }
}

/// The translation by `offset`.
pub(crate) fn translation(offset: DVec3) -> DMat4 {
    DMat4::from_translation(offset)
}

/// The scaling by `factors` along x, y and z.
pub(crate) fn scaling(factors: DVec3) -> DMat4 {
    DMat4::from_diagonal(factors.extend(1.0))
}

/// `<translate/>` and `<scale/>` without attributes are errors in Mitsuba (a likely slip).
fn require_some_attribute(element: &Element) -> Result<()> {
    if element.attributes.is_empty() {
        return Err(Error::input(
            &element.location,
            format!("<{}> has no x, y, z or value attribute", element.tag),
        )
        .with_help(format!(
            "write for example <{} value=\"1, 2, 3\"/>",
            element.tag
        )));
    }
    Ok(())
}

/// `<rotate x="0" y="0" z="1" angle="90"/>` (or `value="0, 0, 1"`): a right-handed rotation by
/// `angle` degrees about the normalized axis; missing axis components are 0.
fn rotate(element: &Element) -> Result<DMat4> {
    element.check_attributes(&["angle", "x", "y", "z", "value"])?;
    let angle = element.number(element.require("angle")?)?;
    let axis = element.xyz(0.0)?;
    rotation(axis, angle).map_err(|problem| {
        Error::input(&element.location, format!("<rotate> has {problem}"))
            .with_help("give the axis with x, y, z (for example z=\"1\") or value=\"0, 0, 1\"")
    })
}

/// The right-handed rotation by `angle` degrees about the normalized `axis`; a zero axis, or
/// one that cannot be normalized, is an error (named as "a zero rotation axis", ...).
pub(crate) fn rotation(axis: DVec3, angle: f64) -> Result<DMat4, &'static str> {
    if axis == DVec3::ZERO {
        return Err("a zero rotation axis");
    }
    let unit = axis.normalize();
    if !unit.is_finite() {
        return Err("an axis too large or too small to normalize");
    }
    Ok(DMat4::from_axis_angle(unit, angle.to_radians()))
}

/// `<matrix value="..."/>`: 16 numbers in row-major order, or 9 for the linear 3x3 part (the
/// rest is taken from the identity).
fn matrix(element: &Element) -> Result<DMat4> {
    element.check_attributes(&["value"])?;
    let value = element.require("value")?;
    let numbers = element.number_list(value)?;
    if let Ok(rows) = <[f64; 16]>::try_from(numbers.as_slice()) {
        Ok(DMat4::from_cols_array(&rows).transpose())
    } else if let Ok(rows) = <[f64; 9]>::try_from(numbers.as_slice()) {
        Ok(DMat4::from_mat3(DMat3::from_cols_array(&rows).transpose()))
    } else {
        Err(element.count_error(value, numbers.len(), "16 (or 9)"))
    }
}

/// `<lookat origin="x, y, z" target="x, y, z" up="x, y, z"/>`; `up` is optional.
fn look_at_element(element: &Element) -> Result<DMat4> {
    element.check_attributes(&["origin", "target", "up"])?;
    let point = |name: &str| -> Result<DVec3> {
        let attribute = element.require(name)?;
        three_numbers(element, attribute)
    };
    let origin = point("origin")?;
    let target = point("target")?;
    let up = match element.get("up").filter(|a| !a.value.trim().is_empty()) {
        Some(attribute) => three_numbers(element, attribute)?,
        None => DVec3::ZERO,
    };
    look_at(origin, target, up).map_err(|problem| {
        Error::input(&element.location, format!("invalid <lookat>: {problem}")).with_help(
            "the camera needs distinct origin and target, and an up direction that is not \
             parallel to target - origin",
        )
    })
}

/// Exactly three numbers, as Mitsuba's `parse_vector_from_string` requires.
fn three_numbers(element: &Element, attribute: &Attribute) -> Result<DVec3> {
    let numbers = element.number_list(attribute)?;
    match numbers[..] {
        [x, y, z] => Ok(DVec3::new(x, y, z)),
        _ => Err(element.count_error(attribute, numbers.len(), "3")),
    }
}

/// Mitsuba's `Transform::look_at`: the camera-to-world matrix whose columns are
/// `left = normalize(cross(up, dir))`, `new_up = cross(dir, left)`, `dir = normalize(target -
/// origin)` and `origin`. A zero `up` is replaced by the first vector of
/// [`coordinate_system`]`(dir)`, as Mitsuba does when `up` is missing.
pub(crate) fn look_at(origin: DVec3, target: DVec3, up: DVec3) -> Result<DMat4, &'static str> {
    if origin == target {
        return Err("origin and target coincide");
    }
    let dir = (target - origin).normalize_or_zero();
    if dir == DVec3::ZERO {
        return Err("the direction from origin to target cannot be normalized");
    }
    let up = if up == DVec3::ZERO {
        coordinate_system(dir).0
    } else {
        up
    };
    let left = up.cross(dir).normalize_or_zero();
    if left == DVec3::ZERO {
        return Err("up is parallel to the viewing direction");
    }
    let new_up = dir.cross(left);
    let matrix = DMat4::from_cols(
        left.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        origin.extend(1.0),
    );
    if matrix.is_finite() {
        Ok(matrix)
    } else {
        Err("the matrix is not finite")
    }
}

/// Two unit vectors completing the unit vector `n` to an orthonormal basis, by the method of
/// Duff et al., "Building an Orthonormal Basis, Revisited" (JCGT 2017), as Mitsuba's
/// `coordinate_system` computes it.
pub(super) fn coordinate_system(n: DVec3) -> (DVec3, DVec3) {
    let sign = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        DVec3::new(sign * n.x * n.x * a + 1.0, sign * b, -sign * n.x),
        DVec3::new(b, n.y * n.y * a + sign, -n.y),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn look_at_columns_follow_mitsuba() {
        let origin = DVec3::new(1.0, 2.0, 3.0);
        let target = DVec3::new(1.0, 2.0, 0.0);
        let m = look_at(origin, target, DVec3::Y).unwrap();
        let dir = DVec3::new(0.0, 0.0, -1.0);
        let left = DVec3::Y.cross(dir).normalize();
        assert_eq!(m.z_axis.truncate(), dir);
        assert_eq!(m.x_axis.truncate(), left);
        assert_eq!(m.y_axis.truncate(), dir.cross(left));
        assert_eq!(m.w_axis, origin.extend(1.0));
        assert_eq!(left, DVec3::new(-1.0, 0.0, 0.0));
    }

    #[test]
    fn look_at_rejects_degenerate_input() {
        assert!(look_at(DVec3::ONE, DVec3::ONE, DVec3::Y).is_err());
        assert!(look_at(DVec3::ZERO, DVec3::Y, DVec3::Y).is_err());
        // A missing up vector is generated, even when looking straight up.
        assert!(look_at(DVec3::ZERO, DVec3::Y, DVec3::ZERO).is_ok());
    }

    #[test]
    fn coordinate_system_is_orthonormal() {
        for n in [
            DVec3::Z,
            -DVec3::Z,
            DVec3::X,
            DVec3::new(1.0, -2.0, 0.5).normalize(),
            DVec3::new(0.3, 0.1, -0.9).normalize(),
        ] {
            let (s, t) = coordinate_system(n);
            assert!((s.length() - 1.0).abs() < 1e-12 && (t.length() - 1.0).abs() < 1e-12);
            assert!(s.dot(t).abs() < 1e-12 && s.dot(n).abs() < 1e-12 && t.dot(n).abs() < 1e-12);
        }
    }
}
