//! Direct light by two strategies combined with multiple importance sampling (Veach 1997,
//! §9.2): light samples (a light chosen by the integrator's light sampler, a point on it, a
//! shadow ray) and BSDF (or phase-function) samples that happen to find an emitter. Every
//! integrator takes both halves from here, so that all of them weigh each light the same way:
//! [`sample_light`] with a hook for what the shadow ray crosses (vacuum for the surface
//! integrators, media and index-matched boundaries for the volumetric ones), and
//! [`emission_along`] with [`FoundEmission::light_pdf`] for the emission a sampled direction
//! finds.
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
//! delta lobes only by BSDF samples, each then with weight 1. A light sample's density p_l is
//! the light sampler's probability of choosing the light times the light's density of the
//! point, both seen from the receiver ([`Receiver`]: the point and, on a surface, its shading
//! normal), and the emission a BSDF sample finds is weighed with the same product seen from
//! the vertex the sample left.

use glam::Vec3;

use crate::bsdf::{BsdfEval, Scattering};
use crate::geometry::{SurfaceInteraction, SurfaceSample};
use crate::integrator::SampleContext;
use crate::integrator::transmittance::ShadowTransmittance;
use crate::integrator::vertex::normals_agree;
use crate::light::{AreaLight, Light, LightQuery, LightSample, LightSource, Receiver};
use crate::math::Ray;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::world::World;

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
    /// One light sample and one BSDF sample per vertex (the path tracers).
    pub const ONE_EACH: Strategies = Strategies {
        light_samples: 1.0,
        bsdf_samples: 1.0,
    };
}

/// Where a BSDF sample came from, for weighing the emission it finds.
#[derive(Clone, Copy, Debug)]
pub struct ScatterOrigin {
    /// The vertex the sampled ray left from, as light sampling sees it.
    pub receiver: Receiver,
    /// Solid-angle density of the BSDF sample.
    pub pdf: f32,
    /// Whether it came from a delta lobe (no light sample could have found its direction).
    pub specular: bool,
}

/// Emitted radiance found along a direction: at an area light's shape, or in the environment.
pub struct FoundEmission<'w, 'h> {
    /// The radiance arriving back along the direction.
    pub radiance: SampledSpectrum,
    light: u32,
    at: EmitterPoint<'w, 'h>,
}

/// Where the emission was found, which its light-sampling density depends on.
enum EmitterPoint<'w, 'h> {
    /// The environment, in this direction (unit).
    Environment(Vec3),
    /// A point of an area light's shape.
    Surface(&'w AreaLight, &'h SurfaceInteraction),
}

/// The emission that a ray in direction `d` (unit) finds: at `hit` (the emission of its shape's
/// area light, if any), or in the environment when the ray escapes (`hit` None); None where
/// it finds no emitter.
#[inline]
pub fn emission_along<'w, 'h>(
    world: &'w World,
    d: Vec3,
    hit: Option<&'h SurfaceInteraction>,
    lambda: &SampledWavelengths,
) -> Option<FoundEmission<'w, 'h>> {
    match hit {
        None => {
            let light = world.environment?;
            Some(FoundEmission {
                radiance: world.lights[light as usize].environment_radiance(d, lambda),
                light,
                at: EmitterPoint::Environment(d),
            })
        }
        Some(si) => {
            let light = world.shape_info[si.shape as usize].light?;
            let Light::Area(area) = &world.lights[light as usize] else {
                unreachable!("only area lights are attached to shapes");
            };
            Some(FoundEmission {
                radiance: area.emitted(si.uv, si.shading.n, -d, lambda),
                light,
                at: EmitterPoint::Surface(area, si),
            })
        }
    }
}

impl FoundEmission<'_, '_> {
    /// The density with which light sampling from `from` would have found this emission per
    /// unit solid angle: the probability of choosing its light times the light's density of
    /// the point (or direction).
    #[inline]
    pub fn light_pdf(&self, ctx: &SampleContext, from: &Receiver) -> f32 {
        let world = ctx.world();
        let choice = ctx.light_sampler().pmf(self.light as usize, from);
        choice
            * match self.at {
                EmitterPoint::Environment(d) => {
                    world.lights[self.light as usize].environment_pdf(d)
                }
                EmitterPoint::Surface(light, si) => light.pdf_from(
                    &world.geometry.primitives,
                    from.p,
                    si.time,
                    &SurfaceSample::at(si),
                ),
            }
    }
}

/// The emitted radiance that `ray` finds at `hit` (or in the environment, `hit` None),
/// weighted against the light samples that could have found it. Without an `origin` (a camera
/// ray) or after a delta lobe the weight is 1.
#[inline]
pub fn emission_found(
    ctx: &SampleContext,
    ray: &Ray,
    hit: Option<&SurfaceInteraction>,
    origin: Option<&ScatterOrigin>,
    lambda: &SampledWavelengths,
    strategies: Strategies,
) -> SampledSpectrum {
    let Some(found) = emission_along(ctx.world(), ray.d.normalize(), hit, lambda) else {
        return SampledSpectrum::ZERO;
    };
    let Some(origin) = origin.filter(|o| !o.specular) else {
        return found.radiance;
    };
    if found.radiance.is_black() {
        return found.radiance;
    }
    let light_pdf = found.light_pdf(ctx, &origin.receiver);
    found.radiance
        * power_heuristic(
            strategies.bsdf_samples * origin.pdf,
            strategies.light_samples * light_pdf,
        )
}

/// The factors of one light sample at a vertex: the BSDF's or phase function's value towards
/// the light and its solid-angle density of that direction, the light sample's density (the
/// light's choice included), the transmittance of the shadow ray (media and null surfaces) and
/// the radiance.
#[derive(Clone, Copy, Debug)]
pub struct LightSampleTerms {
    pub value: SampledSpectrum,
    pub direction_pdf: f32,
    pub light_pdf: f32,
    pub is_delta: bool,
    pub transmittance: ShadowTransmittance,
    pub radiance: SampledSpectrum,
}

impl LightSampleTerms {
    /// The sample's contribution f·Tr·L·w / p_light, w the power heuristic against the
    /// vertex's own sampling with the strategies' counts (1 for a delta light).
    #[inline]
    pub fn weighted(&self, strategies: Strategies) -> SampledSpectrum {
        let weight = if self.is_delta {
            1.0
        } else {
            power_heuristic(
                strategies.light_samples * self.light_pdf,
                strategies.bsdf_samples * self.direction_pdf,
            )
        };
        self.value * self.transmittance.total() * self.radiance * (weight / self.light_pdf)
    }
}

/// A point on `light` seen from `reference` at `time`, drawing its two random numbers.
#[inline]
pub fn sample_point_on(
    ctx: &mut SampleContext,
    light: &Light,
    reference: Vec3,
    time: f32,
    lambda: &SampledWavelengths,
) -> Option<LightSample> {
    let u_choice = ctx.sampler.next_1d();
    let u = ctx.sampler.next_2d();
    light.sample_incident(LightQuery {
        shapes: &ctx.world().geometry.primitives,
        reference,
        time,
        u_choice,
        u,
        lambda,
    })
}

/// One light sample at `receiver` at `time`: a light chosen by the light sampler and a point on
/// it. `reach` is the vertex's side of it: the vertex's value and density towards the sample
/// (its BSDF's or phase function's) and the transmittance of the shadow ray (1 or 0 through
/// vacuum, that of the media and null surfaces crossed in volumetric path tracing), or None
/// where no light arrives; it is asked only for a sample that exists.
#[inline]
pub fn sample_light(
    ctx: &mut SampleContext,
    receiver: &Receiver,
    time: f32,
    lambda: &SampledWavelengths,
    reach: impl FnOnce(&mut SampleContext, &LightSample) -> Option<(BsdfEval, ShadowTransmittance)>,
) -> Option<LightSampleTerms> {
    let u_light = ctx.sampler.next_1d();
    let u_choice = ctx.sampler.next_1d();
    let u = ctx.sampler.next_2d();
    let world = ctx.world();
    let (light, choice_pmf) = ctx.light_sampler().sample(u_light, receiver)?;
    let ls = world.lights[light].sample_incident(LightQuery {
        shapes: &world.geometry.primitives,
        reference: receiver.p,
        time,
        u_choice,
        u,
        lambda,
    })?;
    let (f, transmittance) = reach(ctx, &ls)?;
    Some(LightSampleTerms {
        value: f.value,
        direction_pdf: f.pdf,
        light_pdf: choice_pmf * ls.pdf,
        is_delta: ls.is_delta,
        transmittance,
        radiance: ls.radiance,
    })
}

/// The BSDF's value and density towards the light sample `light`, if it reaches the surface
/// vertex `si` through vacuum: zero values are dropped before the shadow ray is traced.
#[inline]
pub fn unoccluded(
    ctx: &mut SampleContext,
    si: &SurfaceInteraction,
    scattering: &Scattering,
    light: &LightSample,
) -> Option<BsdfEval> {
    let f = scattering.eval(light.wi);
    if f.value.is_black() || ctx.occluded(&si.spawn_ray_to(light.p, light.n)) {
        return None;
    }
    Some(f)
}

/// One light sample at the surface vertex `si` through vacuum (the surface integrators). With
/// `strict_normals` a light whose direction the geometric and shading normals put on different
/// sides contributes nothing (Mitsuba 0.6's `strictNormals`).
#[inline]
pub fn sample_light_at_surface(
    ctx: &mut SampleContext,
    si: &SurfaceInteraction,
    scattering: &Scattering,
    lambda: &SampledWavelengths,
    strict_normals: bool,
) -> Option<LightSampleTerms> {
    let receiver = Receiver::surface(si.p, si.shading.n);
    sample_light(ctx, &receiver, si.time, lambda, |ctx, ls| {
        if strict_normals && !normals_agree(si, ls.wi) {
            return None;
        }
        unoccluded(ctx, si, scattering, ls).map(|f| (f, ShadowTransmittance::ONE))
    })
}
