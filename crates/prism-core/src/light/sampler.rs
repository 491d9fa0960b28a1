//! Choosing one light per shading point: by default with probability proportional to its power
//! (the lecture's "assign the probabilities proportional to the emitted spectral power"),
//! through an alias table, or uniformly (Mitsuba's default, every emitter with the same
//! `sampling_weight`); the estimate is then divided by that probability (DESIGN.md §4).
//!
//! The choice is the path integrator's `emitter_sampling` parameter (a Prism extension that
//! Mitsuba does not know):
//! ```xml
//! <integrator type="path">
//!     <string name="emitter_sampling" value="uniform"/>   <!-- "power" (default) or "uniform" -->
//! </integrator>
//! ```
//!
//! Each emitter's `sampling_weight` wᵢ (Mitsuba 3's parameter, default 1) scales its share:
//! uniform selection picks light i with P(i) = wᵢ / Σⱼ wⱼ, exactly as Mitsuba's
//! `Scene::sample_emitter` does; selection by power with P(i) = Φᵢwᵢ / Σⱼ Φⱼwⱼ, so that equal
//! weights leave it by power and a weight says how much more (or less) often than its power
//! alone a light should be chosen. Either way the direct-light estimate
//! Lᵢ/P(i), summed over the choice, is Σᵢ Lᵢ for every light with P(i) > 0: the weights change
//! the variance, not the mean. A light of weight 0 is never chosen: an area or environment
//! light is then found only by scattered rays (whose multiple importance sampling weight
//! becomes 1), and a point, spot or directional light contributes nothing (as in Mitsuba).

use crate::sampling::distribution::AliasTable;

/// How the light sampler weighs the lights.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LightSelection {
    /// Probability ∝ the light's power Φ (luminance-weighted).
    #[default]
    Power,
    /// The same probability for every light.
    Uniform,
}

/// Picks one light of a scene.
#[derive(Clone, Debug)]
pub enum LightSampler {
    /// In proportion to given weights (None when no light has weight).
    Weighted(Option<AliasTable>),
    /// Uniformly among `count` lights.
    Uniform { count: usize },
}

impl LightSampler {
    /// A sampler choosing lights in proportion to `weights`. Lights of zero (or non-finite)
    /// weight are never chosen; if no weight is positive (or there are no lights) nothing is
    /// ever chosen.
    pub fn new(weights: &[f32]) -> LightSampler {
        let weights: Vec<f64> = weights
            .iter()
            .map(|&w| {
                if w.is_finite() && w > 0.0 {
                    f64::from(w)
                } else {
                    0.0
                }
            })
            .collect();
        LightSampler::Weighted(AliasTable::new(&weights))
    }

    /// A sampler that picks each of `count` lights with probability 1/count.
    pub fn uniform(count: usize) -> LightSampler {
        LightSampler::Uniform { count }
    }

    /// The sampler for lights of the given powers and sampling weights (one each) under a
    /// selection rule: P(i) ∝ Φᵢwᵢ by power, P(i) ∝ wᵢ uniformly (see the module's text).
    pub fn with_selection(
        powers: &[f32],
        sampling_weights: &[f32],
        selection: LightSelection,
    ) -> LightSampler {
        assert_eq!(
            powers.len(),
            sampling_weights.len(),
            "one sampling weight per light"
        );
        match selection {
            LightSelection::Power => {
                let weights: Vec<f32> = powers
                    .iter()
                    .zip(sampling_weights)
                    .map(|(&p, &w)| p * w)
                    .collect();
                LightSampler::new(&weights)
            }
            LightSelection::Uniform => match sampling_weights.split_first() {
                Some((&first, rest)) if first > 0.0 && rest.iter().all(|&w| w == first) => {
                    LightSampler::uniform(sampling_weights.len())
                }
                None => LightSampler::uniform(0),
                Some(_) => LightSampler::new(sampling_weights),
            },
        }
    }

    /// A light index and the probability it was chosen with (the same number [`Self::pmf`]
    /// reports for that index).
    #[inline]
    pub fn sample(&self, u: f32) -> Option<(usize, f32)> {
        match self {
            LightSampler::Weighted(table) => table.as_ref().map(|t| t.sample(u)),
            LightSampler::Uniform { count: 0 } => None,
            LightSampler::Uniform { count } => {
                let index = ((u * *count as f32) as usize).min(count - 1);
                Some((index, self.pmf(index)))
            }
        }
    }

    /// The probability [`Self::sample`] chooses light `index`.
    #[inline]
    pub fn pmf(&self, index: usize) -> f32 {
        match self {
            LightSampler::Weighted(table) => table.as_ref().map_or(0.0, |t| t.pmf(index)),
            LightSampler::Uniform { count } => {
                if index < *count {
                    1.0 / *count as f32
                } else {
                    0.0
                }
            }
        }
    }
}
