//! Choosing one light per shading point with probability proportional to its power (the
//! lecture's "assign the probabilities proportional to the emitted spectral power"), through an
//! alias table; the estimate is then divided by that probability (DESIGN.md §4).

use crate::sampling::distribution::AliasTable;

/// Picks lights in proportion to given powers.
#[derive(Clone, Debug)]
pub struct LightSampler {
    table: Option<AliasTable>,
}

impl LightSampler {
    /// A sampler for lights of the given powers. Lights of zero power are never chosen; if all
    /// powers are zero (or there are no lights) nothing is ever chosen.
    pub fn new(powers: &[f32]) -> LightSampler {
        let weights: Vec<f64> = powers
            .iter()
            .map(|&p| {
                if p.is_finite() && p > 0.0 {
                    f64::from(p)
                } else {
                    0.0
                }
            })
            .collect();
        LightSampler {
            table: AliasTable::new(&weights),
        }
    }

    /// A light index and the probability it was chosen with.
    #[inline]
    pub fn sample(&self, u: f32) -> Option<(usize, f32)> {
        self.table.as_ref().map(|t| t.sample(u))
    }

    /// The probability [`Self::sample`] chooses light `index`.
    #[inline]
    pub fn pmf(&self, index: usize) -> f32 {
        self.table.as_ref().map_or(0.0, |t| t.pmf(index))
    }
}
