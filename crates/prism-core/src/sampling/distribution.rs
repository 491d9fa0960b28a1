//! Tabulated distributions: a piecewise-constant density on an interval (sampled by its inverse
//! CDF), its extension to the unit square, a piecewise-linear density on an interval, and the
//! alias table for discrete choices in constant time.

use glam::Vec2;

/// A piecewise-constant density on `[min, max)` with `n` equal cells, proportional to given
/// non-negative weights; sampled by inverting its CDF (pbrt-v4, §A.4.1 "Piecewise-Constant 1D").
/// The cell holding u is found through a guide table (Chen & Asau 1974, "On Generating Random
/// Variates from an Empirical Distribution"): `guide[j]` is the cell where u = j/G falls, so the
/// search starts next to the answer and usually takes one or two steps.
#[derive(Clone, Debug)]
pub struct PiecewiseConstant1D {
    /// The normalised density in each cell.
    density: Vec<f32>,
    /// Where each cell starts in the CDF, and the reciprocal of its width there.
    cells: Vec<CdfCell>,
    /// guide[j] = the cell containing u = j / guide.len().
    guide: Vec<u32>,
    /// Integral of the (unnormalised) weights over the domain.
    integral: f64,
    min: f32,
    max: f32,
    /// The width of a cell, (max − min) / n.
    cell_width: f32,
    /// Cells per unit of the domain, n / (max − min).
    cells_per_unit: f32,
    /// The largest f32 below `max`, the largest point a sample may return.
    last: f32,
}

/// One cell of a [`PiecewiseConstant1D`] as its CDF sees it.
#[derive(Clone, Copy, Debug)]
struct CdfCell {
    /// cdf(i) = integral of the normalised density over the cells before this one (the CDF
    /// ends at 1 after the last). Summed in f64 and rounded to f32: u is an f32, so its
    /// resolution, not the table's, limits which cells can be told apart.
    start: f32,
    /// 1 / (cdf(i + 1) − cdf(i)), or 0 for a cell of zero probability: the position of u
    /// within its cell is then a product, not a division.
    inverse_width: f32,
}

impl PiecewiseConstant1D {
    /// A density proportional to `weights` (absolute values are taken). If all weights are zero,
    /// the density is uniform. Panics on an empty table or `max <= min` (programming errors).
    pub fn new(weights: &[f32], min: f32, max: f32) -> Self {
        assert!(!weights.is_empty() && max > min);
        let weights: Vec<f32> = weights.iter().map(|w| w.abs()).collect();
        let n = weights.len();
        let cell = f64::from(max - min) / n as f64;
        let mut cdf = Vec::with_capacity(n + 1);
        cdf.push(0.0);
        let mut running = 0.0f64;
        for &w in &weights {
            running += f64::from(w) * cell;
            cdf.push(running);
        }
        let integral = running;
        if integral > 0.0 {
            for c in &mut cdf[1..] {
                *c /= integral;
            }
        } else {
            for (i, c) in cdf.iter_mut().enumerate() {
                *c = i as f64 / n as f64;
            }
        }
        // Four guide entries per cell for small tables (the wavelength density's 470 cells: a
        // search then rarely takes a step), one per cell for large ones (the rows of an
        // environment map), whose memory matters more.
        let per_cell = if n <= 1024 { 4 } else { 1 };
        let guide_len = (per_cell * n).next_power_of_two().max(16);
        let cdf: Vec<f32> = cdf.iter().map(|&c| c as f32).collect();
        let cells = cdf
            .windows(2)
            .map(|w| CdfCell {
                start: w[0],
                inverse_width: if w[1] > w[0] {
                    1.0 / (w[1] - w[0])
                } else {
                    0.0
                },
            })
            .collect();
        let mut guide = Vec::with_capacity(guide_len);
        let mut cell = 0usize;
        for j in 0..guide_len {
            let u = j as f32 / guide_len as f32;
            while cell + 1 < n && cdf[cell + 1] <= u {
                cell += 1;
            }
            guide.push(cell as u32);
        }
        let density = weights
            .iter()
            .map(|&w| {
                if integral > 0.0 {
                    (f64::from(w) / integral) as f32
                } else {
                    1.0 / (max - min)
                }
            })
            .collect();
        PiecewiseConstant1D {
            density,
            cells,
            guide,
            integral,
            min,
            max,
            cell_width: (max - min) / n as f32,
            cells_per_unit: n as f32 / (max - min),
            last: max.next_down(),
        }
    }

    /// Integral of |weights| over the domain (before normalisation).
    pub fn integral(&self) -> f64 {
        self.integral
    }

    pub fn len(&self) -> usize {
        self.density.len()
    }

    pub fn is_empty(&self) -> bool {
        self.density.is_empty()
    }

    pub fn domain(&self) -> (f32, f32) {
        (self.min, self.max)
    }

    /// Maps `u` in [0, 1) to a point of the domain with density [`Self::pdf`]. Returns the point
    /// and the index of its cell.
    pub fn sample(&self, u: f32) -> (f32, usize) {
        // The last cell whose start is at most u, searched from the guide's cell on.
        let slot = ((u * self.guide.len() as f32) as u32 as usize).min(self.guide.len() - 1);
        let mut index = self.guide[slot] as usize;
        while let Some(next) = self.cells.get(index + 1)
            && next.start <= u
        {
            index += 1;
        }
        let cell = self.cells[index];
        let offset = (u - cell.start) * cell.inverse_width;
        let mut x = (self.min + (index as u32 as f32 + offset) * self.cell_width)
            .clamp(self.min, self.last);
        // Rounding may put x on the neighbouring cell's side of a border, where [`Self::pdf`]
        // would give that cell's density: keep it in the cell drawn.
        let mut cell = self.cell_of(x);
        while cell != index {
            x = if cell > index {
                x.next_down()
            } else {
                x.next_up()
            };
            cell = self.cell_of(x);
        }
        (x, index)
    }

    /// The cell [`Self::pdf`] finds `x` in, for `x` in the domain.
    #[inline]
    fn cell_of(&self, x: f32) -> usize {
        (((x - self.min) * self.cells_per_unit) as usize).min(self.density.len() - 1)
    }

    /// Density of [`Self::sample`] at `x` (zero outside the domain).
    pub fn pdf(&self, x: f32) -> f32 {
        if !(x >= self.min && x < self.max) {
            return 0.0;
        }
        self.cell_pdf(self.cell_of(x))
    }

    /// Density within cell `index`.
    #[inline]
    pub fn cell_pdf(&self, index: usize) -> f32 {
        self.density[index]
    }

    /// The `u` that [`Self::sample`] maps to `x`: the normalised CDF at `x`.
    pub fn invert(&self, x: f32) -> Option<f32> {
        if !(x >= self.min && x < self.max) {
            return None;
        }
        let n = self.density.len();
        let t = f64::from((x - self.min) / (self.max - self.min)) * n as f64;
        let index = (t as usize).min(n - 1);
        let frac = t - index as f64;
        let cdf = |i: usize| self.cells.get(i).map_or(1.0, |c| f64::from(c.start));
        let (lo, hi) = (cdf(index), cdf(index + 1));
        Some((lo + frac * (hi - lo)) as f32)
    }
}

/// A piecewise-constant density on the unit square [0, 1)² with `nx` × `ny` equal cells,
/// proportional to given non-negative weights (row-major, row 0 at y = 0). Sampled as a
/// marginal density over rows followed by the conditional density within the chosen row
/// (pbrt-v4, §A.5.2 "Piecewise-Constant 2D"), each by its inverse CDF, so the map from the
/// unit square is continuous within rows and invertible.
#[derive(Clone, Debug)]
pub struct PiecewiseConstant2D {
    /// One conditional density over x per row.
    rows: Vec<PiecewiseConstant1D>,
    /// The density over y of the rows' integrals.
    marginal: PiecewiseConstant1D,
}

impl PiecewiseConstant2D {
    /// A density proportional to `weights` (`nx` × `ny`, row-major; absolute values are taken);
    /// uniform if all are zero. Panics if the table is empty or of the wrong length
    /// (programming errors).
    pub fn new(weights: &[f32], nx: usize, ny: usize) -> Self {
        assert!(nx > 0 && ny > 0 && weights.len() == nx * ny);
        let rows: Vec<PiecewiseConstant1D> = weights
            .chunks_exact(nx)
            .map(|row| PiecewiseConstant1D::new(row, 0.0, 1.0))
            .collect();
        let row_integrals: Vec<f32> = rows.iter().map(|r| r.integral() as f32).collect();
        PiecewiseConstant2D {
            marginal: PiecewiseConstant1D::new(&row_integrals, 0.0, 1.0),
            rows,
        }
    }

    /// Integral of |weights| over the unit square (before normalisation).
    pub fn integral(&self) -> f64 {
        self.marginal.integral()
    }

    /// Maps `u` in [0, 1)² to a point of the unit square with density [`Self::pdf`].
    pub fn sample(&self, u: Vec2) -> Vec2 {
        let (y, row) = self.marginal.sample(u.y);
        let (x, _) = self.rows[row].sample(u.x);
        Vec2::new(x, y)
    }

    /// Density of [`Self::sample`] at `p` (zero outside the unit square).
    pub fn pdf(&self, p: Vec2) -> f32 {
        if !(p.y >= 0.0 && p.y < 1.0) {
            return 0.0;
        }
        let row = ((p.y * self.rows.len() as f32) as usize).min(self.rows.len() - 1);
        self.marginal.cell_pdf(row) * self.rows[row].pdf(p.x)
    }

    /// The `u` that [`Self::sample`] maps to `p`.
    pub fn invert(&self, p: Vec2) -> Option<Vec2> {
        let uy = self.marginal.invert(p.y)?;
        let row = ((p.y * self.rows.len() as f32) as usize).min(self.rows.len() - 1);
        let ux = self.rows[row].invert(p.x)?;
        Some(Vec2::new(ux, uy))
    }
}

/// A piecewise-linear density on `[min, max]` through values at `n ≥ 2` equally spaced nodes
/// (the first at `min`, the last at `max`), normalised to integrate to one: Mitsuba 3's
/// `ContinuousDistribution`. Sampled by its inverse CDF: the interval [x_i, x_i+1] is found
/// from the cumulative trapezoid areas, and within it the density y(s) = y_i + (y_i+1 − y_i) s/Δ
/// has the area A(s) = y_i s + (y_i+1 − y_i) s²/(2Δ), so the point with A(s) = a is
/// s = 2a / (y_i + sqrt(y_i² + 2 (y_i+1 − y_i) a/Δ)) (the root of the quadratic written without
/// cancellation; it is a/y_i where the density is flat).
#[derive(Clone, Debug, PartialEq)]
pub struct PiecewiseLinear1D {
    /// The normalised density at each node.
    density: Vec<f64>,
    /// cdf[i] = the probability of [min, x_i]; cdf[0] = 0, cdf[n − 1] = 1.
    cdf: Vec<f64>,
    min: f64,
    max: f64,
    /// The spacing Δ of the nodes, (max − min) / (n − 1).
    spacing: f64,
}

impl PiecewiseLinear1D {
    /// The density through `values` (at least two, finite and non-negative, not all zero) on
    /// `[min, max]` (min < max); None otherwise.
    pub fn new(values: &[f32], min: f32, max: f32) -> Option<PiecewiseLinear1D> {
        let valid = values.len() >= 2
            && min < max
            && values.iter().all(|v| v.is_finite() && *v >= 0.0)
            && values.iter().any(|v| *v > 0.0);
        if !valid {
            return None;
        }
        let (min, max) = (f64::from(min), f64::from(max));
        let spacing = (max - min) / (values.len() - 1) as f64;
        let mut cdf = Vec::with_capacity(values.len());
        let mut total = 0.0;
        cdf.push(total);
        for pair in values.windows(2) {
            total += 0.5 * (f64::from(pair[0]) + f64::from(pair[1])) * spacing;
            cdf.push(total);
        }
        for c in &mut cdf {
            *c /= total;
        }
        Some(PiecewiseLinear1D {
            density: values.iter().map(|v| f64::from(*v) / total).collect(),
            cdf,
            min,
            max,
            spacing,
        })
    }

    /// The density at `x` (zero outside `[min, max]`).
    pub fn pdf(&self, x: f32) -> f32 {
        let x = f64::from(x);
        if !(x >= self.min && x <= self.max) {
            return 0.0;
        }
        let position = (x - self.min) / self.spacing;
        let i = (position as usize).min(self.density.len() - 2);
        let t = position - i as f64;
        (self.density[i] * (1.0 - t) + self.density[i + 1] * t) as f32
    }

    /// Maps `u` in [0, 1) to a point of `[min, max]` with density [`Self::pdf`].
    pub fn sample(&self, u: f32) -> f32 {
        let u = f64::from(u);
        // The interval whose cumulative probabilities bracket u (never one of zero width).
        let i = (self.cdf.partition_point(|c| *c <= u).max(1) - 1).min(self.cdf.len() - 2);
        let area = (u - self.cdf[i]).max(0.0);
        let (y0, y1) = (self.density[i], self.density[i + 1]);
        let root = (y0 * y0 + 2.0 * (y1 - y0) * area / self.spacing)
            .max(0.0)
            .sqrt();
        let s = if y0 + root > 0.0 {
            2.0 * area / (y0 + root)
        } else {
            0.0
        };
        let x = self.min + i as f64 * self.spacing + s.min(self.spacing);
        (x.min(self.max) as f32).max(self.min as f32)
    }
}

/// Walker's alias method (Vose 1991, "A Linear Algorithm for Generating Random Numbers with a
/// Given Distribution"): picks index i with probability w_i / sum(w) from one uniform number in
/// constant time.
#[derive(Clone, Debug)]
pub struct AliasTable {
    bins: Vec<AliasBin>,
}

#[derive(Clone, Copy, Debug)]
struct AliasBin {
    /// Probability of this index itself.
    pmf: f32,
    /// Probability of keeping this bin's own index rather than its alias, given the bin.
    keep: f32,
    alias: u32,
}

impl AliasTable {
    /// Bytes of heap memory the table holds.
    pub fn heap_bytes(&self) -> usize {
        self.bins.capacity() * std::mem::size_of::<AliasBin>()
    }

    /// A table for non-negative, finite weights that are not all zero; `None` otherwise.
    pub fn new(weights: &[f64]) -> Option<Self> {
        let total: f64 = weights.iter().sum();
        if weights.is_empty()
            || weights.len() > u32::MAX as usize
            || !(total > 0.0 && total.is_finite())
            || weights.iter().any(|w| !(*w >= 0.0))
        {
            return None;
        }
        let n = weights.len();
        let mut bins: Vec<AliasBin> = weights
            .iter()
            .enumerate()
            .map(|(i, w)| AliasBin {
                pmf: (w / total) as f32,
                keep: 1.0,
                alias: i as u32,
            })
            .collect();
        // Scaled probabilities p_i * n: bins below 1 are filled up from bins above 1.
        let mut scaled: Vec<f64> = weights.iter().map(|w| w / total * n as f64).collect();
        let mut small: Vec<usize> = (0..n).filter(|&i| scaled[i] < 1.0).collect();
        let mut large: Vec<usize> = (0..n).filter(|&i| scaled[i] >= 1.0).collect();
        while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
            small.pop();
            bins[s].keep = scaled[s] as f32;
            bins[s].alias = l as u32;
            scaled[l] -= 1.0 - scaled[s];
            if scaled[l] < 1.0 {
                large.pop();
                small.push(l);
            }
        }
        // What is left (rounding) keeps its own index with certainty.
        for i in small.into_iter().chain(large) {
            bins[i].keep = 1.0;
            bins[i].alias = i as u32;
        }
        Some(AliasTable { bins })
    }

    pub fn len(&self) -> usize {
        self.bins.len()
    }

    pub fn is_empty(&self) -> bool {
        self.bins.is_empty()
    }

    /// Probability of index `i`.
    pub fn pmf(&self, i: usize) -> f32 {
        self.bins[i].pmf
    }

    /// An index drawn with probability [`Self::pmf`], and that probability.
    pub fn sample(&self, u: f32) -> (usize, f32) {
        let n = self.bins.len();
        let scaled = u * n as f32;
        let bin = (scaled as usize).min(n - 1);
        let remapped = (scaled - bin as f32).min(1.0f32.next_down());
        let entry = self.bins[bin];
        let index = if remapped < entry.keep {
            bin
        } else {
            entry.alias as usize
        };
        (index, self.bins[index].pmf)
    }

    /// As [`Self::sample`], and `u` made again into a number uniform in [0, 1) and independent
    /// of the index drawn (Mitsuba's `sample_reuse`), so that one number both picks the index
    /// and places a point within it: u·n lands in a bin, and where it lies within the part of
    /// the bin that chose the index (the first `keep` of it, or the rest) is uniform whatever
    /// the index. It keeps the bits of `u` left over after the bin, about 24 − log₂ n.
    pub fn sample_reuse(&self, u: f32) -> (usize, f32, f32) {
        let n = self.bins.len();
        let scaled = u * n as f32;
        let bin = (scaled as usize).min(n - 1);
        let remapped = (scaled - bin as f32).clamp(0.0, 1.0f32.next_down());
        let entry = self.bins[bin];
        let (index, reused) = if remapped < entry.keep {
            (bin, remapped / entry.keep)
        } else {
            (
                entry.alias as usize,
                (remapped - entry.keep) / (1.0 - entry.keep),
            )
        };
        (
            index,
            self.bins[index].pmf,
            reused.clamp(0.0, 1.0f32.next_down()),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn piecewise_constant_sample_and_invert_round_trip() {
        let d = PiecewiseConstant1D::new(&[1.0, 0.0, 3.0, 2.0], 10.0, 14.0);
        assert!((d.integral() - 6.0).abs() < 1e-9);
        for i in 0..1000 {
            let u = (i as f32 + 0.5) / 1000.0;
            let (x, cell) = d.sample(u);
            assert_ne!(cell, 1, "a zero-weight cell was sampled");
            let back = d.invert(x).unwrap();
            assert!((back - u).abs() < 1e-5, "u {u} -> x {x} -> {back}");
        }
        assert!((d.pdf(12.5) - 0.5).abs() < 1e-6);
        assert_eq!(d.pdf(9.0), 0.0);
        assert_eq!(d.pdf(14.0), 0.0);
    }

    #[test]
    fn piecewise_constant_with_zero_weights_is_uniform() {
        let d = PiecewiseConstant1D::new(&[0.0, 0.0], 0.0, 2.0);
        assert_eq!(d.pdf(0.3), 0.5);
        assert!((d.sample(0.75).0 - 1.5).abs() < 1e-6);
    }

    #[test]
    fn piecewise_constant_2d_density_sample_and_invert_agree() {
        // 3 × 2 cells; the middle cell of the first row is empty.
        let d = PiecewiseConstant2D::new(&[1.0, 0.0, 2.0, 3.0, 1.0, 5.0], 3, 2);
        assert!((d.integral() - 2.0).abs() < 1e-9);
        assert!((d.pdf(Vec2::new(0.9, 0.8)) - 2.5).abs() < 1e-5);
        assert_eq!(d.pdf(Vec2::new(0.5, 0.2)), 0.0);
        assert_eq!(d.pdf(Vec2::new(0.5, 1.0)), 0.0);
        for i in 0..40 {
            for j in 0..40 {
                let u = Vec2::new((i as f32 + 0.5) / 40.0, (j as f32 + 0.5) / 40.0);
                let p = d.sample(u);
                assert!(d.pdf(p) > 0.0, "{u} -> {p} in an empty cell");
                let back = d.invert(p).unwrap();
                assert!(
                    (back - u).abs().max_element() < 1e-4,
                    "{u} -> {p} -> {back}"
                );
            }
        }
    }

    #[test]
    fn alias_table_reports_the_normalised_weights() {
        let table = AliasTable::new(&[1.0, 2.0, 0.0, 5.0]).unwrap();
        let pmfs: Vec<f32> = (0..4).map(|i| table.pmf(i)).collect();
        assert_eq!(pmfs, vec![0.125, 0.25, 0.0, 0.625]);
        // Exhaustive sweep of u: the fraction of u mapping to each index equals its pmf.
        let steps = 80_000;
        let mut counts = [0usize; 4];
        for k in 0..steps {
            let (i, p) = table.sample((k as f32 + 0.5) / steps as f32);
            assert_eq!(p, table.pmf(i));
            counts[i] += 1;
        }
        for i in 0..4 {
            let fraction = counts[i] as f32 / steps as f32;
            assert!((fraction - pmfs[i]).abs() < 1e-3, "index {i}: {fraction}");
        }
    }

    #[test]
    fn alias_table_rejects_invalid_weights() {
        assert!(AliasTable::new(&[]).is_none());
        assert!(AliasTable::new(&[0.0, 0.0]).is_none());
        assert!(AliasTable::new(&[1.0, -1.0]).is_none());
        assert!(AliasTable::new(&[1.0, f64::NAN]).is_none());
        assert!(AliasTable::new(&[1.0, f64::INFINITY]).is_none());
    }
}
