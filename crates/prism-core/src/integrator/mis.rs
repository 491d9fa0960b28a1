//! Direct light by two strategies combined with multiple importance sampling (Veach 1997,
//! §9.2): light samples (a light chosen by the integrator's light sampler, a point on it, a
//! shadow ray) and BSDF samples that happen to find an emitter. The path tracer and the
//! direct-illumination integrator share these two halves, so that both weigh each light the
//! same way.
//!
//! With n_l light samples and n_b BSDF samples per vertex, a sample of strategy s with density
//! p_s gets the power heuristic with sample counts (Veach's eq. 9.13, β = 2),
//!
//! ```text
//! w_s = (n_s p_s)² / ((n_l p_l)² + (n_b p_b)²),
//! ```
//!
//! and the vertex's estimate is Σ_l w_l f L / (n_l p_l) + Σ_b w_b f L / (n_b p_b): the callers
//! divide each strategy's sum by its count. Delta lights are found only by light samples and
//! delta lobes only by BSDF samples, each then with weight 1.

use glam::Vec3;

use crate::bsdf::Scattering;
use crate::geometry::{SurfaceInteraction, SurfaceSample};
use crate::integrator::{PreparedIntegrator, RayCount, normals_agree, unoccluded};
use crate::light::{AreaLight, Light, Receiver};
use crate::math::Ray;
use crate::sampling::sampler::Sampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

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

/// How many samples of each strategy a vertex takes: they scale the densities in the weights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Strategies {
    pub light_samples: f32,
    pub bsdf_samples: f32,
}

impl Strategies {
    /// One light sample and one BSDF sample per vertex (the path tracer).
    pub const ONE_EACH: Strategies = Strategies {
        light_samples: 1.0,
        bsdf_samples: 1.0,
    };
}

/// Where a BSDF sample came from, for weighing the emission it finds.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSampleOrigin {
    /// The vertex the sampled ray left from, and its shading normal.
    pub p: Vec3,
    pub n: Vec3,
    /// Solid-angle density of the BSDF sample.
    pub pdf: f32,
    /// Whether it came from a delta lobe (no light sample could have found its direction).
    pub specular: bool,
}

/// The emitted radiance that `ray` finds, weighted against the light samples that could have
/// found it: at `hit` (an area light's shape), or in the environment when the ray escapes
/// (`hit` None). Without an `origin` (a camera ray) or after a delta lobe the weight is 1.
#[inline]
pub fn emission_found(
    prepared: &PreparedIntegrator,
    ray: &Ray,
    hit: Option<&SurfaceInteraction>,
    origin: Option<&BsdfSampleOrigin>,
    lambda: &SampledWavelengths,
    strategies: Strategies,
) -> SampledSpectrum {
    let world = prepared.world;
    let (emitted, light_index, light_pdf) = match hit {
        None => {
            let Some(env) = world.environment else {
                return SampledSpectrum::ZERO;
            };
            let light = &world.lights[env as usize];
            let d = ray.d.normalize();
            let emitted = light.environment_radiance(d, lambda);
            (emitted, env, LightPdf::Environment(d))
        }
        Some(si) => {
            let Some(light_index) = world.shape_info[si.shape as usize].light else {
                return SampledSpectrum::ZERO;
            };
            let Light::Area(light) = &world.lights[light_index as usize] else {
                unreachable!("only area lights are attached to shapes");
            };
            let emitted = light.emitted(si.uv, si.shading.n, -ray.d.normalize(), lambda);
            (emitted, light_index, LightPdf::Area(light, si))
        }
    };
    let Some(origin) = origin.filter(|o| !o.specular) else {
        return emitted;
    };
    if emitted.is_black() {
        return emitted;
    }
    let choice = prepared
        .light_sampler
        .pmf(light_index as usize, &Receiver::surface(origin.p, origin.n));
    let light_pdf = choice
        * match light_pdf {
            LightPdf::Environment(d) => world.lights[light_index as usize].environment_pdf(d),
            LightPdf::Area(light, si) => light.pdf_from(
                &world.geometry.primitives,
                origin.p,
                si.time,
                &SurfaceSample::at(si),
            ),
        };
    emitted
        * power_heuristic(
            strategies.bsdf_samples * origin.pdf,
            strategies.light_samples * light_pdf,
        )
}

/// What the light-sampling density of an emitter found by a BSDF sample depends on.
enum LightPdf<'a> {
    Environment(Vec3),
    Area(&'a AreaLight, &'a SurfaceInteraction),
}

/// One light sample at `si`: a light chosen by the light sampler, a point on it, the shadow
/// ray, and the MIS-weighted contribution f·L·w / (p_light · p_choice). With `strict_normals`
/// a light whose direction the geometric and shading normals put on different sides
/// contributes nothing (Mitsuba 0.6's `strictNormals`).
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn sample_light(
    prepared: &PreparedIntegrator,
    si: &SurfaceInteraction,
    scattering: &Scattering,
    lambda: &SampledWavelengths,
    sampler: &mut Sampler,
    count: &mut RayCount,
    strategies: Strategies,
    strict_normals: bool,
) -> SampledSpectrum {
    let world = prepared.world;
    let u_light = sampler.next_1d();
    let u_choice = sampler.next_1d();
    let u = sampler.next_2d();
    let Some((light_index, choice_pmf)) = prepared
        .light_sampler
        .sample(u_light, &Receiver::surface(si.p, si.shading.n))
    else {
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
    if strict_normals && !normals_agree(si, ls.wi) {
        return SampledSpectrum::ZERO;
    }
    let Some(f) = unoccluded(world, si, scattering, &ls, count) else {
        return SampledSpectrum::ZERO;
    };
    let light_pdf = choice_pmf * ls.pdf;
    let weight = if ls.is_delta {
        1.0
    } else {
        power_heuristic(
            strategies.light_samples * light_pdf,
            strategies.bsdf_samples * f.pdf,
        )
    };
    f.value * ls.radiance * (weight / light_pdf)
}
