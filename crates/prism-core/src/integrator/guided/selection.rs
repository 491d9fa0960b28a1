//! The learned probability of sampling the BSDF rather than the guide (Müller 2019, "Practical
//! Path Guiding in Production", §10.5 "Learning the BSDF sampling fraction"; the authors'
//! `bsdfSamplingFractionLoss`): each spatial leaf (and orientation class) keeps α = σ(θ), the
//! logistic function of a parameter θ trained by stochastic gradient descent on the records
//! filed into it.
//!
//! A record at direction ω drawn with density p_wo(ω) brings the integrand's estimate
//! F = f(ω) cos θ L_i(ω) (the mean over the wavelengths) and the two densities p_bsdf(ω) and
//! p_guide(ω) of the mixture p_α = α p_bsdf + (1 − α) p_guide. The loss is the KL divergence
//! from F / ∫F to p_α (`kl`) or the variance of F / p_α (`var`); their gradients in α, estimated
//! from the one record, are
//!
//!   ∂D/∂α ≈ −(F / p_α)ᵏ (p_bsdf − p_guide) / p_wo,  k = 1 (`kl`) or 2 (`var`),
//!
//! times ∂α/∂θ = α (1 − α) for θ, plus the L2 regulariser's 0.01 θ. θ follows Adam (Kingma & Ba
//! 2014; learning rate 0.01, β₁ = 0.9, β₂ = 0.999, ε = 10⁻⁸, a step per record, the authors'
//! choices), clamped to [−20, 20]. θ starts at 0 (α = ½), is copied to both halves where a leaf
//! splits, and is kept from one iteration to the next.

use super::encoding::{Decoder, Encoder, Malformed};

/// Which loss trains α.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SelectionLoss {
    /// α is fixed (`bsdfSamplingFraction`).
    None,
    /// The KL divergence from the normalised integrand to the mixture.
    KullbackLeibler,
    /// The variance of the estimate F / p_α.
    Variance,
}

impl SelectionLoss {
    /// k, the power of F / p_α in the loss's gradient (0 where nothing is learned).
    fn power(self) -> i32 {
        match self {
            SelectionLoss::None => 0,
            SelectionLoss::KullbackLeibler => 1,
            SelectionLoss::Variance => 2,
        }
    }
}

/// What a record brings to the training of α.
#[derive(Clone, Copy, Debug)]
pub struct SelectionSample {
    /// F = f cos θ L_i at the record's direction (the mean over the wavelengths).
    pub integrand: f32,
    /// The density the direction was drawn with.
    pub pdf: f32,
    pub bsdf_pdf: f32,
    pub guide_pdf: f32,
}

const LEARNING_RATE: f64 = 0.01;
const BETA1: f64 = 0.9;
const BETA2: f64 = 0.999;
const EPSILON: f64 = 1e-8;
/// The L2 regulariser's weight: its gradient is this times θ.
const REGULARISATION: f64 = 0.01;
/// The bound on |θ|: σ(±20) is 1 within 2·10⁻⁹.
const THETA_BOUND: f64 = 20.0;

/// The learned α of a spatial leaf: θ and Adam's moments.
#[derive(Clone, Copy, Debug, Default)]
pub struct LearnedSelection {
    theta: f64,
    first_moment: f64,
    second_moment: f64,
    steps: i32,
}

/// The logistic function.
fn logistic(x: f64) -> f64 {
    1.0 / (1.0 + (-x).exp())
}

impl LearnedSelection {
    /// α = σ(θ).
    pub fn fraction(&self) -> f32 {
        logistic(self.theta) as f32
    }

    /// Takes a gradient step on `sample` under `loss` (see the module's text); samples
    /// without integrand or density are skipped.
    pub fn train(&mut self, sample: &SelectionSample, loss: SelectionLoss) {
        let power = loss.power();
        if power == 0
            || !(sample.integrand > 0.0 && sample.integrand.is_finite())
            || !(sample.pdf > 0.0 && sample.pdf.is_finite())
        {
            return;
        }
        let alpha = logistic(self.theta);
        let bsdf_pdf = f64::from(sample.bsdf_pdf);
        let guide_pdf = f64::from(sample.guide_pdf);
        let mixture = alpha * bsdf_pdf + (1.0 - alpha) * guide_pdf;
        if !(mixture > 0.0) {
            return;
        }
        let ratio = (f64::from(sample.integrand) / mixture).powi(power);
        let d_alpha = -ratio * (bsdf_pdf - guide_pdf) / f64::from(sample.pdf);
        let gradient = d_alpha * alpha * (1.0 - alpha) + REGULARISATION * self.theta;
        if gradient.is_finite() {
            self.step(gradient);
        }
    }

    /// Appends θ, Adam's two moments and its step count.
    pub fn encode(&self, out: &mut Encoder) {
        out.f64(self.theta);
        out.f64(self.first_moment);
        out.f64(self.second_moment);
        out.i32(self.steps);
    }

    /// Reads what [`Self::encode`] wrote: θ within its bound, the moments finite, the second
    /// and the step count not negative.
    pub fn decode(input: &mut Decoder) -> Result<LearnedSelection, Malformed> {
        let theta = input.f64_at_least(-THETA_BOUND, "a learned θ")?;
        if theta > THETA_BOUND {
            return Err(format!("a learned θ is {theta}"));
        }
        let first_moment = input.f64_at_least(f64::MIN, "a learned θ's first moment")?;
        let second_moment = input.f64_at_least(0.0, "a learned θ's second moment")?;
        let steps = input.i32()?;
        if steps < 0 {
            return Err(format!("a learned θ has taken {steps} steps"));
        }
        Ok(LearnedSelection {
            theta,
            first_moment,
            second_moment,
            steps,
        })
    }

    /// One step of Adam with `gradient`.
    fn step(&mut self, gradient: f64) {
        self.steps = self.steps.saturating_add(1);
        let rate =
            LEARNING_RATE * (1.0 - BETA2.powi(self.steps)).sqrt() / (1.0 - BETA1.powi(self.steps));
        self.first_moment = BETA1 * self.first_moment + (1.0 - BETA1) * gradient;
        self.second_moment = BETA2 * self.second_moment + (1.0 - BETA2) * gradient * gradient;
        self.theta -= rate * self.first_moment / (self.second_moment.sqrt() + EPSILON);
        self.theta = self.theta.clamp(-THETA_BOUND, THETA_BOUND);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::rng::Pcg32;

    /// Where the guide's density is the integrand's and the BSDF's is uniform, the variance of
    /// F / p_α is least at α = 0 and the KL divergence too: trained on samples drawn from the
    /// mixture, α falls from ½ to below 0.3 (the regulariser, pulling θ to 0, keeps it above
    /// 0; the KL divergence's gradient vanishes at α = 0). Where the guide is uniform and the
    /// BSDF's density the integrand's, α rises above 0.7. The integrand on [0, 1]: F(x) = 2x.
    #[test]
    fn learned_fraction_moves_towards_the_better_density() {
        for loss in [SelectionLoss::KullbackLeibler, SelectionLoss::Variance] {
            for guide_is_good in [true, false] {
                let mut learned = LearnedSelection::default();
                let mut rng = Pcg32::new(17, 1);
                for _ in 0..20_000 {
                    let alpha = learned.fraction();
                    // The good density 2x is drawn as √u; the uniform one as u.
                    let choose_bsdf = rng.next_f32() < alpha;
                    let u = rng.next_f32().max(1e-6);
                    let good_drawn = choose_bsdf != guide_is_good;
                    let x = if good_drawn { u.sqrt() } else { u };
                    let (good, uniform) = (2.0 * x, 1.0);
                    let (bsdf_pdf, guide_pdf) = if guide_is_good {
                        (uniform, good)
                    } else {
                        (good, uniform)
                    };
                    let sample = SelectionSample {
                        integrand: 2.0 * x,
                        pdf: alpha * bsdf_pdf + (1.0 - alpha) * guide_pdf,
                        bsdf_pdf,
                        guide_pdf,
                    };
                    learned.train(&sample, loss);
                }
                let alpha = learned.fraction();
                if guide_is_good {
                    assert!(alpha < 0.3, "{loss:?}: α = {alpha} with a good guide");
                } else {
                    assert!(alpha > 0.7, "{loss:?}: α = {alpha} with a good BSDF");
                }
            }
        }
    }

    /// Without a loss, or without integrand, α stays ½.
    #[test]
    fn fraction_stays_without_a_loss() {
        let mut learned = LearnedSelection::default();
        let sample = SelectionSample {
            integrand: 1.0,
            pdf: 1.0,
            bsdf_pdf: 2.0,
            guide_pdf: 0.5,
        };
        learned.train(&sample, SelectionLoss::None);
        learned.train(
            &SelectionSample {
                integrand: 0.0,
                ..sample
            },
            SelectionLoss::KullbackLeibler,
        );
        assert_eq!(learned.fraction(), 0.5);
    }
}
