//! Choosing one light per shading point: by default in proportion to its importance at that
//! point ([`crate::light::bounds`]: power over squared distance, times a bound on the
//! receiver's cosine), or everywhere alike in proportion to its power (the lecture's "assign the
//! probabilities proportional to the emitted spectral power", through an alias table), or
//! uniformly (Mitsuba's default, every emitter with the same `sampling_weight`); the estimate is
//! then divided by that probability (docs/architecture.md, The lecture's errata).
//!
//! The choice is the path integrator's `emitter_sampling` parameter (a Prism extension that
//! Mitsuba does not know):
//! ```xml
//! <integrator type="path">
//!     <string name="emitter_sampling" value="power"/>   <!-- "exhaustive", "power" or "uniform" -->
//! </integrator>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! `exhaustive` is pbrt-v4's `ExhaustiveLightSampler` (Pharr, Jakob and Humphreys, pbrt-v4,
//! §12.6.3): every light at a finite place is weighed by its importance I(p, n) at the receiver,
//! and the N_∞ lights at infinity (environments, directional lights), which have no place, are
//! chosen together with pbrt-v4's probability P_∞ = N_∞/(N_∞ + 1), as if the finite lights were
//! one more light at infinity: light i at infinity with P(i) = P_∞ Φᵢ/Φ_∞ (Φ_∞ their total
//! power) and one at a finite place with P(i) = (1 − P_∞) Iᵢ(p, n)/Σⱼ Iⱼ(p, n). Where no finite
//! light has importance (none can light the point) the lights at infinity share everything.
//! (A share by power, Φ_∞/Φ, starves a dim sky beside a bright lamp: on the bundled smoke box,
//! a floor under a small sphere light and a dim constant sky, it measured 1.4× the relMSE of
//! P_∞ = ½ at equal samples.) The cost is one importance per light per choice and per density, so it suits
//! scenes of up to some hundreds of emitters.
//!
//! Each emitter's `sampling_weight` wᵢ (Mitsuba 3's parameter, default 1) scales its share:
//! uniform selection picks light i with P(i) = wᵢ / Σⱼ wⱼ, exactly as Mitsuba's
//! `Scene::sample_emitter` does; selection by power with P(i) = Φᵢwᵢ / Σⱼ Φⱼwⱼ, and by importance
//! with Φᵢwᵢ in place of Φᵢ, so that equal weights leave them as they are and a weight says how
//! much more (or less) often than otherwise a light should be chosen. Either way the
//! direct-light estimate Lᵢ/P(i), summed over the choice, is Σᵢ Lᵢ for every light with P(i) > 0:
//! the weights change the variance, not the mean. A light of weight 0 is never chosen: an area
//! or environment light is then found only by scattered rays (whose multiple importance
//! sampling weight becomes 1), and a point, spot or directional light contributes nothing (as
//! in Mitsuba).

use super::bounds::{LightBounds, Receiver};
use crate::sampling::distribution::AliasTable;

/// How the light sampler weighs the lights.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LightSelection {
    /// Probability ∝ the light's importance at the shading point (pbrt-v4's `exhaustive`).
    #[default]
    Exhaustive,
    /// Probability ∝ the light's power Φ (luminance-weighted), the same everywhere.
    Power,
    /// The same probability for every light.
    Uniform,
}

impl LightSelection {
    /// Every selection's name, as scenes give it.
    pub const NAMES: [&'static str; 3] = ["exhaustive", "power", "uniform"];

    pub fn from_name(name: &str) -> Option<LightSelection> {
        match name {
            "exhaustive" => Some(LightSelection::Exhaustive),
            "power" => Some(LightSelection::Power),
            "uniform" => Some(LightSelection::Uniform),
            _ => None,
        }
    }
}

/// Picks one light of a scene.
#[derive(Clone, Debug)]
pub enum LightSampler {
    /// In proportion to given weights (None when no light has weight).
    Weighted(Option<AliasTable>),
    /// Uniformly among `count` lights.
    Uniform { count: usize },
    /// By importance at the receiver (see the module's text).
    Exhaustive(Box<ExhaustiveSampler>),
}

/// The lights of [`LightSelection::Exhaustive`]: those at a finite place with their bounds,
/// those at infinity by power.
#[derive(Clone, Debug)]
pub struct ExhaustiveSampler {
    /// Each light's place among the finite or the infinite ones.
    slots: Vec<Slot>,
    /// The finite lights: their index and bounds (power times sampling weight).
    finite: Vec<(usize, LightBounds)>,
    /// The lights at infinity, by power times sampling weight (None if there are none).
    infinite: Option<AliasTable>,
    infinite_lights: Vec<usize>,
    /// N_∞ / (N_∞ + 1): the share of the lights at infinity when finite lights can light the
    /// receiver.
    infinite_share: f32,
}

#[derive(Clone, Copy, Debug)]
enum Slot {
    Finite(usize),
    Infinite(usize),
    Never,
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

    /// A sampler choosing by importance among lights of the given powers (times their
    /// sampling weights) and bounds (None for a light at infinity).
    pub fn exhaustive(powers: &[f32], bounds: &[Option<LightBounds>]) -> LightSampler {
        assert_eq!(powers.len(), bounds.len(), "one bound per light");
        let usable = |p: f32| p.is_finite() && p > 0.0;
        let mut slots = Vec::with_capacity(powers.len());
        let (mut finite, mut infinite_lights, mut infinite_powers) =
            (Vec::new(), Vec::new(), Vec::new());
        for (index, (&power, bound)) in powers.iter().zip(bounds).enumerate() {
            if !usable(power) {
                slots.push(Slot::Never);
                continue;
            }
            match bound {
                Some(b) => {
                    slots.push(Slot::Finite(finite.len()));
                    finite.push((index, LightBounds { power, ..*b }));
                }
                None => {
                    slots.push(Slot::Infinite(infinite_lights.len()));
                    infinite_lights.push(index);
                    infinite_powers.push(f64::from(power));
                }
            }
        }
        let infinite_count = infinite_lights.len();
        LightSampler::Exhaustive(Box::new(ExhaustiveSampler {
            slots,
            finite,
            infinite: AliasTable::new(&infinite_powers),
            infinite_lights,
            infinite_share: infinite_count as f32 / (infinite_count + 1) as f32,
        }))
    }

    /// The sampler for lights of the given powers, sampling weights and bounds (one each) under
    /// a selection rule: P(i) ∝ Φᵢwᵢ by power, P(i) ∝ wᵢ uniformly, by importance as the module's
    /// text says.
    pub fn with_selection(
        powers: &[f32],
        sampling_weights: &[f32],
        bounds: &[Option<LightBounds>],
        selection: LightSelection,
    ) -> LightSampler {
        assert_eq!(
            powers.len(),
            sampling_weights.len(),
            "one sampling weight per light"
        );
        let weighted_powers = || -> Vec<f32> {
            powers
                .iter()
                .zip(sampling_weights)
                .map(|(&p, &w)| p * w)
                .collect()
        };
        match selection {
            LightSelection::Exhaustive => LightSampler::exhaustive(&weighted_powers(), bounds),
            LightSelection::Power => LightSampler::new(&weighted_powers()),
            LightSelection::Uniform => match sampling_weights.split_first() {
                Some((&first, rest)) if first > 0.0 && rest.iter().all(|&w| w == first) => {
                    LightSampler::uniform(sampling_weights.len())
                }
                None => LightSampler::uniform(0),
                Some(_) => LightSampler::new(sampling_weights),
            },
        }
    }

    /// A light index for `receiver` and the probability it was chosen with (the same number
    /// [`Self::pmf`] reports for that index).
    #[inline]
    pub fn sample(&self, u: f32, receiver: &Receiver) -> Option<(usize, f32)> {
        match self {
            LightSampler::Weighted(table) => table.as_ref().map(|t| t.sample(u)),
            LightSampler::Exhaustive(sampler) => sampler.sample(u, receiver),
            LightSampler::Uniform { count: 0 } => None,
            LightSampler::Uniform { count } => {
                let index = ((u * *count as f32) as usize).min(count - 1);
                Some((index, 1.0 / *count as f32))
            }
        }
    }

    /// The probability [`Self::sample`] chooses light `index` for `receiver`.
    #[inline]
    pub fn pmf(&self, index: usize, receiver: &Receiver) -> f32 {
        match self {
            LightSampler::Weighted(table) => table.as_ref().map_or(0.0, |t| t.pmf(index)),
            LightSampler::Exhaustive(sampler) => sampler.pmf(index, receiver),
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

impl ExhaustiveSampler {
    /// One light in proportion to the finite lights' importance (weighted reservoir sampling
    /// with a single number: the running choice is replaced by light j with probability
    /// Iⱼ / Σ_{k≤j} Iₖ, and u is rescaled to stay uniform), or one at infinity.
    fn sample(&self, u: f32, receiver: &Receiver) -> Option<(usize, f32)> {
        if let Some(index) = self.only_light() {
            return Some((index, 1.0));
        }
        let mut rest = u;
        let share = if self.infinite.is_some() {
            self.share_given(self.any_finite_light_reaches(receiver))
        } else {
            0.0
        };
        if let Some(table) = &self.infinite
            && rest < share
        {
            let (k, pmf) = table.sample((rest / share).min(ONE_MINUS_EPSILON));
            return Some((self.infinite_lights[k], share * pmf));
        }
        if share > 0.0 {
            rest = ((rest - share) / (1.0 - share)).clamp(0.0, ONE_MINUS_EPSILON);
        }
        let (mut chosen, mut chosen_importance, mut total) = (None, 0.0f32, 0.0f32);
        for &(index, bounds) in &self.finite {
            let importance = bounds.importance(receiver);
            if !(importance > 0.0) {
                continue;
            }
            total += importance;
            let p = importance / total;
            if rest < p {
                chosen = Some(index);
                chosen_importance = importance;
                rest = (rest / p).min(ONE_MINUS_EPSILON);
            } else {
                rest = ((rest - p) / (1.0 - p)).clamp(0.0, ONE_MINUS_EPSILON);
            }
        }
        chosen.map(|index| (index, (1.0 - share) * chosen_importance / total))
    }

    fn pmf(&self, index: usize, receiver: &Receiver) -> f32 {
        if let Some(only) = self.only_light() {
            return if index == only { 1.0 } else { 0.0 };
        }
        match self.slots.get(index) {
            Some(&Slot::Finite(k)) => {
                // One pass: this light's importance and the sum, in `sample`'s order.
                let (mut importance, mut total) = (0.0f32, 0.0f32);
                for (j, (_, bounds)) in self.finite.iter().enumerate() {
                    let i = bounds.importance(receiver);
                    if j == k {
                        importance = i;
                    }
                    if i > 0.0 {
                        total += i;
                    }
                }
                if !(importance > 0.0) {
                    return 0.0;
                }
                (1.0 - self.share_given(true)) * importance / total
            }
            Some(&Slot::Infinite(k)) => self.infinite.as_ref().map_or(0.0, |t| {
                self.share_given(self.any_finite_light_reaches(receiver)) * t.pmf(k)
            }),
            Some(&Slot::Never) | None => 0.0,
        }
    }

    /// The one light there is to choose, if the scene has a single one with power (it is then
    /// chosen everywhere, even where it cannot give light, at no cost).
    #[inline]
    fn only_light(&self) -> Option<usize> {
        match (self.finite.as_slice(), self.infinite_lights.as_slice()) {
            ([(index, _)], []) | ([], [index]) => Some(*index),
            _ => None,
        }
    }

    /// Whether some finite light has importance at `receiver`.
    fn any_finite_light_reaches(&self, receiver: &Receiver) -> bool {
        self.finite
            .iter()
            .any(|(_, b)| b.importance(receiver) > 0.0)
    }

    /// The probability of choosing some light at infinity: N_∞/(N_∞ + 1) where a finite light
    /// has importance, else 1 (0 without lights at infinity).
    fn share_given(&self, finite_light_reaches: bool) -> f32 {
        match (&self.infinite, finite_light_reaches) {
            (None, _) => 0.0,
            (Some(_), true) => self.infinite_share,
            (Some(_), false) => 1.0,
        }
    }
}

/// The largest f32 below 1.
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;
