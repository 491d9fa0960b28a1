//! The path tracer for polarized light, which a scene gets in place of `path` when it holds a
//! polarizing element (`polarizer`, `retarder`, `circular`) or asks for the `stokes`
//! integrator (Mitsuba 3's `path` in its `*_polarized` variants). It is the path tracer of
//! [`super::path`], with the same sampling, random numbers, light sampling, MIS, depth and
//! Russian roulette, except that a path carries a Mueller matrix per wavelength instead of a
//! throughput and its estimate is a Stokes vector per wavelength.
//!
//! Each vertex multiplies the path's matrix from the right by the scattering's Mueller matrix
//! ([`Scattering::polarized`]: the BSDF's, in the implicit Stokes bases of the world directions
//! of the incident and outgoing beams, Mitsuba's `to_world_mueller`), so the matrix maps Stokes
//! vectors arriving at the last vertex to the one arriving at the camera, in the implicit basis
//! of the camera ray's reversed direction. Emitters are unpolarized: emission L found along the
//! path adds the matrix's first column times L. M₀₀ of each vertex's matrix is the unpolarized
//! path tracer's weight, so the S₀ estimate is the unpolarized one wherever the BSDFs depolarize
//! (Russian roulette reads M₀₀, as Mitsuba's `unpolarized_spectrum`).

use glam::{Vec3, Vec4};

use crate::bsdf::{BsdfFlags, BxdfTree};
use crate::integrator::SampleContext;
use crate::integrator::mis::{ScatterOrigin, Strategies, emission_found, sample_light, unoccluded};
use crate::integrator::path::PathIntegrator;
use crate::integrator::transmittance::ShadowTransmittance;
use crate::integrator::vertex::{
    allows_next_vertex, normals_agree, russian_roulette, surface_scattering, wavelengths_after,
};
use crate::light::{LightSelection, Receiver};
use crate::math::Ray;
use crate::polarization::{SampledMueller, Stokes};
use crate::spectrum::{N_SPECTRUM_SAMPLES, SampledSpectrum, SampledWavelengths};

/// A Stokes vector per wavelength of a path.
pub type SampledStokes = [Stokes; N_SPECTRUM_SAMPLES];

/// The polarized path tracer: the settings of the path tracer it stands in for.
#[derive(Clone, Debug)]
pub struct PolarizedPathIntegrator {
    pub path: PathIntegrator,
}

impl PolarizedPathIntegrator {
    /// How one light is chosen for each light sample.
    pub fn light_selection(&self) -> LightSelection {
        self.path.light_selection
    }

    /// The Stokes vector per wavelength arriving at the camera along `ray` (which travels away
    /// from the camera), in the implicit basis of −`ray.d`, for the wavelengths `wavelengths`.
    pub fn stokes(
        &self,
        ctx: &mut SampleContext,
        ray: Ray,
        wavelengths: &SampledWavelengths,
    ) -> SampledStokes {
        let settings = &self.path;
        let mut result = [Vec4::ZERO; N_SPECTRUM_SAMPLES];
        if settings.max_depth == 0 {
            return result;
        }
        let mut ray = ray;
        let mut lambda = *wavelengths;
        let mut throughput = SampledMueller::IDENTITY;
        let mut eta_scale = 1.0f32;
        let mut previous: Option<ScatterOrigin> = None;
        let mut depth = 0;
        let add = |result: &mut SampledStokes, m: &SampledMueller, radiance: SampledSpectrum| {
            for (s, l) in result.iter_mut().zip(m.apply_unpolarized(radiance)) {
                *s += l;
            }
        };
        loop {
            let hit = ctx.intersect(&ray);
            if !(settings.hide_emitters && depth == 0) {
                let emitted = emission_found(
                    ctx,
                    &ray,
                    hit.as_ref(),
                    previous.as_ref(),
                    &lambda,
                    Strategies::ONE_EACH,
                );
                if !emitted.is_black() {
                    add(&mut result, &throughput, emitted);
                }
            }
            let Some(si) = hit else {
                break;
            };
            let wo_world = -ray.d.normalize();
            if !allows_next_vertex(settings.max_depth, depth)
                || (settings.strict_normals && !normals_agree(&si, wo_world))
            {
                break;
            }
            let world = ctx.world();
            let mut lobes = BxdfTree::empty();
            let scattering = surface_scattering(world, &si, wo_world, &mut lambda, &mut lobes);

            let receiver = Receiver::surface(si.p, si.shading.n);
            if scattering.flags().has_smooth_lobe() {
                let mut wi = Vec3::ZERO;
                let light = sample_light(ctx, &receiver, si.time, &lambda, |ctx, ls| {
                    if settings.strict_normals && !normals_agree(&si, ls.wi) {
                        return None;
                    }
                    wi = ls.wi;
                    unoccluded(ctx, &si, &scattering, ls).map(|f| (f, ShadowTransmittance::ONE))
                });
                if let Some(light) = light {
                    let contribution = light.weighted(Strategies::ONE_EACH);
                    let vertex = scattering.polarized(wi, BsdfFlags::NONE, contribution);
                    add(&mut result, &(throughput * vertex), SampledSpectrum::ONE);
                }
            }

            let u_lobe = ctx.sampler.next_1d();
            let u = ctx.sampler.next_2d();
            let Some(bs) = scattering.sample(u_lobe, u) else {
                break;
            };
            if settings.strict_normals && !normals_agree(&si, bs.wi) {
                break;
            }
            lambda = wavelengths_after(&lambda, &bs);
            throughput = throughput * scattering.polarized(bs.wi, bs.flags, bs.weight);
            eta_scale *= bs.eta;
            let potential = throughput.m00();
            if potential.is_black() {
                break;
            }
            ray = si.spawn_ray(bs.wi);
            previous = Some(ScatterOrigin {
                receiver,
                pdf: bs.pdf,
                specular: bs.flags.is_delta(),
            });
            depth += 1;
            if depth >= settings.rr_depth {
                let Some(factor) = russian_roulette(ctx, potential, eta_scale) else {
                    break;
                };
                throughput = throughput.scaled(SampledSpectrum::splat(factor));
            }
        }
        if !wavelengths.secondary_terminated() && lambda.secondary_terminated() {
            // The hero carries the whole estimate ([`crate::integrator::vertex::hero_only`]).
            let hero = result[0] * N_SPECTRUM_SAMPLES as f32;
            result = [Vec4::ZERO; N_SPECTRUM_SAMPLES];
            result[0] = hero;
        }
        result
    }

    /// The intensity S₀ of [`Self::stokes`]: the image of a polarized render.
    pub(super) fn radiance(
        &self,
        ctx: &mut SampleContext,
        ray: Ray,
        wavelengths: &SampledWavelengths,
    ) -> SampledSpectrum {
        let stokes = self.stokes(ctx, ray, wavelengths);
        SampledSpectrum::from_fn(|i| stokes[i].x)
    }
}
