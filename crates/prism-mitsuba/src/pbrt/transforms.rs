//! The matrices of pbrt-v4's transform directives (`src/pbrt/util/transform.cpp`). pbrt keeps a
//! current transformation matrix (CTM) from object to world space and right-multiplies it by
//! each directive's matrix, so the directive written last applies first to a shape's points.
//!
//! pbrt's camera space is left-handed: +x to the right of the image, +y up, +z forward. Mitsuba's
//! (and Prism's) camera looks along +z with +y up and +x to the image's left, so a camera's
//! `to_world` is pbrt's world-from-camera transform followed by the mirror x → −x
//! ([`sensor_to_world`]).

use glam::{DMat4, DVec3, DVec4};

/// `Translate dx dy dz`.
pub fn translate(delta: DVec3) -> DMat4 {
    DMat4::from_translation(delta)
}

/// `Scale sx sy sz`.
pub fn scale(factors: DVec3) -> DMat4 {
    DMat4::from_scale(factors)
}

/// `Rotate angle ax ay az`: a right-handed rotation by `degrees` about the axis (normalised
/// first), Rodrigues' formula as pbrt's `Rotate(sinθ, cosθ, axis)` writes it. `None` for an
/// axis of no length.
pub fn rotate(degrees: f64, axis: DVec3) -> Option<DMat4> {
    let axis = axis.try_normalize()?;
    Some(DMat4::from_axis_angle(axis, degrees.to_radians()))
}

/// `LookAt eye target up`: the camera-from-world matrix of a camera at `eye` looking at
/// `target`, with right = normalize(normalize(up) × dir) and up' = dir × right (pbrt's
/// `LookAt`). `None` when `up` is parallel to the viewing direction or the two points meet.
pub fn look_at(eye: DVec3, target: DVec3, up: DVec3) -> Option<DMat4> {
    let dir = (target - eye).try_normalize()?;
    let right = up.try_normalize()?.cross(dir).try_normalize()?;
    let new_up = dir.cross(right);
    let world_from_camera = DMat4::from_cols(
        right.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        eye.extend(1.0),
    );
    Some(world_from_camera.inverse())
}

/// `Transform [m00 ... m33]` and `ConcatTransform`: pbrt reads the 16 numbers as the rows of a
/// matrix and transposes it, so the numbers are the columns, the translation last.
pub fn from_columns(values: &[f64; 16]) -> DMat4 {
    DMat4::from_cols_array(values)
}

/// The camera's `to_world` for Prism from pbrt's camera-from-world CTM: pbrt's world-from-camera
/// followed by the mirror of the camera's x axis (see the module's documentation). `None` when
/// the CTM is singular.
pub fn sensor_to_world(camera_from_world: DMat4) -> Option<DMat4> {
    if !is_invertible(camera_from_world) {
        return None;
    }
    Some(camera_from_world.inverse() * DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0)))
}

/// Whether `m` is an affine transform with an inverse.
pub fn is_invertible(m: DMat4) -> bool {
    let det = m.determinant();
    m.row(3) == DVec4::new(0.0, 0.0, 0.0, 1.0) && det.is_finite() && det.abs() > 1e-300
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_close(found: DMat4, expected: DMat4) {
        assert!(
            found.abs_diff_eq(expected, 1e-12),
            "found {found:?}, expected {expected:?}"
        );
    }

    /// A matrix from its rows, as written on paper.
    fn rows(r: [[f64; 4]; 4]) -> DMat4 {
        DMat4::from_cols_array_2d(&r).transpose()
    }

    #[test]
    fn translate_and_scale() {
        assert_close(
            translate(DVec3::new(1.0, 2.0, 3.0)),
            rows([
                [1.0, 0.0, 0.0, 1.0],
                [0.0, 1.0, 0.0, 2.0],
                [0.0, 0.0, 1.0, 3.0],
                [0.0, 0.0, 0.0, 1.0],
            ]),
        );
        assert_close(
            scale(DVec3::new(2.0, -1.0, 0.5)),
            rows([
                [2.0, 0.0, 0.0, 0.0],
                [0.0, -1.0, 0.0, 0.0],
                [0.0, 0.0, 0.5, 0.0],
                [0.0, 0.0, 0.0, 1.0],
            ]),
        );
    }

    #[test]
    fn rotate_is_right_handed_about_the_normalised_axis() {
        // 90° about +z takes +x to +y.
        assert_close(
            rotate(90.0, DVec3::new(0.0, 0.0, 5.0)).unwrap(),
            rows([
                [0.0, -1.0, 0.0, 0.0],
                [1.0, 0.0, 0.0, 0.0],
                [0.0, 0.0, 1.0, 0.0],
                [0.0, 0.0, 0.0, 1.0],
            ]),
        );
        // 120° about (1, 1, 1) cycles the axes: x → y → z → x.
        assert_close(
            rotate(120.0, DVec3::ONE).unwrap(),
            rows([
                [0.0, 0.0, 1.0, 0.0],
                [1.0, 0.0, 0.0, 0.0],
                [0.0, 1.0, 0.0, 0.0],
                [0.0, 0.0, 0.0, 1.0],
            ]),
        );
        assert!(rotate(30.0, DVec3::ZERO).is_none());
    }

    #[test]
    fn look_at_maps_the_eye_to_the_origin_and_the_target_to_plus_z() {
        // From (0, 0, -5) towards the origin, y up: right = up × dir = +x.
        let m = look_at(DVec3::new(0.0, 0.0, -5.0), DVec3::ZERO, DVec3::Y).unwrap();
        assert_close(
            m,
            rows([
                [1.0, 0.0, 0.0, 0.0],
                [0.0, 1.0, 0.0, 0.0],
                [0.0, 0.0, 1.0, 5.0],
                [0.0, 0.0, 0.0, 1.0],
            ]),
        );
        // From (1, 2, 3) looking along −x, z up: right = z × (−x) = −y, up' = (−x) × (−y) = z.
        let m = look_at(
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(0.0, 2.0, 3.0),
            DVec3::Z,
        )
        .unwrap();
        // Rows: right, up', dir; then −(rows · eye).
        assert_close(
            m,
            rows([
                [0.0, -1.0, 0.0, 2.0],
                [0.0, 0.0, 1.0, -3.0],
                [-1.0, 0.0, 0.0, 1.0],
                [0.0, 0.0, 0.0, 1.0],
            ]),
        );
        assert!(look_at(DVec3::ZERO, DVec3::Y, DVec3::Y).is_none());
        assert!(look_at(DVec3::ZERO, DVec3::ZERO, DVec3::Y).is_none());
    }

    #[test]
    fn transform_numbers_are_columns() {
        let values = [
            1.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.0, 3.0, 0.0, 4.0, 5.0, 6.0, 1.0,
        ];
        assert_close(
            from_columns(&values),
            rows([
                [1.0, 0.0, 0.0, 4.0],
                [0.0, 2.0, 0.0, 5.0],
                [0.0, 0.0, 3.0, 6.0],
                [0.0, 0.0, 0.0, 1.0],
            ]),
        );
    }

    #[test]
    fn the_sensor_mirrors_the_camera_x_axis() {
        // pbrt's camera at the origin looking along +z (identity CTM) sees +x on the image's
        // right; Prism's camera x points to the image's left, so to_world maps it to −x.
        let to_world = sensor_to_world(DMat4::IDENTITY).unwrap();
        assert_close(to_world, scale(DVec3::new(-1.0, 1.0, 1.0)));
        // `Scale -1 1 1` before the LookAt (pbrt scenes written for Mitsuba's convention)
        // gives a rigid to_world.
        let ctm = scale(DVec3::new(-1.0, 1.0, 1.0))
            * look_at(DVec3::new(0.0, 0.0, -5.0), DVec3::ZERO, DVec3::Y).unwrap();
        assert_close(
            sensor_to_world(ctm).unwrap(),
            translate(DVec3::new(0.0, 0.0, -5.0)),
        );
        assert!(sensor_to_world(DMat4::ZERO).is_none());
    }
}
