//! The inverse of a triangle mesh's texture parametrisation: which triangle covers a point
//! (u, v) of the unit square, as Mitsuba's `Mesh::eval_parameterization` finds it (there by
//! tracing a ray through a copy of the mesh laid out in uv space). Here a uniform grid over
//! [0, 1]² lists, per cell, the triangles whose uv bounding box meets it; a query tests those
//! candidates' uv barycentrics and returns the lowest-numbered triangle that contains the point,
//! so that a point covered by several triangles (overlapping uv charts) maps to one of them,
//! always the same.

use glam::Vec2;

/// Triangles found by their texture coordinates.
#[derive(Clone, Debug)]
pub struct UvGrid {
    /// Cells per side.
    resolution: usize,
    /// Cell c lists `triangles[starts[c]..starts[c + 1]]`, in increasing order.
    starts: Vec<u32>,
    triangles: Vec<u32>,
}

/// A triangle containing a uv point, with the point's barycentric coordinates in it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvHit {
    pub triangle: usize,
    pub barycentrics: [f32; 3],
}

/// Barycentric coordinates of `p` in the uv triangle `t`, if it lies inside (edges included)
/// and the triangle has non-zero uv area.
fn barycentrics(t: [Vec2; 3], p: Vec2) -> Option<[f32; 3]> {
    let (e1, e2, d) = (t[1] - t[0], t[2] - t[0], p - t[0]);
    let det = e1.perp_dot(e2);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let b1 = d.perp_dot(e2) / det;
    let b2 = e1.perp_dot(d) / det;
    let b0 = 1.0 - b1 - b2;
    (b0 >= 0.0 && b1 >= 0.0 && b2 >= 0.0).then_some([b0, b1, b2])
}

impl UvGrid {
    /// The grid over the triangles' texture coordinates (`uv_triangles[i]` are triangle i's
    /// three uv points), with about one triangle per cell and at most 1024² cells.
    pub fn new(uv_triangles: &[[Vec2; 3]]) -> UvGrid {
        let resolution = ((uv_triangles.len() as f64).sqrt().ceil() as usize).clamp(1, 1024);
        let n = resolution as f32;
        let cell_range = |lo: f32, hi: f32| -> Option<(usize, usize)> {
            if !(hi >= 0.0 && lo <= 1.0) {
                return None;
            }
            let first = ((lo.max(0.0) * n) as usize).min(resolution - 1);
            let last = ((hi.min(1.0) * n) as usize).min(resolution - 1);
            Some((first, last))
        };
        let footprint = |t: &[Vec2; 3]| -> Option<((usize, usize), (usize, usize))> {
            let lo = t[0].min(t[1]).min(t[2]);
            let hi = t[0].max(t[1]).max(t[2]);
            Some((cell_range(lo.x, hi.x)?, cell_range(lo.y, hi.y)?))
        };
        let mut counts = vec![0u32; resolution * resolution + 1];
        for t in uv_triangles {
            if let Some(((x0, x1), (y0, y1))) = footprint(t) {
                for y in y0..=y1 {
                    for x in x0..=x1 {
                        counts[y * resolution + x + 1] += 1;
                    }
                }
            }
        }
        for c in 1..counts.len() {
            counts[c] += counts[c - 1];
        }
        let starts = counts;
        let mut next = starts.clone();
        let mut triangles = vec![0u32; starts[resolution * resolution] as usize];
        for (i, t) in uv_triangles.iter().enumerate() {
            if let Some(((x0, x1), (y0, y1))) = footprint(t) {
                for y in y0..=y1 {
                    for x in x0..=x1 {
                        let slot = &mut next[y * resolution + x];
                        triangles[*slot as usize] = i as u32;
                        *slot += 1;
                    }
                }
            }
        }
        UvGrid {
            resolution,
            starts,
            triangles,
        }
    }

    /// The lowest-numbered triangle whose uv triangle contains `uv` (None outside [0, 1]² or
    /// where no triangle covers it). `uv_triangle(i)` gives triangle i's texture coordinates.
    pub fn find(&self, uv: Vec2, uv_triangle: impl Fn(usize) -> [Vec2; 3]) -> Option<UvHit> {
        if !(uv.x >= 0.0 && uv.x <= 1.0 && uv.y >= 0.0 && uv.y <= 1.0) {
            return None;
        }
        let n = self.resolution;
        let x = ((uv.x * n as f32) as usize).min(n - 1);
        let y = ((uv.y * n as f32) as usize).min(n - 1);
        let cell = y * n + x;
        let candidates =
            &self.triangles[self.starts[cell] as usize..self.starts[cell + 1] as usize];
        candidates.iter().find_map(|&i| {
            let i = i as usize;
            barycentrics(uv_triangle(i), uv).map(|barycentrics| UvHit {
                triangle: i,
                barycentrics,
            })
        })
    }

    /// Bytes of heap memory the grid holds.
    pub fn heap_bytes(&self) -> usize {
        (self.starts.capacity() + self.triangles.capacity()) * std::mem::size_of::<u32>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two triangles splitting the unit square along its diagonal, and a third overlapping the
    /// first: points are found in the right triangle, the overlap in the lower-numbered one.
    #[test]
    fn finds_the_lowest_covering_triangle() {
        let tris = [
            [Vec2::ZERO, Vec2::X, Vec2::ONE],
            [Vec2::ONE, Vec2::Y, Vec2::ZERO],
            [Vec2::new(0.5, 0.0), Vec2::X, Vec2::new(1.0, 0.5)],
        ];
        let grid = UvGrid::new(&tris);
        let find = |p: Vec2| grid.find(p, |i| tris[i]).map(|h| h.triangle);
        assert_eq!(find(Vec2::new(0.8, 0.1)), Some(0));
        assert_eq!(find(Vec2::new(0.1, 0.8)), Some(1));
        assert_eq!(find(Vec2::new(1.5, 0.5)), None);
        let hit = grid.find(Vec2::new(0.75, 0.25), |i| tris[i]).unwrap();
        let [b0, b1, b2] = hit.barycentrics;
        let back = tris[0][0] * b0 + tris[0][1] * b1 + tris[0][2] * b2;
        assert!((back - Vec2::new(0.75, 0.25)).length() < 1e-6);
    }
}
