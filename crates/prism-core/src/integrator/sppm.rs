//! Stochastic progressive photon mapping (Hachisuka & Jensen 2009; Mitsuba 0.6's `sppm`,
//! pbrt-v4's `SPPMIntegrator`): the estimator of one pass, its photons and its camera paths.
//! The passes, the per-pixel statistics and their progressive update are the render driver's
//! (`render::sppm`).
//!
//! Its parameters (`initialRadius`, `alpha`, `photonCount`, `maxPasses`, `granularity`,
//! `maxDepth`, `rrDepth`) and their defaults are listed in docs/plugins.md.
//!
//! A pass has two halves:
//!
//! * **Photons** ([`SppmIntegrator::trace_photon`]): `photonCount` light subpaths, each from a
//!   light chosen by power and a ray of its emission with weight β = L_e |cos θ| /
//!   (P(light) p_A p_ω), continued by sampling the adjoint BSDF as the particle tracer does
//!   (Veach's shading-normal factor, η² on refractions, Russian roulette after `rrDepth`
//!   bounces on the weight relative to the emitted one). At the k-th surface it meets (k ≥ 2) where the BSDF has a smooth lobe, the
//!   photon (position, incident direction, β, k) is stored; the first hits (k = 1) are direct
//!   light, which the camera side estimates by light sampling, as in pbrt-v4. The photons of a
//!   pass form a [`PhotonMap`], a hash grid with cells as wide as the largest search radius.
//! * **Camera paths** ([`SppmIntegrator::estimate`]): one per pixel, followed through specular
//!   and glossy vertices by sampling the BSDF, to the first vertex with a diffuse lobe (or a
//!   glossy one where `maxDepth` allows no further vertex), the pixel's visible point. Along
//!   the way the path adds the emission it finds at its first hit and after specular bounces,
//!   and at every vertex with a smooth lobe a light sample (light sampling alone: emission
//!   found after a smooth bounce is left to it). At the visible point x with outgoing
//!   direction ω_o, the photons p within the pixel's radius r give M photons and the flux
//!   Φ = β_camera Σ_p β_p f(x, ω_o, ω_p) (f without the cosine, which the photons' density
//!   carries), for photons whose path, joined to the camera path, has at most `maxDepth`
//!   vertices after the camera.
//!
//! The driver turns (Φ, M) into the pixel's progressive estimate: with N the pixel's
//! accumulated photon count, N' = N + αM, r'² = r² N'/(N + M), τ' = (τ + Φ) r'²/r², and after
//! P passes of `photonCount` photons each L = Σ L_direct / P + τ / (P · photonCount · π r²)
//! (Hachisuka & Jensen 2009, eqs. 5–8, with one statistic per pixel as pbrt-v4 keeps them).
//!
//! **Wavelengths.** Every pass draws one set of wavelengths (a hero and its three rotations)
//! that every pixel and every photon of the pass use. A photon's β and a camera path's weight
//! are then spectra at the same wavelengths, their product is the path's contribution at
//! those wavelengths, and Φ is converted to CIE XYZ with the pass's densities before it joins
//! τ. The progressive update is linear in Φ and its factors depend on photon counts only,
//! never on spectra, so τ can be kept in XYZ and the estimate averages over passes as the
//! radius shrinks: consistent in XYZ as the passes grow. Where a dispersive interface keeps
//! only the hero wavelength (on the photon's side or the camera's), the contribution is the
//! hero's alone, counted N times ([`super::vertex::hero_only`]).
//!
//! **Bias.** At any finite pass count the estimate is biased (blurred by the radius, and
//! darkened at corners and edges); the bias vanishes as the passes grow, which the tests check
//! against closed forms. There is no per-sample variance to report.
//!
//! No participating media (as Mitsuba 0.6's `sppm`): scenes with media are refused when read.

use glam::Vec3;

use crate::bsdf::{BsdfFlags, BxdfTree};
use crate::integrator::adjoint::sample_adjoint;
use crate::integrator::mis::{Strategies, emission_found, sample_light_at_surface};
use crate::integrator::photon_map::{Located, PhotonMap};
use crate::integrator::ptracer::{choose_light, emission_ray};
use crate::integrator::vertex::{
    allows_next_vertex, hero_only, path_estimate, russian_roulette, surface_scattering,
    wavelengths_after,
};
use crate::integrator::{PreparedIntegrator, RayCount, SampleContext};
use crate::light::{EmissionQuery, LightSource};
use crate::math::Ray;
use crate::sampling::sampler::Sampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

#[derive(Clone, Debug)]
pub struct SppmIntegrator {
    /// The search radius every pixel starts with, in world units; None for Mitsuba 0.6's
    /// automatic choice (five times the scene's bounding radius over the film's larger side).
    pub initial_radius: Option<f32>,
    /// The fraction of a pass's photons a pixel keeps (α ∈ (0, 1)).
    pub alpha: f32,
    /// Light subpaths traced per pass.
    pub photon_count: u32,
    /// The number of passes, replacing the sample count where given.
    pub max_passes: Option<u32>,
    /// Light subpaths per parallel task; None to choose.
    pub granularity: Option<u32>,
    /// Longest path in vertices after the camera; negative for unbounded.
    pub max_depth: i32,
    /// Bounces of a light subpath or camera path after which Russian roulette is used.
    pub rr_depth: i32,
}

impl Default for SppmIntegrator {
    fn default() -> Self {
        SppmIntegrator {
            initial_radius: None,
            alpha: 0.7,
            photon_count: 250_000,
            max_passes: None,
            granularity: None,
            max_depth: -1,
            rr_depth: 3,
        }
    }
}

/// A photon stored where a light subpath met a surface with a smooth lobe.
#[derive(Clone, Copy, Debug)]
pub struct Photon {
    pub p: Vec3,
    /// The unit direction back towards where the photon came from.
    pub wi: Vec3,
    /// The subpath's weight there (flux per photon, times the number of photons).
    pub beta: SampledSpectrum,
    /// How many surfaces the subpath has met (1 at the first).
    pub depth: i32,
    /// Whether the subpath kept only its hero wavelength on the way.
    pub hero_only: bool,
}

impl Located for Photon {
    fn position(&self) -> Vec3 {
        self.p
    }
}

/// What one pass's camera path brings its pixel: the direct estimate, the flux Φ of the
/// photons found at its visible point (both for the pass's wavelengths) and their count M.
#[derive(Clone, Copy, Debug, Default)]
pub struct PixelPass {
    pub direct: SampledSpectrum,
    pub flux: SampledSpectrum,
    pub photons: u32,
}

impl SppmIntegrator {
    /// Whether a path of `vertices` vertices after the camera is within `max_depth`.
    #[inline]
    fn allows_vertices(&self, vertices: i32) -> bool {
        self.max_depth < 0 || vertices <= self.max_depth
    }

    /// Traces one light subpath at the wavelengths `lambda` and time `time` (with the
    /// shutter's weight `time_weight`), drawing random numbers from `sampler`, and stores its
    /// photons in `out` (see the module's text).
    #[allow(clippy::too_many_arguments)]
    pub fn trace_photon(
        &self,
        prepared: &PreparedIntegrator,
        sampler: &mut Sampler,
        count: &mut RayCount,
        lambda: &SampledWavelengths,
        time: f32,
        time_weight: f32,
        out: &mut Vec<Photon>,
    ) {
        let ctx = &mut SampleContext {
            prepared,
            sampler,
            count,
        };
        let world = ctx.world();
        let Some((index, choice)) = choose_light(ctx) else {
            return;
        };
        let u_choice = ctx.sampler.next_1d();
        let u_position = ctx.sampler.next_2d();
        let u_direction = ctx.sampler.next_2d();
        let Some(emission) = world.lights[index].sample_emission(EmissionQuery {
            shapes: &world.geometry.primitives,
            time,
            u_choice,
            u_position,
            u_direction,
            lambda,
        }) else {
            return;
        };
        let mut beta = emission.weight * (time_weight / choice);
        if beta.is_black() {
            return;
        }
        // Russian roulette plays on the photon's weight relative to its start, the product of
        // the albedos it has met.
        let relative = 1.0 / beta.max_value();
        let mut ray = emission_ray(&emission, time);
        let mut path_lambda = *lambda;
        let mut eta_scale = 1.0f32;
        let mut lobes = BxdfTree::empty();
        let mut depth = 1i32;
        // A photon at the k-th surface joined to a visible point at camera depth d ≥ 0 makes a
        // path of d + 1 + k vertices after the camera.
        while self.allows_vertices(depth + 1) {
            let Some(si) = ctx.intersect(&ray) else {
                break;
            };
            let w_light = -ray.d.normalize();
            let scattering = surface_scattering(world, &si, w_light, &mut path_lambda, &mut lobes);
            if depth >= 2 && scattering.flags().has_smooth_lobe() {
                out.push(Photon {
                    p: si.p,
                    wi: w_light,
                    beta,
                    depth,
                    hero_only: !lambda.secondary_terminated() && path_lambda.secondary_terminated(),
                });
            }
            let Some((bs, factor)) = sample_adjoint(ctx, &si, &scattering, w_light) else {
                break;
            };
            path_lambda = wavelengths_after(&path_lambda, &bs);
            beta *= bs.weight * factor;
            eta_scale *= bs.eta;
            if beta.is_black() {
                break;
            }
            ray = si.spawn_ray(bs.wi);
            depth += 1;
            if depth > self.rr_depth {
                let Some(factor) = russian_roulette(ctx, beta * relative, eta_scale) else {
                    break;
                };
                beta *= factor;
            }
        }
    }

    /// One pass of a pixel: the camera path along `ray` with weight `weight` at the pass's
    /// wavelengths `lambda`, its direct estimate, and the photons of `photons` within `radius`
    /// of its visible point (see the module's text).
    #[allow(clippy::too_many_arguments)]
    pub fn estimate(
        &self,
        prepared: &PreparedIntegrator,
        sampler: &mut Sampler,
        count: &mut RayCount,
        mut ray: Ray,
        weight: f32,
        lambda: &SampledWavelengths,
        photons: &PhotonMap<Photon>,
        radius: f32,
    ) -> PixelPass {
        let ctx = &mut SampleContext {
            prepared,
            sampler,
            count,
        };
        let world = ctx.world();
        let mut path_lambda = *lambda;
        let mut beta = SampledSpectrum::splat(weight);
        let mut eta_scale = 1.0f32;
        let mut result = PixelPass::default();
        let mut lobes = BxdfTree::empty();
        let mut specular = true;
        let mut depth = 0i32;
        loop {
            let hit = ctx.intersect(&ray);
            if specular {
                result.direct += beta
                    * emission_found(
                        ctx,
                        &ray,
                        hit.as_ref(),
                        None,
                        &path_lambda,
                        Strategies::ONE_EACH,
                    );
            }
            let Some(si) = hit else {
                break;
            };
            if !allows_next_vertex(self.max_depth, depth) {
                break;
            }
            let wo = -ray.d.normalize();
            let scattering = surface_scattering(world, &si, wo, &mut path_lambda, &mut lobes);
            let flags = scattering.flags();
            if flags.has_smooth_lobe()
                && let Some(light) =
                    sample_light_at_surface(ctx, &si, &scattering, &path_lambda, false)
            {
                result.direct += beta * light.weighted(LIGHT_SAMPLES_ONLY);
            }
            if flags.contains(BsdfFlags::DIFFUSE)
                || (flags.contains(BsdfFlags::GLOSSY)
                    && !allows_next_vertex(self.max_depth, depth + 1))
            {
                let camera_hero_only = path_lambda.secondary_terminated();
                let mut flux = SampledSpectrum::ZERO;
                photons.for_each_near(si.p, radius, |photon| {
                    if !self.allows_vertices(depth + 1 + photon.depth) {
                        return;
                    }
                    let cos = si.shading.n.dot(photon.wi).abs();
                    if cos == 0.0 {
                        return;
                    }
                    let term = photon.beta * scattering.eval(photon.wi).value * (1.0 / cos);
                    flux += if photon.hero_only && !camera_hero_only {
                        hero_only(term)
                    } else {
                        term
                    };
                    result.photons += 1;
                });
                result.flux = beta * flux;
                break;
            }
            let u_lobe = ctx.sampler.next_1d();
            let u = ctx.sampler.next_2d();
            let Some(bs) = scattering.sample(u_lobe, u) else {
                break;
            };
            path_lambda = wavelengths_after(&path_lambda, &bs);
            beta *= bs.weight;
            eta_scale *= bs.eta;
            if beta.is_black() {
                break;
            }
            specular = bs.flags.is_delta();
            ray = si.spawn_ray(bs.wi);
            depth += 1;
            if depth >= self.rr_depth {
                let Some(factor) = russian_roulette(ctx, beta, eta_scale) else {
                    break;
                };
                beta *= factor;
            }
        }
        result.direct = path_estimate(result.direct, lambda, &path_lambda);
        result.flux = path_estimate(result.flux, lambda, &path_lambda);
        result
    }
}

/// Light samples weighed as the only strategy: the camera path counts no emission after a
/// smooth bounce.
const LIGHT_SAMPLES_ONLY: Strategies = Strategies {
    light_samples: 1.0,
    bsdf_samples: 0.0,
};
