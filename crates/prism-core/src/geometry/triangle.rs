//! Watertight ray–triangle intersection (Woop, Benthin & Wald 2013, "Watertight Ray/Triangle
//! Intersection", JCGT 2(1)), with the conservative t > 0 test of pbrt-v4 §6.5.3.
//!
//! The triangle is translated to the ray origin, the axes permuted so the ray's dominant axis is
//! z, and sheared so the ray points along +z; the 2-D edge functions of the projected vertices
//! then decide the hit with no gaps or double hits along shared edges: two triangles sharing an
//! edge compute its edge function from the same rounded products with opposite signs, so a ray
//! is never outside both. Only where an edge function is exactly zero (the ray passes through
//! the edge or a vertex at float precision) are the three evaluated again in double precision,
//! as Woop et al. (§3.4) and pbrt-v4 do, so that the tie is broken the same way by both sides.

use glam::Vec3;

/// Where a ray hits a triangle: the ray parameter and barycentric coordinates
/// (the point is b0·p0 + b1·p1 + b2·p2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    pub t: f32,
    pub b0: f32,
    pub b1: f32,
    pub b2: f32,
}

/// γ(n) = nε/(1 − nε), the bound on accumulated relative rounding error (pbrt-v4 §6.8.1).
#[inline]
pub(super) const fn gamma(n: i32) -> f32 {
    let e = f32::EPSILON * 0.5;
    (n as f32 * e) / (1.0 - n as f32 * e)
}

/// a·b − c·d with a single rounding: the products of two f32 are exact in f64.
#[inline]
fn difference_of_products_f64(a: f32, b: f32, c: f32, d: f32) -> f32 {
    (f64::from(a) * f64::from(b) - f64::from(c) * f64::from(d)) as f32
}

#[inline]
fn permute(v: Vec3, x: usize, y: usize, z: usize) -> Vec3 {
    Vec3::new(v[x], v[y], v[z])
}

/// A ray prepared for watertight triangle tests: the permutation that makes the direction's
/// largest component z, and the shear that turns the direction into +z. Computed once per ray
/// and shared by every triangle the traversal visits.
#[derive(Clone, Copy, Debug)]
pub struct WatertightRay {
    pub(super) origin: Vec3,
    /// The axes that become x, y and z.
    pub(super) permutation: [usize; 3],
    /// (−d_x/d_z, −d_y/d_z, 1/d_z) in permuted coordinates.
    pub(super) shear: Vec3,
}

impl WatertightRay {
    /// Prepares the ray o + t·d.
    #[inline]
    pub fn new(o: Vec3, d: Vec3) -> WatertightRay {
        let abs_d = d.abs();
        let kz = if abs_d.x > abs_d.y {
            if abs_d.x > abs_d.z { 0 } else { 2 }
        } else if abs_d.y > abs_d.z {
            1
        } else {
            2
        };
        let kx = if kz == 2 { 0 } else { kz + 1 };
        let ky = if kx == 2 { 0 } else { kx + 1 };
        let d = permute(d, kx, ky, kz);
        WatertightRay {
            origin: o,
            permutation: [kx, ky, kz],
            shear: Vec3::new(-d.x / d.z, -d.y / d.z, 1.0 / d.z),
        }
    }

    /// Intersects the ray, 0 < t < t_max, with the triangle (p0, p1, p2); both faces count.
    /// A degenerate triangle (zero area) may or may not report hits: callers leave them out.
    #[inline]
    pub fn intersect(&self, t_max: f32, p0: Vec3, p1: Vec3, p2: Vec3) -> Option<TriangleHit> {
        let [kx, ky, kz] = self.permutation;
        let mut p0t = permute(p0 - self.origin, kx, ky, kz);
        let mut p1t = permute(p1 - self.origin, kx, ky, kz);
        let mut p2t = permute(p2 - self.origin, kx, ky, kz);
        let (sx, sy, sz) = (self.shear.x, self.shear.y, self.shear.z);
        p0t.x += sx * p0t.z;
        p0t.y += sy * p0t.z;
        p1t.x += sx * p1t.z;
        p1t.y += sy * p1t.z;
        p2t.x += sx * p2t.z;
        p2t.y += sy * p2t.z;
        let mut e0 = p1t.x * p2t.y - p1t.y * p2t.x;
        let mut e1 = p2t.x * p0t.y - p2t.y * p0t.x;
        let mut e2 = p0t.x * p1t.y - p0t.y * p1t.x;
        if e0 == 0.0 || e1 == 0.0 || e2 == 0.0 {
            e0 = difference_of_products_f64(p1t.x, p2t.y, p1t.y, p2t.x);
            e1 = difference_of_products_f64(p2t.x, p0t.y, p2t.y, p0t.x);
            e2 = difference_of_products_f64(p0t.x, p1t.y, p0t.y, p1t.x);
        }
        if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0) {
            return None;
        }
        let det = e0 + e1 + e2;
        if det == 0.0 {
            return None;
        }
        // Scaled hit distance, compared with t_max before dividing.
        p0t.z *= sz;
        p1t.z *= sz;
        p2t.z *= sz;
        let t_scaled = e0 * p0t.z + e1 * p1t.z + e2 * p2t.z;
        if det < 0.0 && (t_scaled >= 0.0 || t_scaled < t_max * det) {
            return None;
        }
        if det > 0.0 && (t_scaled <= 0.0 || t_scaled > t_max * det) {
            return None;
        }
        let inv_det = 1.0 / det;
        let (b0, b1, b2) = (e0 * inv_det, e1 * inv_det, e2 * inv_det);
        let t = t_scaled * inv_det;
        if !t.is_finite() {
            return None;
        }
        // Make sure t is certainly positive given the rounding errors above (pbrt-v4 §6.8.7).
        let max_zt = Vec3::new(p0t.z, p1t.z, p2t.z).abs().max_element();
        let delta_z = gamma(3) * max_zt;
        let max_xt = Vec3::new(p0t.x, p1t.x, p2t.x).abs().max_element();
        let max_yt = Vec3::new(p0t.y, p1t.y, p2t.y).abs().max_element();
        let delta_x = gamma(5) * (max_xt + max_zt);
        let delta_y = gamma(5) * (max_yt + max_zt);
        let delta_e = 2.0 * (gamma(2) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
        let max_e = Vec3::new(e0, e1, e2).abs().max_element();
        let delta_t =
            3.0 * (gamma(3) * max_e * max_zt + delta_e * max_zt + delta_z * max_e) * inv_det.abs();
        if t <= delta_t {
            return None;
        }
        Some(TriangleHit { t, b0, b1, b2 })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::rng::Pcg32;

    #[test]
    fn hits_inside_and_misses_outside() {
        let (p0, p1, p2) = (Vec3::ZERO, Vec3::X, Vec3::Y);
        let down = WatertightRay::new(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z);
        let hit = down.intersect(f32::INFINITY, p0, p1, p2).unwrap();
        assert!((hit.t - 1.0).abs() < 1e-6);
        assert!((hit.b1 - 0.25).abs() < 1e-6 && (hit.b2 - 0.25).abs() < 1e-6);
        let outside = WatertightRay::new(Vec3::new(0.75, 0.75, 1.0), -Vec3::Z);
        assert!(outside.intersect(f32::INFINITY, p0, p1, p2).is_none());
        // Behind the origin and beyond t_max.
        let up = WatertightRay::new(Vec3::new(0.25, 0.25, 1.0), Vec3::Z);
        assert!(up.intersect(f32::INFINITY, p0, p1, p2).is_none());
        assert!(down.intersect(0.5, p0, p1, p2).is_none());
    }

    /// Rays through the shared edge of two triangles hit exactly one or both, never neither.
    #[test]
    fn shared_edges_are_watertight() {
        let a = [
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
        ];
        let b = [
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
            Vec3::new(-1.0, -1.0, 0.0),
        ];
        let mut rng = Pcg32::seeded(4);
        for _ in 0..100_000 {
            // Points on the diagonal x = y, seen from random origins.
            let s = rng.next_f32() * 1.8 - 0.9;
            let target = Vec3::new(s, s, 0.0);
            let o = Vec3::new(
                rng.next_f32() * 4.0 - 2.0,
                rng.next_f32() * 4.0 - 2.0,
                1.0 + rng.next_f32() * 3.0,
            );
            let d = target - o;
            let ray = WatertightRay::new(o, d);
            let ha = ray.intersect(f32::INFINITY, a[0], a[1], a[2]);
            let hb = ray.intersect(f32::INFINITY, b[0], b[1], b[2]);
            assert!(
                ha.is_some() || hb.is_some(),
                "ray {o} -> {target} slipped through the edge"
            );
        }
    }
}
