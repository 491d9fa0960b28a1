//! The path tracer (Mitsuba's `path` integrator), as the lecture's "Monte Carlo Path Tracing":
//! one BSDF sample per bounce, so the estimate is the product (w₁/p₁)(w₂/p₂)…L_e, with direct
//! light sampling at every vertex ("Direct Light Sampling") and Russian roulette.
//!
//! Its parameters (`max_depth`, `rr_depth`, `hide_emitters`, `emitter_sampling`,
//! `strict_normals`) and their defaults are listed in docs/plugins.md.
//!
//! * Light sampling picks one light with the integrator's light sampler
//!   ([`crate::light::sampler`]: by default by its importance at the vertex, or ∝ its power as
//!   the lecture does, or uniformly) and divides by that probability. Light samples
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
use crate::integrator::SampleContext;
use crate::integrator::mis::{ScatterOrigin, Strategies, emission_found, sample_light_at_surface};
use crate::integrator::vertex::{
    allows_next_vertex, normals_agree, path_estimate, russian_roulette, surface_scattering,
    wavelengths_after,
};
use crate::light::{LightSelection, Receiver};
use crate::math::Ray;
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
    pub(super) fn radiance(
        &self,
        ctx: &mut SampleContext,
        mut ray: Ray,
        wavelengths: &SampledWavelengths,
    ) -> SampledSpectrum {
        let world = ctx.world();
        // The path's own copy: a dispersive interface may drop the companion wavelengths.
        let mut lambda = *wavelengths;
        let mut result = SampledSpectrum::ZERO;
        let mut throughput = SampledSpectrum::ONE;
        // Product of the relative indices of refraction crossed (Mitsuba's η).
        let mut eta_scale = 1.0f32;
        let mut previous: Option<ScatterOrigin> = None;
        let mut depth = 0i32;
        // The lobes of the vertex at hand, rewritten at every bounce.
        let mut lobes = BxdfTree::empty();
        if self.max_depth == 0 {
            return result;
        }
        loop {
            let hit = ctx.intersect(&ray);
            // Emission found by the previous BSDF sample (or by the camera ray), weighted
            // against the light sample that could have found it.
            if !(self.hide_emitters && depth == 0) {
                result += throughput
                    * emission_found(
                        ctx,
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

            if !allows_next_vertex(self.max_depth, depth)
                || (self.strict_normals && !normals_agree(&si, wo_world))
            {
                break;
            }

            let scattering = surface_scattering(world, &si, wo_world, &mut lambda, &mut lobes);
            if scattering.flags().has_smooth_lobe()
                && let Some(light) =
                    sample_light_at_surface(ctx, &si, &scattering, &lambda, self.strict_normals)
            {
                result += throughput * light.weighted(Strategies::ONE_EACH);
            }

            // BSDF sampling for the next direction.
            let u_lobe = ctx.sampler.next_1d();
            let u = ctx.sampler.next_2d();
            let Some(bs) = scattering.sample(u_lobe, u) else {
                break;
            };
            if self.strict_normals && !normals_agree(&si, bs.wi) {
                break;
            }
            lambda = wavelengths_after(&lambda, &bs);
            throughput *= bs.weight;
            eta_scale *= bs.eta;
            if throughput.is_black() {
                break;
            }
            ray = si.spawn_ray(bs.wi);
            previous = Some(ScatterOrigin {
                receiver: Receiver::surface(si.p, si.shading.n),
                pdf: bs.pdf,
                specular: bs.flags.is_delta(),
            });
            depth += 1;

            // Russian roulette on the path's potential, from depth `rr_depth` on.
            if depth >= self.rr_depth {
                let Some(factor) = russian_roulette(ctx, throughput, eta_scale) else {
                    break;
                };
                throughput *= factor;
            }
        }
        path_estimate(result, wavelengths, &lambda)
    }
}
