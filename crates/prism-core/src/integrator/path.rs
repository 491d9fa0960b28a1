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

use crate::bsdf::{BxdfTree, Scattering};
use crate::geometry::{SurfaceInteraction, SurfaceSample};
use crate::integrator::{PreparedIntegrator, RayCount, hero_only, unoccluded};
use crate::light::{Light, LightSelection};
use crate::math::Ray;
use crate::sampling::sampler::Sampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

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

    pub(super) fn radiance(
        &self,
        prepared: &PreparedIntegrator,
        mut ray: Ray,
        wavelengths: &SampledWavelengths,
        sampler: &mut Sampler,
        count: &mut RayCount,
    ) -> SampledSpectrum {
        let world = prepared.world;
        // The path's own copy: a dispersive interface may drop the companion wavelengths.
        let mut lambda = *wavelengths;
        let lambda_was_whole = !wavelengths.secondary_terminated();
        let mut result = SampledSpectrum::ZERO;
        let mut throughput = SampledSpectrum::ONE;
        // Product of the relative indices of refraction crossed (Mitsuba's η).
        let mut eta_scale = 1.0f32;
        let mut previous: Option<PreviousBounce> = None;
        let mut depth = 0i32;
        // The lobes of the vertex at hand, rewritten at every bounce.
        let mut lobes = BxdfTree::empty();
        if self.max_depth == 0 {
            return result;
        }
        loop {
            count.rays += 1;
            let Some(si) = world.geometry.intersect(&ray) else {
                // The ray leaves the scene: the environment's emission, weighted like an area
                // light's against the light sample that could have found it.
                if let Some(env) = world.environment
                    && !(self.hide_emitters && depth == 0)
                {
                    result +=
                        throughput * Self::environment(prepared, env, &ray, &previous, &lambda);
                }
                break;
            };
            let wo_world = -ray.d.normalize();
            let info = world.shape_info[si.shape as usize];

            // Emission found by the previous BSDF sample (or by the camera ray).
            if let Some(light_index) = info.light
                && !(self.hide_emitters && depth == 0)
            {
                let Light::Area(light) = &world.lights[light_index as usize] else {
                    unreachable!("only area lights are attached to shapes");
                };
                let emitted = light.emitted(si.uv, si.shading.n, wo_world, &lambda);
                if !emitted.is_black() {
                    let weight = match &previous {
                        Some(prev) if !prev.specular => {
                            let light_pdf = prepared.light_sampler.pmf(light_index as usize)
                                * light.pdf_from(
                                    &world.geometry.primitives,
                                    prev.interaction.p,
                                    si.time,
                                    &SurfaceSample::at(&si),
                                );
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

            // The BSDF of the side the path arrives on, with its textures evaluated here.
            let scattering = world.materials[info.material as usize]
                .scattering(&si, wo_world, &lambda, &mut lobes);
            let smooth = scattering.flags().has_smooth_lobe();
            // A dispersive BSDF that can be evaluated uses the hero wavelength's index for all
            // its lobes (roughdielectric), so only the hero may see it.
            if smooth && scattering.is_dispersive() {
                lambda.terminate_secondary();
            }

            // Direct light sampling.
            if smooth {
                result += throughput
                    * Self::sample_direct(prepared, &si, &scattering, &lambda, sampler, count);
            }

            // BSDF sampling for the next direction.
            let u_lobe = sampler.next_1d();
            let u = sampler.next_2d();
            let Some(bs) = scattering.sample(u_lobe, u) else {
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
            ray = si.spawn_ray(bs.wi);
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
            return hero_only(result);
        }
        result
    }

    /// The MIS-weighted radiance of environment light `env` along the escaped `ray`.
    fn environment(
        prepared: &PreparedIntegrator,
        env: u32,
        ray: &Ray,
        previous: &Option<PreviousBounce>,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let light = &prepared.world.lights[env as usize];
        let d = ray.d.normalize();
        let emitted = light.environment_radiance(d, lambda);
        let weight = match previous {
            Some(prev) if !prev.specular && !emitted.is_black() => {
                let light_pdf = prepared.light_sampler.pmf(env as usize) * light.environment_pdf(d);
                power_heuristic(prev.pdf, light_pdf)
            }
            _ => 1.0,
        };
        emitted * weight
    }

    /// One light sample at `si`: a light chosen by the light sampler, a point on it, the shadow
    /// ray, and the MIS-weighted contribution f·L·w / (p_light · p_choice).
    fn sample_direct(
        prepared: &PreparedIntegrator,
        si: &SurfaceInteraction,
        scattering: &Scattering,
        lambda: &SampledWavelengths,
        sampler: &mut Sampler,
        count: &mut RayCount,
    ) -> SampledSpectrum {
        let world = prepared.world;
        let u_light = sampler.next_1d();
        let u_choice = sampler.next_1d();
        let u = sampler.next_2d();
        let Some((light_index, choice_pmf)) = prepared.light_sampler.sample(u_light) else {
            return SampledSpectrum::ZERO;
        };
        let light = &world.lights[light_index];
        let Some(ls) = light.sample_incident(
            &world.geometry.primitives,
            si.p,
            si.time,
            u_choice,
            u,
            lambda,
        ) else {
            return SampledSpectrum::ZERO;
        };
        let Some(f) = unoccluded(world, si, scattering, &ls, count) else {
            return SampledSpectrum::ZERO;
        };
        let light_pdf = choice_pmf * ls.pdf;
        let weight = if ls.is_delta {
            1.0
        } else {
            power_heuristic(light_pdf, f.pdf)
        };
        f.value * ls.radiance * (weight / light_pdf)
    }
}
