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
    /// In proportion to given powers (None when no light has power).
    Power(Option<AliasTable>),
    /// Uniformly among `count` lights.
    Uniform { count: usize },
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
        LightSampler::Power(AliasTable::new(&weights))
    }

    /// A sampler that picks each of `count` lights with probability 1/count.
    pub fn uniform(count: usize) -> LightSampler {
        LightSampler::Uniform { count }
    }

    /// The sampler for lights of the given powers under a selection rule.
    pub fn with_selection(powers: &[f32], selection: LightSelection) -> LightSampler {
        match selection {
            LightSelection::Power => LightSampler::new(powers),
            LightSelection::Uniform => LightSampler::uniform(powers.len()),
        }
    }

    /// A light index and the probability it was chosen with (the same number [`Self::pmf`]
    /// reports for that index).
    #[inline]
    pub fn sample(&self, u: f32) -> Option<(usize, f32)> {
        match self {
            LightSampler::Power(table) => table.as_ref().map(|t| t.sample(u)),
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
            LightSampler::Power(table) => table.as_ref().map_or(0.0, |t| t.pmf(index)),
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
