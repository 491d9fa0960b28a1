//! Tabulated distributions: a piecewise-constant density on an interval (sampled by its inverse
//! CDF) and the alias table for discrete choices in constant time.

/// A piecewise-constant density on `[min, max)` with `n` equal cells, proportional to given
/// non-negative weights; sampled by inverting its CDF (pbrt-v4, §A.4.1 "Piecewise-Constant 1D").
/// The cell holding u is found through a guide table (Chen & Asau 1974, "On Generating Random
/// Variates from an Empirical Distribution"): guide[j] is the cell where u = j/G falls, so the
/// search starts next to the answer and usually takes one or two steps.
#[derive(Clone, Debug)]
pub struct PiecewiseConstant1D {
    weights: Vec<f32>,
    /// cdf[i] = integral of the normalised density over the first i cells; cdf[n] = 1.
    cdf: Vec<f64>,
    /// guide[j] = the cell containing u = j / guide.len().
    guide: Vec<u32>,
    /// Integral of the (unnormalised) weights over the domain.
    integral: f64,
    min: f32,
    max: f32,
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
        let guide_len = n.next_power_of_two().max(16);
        let mut guide = Vec::with_capacity(guide_len);
        let mut cell = 0usize;
        for j in 0..guide_len {
            let u = j as f64 / guide_len as f64;
            while cell + 1 < n && cdf[cell + 1] <= u {
                cell += 1;
            }
            guide.push(cell as u32);
        }
        PiecewiseConstant1D {
            weights,
            cdf,
            guide,
            integral,
            min,
            max,
        }
    }

    /// Integral of |weights| over the domain (before normalisation).
    pub fn integral(&self) -> f64 {
        self.integral
    }

    pub fn len(&self) -> usize {
        self.weights.len()
    }

    pub fn is_empty(&self) -> bool {
        self.weights.is_empty()
    }

    pub fn domain(&self) -> (f32, f32) {
        (self.min, self.max)
    }

    /// Maps `u` in [0, 1) to a point of the domain with density [`Self::pdf`]. Returns the point
    /// and the index of its cell.
    pub fn sample(&self, u: f32) -> (f32, usize) {
        let n = self.weights.len();
        // The last cell whose start cdf[i] is at most u, searched from the guide's cell on.
        let slot = ((u * self.guide.len() as f32) as usize).min(self.guide.len() - 1);
        let u = f64::from(u);
        let mut index = self.guide[slot] as usize;
        while index + 1 < n && self.cdf[index + 1] <= u {
            index += 1;
        }
        let lo = self.cdf[index];
        let width = self.cdf[index + 1] - lo;
        let offset = if width > 0.0 { (u - lo) / width } else { 0.0 };
        let cell = (self.max - self.min) / n as f32;
        let x = self.min + (index as f32 + offset as f32) * cell;
        (x.min(self.max.next_down()).max(self.min), index)
    }

    /// Density of [`Self::sample`] at `x` (zero outside the domain).
    pub fn pdf(&self, x: f32) -> f32 {
        if !(x >= self.min && x < self.max) {
            return 0.0;
        }
        let n = self.weights.len();
        let index = (((x - self.min) / (self.max - self.min) * n as f32) as usize).min(n - 1);
        self.cell_pdf(index)
    }

    /// Density within cell `index`.
    pub fn cell_pdf(&self, index: usize) -> f32 {
        if self.integral > 0.0 {
            (f64::from(self.weights[index]) / self.integral) as f32
        } else {
            1.0 / (self.max - self.min)
        }
    }

    /// The `u` that [`Self::sample`] maps to `x`: the normalised CDF at `x`.
    pub fn invert(&self, x: f32) -> Option<f32> {
        if !(x >= self.min && x < self.max) {
            return None;
        }
        let n = self.weights.len();
        let t = f64::from((x - self.min) / (self.max - self.min)) * n as f64;
        let index = (t as usize).min(n - 1);
        let frac = t - index as f64;
        Some((self.cdf[index] + frac * (self.cdf[index + 1] - self.cdf[index])) as f32)
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
