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
use crate::geometry::SurfaceInteraction;
use crate::integrator::SampleContext;
use crate::integrator::mis::{ScatterOrigin, Strategies, emission_found, sample_light_at_surface};
use crate::integrator::stepped::SteppedPath;
use crate::integrator::vertex::{
    allows_next_vertex, normals_agree, path_estimate, russian_roulette, surface_scattering,
    wavelengths_after,
};
use crate::light::{LightSelection, Receiver};
use crate::math::Ray;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::world::World;

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

/// A path of the path tracer between two vertices: everything one step of it hands the next,
/// so that a driver can hold many paths at once and advance each by one vertex at a time
/// ([`SteppedPath`]; docs/architecture.md, Paths in lanes).
#[derive(Clone, Debug)]
pub struct PathState {
    /// The ray to the next vertex.
    ray: Ray,
    /// The wavelengths the path started with.
    started: SampledWavelengths,
    /// The path's own copy: a dispersive interface may drop the companion wavelengths.
    lambda: SampledWavelengths,
    result: SampledSpectrum,
    throughput: SampledSpectrum,
    /// Product of the relative indices of refraction crossed (Mitsuba's η).
    eta_scale: f32,
    previous: Option<ScatterOrigin>,
    depth: i32,
}

impl SteppedPath for PathIntegrator {
    type State = PathState;

    /// The path before its first vertex; None when `max_depth` is 0.
    #[inline]
    fn start(
        &self,
        _world: &World,
        ray: Ray,
        wavelengths: &SampledWavelengths,
    ) -> Option<PathState> {
        (self.max_depth != 0).then_some(PathState {
            ray,
            started: *wavelengths,
            lambda: *wavelengths,
            result: SampledSpectrum::ZERO,
            throughput: SampledSpectrum::ONE,
            eta_scale: 1.0,
            previous: None,
            depth: 0,
        })
    }

    #[inline]
    fn ray(state: &PathState) -> &Ray {
        &state.ray
    }

    /// One vertex of the path: the emission found at `hit`, a light sample and a BSDF sample
    /// for the next direction, and Russian roulette.
    #[inline]
    fn step(
        &self,
        ctx: &mut SampleContext,
        state: &mut PathState,
        hit: Option<SurfaceInteraction>,
    ) -> bool {
        let world = ctx.world();
        let ray = &state.ray;
        // Emission found by the previous BSDF sample (or by the camera ray), weighted against
        // the light sample that could have found it.
        if !(self.hide_emitters && state.depth == 0) {
            state.result += state.throughput
                * emission_found(
                    ctx,
                    ray,
                    hit.as_ref(),
                    state.previous.as_ref(),
                    &state.lambda,
                    Strategies::ONE_EACH,
                );
        }
        let Some(si) = hit else {
            return false;
        };
        let wo_world = -ray.d.normalize();

        if !allows_next_vertex(self.max_depth, state.depth)
            || (self.strict_normals && !normals_agree(&si, wo_world))
        {
            return false;
        }

        let mut lobes = BxdfTree::empty();
        let scattering = surface_scattering(world, &si, wo_world, &mut state.lambda, &mut lobes);
        if scattering.flags().has_smooth_lobe()
            && let Some(light) =
                sample_light_at_surface(ctx, &si, &scattering, &state.lambda, self.strict_normals)
        {
            state.result += state.throughput * light.weighted(Strategies::ONE_EACH);
        }

        // BSDF sampling for the next direction.
        let u_lobe = ctx.sampler.next_1d();
        let u = ctx.sampler.next_2d();
        let Some(bs) = scattering.sample(u_lobe, u) else {
            return false;
        };
        if self.strict_normals && !normals_agree(&si, bs.wi) {
            return false;
        }
        state.lambda = wavelengths_after(&state.lambda, &bs);
        state.throughput *= bs.weight;
        state.eta_scale *= bs.eta;
        if state.throughput.is_black() {
            return false;
        }
        state.ray = si.spawn_ray(bs.wi);
        state.previous = Some(ScatterOrigin {
            receiver: Receiver::surface(si.p, si.shading.n),
            pdf: bs.pdf,
            specular: bs.flags.is_delta(),
        });
        state.depth += 1;

        // Russian roulette on the path's potential, from depth `rr_depth` on.
        if state.depth >= self.rr_depth {
            let Some(factor) = russian_roulette(ctx, state.throughput, state.eta_scale) else {
                return false;
            };
            state.throughput *= factor;
        }
        true
    }

    #[inline]
    fn estimate(&self, state: &PathState) -> SampledSpectrum {
        path_estimate(state.result, &state.started, &state.lambda)
    }
}
