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
use crate::integrator::mis::{Strategies, emission_found, sample_light_at_surface};
use crate::integrator::ptracer::{choose_light, emission_ray, sample_adjoint};
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

/// What a [`PhotonMap`] holds: anything with a position (photons, and the light vertices of
/// vertex merging, [`super::vcm`]).
pub trait Located {
    fn position(&self) -> Vec3;
}

/// The photons of one pass in a hash grid (Teschner et al. 2003's spatial hash): cells of one
/// size, hashed into as many buckets as there are photons, each bucket's photons stored
/// together in the order they were traced, so lookups are deterministic.
pub struct PhotonMap<P = Photon> {
    photons: Vec<P>,
    /// Where each bucket's photons start in `photons` (one more entry than buckets).
    starts: Vec<u32>,
    cell_size: f32,
}

impl<P: Located + Clone> PhotonMap<P> {
    /// The map of `photons` for searches within `largest_radius`: cells twice as wide, so that
    /// a search spans at most two cells per axis.
    pub fn new(photons: Vec<P>, largest_radius: f32) -> PhotonMap<P> {
        let cell_size = 2.0 * largest_radius.max(f32::MIN_POSITIVE);
        let buckets = photons.len().max(1);
        let mut starts = vec![0u32; buckets + 1];
        let bucket_of: Vec<usize> = photons
            .iter()
            .map(|photon| bucket(cell_of(photon.position(), cell_size), buckets))
            .collect();
        for &b in &bucket_of {
            starts[b + 1] += 1;
        }
        for b in 0..buckets {
            starts[b + 1] += starts[b];
        }
        let mut next = starts.clone();
        let mut order = vec![0u32; photons.len()];
        for (i, &b) in bucket_of.iter().enumerate() {
            order[next[b] as usize] = i as u32;
            next[b] += 1;
        }
        PhotonMap {
            photons: order.iter().map(|&i| photons[i as usize].clone()).collect(),
            starts,
            cell_size,
        }
    }

    /// Calls `f` for every photon within `radius` (at most the largest radius the map was
    /// made for) of `p`, in a fixed order.
    pub fn for_each_near(&self, p: Vec3, radius: f32, mut f: impl FnMut(&P)) {
        let buckets = self.starts.len() - 1;
        let low = cell_of(p - Vec3::splat(radius), self.cell_size);
        let high = cell_of(p + Vec3::splat(radius), self.cell_size);
        // Two cells of the search may share a bucket: each bucket is visited once.
        let mut visit = [0usize; 8];
        let mut count = 0;
        for z in low[2]..=high[2] {
            for y in low[1]..=high[1] {
                for x in low[0]..=high[0] {
                    let b = bucket([x, y, z], buckets);
                    if count < visit.len() && !visit[..count].contains(&b) {
                        visit[count] = b;
                        count += 1;
                    }
                }
            }
        }
        let radius_squared = radius * radius;
        for &b in &visit[..count] {
            let range = self.starts[b] as usize..self.starts[b + 1] as usize;
            for photon in &self.photons[range] {
                if (photon.position() - p).length_squared() <= radius_squared {
                    f(photon);
                }
            }
        }
    }
}

/// The grid cell of `p`.
fn cell_of(p: Vec3, cell_size: f32) -> [i32; 3] {
    (p / cell_size).floor().as_ivec3().to_array()
}

/// The bucket of cell `cell` among `buckets`.
fn bucket(cell: [i32; 3], buckets: usize) -> usize {
    let [x, y, z] = cell.map(|c| c as u32 as u64);
    let h =
        (x.wrapping_mul(73_856_093)) ^ (y.wrapping_mul(19_349_663)) ^ (z.wrapping_mul(83_492_791));
    (h % buckets as u64) as usize
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
        photons: &PhotonMap,
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::rng::Pcg32;

    /// A search of the map finds exactly the photons a search of every photon finds, in
    /// searches of radii up to the largest, over photons spread across many cells (including
    /// negative coordinates).
    #[test]
    fn photon_map_finds_what_a_brute_force_search_finds() {
        let mut rng = Pcg32::seeded(3);
        let point = |rng: &mut Pcg32| {
            Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 4.0 - Vec3::splat(2.0)
        };
        let photons: Vec<Photon> = (0..5000)
            .map(|i| Photon {
                p: point(&mut rng),
                wi: Vec3::Z,
                beta: SampledSpectrum::splat(1.0),
                depth: i,
                hero_only: false,
            })
            .collect();
        let largest = 0.3;
        let map = PhotonMap::new(photons.clone(), largest);
        for _ in 0..500 {
            let p = point(&mut rng);
            let radius = largest * rng.next_f32();
            let mut found = Vec::new();
            map.for_each_near(p, radius, |photon| found.push(photon.depth));
            found.sort_unstable();
            let expected: Vec<i32> = photons
                .iter()
                .filter(|photon| (photon.p - p).length_squared() <= radius * radius)
                .map(|photon| photon.depth)
                .collect();
            assert_eq!(found, expected, "search at {p} within {radius}");
        }
    }
}
