//! The points a light subpath leaves for camera paths to gather: `sppm`'s photons and vertex
//! merging's light vertices ([`super::vcm`]), in a hash grid (Teschner et al. 2003's spatial
//! hash) for searches within a radius.

use glam::Vec3;

/// What a [`PhotonMap`] holds: anything with a position.
pub trait Located {
    fn position(&self) -> Vec3;
}

/// Points of one pass in a hash grid: cells of one size, hashed into as many buckets as there
/// are points. The map borrows the points and keeps, per bucket, their positions and indices
/// together in the order of the points, so a search reads contiguous positions, touches a
/// point only when it is within the radius, and visits the points in a fixed order.
pub struct PhotonMap<'a, P> {
    points: &'a [P],
    /// Each point's position and index, bucket by bucket.
    entries: Vec<(Vec3, u32)>,
    /// Where each bucket's entries start (one more entry than buckets).
    starts: Vec<u32>,
    cell_size: f32,
}

impl<'a, P: Located> PhotonMap<'a, P> {
    /// The map of `points` for searches within `largest_radius`: cells twice as wide, so that a
    /// search spans at most two cells per axis.
    pub fn new(points: &'a [P], largest_radius: f32) -> PhotonMap<'a, P> {
        let cell_size = 2.0 * largest_radius.max(f32::MIN_POSITIVE);
        let buckets = points.len().max(1);
        let mut starts = vec![0u32; buckets + 1];
        let bucket_of: Vec<usize> = points
            .iter()
            .map(|point| bucket(cell_of(point.position(), cell_size), buckets))
            .collect();
        for &b in &bucket_of {
            starts[b + 1] += 1;
        }
        for b in 0..buckets {
            starts[b + 1] += starts[b];
        }
        let mut next = starts.clone();
        let mut entries = vec![(Vec3::ZERO, 0u32); points.len()];
        for (i, (&b, point)) in bucket_of.iter().zip(points).enumerate() {
            entries[next[b] as usize] = (point.position(), i as u32);
            next[b] += 1;
        }
        PhotonMap {
            points,
            entries,
            starts,
            cell_size,
        }
    }

    /// Calls `f` for every point within `radius` (at most the largest radius the map was made
    /// for) of `p`, in a fixed order.
    pub fn for_each_near(&self, p: Vec3, radius: f32, mut f: impl FnMut(&P)) {
        let buckets = self.starts.len() - 1;
        let low = cell_of(p - Vec3::splat(radius), self.cell_size);
        let high = cell_of(p + Vec3::splat(radius), self.cell_size);
        // Two cells of the search may share a bucket: each bucket is visited once.
        let mut visit = [0usize; 8];
        let mut count = 0;
        for z in low[2]..=high[2] {
            for y in low[1]..=high[1] {
                for x in low[0]..=high[0] {
                    let b = bucket([x, y, z], buckets);
                    if count < visit.len() && !visit[..count].contains(&b) {
                        visit[count] = b;
                        count += 1;
                    }
                }
            }
        }
        let radius_squared = radius * radius;
        for &b in &visit[..count] {
            let range = self.starts[b] as usize..self.starts[b + 1] as usize;
            for &(position, index) in &self.entries[range] {
                if (position - p).length_squared() <= radius_squared {
                    f(&self.points[index as usize]);
                }
            }
        }
    }
}

/// The grid cell of `p`.
fn cell_of(p: Vec3, cell_size: f32) -> [i32; 3] {
    (p / cell_size).floor().as_ivec3().to_array()
}

/// The bucket of cell `cell` among `buckets`.
fn bucket(cell: [i32; 3], buckets: usize) -> usize {
    let [x, y, z] = cell.map(|c| c as u32 as u64);
    let h =
        (x.wrapping_mul(73_856_093)) ^ (y.wrapping_mul(19_349_663)) ^ (z.wrapping_mul(83_492_791));
    (h % buckets as u64) as usize
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::rng::Pcg32;

    struct Point {
        p: Vec3,
        id: u32,
    }

    impl Located for Point {
        fn position(&self) -> Vec3 {
            self.p
        }
    }

    /// A search of the map finds exactly the points a search of every point finds, in the
    /// points' order, in searches of radii up to the largest, over points spread across many
    /// cells (including negative coordinates).
    #[test]
    fn finds_what_a_brute_force_search_finds() {
        let mut rng = Pcg32::seeded(3);
        let point = |rng: &mut Pcg32| {
            Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 4.0 - Vec3::splat(2.0)
        };
        let points: Vec<Point> = (0..5000)
            .map(|id| Point {
                p: point(&mut rng),
                id,
            })
            .collect();
        let largest = 0.3;
        let map = PhotonMap::new(&points, largest);
        for _ in 0..500 {
            let p = point(&mut rng);
            let radius = largest * rng.next_f32();
            let mut found = Vec::new();
            map.for_each_near(p, radius, |point| found.push(point.id));
            found.sort_unstable();
            let expected: Vec<u32> = points
                .iter()
                .filter(|point| (point.p - p).length_squared() <= radius * radius)
                .map(|point| point.id)
                .collect();
            assert_eq!(found, expected, "search at {p} within {radius}");
        }
    }
}
