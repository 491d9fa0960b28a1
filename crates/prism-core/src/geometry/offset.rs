//! Ray origins that cannot re-hit their own surface.
//!
//! A hit point computed in floating point lies a few ulps off the surface; a ray spawned from it
//! may hit the same surface again ("shadow acne"). Following Wächter & Binder 2019, "A Fast and
//! Robust Method for Avoiding Self-Intersection" (Ray Tracing Gems, ch. 6), the origin is moved
//! along the geometric normal by a number of ulps proportional to the normal's component, so the
//! offset scales with the point's magnitude; near the world origin, where ulps are tiny, a small
//! absolute offset is used instead.

use glam::Vec3;

/// Below this magnitude a coordinate is offset by a fixed amount instead of in ulps.
const ORIGIN: f32 = 1.0 / 32.0;
/// The fixed offset near the origin, per unit of normal.
const FLOAT_SCALE: f32 = 1.0 / 65536.0;
/// Ulps of offset per unit of normal.
const INT_SCALE: f32 = 256.0;

/// Moves `p` off its surface to the side of `n` (the geometric normal, oriented towards the side
/// the new ray leaves from; its length need not be one but should be close).
#[inline]
pub fn offset_ray_origin(p: Vec3, n: Vec3) -> Vec3 {
    let offset_ulps = |coordinate: f32, normal: f32| -> f32 {
        if coordinate.abs() < ORIGIN {
            return coordinate + FLOAT_SCALE * normal;
        }
        let ulps = (INT_SCALE * normal) as i32;
        let bits = coordinate.to_bits() as i32;
        // Moving away from zero adds ulps to the magnitude; towards zero removes them.
        let moved = if coordinate < 0.0 {
            bits - ulps
        } else {
            bits + ulps
        };
        f32::from_bits(moved as u32)
    };
    Vec3::new(
        offset_ulps(p.x, n.x),
        offset_ulps(p.y, n.y),
        offset_ulps(p.z, n.z),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_moves_to_the_side_of_the_normal() {
        for p in [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1000.0, -3.0, 0.01),
            Vec3::new(-5e5, 2e5, -1.0),
        ] {
            for n in [Vec3::X, -Vec3::Y, Vec3::new(0.6, 0.0, -0.8)] {
                let q = offset_ray_origin(p, n);
                assert!((q - p).dot(n) > 0.0, "{p} {n} -> {q}");
                // Small relative to the point's magnitude.
                assert!((q - p).length() <= 1e-4 * (1.0 + p.abs().max_element()));
            }
        }
    }
}
