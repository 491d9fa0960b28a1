//! The directional half of the SD-tree (Müller, Gross & Novák 2017, §3.2–3.3): a quadtree over
//! the unit square of the cylindrical mapping of the sphere, (x, y) = ((cos θ + 1)/2, φ/2π),
//! which preserves area up to the factor 4π, so a density p on the square is the solid-angle
//! density p / 4π.
//!
//! Every node holds the flux recorded in each of its four quadrants: the sum over the
//! recorded samples of L_i / p(ω) times their statistical weight (an estimate of the radiance
//! arriving through the quadrant, integrated over its solid angle). Sampling descends from the
//! root, choosing a quadrant in proportion to its flux; the density of a point is the product
//! over the levels of 4 × the chosen quadrant's share of its node's flux.
//!
//! Between iterations a tree is rebuilt from the previous one ([`DirectionalTree::refined`]):
//! a quadrant is split where it holds more than the fraction ρ (`dTreeThreshold`, 0.01) of
//! the total flux, up to depth 20, so the leaves hold comparable flux (§3.3).

use glam::Vec2;

use super::encoding::{Decoder, Encoder, Malformed};

/// The deepest level of a quadtree (the authors' limit).
pub const MAX_DEPTH: u32 = 20;

/// Bytes of a node in [`DirectionalTree::encode`]: four fluxes and four children.
const NODE_BYTES: usize = 4 * 8 + 4 * 4;

/// A node: the flux of each quadrant and the node that refines it (0 for a leaf quadrant: the
/// root is never a child). Quadrant i covers x ≥ ½ where bit 0 of i is set, y ≥ ½ where bit 1
/// is.
#[derive(Clone, Copy, Debug, Default)]
struct QuadNode {
    flux: [f64; 4],
    children: [u32; 4],
}

impl QuadNode {
    fn total(&self) -> f64 {
        self.flux.iter().sum()
    }
}

/// The quadrant of a node that `p` (in the node's unit square) falls in, and `p` in the
/// quadrant's unit square.
#[inline]
fn quadrant(p: Vec2) -> (usize, Vec2) {
    let mut index = 0;
    let mut q = p * 2.0;
    if p.x >= 0.5 {
        index |= 1;
        q.x -= 1.0;
    }
    if p.y >= 0.5 {
        index |= 2;
        q.y -= 1.0;
    }
    (index, q.clamp(Vec2::ZERO, Vec2::ONE))
}

/// A directional quadtree with its statistics.
#[derive(Clone, Debug)]
pub struct DirectionalTree {
    nodes: Vec<QuadNode>,
    /// The total flux, set by [`Self::build`].
    total: f64,
    /// The statistical weight of the samples recorded (their count, by default).
    weight: f64,
}

impl Default for DirectionalTree {
    /// The tree of one node with no flux: it samples the square uniformly.
    fn default() -> Self {
        DirectionalTree {
            nodes: vec![QuadNode::default()],
            total: 0.0,
            weight: 0.0,
        }
    }
}

impl DirectionalTree {
    /// The statistical weight of the samples recorded since the tree was made.
    pub fn weight(&self) -> f64 {
        self.weight
    }

    /// Sets the statistical weight (halved where a spatial leaf is split in two).
    pub fn set_weight(&mut self, weight: f64) {
        self.weight = weight;
    }

    /// Nodes in the tree.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Records a sample at `p` (unit square) with the value `flux` = L_i / p(ω) and statistical
    /// weight `weight`: the flux, times the weight, goes to the leaf quadrant holding `p`.
    pub fn record(&mut self, p: Vec2, flux: f32, weight: f32) {
        if !(weight.is_finite() && weight > 0.0) {
            return;
        }
        self.weight += f64::from(weight);
        if !(flux.is_finite() && flux > 0.0) {
            return;
        }
        let mut node = 0usize;
        let mut p = p.clamp(Vec2::ZERO, Vec2::ONE);
        loop {
            let (i, q) = quadrant(p);
            let child = self.nodes[node].children[i];
            if child == 0 {
                self.nodes[node].flux[i] += f64::from(flux) * f64::from(weight);
                return;
            }
            node = child as usize;
            p = q;
        }
    }

    /// Makes every inner quadrant's flux the sum of its children's (samples are recorded in
    /// the leaves), and the total that of the root.
    pub fn build(&mut self) {
        // Children always come after their parents: summing from the last node up settles
        // every child before its parent reads it.
        for node in (0..self.nodes.len()).rev() {
            for i in 0..4 {
                let child = self.nodes[node].children[i];
                if child != 0 {
                    self.nodes[node].flux[i] = self.nodes[child as usize].total();
                }
            }
        }
        self.total = self.nodes[0].total();
    }

    /// Whether the tree has flux to sample by; one without samples the square uniformly.
    fn has_flux(&self) -> bool {
        self.total > 0.0
    }

    /// The density (on the unit square) of sampling `p`.
    pub fn pdf(&self, p: Vec2) -> f32 {
        if !self.has_flux() {
            return 1.0;
        }
        let mut density = 1.0f64;
        let mut node = 0usize;
        let mut p = p.clamp(Vec2::ZERO, Vec2::ONE);
        loop {
            let n = &self.nodes[node];
            let (i, q) = quadrant(p);
            let total = n.total();
            if !(n.flux[i] > 0.0 && total > 0.0) {
                return 0.0;
            }
            density *= 4.0 * n.flux[i] / total;
            if n.children[i] == 0 {
                return density as f32;
            }
            node = n.children[i] as usize;
            p = q;
        }
    }

    /// A point of the unit square drawn with the density [`Self::pdf`] from the uniform `u`:
    /// at each level the quadrant's column by u.x and its row by u.y, each rescaled to [0, 1)
    /// for the next level (in double precision, so that 20 levels keep their resolution).
    pub fn sample(&self, u: Vec2) -> Vec2 {
        if !self.has_flux() {
            return u;
        }
        let (mut ux, mut uy) = (f64::from(u.x), f64::from(u.y));
        let mut origin = [0.0f64; 2];
        let mut size = 1.0f64;
        let mut node = 0usize;
        loop {
            let f = self.nodes[node].flux;
            let left = f[0] + f[2];
            let total = left + f[1] + f[3];
            if !(total > 0.0) {
                break;
            }
            size *= 0.5;
            // The column (bit 0): x < ½ holds quadrants 0 and 2.
            let (column, column_flux) = if ux * total < left {
                ux = ux * total / left;
                (0, left)
            } else {
                ux = (ux * total - left) / (total - left);
                origin[0] += size;
                (1, total - left)
            };
            // The row (bit 1) within the column.
            let top = f[column];
            let row = if uy * column_flux < top {
                uy = uy * column_flux / top;
                0
            } else {
                uy = (uy * column_flux - top) / (column_flux - top);
                origin[1] += size;
                1
            };
            ux = ux.clamp(0.0, 1.0f64.next_down());
            uy = uy.clamp(0.0, 1.0f64.next_down());
            let child = self.nodes[node].children[column | row << 1];
            if child == 0 {
                break;
            }
            node = child as usize;
        }
        Vec2::new(
            (origin[0] + size * ux) as f32,
            (origin[1] + size * uy) as f32,
        )
        .clamp(Vec2::ZERO, Vec2::ONE)
    }

    /// Appends the tree's bytes: its node count, each node's four fluxes and four children,
    /// its total flux and its weight.
    pub fn encode(&self, out: &mut Encoder) {
        out.length(self.nodes.len());
        for node in &self.nodes {
            for flux in node.flux {
                out.f64(flux);
            }
            for child in node.children {
                out.u32(child);
            }
        }
        out.f64(self.total);
        out.f64(self.weight);
    }

    /// Reads a tree [`Self::encode`] wrote: at least the root, every flux and weight finite and
    /// not negative, every child after its parent (so descents end) and within the tree.
    pub fn decode(input: &mut Decoder) -> Result<DirectionalTree, Malformed> {
        let count = input.length(NODE_BYTES, "quadtree nodes")?;
        if count == 0 {
            return Err("a quadtree has no root".into());
        }
        let mut nodes = Vec::with_capacity(count);
        for index in 0..count {
            let mut node = QuadNode::default();
            for flux in &mut node.flux {
                *flux = input.f64_at_least(0.0, "a quadrant's flux")?;
            }
            for child in &mut node.children {
                *child = input.u32()?;
                if *child != 0 && !(*child as usize > index && (*child as usize) < count) {
                    return Err(format!(
                        "quadtree node {index} of {count} names child {child}"
                    ));
                }
            }
            nodes.push(node);
        }
        let total = input.f64_at_least(0.0, "a quadtree's total flux")?;
        let weight = input.f64_at_least(0.0, "a quadtree's weight")?;
        Ok(DirectionalTree {
            nodes,
            total,
            weight,
        })
    }

    /// An empty tree (no flux, no weight) whose quadrants are those of `previous` refined by
    /// its flux: a quadrant holding more than `threshold` of `previous`'s total flux is split
    /// (a leaf quadrant's flux taken as spread evenly over its four children), to depth
    /// `max_depth`. Without flux the shares are those of the uniform distribution, 4⁻ᵈ at depth
    /// d.
    pub fn refined(previous: &DirectionalTree, threshold: f32, max_depth: u32) -> DirectionalTree {
        /// Where a new node's quadrants take their flux from.
        enum Source {
            /// A node of the previous tree.
            Node(usize),
            /// A leaf quadrant of the previous tree spread evenly: each quadrant's flux.
            Even(f64),
        }
        let total = previous.total;
        let threshold = f64::from(threshold);
        let mut nodes = vec![QuadNode::default()];
        let mut stack = vec![(0usize, Source::Node(0), 1u32)];
        while let Some((node, source, depth)) = stack.pop() {
            for i in 0..4 {
                let flux = match source {
                    Source::Node(n) => previous.nodes[n].flux[i],
                    Source::Even(flux) => flux,
                };
                let share = if total > 0.0 {
                    flux / total
                } else {
                    0.25f64.powi(depth as i32)
                };
                if depth >= max_depth || share <= threshold {
                    continue;
                }
                let child_source = match source {
                    Source::Node(n) if previous.nodes[n].children[i] != 0 => {
                        Source::Node(previous.nodes[n].children[i] as usize)
                    }
                    _ => Source::Even(flux / 4.0),
                };
                let child = nodes.len();
                nodes[node].children[i] = child as u32;
                nodes.push(QuadNode::default());
                stack.push((child, child_source, depth + 1));
            }
        }
        DirectionalTree {
            nodes,
            total: 0.0,
            weight: 0.0,
        }
    }

    /// The depth of the deepest quadrant.
    pub fn depth(&self) -> u32 {
        let mut deepest = 1;
        let mut stack = vec![(0usize, 1u32)];
        while let Some((node, depth)) = stack.pop() {
            deepest = deepest.max(depth);
            for &child in &self.nodes[node].children {
                if child != 0 {
                    stack.push((child as usize, depth + 1));
                }
            }
        }
        deepest
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::guided::{direction_to_square, square_to_direction};
    use crate::sampling::chi2::{Suite, chi2_from_counts, chi2_sphere};
    use crate::sampling::rng::Pcg32;
    use glam::Vec3;
    use std::f64::consts::PI;

    /// A tree trained on flux concentrated towards one lobe: three rounds of recording
    /// samples drawn from a lobe around +x slightly up, refining after each.
    fn trained_tree(seed: u64) -> DirectionalTree {
        let mut rng = Pcg32::new(seed, 7);
        let mut tree = DirectionalTree::refined(&DirectionalTree::default(), 0.01, MAX_DEPTH);
        for _ in 0..3 {
            for _ in 0..20_000 {
                let p = Vec2::new(
                    0.6 + 0.1 * rng.next_f32() * rng.next_f32(),
                    0.05 * rng.next_f32(),
                );
                tree.record(p, 1.0 + rng.next_f32(), 1.0);
                let q = Vec2::new(rng.next_f32(), rng.next_f32());
                tree.record(q, 0.05, 1.0);
            }
            tree.build();
            tree = DirectionalTree::refined(&tree, 0.01, 6);
        }
        for _ in 0..20_000 {
            let p = Vec2::new(0.6 + 0.1 * rng.next_f32(), 0.05 * rng.next_f32());
            tree.record(p, 1.0, 1.0);
            tree.record(Vec2::new(rng.next_f32(), rng.next_f32()), 0.05, 1.0);
        }
        tree.build();
        tree
    }

    const SUITE: Suite = Suite::new(&["quadtree"]);

    /// The quadtree's samples follow its density: a chi-square test on the 64 × 64 cells of
    /// the unit square, which the leaves (at most 6 levels deep, 1/64 wide) tile exactly, so a
    /// cell's expected count is N × its density at its centre / 64².
    #[test]
    fn quadtree_sampling_matches_its_density() {
        let tree = trained_tree(3);
        assert!(
            tree.depth() > 4,
            "the tree did not refine: {}",
            tree.depth()
        );
        let (n, cells) = (1_000_000usize, 64usize);
        let mut observed = vec![0.0f64; cells * cells];
        let mut rng = Pcg32::new(11, 3);
        for _ in 0..n {
            let p = tree.sample(Vec2::new(rng.next_f32(), rng.next_f32()));
            assert!(
                (0.0..=1.0).contains(&p.x) && (0.0..=1.0).contains(&p.y),
                "{p}"
            );
            let cell = |v: f32| ((v * cells as f32) as usize).min(cells - 1);
            observed[cell(p.y) * cells + cell(p.x)] += 1.0;
        }
        let expected: Vec<f64> = (0..cells * cells)
            .map(|i| {
                let centre = Vec2::new(
                    ((i % cells) as f32 + 0.5) / cells as f32,
                    ((i / cells) as f32 + 0.5) / cells as f32,
                );
                n as f64 * f64::from(tree.pdf(centre)) / (cells * cells) as f64
            })
            .collect();
        let outcome = chi2_from_counts(&observed, &expected).unwrap();
        SUITE.assert_passes("quadtree", &outcome);
    }

    /// The cylindrical mapping preserves area up to 4π: directions drawn uniformly on the
    /// square are uniform on the sphere (chi-square on 32 × 64 cells of cos θ and φ).
    #[test]
    fn cylindrical_mapping_is_uniform_on_the_sphere() {
        let outcome = chi2_sphere(
            200_000,
            32,
            64,
            5,
            |rng| {
                Some(square_to_direction(Vec2::new(
                    rng.next_f32(),
                    rng.next_f32(),
                )))
            },
            |_| 1.0 / (4.0 * PI),
        )
        .unwrap();
        MAPPING.assert_passes("mapping", &outcome);
        let d = Vec3::new(0.3, -0.4, 0.5).normalize();
        assert!((square_to_direction(direction_to_square(d)) - d).length() < 1e-5);
    }

    const MAPPING: Suite = Suite::new(&["mapping"]);

    /// The density integrates to one over the square (midpoint rule on the leaves' grid).
    #[test]
    fn quadtree_density_integrates_to_one() {
        let tree = trained_tree(5);
        let n = 256;
        let sum: f64 = (0..n * n)
            .map(|i| {
                let p = Vec2::new(
                    ((i % n) as f32 + 0.5) / n as f32,
                    ((i / n) as f32 + 0.5) / n as f32,
                );
                f64::from(tree.pdf(p))
            })
            .sum();
        let integral = sum / (n * n) as f64;
        assert!((integral - 1.0).abs() < 1e-4, "integral {integral}");
    }

    /// A quadrant is split where it holds more than ρ of the flux and not elsewhere. Without
    /// flux the uniform shares 4⁻ᵈ split the nodes of depths 1 to 3 (85 nodes, the deepest at
    /// depth 4). With all the flux in one corner, only the chain of nodes towards it is kept,
    /// and below the old tree's leaf there the flux, spread evenly, splits three levels more
    /// (4 + 1 + 4 + 16 + 64 nodes, the deepest at depth 8).
    #[test]
    fn refinement_follows_the_flux_fraction() {
        let uniform = DirectionalTree::refined(&DirectionalTree::default(), 0.01, MAX_DEPTH);
        assert_eq!(uniform.depth(), 4);
        assert_eq!(uniform.node_count(), 1 + 4 + 16 + 64);
        let mut one_corner = uniform.clone();
        one_corner.record(Vec2::new(0.01, 0.01), 1.0, 1.0);
        one_corner.build();
        let refined = DirectionalTree::refined(&one_corner, 0.01, MAX_DEPTH);
        assert_eq!(refined.depth(), 8);
        assert_eq!(refined.node_count(), 4 + 1 + 4 + 16 + 64);
    }
}
