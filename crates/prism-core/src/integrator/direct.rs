//! Direct illumination (Mitsuba 3's `direct` integrator): at the camera ray's first hit, the
//! light arriving straight from emitters, estimated by `emitter_samples` light samples and
//! `bsdf_samples` BSDF samples combined by multiple importance sampling with the power
//! heuristic and the sample counts (see [`crate::integrator::mis`]):
//!
//! ```text
//! L = L_e + (1/n_l) Σ_l w_l f L / p_l + (1/n_b) Σ_b w_b f L / p_b
//! ```
//!
//! Its parameters (`emitter_samples`, `bsdf_samples`, `shading_samples` setting both,
//! `hide_emitters`) and their defaults are listed in docs/plugins.md.
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
use crate::geometry::SurfaceInteraction;
use crate::integrator::SampleContext;
use crate::integrator::mis::{ScatterOrigin, Strategies, emission_found, sample_light_at_surface};
use crate::integrator::stepped::SteppedPath;
use crate::integrator::vertex::{path_estimate, surface_scattering, wavelengths_after};
use crate::light::Receiver;
use crate::math::Ray;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::world::World;

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

    /// The estimate along the camera ray `ray`, whose nearest surface is `hit`.
    fn estimate_at(
        &self,
        ctx: &mut SampleContext,
        ray: &Ray,
        hit: Option<SurfaceInteraction>,
        wavelengths: &SampledWavelengths,
    ) -> SampledSpectrum {
        let world = ctx.world();
        let strategies = self.strategies();
        let mut lambda = *wavelengths;
        let mut result = SampledSpectrum::ZERO;
        if !self.hide_emitters {
            result += emission_found(ctx, ray, hit.as_ref(), None, &lambda, strategies);
        }
        let Some(si) = hit else {
            return result;
        };
        let wo_world = -ray.d.normalize();
        let mut lobes = BxdfTree::empty();
        let scattering = surface_scattering(world, &si, wo_world, &mut lambda, &mut lobes);

        if scattering.flags().has_smooth_lobe() && self.emitter_samples > 0 {
            let mut light = SampledSpectrum::ZERO;
            for _ in 0..self.emitter_samples {
                if let Some(terms) = sample_light_at_surface(ctx, &si, &scattering, &lambda, false)
                {
                    light += terms.weighted(strategies);
                }
            }
            result += light * (1.0 / self.emitter_samples as f32);
        }

        let mut bsdf = SampledSpectrum::ZERO;
        for _ in 0..self.bsdf_samples {
            let u_lobe = ctx.sampler.next_1d();
            let u = ctx.sampler.next_2d();
            let Some(bs) = scattering.sample(u_lobe, u) else {
                continue;
            };
            if bs.weight.is_black() {
                continue;
            }
            // This sample's own wavelengths: a dispersive refraction is the hero's alone.
            let sample_lambda = wavelengths_after(&lambda, &bs);
            let origin = ScatterOrigin {
                receiver: Receiver::surface(si.p, si.shading.n),
                pdf: bs.pdf,
                specular: bs.flags.is_delta(),
            };
            let sampled_ray = si.spawn_ray(bs.wi);
            let found = ctx.intersect(&sampled_ray);
            let emitted = emission_found(
                ctx,
                &sampled_ray,
                found.as_ref(),
                Some(&origin),
                &sample_lambda,
                strategies,
            );
            bsdf += path_estimate(bs.weight * emitted, &lambda, &sample_lambda);
        }
        if self.bsdf_samples > 0 {
            result += bsdf * (1.0 / self.bsdf_samples as f32);
        }
        path_estimate(result, wavelengths, &lambda)
    }
}

/// The camera sample of the direct integrator before its one ray query: the camera ray and its
/// wavelengths, and the estimate once the query is answered.
#[derive(Clone, Debug)]
pub struct DirectState {
    ray: Ray,
    wavelengths: SampledWavelengths,
    result: SampledSpectrum,
}

impl SteppedPath for DirectIntegrator {
    type State = DirectState;

    fn start(
        &self,
        _world: &World,
        ray: Ray,
        wavelengths: &SampledWavelengths,
    ) -> Option<DirectState> {
        Some(DirectState {
            ray,
            wavelengths: *wavelengths,
            result: SampledSpectrum::ZERO,
        })
    }

    #[inline]
    fn ray(state: &DirectState) -> &Ray {
        &state.ray
    }

    /// The whole estimate at the camera ray's hit: the emission there, the light samples and
    /// the BSDF samples (whose rays it traces itself). The sample ends with it.
    fn step(
        &self,
        ctx: &mut SampleContext,
        state: &mut DirectState,
        hit: Option<SurfaceInteraction>,
    ) -> bool {
        state.result = self.estimate_at(ctx, &state.ray, hit, &state.wavelengths);
        false
    }

    #[inline]
    fn estimate(&self, state: &DirectState) -> SampledSpectrum {
        state.result
    }
}
