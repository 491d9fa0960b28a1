//! The operations inside a `<transform>` element, as Mitsuba 3 defines them
//! (`parse_transform_node` in `src/core/parser.cpp`, `Transform::look_at` in
//! `include/mitsuba/core/transform.h`, `rotate` in Dr.Jit's `include/drjit/transform.h`).
//!
//! The reader composes them in document order, each new operation on the left (`M = op * M`), so
//! `<scale value="2"/><translate x="1"/>` scales first and then translates. All matrices act on
//! column vectors.
//!
//! Two operations read differently by version, and Prism warns where a scene meets them:
//! - `<rotate>` with an axis `a` that is not of unit length: Mitsuba 3 builds its matrix from
//!   `a` as given, `R = cos θ I + (1 − cos θ) a aᵀ + sin θ [a]ₓ`, which then also stretches (by
//!   `cos θ + (1 − cos θ)|a|²` along `a`) and shears; Mitsuba 0.6 (`Transform::rotate` in
//!   `src/libcore/transform.cpp`) normalised the axis first. Files older than version 2.0.0 get
//!   0.6's matrix, the others Mitsuba 3's.
//! - `<matrix>` with a last row other than `0 0 0 1`: Mitsuba 3 keeps transforms affine and drops
//!   that row (its `AffineTransform` products never read it). Older files keep it, and a shape or
//!   camera refuses the projective transform.
//!
//! `<lookat>` needs no such care: both versions take `dir = normalize(target − origin)`,
//! `left = normalize(up × dir)` and `up' = dir × left`, so an `up` of any length and at any
//! angle to the view other than parallel gives the same orthonormal frame.
//!
//! Where Mitsuba is silent we decide:
//! - a zero rotation axis is an error (Mitsuba 3.7 does the same);
//! - a scale by 0 is accepted, as in Mitsuba (it flattens a shape); a consumer that needs the
//!   inverse must check it;
//! - `<lookat>` with coinciding origin and target, or with `up` parallel to the viewing direction,
//!   is an error (Mitsuba reports "invalid lookat transformation" when its matrix has NaNs).

use glam::{DMat3, DMat4, DVec3, DVec4};

use super::description::Warning;
use super::element::{Attribute, Element};
use crate::suggest::closest_match;
use prism_core::error::{Error, Result};

/// The transform operation tags.
pub(super) const OPERATIONS: [&str; 5] = ["translate", "rotate", "scale", "matrix", "lookat"];

/// Which Mitsuba a file was written for, by its version: the two read `<rotate>` and `<matrix>`
/// differently.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Dialect {
    /// Version 2.0.0 and later.
    Mitsuba3,
    /// Versions before 2.0.0.
    Mitsuba06,
}

/// The matrix of one operation element, and a warning where the file's Mitsuba reads it
/// otherwise than a reader would expect.
pub(super) fn operation_matrix(
    element: &Element,
    dialect: Dialect,
) -> Result<(DMat4, Option<Warning>)> {
    match element.tag.as_str() {
        "translate" => {
            element.check_attributes(&["x", "y", "z", "value"])?;
            require_some_attribute(element)?;
            Ok((translation(element.xyz(0.0)?), None))
        }
        "scale" => {
            element.check_attributes(&["x", "y", "z", "value"])?;
            require_some_attribute(element)?;
            Ok((scaling(element.xyz(1.0)?), None))
        }
        "rotate" => rotate(element, dialect),
        "matrix" => matrix(element, dialect),
        "lookat" => Ok((look_at_element(element)?, None)),
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

/// How far from 1 an axis's length may be before `<rotate>` warns: a unit axis written with six
/// digits (0.57735 three times) is 3 × 10⁻⁶ short.
const UNIT_AXIS_TOLERANCE: f64 = 1e-4;

/// `<rotate x="0" y="0" z="1" angle="90"/>` (or `value="0, 0, 1"`): a right-handed rotation by
/// `angle` degrees about the axis, missing components 0, read as `dialect`'s Mitsuba reads it.
fn rotate(element: &Element, dialect: Dialect) -> Result<(DMat4, Option<Warning>)> {
    element.check_attributes(&["angle", "x", "y", "z", "value"])?;
    let angle = element.number(element.require("angle")?)?;
    let axis = element.xyz(0.0)?;
    let matrix = match dialect {
        Dialect::Mitsuba3 => rotation(axis, angle),
        Dialect::Mitsuba06 => normalized_rotation(axis, angle),
    }
    .map_err(|problem| {
        Error::input(&element.location, format!("<rotate> has {problem}"))
            .with_help("give the axis with x, y, z (for example z=\"1\") or value=\"0, 0, 1\"")
    })?;
    let length = axis.length();
    let warning = ((length - 1.0).abs() > UNIT_AXIS_TOLERANCE).then(|| {
        let what = match dialect {
            Dialect::Mitsuba3 => {
                "Mitsuba 3 rotates about it as given, which also stretches and shears the \
                 object, and so does Prism; divide the axis by its length for a pure rotation"
            }
            Dialect::Mitsuba06 => {
                "Mitsuba 0.6, this file's version, normalises it, and so does Prism, but \
                 Mitsuba 3 would also stretch and shear the object; give a unit axis for the \
                 same image in both"
            }
        };
        Warning {
            location: element.location.clone(),
            message: format!("<rotate> has an axis of length {length:.4}, not 1: {what}"),
        }
    });
    Ok((matrix, warning))
}

/// Mitsuba 3's rotation by `angle` degrees about `axis` as given (Dr.Jit's `rotate`):
/// `cos θ I + (1 − cos θ) a aᵀ + sin θ [a]ₓ`, a right-handed rotation when `a` is of unit length;
/// a zero axis, or one so large that the matrix overflows, is an error (named as "a zero
/// rotation axis", ...).
pub(crate) fn rotation(axis: DVec3, angle: f64) -> Result<DMat4, &'static str> {
    if axis == DVec3::ZERO {
        return Err("a zero rotation axis");
    }
    let (sin, cos) = angle.to_radians().sin_cos();
    let cross = DMat3::from_cols(
        DVec3::new(0.0, axis.z, -axis.y),
        DVec3::new(-axis.z, 0.0, axis.x),
        DVec3::new(axis.y, -axis.x, 0.0),
    );
    let outer = DMat3::from_cols(axis * axis.x, axis * axis.y, axis * axis.z);
    let matrix = DMat4::from_mat3(
        DMat3::from_diagonal(DVec3::splat(cos)) + outer * (1.0 - cos) + cross * sin,
    );
    if matrix.is_finite() {
        Ok(matrix)
    } else {
        Err("an axis too large for its rotation matrix")
    }
}

/// Mitsuba 0.6's rotation: about the normalized `axis`; a zero axis, or one that cannot be
/// normalized, is an error.
fn normalized_rotation(axis: DVec3, angle: f64) -> Result<DMat4, &'static str> {
    if axis == DVec3::ZERO {
        return Err("a zero rotation axis");
    }
    let unit = axis.normalize();
    if !unit.is_finite() {
        return Err("an axis too large or too small to normalize");
    }
    rotation(unit, angle)
}

/// `<matrix value="..."/>`: 16 numbers in row-major order, or 9 for the linear 3x3 part (the
/// rest is taken from the identity). In `Dialect::Mitsuba3` a last row other than `0 0 0 1` is
/// replaced by it, with a warning.
fn matrix(element: &Element, dialect: Dialect) -> Result<(DMat4, Option<Warning>)> {
    element.check_attributes(&["value"])?;
    let value = element.require("value")?;
    let numbers = element.number_list(value)?;
    if let Ok(rows) = <[f64; 16]>::try_from(numbers.as_slice()) {
        let mut matrix = DMat4::from_cols_array(&rows).transpose();
        let last_row = matrix.row(3);
        if dialect == Dialect::Mitsuba3 && last_row != DVec4::W {
            matrix = DMat4::from_cols(
                matrix.x_axis.truncate().extend(0.0),
                matrix.y_axis.truncate().extend(0.0),
                matrix.z_axis.truncate().extend(0.0),
                matrix.w_axis.truncate().extend(1.0),
            );
            let warning = Warning {
                location: element.location.clone(),
                message: format!(
                    "<matrix> has the last row {}, not 0 0 0 1: Mitsuba 3 keeps transforms \
                     affine and ignores it, and so does Prism",
                    last_row.to_array().map(|v| v.to_string()).join(" ")
                ),
            };
            return Ok((matrix, Some(warning)));
        }
        Ok((matrix, None))
    } else if let Ok(rows) = <[f64; 9]>::try_from(numbers.as_slice()) {
        Ok((
            DMat4::from_mat3(DMat3::from_cols_array(&rows).transpose()),
            None,
        ))
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

    /// Dr.Jit's formula: for a unit axis the rotation glam builds; for a longer axis `a`, `R a
    /// = (cos θ + (1 − cos θ)|a|²) a` and `R v = cos θ v + sin θ a × v` for `v ⟂ a`.
    #[test]
    fn rotation_uses_the_axis_as_given() {
        let unit = DVec3::new(1.0, -2.0, 0.5).normalize();
        let angle: f64 = 37.0;
        let r = rotation(unit, angle).unwrap();
        assert!(r.abs_diff_eq(DMat4::from_axis_angle(unit, angle.to_radians()), 1e-14));
        let axis = DVec3::new(0.0, 1.0, 1.0);
        let (sin, cos) = angle.to_radians().sin_cos();
        let r = rotation(axis, angle).unwrap();
        let along = r.transform_vector3(axis);
        assert!(along.abs_diff_eq(axis * (cos + (1.0 - cos) * 2.0), 1e-14));
        let v = DVec3::X;
        assert!(
            r.transform_vector3(v)
                .abs_diff_eq(v * cos + axis.cross(v) * sin, 1e-14)
        );
        assert!(rotation(DVec3::ZERO, angle).is_err());
        assert!(rotation(DVec3::splat(1e200), angle).is_err());
        let normalized = normalized_rotation(axis * 3.0, angle).unwrap();
        assert!(normalized.abs_diff_eq(rotation(axis.normalize(), angle).unwrap(), 1e-14));
        assert!(normalized_rotation(DVec3::ZERO, angle).is_err());
    }

    /// `up` of any length, at any angle to the view but parallel, gives the same frame.
    #[test]
    fn look_at_makes_up_orthonormal() {
        let (origin, target) = (DVec3::new(0.0, 0.0, 5.0), DVec3::new(0.3, -0.2, 0.0));
        let dir = (target - origin).normalize();
        let up = DVec3::new(0.5, 2.0, 0.3);
        let orthonormal = (up - dir * up.dot(dir)).normalize();
        let given = look_at(origin, target, up).unwrap();
        assert!(given.abs_diff_eq(look_at(origin, target, orthonormal).unwrap(), 1e-14));
        let rotation = DMat3::from_mat4(given);
        assert!((rotation.transpose() * rotation).abs_diff_eq(DMat3::IDENTITY, 1e-14));
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
