//! Four triangles intersected at once: the watertight test of [`super::triangle`] (Woop, Benthin
//! & Wald 2013) evaluated lane by lane in 4-wide SIMD, as Embree's `Triangle4` leaves are.
//!
//! A pack stores the vertices of up to four triangles structure-of-arrays (`vertex[i][axis]`
//! holds that coordinate of vertex i for the four lanes), so the ray's axis permutation is a
//! choice of arrays and every step of the test is one SIMD operation for all four triangles.
//! The arithmetic is the scalar test's, operation for operation (no fused multiply-adds), so a
//! pack reports exactly the hits the scalar test would: where an edge function of a live lane is
//! exactly zero the pack is handed to the scalar test, which retests that case in double
//! precision.

use glam::Vec3;
use wide::{CmpEq, CmpGt, CmpLe, CmpLt, CmpNe, f32x4};

use super::triangle::{TriangleHit, WatertightRay, gamma};

/// Up to four triangles, their vertices in structure-of-arrays form, and which lanes hold one.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub struct TrianglePack {
    /// `vertex[i][axis]`: coordinate `axis` of vertex i of each lane's triangle.
    vertex: [[f32x4; 3]; 3],
    /// The caller's id of each lane's triangle (see [`super::bvh::BuildPrimitive`]); `u32::MAX`
    /// where empty.
    pub id: [u32; 4],
}

/// A ray prepared for packs: the watertight test's permutation, and its origin and shear as
/// one SIMD value per coordinate, computed once per ray rather than once per pack.
#[derive(Clone, Copy, Debug)]
pub struct PackRay {
    permutation: [usize; 3],
    /// The origin's coordinates along the permuted axes x, y, z.
    origin: [f32x4; 3],
    shear: [f32x4; 3],
    /// The ray itself, for the scalar test.
    scalar: WatertightRay,
}

impl PackRay {
    #[inline]
    pub fn new(ray: &WatertightRay) -> PackRay {
        let o = ray.origin.to_array();
        PackRay {
            permutation: ray.permutation,
            origin: ray.permutation.map(|k| f32x4::splat(o[k])),
            shear: ray.shear.to_array().map(f32x4::splat),
            scalar: *ray,
        }
    }
}

/// The number of triangles in a pack.
pub const PACK_WIDTH: usize = 4;

impl TrianglePack {
    /// An empty pack.
    pub fn empty() -> TrianglePack {
        TrianglePack {
            vertex: [[f32x4::ZERO; 3]; 3],
            id: [u32::MAX; 4],
        }
    }

    /// Puts triangle `id` with vertices `v` in `lane`.
    pub fn set(&mut self, lane: usize, v: [Vec3; 3], id: u32) {
        for (vertex, p) in self.vertex.iter_mut().zip(v) {
            for (axis, coordinate) in vertex.iter_mut().enumerate() {
                let mut lanes = coordinate.to_array();
                lanes[lane] = p[axis];
                *coordinate = f32x4::new(lanes);
            }
        }
        self.id[lane] = id;
    }

    /// The vertices of the triangle in `lane`.
    pub fn vertices(&self, lane: usize) -> [Vec3; 3] {
        self.vertex.map(|v| {
            Vec3::new(
                v[0].to_array()[lane],
                v[1].to_array()[lane],
                v[2].to_array()[lane],
            )
        })
    }

    /// The nearest hit, 0 < t < t_max, among the lanes set in `lanes` (bit i for lane i): the
    /// lane and the hit. Both faces count. Always inlined, so that the traversal compiled for AVX
    /// runs it in AVX's three-operand instructions.
    #[inline(always)]
    pub fn intersect(&self, ray: &PackRay, lanes: u32, t_max: f32) -> Option<(usize, TriangleHit)> {
        let [kx, ky, kz] = ray.permutation;
        let [ox, oy, oz] = ray.origin;
        let [sx, sy, sz] = ray.shear;
        // Vertices relative to the origin, permuted and sheared (the ray becomes +z).
        let translate = |v: &[f32x4; 3]| {
            let z = v[kz] - oz;
            (v[kx] - ox + sx * z, v[ky] - oy + sy * z, z)
        };
        let (x0, y0, z0) = translate(&self.vertex[0]);
        let (x1, y1, z1) = translate(&self.vertex[1]);
        let (x2, y2, z2) = translate(&self.vertex[2]);
        let e0 = x1 * y2 - y1 * x2;
        let e1 = x2 * y0 - y2 * x0;
        let e2 = x0 * y1 - y0 * x1;
        let zero = f32x4::ZERO;
        let live = lanes & 0xF;
        let exact_zero =
            (e0.cmp_eq(zero) | e1.cmp_eq(zero) | e2.cmp_eq(zero)).move_mask() as u32 & live;
        if exact_zero != 0 {
            return self.intersect_scalar(&ray.scalar, live, t_max);
        }
        // No edge function is zero, so a lane is outside exactly where their signs differ: where
        // the sign bit of e0 | e1 | e2 (some negative) is not that of e0 & e1 & e2 (all
        // negative). (A NaN, from overflowing coordinates, makes t NaN below: never a hit.)
        let outside = ((e0 | e1 | e2) ^ (e0 & e1 & e2)).move_mask() as u32;
        let det = e0 + e1 + e2;
        // The scaled distance, its sign made that of det · t, compared with t_max before dividing.
        let (z0, z1, z2) = (z0 * sz, z1 * sz, z2 * sz);
        let t_scaled = e0 * z0 + e1 * z1 + e2 * z2;
        let sign = det & f32x4::splat(-0.0);
        let t_signed = t_scaled ^ sign;
        let det_abs = det.abs();
        let in_range = t_signed.cmp_gt(zero) & t_signed.cmp_le(f32x4::splat(t_max) * det_abs);
        let candidate = (det.cmp_ne(zero) & in_range).move_mask() as u32 & !outside & live;
        if candidate == 0 {
            return None;
        }
        let inv_det = f32x4::splat(1.0) / det;
        let t = t_scaled * inv_det;
        // Make sure t is certainly positive given the rounding errors (pbrt-v4 §6.8.7).
        let max3 = |a: f32x4, b: f32x4, c: f32x4| a.abs().fast_max(b.abs()).fast_max(c.abs());
        let max_zt = max3(z0, z1, z2);
        let max_xt = max3(x0, x1, x2);
        let max_yt = max3(y0, y1, y2);
        let delta_z = f32x4::splat(gamma(3)) * max_zt;
        let delta_x = f32x4::splat(gamma(5)) * (max_xt + max_zt);
        let delta_y = f32x4::splat(gamma(5)) * (max_yt + max_zt);
        let delta_e = f32x4::splat(2.0)
            * (f32x4::splat(gamma(2)) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
        let max_e = max3(e0, e1, e2);
        let delta_t = f32x4::splat(3.0)
            * (f32x4::splat(gamma(3)) * max_e * max_zt + delta_e * max_zt + delta_z * max_e)
            * inv_det.abs();
        let accepted = (t.cmp_gt(delta_t) & t.cmp_lt(f32x4::splat(t_max)) & t.is_finite())
            .move_mask() as u32
            & candidate;
        if accepted == 0 {
            return None;
        }
        let t = t.to_array();
        let mut lane = accepted.trailing_zeros() as usize;
        let mut rest = accepted & (accepted - 1);
        while rest != 0 {
            let other = rest.trailing_zeros() as usize;
            if t[other] < t[lane] {
                lane = other;
            }
            rest &= rest - 1;
        }
        let inv_det = inv_det.to_array()[lane];
        Some((
            lane,
            TriangleHit {
                t: t[lane],
                b0: e0.to_array()[lane] * inv_det,
                b1: e1.to_array()[lane] * inv_det,
                b2: e2.to_array()[lane] * inv_det,
            },
        ))
    }

    /// The same query, lane by lane with the scalar test (for the rare exact-zero edges).
    #[cold]
    fn intersect_scalar(
        &self,
        ray: &WatertightRay,
        lanes: u32,
        mut t_max: f32,
    ) -> Option<(usize, TriangleHit)> {
        let mut nearest = None;
        for lane in 0..PACK_WIDTH {
            if lanes & (1 << lane) == 0 {
                continue;
            }
            let [p0, p1, p2] = self.vertices(lane);
            if let Some(hit) = ray.intersect(t_max, p0, p1, p2)
                && hit.t < t_max
            {
                t_max = hit.t;
                nearest = Some((lane, hit));
            }
        }
        nearest
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::rng::Pcg32;

    fn random_point(rng: &mut Pcg32) -> Vec3 {
        Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0
    }

    /// The pack finds exactly the hit the scalar test finds nearest, bit for bit, on random
    /// triangles and rays, including rays through shared vertices (exact-zero edges).
    #[test]
    fn agrees_with_the_scalar_test() {
        let mut rng = Pcg32::seeded(11);
        let mut hits = 0;
        for case in 0..200_000 {
            let mut pack = TrianglePack::empty();
            let mut triangles = Vec::new();
            let n = 1 + case % 4;
            for lane in 0..n {
                let v = [
                    random_point(&mut rng),
                    random_point(&mut rng),
                    random_point(&mut rng),
                ];
                pack.set(lane, v, lane as u32);
                triangles.push(v);
            }
            let o = random_point(&mut rng) * 3.0;
            // Aim at a vertex now and then, so that edge functions are exactly zero.
            let target = if case % 16 == 0 {
                triangles[0][0]
            } else {
                random_point(&mut rng) * 0.5
            };
            let ray = WatertightRay::new(o, target - o);
            let t_max = if case % 3 == 0 {
                f32::INFINITY
            } else {
                rng.next_f32() * 2.0
            };
            let mut expected: Option<(usize, TriangleHit)> = None;
            for (lane, v) in triangles.iter().enumerate() {
                let limit = expected.map_or(t_max, |(_, h)| h.t);
                if let Some(h) = ray.intersect(limit, v[0], v[1], v[2])
                    && h.t < limit
                {
                    expected = Some((lane, h));
                }
            }
            let mask = (1u32 << n) - 1;
            let found = pack.intersect(&PackRay::new(&ray), mask, t_max);
            match (found, expected) {
                (Some((la, a)), Some((lb, b))) => {
                    hits += 1;
                    assert_eq!(a.t, b.t, "case {case}");
                    // Equal distances may be reported by either triangle.
                    if la == lb {
                        assert_eq!(a, b, "case {case}");
                    }
                }
                (None, None) => {}
                _ => panic!("case {case}: pack {found:?}, scalar {expected:?}"),
            }
        }
        assert!(
            hits > 20_000,
            "only {hits} hits: the test exercises too little"
        );
    }

    /// A ray through a vertex makes two edge functions exactly zero, which sends the pack to
    /// the scalar test (its double-precision retest): the vertex is hit, as the scalar test says.
    #[test]
    fn exact_zero_edges_take_the_scalar_path() {
        let v = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let mut pack = TrianglePack::empty();
        pack.set(2, v, 7);
        let ray = WatertightRay::new(Vec3::Z, -Vec3::Z);
        let scalar = ray.intersect(f32::INFINITY, v[0], v[1], v[2]).unwrap();
        let (lane, hit) = pack
            .intersect(&PackRay::new(&ray), 0b100, f32::INFINITY)
            .unwrap();
        assert_eq!((lane, hit), (2, scalar));
        assert_eq!(hit.t, 1.0);
    }

    /// Lanes outside the mask are never reported.
    #[test]
    fn masked_lanes_are_ignored() {
        let mut pack = TrianglePack::empty();
        let v = [Vec3::ZERO, Vec3::X, Vec3::Y];
        pack.set(0, v, 0);
        pack.set(1, v.map(|p| p + Vec3::Z * 0.5), 1);
        let ray = PackRay::new(&WatertightRay::new(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z));
        assert_eq!(pack.intersect(&ray, 0b11, f32::INFINITY).unwrap().0, 1);
        assert_eq!(pack.intersect(&ray, 0b01, f32::INFINITY).unwrap().0, 0);
        assert!(pack.intersect(&ray, 0b00, f32::INFINITY).is_none());
        assert!(pack.intersect(&ray, 0b11, 0.4).is_none());
    }
}
