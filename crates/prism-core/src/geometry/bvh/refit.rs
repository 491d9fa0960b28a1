//! Refitting: the hierarchy kept, its primitives moved. The triangles' packs are written
//! again from the primitives' new places, then every box is recomputed bottom-up as the union
//! of its primitives' boxes (Wald, Boulos & Shirley 2007, "Ray Tracing Deformable Scenes Using
//! Dynamic Bounding Volume Hierarchies", §4). Unions of boxes are exact (minima and maxima), so
//! a refit to the places the tree was built for gives back the built tree bit for bit.
//!
//! A refit keeps the tree's topology, which was chosen for the old places: after large motions
//! (a rotation turns every box of a mesh; a shape moved far away stretches the boxes that
//! held it and its former neighbours) boxes grow and overlap, and rays test more of them. The
//! refit is refused when the tree's cost by the surface area heuristic (MacDonald & Booth
//! 1990), C = A(root)·c(root) + Σ A(child)·c(child) over every child of every node, exceeds
//! [`REFIT_COST_LIMIT`] times the cost the tree had when it was built; the caller then builds
//! a new hierarchy. The areas are not divided by the root's: the rays (from the same camera,
//! into the same room) stay where they were while the tree changes, so the probability that
//! one enters a box grows with the box's area alone. A shape moved far off is thus refit
//! rather than rebuilt only when its old neighbourhood is small in the tree's total.

use glam::Vec3;
use obvhs::aabb::Aabb;
use rayon::prelude::*;

use super::{
    ANALYTIC, Bvh, LANES_SHIFT, LEAF, LEAF_COST, Lanes, NODE_COST, NodeRef, PACK_INDEX_MASK,
};
use crate::geometry::triangle_pack::PACK_WIDTH;

/// A refit tree may cost this many times what it cost when built (by the surface area
/// heuristic; see [`Bvh::refit`]) before a new one is built instead.
pub const REFIT_COST_LIMIT: f64 = 1.25;

/// Where the primitives of a hierarchy are now, by the ids they were built with.
pub trait PrimitivePlaces: Sync {
    /// The vertices of triangle `id`; None when `id` is no longer a triangle to be hit.
    fn triangle(&self, id: u32) -> Option<[Vec3; 3]>;
    /// The box of analytic primitive `id`; None when `id` is no longer an analytic primitive.
    fn analytic_bounds(&self, id: u32) -> Option<(Vec3, Vec3)>;
}

impl Bvh {
    /// The hierarchy over the same primitives at their new `places`, its tree kept: None when
    /// a primitive it holds is not among `places` (the primitives changed, not only moved), or
    /// when the refit tree would cost more than [`REFIT_COST_LIMIT`] times the built one. The
    /// caller vouches that `places` holds no primitive the tree does not (as many of them).
    pub fn refit(mut self, places: &impl PrimitivePlaces) -> Option<Bvh> {
        // The triangles' boxes, by pack and lane, for the leaves' boxes below.
        let lane_boxes = (self.packs.par_iter_mut())
            .map(|pack| {
                let mut boxes = [Aabb::empty(); PACK_WIDTH];
                for (lane, lane_box) in boxes.iter_mut().enumerate() {
                    let id = pack.id[lane];
                    if id != u32::MAX {
                        let [a, b, c] = places.triangle(id)?;
                        pack.set(lane, [a, b, c], id);
                        *lane_box = Aabb::new(a.min(b).min(c).into(), a.max(b).max(c).into());
                    }
                }
                Some(boxes)
            })
            .collect::<Option<Vec<_>>>()?;
        // Children come after their parents (the tree is laid out depth first), so going
        // backwards meets every node after its children.
        let mut boxes = vec![Aabb::empty(); self.nodes.len()];
        for index in (0..self.nodes.len()).rev() {
            let mut node = self.nodes[index];
            let mut bounds = node.bounds.map(|lanes| lanes.to_array());
            let mut node_box = Aabb::empty();
            for (slot, &child) in node.children.iter().enumerate() {
                if bounds[0][slot] == f32::INFINITY && bounds[3][slot] == f32::NEG_INFINITY {
                    continue; // an empty slot
                }
                let child_box = if child.is_inner() {
                    debug_assert!(child.0 as usize > index, "children follow their parents");
                    boxes[child.0 as usize]
                } else {
                    self.leaf_box(child, &lane_boxes, places)?
                };
                for axis in 0..3 {
                    bounds[axis][slot] = child_box.min[axis];
                    bounds[3 + axis][slot] = child_box.max[axis];
                }
                node_box = node_box.union(&child_box);
            }
            node.bounds = bounds.map(Lanes::new);
            self.nodes[index] = node;
            boxes[index] = node_box;
        }
        let root_box = if self.root.is_inner() {
            boxes[self.root.0 as usize]
        } else {
            self.leaf_box(self.root, &lane_boxes, places)?
        };
        self.lo = Vec3::from(root_box.min);
        self.hi = Vec3::from(root_box.max);
        (self.sah_cost() <= REFIT_COST_LIMIT * self.built_cost).then_some(self)
    }

    /// The box around a leaf's primitives: the union of its triangles' boxes in
    /// `lane_boxes` (by pack and lane), or the analytic primitive's box from `places`.
    fn leaf_box(
        &self,
        leaf: NodeRef,
        lane_boxes: &[[Aabb; PACK_WIDTH]],
        places: &impl PrimitivePlaces,
    ) -> Option<Aabb> {
        if leaf.0 & ANALYTIC != 0 {
            let (lo, hi) = places.analytic_bounds(leaf.0 & !(LEAF | ANALYTIC))?;
            return Some(Aabb::new(lo.into(), hi.into()));
        }
        let boxes = &lane_boxes[(leaf.0 & PACK_INDEX_MASK) as usize];
        let lanes = (leaf.0 >> LANES_SHIFT) & 0xF;
        let leaf_box = (0..PACK_WIDTH)
            .filter(|lane| lanes & (1 << lane) != 0)
            .fold(Aabb::empty(), |union, lane| union.union(&boxes[lane]));
        Some(leaf_box)
    }

    /// The tree's cost by the surface area heuristic: A(root)·c(root) + Σ A(child)·c(child)
    /// over every child of every node, A being half a box's surface area and c [`NODE_COST`]
    /// for inner nodes and [`LEAF_COST`] for leaves.
    pub(super) fn sah_cost(&self) -> f64 {
        let half_area = |lo: Vec3, hi: Vec3| f64::from(Aabb::new(lo.into(), hi.into()).half_area());
        let cost_of = |r: NodeRef| f64::from(if r.is_inner() { NODE_COST } else { LEAF_COST });
        let mut children = 0.0;
        for node in &self.nodes {
            let bounds = node.bounds.map(|lanes| lanes.to_array());
            for (slot, &child) in node.children.iter().enumerate() {
                if bounds[0][slot] > bounds[3][slot] {
                    continue; // an empty slot
                }
                let lo = Vec3::new(bounds[0][slot], bounds[1][slot], bounds[2][slot]);
                let hi = Vec3::new(bounds[3][slot], bounds[4][slot], bounds[5][slot]);
                children += half_area(lo, hi) * cost_of(child);
            }
        }
        half_area(self.lo, self.hi) * cost_of(self.root) + children
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{random_unit, scene, sphere_hit};
    use super::super::{BuildPrimitive, NODE_WIDTH, PrimitiveKind};
    use super::*;
    use crate::geometry::triangle::WatertightRay;
    use crate::math::Ray;
    use crate::sampling::rng::Pcg32;

    /// Primitives by id, as the tests' scenes number them (id = index).
    struct Places<'a>(&'a [BuildPrimitive]);

    impl PrimitivePlaces for Places<'_> {
        fn triangle(&self, id: u32) -> Option<[Vec3; 3]> {
            match self.0.get(id as usize)?.kind {
                PrimitiveKind::Triangle(v) => Some(v),
                PrimitiveKind::Analytic { .. } => None,
            }
        }

        fn analytic_bounds(&self, id: u32) -> Option<(Vec3, Vec3)> {
            match self.0.get(id as usize)?.kind {
                PrimitiveKind::Analytic { lo, hi } => Some((lo, hi)),
                PrimitiveKind::Triangle(_) => None,
            }
        }
    }

    /// `primitives` with the first `count` turned by 0.02 radians about z and moved by
    /// `offset` (a rigid motion, as a changed transform gives).
    fn moved(primitives: &[BuildPrimitive], count: usize, offset: Vec3) -> Vec<BuildPrimitive> {
        let (sin, cos) = 0.02f32.sin_cos();
        let turn = |p: Vec3| Vec3::new(cos * p.x - sin * p.y, sin * p.x + cos * p.y, p.z) + offset;
        let mut moved = primitives.to_vec();
        for primitive in &mut moved[..count] {
            primitive.kind = match primitive.kind {
                PrimitiveKind::Triangle(v) => PrimitiveKind::Triangle(v.map(turn)),
                PrimitiveKind::Analytic { lo, hi } => PrimitiveKind::Analytic {
                    lo: lo + offset,
                    hi: hi + offset,
                },
            };
        }
        moved
    }

    fn bounds_of(bvh: &Bvh) -> Vec<[[f32; NODE_WIDTH]; 6]> {
        (bvh.nodes.iter())
            .map(|node| node.bounds.map(|lanes| lanes.to_array()))
            .collect()
    }

    /// A refit to the places the tree was built for gives back the same tree, bit for bit;
    /// refit to new places and back, too.
    #[test]
    fn a_refit_to_the_built_places_changes_nothing() {
        let mut rng = Pcg32::seeded(21);
        let (primitives, _) = scene(&mut rng, 3000);
        let built = Bvh::build(&primitives).unwrap();
        let same = built.clone().refit(&Places(&primitives)).unwrap();
        let away = moved(&primitives, 1000, Vec3::new(0.1, 0.0, 0.05));
        let back = (built.clone().refit(&Places(&away)).unwrap())
            .refit(&Places(&primitives))
            .unwrap();
        for refit in [same, back] {
            assert_eq!(bounds_of(&refit), bounds_of(&built));
            assert_eq!(
                (refit.root, refit.lo, refit.hi),
                (built.root, built.lo, built.hi)
            );
            for (a, b) in refit.packs.iter().zip(&built.packs) {
                assert_eq!(a.id, b.id);
                for lane in 0..PACK_WIDTH {
                    assert_eq!(a.vertices(lane), b.vertices(lane));
                }
            }
            assert_eq!(refit.sah_cost(), built.built_cost);
        }
    }

    /// After a refit every box holds all the primitives below it, and the closest hits and
    /// occlusion are those of testing every primitive at its new place.
    #[test]
    fn a_refit_tree_bounds_its_primitives_and_finds_the_closest_hits() {
        let mut rng = Pcg32::seeded(23);
        let triangles = 4000;
        let (primitives, spheres) = scene(&mut rng, triangles);
        let offset = Vec3::new(0.05, -0.03, 0.02);
        // The spheres (last) stay; a third of the triangles move.
        let places = moved(&primitives, triangles / 3, offset);
        let bvh = Bvh::build(&primitives)
            .unwrap()
            .refit(&Places(&places))
            .expect("a small motion keeps the tree");
        // Every triangle and sphere lies in every box on its way from the root.
        let inside = |lo: Vec3, hi: Vec3, p: Vec3| p.cmpge(lo).all() && p.cmple(hi).all();
        let mut seen = 0;
        let mut work = vec![(bvh.root, bvh.lo, bvh.hi)];
        while let Some((node, lo, hi)) = work.pop() {
            if node.is_inner() {
                let n = &bvh.nodes[node.0 as usize];
                let b = n.bounds.map(|lanes| lanes.to_array());
                for (slot, &child) in n.children.iter().enumerate() {
                    if b[0][slot] > b[3][slot] {
                        continue;
                    }
                    let child_lo = Vec3::new(b[0][slot], b[1][slot], b[2][slot]);
                    let child_hi = Vec3::new(b[3][slot], b[4][slot], b[5][slot]);
                    assert!(inside(lo, hi, child_lo) && inside(lo, hi, child_hi));
                    work.push((child, child_lo, child_hi));
                }
            } else if node.0 & ANALYTIC != 0 {
                let id = node.0 & !(LEAF | ANALYTIC);
                let (c, r) = spheres[id as usize - triangles];
                assert!(inside(lo, hi, c - r) && inside(lo, hi, c + r));
                seen += 1;
            } else {
                let pack = &bvh.packs[(node.0 & PACK_INDEX_MASK) as usize];
                let lanes = (node.0 >> LANES_SHIFT) & 0xF;
                for lane in (0..PACK_WIDTH).filter(|lane| lanes & (1 << lane) != 0) {
                    let PrimitiveKind::Triangle(v) = places[pack.id[lane] as usize].kind else {
                        unreachable!("packs hold triangles")
                    };
                    assert_eq!(pack.vertices(lane), v, "the pack holds the moved triangle");
                    assert!(v.iter().all(|&p| inside(lo, hi, p)));
                    seen += 1;
                }
            }
        }
        assert_eq!(seen, places.len(), "every primitive is below the root");
        let mut hits = 0;
        for k in 0..3000 {
            let o = random_unit(&mut rng) * 2.0;
            let aim = match places[k % places.len()].kind {
                PrimitiveKind::Triangle(v) => (v[0] + v[1] + v[2]) / 3.0,
                PrimitiveKind::Analytic { lo, hi } => (lo + hi) / 2.0,
            };
            let d = aim + random_unit(&mut rng) * 0.02 - o;
            let ray = Ray::new(o, d, f32::INFINITY, 0.0);
            let watertight = WatertightRay::new(o, d);
            let analytic =
                |id: u32, t_max: f32| sphere_hit(&ray, spheres[id as usize - triangles], t_max);
            let mut expected: Option<f32> = None;
            for p in &places {
                let limit = expected.unwrap_or(f32::INFINITY);
                let t = match p.kind {
                    PrimitiveKind::Triangle(v) => {
                        watertight.intersect(limit, v[0], v[1], v[2]).map(|h| h.t)
                    }
                    PrimitiveKind::Analytic { .. } => analytic(p.id, limit),
                };
                if let Some(t) = t.filter(|&t| t < limit) {
                    expected = Some(t);
                }
            }
            let found = bvh.closest_hit(&ray, &watertight, analytic);
            assert_eq!(found.map(|(_, h)| h.t), expected, "ray {k}");
            assert_eq!(
                bvh.occluded(&ray, &watertight, analytic),
                expected.is_some()
            );
            hits += usize::from(expected.is_some());
        }
        assert!(hits > 2000, "only {hits} of 3000 aimed rays hit");
    }

    /// A motion that spreads the tree's boxes across the scene is refused, and so is a
    /// primitive that changed kind.
    #[test]
    fn a_refit_is_refused_when_the_tree_gets_costly_or_the_primitives_change() {
        let mut rng = Pcg32::seeded(29);
        let (primitives, _) = scene(&mut rng, 3000);
        let built = Bvh::build(&primitives).unwrap();
        let far = moved(&primitives, 1500, Vec3::new(3.0, 0.0, 0.0));
        assert!(built.clone().refit(&Places(&far)).is_none());
        let mut changed = primitives.clone();
        changed[7].kind = PrimitiveKind::Analytic {
            lo: Vec3::ZERO,
            hi: Vec3::ONE,
        };
        assert!(built.refit(&Places(&changed)).is_none());
    }
}
