//! Vertex connection and merging (Georgiev, Křivánek, Davidovič & Slusallek 2012, "Light
//! Transport Simulation with Vertex Connection and Merging"; the recursive weights of their
//! technical report and of Davidovič's SmallVCM): bidirectional path tracing and photon mapping
//! as strategies of one estimator, weighted against each other by the power heuristic.
//!
//! Its parameters (`max_depth`/`maxDepth`, `rr_depth`/`rrDepth`, `hide_emitters`, `lightImage`,
//! `initialRadius`, `radiusScale`, `alpha`, `useVM`) and their defaults are listed in
//! docs/plugins.md.
//!
//! **An iteration** (one sample index of the render, the render driver's `render::vcm`) traces
//! N = W·H light subpaths, one per pixel of the full film, keeps their vertices, and then one
//! camera subpath per pixel. Light subpaths start as `bdpt`'s do (a light chosen by power, a
//! point uniform over an area light with a cosine-distributed direction, or a point light with
//! a uniform direction) and go on by sampling the adjoint BSDF (Veach's shading-normal factor,
//! η² on refractions); camera subpaths follow the camera ray by sampling the BSDF. Both use
//! Russian roulette after `rr_depth` bounces. At every vertex with a smooth lobe, a light
//! subpath's vertex y (l segments from the light) is
//!
//! * connected to a fresh point of the camera's lens and splatted where it lands on the film
//!   (t = 1, as `bdpt`'s light image; left out without `lightImage`), and
//! * kept for the camera subpaths;
//!
//! and a camera subpath's vertex z (c segments from the camera) adds
//!
//! * the emission it finds (c = 1: the emitter seen directly, unweighted unless hidden);
//! * a light sample (next-event estimation with the scene's light sampler);
//! * a connection to every kept vertex of its own pixel's light subpath (vertex connection);
//! * every kept vertex of any light subpath within the radius r of z (vertex merging), the
//!   photon-mapping estimate β_z Σ_y f(z, ω_o, ω_y) β_y / (N π r²) with the uniform kernel.
//!
//! A path has at most `max_depth` segments: c segments for emission, c + 1 for a light sample
//! and c + l + 1 for a connection, c + l for a merge (the two vertices made one).
//!
//! **Weights.** Each vertex carries SmallVCM's three running quantities d_VCM, d_VC, d_VM (the
//! recursive formulation of the paper's technical report, "Implementing Vertex Connection and
//! Merging", Georgiev 2012): sums over the strategies that would have made the subpath's
//! prefix with more vertices from the other side, as ratios of densities per unit area, each
//! squared for the power heuristic. With η_VCM = π r² N, a subpath leaving vertex x_i by a
//! non-delta sample with density p→ (and reverse density p←, per unit solid angle) and
//! cosine cos_o updates them to
//!
//! ```text
//! d_VC  ← (cos_o/p→)² · (d_VC · p←² + d_VCM + η_VCM²)
//! d_VM  ← (cos_o/p→)² · (d_VM · p←² + d_VCM / η_VCM² + 1)
//! d_VCM ← 1/p→²
//! ```
//!
//! (a delta sample sets d_VCM to 0 and multiplies the others by cos_o²), and on arriving at
//! the next vertex, d away with cosine cos_i, d_VCM ← d_VCM (d²/cos_i)² and d_VC, d_VM are
//! divided by cos_i². A light subpath starts with d_VCM = 1/p_ω², d_VC = cos_light²/p_e² (0 for a point light,
//! which nothing can hit), d_VM = d_VC/η_VCM², p_e the density of its point and direction; a
//! camera subpath with d_VCM = 1/p_c(z₁)², p_c the camera's density of its first vertex per
//! unit area (the importance normalised to the whole film, as `bdpt`'s, so that the t = 1
//! strategies of N light subpaths compare per film; 0 without `lightImage`, which removes them)
//! and d_VC = d_VM = 0. Each contribution's weight is then 1/(1 + w_light + w_camera) with the
//! report's w for its kind, in which η_VCM² weighs a connection against the merges
//! of its vertices. The densities are the nominal ones (a light's point 1/A, chosen by power),
//! as in `bdpt`; Russian roulette is left out of them. Without merging (`useVM` false) the
//! η_VCM terms are left out and no vertices are gathered: the estimator is bidirectional path
//! tracing with light sampling for s = 1.
//!
//! **Radius.** Iteration i (from 1) merges within r_i = r₁ · i^((α−1)/2) (the paper's
//! schedule, after Knaus & Zwicker 2011): the merges' bias vanishes and their variance grows
//! slowly enough for the average over iterations to converge. r₁ = `initialRadius` ×
//! `radiusScale`, with an automatic `initialRadius` of three times the scene's bounding radius
//! over the film's larger side.
//!
//! **Spectral.** Merging needs one set of wavelengths for the vertices of all the light
//! subpaths an iteration keeps, so every subpath of an iteration uses the iteration's
//! wavelengths (a hero and its rotations), as `sppm`'s passes do. Where a BSDF disperses, the
//! subpath that meets it keeps only its hero wavelength from there on (the dispersion rule of
//! [`super::vertex`]), and so does every contribution that uses a vertex of it
//! ([`super::vertex::hero_only`]).
//!
//! **Bias.** Merges are biased at any finite iteration count (blurred by the radius, darkened
//! at corners); the bias vanishes as the iterations grow. With merging off the estimate is
//! unbiased.
//!
//! Surfaces only: scenes with participating media, lights at infinity, spot lights and
//! projectors are refused when read, as for `bdpt`.

use std::f32::consts::PI;

use glam::Vec3;

use crate::bsdf::{BxdfTree, Scattering};
use crate::camera::CameraModel;
use crate::geometry::SurfaceInteraction;
use crate::geometry::offset::offset_ray_origin;
use crate::integrator::adjoint::shading_correction;
use crate::integrator::photon_map::{Located, PhotonMap};
use crate::integrator::vertex::{
    hero_only, russian_roulette, surface_scattering, wavelengths_after,
};
use crate::integrator::{LightPathSample, SampleContext, Splat};
use crate::light::{Light, LightQuery, LightSource, Receiver};
use crate::math::{Frame, Ray};
use crate::sampling::warp::{sample_cosine_hemisphere, sample_uniform_sphere, uniform_sphere_pdf};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::world::World;

#[derive(Clone, Debug)]
pub struct VcmIntegrator {
    /// Longest path in segments (Mitsuba's depth); negative for unbounded.
    pub max_depth: i32,
    /// Bounces of a subpath after which Russian roulette is used.
    pub rr_depth: i32,
    /// Whether emitters seen directly by the camera are left black.
    pub hide_emitters: bool,
    /// Whether light subpaths are connected to the camera (t = 1).
    pub light_image: bool,
    /// The first iteration's radius before `radius_scale`, in world units; None for the
    /// automatic choice (see the module's text).
    pub initial_radius: Option<f32>,
    /// A factor on the initial radius.
    pub radius_scale: f32,
    /// The radius schedule's α ∈ (0, 1).
    pub alpha: f32,
    /// Whether camera vertices merge with light vertices (false: connections only).
    pub merging: bool,
}

impl Default for VcmIntegrator {
    fn default() -> Self {
        VcmIntegrator {
            max_depth: -1,
            rr_depth: 5,
            hide_emitters: false,
            light_image: true,
            initial_radius: None,
            radius_scale: 1.0,
            alpha: 0.75,
            merging: true,
        }
    }
}

/// The power heuristic's exponent applied to a density ratio.
#[inline]
fn mis(x: f32) -> f32 {
    x * x
}

/// What the strategies of one iteration share: its merge radius and light subpath count.
#[derive(Clone, Copy, Debug)]
pub struct Iteration {
    /// The merge radius r.
    pub radius: f32,
    /// The light subpaths N traced in the iteration.
    pub light_paths: f32,
    /// Whether vertices are merged.
    pub merging: bool,
}

impl Iteration {
    /// η_VCM = π r² N: the ratio of a merge's density to a connection's.
    fn eta(&self) -> f32 {
        PI * self.radius * self.radius * self.light_paths
    }

    /// η_VCM² where merging, else 0 (SmallVCM's `misVmWeightFactor`).
    fn vm_weight(&self) -> f32 {
        if self.merging { mis(self.eta()) } else { 0.0 }
    }

    /// 1/η_VCM² where merging, else 0 (SmallVCM's `misVcWeightFactor`, which only the merges'
    /// quantities use).
    fn vc_weight(&self) -> f32 {
        if self.merging {
            mis(1.0 / self.eta())
        } else {
            0.0
        }
    }
}

/// A vertex of a light subpath kept for the camera subpaths.
#[derive(Clone, Copy, Debug)]
pub struct LightVertex {
    si: SurfaceInteraction,
    /// The unit direction towards the light's side (the previous vertex).
    wo: Vec3,
    /// The subpath's throughput on arriving here.
    beta: SampledSpectrum,
    /// The subpath's wavelengths here.
    lambda: SampledWavelengths,
    /// Segments from the light.
    depth: i32,
    d_vcm: f32,
    d_vc: f32,
    d_vm: f32,
}

impl Located for LightVertex {
    fn position(&self) -> Vec3 {
        self.si.p
    }
}

/// The running MIS quantities of a subpath (see the module's text).
#[derive(Clone, Copy, Debug)]
struct Weights {
    d_vcm: f32,
    d_vc: f32,
    d_vm: f32,
}

impl Weights {
    /// On arriving at a vertex `distance_squared` away with cosine `cos_in` there.
    fn arrive(&mut self, distance_squared: f32, cos_in: f32) {
        self.d_vcm *= mis(distance_squared);
        let cos = mis(cos_in);
        self.d_vcm /= cos;
        self.d_vc /= cos;
        self.d_vm /= cos;
    }

    /// On leaving a vertex along a direction drawn with density `pdf` (reverse density
    /// `pdf_rev`), with cosine `cos_out`, by a delta lobe where `delta`.
    fn leave(&mut self, iteration: &Iteration, pdf: f32, pdf_rev: f32, cos_out: f32, delta: bool) {
        if delta {
            self.d_vcm = 0.0;
            self.d_vc *= mis(cos_out);
            self.d_vm *= mis(cos_out);
        } else {
            let factor = mis(cos_out / pdf);
            self.d_vc = factor * (self.d_vc * mis(pdf_rev) + self.d_vcm + iteration.vm_weight());
            self.d_vm =
                factor * (self.d_vm * mis(pdf_rev) + self.d_vcm * iteration.vc_weight() + 1.0);
            self.d_vcm = mis(1.0 / pdf);
        }
    }
}

/// The BSDF at `si` seen from `wo` at the wavelengths `lambda`: the value f|cos θ| and the
/// density of `wi`.
fn eval(
    world: &World,
    si: &SurfaceInteraction,
    wo: Vec3,
    wi: Vec3,
    lambda: &SampledWavelengths,
) -> (SampledSpectrum, f32) {
    let mut lobes = BxdfTree::empty();
    let e = world
        .material(si)
        .scattering(si, wo, lambda, &mut lobes)
        .eval(wi);
    (e.value, e.pdf)
}

/// The unit direction from `from` to `to`, and the squared distance.
fn direction(from: Vec3, to: Vec3) -> Option<(Vec3, f32)> {
    let d = to - from;
    let r2 = d.length_squared();
    (r2 > 0.0 && r2.is_finite()).then(|| (d / r2.sqrt(), r2))
}

/// A contribution whose subpaths have the wavelengths `a` and `b` as an estimate for the
/// iteration's wavelengths `started`: its hero wavelength's alone where either subpath kept
/// only its hero ([`hero_only`]).
fn for_started_wavelengths(
    value: SampledSpectrum,
    started: &SampledWavelengths,
    a: &SampledWavelengths,
    b: &SampledWavelengths,
) -> SampledSpectrum {
    if !started.secondary_terminated() && (a.secondary_terminated() || b.secondary_terminated()) {
        hero_only(value)
    } else {
        value
    }
}

/// The probability of starting a light subpath at light `light` times the density of its
/// point: P(light) / A for an area light, P(light) for a point light.
fn light_origin_pdf(ctx: &SampleContext, light: usize) -> f32 {
    let world = ctx.world();
    let choice = ctx.light_sampler().pmf(light, &Receiver::point(Vec3::ZERO));
    match &world.lights[light] {
        Light::Area(area) => {
            let area = world.geometry.primitives[area.shape as usize].area();
            if area > 0.0 { choice / area } else { 0.0 }
        }
        Light::Point(_) => choice,
        _ => 0.0,
    }
}

impl VcmIntegrator {
    /// Whether a path of `segments` segments is within `max_depth`.
    #[inline]
    fn allows(&self, segments: i32) -> bool {
        self.max_depth < 0 || segments <= self.max_depth
    }

    /// Traces one light subpath of `iteration` at the sample's wavelengths and time: its
    /// vertices with a smooth lobe go to `vertices`, their connections to the camera to `out`.
    pub fn trace_light_path(
        &self,
        ctx: &mut SampleContext,
        sample: &LightPathSample,
        iteration: &Iteration,
        vertices: &mut Vec<LightVertex>,
        out: &mut impl Splat,
    ) {
        let world = ctx.world();
        let u_light = ctx.sampler.next_1d();
        let u_choice = ctx.sampler.next_1d();
        let u_position = ctx.sampler.next_2d();
        let u_direction = ctx.sampler.next_2d();
        if !self.allows(2) {
            return;
        }
        let Some((index, choice)) = ctx
            .light_sampler()
            .sample(u_light, &Receiver::point(Vec3::ZERO))
        else {
            return;
        };
        let mut lambda = *sample.lambda;
        let (origin, d, pdf_dir, position_pdf, emitted, cos_light) = match &world.lights[index] {
            Light::Area(area) => {
                let Some(s) = area.sample_position(
                    &world.geometry.primitives,
                    sample.time,
                    u_choice,
                    u_position,
                ) else {
                    return;
                };
                let side = if s.n.dot(s.shading_n) >= 0.0 {
                    s.n
                } else {
                    -s.n
                };
                let local = sample_cosine_hemisphere(u_direction);
                if !(local.z > 0.0) {
                    return;
                }
                let d = Frame::from_normal(side).to_world(local);
                let cos = s.n.dot(d).abs();
                let emitted = area.emitted(s.uv, s.shading_n, d, &lambda) * cos;
                let origin = offset_ray_origin(s.p, side);
                (origin, d, local.z / PI, s.pdf, emitted, Some(cos))
            }
            Light::Point(point) => {
                let d = sample_uniform_sphere(u_direction);
                let emitted = point.intensity.sample(&lambda);
                (point.position, d, uniform_sphere_pdf(), 1.0, emitted, None)
            }
            _ => return,
        };
        let mut beta = emitted * (1.0 / (choice * position_pdf * pdf_dir));
        if beta.is_black() || !beta.max_value().is_finite() {
            return;
        }
        let emission_pdf = light_origin_pdf(ctx, index) * pdf_dir;
        let d_vc = match cos_light {
            Some(cos) => mis(cos / emission_pdf),
            None => 0.0,
        };
        let mut weights = Weights {
            d_vcm: mis(1.0 / pdf_dir),
            d_vc,
            d_vm: d_vc * iteration.vc_weight(),
        };
        let mut previous = origin;
        let mut ray = Ray::new(origin, d, f32::INFINITY, sample.time);
        let mut lobes = BxdfTree::empty();
        let mut eta_scale = 1.0f32;
        let mut depth = 1i32;
        while let Some(si) = ctx.intersect(&ray) {
            let wo = -ray.d.normalize();
            weights.arrive((si.p - previous).length_squared(), si.n.dot(wo).abs());
            let scattering = surface_scattering(world, &si, wo, &mut lambda, &mut lobes);
            if scattering.flags().has_smooth_lobe() {
                let vertex = LightVertex {
                    si,
                    wo,
                    beta,
                    lambda,
                    depth,
                    d_vcm: weights.d_vcm,
                    d_vc: weights.d_vc,
                    d_vm: weights.d_vm,
                };
                if self.light_image {
                    self.connect_to_camera(ctx, sample, iteration, &vertex, out);
                }
                vertices.push(vertex);
            }
            if !self.allows(depth + 2) {
                break;
            }
            let u_lobe = ctx.sampler.next_1d();
            let u = ctx.sampler.next_2d();
            let Some(bs) = scattering.sample(u_lobe, u) else {
                break;
            };
            let Some(correction) = shading_correction(&si, wo, bs.wi) else {
                break;
            };
            let delta = bs.flags.is_delta();
            let pdf_rev = if delta {
                0.0
            } else {
                eval(world, &si, bs.wi, wo, &lambda).1
            };
            weights.leave(iteration, bs.pdf, pdf_rev, si.n.dot(bs.wi).abs(), delta);
            lambda = wavelengths_after(&lambda, &bs);
            beta *= bs.weight * (correction * bs.eta * bs.eta);
            eta_scale *= bs.eta;
            if beta.is_black() {
                break;
            }
            previous = si.p;
            ray = si.spawn_ray(bs.wi);
            if depth >= self.rr_depth {
                let Some(factor) = russian_roulette(ctx, beta, eta_scale) else {
                    break;
                };
                beta *= factor;
            }
            depth += 1;
        }
    }

    /// What the light-side vertex `y` sends along `w`: f(w, wo) |cos θ_wo| with the adjoint's
    /// shading-normal factor |cos_g θ_w| / |cos_g θ_wo| (as `bdpt`'s light side), and the
    /// density with which its subpath would draw `y.wo` from `w`.
    fn light_side(world: &World, y: &LightVertex, w: Vec3) -> (SampledSpectrum, f32) {
        let (value, pdf_rev) = eval(world, &y.si, w, y.wo, &y.lambda);
        let factor = y.si.n.dot(w).abs() / y.si.n.dot(y.wo).abs();
        if !factor.is_finite() {
            return (SampledSpectrum::ZERO, 0.0);
        }
        (value * factor, pdf_rev)
    }

    /// The light vertex `y` connected to a fresh point of the lens and splatted (t = 1).
    fn connect_to_camera(
        &self,
        ctx: &mut SampleContext,
        sample: &LightPathSample,
        iteration: &Iteration,
        y: &LightVertex,
        out: &mut impl Splat,
    ) {
        let u_lens = ctx.sampler.next_2d();
        if !self.allows(y.depth + 1) {
            return;
        }
        let world = ctx.world();
        let Some(importance) = sample.camera.sample_importance(y.si.p, u_lens, sample.time) else {
            return;
        };
        if !out.reaches(importance.film) {
            return;
        }
        let (f, pdf_rev) = Self::light_side(world, y, importance.wi);
        let value = y.beta * f * importance.weight;
        if value.is_black() {
            return;
        }
        let camera_pdf = importance.weight * y.si.n.dot(importance.wi).abs();
        let w_light = mis(camera_pdf) * (iteration.vm_weight() + y.d_vcm + y.d_vc * mis(pdf_rev));
        if ctx.occluded(&y.si.spawn_ray_to(importance.p, Vec3::ZERO)) {
            return;
        }
        let weight = 1.0 / (1.0 + w_light);
        out.splat(
            importance.film,
            for_started_wavelengths(value * weight, sample.lambda, &y.lambda, &y.lambda),
        );
    }

    /// The camera subpath along `ray` (drawn with the sample's lens point) of `iteration`: the
    /// estimate of every strategy with t ≥ 2, connecting to `light_path` (its pixel's light
    /// subpath's kept vertices) and merging with `vertices` (every light subpath's, where the
    /// iteration merges).
    pub fn trace_camera_path(
        &self,
        ctx: &mut SampleContext,
        sample: &LightPathSample,
        mut ray: Ray,
        iteration: &Iteration,
        light_path: &[LightVertex],
        vertices: Option<&PhotonMap<LightVertex>>,
    ) -> SampledSpectrum {
        let world = ctx.world();
        let started = sample.lambda;
        let mut lambda = *started;
        let mut result = SampledSpectrum::ZERO;
        let mut beta = SampledSpectrum::ONE;
        let mut weights = Weights {
            d_vcm: 0.0,
            d_vc: 0.0,
            d_vm: 0.0,
        };
        let mut lobes = BxdfTree::empty();
        let mut eta_scale = 1.0f32;
        let mut previous = ray.o;
        let mut depth = 1i32;
        if !self.allows(1) {
            return result;
        }
        while let Some(si) = ctx.intersect(&ray) {
            let wo = -ray.d.normalize();
            let cos_in = si.n.dot(wo).abs();
            if depth == 1 {
                let camera_pdf = sample
                    .camera
                    .sample_importance(si.p, sample.u_lens, sample.time)
                    .map_or(0.0, |importance| importance.weight * cos_in);
                if self.light_image && camera_pdf > 0.0 {
                    weights.d_vcm = mis(1.0 / camera_pdf);
                }
            } else {
                weights.arrive((si.p - previous).length_squared(), cos_in);
            }
            if let Some(light) = world.shape_info[si.shape as usize].light
                && let Light::Area(area) = &world.lights[light as usize]
                && !(depth == 1 && self.hide_emitters)
            {
                let le = area.emitted(si.uv, si.shading.n, wo, &lambda);
                let weight = if depth == 1 {
                    1.0
                } else {
                    let direct = light_origin_pdf(ctx, light as usize);
                    let emission = direct * cos_in / PI;
                    1.0 / (1.0 + mis(direct) * weights.d_vcm + mis(emission) * weights.d_vc)
                };
                if weight.is_finite() {
                    result +=
                        for_started_wavelengths(beta * le * weight, started, &lambda, &lambda);
                }
            }
            if !self.allows(depth + 1) {
                break;
            }
            let scattering = surface_scattering(world, &si, wo, &mut lambda, &mut lobes);
            if scattering.flags().has_smooth_lobe() {
                let vertex = CameraVertex {
                    si: &si,
                    wo,
                    beta,
                    lambda: &lambda,
                    depth,
                    weights: &weights,
                    scattering: &scattering,
                };
                result += self.sample_light(ctx, sample, iteration, &vertex);
                for y in light_path {
                    if self.allows(depth + y.depth + 1) {
                        result += self.connect(ctx, started, iteration, &vertex, y);
                    }
                }
                if let Some(vertices) = vertices {
                    result += self.merge(world, started, iteration, &vertex, vertices);
                }
            }
            let u_lobe = ctx.sampler.next_1d();
            let u = ctx.sampler.next_2d();
            let Some(bs) = scattering.sample(u_lobe, u) else {
                break;
            };
            let delta = bs.flags.is_delta();
            let pdf_rev = if delta {
                0.0
            } else {
                eval(world, &si, bs.wi, wo, &lambda).1
            };
            weights.leave(iteration, bs.pdf, pdf_rev, si.n.dot(bs.wi).abs(), delta);
            lambda = wavelengths_after(&lambda, &bs);
            beta *= bs.weight;
            eta_scale *= bs.eta;
            if beta.is_black() {
                break;
            }
            previous = si.p;
            ray = si.spawn_ray(bs.wi);
            if depth >= self.rr_depth {
                let Some(factor) = russian_roulette(ctx, beta, eta_scale) else {
                    break;
                };
                beta *= factor;
            }
            depth += 1;
        }
        result
    }

    /// Next-event estimation at the camera vertex `z`: a light chosen by power, a point of it
    /// by its own sampling, weighted against the BSDF sample that could have found it and the
    /// strategies that take z into the light subpath.
    fn sample_light(
        &self,
        ctx: &mut SampleContext,
        sample: &LightPathSample,
        iteration: &Iteration,
        z: &CameraVertex,
    ) -> SampledSpectrum {
        let world = ctx.world();
        let u_light = ctx.sampler.next_1d();
        let u_choice = ctx.sampler.next_1d();
        let u = ctx.sampler.next_2d();
        let Some((index, choice)) = ctx
            .light_sampler()
            .sample(u_light, &Receiver::point(Vec3::ZERO))
        else {
            return SampledSpectrum::ZERO;
        };
        let Some(ls) = world.lights[index].sample_incident(LightQuery {
            shapes: &world.geometry.primitives,
            reference: z.si.p,
            time: sample.time,
            u_choice,
            u,
            lambda: z.lambda,
        }) else {
            return SampledSpectrum::ZERO;
        };
        if !(ls.pdf > 0.0) {
            return SampledSpectrum::ZERO;
        }
        let e = z.scattering.eval(ls.wi);
        let value = z.beta * e.value * ls.radiance * (1.0 / (choice * ls.pdf));
        let Some((_, r2)) = direction(z.si.p, ls.p) else {
            return SampledSpectrum::ZERO;
        };
        if value.is_black() {
            return SampledSpectrum::ZERO;
        }
        let (w_light, emission_pdf) = match &world.lights[index] {
            Light::Area(_) => {
                let cos_light = ls.n.dot(ls.wi).abs();
                let direct = light_origin_pdf(ctx, index);
                (mis(e.pdf * cos_light / r2 / direct), cos_light / PI)
            }
            _ => (0.0, uniform_sphere_pdf()),
        };
        let pdf_rev = eval(world, z.si, ls.wi, z.wo, z.lambda).1;
        let w_camera = mis(emission_pdf * z.si.n.dot(ls.wi).abs() / r2)
            * (iteration.vm_weight() + z.weights.d_vcm + z.weights.d_vc * mis(pdf_rev));
        let weight = 1.0 / (w_light + 1.0 + w_camera);
        if !weight.is_finite() || ctx.occluded(&z.si.spawn_ray_to(ls.p, ls.n)) {
            return SampledSpectrum::ZERO;
        }
        for_started_wavelengths(value * weight, sample.lambda, z.lambda, z.lambda)
    }

    /// The camera vertex `z` connected to the light vertex `y` by a shadow ray.
    fn connect(
        &self,
        ctx: &mut SampleContext,
        started: &SampledWavelengths,
        iteration: &Iteration,
        z: &CameraVertex,
        y: &LightVertex,
    ) -> SampledSpectrum {
        let world = ctx.world();
        let Some((w, r2)) = direction(z.si.p, y.si.p) else {
            return SampledSpectrum::ZERO;
        };
        let camera_side = z.scattering.eval(w);
        if camera_side.value.is_black() {
            return SampledSpectrum::ZERO;
        }
        let (light_value, light_pdf_rev) = Self::light_side(world, y, -w);
        let value = z.beta * camera_side.value * light_value * y.beta * (1.0 / r2);
        if value.is_black() {
            return SampledSpectrum::ZERO;
        }
        let light_pdf = eval(world, &y.si, y.wo, -w, &y.lambda).1;
        let camera_pdf_rev = eval(world, z.si, w, z.wo, z.lambda).1;
        let camera_pdf_area = camera_side.pdf * y.si.n.dot(w).abs() / r2;
        let light_pdf_area = light_pdf * z.si.n.dot(w).abs() / r2;
        let w_light =
            mis(camera_pdf_area) * (iteration.vm_weight() + y.d_vcm + y.d_vc * mis(light_pdf_rev));
        let w_camera = mis(light_pdf_area)
            * (iteration.vm_weight() + z.weights.d_vcm + z.weights.d_vc * mis(camera_pdf_rev));
        let weight = 1.0 / (w_light + 1.0 + w_camera);
        if !weight.is_finite() || ctx.occluded(&z.si.spawn_ray_to(y.si.p, y.si.n)) {
            return SampledSpectrum::ZERO;
        }
        for_started_wavelengths(value * weight, started, z.lambda, &y.lambda)
    }

    /// The light vertices of `vertices` within the iteration's radius of the camera vertex `z`,
    /// merged with it: β_z Σ_y w_y f(z, ω_o, ω_y) β_y / (π r² N).
    fn merge(
        &self,
        world: &World,
        started: &SampledWavelengths,
        iteration: &Iteration,
        z: &CameraVertex,
        vertices: &PhotonMap<LightVertex>,
    ) -> SampledSpectrum {
        let mut sum = SampledSpectrum::ZERO;
        vertices.for_each_near(z.si.p, iteration.radius, |y| {
            if !self.allows(z.depth + y.depth) {
                return;
            }
            let cos = z.si.shading.n.dot(y.wo).abs();
            if cos == 0.0 {
                return;
            }
            let e = z.scattering.eval(y.wo);
            if e.value.is_black() {
                return;
            }
            let pdf_rev = eval(world, z.si, y.wo, z.wo, z.lambda).1;
            let w_light = y.d_vcm * iteration.vc_weight() + y.d_vm * mis(e.pdf);
            let w_camera = z.weights.d_vcm * iteration.vc_weight() + z.weights.d_vm * mis(pdf_rev);
            let weight = 1.0 / (w_light + 1.0 + w_camera);
            if weight.is_finite() {
                let term = y.beta * e.value * (weight / cos);
                sum += for_started_wavelengths(term, started, z.lambda, &y.lambda);
            }
        });
        z.beta * sum * (1.0 / iteration.eta())
    }
}

/// A camera subpath's vertex with a smooth lobe, as its strategies see it.
struct CameraVertex<'a, 's, 't, 'w> {
    si: &'a SurfaceInteraction,
    /// The unit direction towards the previous vertex.
    wo: Vec3,
    /// The subpath's throughput on arriving here.
    beta: SampledSpectrum,
    lambda: &'a SampledWavelengths,
    /// Segments from the camera.
    depth: i32,
    weights: &'a Weights,
    scattering: &'s Scattering<'t, 'w>,
}
