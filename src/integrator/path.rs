//! The path tracer (Mitsuba's `path` integrator), as the lecture's "Monte Carlo Path Tracing":
//! one BSDF sample per bounce, so the estimate is the product (w₁/p₁)(w₂/p₂)…L_e, with direct
//! light sampling at every vertex ("Direct Light Sampling") and Russian roulette.
//!
//! ```xml
//! <integrator type="path">
//!     <integer name="max_depth" value="-1"/>     <!-- -1: unbounded; 1: emitters only; 2: direct -->
//!     <integer name="rr_depth" value="5"/>       <!-- depth at which Russian roulette starts -->
//!     <boolean name="hide_emitters" value="false"/>
//!     <string name="emitter_sampling" value="power"/>   <!-- or "uniform" (Prism only) -->
//! </integrator>
//! ```
//!
//! * Light sampling picks one light with probability ∝ its power (or uniformly, see
//!   [`crate::light::sampler`]) and divides by that probability (DESIGN.md §4). Light samples
//!   and BSDF samples that hit an emitter or leave the scene towards the environment are
//!   combined by multiple importance sampling with the power heuristic (Veach 1997, §9.2), so
//!   no light is counted twice; delta lights (point, spot, directional) are reached only by
//!   light sampling and BSDF-specular directions only by BSDF sampling.
//! * Russian roulette (the lecture's "Termination of Recursion"): from depth `rr_depth` on, the
//!   path continues with probability s = min(max_λ throughput · η², 0.95), the path's potential
//!   (η² undoes the radiance scaling of refractions, so that light inside glass is not killed
//!   for being compressed, as in Mitsuba 3), and its throughput is divided by s, which keeps the
//!   estimator unbiased. `max_depth` is the user's explicit truncation, -1 (the default) for none.
//! * Delta lobes (mirrors, clear glass, the null pass of `mask`) are found by BSDF sampling
//!   only: no light sampling towards them and no MIS for the emitters they lead to.
//! * Dispersion: where a BSDF refracts each wavelength its own way, the path keeps only its hero
//!   wavelength from there on (`SampledWavelengths::terminate_secondary`).
//! * Depth follows Mitsuba: the camera ray's hit is depth 0; a path of depth d has d bounces.

use crate::bsdf::{Bsdf, ShadingPoint};
use crate::geometry::SurfaceInteraction;
use crate::integrator::RayCount;
use crate::light::{Light, LightSelection};
use crate::math::Ray;
use crate::sampling::sampler::Sampler;
use crate::scene::Scene;
use crate::spectrum::{N_SPECTRUM_SAMPLES, SampledSpectrum, SampledWavelengths};

#[derive(Clone, Debug)]
pub struct PathIntegrator {
    /// Longest path in vertices after the camera; negative for unbounded.
    pub max_depth: i32,
    /// Depth from which Russian roulette is used.
    pub rr_depth: i32,
    /// Whether emitters seen directly by the camera are left black.
    pub hide_emitters: bool,
    /// How one light is chosen for each light sample.
    pub light_selection: LightSelection,
}

impl Default for PathIntegrator {
    fn default() -> Self {
        PathIntegrator {
            max_depth: -1,
            rr_depth: 5,
            hide_emitters: false,
            light_selection: LightSelection::Power,
        }
    }
}

/// The power heuristic with β = 2: w = p_a² / (p_a² + p_b²).
#[inline]
pub fn power_heuristic(pdf_a: f32, pdf_b: f32) -> f32 {
    let (a, b) = (pdf_a * pdf_a, pdf_b * pdf_b);
    if a.is_infinite() {
        return 1.0;
    }
    let w = a / (a + b);
    if w.is_finite() { w } else { 0.0 }
}

/// What the next vertex needs to know about the BSDF sample that led to it.
struct PreviousBounce {
    /// The vertex the ray left from.
    interaction: SurfaceInteraction,
    /// Solid-angle density of the BSDF sample.
    pdf: f32,
    /// Whether it came from a delta lobe (then emitters it finds are not light-sampled).
    specular: bool,
}

impl PathIntegrator {
    fn depth_allows_next_vertex(&self, depth: i32) -> bool {
        self.max_depth < 0 || depth + 1 < self.max_depth
    }

    pub fn radiance(
        &self,
        scene: &Scene,
        mut ray: Ray,
        wavelengths: &SampledWavelengths,
        sampler: &mut Sampler,
        count: &mut RayCount,
    ) -> SampledSpectrum {
        // The path's own copy: a dispersive interface may drop the companion wavelengths.
        let mut lambda = *wavelengths;
        let lambda_was_whole = !wavelengths.secondary_terminated();
        let mut result = SampledSpectrum::ZERO;
        let mut throughput = SampledSpectrum::ONE;
        // Product of the relative indices of refraction crossed (Mitsuba's η).
        let mut eta_scale = 1.0f32;
        let mut previous: Option<PreviousBounce> = None;
        let mut depth = 0i32;
        if self.max_depth == 0 {
            return result;
        }
        loop {
            count.rays += 1;
            let Some(si) = scene.geometry.intersect(&ray) else {
                // The ray leaves the scene: the environment's emission, weighted like an area
                // light's against the light sample that could have found it.
                if let Some(env) = scene.environment
                    && !(self.hide_emitters && depth == 0)
                {
                    result += throughput * self.environment(scene, env, &ray, &previous, &lambda);
                }
                break;
            };
            let wo_world = -ray.d.normalize();
            let info = scene.shape_info[si.shape as usize];

            // Emission found by the previous BSDF sample (or by the camera ray).
            if let Some(light_index) = info.light
                && !(self.hide_emitters && depth == 0)
            {
                let Light::Area(light) = &scene.lights[light_index as usize] else {
                    unreachable!("only area lights are attached to shapes");
                };
                let emitted = light.emitted(si.shading.n, wo_world, &lambda);
                if !emitted.is_black() {
                    let weight = match &previous {
                        Some(prev) if !prev.specular => {
                            let shape = &scene.geometry.primitives[si.shape as usize];
                            let light_pdf = scene.light_sampler.pmf(light_index as usize)
                                * shape.pdf_from(prev.interaction.p, si.time, si.p, si.n);
                            power_heuristic(prev.pdf, light_pdf)
                        }
                        _ => 1.0,
                    };
                    result += throughput * emitted * weight;
                }
            }

            if !self.depth_allows_next_vertex(depth) {
                break;
            }

            // The BSDF of the side the path arrives on, in its local frame.
            let material = &scene.materials[info.material as usize];
            let wo_shading = si.shading.to_local(wo_world);
            let (bsdf, flip) = material.side(wo_shading.z);
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
            let smooth = bsdf.flags().has_smooth_lobe();
            // A dispersive BSDF that can be evaluated uses the hero wavelength's index for all
            // its lobes (roughdielectric), so only the hero may see it.
            if smooth && bsdf.is_dispersive() {
                lambda.terminate_secondary();
            }

            // Direct light sampling.
            if smooth {
                result += throughput
                    * self.sample_direct(scene, &si, &sp, bsdf, wo, &lambda, sampler, count);
            }

            // BSDF sampling for the next direction.
            let u_lobe = sampler.next_1d();
            let u = sampler.next_2d();
            let Some(bs) = bsdf.sample(&sp, wo, u_lobe, u, &lambda) else {
                break;
            };
            if bs.terminates_secondary {
                lambda.terminate_secondary();
            }
            throughput *= bs.weight;
            eta_scale *= bs.eta;
            if throughput.is_black() {
                break;
            }
            let direction = frame.to_world(bs.wi);
            ray = si.spawn_ray(direction);
            previous = Some(PreviousBounce {
                interaction: si,
                pdf: bs.pdf,
                specular: bs.flags.is_delta(),
            });
            depth += 1;

            // Russian roulette on the path's potential.
            if depth >= self.rr_depth {
                let survival = (throughput.max_value() * eta_scale * eta_scale).min(0.95);
                if !(sampler.next_1d() < survival) {
                    break;
                }
                throughput *= 1.0 / survival;
            }
        }
        if lambda_was_whole && lambda.secondary_terminated() {
            // The hero carries the whole estimate, with a quarter of its density
            // (`terminate_secondary`); expressed for the caller's wavelengths, whose `to_xyz`
            // divides by the full density, that is N times its radiance.
            let mut hero_only = SampledSpectrum::ZERO;
            hero_only[0] = result[0] * N_SPECTRUM_SAMPLES as f32;
            return hero_only;
        }
        result
    }

    /// The MIS-weighted radiance of environment light `env` along the escaped `ray`.
    fn environment(
        &self,
        scene: &Scene,
        env: u32,
        ray: &Ray,
        previous: &Option<PreviousBounce>,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let light = &scene.lights[env as usize];
        let d = ray.d.normalize();
        let emitted = light.environment_radiance(d, lambda);
        let weight = match previous {
            Some(prev) if !prev.specular && !emitted.is_black() => {
                let light_pdf = scene.light_sampler.pmf(env as usize) * light.environment_pdf(d);
                power_heuristic(prev.pdf, light_pdf)
            }
            _ => 1.0,
        };
        emitted * weight
    }

    /// One light sample at `si`: a light chosen ∝ power, a point on it, the shadow ray, and the
    /// MIS-weighted contribution f·L·w / (p_light · p_choice).
    #[allow(clippy::too_many_arguments)]
    fn sample_direct(
        &self,
        scene: &Scene,
        si: &SurfaceInteraction,
        sp: &ShadingPoint,
        bsdf: &Bsdf,
        wo: glam::Vec3,
        lambda: &SampledWavelengths,
        sampler: &mut Sampler,
        count: &mut RayCount,
    ) -> SampledSpectrum {
        let u_light = sampler.next_1d();
        let u_choice = sampler.next_1d();
        let u = sampler.next_2d();
        let Some((light_index, choice_pmf)) = scene.light_sampler.sample(u_light) else {
            return SampledSpectrum::ZERO;
        };
        let light = &scene.lights[light_index];
        let Some(ls) = light.sample_incident(
            &scene.geometry.primitives,
            si.p,
            si.time,
            u_choice,
            u,
            lambda,
        ) else {
            return SampledSpectrum::ZERO;
        };
        let wi = sp.frame.to_local(ls.wi);
        let f = bsdf.eval(sp, wo, wi, lambda);
        if f.is_black() {
            return SampledSpectrum::ZERO;
        }
        count.rays += 1;
        if scene.geometry.occluded(&si.spawn_ray_to(ls.p, ls.n)) {
            return SampledSpectrum::ZERO;
        }
        let light_pdf = choice_pmf * ls.pdf;
        let weight = if ls.is_delta {
            1.0
        } else {
            power_heuristic(light_pdf, bsdf.pdf(sp, wo, wi, lambda))
        };
        f * ls.radiance * (weight / light_pdf)
    }
}
