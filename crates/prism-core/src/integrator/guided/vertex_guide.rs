//! The guide's distribution of directions at one vertex: its spatial leaf's quadtree
//! ([`DirectionalTree`]) over the sphere, folded onto the hemisphere the path arrived from
//! where the BSDF only reflects.
//!
//! A spatial leaf may hold surfaces of several orientations (a wall and the floor it meets,
//! both sides of a thin panel), and its quadtree then puts part of its mass behind the vertex's
//! surface, where a reflecting BSDF is zero and a guided sample would end the path. Folding
//! mirrors such a direction about the surface: with n the shading normal turned towards the
//! outgoing direction and M(ω) = ω − 2 (ω · n) n the reflection about the surface's plane, a
//! direction ω drawn from the quadtree is kept where ω · n > 0 and replaced by M(ω) where it is
//! behind. M is its own inverse and keeps solid angle, so the folded density is
//!
//!   p_fold(ω) = p(ω) + p(M(ω)) for ω · n > 0, and 0 behind,
//!
//! a density on the front hemisphere (it integrates to one there), covering all of it where the
//! quadtree covers the sphere. It is used only where the BSDF has no transmitting lobe, so the
//! mixture with the BSDF's own density keeps every direction the BSDF scatters into.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::quadtree::DirectionalTree;
use super::{direction_to_square, square_to_direction};

/// The guide's distribution at a vertex (see the module's text).
#[derive(Clone, Copy, Debug)]
pub struct VertexGuide<'a> {
    tree: &'a DirectionalTree,
    /// The unit normal of the front side, where the distribution is folded.
    front: Option<Vec3>,
}

impl<'a> VertexGuide<'a> {
    /// The quadtree `tree` over the whole sphere.
    pub fn sphere(tree: &'a DirectionalTree) -> Self {
        VertexGuide { tree, front: None }
    }

    /// The quadtree `tree` folded onto the hemisphere around the unit vector `front`.
    pub fn folded(tree: &'a DirectionalTree, front: Vec3) -> Self {
        VertexGuide {
            tree,
            front: Some(front),
        }
    }

    /// The quadtree's solid-angle density of `d`.
    #[inline]
    fn sphere_pdf(&self, d: Vec3) -> f32 {
        self.tree.pdf(direction_to_square(d)) / (4.0 * PI)
    }

    /// The solid-angle density of the unit direction `d`.
    #[inline]
    pub fn pdf(&self, d: Vec3) -> f32 {
        match self.front {
            None => self.sphere_pdf(d),
            Some(n) => {
                let cos = d.dot(n);
                if cos > 0.0 {
                    self.sphere_pdf(d) + self.sphere_pdf(d - 2.0 * cos * n)
                } else {
                    0.0
                }
            }
        }
    }

    /// A unit direction drawn with the density [`Self::pdf`] from the uniform `u`.
    #[inline]
    pub fn sample(&self, u: Vec2) -> Vec3 {
        let d = square_to_direction(self.tree.sample(u));
        match self.front {
            Some(n) if d.dot(n) < 0.0 => (d - 2.0 * d.dot(n) * n).normalize(),
            _ => d,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::chi2::{Suite, chi2_from_counts};
    use crate::sampling::rng::Pcg32;

    /// A quadtree trained on flux around two lobes, one on each side of the planes z = 0 and
    /// x = 0, over a faint uniform floor, its leaves at most 6 levels deep (1/64 of the square).
    fn two_lobe_tree(seed: u64) -> DirectionalTree {
        let mut rng = Pcg32::new(seed, 5);
        let mut tree = DirectionalTree::refined(&DirectionalTree::default(), 0.01, 6);
        for _ in 0..4 {
            for _ in 0..20_000 {
                let a = Vec2::new(0.7 + 0.1 * rng.next_f32(), 0.05 * rng.next_f32());
                tree.record(a, 1.0, 1.0);
                let b = Vec2::new(0.2 + 0.1 * rng.next_f32(), 0.55 + 0.05 * rng.next_f32());
                tree.record(b, 0.5, 1.0);
                tree.record(Vec2::new(rng.next_f32(), rng.next_f32()), 0.05, 1.0);
            }
            tree.build();
            if tree.depth() < 6 {
                tree = DirectionalTree::refined(&tree, 0.01, 6);
            }
        }
        tree
    }

    const SUITE: Suite = Suite::new(&["folded +z", "folded -z", "folded +x", "folded -x"]);

    /// Directions drawn from the folded guide follow its density: a chi-square test on the
    /// 64 × 64 cells of the unit square of the cylindrical mapping, which the quadtree's
    /// leaves (at most 6 levels deep) tile exactly. Folded about ±z or ±x, the mirror maps
    /// cells onto cells and the hemisphere's border runs along cells' borders, so the density
    /// is constant in each cell: its expected count is N × the density at its centre × the
    /// cell's solid angle 4π / 64².
    #[test]
    fn folded_guide_sampling_matches_its_density() {
        let tree = two_lobe_tree(9);
        assert!(tree.depth() >= 5, "the tree did not refine");
        let (n, cells) = (400_000usize, 64usize);
        let cell = |v: f32| ((v * cells as f32) as usize).min(cells - 1);
        for (name, front) in [
            ("folded +z", Vec3::Z),
            ("folded -z", Vec3::NEG_Z),
            ("folded +x", Vec3::X),
            ("folded -x", Vec3::NEG_X),
        ] {
            let guide = VertexGuide::folded(&tree, front);
            let mut rng = Pcg32::new(13, 2);
            let mut observed = vec![0.0f64; cells * cells];
            for _ in 0..n {
                let d = guide.sample(Vec2::new(rng.next_f32(), rng.next_f32()));
                assert!(d.dot(front) >= 0.0, "{name}: {d} behind the surface");
                let p = direction_to_square(d);
                observed[cell(p.y) * cells + cell(p.x)] += 1.0;
            }
            let expected: Vec<f64> = (0..cells * cells)
                .map(|i| {
                    let centre = Vec2::new(
                        ((i % cells) as f32 + 0.5) / cells as f32,
                        ((i / cells) as f32 + 0.5) / cells as f32,
                    );
                    let density = f64::from(guide.pdf(square_to_direction(centre)));
                    n as f64 * density * 4.0 * std::f64::consts::PI / (cells * cells) as f64
                })
                .collect();
            let outcome = chi2_from_counts(&observed, &expected).unwrap();
            SUITE.assert_passes(name, &outcome);
        }
    }

    /// The folded density integrates to one over the front hemisphere and the guide over the
    /// sphere is the quadtree's: midpoint rule on 256 × 256 cells of cos θ and φ.
    #[test]
    fn folded_density_integrates_to_one() {
        let tree = two_lobe_tree(4);
        let n = 256;
        let integral = |guide: VertexGuide| {
            let sum: f64 = (0..n * n)
                .map(|i| {
                    let p = Vec2::new(
                        ((i % n) as f32 + 0.5) / n as f32,
                        ((i / n) as f32 + 0.5) / n as f32,
                    );
                    f64::from(guide.pdf(square_to_direction(p)))
                })
                .sum();
            sum * 4.0 * std::f64::consts::PI / (n * n) as f64
        };
        for front in [Vec3::Z, Vec3::NEG_X, Vec3::new(0.3, -0.5, 0.8).normalize()] {
            let folded = integral(VertexGuide::folded(&tree, front));
            assert!((folded - 1.0).abs() < 2e-2, "{front}: {folded}");
        }
        let sphere = integral(VertexGuide::sphere(&tree));
        assert!((sphere - 1.0).abs() < 1e-4, "sphere: {sphere}");
    }
}
