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
//!     <boolean name="strict_normals" value="false"/>    <!-- Mitsuba 0.6's strictNormals -->
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
//! * `strict_normals` (Mitsuba 0.6; Mitsuba 3 has no such parameter): where the geometric and
//!   the shading normal put a direction on different sides of the surface, the path ends on
//!   arriving from it, a light sample towards it adds nothing, and a BSDF sample into it ends
//!   the path, as in Mitsuba 0.6's `path`: no light leaks through surfaces whose shading
//!   normals bend across the geometry, at the price of some energy.

use crate::bsdf::BxdfTree;
use crate::integrator::mis::{BsdfSampleOrigin, Strategies, emission_found, sample_light};
use crate::integrator::{PreparedIntegrator, RayCount, hero_only, normals_agree};
use crate::light::LightSelection;
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
    /// Whether directions the geometric and shading normals disagree about end the path.
    pub strict_normals: bool,
}

impl Default for PathIntegrator {
    fn default() -> Self {
        PathIntegrator {
            max_depth: -1,
            rr_depth: 5,
            hide_emitters: false,
            light_selection: LightSelection::Exhaustive,
            strict_normals: false,
        }
    }
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
        let mut previous: Option<BsdfSampleOrigin> = None;
        let mut depth = 0i32;
        // The lobes of the vertex at hand, rewritten at every bounce.
        let mut lobes = BxdfTree::empty();
        if self.max_depth == 0 {
            return result;
        }
        loop {
            count.rays += 1;
            let hit = world.geometry.intersect(&ray);
            // Emission found by the previous BSDF sample (or by the camera ray), weighted
            // against the light sample that could have found it.
            if !(self.hide_emitters && depth == 0) {
                result += throughput
                    * emission_found(
                        prepared,
                        &ray,
                        hit.as_ref(),
                        previous.as_ref(),
                        &lambda,
                        Strategies::ONE_EACH,
                    );
            }
            let Some(si) = hit else {
                break;
            };
            let wo_world = -ray.d.normalize();
            let info = world.shape_info[si.shape as usize];

            if !self.depth_allows_next_vertex(depth)
                || (self.strict_normals && !normals_agree(&si, wo_world))
            {
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
                    * sample_light(
                        prepared,
                        &si,
                        &scattering,
                        &lambda,
                        sampler,
                        count,
                        Strategies::ONE_EACH,
                        self.strict_normals,
                    );
            }

            // BSDF sampling for the next direction.
            let u_lobe = sampler.next_1d();
            let u = sampler.next_2d();
            let Some(bs) = scattering.sample(u_lobe, u) else {
                break;
            };
            if self.strict_normals && !normals_agree(&si, bs.wi) {
                break;
            }
            if bs.terminates_secondary {
                lambda.terminate_secondary();
            }
            throughput *= bs.weight;
            eta_scale *= bs.eta;
            if throughput.is_black() {
                break;
            }
            ray = si.spawn_ray(bs.wi);
            previous = Some(BsdfSampleOrigin {
                p: si.p,
                n: si.shading.n,
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
}
