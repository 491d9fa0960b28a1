//! The spatial half of the SD-tree (Müller, Gross & Novák 2017, §3.1): a binary tree over a
//! cube around the scene, each node split at its middle along x, y, z in turn, each leaf holding
//! two directional quadtrees ([`DirectionalTree`]): the one paths sample from (learned in the
//! previous iteration) and the one they record into.
//!
//! Unlike the authors' tree, a leaf holds such a pair for each of six orientation classes of
//! the surface's front side (the normal turned towards the outgoing direction, classed by its
//! dominant axis and that axis's sign, [`orientation`]): a vertex samples from and records into
//! its class's trees. A leaf holding surfaces that face apart (both sides of a thin panel, a
//! wall and the floor it meets) then learns their incident light apart; with one pair the
//! brighter side's light decides the trees, and the other side's guided samples go where its
//! BSDF is zero or its light is not.
//!
//! Between iterations ([`SdTree::refine`]) a leaf is split in two where the statistical weight
//! recorded in it (over its classes) exceeds c·√(2ᵏ) (§3.1; with the authors' code's scale, c = `sTreeThreshold`
//! × √(`sppPerPass` / 4) at iteration k, so the leaves' sample counts grow as the square root
//! of the iteration's samples); each half starts with a copy of the leaf's trees and half its
//! weight, and splits again while its weight exceeds the threshold. Then every leaf's recording
//! tree is rebuilt from its sampling tree's flux ([`DirectionalTree::refined`]), and at the end
//! of the iteration ([`SdTree::build`]) it becomes the sampling tree.

use glam::Vec3;

use super::Record;
use super::encoding::{Decoder, Encoder, Malformed};
use super::quadtree::{self, DirectionalTree};
use super::selection::{LearnedSelection, SelectionLoss};

/// The orientation classes a spatial leaf keeps apart: the dominant axis of the normal of the
/// surface's front side, and its sign.
pub const ORIENTATIONS: u32 = 6;

/// The orientation class of the unit normal `n`: 2 × the axis of its largest component, plus
/// 1 where that component is negative.
#[inline]
pub fn orientation(n: Vec3) -> u32 {
    let a = n.abs();
    let axis = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    2 * axis + u32::from(n[axis as usize] < 0.0)
}

/// A node of the spatial tree.
#[derive(Clone, Copy, Debug)]
enum SpatialNode {
    /// A leaf: the index of its first trees (one per orientation class follow), and the axis
    /// it would be split along.
    Leaf { trees: u32, axis: u8 },
    /// Split at the middle of `axis` into the lower and the upper half.
    Split { axis: u8, children: [u32; 2] },
}

/// The directional trees of a spatial leaf and its learned BSDF sampling fraction.
#[derive(Clone, Debug, Default)]
pub struct LeafTrees {
    /// Learned in the previous iteration: what paths sample from.
    pub sampling: DirectionalTree,
    /// What this iteration's paths record into.
    pub building: DirectionalTree,
    /// α where it is learned (`bsdfSamplingFractionLoss`).
    pub selection: LearnedSelection,
    /// The mean indirect radiance the leaf's vertices sent back along their paths, learned in
    /// the previous iteration (0 where none was recorded).
    reflected: f32,
    /// The statistical weight and the weighted sum of this iteration's records of it.
    reflected_sums: (f64, f64),
}

impl LeafTrees {
    /// The mean indirect radiance the leaf's vertices sent back along their paths, as learned
    /// in the previous iteration (0 where none was recorded): the L_o of the weight window
    /// ([`super::weight_window`]).
    #[inline]
    pub fn reflected(&self) -> f32 {
        self.reflected
    }
}

/// The trees found for a point and orientation: their index and the extent of their spatial
/// leaf.
#[derive(Clone, Copy, Debug)]
pub struct SpatialLeaf {
    pub index: u32,
    pub size: Vec3,
}

/// The SD-tree.
#[derive(Clone, Debug)]
pub struct SdTree {
    /// The lowest corner of the cube the tree covers.
    origin: Vec3,
    /// The cube's edge length.
    extent: f32,
    nodes: Vec<SpatialNode>,
    /// The trees of every spatial leaf, [`ORIENTATIONS`] consecutive ones per leaf.
    leaves: Vec<LeafTrees>,
}

impl SdTree {
    /// A tree of one leaf over the cube with lowest corner `lo` whose edge is the longest of
    /// the box (`lo`, `hi`) (the authors enlarge the scene's box to a cube, so the splits stay
    /// even).
    pub fn new(lo: Vec3, hi: Vec3) -> SdTree {
        let extent = (hi - lo).max_element().max(f32::MIN_POSITIVE);
        SdTree {
            origin: lo,
            extent,
            nodes: vec![SpatialNode::Leaf { trees: 0, axis: 0 }],
            leaves: vec![LeafTrees::default(); ORIENTATIONS as usize],
        }
    }

    /// The trees of orientation class `class` ([`orientation`]) in the leaf holding the point
    /// `p` (clamped into the cube).
    #[inline]
    pub fn leaf_at(&self, p: Vec3, class: u32) -> SpatialLeaf {
        let mut q = ((p - self.origin) / self.extent).clamp(Vec3::ZERO, Vec3::ONE);
        let mut size = Vec3::splat(self.extent);
        let mut node = 0usize;
        loop {
            match self.nodes[node] {
                SpatialNode::Leaf { trees, .. } => {
                    return SpatialLeaf {
                        index: trees + class,
                        size,
                    };
                }
                SpatialNode::Split { axis, children } => {
                    let axis = axis as usize;
                    size[axis] *= 0.5;
                    let upper = q[axis] >= 0.5;
                    q[axis] = (q[axis] * 2.0 - if upper { 1.0 } else { 0.0 }).clamp(0.0, 1.0);
                    node = children[usize::from(upper)] as usize;
                }
            }
        }
    }

    /// The point `p` clamped into the cube the tree covers.
    pub fn clamp(&self, p: Vec3) -> Vec3 {
        p.clamp(self.origin, self.origin + Vec3::splat(self.extent))
    }

    /// The trees of leaf `index`.
    #[inline]
    pub fn leaf(&self, index: u32) -> &LeafTrees {
        &self.leaves[index as usize]
    }

    /// Files `record` into its leaf: its flux into the building tree, its reflected radiance
    /// into the leaf's mean and, under `loss`, its gradient into the leaf's learned α.
    pub fn file(&mut self, record: &Record, loss: SelectionLoss) {
        let leaf = &mut self.leaves[record.leaf as usize];
        leaf.building
            .record(record.point, record.flux, record.weight);
        if let Some(reflected) = record.reflected
            && reflected.is_finite()
        {
            let weight = f64::from(record.weight);
            leaf.reflected_sums.0 += weight;
            leaf.reflected_sums.1 += weight * f64::from(reflected);
        }
        if let Some(sample) = &record.selection {
            leaf.selection.train(sample, loss);
        }
    }

    /// Spatial leaves.
    pub fn leaf_count(&self) -> usize {
        self.leaves.len() / ORIENTATIONS as usize
    }

    /// The statistical weight recorded in the leaf whose trees start at `trees`, over its
    /// orientation classes.
    fn recorded_weight(&self, trees: u32) -> f64 {
        let first = trees as usize;
        self.leaves[first..first + ORIENTATIONS as usize]
            .iter()
            .map(|t| t.building.weight())
            .sum()
    }

    /// About how many bytes the directional trees take.
    fn footprint(&self) -> usize {
        let per_node = 48;
        self.leaves
            .iter()
            .map(|l| (l.sampling.node_count() + l.building.node_count()) * per_node)
            .sum()
    }

    /// Prepares the tree for an iteration (see the module's text): splits the leaves whose
    /// recorded weight exceeds `threshold` (unless the trees already take `max_bytes`), then
    /// rebuilds every leaf's recording tree from its sampling tree, refined at the flux
    /// fraction `flux_fraction`.
    pub fn refine(&mut self, threshold: f64, flux_fraction: f32, max_bytes: Option<usize>) {
        if max_bytes.is_none_or(|max| self.footprint() < max) {
            let mut stack = vec![0usize];
            while let Some(node) = stack.pop() {
                if let SpatialNode::Leaf { trees, axis } = self.nodes[node]
                    && self.recorded_weight(trees) > threshold
                {
                    self.split(node, trees, axis);
                }
                if let SpatialNode::Split { children, .. } = self.nodes[node] {
                    stack.extend(children.map(|c| c as usize));
                }
            }
        }
        for leaf in &mut self.leaves {
            leaf.building =
                DirectionalTree::refined(&leaf.sampling, flux_fraction, quadtree::MAX_DEPTH);
        }
    }

    /// Splits leaf node `node` (holding the trees from `index`) in two along `axis`: both
    /// halves get its trees with half the recorded weight, and split along the next axis.
    fn split(&mut self, node: usize, index: u32, axis: u8) {
        let upper = self.leaves.len() as u32;
        for class in 0..ORIENTATIONS {
            let trees = &mut self.leaves[(index + class) as usize];
            let weight = trees.building.weight() * 0.5;
            trees.building.set_weight(weight);
            let copy = trees.clone();
            self.leaves.push(copy);
        }
        let lower_node = self.nodes.len() as u32;
        let next = (axis + 1) % 3;
        self.nodes.push(SpatialNode::Leaf {
            trees: index,
            axis: next,
        });
        self.nodes.push(SpatialNode::Leaf {
            trees: upper,
            axis: next,
        });
        self.nodes[node] = SpatialNode::Split {
            axis,
            children: [lower_node, lower_node + 1],
        };
    }

    /// Ends an iteration: every leaf's recorded tree, its sums built, becomes the tree paths
    /// sample from, and the mean of its recorded reflected radiance the one they read.
    pub fn build(&mut self) {
        for leaf in &mut self.leaves {
            leaf.building.build();
            leaf.sampling = leaf.building.clone();
            let (weight, sum) = std::mem::take(&mut leaf.reflected_sums);
            leaf.reflected = if weight > 0.0 {
                (sum / weight) as f32
            } else {
                0.0
            };
        }
    }
}

/// The fewest bytes a leaf's trees take in [`SdTree::encode`]: two quadtrees of one node, the
/// learned α, the reflected radiance and its sums.
const LEAF_TREES_BYTES: usize = 2 * (8 + 48 + 16) + 28 + 4 + 16;
/// The fewest bytes a spatial node takes (a leaf).
const NODE_BYTES: usize = 6;

impl LeafTrees {
    fn encode(&self, out: &mut Encoder) {
        self.sampling.encode(out);
        self.building.encode(out);
        self.selection.encode(out);
        out.f32(self.reflected);
        out.f64(self.reflected_sums.0);
        out.f64(self.reflected_sums.1);
    }

    fn decode(input: &mut Decoder) -> Result<LeafTrees, Malformed> {
        Ok(LeafTrees {
            sampling: DirectionalTree::decode(input)?,
            building: DirectionalTree::decode(input)?,
            selection: LearnedSelection::decode(input)?,
            reflected: input.f32_at_least(f32::MIN, "a leaf's reflected radiance")?,
            reflected_sums: (
                input.f64_at_least(0.0, "a leaf's recorded weight")?,
                input.f64_at_least(f64::MIN, "a leaf's sum of reflected radiance")?,
            ),
        })
    }
}

impl SdTree {
    /// Appends the tree's bytes: its cube, every leaf's trees (sampling and recording
    /// quadtrees, learned α, reflected radiance and its sums), then the spatial nodes.
    pub fn encode(&self, out: &mut Encoder) {
        for v in self.origin.to_array() {
            out.f32(v);
        }
        out.f32(self.extent);
        out.length(self.leaves.len());
        for leaf in &self.leaves {
            leaf.encode(out);
        }
        out.length(self.nodes.len());
        for node in &self.nodes {
            match *node {
                SpatialNode::Leaf { trees, axis } => {
                    out.u8(0);
                    out.u32(trees);
                    out.u8(axis);
                }
                SpatialNode::Split { axis, children } => {
                    out.u8(1);
                    out.u8(axis);
                    out.u32(children[0]);
                    out.u32(children[1]);
                }
            }
        }
    }

    /// Reads a tree [`Self::encode`] wrote, checking that its cube is finite, that its leaves
    /// come in whole orientation classes, that every node's children come after it and within
    /// the tree, and that every leaf node's trees exist.
    pub fn decode(input: &mut Decoder) -> Result<SdTree, Malformed> {
        let mut origin = [0.0; 3];
        for v in &mut origin {
            *v = input.f32_at_least(f32::MIN, "the SD-tree's corner")?;
        }
        let extent = input.f32_at_least(f32::MIN_POSITIVE, "the SD-tree's extent")?;
        let leaf_count = input.length(LEAF_TREES_BYTES, "leaf trees")?;
        if leaf_count == 0 || !leaf_count.is_multiple_of(ORIENTATIONS as usize) {
            return Err(format!(
                "it holds {leaf_count} leaf trees, not a positive multiple of {ORIENTATIONS}"
            ));
        }
        let mut leaves = Vec::with_capacity(leaf_count);
        for _ in 0..leaf_count {
            leaves.push(LeafTrees::decode(input)?);
        }
        let node_count = input.length(NODE_BYTES, "spatial nodes")?;
        if node_count == 0 {
            return Err("the spatial tree has no root".into());
        }
        let mut nodes = Vec::with_capacity(node_count);
        for index in 0..node_count {
            let node = match input.u8()? {
                0 => {
                    let trees = input.u32()?;
                    let axis = input.u8()?;
                    let fits = (trees as usize)
                        .checked_add(ORIENTATIONS as usize)
                        .is_some_and(|end| end <= leaf_count);
                    if !fits || !trees.is_multiple_of(ORIENTATIONS) || axis > 2 {
                        return Err(format!(
                            "spatial leaf {index} names trees {trees} of {leaf_count} and axis {axis}"
                        ));
                    }
                    SpatialNode::Leaf { trees, axis }
                }
                1 => {
                    let axis = input.u8()?;
                    let children = [input.u32()?, input.u32()?];
                    let within = |c: u32| c as usize > index && (c as usize) < node_count;
                    if axis > 2 || !children.iter().all(|&c| within(c)) {
                        return Err(format!(
                            "spatial node {index} of {node_count} splits axis {axis} into nodes {} and {}",
                            children[0], children[1]
                        ));
                    }
                    SpatialNode::Split { axis, children }
                }
                tag => return Err(format!("spatial node {index} is of kind {tag}")),
            };
            nodes.push(node);
        }
        Ok(SdTree {
            origin: Vec3::from_array(origin),
            extent,
            nodes,
            leaves,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;

    /// A trained tree (small quadtrees: ρ = 0.3) comes back from its bytes the same (it
    /// encodes the same and samples the same); every truncation, and indices out of range, are
    /// refused without a panic.
    #[test]
    fn a_tree_round_trips_through_its_bytes() {
        let mut tree = SdTree::new(Vec3::ZERO, Vec3::ONE);
        tree.refine(0.0, 0.3, None);
        for i in 0..200 {
            let record = Record {
                leaf: (i % 12) as u32 % ORIENTATIONS,
                point: Vec2::new((i as f32 * 0.37).fract(), (i as f32 * 0.61).fract()),
                flux: 1.0 + (i % 7) as f32,
                reflected: Some(0.5),
                weight: 1.0,
                selection: None,
            };
            tree.file(&record, SelectionLoss::None);
        }
        tree.build();
        tree.refine(30.0, 0.3, None);
        let mut out = Encoder::default();
        tree.encode(&mut out);
        assert!(tree.leaf_count() > 1 && out.bytes.len() < 20_000);
        let mut input = Decoder::new(&out.bytes);
        let decoded = SdTree::decode(&mut input).unwrap();
        input.finish().unwrap();
        let mut again = Encoder::default();
        decoded.encode(&mut again);
        assert_eq!(again.bytes, out.bytes);
        assert_eq!(decoded.leaf_count(), tree.leaf_count());
        let p = Vec2::new(0.3, 0.8);
        let a = tree.leaf_at(Vec3::splat(0.2), 1).index;
        assert_eq!(
            decoded.leaf(a).sampling.pdf(p),
            tree.leaf(a).sampling.pdf(p)
        );
        for n in 0..out.bytes.len() {
            assert!(SdTree::decode(&mut Decoder::new(&out.bytes[..n])).is_err());
        }
        // The last node's tree index, beyond the leaves.
        let mut damaged = out.bytes.clone();
        let at = damaged.len() - 5;
        damaged[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
        let error = SdTree::decode(&mut Decoder::new(&damaged)).unwrap_err();
        assert!(error.contains("names trees"), "{error}");
    }

    /// A leaf with more recorded weight than the threshold splits, and its halves split again
    /// while half the weight still exceeds it; points find the leaf of their octant.
    #[test]
    fn leaves_split_by_recorded_weight() {
        let mut tree = SdTree::new(Vec3::ZERO, Vec3::new(2.0, 1.0, 1.0));
        tree.refine(0.0, 0.01, None);
        let record = Record {
            leaf: 0,
            point: Vec2::splat(0.5),
            flux: 1.0,
            reflected: None,
            weight: 1.0,
            selection: None,
        };
        for _ in 0..100 {
            tree.file(&record, SelectionLoss::None);
        }
        tree.build();
        // 100 > 30: split in x (50 each), again in y (25 each), then no more.
        tree.refine(30.0, 0.01, None);
        assert_eq!(tree.leaf_count(), 4);
        let a = tree.leaf_at(Vec3::new(0.1, 0.1, 0.1), 0);
        let b = tree.leaf_at(Vec3::new(1.9, 0.1, 0.1), 0);
        let c = tree.leaf_at(Vec3::new(0.1, 1.9, 1.9), 0);
        assert_ne!(a.index, b.index);
        assert_ne!(a.index, c.index);
        assert_eq!(a.size, Vec3::new(1.0, 1.0, 2.0));
        // The sampling trees are the parent's.
        assert!(tree.leaf(a.index).sampling.pdf(Vec2::splat(0.5)) > 1.0);
    }

    /// A leaf's reflected radiance is the weighted mean of its records' from the iteration
    /// built last (records without one left out), and 0 where an iteration recorded none.
    #[test]
    fn reflected_radiance_is_the_mean_of_the_last_iterations_records() {
        let mut tree = SdTree::new(Vec3::ZERO, Vec3::ONE);
        tree.refine(1e9, 0.01, None);
        let record = |reflected, weight| Record {
            leaf: 0,
            point: Vec2::splat(0.5),
            flux: 1.0,
            reflected,
            weight,
            selection: None,
        };
        for r in [
            record(Some(1.0), 1.0),
            record(Some(4.0), 0.5),
            record(None, 1.0),
            record(Some(f32::NAN), 1.0),
        ] {
            tree.file(&r, SelectionLoss::None);
        }
        assert_eq!(tree.leaf(0).reflected(), 0.0);
        tree.build();
        assert_eq!(tree.leaf(0).reflected(), 2.0);
        tree.refine(1e9, 0.01, None);
        tree.build();
        assert_eq!(tree.leaf(0).reflected(), 0.0);
    }

    /// Records of the two sides of a surface go to trees of their own in the same leaf, and
    /// the leaf splits by the weight of both; the classes are the normal's dominant axis and
    /// sign.
    #[test]
    fn orientation_classes_keep_apart_in_a_leaf() {
        assert_eq!(orientation(Vec3::X), 0);
        assert_eq!(orientation(Vec3::new(-0.8, 0.6, 0.0)), 1);
        assert_eq!(orientation(Vec3::new(0.1, 0.9, -0.4)), 2);
        assert_eq!(orientation(Vec3::NEG_Y), 3);
        assert_eq!(orientation(Vec3::new(0.5, 0.4, 0.76)), 4);
        assert_eq!(orientation(Vec3::NEG_Z), 5);
        let mut tree = SdTree::new(Vec3::ZERO, Vec3::ONE);
        tree.refine(0.0, 0.01, None);
        let p = Vec3::splat(0.25);
        let (up, down) = (tree.leaf_at(p, 2), tree.leaf_at(p, 3));
        assert_ne!(up.index, down.index);
        for (leaf, point) in [(up, Vec2::new(0.9, 0.5)), (down, Vec2::new(0.1, 0.5))] {
            let record = Record {
                leaf: leaf.index,
                point,
                flux: 1.0,
                reflected: None,
                weight: 1.0,
                selection: None,
            };
            for _ in 0..20 {
                tree.file(&record, SelectionLoss::None);
            }
        }
        tree.build();
        assert!(tree.leaf(up.index).sampling.pdf(Vec2::new(0.9, 0.5)) > 10.0);
        assert_eq!(tree.leaf(up.index).sampling.pdf(Vec2::new(0.1, 0.5)), 0.0);
        assert!(tree.leaf(down.index).sampling.pdf(Vec2::new(0.1, 0.5)) > 10.0);
        // 40 records exceed 30 where 20 would not: the leaf splits, its classes together.
        tree.refine(30.0, 0.01, None);
        assert_eq!(tree.leaf_count(), 2);
        let lower = tree.leaf_at(p, 3);
        let upper = tree.leaf_at(Vec3::new(0.75, 0.25, 0.25), 3);
        assert_ne!(lower.index, upper.index);
        assert!(tree.leaf(upper.index).sampling.pdf(Vec2::new(0.1, 0.5)) > 10.0);
    }
}
