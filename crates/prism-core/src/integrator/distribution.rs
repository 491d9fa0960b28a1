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
//! ```xml
//! <integrator type="distrib">
//!     <integer name="max_depth" value="-1"/>          <!-- as for path -->
//!     <integer name="bounce_samples" value="4"/>      <!-- N at potential 1 -->
//!     <integer name="shadow_rays" value="4"/>         <!-- N_l at potential 1 -->
//!     <string name="lights" value="power"/>           <!-- one light chosen ∝ "power" or "uniform"ly; or "all" -->
//!     <float name="rr_threshold" value="0.1"/>        <!-- potential below which roulette starts -->
//!     <boolean name="hide_emitters" value="false"/>
//! </integrator>
//! ```

use glam::Vec3;

use crate::bsdf::{BxdfTree, Scattering};
use crate::geometry::SurfaceInteraction;
use crate::integrator::{PreparedIntegrator, RayCount, hero_only, unoccluded};
use crate::light::{Light, LightSelection, Receiver};
use crate::math::Ray;
use crate::sampling::sampler::Sampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// Which lights a vertex sends shadow rays to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DirectLights {
    /// One light per shading point, drawn by the integrator's light sampler (∝ power, or
    /// uniformly) and the estimate divided by its probability.
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

    fn depth_allows_next_vertex(&self, depth: i32) -> bool {
        self.max_depth < 0 || depth + 1 < self.max_depth
    }

    pub(super) fn radiance(
        &self,
        prepared: &PreparedIntegrator,
        ray: Ray,
        lambda: &SampledWavelengths,
        sampler: &mut Sampler,
        count: &mut RayCount,
    ) -> SampledSpectrum {
        if self.max_depth == 0 {
            return SampledSpectrum::ZERO;
        }
        let mut estimate = Estimate {
            integrator: self,
            prepared,
            sampler,
            count,
        };
        estimate.incoming(ray, 0, 1.0, !self.hide_emitters, lambda)
    }
}

/// One camera sample's recursive estimate: the integrator, its world and light sampler, and the
/// sample's random numbers and ray count.
struct Estimate<'a, 's> {
    integrator: &'a DistributionIntegrator,
    prepared: &'a PreparedIntegrator<'a>,
    sampler: &'s mut Sampler,
    count: &'s mut RayCount,
}

impl Estimate<'_, '_> {
    /// Radiance arriving along `ray` (the slides' `incoming_radiance`); emission at the hit is
    /// counted only when `with_emission`.
    fn incoming(
        &mut self,
        ray: Ray,
        depth: i32,
        potential: f32,
        with_emission: bool,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let world = self.prepared.world;
        self.count.rays += 1;
        let Some(si) = world.geometry.intersect(&ray) else {
            // Leaving the scene: the environment is a light like any other, counted here only
            // where no shadow ray could have found it (camera rays, specular bounces).
            return match world.environment {
                Some(env) if with_emission => {
                    world.lights[env as usize].environment_radiance(ray.d.normalize(), lambda)
                }
                _ => SampledSpectrum::ZERO,
            };
        };
        let wo_world = -ray.d.normalize();
        let info = world.shape_info[si.shape as usize];
        let mut result = SampledSpectrum::ZERO;
        if with_emission
            && let Some(light_index) = info.light
            && let Light::Area(light) = &world.lights[light_index as usize]
        {
            result += light.emitted(si.uv, si.shading.n, wo_world, lambda);
        }
        if self.integrator.depth_allows_next_vertex(depth) {
            result += self.reflected(&si, wo_world, depth, potential, lambda);
        }
        result
    }

    /// Reflected radiance at `si` towards `wo_world` (the slides' `reflected_radiance`).
    fn reflected(
        &mut self,
        si: &SurfaceInteraction,
        wo_world: Vec3,
        depth: i32,
        potential: f32,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let world = self.prepared.world;
        let survival = self.integrator.choose_s(potential, depth);
        if !(self.sampler.next_1d() < survival) {
            return SampledSpectrum::ZERO;
        }
        let material = &world.materials[world.shape_info[si.shape as usize].material as usize];
        // This level's lobes, alive while the levels below it are estimated.
        let mut lobes = BxdfTree::empty();
        let scattering = material.scattering(si, wo_world, lambda, &mut lobes);
        let smooth = scattering.flags().has_smooth_lobe();
        // A dispersive BSDF that can be evaluated uses the hero's index for all its lobes
        // (roughdielectric): the whole vertex continues with the hero alone.
        if smooth && scattering.is_dispersive() && !lambda.secondary_terminated() {
            let mut hero = *lambda;
            hero.terminate_secondary();
            let estimate = self.scatter(si, &scattering, depth, potential, survival, &hero);
            return hero_only(estimate);
        }
        self.scatter(si, &scattering, depth, potential, survival, lambda)
    }

    /// The direct and split indirect estimate at a vertex that survived roulette with
    /// probability `survival`.
    fn scatter(
        &mut self,
        si: &SurfaceInteraction,
        scattering: &Scattering,
        depth: i32,
        potential: f32,
        survival: f32,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let mut result = SampledSpectrum::ZERO;
        if scattering.flags().has_smooth_lobe() {
            result += self.direct(si, scattering, potential, lambda);
        }

        let n = self.integrator.choose_n(potential);
        let mut indirect = SampledSpectrum::ZERO;
        for _ in 0..n {
            let u_lobe = self.sampler.next_1d();
            let u = self.sampler.next_2d();
            let Some(bs) = scattering.sample(u_lobe, u) else {
                continue;
            };
            let specular = bs.flags.is_delta();
            let next_potential = potential * bs.weight.max_value() / (n as f32 * survival);
            let ray = si.spawn_ray(bs.wi);
            let arriving = if bs.terminates_secondary && !lambda.secondary_terminated() {
                // This direction is the hero's alone: so is what arrives along it.
                let mut hero = *lambda;
                hero.terminate_secondary();
                hero_only(self.incoming(ray, depth + 1, next_potential, specular, &hero))
            } else {
                self.incoming(ray, depth + 1, next_potential, specular, lambda)
            };
            indirect += bs.weight * arriving;
        }
        result += indirect * (1.0 / n as f32);
        result * (1.0 / survival)
    }

    /// Direct light by shadow rays: N_l per light, over every light or one drawn by the light
    /// sampler.
    fn direct(
        &mut self,
        si: &SurfaceInteraction,
        scattering: &Scattering,
        potential: f32,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let world = self.prepared.world;
        let rays = self.integrator.shadow_rays_for(potential);
        let estimate_light = |light: &Light, sampler: &mut Sampler, count: &mut RayCount| {
            let mut sum = SampledSpectrum::ZERO;
            for _ in 0..rays {
                let u_choice = sampler.next_1d();
                let u = sampler.next_2d();
                let Some(ls) = light.sample_incident(
                    &world.geometry.primitives,
                    si.p,
                    si.time,
                    u_choice,
                    u,
                    lambda,
                ) else {
                    continue;
                };
                if let Some(f) = unoccluded(world, si, scattering, &ls, count) {
                    sum += f.value * ls.radiance * (1.0 / ls.pdf);
                }
            }
            sum * (1.0 / rays as f32)
        };
        match self.integrator.lights {
            DirectLights::All => {
                let mut total = SampledSpectrum::ZERO;
                for light in &world.lights {
                    total += estimate_light(light, self.sampler, self.count);
                }
                total
            }
            DirectLights::One(_) => {
                let Some((index, pmf)) = self.prepared.light_sampler.sample(
                    self.sampler.next_1d(),
                    &Receiver::surface(si.p, si.shading.n),
                ) else {
                    return SampledSpectrum::ZERO;
                };
                estimate_light(&world.lights[index], self.sampler, self.count) * (1.0 / pmf)
            }
        }
    }
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
