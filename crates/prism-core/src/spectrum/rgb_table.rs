//! Fast upsampling of many RGB colours (the pixels of an image) to sigmoid polynomials.
//!
//! Fitting one colour ([`RgbSigmoidPolynomial::fit`]) takes about half a millisecond, far too
//! long for the million pixels of an environment map. Images are upsampled the way Mitsuba 3
//! upsamples them: each pixel's colour is divided by twice its largest component (so that the
//! largest component is exactly ½ and the spectrum is smooth) and the coefficients for that
//! normalised colour are interpolated in a precomputed table. Mitsuba interpolates a 64³ table
//! (Jakob & Hanika 2019, §5); here the largest component is always ½, so a table over the two
//! other components' ratios to it suffices: one N × N grid per channel that can be the largest.
//! Grid nodes are fitted on first use (in parallel by [`RgbTable::prepare`]) and kept for the
//! program's lifetime, so an image costs as many fits as it touches nodes.

use std::sync::OnceLock;

use rayon::prelude::*;

use super::rgb::RgbSigmoidPolynomial;

/// Nodes per axis of each channel's grid: ratios 0, 1/(N−1), …, 1.
const N: usize = 32;

/// The coefficients at every node, fitted on demand.
static NODES: [OnceLock<RgbSigmoidPolynomial>; 3 * N * N] = [const { OnceLock::new() }; 3 * N * N];

/// Where a normalised colour falls in the table: the channel that is largest, and the
/// fractional grid position of the two others.
#[derive(Clone, Copy, Debug)]
struct Position {
    largest: usize,
    /// The lower node on each axis.
    cell: [usize; 2],
    /// The fractions between the lower and upper node.
    fraction: [f32; 2],
}

/// The interpolated table of sigmoid-polynomial coefficients for colours with largest
/// component ½.
pub struct RgbTable;

impl RgbTable {
    fn position(rgb: [f32; 3]) -> Option<Position> {
        let largest = (0..3).max_by(|&a, &b| rgb[a].total_cmp(&rgb[b]))?;
        let max = rgb[largest];
        if !(max > 0.0) {
            return None;
        }
        let mut cell = [0; 2];
        let mut fraction = [0.0; 2];
        for axis in 0..2 {
            let ratio = (rgb[(largest + 1 + axis) % 3] / max).clamp(0.0, 1.0);
            let x = ratio * (N - 1) as f32;
            let lower = (x as usize).min(N - 2);
            cell[axis] = lower;
            fraction[axis] = x - lower as f32;
        }
        Some(Position {
            largest,
            cell,
            fraction,
        })
    }

    fn node_index(largest: usize, i: usize, j: usize) -> usize {
        (largest * N + j) * N + i
    }

    /// The colour with largest component ½ at a node.
    fn node_colour(index: usize) -> [f32; 3] {
        let largest = index / (N * N);
        let (j, i) = ((index / N) % N, index % N);
        let mut rgb = [0.0; 3];
        rgb[largest] = 0.5;
        rgb[(largest + 1) % 3] = 0.5 * i as f32 / (N - 1) as f32;
        rgb[(largest + 2) % 3] = 0.5 * j as f32 / (N - 1) as f32;
        rgb
    }

    fn node(index: usize) -> RgbSigmoidPolynomial {
        *NODES[index].get_or_init(|| RgbSigmoidPolynomial::fit(Self::node_colour(index)))
    }

    fn corners(p: &Position) -> [usize; 4] {
        let [i, j] = p.cell;
        [
            Self::node_index(p.largest, i, j),
            Self::node_index(p.largest, i + 1, j),
            Self::node_index(p.largest, i, j + 1),
            Self::node_index(p.largest, i + 1, j + 1),
        ]
    }

    /// Fits, in parallel, every node that [`Self::lookup`] will need for these colours.
    pub fn prepare(colours: impl Iterator<Item = [f32; 3]>) {
        let mut needed = vec![false; 3 * N * N];
        for rgb in colours {
            if let Some(p) = Self::position(rgb) {
                for index in Self::corners(&p) {
                    needed[index] = true;
                }
            }
        }
        (0..needed.len())
            .into_par_iter()
            .filter(|&i| needed[i])
            .for_each(|i| {
                Self::node(i);
            });
    }

    /// The coefficients for a colour whose largest component is ½ (Mitsuba's normalisation of
    /// an unbounded colour c: c / (2 max c)): bilinear interpolation of the coefficients at the
    /// four surrounding nodes, as Mitsuba interpolates its table. Black gives the zero spectrum.
    pub fn lookup(rgb: [f32; 3]) -> RgbSigmoidPolynomial {
        let Some(p) = Self::position(rgb) else {
            return RgbSigmoidPolynomial::constant(0.0);
        };
        let [c00, c10, c01, c11] = Self::corners(&p).map(Self::node);
        let [fx, fy] = p.fraction;
        let mix = |a: f32, b: f32, c: f32, d: f32| {
            (1.0 - fy) * ((1.0 - fx) * a + fx * b) + fy * ((1.0 - fx) * c + fx * d)
        };
        RgbSigmoidPolynomial {
            c0: mix(c00.c0, c10.c0, c01.c0, c11.c0),
            c1: mix(c00.c1, c10.c1, c01.c1, c11.c1),
            c2: mix(c00.c2, c10.c2, c01.c2, c11.c2),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::cie::{cie_xyz, d65_normalized, xyz_to_linear_srgb};
    use crate::spectrum::cie_tables::CIE_Y_INTEGRAL;

    /// Linear sRGB of a reflectance under D65 (1 nm Riemann sum).
    fn colour(poly: &RgbSigmoidPolynomial) -> [f32; 3] {
        let mut xyz = [0.0f64; 3];
        for l in 360..=830 {
            let l = l as f32;
            let v = f64::from(poly.eval(l) * d65_normalized(l));
            let cmf = cie_xyz(l);
            for c in 0..3 {
                xyz[c] += v * f64::from(cmf[c]) / CIE_Y_INTEGRAL;
            }
        }
        xyz_to_linear_srgb(xyz.map(|v| v as f32))
    }

    /// Interpolated coefficients reproduce colours between the nodes to within 0.4 % of the
    /// largest component (over 300 random colours the worst error was 0.24 %).
    #[test]
    fn interpolated_colours_are_close_to_their_targets() {
        let colours = [
            [0.5, 0.37, 0.21],
            [0.13, 0.5, 0.44],
            [0.29, 0.08, 0.5],
            [0.5, 0.49, 0.47],
            [0.5, 0.02, 0.3],
        ];
        RgbTable::prepare(colours.into_iter());
        for rgb in colours {
            let back = colour(&RgbTable::lookup(rgb));
            for c in 0..3 {
                assert!(
                    (back[c] - rgb[c]).abs() < 0.002,
                    "{rgb:?} comes back as {back:?}"
                );
            }
        }
        assert_eq!(RgbTable::lookup([0.0; 3]).eval(550.0), 0.0);
        assert!((RgbTable::lookup([0.5; 3]).eval(400.0) - 0.5).abs() < 1e-6);
    }
}
