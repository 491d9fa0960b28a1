//! An orthonormal basis: the local shading frame in which BSDFs are written (z = normal).

use glam::Vec3;

/// Orthonormal basis (s, t, n); local coordinates have the normal along +z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub s: Vec3,
    pub t: Vec3,
    pub n: Vec3,
}

impl Frame {
    /// A frame around the unit vector `n`, continuous except where n.z = 0 changes sign
    /// (Duff et al. 2017, "Building an Orthonormal Basis, Revisited", Listing 3).
    pub fn from_normal(n: Vec3) -> Frame {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Frame { s, t, n }
    }

    /// A frame with normal `n` whose first tangent is `s` made orthogonal to `n` (Gram–Schmidt);
    /// falls back to [`Frame::from_normal`] when `s` is (nearly) parallel to `n`.
    pub fn from_normal_and_tangent(n: Vec3, s: Vec3) -> Frame {
        let s = s - n * n.dot(s);
        let length = s.length();
        if !(length > 1e-6) {
            return Frame::from_normal(n);
        }
        let s = s / length;
        Frame {
            s,
            t: n.cross(s),
            n,
        }
    }

    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }

    /// The same frame seen from the other side: normal flipped, handedness kept.
    #[inline]
    pub fn flipped(&self) -> Frame {
        Frame {
            s: self.s,
            t: -self.t,
            n: -self.n,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::rng::Pcg32;
    use crate::sampling::warp::sample_uniform_sphere;

    #[test]
    fn frames_are_orthonormal_and_round_trip() {
        let mut rng = Pcg32::seeded(1);
        let mut normals: Vec<Vec3> = (0..1000)
            .map(|_| sample_uniform_sphere(glam::Vec2::new(rng.next_f32(), rng.next_f32())))
            .collect();
        normals.extend([Vec3::Z, -Vec3::Z, Vec3::X, Vec3::new(0.0, 0.0, -0.0)]);
        for n in normals {
            let n = if n.length() == 0.0 { Vec3::Z } else { n };
            let f = Frame::from_normal(n);
            assert!((f.s.length() - 1.0).abs() < 1e-5);
            assert!((f.t.length() - 1.0).abs() < 1e-5);
            assert!(
                f.s.dot(f.t).abs() < 1e-5 && f.s.dot(n).abs() < 1e-5 && f.t.dot(n).abs() < 1e-5
            );
            assert!((f.s.cross(f.t) - n).length() < 1e-4, "right-handed");
            let v = Vec3::new(0.3, -0.2, 0.9);
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-5);
            let g = f.flipped();
            assert!((g.s.cross(g.t) - g.n).length() < 1e-4);
        }
    }
}
