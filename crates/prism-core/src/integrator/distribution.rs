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
//! Its parameters (`bounce_samples` N and `shadow_rays` N_l at potential 1, `rr_threshold`, the
//! choice of `lights`, `max_depth`, `hide_emitters`) and their defaults are listed in
//! docs/plugins.md.

use glam::Vec3;

use crate::bsdf::{BxdfTree, Scattering};
use crate::geometry::SurfaceInteraction;
use crate::integrator::SampleContext;
use crate::integrator::mis::{emission_along, sample_point_on, unoccluded};
use crate::integrator::vertex::{allows_next_vertex, hero_only, surface_scattering};
use crate::light::{Light, LightSelection, Receiver};
use crate::math::Ray;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

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

/// The depth below which the roulette may let a path survive with certainty.
pub const CERTAIN_SURVIVAL_DEPTH: i32 = 128;

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
            survival.min(0.95)
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

    pub(super) fn radiance(
        &self,
        ctx: &mut SampleContext,
        ray: Ray,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        if self.max_depth == 0 {
            return SampledSpectrum::ZERO;
        }
        let camera = Level {
            depth: 0,
            potential: 1.0,
        };
        self.incoming(ctx, ray, camera, !self.hide_emitters, lambda)
    }

    /// Radiance arriving along `ray` at a vertex of `level` (the slides' `incoming_radiance`);
    /// emission at the hit is counted only when `with_emission`.
    fn incoming(
        &self,
        ctx: &mut SampleContext,
        ray: Ray,
        level: Level,
        with_emission: bool,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let hit = ctx.intersect(&ray);
        let d = ray.d.normalize();
        let mut result = SampledSpectrum::ZERO;
        // Emission (the environment's when the ray leaves the scene) is counted only where no
        // shadow ray could have found it: camera rays and specular bounces.
        if with_emission && let Some(found) = emission_along(ctx.world(), d, hit.as_ref(), lambda) {
            result += found.radiance;
        }
        let Some(si) = hit else {
            return result;
        };
        if allows_next_vertex(self.max_depth, level.depth) {
            result += self.reflected(ctx, &si, -d, level, lambda);
        }
        result
    }

    /// Reflected radiance at `si` towards `wo_world` (the slides' `reflected_radiance`).
    fn reflected(
        &self,
        ctx: &mut SampleContext,
        si: &SurfaceInteraction,
        wo_world: Vec3,
        level: Level,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let survival = self.choose_s(level.potential, level.depth);
        if !(ctx.sampler.next_1d() < survival) {
            return SampledSpectrum::ZERO;
        }
        // This level's lobes, alive while the levels below it are estimated.
        let mut lobes = BxdfTree::empty();
        let mut vertex_lambda = *lambda;
        let scattering =
            surface_scattering(ctx.world(), si, wo_world, &mut vertex_lambda, &mut lobes);
        let estimate = self.scatter(ctx, si, &scattering, level, survival, &vertex_lambda);
        // A vertex whose BSDF keeps only the hero continues with it alone.
        if vertex_lambda.secondary_terminated() && !lambda.secondary_terminated() {
            hero_only(estimate)
        } else {
            estimate
        }
    }

    /// The direct and split indirect estimate at a vertex that survived roulette with
    /// probability `survival`.
    fn scatter(
        &self,
        ctx: &mut SampleContext,
        si: &SurfaceInteraction,
        scattering: &Scattering,
        level: Level,
        survival: f32,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let mut result = SampledSpectrum::ZERO;
        if scattering.flags().has_smooth_lobe() {
            result += self.direct(ctx, si, scattering, level.potential, lambda);
        }

        let n = self.choose_n(level.potential);
        let mut indirect = SampledSpectrum::ZERO;
        for _ in 0..n {
            let u_lobe = ctx.sampler.next_1d();
            let u = ctx.sampler.next_2d();
            let Some(bs) = scattering.sample(u_lobe, u) else {
                continue;
            };
            let specular = bs.flags.is_delta();
            let next = Level {
                depth: level.depth + 1,
                potential: level.potential * bs.weight.max_value() / (n as f32 * survival),
            };
            let ray = si.spawn_ray(bs.wi);
            let arriving = if bs.terminates_secondary && !lambda.secondary_terminated() {
                // This direction is the hero's alone: so is what arrives along it.
                let mut hero = *lambda;
                hero.terminate_secondary();
                hero_only(self.incoming(ctx, ray, next, specular, &hero))
            } else {
                self.incoming(ctx, ray, next, specular, lambda)
            };
            indirect += bs.weight * arriving;
        }
        result += indirect * (1.0 / n as f32);
        result * (1.0 / survival)
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
