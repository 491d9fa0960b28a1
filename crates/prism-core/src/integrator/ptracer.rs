//! The particle tracer (Mitsuba 3's `ptracer`): light subpaths traced from the lights and
//! connected to the camera at every surface vertex, each connection splatted to the film
//! position it lands on (Veach 1997, §10.2, the strategies t = 1 of bidirectional path
//! tracing; Arvo & Kirk 1990).
//!
//! Its parameters (`max_depth`, `rr_depth`, `hide_emitters`, `samples_per_pass`) and their
//! defaults are listed in docs/plugins.md.
//!
//! One sample draws two independent things, as Mitsuba's `ParticleTracerIntegrator::sample`:
//!
//! * **The emitters the camera sees.** A light chosen by power; a point of an area light
//!   (density per unit area p_A), or a direction of a light at infinity from the centre of the
//!   scene's bounding sphere (density p_ω), which stands for the point ρ ω on the sphere of
//!   radius ρ = 2R around the centre (density p_ω / ρ²) emitting the environment's radiance
//!   inwards (so the camera, from anywhere within that sphere, sees the environment through
//!   it); the point is connected to the camera: L_e |cos θ_e| W / (P(light) p_A). Delta lights
//!   (points, directions) cannot be seen and are skipped. Left out with `hide_emitters`.
//! * **A light subpath.** A light chosen by power and a ray of its emission
//!   ([`crate::light::LightSource::sample_emission`]), with throughput β = L_e |cos θ| /
//!   (P(light) p_A p_ω); at every surface it meets the vertex is connected to the camera
//!   ([`crate::camera::CameraModel::sample_importance`]), adding β f*(ω_light → ω_camera) W
//!   through an unoccluded shadow ray, and the subpath goes on by sampling the BSDF, β ×= f* |cos|
//!   / p, with Russian roulette after `rr_depth` bounces, on min(max β · η², 0.95) as Mitsuba.
//!
//! **The adjoint BSDF.** Light subpaths carry importance's adjoint, so the BSDF is used with its
//! arguments exchanged (f*(ωi → ωo) = f(ωo → ωi)), and two corrections apply (Veach 1997,
//! §5.2–5.3):
//!
//! * shading normals make the adjoint differ from the BSDF by
//!   |ω_light · n_s| |ω_out · n_g| / (|ω_light · n_g| |ω_out · n_s|) (Veach's eq. 5.19, as
//!   Mitsuba's `ptracer`), and a direction that the geometric and shading normals put on
//!   different sides ends the subpath (no light leaks through the surface);
//! * refraction scales radiance by 1/η² (the BSDFs are written for radiance) but not
//!   importance, so a sampled refraction's weight is multiplied by η² (its `eta`), and a
//!   connection across a transmitting surface evaluates the BSDF from the camera's side, by
//!   reciprocity of the radiance BSDF (f(ω_camera ← ω_light), divided by the cosine it carries
//!   and multiplied by the camera side's).
//!
//! Depth follows Mitsuba: an emitter seen by the camera is a path of depth 1, a connection from
//! the k-th surface of a subpath one of depth k + 1; `max_depth` bounds it (-1: no bound).
//! Wavelengths are drawn once per sample, as camera samples draw them, and where a dispersive
//! surface keeps only the hero wavelength the later contributions are [`super::vertex::hero_only`].
//! No participating media (as Mitsuba's `ptracer`): scenes with media are refused when read.

use glam::{Vec2, Vec3};

use crate::bsdf::{BsdfFlags, BxdfTree};
use crate::camera::{Camera, CameraModel};
use crate::geometry::interaction::SHADOW_EPSILON;
use crate::geometry::offset::offset_ray_origin;
use crate::integrator::SampleContext;
use crate::integrator::adjoint::{sample_adjoint, shading_correction_without_leaks};
use crate::integrator::vertex::{
    path_estimate, russian_roulette, surface_scattering, wavelengths_after,
};
use crate::light::{
    BoundingSphere, EmissionQuery, EmissionSample, Light, LightQuery, LightSource, Receiver,
};
use crate::math::Ray;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

#[derive(Clone, Debug)]
pub struct ParticleTracer {
    /// Longest path in vertices after the camera; negative for unbounded.
    pub max_depth: i32,
    /// Bounces of a light subpath after which Russian roulette is used.
    pub rr_depth: i32,
    /// Whether emitters seen directly by the camera are left black.
    pub hide_emitters: bool,
    /// The most sample indices a pass of the render takes; None for no bound.
    pub samples_per_pass: Option<u32>,
}

impl Default for ParticleTracer {
    fn default() -> Self {
        ParticleTracer {
            max_depth: -1,
            rr_depth: 5,
            hide_emitters: false,
            samples_per_pass: None,
        }
    }
}

/// Where a light subpath's contributions go: the film position (pixels of the full film) and
/// the estimate for the sample's wavelengths, already weighted by the camera's importance.
pub trait Splat {
    /// Whether a contribution at film position `film` would reach a pixel that is rendered
    /// (so that no shadow ray is traced for one that would not).
    fn reaches(&self, film: Vec2) -> bool;

    fn splat(&mut self, film: Vec2, value: SampledSpectrum);
}

/// What a light subpath sample is given: the camera, the sample's wavelengths and time, and
/// the lens sample for connecting the emitters the camera sees.
pub struct LightPathSample<'a> {
    pub camera: &'a Camera,
    pub lambda: &'a SampledWavelengths,
    pub time: f32,
    pub u_lens: Vec2,
}

/// A shadow ray from `from` (offset off its surface along `n` where it has one) to `to`,
/// stopping short of it.
fn shadow_ray(from: Vec3, n: Vec3, to: Vec3, time: f32) -> Ray {
    let d = to - from;
    let origin = if n == Vec3::ZERO {
        from
    } else {
        offset_ray_origin(from, if d.dot(n) >= 0.0 { n } else { -n })
    };
    Ray::new(origin, to - origin, 1.0 - SHADOW_EPSILON, time)
}

impl ParticleTracer {
    /// Whether a light subpath whose last vertex has depth `depth` may connect it to the camera.
    #[inline]
    fn allows(&self, depth: i32) -> bool {
        self.max_depth < 0 || depth < self.max_depth
    }

    /// Traces one sample: the emitters the camera sees (unless hidden) and one light subpath,
    /// handing every contribution to `out`.
    pub fn sample(&self, ctx: &mut SampleContext, sample: &LightPathSample, out: &mut impl Splat) {
        if self.max_depth == 0 {
            return;
        }
        if !self.hide_emitters {
            self.visible_emitter(ctx, sample, out);
        }
        self.light_subpath(ctx, sample, out);
    }

    /// A point of an emitter connected straight to the camera (see the module's text).
    fn visible_emitter(
        &self,
        ctx: &mut SampleContext,
        sample: &LightPathSample,
        out: &mut impl Splat,
    ) {
        let world = ctx.world();
        let Some((index, choice)) = choose_light(ctx) else {
            return;
        };
        let u_choice = ctx.sampler.next_1d();
        let u = ctx.sampler.next_2d();
        let light = &world.lights[index];
        let (lambda, time) = (sample.lambda, sample.time);
        let shapes = &world.geometry.primitives;
        let (camera, radiance, cos, pdf, ray) = match light {
            Light::Area(area) => {
                let Some(s) = area.sample_position(shapes, time, u_choice, u) else {
                    return;
                };
                let Some(camera) = sample.camera.sample_importance(s.p, sample.u_lens, time) else {
                    return;
                };
                let radiance = area.emitted(s.uv, s.shading_n, camera.wi, lambda);
                let ray = shadow_ray(s.p, s.n, camera.p, time);
                (camera, radiance, s.shading_n.dot(camera.wi), s.pdf, ray)
            }
            _ if light.is_environment() => {
                let center = BoundingSphere::around_box(world.geometry.bounds()).center;
                let Some(s) = light.sample_incident(LightQuery {
                    shapes,
                    reference: center,
                    time,
                    u_choice,
                    u,
                    lambda,
                }) else {
                    return;
                };
                let Some(camera) = sample.camera.sample_importance(s.p, sample.u_lens, time) else {
                    return;
                };
                let radiance = light.environment_radiance(-camera.wi, lambda);
                let pdf = s.pdf / (s.p - center).length_squared();
                let ray = shadow_ray(s.p, Vec3::ZERO, camera.p, time);
                (camera, radiance, -s.wi.dot(camera.wi), pdf, ray)
            }
            _ => return,
        };
        if !(cos > 0.0 && pdf > 0.0)
            || radiance.is_black()
            || !out.reaches(camera.film)
            || ctx.occluded(&ray)
        {
            return;
        }
        out.splat(
            camera.film,
            radiance * (cos * camera.weight / (choice * pdf)),
        );
    }

    /// A light subpath, connected to the camera at every surface (see the module's text).
    fn light_subpath(
        &self,
        ctx: &mut SampleContext,
        sample: &LightPathSample,
        out: &mut impl Splat,
    ) {
        let world = ctx.world();
        let Some((index, choice)) = choose_light(ctx) else {
            return;
        };
        let u_choice = ctx.sampler.next_1d();
        let u_position = ctx.sampler.next_2d();
        let u_direction = ctx.sampler.next_2d();
        let Some(emission) = world.lights[index].sample_emission(EmissionQuery {
            shapes: &world.geometry.primitives,
            time: sample.time,
            u_choice,
            u_position,
            u_direction,
            lambda: sample.lambda,
        }) else {
            return;
        };
        let mut throughput = emission.weight * (1.0 / choice);
        if throughput.is_black() {
            return;
        }
        let mut ray = emission_ray(&emission, sample.time);
        let mut lambda = *sample.lambda;
        let mut eta_scale = 1.0f32;
        let mut lobes = BxdfTree::empty();
        let mut reverse_lobes = BxdfTree::empty();
        let mut depth = 1i32;
        while self.allows(depth) {
            let Some(si) = ctx.intersect(&ray) else {
                break;
            };
            let w_light = -ray.d.normalize();
            let scattering = surface_scattering(world, &si, w_light, &mut lambda, &mut lobes);
            let flags = scattering.flags();

            // The connection to the camera.
            let u_lens = ctx.sampler.next_2d();
            if flags.has_smooth_lobe()
                && let Some(camera) = sample.camera.sample_importance(si.p, u_lens, si.time)
                && out.reaches(camera.film)
                && let Some(correction) = shading_correction_without_leaks(&si, w_light, camera.wi)
            {
                let value = if si.n.dot(w_light) * si.n.dot(camera.wi) < 0.0
                    && flags.contains(BsdfFlags::TRANSMISSION)
                {
                    // Across the surface: the radiance BSDF from the camera's side.
                    let reverse =
                        world
                            .material(&si)
                            .scattering(&si, camera.wi, &lambda, &mut reverse_lobes);
                    let cos_light = si.shading.n.dot(w_light).abs();
                    let cos_camera = si.shading.n.dot(camera.wi).abs();
                    reverse.eval(w_light).value * (cos_camera / cos_light)
                } else {
                    scattering.eval(camera.wi).value
                };
                let contribution = throughput * value * (correction * camera.weight);
                if !contribution.is_black() && !ctx.occluded(&si.spawn_ray_to(camera.p, Vec3::ZERO))
                {
                    out.splat(
                        camera.film,
                        path_estimate(contribution, sample.lambda, &lambda),
                    );
                }
            }

            // The next vertex, by sampling the adjoint BSDF.
            let Some((bs, factor)) = sample_adjoint(ctx, &si, &scattering, w_light) else {
                break;
            };
            lambda = wavelengths_after(&lambda, &bs);
            throughput *= bs.weight * factor;
            eta_scale *= bs.eta;
            if throughput.is_black() {
                break;
            }
            ray = si.spawn_ray(bs.wi);
            depth += 1;
            if depth > self.rr_depth {
                let Some(factor) = russian_roulette(ctx, throughput, eta_scale) else {
                    break;
                };
                throughput *= factor;
            }
        }
    }
}

/// The ray of an emission sample, started off the light's surface where it has one.
pub(super) fn emission_ray(emission: &EmissionSample, time: f32) -> Ray {
    let origin = if emission.n == Vec3::ZERO {
        emission.p
    } else {
        let side = if emission.d.dot(emission.n) >= 0.0 {
            emission.n
        } else {
            -emission.n
        };
        offset_ray_origin(emission.p, side)
    };
    Ray::new(origin, emission.d, f32::INFINITY, time)
}

/// A light for a light subpath or a visible emitter, and its probability: the particle tracer's
/// light sampler chooses by power, the same wherever the receiver (here the origin) is.
pub(super) fn choose_light(ctx: &mut SampleContext) -> Option<(usize, f32)> {
    let u_light = ctx.sampler.next_1d();
    ctx.light_sampler()
        .sample(u_light, &Receiver::point(Vec3::ZERO))
}
