//! A continuous 2D distribution on [0, 1]² that interpolates a grid of values bilinearly and may
//! depend on further parameters (interpolated linearly between the grids tabulated for them):
//! Mitsuba 3's `Marginal2D<Float, Dimension, Continuous = true>` (`include/mitsuba/core/distr_2d.h`),
//! which its `measured` BSDF samples and evaluates.
//!
//! A grid of w × h values v (x fastest) spans the unit square in (w − 1) × (h − 1) bilinear
//! patches. Sampling inverts the marginal CDF of y, which is piecewise quadratic (the integral
//! over x of the interpolant is linear between rows), then the conditional CDF of x at that y
//! (linear between the two rows' CDFs): the map is continuous, and `invert` is its exact
//! inverse. Several grids (one per combination of parameter nodes) are stored one after the
//! other, the first parameter slowest; a query interpolates every table (values and CDFs)
//! multilinearly between the nodes around its parameters, clamped to their range.

use arrayvec::ArrayVec;
use glam::Vec2;

/// The most parameters a distribution depends on.
pub const MAX_PARAMETERS: usize = 3;

/// Parameter-space corners of a query: the grid index of each and its weight.
type Corners = ArrayVec<(usize, f32), { 1 << MAX_PARAMETERS }>;

#[derive(Clone, Debug)]
pub struct Marginal2D {
    /// Grid resolution (w, h).
    width: usize,
    height: usize,
    /// The nodes of each parameter, increasing.
    parameters: Vec<Vec<f32>>,
    /// The values, one grid after another (normalised when the distribution is).
    data: Vec<f32>,
    /// Per grid: the marginal CDF of y at rows 1..h ((h − 1) values), and per row the
    /// conditional CDF of x at columns 1..w (h × (w − 1) values); empty without sampling.
    marginal_cdf: Vec<f32>,
    conditional_cdf: Vec<f32>,
    normalized: bool,
}

/// Why a table cannot be a distribution.
#[derive(Clone, Debug, PartialEq)]
pub enum Marginal2DError {
    /// A grid needs at least 2 × 2 values, and a parameter at least one node.
    TooSmall,
    /// The data's length is not the product of the resolutions.
    WrongLength { expected: usize, found: usize },
    /// A parameter's nodes are not increasing.
    UnsortedParameter(usize),
    /// A grid to be sampled holds a negative value or integrates to zero.
    NotADensity(usize),
}

impl std::fmt::Display for Marginal2DError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Marginal2DError::TooSmall => {
                write!(
                    f,
                    "a grid needs at least 2 × 2 values and a parameter one node"
                )
            }
            Marginal2DError::WrongLength { expected, found } => {
                write!(
                    f,
                    "{found} values where the resolutions call for {expected}"
                )
            }
            Marginal2DError::UnsortedParameter(i) => {
                write!(f, "the nodes of parameter {i} do not increase")
            }
            Marginal2DError::NotADensity(slice) => write!(
                f,
                "grid {slice} holds a negative value or integrates to zero, so it cannot be sampled"
            ),
        }
    }
}

impl Marginal2D {
    /// The distribution of `data`, grids of `width` × `height` values for each combination of
    /// the `parameters`' nodes. With `normalize`, each grid is scaled to integrate to 1 (its
    /// values are then densities); with `sampling`, the CDFs that `sample` and `invert` need
    /// are built, which requires non-negative grids of nonzero integral.
    pub fn new(
        data: &[f32],
        width: usize,
        height: usize,
        parameters: Vec<Vec<f32>>,
        normalize: bool,
        sampling: bool,
    ) -> Result<Marginal2D, Marginal2DError> {
        if width < 2 || height < 2 || parameters.iter().any(Vec::is_empty) {
            return Err(Marginal2DError::TooSmall);
        }
        assert!(parameters.len() <= MAX_PARAMETERS);
        if let Some(i) = parameters
            .iter()
            .position(|nodes| nodes.windows(2).any(|w| !(w[0] < w[1])))
        {
            return Err(Marginal2DError::UnsortedParameter(i));
        }
        let slices: usize = parameters.iter().map(Vec::len).product();
        let n = width * height;
        if data.len() != slices * n {
            return Err(Marginal2DError::WrongLength {
                expected: slices * n,
                found: data.len(),
            });
        }
        let (scale_x, scale_y) = (0.5 / (width - 1) as f64, 0.5 / (height - 1) as f64);
        let mut out = Vec::with_capacity(data.len());
        let (mut marginal_cdf, mut conditional_cdf) = (Vec::new(), Vec::new());
        for (slice, grid) in data.chunks_exact(n).enumerate() {
            let mut row_sums = Vec::with_capacity(height);
            let conditional_start = conditional_cdf.len();
            let marginal_start = marginal_cdf.len();
            for row in grid.chunks_exact(width) {
                let mut accumulated = 0.0f64;
                for x in 0..width - 1 {
                    accumulated += scale_x * (f64::from(row[x]) + f64::from(row[x + 1]));
                    if sampling {
                        conditional_cdf.push(accumulated as f32);
                    }
                }
                row_sums.push(accumulated);
            }
            let mut total = 0.0f64;
            for y in 0..height - 1 {
                total += scale_y * (row_sums[y] + row_sums[y + 1]);
                if sampling {
                    marginal_cdf.push(total as f32);
                }
            }
            if sampling && !(total > 0.0 && grid.iter().all(|&v| v >= 0.0)) {
                return Err(Marginal2DError::NotADensity(slice));
            }
            let norm = if normalize && total > 0.0 {
                (1.0 / total) as f32
            } else {
                1.0
            };
            for v in &mut conditional_cdf[conditional_start..] {
                *v *= norm;
            }
            for v in &mut marginal_cdf[marginal_start..] {
                *v *= norm;
            }
            out.extend(grid.iter().map(|&v| v * norm));
        }
        Ok(Marginal2D {
            width,
            height,
            parameters,
            data: out,
            marginal_cdf,
            conditional_cdf,
            normalized: normalize,
        })
    }

    /// The grids around `params` and their weights (Mitsuba's `interpolate_weights`): per
    /// parameter, the interval of nodes holding it (the first or last beyond the range) and
    /// the weight of its upper node, clamped to [0, 1].
    fn corners(&self, params: &[f32]) -> Corners {
        let mut corners = Corners::new();
        corners.push((0, 1.0));
        let mut stride = 1;
        for (nodes, &value) in self.parameters.iter().zip(params).rev() {
            if nodes.len() > 1 {
                let i = nodes
                    .partition_point(|&node| node < value)
                    .saturating_sub(1)
                    .min(nodes.len() - 2);
                let t = ((value - nodes[i]) / (nodes[i + 1] - nodes[i])).clamp(0.0, 1.0);
                let count = corners.len();
                for c in 0..count {
                    let (index, weight) = corners[c];
                    corners[c] = (index + i * stride, weight * (1.0 - t));
                    corners.push((index + (i + 1) * stride, weight * t));
                }
            }
            stride *= nodes.len();
        }
        corners
    }

    /// Entry `offset` of a table whose grids hold `size` entries each, interpolated between
    /// the corners.
    #[inline]
    fn lookup(table: &[f32], size: usize, offset: usize, corners: &Corners) -> f32 {
        corners
            .iter()
            .map(|&(slice, weight)| weight * table[slice * size + offset])
            .sum()
    }

    fn value(&self, corners: &Corners, offset: usize) -> f32 {
        Self::lookup(&self.data, self.width * self.height, offset, corners)
    }

    fn marginal(&self, corners: &Corners, row: usize) -> f32 {
        Self::lookup(&self.marginal_cdf, self.height - 1, row, corners)
    }

    fn conditional(&self, corners: &Corners, offset: usize) -> f32 {
        Self::lookup(
            &self.conditional_cdf,
            self.height * (self.width - 1),
            offset,
            corners,
        )
    }

    /// The conditional CDF of x at column boundary `column + 1`, between rows `row` and
    /// `row + 1` at the fraction `fy`.
    fn conditional_between(&self, corners: &Corners, row: usize, column: usize, fy: f32) -> f32 {
        let offset = row * (self.width - 1) + column;
        let c0 = self.conditional(corners, offset);
        let c1 = self.conditional(corners, offset + self.width - 1);
        c0 + (c1 - c0) * fy
    }

    /// The density (or, not normalised, the interpolated value) at `pos`.
    pub fn eval(&self, pos: Vec2, params: &[f32]) -> f32 {
        let corners = self.corners(params);
        let (cell, f) = self.cell(pos);
        let [v00, v10, v01, v11] = self.patch(&corners, cell);
        lerp(lerp(v00, v10, f.x), lerp(v01, v11, f.x), f.y)
    }

    /// The patch holding `pos` (clamped to the square) and the position within it.
    fn cell(&self, pos: Vec2) -> ([usize; 2], Vec2) {
        let x = pos.x.clamp(0.0, 1.0) * (self.width - 1) as f32;
        let y = pos.y.clamp(0.0, 1.0) * (self.height - 1) as f32;
        let (cx, cy) = (
            (x as usize).min(self.width - 2),
            (y as usize).min(self.height - 2),
        );
        ([cx, cy], Vec2::new(x - cx as f32, y - cy as f32))
    }

    /// The values at the corners of patch `cell`: (0, 0), (1, 0), (0, 1), (1, 1).
    fn patch(&self, corners: &Corners, [x, y]: [usize; 2]) -> [f32; 4] {
        let i = y * self.width + x;
        [
            self.value(corners, i),
            self.value(corners, i + 1),
            self.value(corners, i + self.width),
            self.value(corners, i + self.width + 1),
        ]
    }

    /// Maps a uniform `u` on [0, 1]² to a point distributed as the interpolant; the point and
    /// its density.
    pub fn sample(&self, u: Vec2, params: &[f32]) -> (Vec2, f32) {
        let corners = self.corners(params);
        let mut u = u.clamp(Vec2::splat(f32::EPSILON), Vec2::splat(1.0 - f32::EPSILON));
        let rows = self.height - 1;
        if !self.normalized {
            u.y *= self.marginal(&corners, rows - 1);
        }
        let row = first_not_below(rows, |i| self.marginal(&corners, i), u.y);
        if row > 0 {
            u.y -= self.marginal(&corners, row - 1);
        }
        let (r0, r1) = self.row_totals(&corners, row);
        let fy = sample_segment(u.y, (self.height - 1) as f32, r0, r1);
        u.x *= lerp(r0, r1, fy);
        let columns = self.width - 1;
        let column = first_not_below(
            columns,
            |i| self.conditional_between(&corners, row, i, fy),
            u.x,
        );
        if column > 0 {
            u.x -= self.conditional_between(&corners, row, column - 1, fy);
        }
        let [v00, v10, v01, v11] = self.patch(&corners, [column, row]);
        let (c0, c1) = (lerp(v00, v01, fy), lerp(v10, v11, fy));
        let fx = sample_segment(u.x, (self.width - 1) as f32, c0, c1);
        let point = Vec2::new(
            (column as f32 + fx) / (self.width - 1) as f32,
            (row as f32 + fy) / (self.height - 1) as f32,
        );
        (point, lerp(c0, c1, fx))
    }

    /// The inverse of [`Marginal2D::sample`]: the uniform point that maps to `pos`, and the
    /// density there.
    pub fn invert(&self, pos: Vec2, params: &[f32]) -> (Vec2, f32) {
        let corners = self.corners(params);
        let ([column, row], f) = self.cell(pos);
        let [v00, v10, v01, v11] = self.patch(&corners, [column, row]);
        let (c0, c1) = (lerp(v00, v01, f.y), lerp(v10, v11, f.y));
        let density = lerp(c0, c1, f.x);
        let mut x = invert_segment(f.x, 1.0 / (self.width - 1) as f32, c0, c1);
        if column > 0 {
            x += self.conditional_between(&corners, row, column - 1, f.y);
        }
        let (r0, r1) = self.row_totals(&corners, row);
        x /= lerp(r0, r1, f.y);
        let mut y = invert_segment(f.y, 1.0 / (self.height - 1) as f32, r0, r1);
        if row > 0 {
            y += self.marginal(&corners, row - 1);
        }
        if !self.normalized {
            y /= self.marginal(&corners, self.height - 2);
        }
        (Vec2::new(x, y), density)
    }

    /// The integrals over x of rows `row` and `row + 1`.
    fn row_totals(&self, corners: &Corners, row: usize) -> (f32, f32) {
        let last = self.width - 2;
        (
            self.conditional(corners, row * (self.width - 1) + last),
            self.conditional(corners, (row + 1) * (self.width - 1) + last),
        )
    }
}

#[inline]
fn lerp(a: f32, b: f32, t: f32) -> f32 {
    a + (b - a) * t
}

/// The first index in 0..count whose `cdf` is at least `u` (the last where none is).
fn first_not_below(count: usize, cdf: impl Fn(usize) -> f32, u: f32) -> usize {
    let (mut lo, mut hi) = (0, count - 1);
    while lo < hi {
        let mid = (lo + hi) / 2;
        if cdf(mid) < u {
            lo = mid + 1;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Inverts the CDF of the linear density from v0 to v1 over a segment of width 1/`inv_width`
/// at the mass `u`: the fraction of the segment.
#[inline]
fn sample_segment(u: f32, inv_width: f32, v0: f32, v1: f32) -> f32 {
    let u = u * 2.0 * inv_width;
    let varies = (v0 - v1).abs() > 1e-4 * (v0 + v1);
    let (numerator, divisor) = if varies {
        (v0 - (v0 * v0 + u * (v1 - v0)).max(0.0).sqrt(), v0 - v1)
    } else {
        (u, v0 + v1)
    };
    if divisor != 0.0 {
        numerator / divisor
    } else {
        numerator
    }
}

/// The mass of the linear density from v0 to v1 over the first fraction `t` of a segment of
/// width `width`.
#[inline]
fn invert_segment(t: f32, width: f32, v0: f32, v1: f32) -> f32 {
    t * lerp(v0, v1, 0.5 * t) * width
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::chi2::{Cells, Suite, chi2_rectangle};

    const SUITE: Suite = Suite::new(&["marginal 2D, between parameter nodes"]);

    fn distribution() -> Marginal2D {
        // Two grids of 4 × 3 values, for the parameter nodes 0 and 2.
        let data = [
            0.1, 0.5, 1.0, 0.2, 0.3, 0.9, 2.0, 0.4, 0.0, 0.2, 0.8, 1.5, //
            1.0, 0.2, 0.1, 0.1, 0.5, 0.5, 0.5, 0.5, 2.0, 1.0, 0.3, 0.0,
        ];
        Marginal2D::new(&data, 4, 3, vec![vec![0.0, 2.0]], true, true).unwrap()
    }

    /// Sampling follows the density it reports, between parameter nodes.
    #[test]
    fn sampling_follows_the_density() {
        let d = distribution();
        let cells = Cells {
            x: (0.0, 1.0),
            y: (0.0, 1.0),
            nx: 40,
            ny: 40,
        };
        let outcome = chi2_rectangle(
            200_000,
            cells,
            3,
            |rng| {
                let u = Vec2::new(rng.next_f32(), rng.next_f32());
                let p = d.sample(u, &[0.7]).0;
                Some((f64::from(p.x), f64::from(p.y)))
            },
            |x, y| f64::from(d.eval(Vec2::new(x as f32, y as f32), &[0.7])),
        )
        .unwrap();
        SUITE.assert_passes("marginal 2D, between parameter nodes", &outcome);
    }

    /// `invert` undoes `sample`, and both report the density `eval` gives.
    #[test]
    fn invert_undoes_sample() {
        let d = distribution();
        for (i, param) in [0.0, 0.7, 2.0, 5.0].into_iter().enumerate() {
            for j in 0..50 {
                let u = Vec2::new(
                    ((j * 7 + i) % 50) as f32 / 50.0 + 0.01,
                    (j as f32 + 0.5) / 50.0,
                );
                let (p, density) = d.sample(u, &[param]);
                let (back, inverse_density) = d.invert(p, &[param]);
                assert!((back - u).abs().max_element() < 2e-4, "{u} → {p} → {back}");
                let expected = d.eval(p, &[param]);
                assert!((density - expected).abs() < 1e-4 * expected.max(1.0));
                assert!((inverse_density - expected).abs() < 1e-4 * expected.max(1.0));
            }
        }
    }

    #[test]
    fn tables_that_are_no_densities_are_errors() {
        let negative = [1.0, -1.0, 1.0, 1.0];
        assert_eq!(
            Marginal2D::new(&negative, 2, 2, vec![], true, true).unwrap_err(),
            Marginal2DError::NotADensity(0)
        );
        assert!(matches!(
            Marginal2D::new(&[1.0; 5], 2, 2, vec![], true, true),
            Err(Marginal2DError::WrongLength { .. })
        ));
        assert_eq!(
            Marginal2D::new(&[1.0; 8], 2, 2, vec![vec![1.0, 1.0]], true, true).unwrap_err(),
            Marginal2DError::UnsortedParameter(0)
        );
    }
}
