//! Affine transforms with their inverses.

use glam::{DMat4, Mat3, Mat4, Vec3};

/// An affine transform and its inverse, both single precision (composed in double precision
/// by the scene reader and rounded once here).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    pub matrix: Mat4,
    pub inverse: Mat4,
    /// Inverse transpose of the linear part, for normals.
    normal_matrix: Mat3,
}

impl Transform {
    pub const IDENTITY: Transform = Transform {
        matrix: Mat4::IDENTITY,
        inverse: Mat4::IDENTITY,
        normal_matrix: Mat3::IDENTITY,
    };

    /// The transform of a matrix; None when it is not invertible (a zero scale, say), not
    /// affine (last row other than 0 0 0 1) or has non-finite entries.
    pub fn new(m: DMat4) -> Option<Transform> {
        let affine = m.row(3) == glam::DVec4::new(0.0, 0.0, 0.0, 1.0);
        let det = m.determinant();
        if !affine || !det.is_finite() || det.abs() < 1e-30 || !m.is_finite() {
            return None;
        }
        let inverse = m.inverse();
        if !inverse.is_finite() {
            return None;
        }
        let matrix = m.as_mat4();
        let inverse = inverse.as_mat4();
        let normal_matrix = Mat3::from_mat4(inverse).transpose();
        Some(Transform {
            matrix,
            inverse,
            normal_matrix,
        })
    }

    #[inline]
    pub fn point(&self, p: Vec3) -> Vec3 {
        self.matrix.transform_point3(p)
    }

    #[inline]
    pub fn vector(&self, v: Vec3) -> Vec3 {
        self.matrix.transform_vector3(v)
    }

    /// Transforms a normal (by the inverse transpose); the result is not normalised.
    #[inline]
    pub fn normal(&self, n: Vec3) -> Vec3 {
        self.normal_matrix * n
    }

    #[inline]
    pub fn inverse_point(&self, p: Vec3) -> Vec3 {
        self.inverse.transform_point3(p)
    }

    #[inline]
    pub fn inverse_vector(&self, v: Vec3) -> Vec3 {
        self.inverse.transform_vector3(v)
    }

    /// Whether the transform turns right-handed frames into left-handed ones.
    pub fn flips_handedness(&self) -> bool {
        Mat3::from_mat4(self.matrix).determinant() < 0.0
    }
}

/// Mitsuba's look-at matrix: the camera (or object) at `origin` looking at `target`, with the
/// columns [left, up, forward, origin] where forward = normalize(target − origin),
/// left = normalize(up × forward) and up is re-orthogonalised. None when origin = target or
/// `up` is parallel to the viewing direction.
pub fn look_at(origin: glam::DVec3, target: glam::DVec3, up: glam::DVec3) -> Option<DMat4> {
    let forward = (target - origin).try_normalize()?;
    let left = up.cross(forward).try_normalize()?;
    let new_up = forward.cross(left);
    Some(DMat4::from_cols(
        left.extend(0.0),
        new_up.extend(0.0),
        forward.extend(0.0),
        origin.extend(1.0),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn look_at_builds_left_up_forward_columns() {
        use glam::DVec3;
        let m = look_at(DVec3::new(0.0, 0.0, -5.0), DVec3::ZERO, DVec3::Y).unwrap();
        // Looking along +z with +y up, "left" is +x (Mitsuba's camera convention).
        assert!((m.x_axis.truncate() - DVec3::X).length() < 1e-12);
        assert!((m.y_axis.truncate() - DVec3::Y).length() < 1e-12);
        assert!((m.z_axis.truncate() - DVec3::Z).length() < 1e-12);
        assert_eq!(m.w_axis.truncate(), DVec3::new(0.0, 0.0, -5.0));
        assert!(look_at(DVec3::ZERO, DVec3::ZERO, DVec3::Y).is_none());
        assert!(look_at(DVec3::ZERO, DVec3::Y, DVec3::Y).is_none());
    }

    #[test]
    fn normals_stay_perpendicular_under_non_uniform_scale() {
        let m = DMat4::from_scale(glam::DVec3::new(2.0, 0.5, 1.0)) * DMat4::from_rotation_z(0.3);
        let t = Transform::new(m).unwrap();
        let tangent = Vec3::new(1.0, 1.0, 0.0);
        let normal = Vec3::new(1.0, -1.0, 0.0);
        assert!(t.vector(tangent).dot(t.normal(normal)).abs() < 1e-5);
        let p = Vec3::new(0.3, -2.0, 5.0);
        assert!((t.inverse_point(t.point(p)) - p).length() < 1e-5);
    }

    #[test]
    fn singular_and_projective_matrices_are_rejected() {
        assert!(Transform::new(DMat4::from_scale(glam::DVec3::new(1.0, 0.0, 1.0))).is_none());
        let mut m = DMat4::IDENTITY;
        m.w_axis.x = f64::NAN;
        assert!(Transform::new(m).is_none());
        let mut p = DMat4::IDENTITY;
        p.x_axis.w = 0.5;
        assert!(Transform::new(p).is_none());
    }
}
