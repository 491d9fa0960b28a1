//! Direct illumination (Mitsuba 3's `direct` integrator): at the camera ray's first hit, the
//! light arriving straight from emitters, estimated by `emitter_samples` light samples and
//! `bsdf_samples` BSDF samples combined by multiple importance sampling with the power
//! heuristic and the sample counts (see [`crate::integrator::mis`]):
//!
//! ```text
//! L = L_e + (1/n_l) Σ_l w_l f L / p_l + (1/n_b) Σ_b w_b f L / p_b
//! ```
//!
//! ```xml
//! <integrator type="direct">
//!     <integer name="shading_samples" value="1"/>   <!-- sets both counts below -->
//!     <integer name="emitter_samples" value="1"/>
//!     <integer name="bsdf_samples" value="1"/>
//!     <boolean name="hide_emitters" value="false"/>
//! </integrator>
//! ```
//!
//! * Light samples are taken only where the BSDF has a smooth lobe; BSDF samples everywhere,
//!   so mirrors and glass show the emitters they reflect or refract, but nothing beyond them.
//! * A delta light's sample enters with weight 1/n_l, like any other. (Mitsuba 3.9.1 gives it
//!   weight 1, so its point, spot and directional lights come out n_l times too bright when
//!   `emitter_samples` > 1: see docs/mitsuba-compatibility.md.)
//! * `hide_emitters` hides the emitters the camera sees; BSDF samples still find them.
//! * Dispersion: as in the path tracer, a vertex whose evaluable BSDF disperses, and each BSDF
//!   sample refracted through a dispersive interface, keep only the hero wavelength.

use crate::bsdf::BxdfTree;
use crate::integrator::mis::{BsdfSampleOrigin, Strategies, emission_found, sample_light};
use crate::integrator::{PreparedIntegrator, RayCount, hero_only};
use crate::math::Ray;
use crate::sampling::sampler::Sampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DirectIntegrator {
    /// Light samples per camera ray (taken where the BSDF has a smooth lobe).
    pub emitter_samples: u32,
    /// BSDF samples per camera ray.
    pub bsdf_samples: u32,
    /// Whether emitters seen directly by the camera are left black.
    pub hide_emitters: bool,
}

impl Default for DirectIntegrator {
    fn default() -> Self {
        DirectIntegrator {
            emitter_samples: 1,
            bsdf_samples: 1,
            hide_emitters: false,
        }
    }
}

impl DirectIntegrator {
    fn strategies(&self) -> Strategies {
        Strategies {
            light_samples: self.emitter_samples as f32,
            bsdf_samples: self.bsdf_samples as f32,
        }
    }

    pub(super) fn radiance(
        &self,
        prepared: &PreparedIntegrator,
        ray: Ray,
        wavelengths: &SampledWavelengths,
        sampler: &mut Sampler,
        count: &mut RayCount,
    ) -> SampledSpectrum {
        let world = prepared.world;
        let strategies = self.strategies();
        let mut lambda = *wavelengths;
        let mut result = SampledSpectrum::ZERO;
        count.rays += 1;
        let hit = world.geometry.intersect(&ray);
        if !self.hide_emitters {
            result += emission_found(prepared, &ray, hit.as_ref(), None, &lambda, strategies);
        }
        let Some(si) = hit else {
            return result;
        };
        let wo_world = -ray.d.normalize();
        let mut lobes = BxdfTree::empty();
        let material = &world.materials[world.shape_info[si.shape as usize].material as usize];
        let scattering = material.scattering(&si, wo_world, &lambda, &mut lobes);
        let smooth = scattering.flags().has_smooth_lobe();
        // A dispersive BSDF that can be evaluated uses the hero's index for all its lobes.
        if smooth && scattering.is_dispersive() {
            lambda.terminate_secondary();
        }

        if smooth && self.emitter_samples > 0 {
            let mut light = SampledSpectrum::ZERO;
            for _ in 0..self.emitter_samples {
                light += sample_light(
                    prepared,
                    &si,
                    &scattering,
                    &lambda,
                    sampler,
                    count,
                    strategies,
                    false,
                );
            }
            result += light * (1.0 / self.emitter_samples as f32);
        }

        let mut bsdf = SampledSpectrum::ZERO;
        for _ in 0..self.bsdf_samples {
            let u_lobe = sampler.next_1d();
            let u = sampler.next_2d();
            let Some(bs) = scattering.sample(u_lobe, u) else {
                continue;
            };
            if bs.weight.is_black() {
                continue;
            }
            // This sample's own wavelengths: a dispersive refraction is the hero's alone.
            let mut sample_lambda = lambda;
            if bs.terminates_secondary {
                sample_lambda.terminate_secondary();
            }
            let origin = BsdfSampleOrigin {
                p: si.p,
                n: si.shading.n,
                pdf: bs.pdf,
                specular: bs.flags.is_delta(),
            };
            let sampled_ray = si.spawn_ray(bs.wi);
            count.rays += 1;
            let found = world.geometry.intersect(&sampled_ray);
            let emitted = emission_found(
                prepared,
                &sampled_ray,
                found.as_ref(),
                Some(&origin),
                &sample_lambda,
                strategies,
            );
            let contribution = bs.weight * emitted;
            bsdf += if sample_lambda.secondary_terminated() && !lambda.secondary_terminated() {
                hero_only(contribution)
            } else {
                contribution
            };
        }
        if self.bsdf_samples > 0 {
            result += bsdf * (1.0 / self.bsdf_samples as f32);
        }

        if !wavelengths.secondary_terminated() && lambda.secondary_terminated() {
            return hero_only(result);
        }
        result
    }
}
