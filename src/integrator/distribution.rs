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
//!   probability, never by a fixed depth;
//! * N = clamp(round(`bounce_samples` · potential), 1, `bounce_samples`) bounce samples;
//! * N_l = clamp(round(`shadow_rays` · potential), 1, `shadow_rays`) shadow rays per light.
//!
//! At the camera's first hit (potential 1) the estimator splits the most; deeper down it falls
//! back to path tracing. Every choice only redistributes effort, so the estimate stays unbiased.
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

use crate::bsdf::{Bsdf, ShadingPoint};
use crate::geometry::SurfaceInteraction;
use crate::integrator::RayCount;
use crate::light::{Light, LightSample, LightSelection};
use crate::math::Ray;
use crate::sampling::sampler::Sampler;
use crate::scene::Scene;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// Which lights a vertex sends shadow rays to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DirectLights {
    /// One light per shading point, drawn by the scene's light sampler (∝ power, or uniformly)
    /// and the estimate divided by its probability.
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
            lights: DirectLights::One(LightSelection::Power),
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
    /// The slides' `choose_s`: the survival probability of Russian roulette.
    pub fn choose_s(&self, potential: f32) -> f32 {
        (potential / self.rr_threshold).min(1.0)
    }

    /// The slides' `choose_N`: bounce samples at a vertex.
    pub fn choose_n(&self, potential: f32) -> u32 {
        count_from_potential(self.bounce_samples, potential)
    }

    /// The slides' `estimate_nr_shadow_rays`: shadow rays per light at a vertex.
    pub fn shadow_rays_for(&self, potential: f32) -> u32 {
        count_from_potential(self.shadow_rays, potential)
    }

    fn depth_allows_next_vertex(&self, depth: i32) -> bool {
        self.max_depth < 0 || depth + 1 < self.max_depth
    }

    pub fn radiance(
        &self,
        scene: &Scene,
        ray: Ray,
        lambda: &SampledWavelengths,
        sampler: &mut Sampler,
        count: &mut RayCount,
    ) -> SampledSpectrum {
        if self.max_depth == 0 {
            return SampledSpectrum::ZERO;
        }
        self.incoming(
            scene,
            ray,
            0,
            1.0,
            !self.hide_emitters,
            lambda,
            sampler,
            count,
        )
    }

    /// Radiance arriving along `ray` (the slides' `incoming_radiance`); emission at the hit is
    /// counted only when `with_emission`.
    #[allow(clippy::too_many_arguments)]
    fn incoming(
        &self,
        scene: &Scene,
        ray: Ray,
        depth: i32,
        potential: f32,
        with_emission: bool,
        lambda: &SampledWavelengths,
        sampler: &mut Sampler,
        count: &mut RayCount,
    ) -> SampledSpectrum {
        count.rays += 1;
        let Some(si) = scene.geometry.intersect(&ray) else {
            // Leaving the scene: the environment is a light like any other, counted here only
            // where no shadow ray could have found it (camera rays, specular bounces).
            return match scene.environment {
                Some(env) if with_emission => {
                    scene.lights[env as usize].environment_radiance(ray.d.normalize(), lambda)
                }
                _ => SampledSpectrum::ZERO,
            };
        };
        let wo_world = -ray.d.normalize();
        let info = scene.shape_info[si.shape as usize];
        let mut result = SampledSpectrum::ZERO;
        if with_emission
            && let Some(light_index) = info.light
            && let Light::Area(light) = &scene.lights[light_index as usize]
        {
            result += light.emitted(si.shading.n, wo_world, lambda);
        }
        if self.depth_allows_next_vertex(depth) {
            result += self.reflected(
                scene, &si, wo_world, depth, potential, lambda, sampler, count,
            );
        }
        result
    }

    /// Reflected radiance at `si` towards `wo_world` (the slides' `reflected_radiance`).
    #[allow(clippy::too_many_arguments)]
    fn reflected(
        &self,
        scene: &Scene,
        si: &SurfaceInteraction,
        wo_world: Vec3,
        depth: i32,
        potential: f32,
        lambda: &SampledWavelengths,
        sampler: &mut Sampler,
        count: &mut RayCount,
    ) -> SampledSpectrum {
        let survival = self.choose_s(potential);
        if !(sampler.next_1d() < survival) {
            return SampledSpectrum::ZERO;
        }
        let material = &scene.materials[scene.shape_info[si.shape as usize].material as usize];
        let (bsdf, flip) = material.side(si.shading.to_local(wo_world).z);
        let frame = if flip {
            si.shading.flipped()
        } else {
            si.shading
        };
        let sp = ShadingPoint {
            uv: si.uv,
            frame,
            ng: if si.n.dot(frame.n) < 0.0 { -si.n } else { si.n },
            dp_du: si.dp_du,
            dp_dv: si.dp_dv,
        };
        let wo = frame.to_local(wo_world);

        let mut result = SampledSpectrum::ZERO;
        if bsdf.flags().has_smooth_lobe() {
            result += self.direct(scene, si, &sp, bsdf, wo, potential, lambda, sampler, count);
        }

        let n = self.choose_n(potential);
        let mut indirect = SampledSpectrum::ZERO;
        for _ in 0..n {
            let u_lobe = sampler.next_1d();
            let u = sampler.next_2d();
            let Some(bs) = bsdf.sample(&sp, wo, u_lobe, u, lambda) else {
                continue;
            };
            let specular = bs.flags.is_delta();
            let next_potential = potential * bs.weight.max_value() / (n as f32 * survival);
            let ray = si.spawn_ray(frame.to_world(bs.wi));
            let arriving = self.incoming(
                scene,
                ray,
                depth + 1,
                next_potential,
                specular,
                lambda,
                sampler,
                count,
            );
            indirect += bs.weight * arriving;
        }
        result += indirect * (1.0 / n as f32);
        result * (1.0 / survival)
    }

    /// Direct light by shadow rays: N_l per light, over every light or one drawn by the scene's
    /// light sampler.
    #[allow(clippy::too_many_arguments)]
    fn direct(
        &self,
        scene: &Scene,
        si: &SurfaceInteraction,
        sp: &ShadingPoint,
        bsdf: &Bsdf,
        wo: Vec3,
        potential: f32,
        lambda: &SampledWavelengths,
        sampler: &mut Sampler,
        count: &mut RayCount,
    ) -> SampledSpectrum {
        let rays = self.shadow_rays_for(potential);
        let estimate_light = |light: &Light, sampler: &mut Sampler, count: &mut RayCount| {
            let mut sum = SampledSpectrum::ZERO;
            for _ in 0..rays {
                let u_choice = sampler.next_1d();
                let u = sampler.next_2d();
                let Some(ls) = light.sample_incident(
                    &scene.geometry.primitives,
                    si.p,
                    si.time,
                    u_choice,
                    u,
                    lambda,
                ) else {
                    continue;
                };
                sum += self.shadow_ray(scene, si, sp, bsdf, wo, &ls, lambda, count);
            }
            sum * (1.0 / rays as f32)
        };
        match self.lights {
            DirectLights::All => {
                let mut total = SampledSpectrum::ZERO;
                for light in &scene.lights {
                    total += estimate_light(light, sampler, count);
                }
                total
            }
            DirectLights::One(_) => {
                let Some((index, pmf)) = scene.light_sampler.sample(sampler.next_1d()) else {
                    return SampledSpectrum::ZERO;
                };
                estimate_light(&scene.lights[index], sampler, count) * (1.0 / pmf)
            }
        }
    }

    /// One shadow ray's contribution f L / p.
    #[allow(clippy::too_many_arguments)]
    fn shadow_ray(
        &self,
        scene: &Scene,
        si: &SurfaceInteraction,
        sp: &ShadingPoint,
        bsdf: &Bsdf,
        wo: Vec3,
        ls: &LightSample,
        lambda: &SampledWavelengths,
        count: &mut RayCount,
    ) -> SampledSpectrum {
        let wi = sp.frame.to_local(ls.wi);
        let f = bsdf.eval(sp, wo, wi, lambda);
        if f.is_black() {
            return SampledSpectrum::ZERO;
        }
        count.rays += 1;
        if scene.geometry.occluded(&si.spawn_ray_to(ls.p, ls.n)) {
            return SampledSpectrum::ZERO;
        }
        f * ls.radiance * (1.0 / ls.pdf)
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
        assert_eq!(integrator.choose_s(1.0), 1.0);
        assert!((integrator.choose_s(0.05) - 0.5).abs() < 1e-6);
    }
}
