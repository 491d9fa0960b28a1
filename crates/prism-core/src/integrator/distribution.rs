//! The lecture's distribution ray tracer (`distrib`): the recursive estimator of the slides
//! "Reference Implementation: reflected radiance", "Indirect Light Sampling" and "Refined
//! Implementation for Direct Light Sampling", with splitting and Russian roulette chosen from the
//! path's potential.
//!
//! At a surface point the reflected radiance is split into a direct part, estimated by shadow
//! rays to the lights, and an indirect part, estimated by N BSDF samples whose hits contribute
//! only their own reflected radiance (never their emission, which the direct part counts):
//!
//! ```text
//! L_r = (1/s) [ Σ_l (1/(p_l N_l)) Σ_k f L_e G / p(y_k)  +  (1/N) Σ_i (f cos / p)(ω_i) L_r(y_i) ]
//! ```
//! with probability s and 0 otherwise (Russian roulette). Emission found after a specular
//! bounce is counted, since no shadow ray can find it.
//!
//! The *potential* of a vertex is the factor its estimate will be multiplied by in the pixel:
//! the product of the weights (f cos / p)/(N s) along the path (its largest value over the
//! wavelengths). From it the estimator chooses, as the slides' `choose_s`, `choose_N` and
//! `estimate_nr_shadow_rays` do:
//! * s = min(1, potential / `rr_threshold`): paths that matter little are ended with high
//!   probability, never by a fixed depth (from depth 128 on, s is at most 0.95, so that a path
//!   caught between mirrors or glass ends too);
//! * N = clamp(round(`bounce_samples` · potential), 1, `bounce_samples`) bounce samples;
//! * N_l = clamp(round(`shadow_rays` · potential), 1, `shadow_rays`) shadow rays per light.
//!
//! At the camera's first hit (potential 1) the estimator splits the most; deeper down it falls
//! back to path tracing. Every choice only redistributes effort, so the estimate stays unbiased.
//!
//! Dispersion is handled as in the path tracer: a vertex whose evaluable BSDF is dispersive, and
//! every bounce sample that refracts through a dispersive interface, continue with the hero
//! wavelength alone, and their estimate enters the vertex's as N times the hero's radiance
//! (the hero-only estimator of the same integral), so each branch of the split decides for
//! itself.
//!
//! The recursion is traced as a tree of rays, depth first and one ray per step
//! ([`SteppedPath`]), so that the estimator's camera samples run in the render driver's lanes:
//! at a vertex, after its shadow rays, all N bounce directions are drawn, then each bounce's
//! subtree is traced before the next, as the slides' recursion orders the rays (the recursion
//! draws each bounce's direction just before its subtree, so the random numbers fall in
//! another order than a literal transcription's, for the same estimator). The factors
//! along a branch (the weights, 1/s, 1/N and the hero-only factor of a dispersive vertex or
//! bounce) are all per wavelength, so they multiply into the branch's weight instead of being
//! applied on the way back up.
//!
//! Its parameters (`bounce_samples` N and `shadow_rays` N_l at potential 1, `rr_threshold`, the
//! choice of `lights`, `max_depth`, `hide_emitters`) and their defaults are listed in
//! docs/plugins.md.

use glam::Vec3;

use crate::bsdf::{BxdfTree, Scattering};
use crate::geometry::SurfaceInteraction;
use crate::integrator::SampleContext;
use crate::integrator::mis::{emission_along, sample_point_on, unoccluded};
use crate::integrator::stepped::SteppedPath;
use crate::integrator::vertex::{
    CERTAIN_SURVIVAL_DEPTH, MAX_SURVIVAL, allows_next_vertex, hero_only, surface_scattering,
};
use crate::light::{Light, LightSelection, Receiver};
use crate::math::Ray;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::world::World;

/// Which lights a vertex sends shadow rays to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DirectLights {
    /// One light per shading point, drawn by the integrator's light sampler (by importance,
    /// ∝ power, or uniformly) and the estimate divided by its probability.
    One(LightSelection),
    /// Every light, each with its own shadow rays (the slides' loop over the lights).
    All,
}

#[derive(Clone, Debug)]
pub struct DistributionIntegrator {
    pub max_depth: i32,
    pub bounce_samples: u32,
    pub shadow_rays: u32,
    pub lights: DirectLights,
    pub rr_threshold: f32,
    pub hide_emitters: bool,
}

impl Default for DistributionIntegrator {
    fn default() -> Self {
        DistributionIntegrator {
            max_depth: -1,
            bounce_samples: 4,
            shadow_rays: 4,
            lights: DirectLights::One(LightSelection::Exhaustive),
            rr_threshold: 0.1,
            hide_emitters: false,
        }
    }
}

/// A count from the potential: clamp(round(maximum · potential), 1, maximum).
fn count_from_potential(maximum: u32, potential: f32) -> u32 {
    ((maximum as f32 * potential).round() as u32).clamp(1, maximum.max(1))
}

impl DistributionIntegrator {
    /// The slides' `choose_s`: the survival probability of Russian roulette at `depth`. From
    /// depth [`CERTAIN_SURVIVAL_DEPTH`] on it is at most 0.95, as in the path tracer: the slides'
    /// rule alone never ends a path whose potential stays above the threshold, such as one
    /// caught between glass surfaces, and the recursion would have no bound.
    pub fn choose_s(&self, potential: f32, depth: i32) -> f32 {
        let survival = (potential / self.rr_threshold).min(1.0);
        if depth >= CERTAIN_SURVIVAL_DEPTH {
            survival.min(MAX_SURVIVAL)
        } else {
            survival
        }
    }

    /// The slides' `choose_N`: bounce samples at a vertex.
    pub fn choose_n(&self, potential: f32) -> u32 {
        count_from_potential(self.bounce_samples, potential)
    }

    /// The slides' `estimate_nr_shadow_rays`: shadow rays per light at a vertex.
    pub fn shadow_rays_for(&self, potential: f32) -> u32 {
        count_from_potential(self.shadow_rays, potential)
    }

    /// How its light sampler weighs the lights (power when every light gets shadow rays: the
    /// sampler is then not used).
    pub(super) fn light_selection(&self) -> LightSelection {
        match self.lights {
            DirectLights::One(selection) => selection,
            DirectLights::All => LightSelection::Power,
        }
    }

    /// The reflected radiance at the hit `si` of `branch`, seen from `wo_world` (the slides'
    /// `reflected_radiance`): its direct part by shadow rays is added to `result`, and its split
    /// indirect part becomes bounce branches, pushed on `pending` so that the first is traced
    /// next.
    fn reflected(
        &self,
        ctx: &mut SampleContext,
        branch: &Branch,
        si: &SurfaceInteraction,
        wo_world: Vec3,
        result: &mut SampledSpectrum,
        pending: &mut Vec<Branch>,
    ) {
        let level = branch.level;
        let survival = self.choose_s(level.potential, level.depth);
        if !(ctx.sampler.next_1d() < survival) {
            return;
        }
        let mut lobes = BxdfTree::empty();
        let mut lambda = branch.lambda;
        let scattering = surface_scattering(ctx.world(), si, wo_world, &mut lambda, &mut lobes);
        let mut weight = branch.weight * (1.0 / survival);
        // A vertex whose BSDF keeps only the hero continues with it alone.
        if lambda.secondary_terminated() && !branch.lambda.secondary_terminated() {
            weight = hero_only(weight);
        }
        if scattering.flags().has_smooth_lobe() {
            *result += weight * self.direct(ctx, si, &scattering, level.potential, &lambda);
        }

        let n = self.choose_n(level.potential);
        let first = pending.len();
        for _ in 0..n {
            let u_lobe = ctx.sampler.next_1d();
            let u = ctx.sampler.next_2d();
            let Some(bs) = scattering.sample(u_lobe, u) else {
                continue;
            };
            let mut bounce = Branch {
                ray: si.spawn_ray(bs.wi),
                weight: weight * bs.weight * (1.0 / n as f32),
                level: Level {
                    depth: level.depth + 1,
                    potential: level.potential * bs.weight.max_value() / (n as f32 * survival),
                },
                with_emission: bs.flags.is_delta(),
                lambda,
            };
            if bs.terminates_secondary && !lambda.secondary_terminated() {
                // This direction is the hero's alone: so is what arrives along it.
                bounce.lambda.terminate_secondary();
                bounce.weight = hero_only(bounce.weight);
            }
            pending.push(bounce);
        }
        pending[first..].reverse();
    }

    /// Direct light by shadow rays: N_l per light, over every light or one drawn by the light
    /// sampler.
    fn direct(
        &self,
        ctx: &mut SampleContext,
        si: &SurfaceInteraction,
        scattering: &Scattering,
        potential: f32,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let world = ctx.world();
        let rays = self.shadow_rays_for(potential);
        let estimate_light = |ctx: &mut SampleContext, light: &Light| {
            let mut sum = SampledSpectrum::ZERO;
            for _ in 0..rays {
                let Some(ls) = sample_point_on(ctx, light, si.p, si.time, lambda) else {
                    continue;
                };
                if let Some(f) = unoccluded(ctx, si, scattering, &ls) {
                    sum += f.value * ls.radiance * (1.0 / ls.pdf);
                }
            }
            sum * (1.0 / rays as f32)
        };
        match self.lights {
            DirectLights::All => {
                let mut total = SampledSpectrum::ZERO;
                for light in &world.lights {
                    total += estimate_light(ctx, light);
                }
                total
            }
            DirectLights::One(_) => {
                let u_light = ctx.sampler.next_1d();
                let receiver = Receiver::surface(si.p, si.shading.n);
                let Some((index, pmf)) = ctx.light_sampler().sample(u_light, &receiver) else {
                    return SampledSpectrum::ZERO;
                };
                estimate_light(ctx, &world.lights[index]) * (1.0 / pmf)
            }
        }
    }
}

/// A ray of the estimator's tree of rays, with the factor the radiance arriving along it
/// enters the pixel's estimate with.
#[derive(Clone, Copy, Debug)]
struct Branch {
    ray: Ray,
    /// The product of the weights (f cos / p)/(N s) from the camera to this ray, with the
    /// hero-only factors of the dispersive vertices on the way.
    weight: SampledSpectrum,
    level: Level,
    /// Whether emission found along the ray counts: camera rays and specular bounces, which
    /// no shadow ray could have found.
    with_emission: bool,
    lambda: SampledWavelengths,
}

/// The estimator's tree of rays for one camera sample, traced depth first, one ray per step,
/// in the order of the slides' recursion: the branch being traced, those waiting, and the sum
/// of the tree's contributions so far.
#[derive(Clone, Debug)]
pub struct DistributionState {
    current: Branch,
    /// Branches waiting, the next on top.
    pending: Vec<Branch>,
    result: SampledSpectrum,
}

impl SteppedPath for DistributionIntegrator {
    type State = DistributionState;

    /// The tree of the camera ray; None when `max_depth` is 0.
    fn start(
        &self,
        _world: &World,
        ray: Ray,
        wavelengths: &SampledWavelengths,
    ) -> Option<DistributionState> {
        (self.max_depth != 0).then(|| DistributionState {
            current: Branch {
                ray,
                weight: SampledSpectrum::ONE,
                level: Level {
                    depth: 0,
                    potential: 1.0,
                },
                with_emission: !self.hide_emitters,
                lambda: *wavelengths,
            },
            pending: Vec::new(),
            result: SampledSpectrum::ZERO,
        })
    }

    #[inline]
    fn ray(state: &DistributionState) -> &Ray {
        &state.current.ray
    }

    /// The radiance arriving along the current branch's ray at `hit` (the slides'
    /// `incoming_radiance`): the emission found there where it counts, the direct part of the
    /// reflected radiance, and the bounce branches; then the next branch waiting.
    fn step(
        &self,
        ctx: &mut SampleContext,
        state: &mut DistributionState,
        hit: Option<SurfaceInteraction>,
    ) -> bool {
        let branch = state.current;
        let d = branch.ray.d.normalize();
        if branch.with_emission
            && let Some(found) = emission_along(ctx.world(), d, hit.as_ref(), &branch.lambda)
        {
            state.result += branch.weight * found.radiance;
        }
        if let Some(si) = hit
            && allows_next_vertex(self.max_depth, branch.level.depth)
        {
            self.reflected(ctx, &branch, &si, -d, &mut state.result, &mut state.pending);
        }
        match state.pending.pop() {
            Some(next) => {
                state.current = next;
                true
            }
            None => false,
        }
    }

    #[inline]
    fn estimate(&self, state: &DistributionState) -> SampledSpectrum {
        state.result
    }
}

/// Where a vertex stands in the recursion: its depth, and its potential, the factor its estimate
/// is multiplied by in the pixel (the product of the weights (f cos / p)/(N s) along the path,
/// its largest value over the wavelengths), from which the splitting and roulette are chosen.
#[derive(Clone, Copy, Debug)]
struct Level {
    depth: i32,
    potential: f32,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn choices_follow_the_potential() {
        let integrator = DistributionIntegrator::default();
        assert_eq!(integrator.choose_n(1.0), 4);
        assert_eq!(integrator.choose_n(0.3), 1);
        assert_eq!(integrator.choose_n(0.0), 1);
        assert_eq!(integrator.shadow_rays_for(0.6), 2);
        assert_eq!(integrator.choose_s(1.0, 0), 1.0);
        assert!((integrator.choose_s(0.05, 0) - 0.5).abs() < 1e-6);
        assert_eq!(integrator.choose_s(1.0, CERTAIN_SURVIVAL_DEPTH), 0.95);
    }
}
