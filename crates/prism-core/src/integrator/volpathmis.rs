//! The volumetric path tracer with spectral MIS (Mitsuba 3's `volpathmis`): `volpath`'s path
//! step ([`super::volpath`]) with the hero wavelength's free flights combined over the path's
//! four wavelengths by multiple importance sampling (Miller, Georgiev and Jarosz 2019, "A
//! Null-Scattering Path Integral Formulation of Light Transport", §5–6).
//!
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! # Free flights of the hero wavelength
//! Each wavelength λⱼ has its own majorant mⱼ ([`Medium::majorants`]: σ_t(λⱼ) itself in a
//! homogeneous medium, the grid's maximum in a heterogeneous one) and null coefficient
//! σ_n,ⱼ = mⱼ − σ_t(x, λⱼ). The path draws tentative collisions with the hero's majorant m₀ and
//! makes each real with probability σ_t,₀/m₀, null otherwise, so that "wavelength j as the hero"
//! is a sampling technique with the density, per event over a free path of length Δ,
//!
//!   pⱼ(real) = σ_t,ⱼ e^{−mⱼΔ},   pⱼ(null) = σ_n,ⱼ e^{−mⱼΔ},   pⱼ(reaching the surface) = e^{−mⱼΔ},
//!
//! while the null-scattering integrand of wavelength i is fᵢ(real) = σ_s,ᵢ e^{−mᵢΔ},
//! fᵢ(null) = σ_n,ᵢ e^{−mᵢΔ}, fᵢ(reaching) = e^{−mᵢΔ} (Miller et al., eq. 14). The hero is
//! equally likely to be any of the four wavelengths (they are P⁻¹(u + k/4) for one uniform u,
//! [`SampledWavelengths`]), so the one-sample balance heuristic over the four techniques,
//!
//!   ⟨Lᵢ⟩ = fᵢ(x̄) / ((1/4) Σⱼ pⱼ(x̄)),
//!
//! is unbiased for each wavelength and bounded where a companion is much less (or more) extinct
//! than the hero, where hero-wavelength tracking's fᵢ/p₀ grows without bound.
//!
//! # Light samples
//! Emission is also reached by light sampling from the last scattering vertex, so a path that
//! ends on an emitter has 2·4 techniques: the four wavelengths' free flights, each completed by
//! the directional sample (density p_dir) or by a light sample (density p_light, its shadow ray
//! not sampled but estimated: its transmittance in closed form through homogeneous media, by
//! ratio tracking with the majorant through heterogeneous ones). The balance heuristic over all
//! eight, ⟨Lᵢ⟩ = fᵢ / ((1/4) Σⱼ (p_uni,ⱼ + p_nee,ⱼ)), is what Mitsuba's `volpathmis` computes.
//!
//! The weights are kept relative to a common scale D (all ratios are unchanged by it):
//! βᵢ = fᵢ/D, Uⱼ = p_uni,ⱼ/D and Nⱼ = p_nee,ⱼ/(D·p_light) for the path so far, renormalised to
//! mean(U) = 1 after every event so that β is the path's MIS throughput. A directional sample
//! multiplies β by f/p_dir and starts N = U/p_dir; a free flight multiplies β by fᵢ, U by pⱼ and
//! N by the light sample's density of the same events (1 for a homogeneous segment, whose
//! transmittance is exact, and mⱼ e^{−mⱼΔ} per collision and e^{−mⱼΔ} at its end for ratio
//! tracking). Emission found by the path adds Lₑ βᵢ / (mean U + p_light mean N); a light sample
//! at a vertex adds f Tr t Lₑ βᵢ / (p_light mean U + p_dir mean(U·Tr)), since the unidirectional
//! technique would have had to pass the shadow ray's segment with density Tr (pⱼ(null)/p_nee
//! = σ_n,ⱼ/mⱼ per ratio-tracking collision, which is ratio tracking's own factor).
//!
//! A surface crossed by a null lobe (`null`, the pass-through of `thindielectric` or `mask`) is
//! no event of these sums: the path multiplies β by the sample's weight (the lobe's value over
//! the probability of choosing it) and keeps U and N, and a light sample's shadow ray carries
//! the surfaces' null transmission t in its value alone (t above; Tr is the media's), as
//! Mitsuba's does. Both techniques then cross the surface alike, so its weights cancel.
//!
//! Differences from Mitsuba's implementation: the real or null choice uses the hero's
//! σ_t,₀/m₀ (Mitsuba weighs it by the path's throughput as spectral tracking does), and the
//! densities are kept as the vector U instead of a 4 × 4 matrix of ratios (its rows are U/βᵢ).
//! A directional sample's density is taken to be the same for every wavelength as the hero,
//! which holds for Prism's BSDFs (dispersive ones keep only the hero, below).
//!
//! `use_spectral_mis = false` (Mitsuba's switch) weights each wavelength by the hero's densities
//! alone, fᵢ / (p_uni,₀ + p_nee,₀). A path that keeps only its hero (behind dispersive glass)
//! also uses the hero's densities for its whole estimate, since the four techniques no longer
//! share one path.

use crate::integrator::mis::LightSampleTerms;
use crate::integrator::throughput::{Estimate, Throughput};
use crate::integrator::volpath::PathWeights;
use crate::math::Ray;
use crate::medium::{Medium, sample_free_flight};
use crate::sampling::sampler::Sampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// `volpathmis`'s weights (see the module's documentation for the symbols).
#[derive(Clone)]
pub(crate) struct SpectralMis<T: Throughput = SampledSpectrum> {
    spectral_mis: bool,
    /// βᵢ = fᵢ / D.
    beta: T,
    /// Uⱼ = p_uni,ⱼ / D, with mean 1.
    uni: SampledSpectrum,
    /// Nⱼ = p_nee,ⱼ / (D p_light) since the last scattering vertex.
    nee: SampledSpectrum,
    /// Whether emission found next counts without MIS against light samples.
    unweighted: bool,
    /// The estimate with the four wavelengths' densities combined.
    result: T::Estimate,
    /// The estimate with the hero's densities alone.
    hero_result: T::Estimate,
}

/// e^{−mΔ}, 1 where m = 0 (also for Δ = ∞).
#[inline]
fn attenuation(majorant: SampledSpectrum, delta: f32) -> SampledSpectrum {
    SampledSpectrum::from_fn(|j| {
        if majorant[j] > 0.0 {
            (-majorant[j] * delta).exp()
        } else {
            1.0
        }
    })
}

/// `value / denominator`, zero where the denominator is zero or not finite.
#[inline]
fn over<E: Estimate>(value: E, denominator: f32) -> E {
    if denominator > 0.0 && denominator.is_finite() {
        value.scaled(1.0 / denominator)
    } else {
        E::ZERO
    }
}

impl<T: Throughput> SpectralMis<T> {
    pub(crate) fn new(spectral_mis: bool) -> Self {
        SpectralMis {
            spectral_mis,
            beta: T::ONE,
            uni: SampledSpectrum::ONE,
            nee: SampledSpectrum::ZERO,
            unweighted: true,
            result: T::Estimate::ZERO,
            hero_result: T::Estimate::ZERO,
        }
    }

    /// A free-flight event of integrand `f`, unidirectional densities `p_uni` and light-sample
    /// densities `p_nee` (per wavelength), then the renormalisation to mean(U) = 1.
    #[inline]
    fn event(&mut self, f: SampledSpectrum, p_uni: SampledSpectrum, p_nee: SampledSpectrum) {
        self.beta.scale(f);
        self.uni *= p_uni;
        self.nee *= p_nee;
        let scale = self.uni.average();
        if scale > 0.0 && scale.is_finite() {
            let inverse = 1.0 / scale;
            self.beta.scale_all(inverse);
            self.uni *= inverse;
            self.nee *= inverse;
        } else {
            self.beta = T::ZERO;
        }
    }
}

impl<T: Throughput> PathWeights for SpectralMis<T> {
    type Throughput = T;

    #[inline]
    fn throughput(&self) -> SampledSpectrum {
        self.beta.intensity()
    }

    #[inline]
    fn scale(&mut self, factor: f32) {
        self.beta.scale_all(factor);
    }

    fn free_flight(
        &mut self,
        medium: &Medium,
        ray: &Ray,
        t_surface: f32,
        lambda: &SampledWavelengths,
        sampler: &mut Sampler,
    ) -> Option<f32> {
        let (t0, t1) = medium.ray_extent(ray, t_surface)?;
        let majorant = medium.majorants(ray.d, lambda);
        let ratio_tracked = !medium.is_homogeneous();
        let mut t = t0;
        loop {
            let next = sample_free_flight(t, t1, majorant[0], sampler.next_1d());
            let Some(collision) = next else {
                let reach = attenuation(majorant, t1 - t);
                let nee = if ratio_tracked {
                    reach
                } else {
                    SampledSpectrum::ONE
                };
                self.event(reach, reach, nee);
                return None;
            };
            let reach = attenuation(majorant, collision - t);
            t = collision;
            let c = medium.coefficients(ray.at(t), ray.d, lambda);
            if !ratio_tracked || sampler.next_1d() * majorant[0] < c.sigma_t[0] {
                self.event(c.sigma_s * reach, c.sigma_t * reach, SampledSpectrum::ZERO);
                return Some(t);
            }
            let sigma_n =
                SampledSpectrum::from_fn(|j| (majorant[j] - c.sigma_t[j]).max(0.0)) * reach;
            self.event(sigma_n, sigma_n, majorant * reach);
            if self.beta.intensity().is_black() {
                return None;
            }
        }
    }

    #[inline]
    fn scatter(&mut self, weight: T, pdf: f32, unweighted: bool) {
        self.beta.then(weight);
        self.unweighted = unweighted || !(pdf > 0.0);
        self.nee = if self.unweighted {
            SampledSpectrum::ZERO
        } else {
            self.uni * (1.0 / pdf)
        };
    }

    /// β times the weight; U and N as they were (the crossing is no technique of the MIS).
    #[inline]
    fn pass_through(&mut self, weight: T) {
        self.beta.then(weight);
    }

    #[inline]
    fn weights_emission(&self) -> bool {
        !self.unweighted
    }

    /// Lₑ βᵢ / (mean U + p_light mean N), or Lₑ βᵢ / mean U when unweighted.
    #[inline]
    fn add_emission(&mut self, emitted: SampledSpectrum, light_pdf: f32) {
        let found = self.beta.gathers(emitted);
        let light_pdf = if self.unweighted { 0.0 } else { light_pdf };
        self.result.add(over(
            found,
            self.uni.average() + light_pdf * self.nee.average(),
        ));
        self.hero_result
            .add(over(found, self.uni[0] + light_pdf * self.nee[0]));
    }

    /// f Tr Lₑ βᵢ / (p_light mean U + p_dir mean(U·Tr_media)), p_dir = 0 for a delta light.
    #[inline]
    fn add_light_sample(&mut self, s: &LightSampleTerms, transfer: &T::LightTransfer) {
        let found = self.beta.gathers_light(s, transfer);
        let direction_pdf = if s.is_delta { 0.0 } else { s.direction_pdf };
        let passing = self.uni * s.transmittance.media;
        self.result.add(over(
            found,
            s.light_pdf * self.uni.average() + direction_pdf * passing.average(),
        ));
        self.hero_result.add(over(
            found,
            s.light_pdf * self.uni[0] + direction_pdf * passing[0],
        ));
    }

    #[inline]
    fn estimate(&self, lambda: &SampledWavelengths, lambda_was_whole: bool) -> T::Estimate {
        if lambda_was_whole && lambda.secondary_terminated() {
            self.hero_result.hero_only()
        } else if self.spectral_mis {
            self.result
        } else {
            self.hero_result
        }
    }
}
