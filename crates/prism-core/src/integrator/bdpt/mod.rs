//! Bidirectional path tracing (Veach 1997, ch. 10; the design of pbrt-v4's `BDPTIntegrator`,
//! with Mitsuba 0.6's parameters): a camera subpath and a light subpath per sample, every
//! prefix of one connected to every prefix of the other, each connection weighted against all
//! the other strategies that could have made the same path by the power heuristic
//! ([`weights`]).
//!
//! Its parameters (`max_depth`/`maxDepth`, `rr_depth`/`rrDepth`, `hide_emitters`, `lightImage`,
//! `sampleDirect`) and their defaults are listed in docs/plugins.md.
//!
//! **The subpaths.** The camera subpath z₀ z₁ … starts at the camera sample's lens point and
//! follows its ray; the light subpath y₀ y₁ … starts at a light chosen by power (as the
//! particle tracer's), at a point drawn uniformly over an area light's surface with a
//! cosine-distributed direction about its normal, or at a point light with a uniform direction.
//! Both go on by sampling the BSDF (the light subpath the adjoint BSDF, with the particle
//! tracer's corrections for shading normals and refraction: [`super::ptracer`], but without
//! ending where the geometric and shading normals disagree, as the camera subpath does not), with Russian
//! roulette after `rr_depth` bounces; each vertex keeps its throughput β, its densities per
//! unit area from either side (`pdf_fwd`, `pdf_rev`) and whether it scattered by a delta lobe.
//!
//! **The strategies** (s light vertices, t camera vertices, a path of s + t − 1 segments, which
//! is its depth as Mitsuba counts it and at most `max_depth`):
//!
//! * s = 0: the camera subpath's vertex z_{t−1} lies on an area light: β L_e;
//! * s = 1: light sampling at z_{t−1} with the scene's light sampler (chosen by power, a point
//!   by the light's own sampling), β f L_e / p; without `sampleDirect` the light subpath's
//!   first vertex y₀ is connected instead;
//! * t = 1: the light subpath's vertex y_{s−1} connected to a fresh point of the camera's lens
//!   ([`crate::camera::CameraModel::sample_importance`]) and splatted where it lands on the
//!   film, as the particle tracer does (left out without `lightImage`);
//! * otherwise: y_{s−1} and z_{t−1} joined by a shadow ray, β_z f(z) G f(y) β_y.
//!
//! s = 1, t = 1 (a light's point seen by the camera) is not traced: such paths are left to
//! s = 0, t = 2, as pbrt does. `hide_emitters` drops s = 0, t = 2.
//!
//! **Densities for the weights.** A light's point has density P(light) / A (1 for a point light,
//! which is a delta), its direction |cos θ| / π (1/4π for a point light); the camera's direction
//! density is the importance's (1/(A cos³θ) per unit solid angle), so that with W·H light
//! subpaths per sample index the t = 1 and t ≥ 2 strategies are compared per film. Densities
//! per unit solid angle become per unit area at the next vertex by |cos θ| / r². The weights use
//! these nominal densities even where a strategy samples otherwise (light sampling of a sphere
//! by its visible cone, a camera sample through the reconstruction filter): the weights of a
//! path still sum to one, so the estimate stays unbiased.
//!
//! **Spectral.** A sample carries the four wavelengths of the camera sample on both subpaths.
//! Where a BSDF disperses, the subpath that meets it keeps only its hero wavelength from there
//! on (the dispersion rule of [`super::vertex`]: a smooth dispersive lobe at the vertex, a
//! dispersive delta refraction after the sample), and so does every connection that uses a
//! vertex of it: a connection is [`hero_only`] when either subpath dropped its companions.
//!
//! **The image.** The connections with t ≥ 2 add to the camera sample's own pixel, weighted by
//! the reconstruction filter as a camera sample's estimate is (the one-pixel reconstruction,
//! whatever the film's `reconstruction` asks); those with t = 1 are splatted through the
//! filter. The render runs it as the particle tracer's passes ([`crate::render`]): one sample
//! per pixel of the full film per sample index, the sums exact, the variance by batch means.
//!
//! Surfaces only: scenes with participating media, lights at infinity, spot lights and
//! projectors are refused when read.

pub mod weights;

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use crate::bsdf::BxdfTree;
use crate::camera::{Camera, CameraModel};
use crate::geometry::SurfaceInteraction;
use crate::geometry::offset::offset_ray_origin;
use crate::integrator::adjoint::shading_correction;
use crate::integrator::vertex::{
    hero_only, russian_roulette, surface_scattering, wavelengths_after,
};
use crate::integrator::{LightPathSample, SampleContext, Splat};
use crate::light::{Light, LightQuery, LightSource, Receiver};
use crate::math::{Frame, Ray};
use crate::sampling::warp::{sample_cosine_hemisphere, sample_uniform_sphere, uniform_sphere_pdf};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::world::World;
use weights::{MisVertex, mis_weight};

#[derive(Clone, Debug)]
pub struct BdptIntegrator {
    /// Longest path in segments (Mitsuba's depth); negative for unbounded.
    pub max_depth: i32,
    /// Bounces of a subpath after which Russian roulette is used.
    pub rr_depth: i32,
    /// Whether emitters seen directly by the camera are left black.
    pub hide_emitters: bool,
    /// Whether the strategies t = 1 (light subpaths connected to the camera) are used.
    pub light_image: bool,
    /// Whether s = 1 samples a light at the camera vertex (rather than connecting y₀).
    pub sample_direct: bool,
}

impl Default for BdptIntegrator {
    fn default() -> Self {
        BdptIntegrator {
            max_depth: -1,
            rr_depth: 5,
            hide_emitters: false,
            light_image: true,
            sample_direct: true,
        }
    }
}

/// Where a vertex lies.
#[derive(Clone, Copy, Debug)]
enum Point {
    /// The camera, at the lens point drawn with `u_lens`.
    Camera { p: Vec3, u_lens: Vec2 },
    /// A point of light `light`: `n` its geometric normal (zero for a point light), `shading_n`
    /// and `uv` what its radiance is looked up with.
    Light {
        light: u32,
        p: Vec3,
        n: Vec3,
        shading_n: Vec3,
        uv: Vec2,
    },
    /// A surface the subpath scattered at.
    Surface(SurfaceInteraction),
}

/// A vertex of a subpath.
#[derive(Clone, Copy, Debug)]
struct Vertex {
    point: Point,
    /// The unit direction towards the previous vertex of its subpath (zero at its start).
    wo: Vec3,
    /// The subpath's throughput on arriving here.
    beta: SampledSpectrum,
    /// The subpath's wavelengths once it has scattered here.
    lambda: SampledWavelengths,
    /// Density per unit area of this vertex drawn by its own subpath.
    pdf_fwd: f32,
    /// Density per unit area of this vertex drawn by the other subpath.
    pdf_rev: f32,
    /// Whether the subpath left this vertex by a delta lobe.
    delta: bool,
    /// Whether this is a point light's vertex.
    delta_light: bool,
}

impl Vertex {
    fn p(&self) -> Vec3 {
        match &self.point {
            Point::Camera { p, .. } | Point::Light { p, .. } => *p,
            Point::Surface(si) => si.p,
        }
    }

    /// The geometric normal, zero for a point (the camera, a point light).
    fn ng(&self) -> Vec3 {
        match &self.point {
            Point::Camera { .. } => Vec3::ZERO,
            Point::Light { n, .. } => *n,
            Point::Surface(si) => si.n,
        }
    }

    fn mis(&self) -> MisVertex {
        MisVertex {
            pdf_fwd: self.pdf_fwd,
            pdf_rev: self.pdf_rev,
            delta: self.delta,
            delta_light: self.delta_light,
        }
    }
}

/// A density per unit solid angle at `from` of the direction towards `to`, as a density per unit
/// area at `to`: times |cos θ_to| / r² (1/r² for a point).
fn to_area(pdf: f32, from: Vec3, to: &Vertex) -> f32 {
    let d = to.p() - from;
    let r2 = d.length_squared();
    if !(r2 > 0.0) {
        return 0.0;
    }
    let n = to.ng();
    let cos = if n == Vec3::ZERO {
        1.0
    } else {
        n.dot(d).abs() / r2.sqrt()
    };
    pdf * cos / r2
}

/// The unit direction from `from` to `to`, and the squared distance.
fn direction(from: Vec3, to: Vec3) -> Option<(Vec3, f32)> {
    let d = to - from;
    let r2 = d.length_squared();
    (r2 > 0.0 && r2.is_finite()).then(|| (d / r2.sqrt(), r2))
}

/// What the strategies of one sample share.
struct Connections<'a> {
    world: &'a World,
    camera: &'a Camera,
    time: f32,
}

impl Connections<'_> {
    /// The density per unit area with which a subpath at vertex `v`, arrived from `prev`,
    /// draws `next` (pbrt's `Vertex::PDF`).
    fn pdf(&self, v: &Vertex, prev: Option<&Vertex>, next: &Vertex) -> f32 {
        match &v.point {
            Point::Camera { u_lens, .. } => self.camera_pdf(*u_lens, next),
            Point::Light { .. } => self.emission_pdf(v, next),
            Point::Surface(si) => {
                let Some(prev) = prev else {
                    return 0.0;
                };
                let (Some((wo, _)), Some((wi, _))) =
                    (direction(si.p, prev.p()), direction(si.p, next.p()))
                else {
                    return 0.0;
                };
                let mut lobes = BxdfTree::empty();
                let scattering = self
                    .world
                    .material(si)
                    .scattering(si, wo, &v.lambda, &mut lobes);
                to_area(scattering.eval(wi).pdf, si.p, next)
            }
        }
    }

    /// The density per unit area at `to` of the camera's ray through the lens point drawn with
    /// `u_lens`: the importance's weight 1/(A cos³θ r²) is the density per unit solid angle
    /// over r² (per unit area of the film for an orthographic camera), times |cos θ_to|.
    fn camera_pdf(&self, u_lens: Vec2, to: &Vertex) -> f32 {
        let Some(importance) = self.camera.sample_importance(to.p(), u_lens, self.time) else {
            return 0.0;
        };
        let n = to.ng();
        let cos = if n == Vec3::ZERO {
            1.0
        } else {
            n.dot(importance.wi).abs()
        };
        importance.weight * cos
    }

    /// The density per unit area at `to` of the emission from the light vertex (or the point
    /// of an area light) `v`: |cos θ| / π about the normal of an area light, 1/4π for a point.
    fn emission_pdf(&self, v: &Vertex, to: &Vertex) -> f32 {
        let (Some((w, _)), Point::Light { light, n, .. }) = (direction(v.p(), to.p()), &v.point)
        else {
            return 0.0;
        };
        let pdf = match &self.world.lights[*light as usize] {
            Light::Area(_) => n.dot(w).abs() / PI,
            Light::Point(_) => uniform_sphere_pdf(),
            _ => 0.0,
        };
        to_area(pdf, v.p(), to)
    }

    /// The radiance (intensity, for a point light) that the light vertex `v` sends along `w`,
    /// times the cosine at the light.
    fn emission_towards(&self, v: &Vertex, w: Vec3) -> SampledSpectrum {
        let Point::Light {
            light,
            n,
            shading_n,
            uv,
            ..
        } = &v.point
        else {
            return SampledSpectrum::ZERO;
        };
        match &self.world.lights[*light as usize] {
            Light::Area(area) => area.emitted(*uv, *shading_n, w, &v.lambda) * n.dot(w).abs(),
            Light::Point(point) => point.intensity.sample(&v.lambda),
            _ => SampledSpectrum::ZERO,
        }
    }

    /// What the camera-side vertex `v` (a surface, arrived at from `v.wo`) passes on from light
    /// arriving along `w`: f(wo, w) |cos θ_w|.
    fn camera_side(&self, v: &Vertex, w: Vec3) -> SampledSpectrum {
        let Point::Surface(si) = &v.point else {
            return SampledSpectrum::ZERO;
        };
        let mut lobes = BxdfTree::empty();
        let scattering = self
            .world
            .material(si)
            .scattering(si, v.wo, &v.lambda, &mut lobes);
        scattering.eval(w).value
    }

    /// What the light-side vertex `v` (a surface whose light arrives from `v.wo`) sends along
    /// `w`: f(w, wo) |cos θ_wo| with the adjoint's shading-normal factor |cos_g θ_w| / |cos_g
    /// θ_wo| (Veach's eq. 5.19, evaluated from the side the light leaves to, so that it holds
    /// across refractions too).
    fn light_side(&self, v: &Vertex, w: Vec3) -> SampledSpectrum {
        let Point::Surface(si) = &v.point else {
            return self.emission_towards(v, w);
        };
        let mut lobes = BxdfTree::empty();
        let scattering = self
            .world
            .material(si)
            .scattering(si, w, &v.lambda, &mut lobes);
        let factor = si.n.dot(w).abs() / si.n.dot(v.wo).abs();
        if !factor.is_finite() {
            return SampledSpectrum::ZERO;
        }
        scattering.eval(v.wo).value * factor
    }

    /// The density with which the light subpath starts at the point of light `light`: the
    /// probability of choosing the light by power times 1/A (1 for a point light).
    fn light_origin_pdf(&self, ctx: &SampleContext, light: u32) -> f32 {
        let choice = ctx
            .light_sampler()
            .pmf(light as usize, &Receiver::point(Vec3::ZERO));
        match &self.world.lights[light as usize] {
            Light::Area(area) => {
                let area = self.world.geometry.primitives[area.shape as usize].area();
                if area > 0.0 { choice / area } else { 0.0 }
            }
            Light::Point(_) => choice,
            _ => 0.0,
        }
    }

    /// The weight of strategy (s, t) for the subpaths `light` and `camera`, with `sampled`
    /// standing for the connection vertex a strategy s = 1 or t = 1 drew itself.
    #[allow(clippy::too_many_arguments)]
    fn weight(
        &self,
        ctx: &SampleContext,
        camera: &[Vertex],
        light: &[Vertex],
        s: usize,
        t: usize,
        sampled: Option<&Vertex>,
        light_image: bool,
    ) -> f32 {
        let mut camera_mis: Vec<MisVertex> = camera[..t].iter().map(Vertex::mis).collect();
        let mut light_mis: Vec<MisVertex> = light[..s].iter().map(Vertex::mis).collect();
        let pt = match (t, sampled) {
            (1, Some(v)) => v,
            _ => &camera[t - 1],
        };
        let qs = match (s, sampled) {
            (1, Some(v)) if t > 1 => Some(v),
            (0, _) => None,
            _ => Some(&light[s - 1]),
        };
        if let (1, Some(v)) = (s, qs) {
            light_mis[0] = v.mis();
        }
        let pt_minus = (t >= 2).then(|| &camera[t - 2]);
        let qs_minus = (s >= 2).then(|| &light[s - 2]);
        camera_mis[t - 1].delta = false;
        if s > 0 {
            light_mis[s - 1].delta = false;
        }
        match qs {
            Some(qs) => {
                camera_mis[t - 1].pdf_rev = self.pdf(qs, qs_minus, pt);
                if let Some(pt_minus) = pt_minus {
                    camera_mis[t - 2].pdf_rev = self.pdf(pt, Some(qs), pt_minus);
                }
                light_mis[s - 1].pdf_rev = self.pdf(pt, pt_minus, qs);
                if let Some(qs_minus) = qs_minus {
                    light_mis[s - 2].pdf_rev = self.pdf(qs, Some(pt), qs_minus);
                }
            }
            None => {
                // The camera subpath found a light: its last vertex as the light's point.
                let Some(as_light) = self.as_light(pt) else {
                    return 0.0;
                };
                camera_mis[t - 1].pdf_rev = match as_light.point {
                    Point::Light { light, .. } => self.light_origin_pdf(ctx, light),
                    _ => 0.0,
                };
                if let Some(pt_minus) = pt_minus {
                    camera_mis[t - 2].pdf_rev = self.emission_pdf(&as_light, pt_minus);
                }
            }
        }
        mis_weight(&camera_mis, &light_mis, light_image)
    }

    /// The camera subpath's vertex `v` on an area light, as a vertex of that light.
    fn as_light(&self, v: &Vertex) -> Option<Vertex> {
        let Point::Surface(si) = &v.point else {
            return None;
        };
        let light = self.world.shape_info[si.shape as usize].light?;
        Some(Vertex {
            point: Point::Light {
                light,
                p: si.p,
                n: si.n,
                shading_n: si.shading.n,
                uv: si.uv,
            },
            ..*v
        })
    }
}

/// A subpath's way on: whether it carries importance (the light subpath, sampling the adjoint
/// BSDF) and how many vertices it may have.
struct Walk {
    adjoint: bool,
    max_vertices: usize,
    rr_depth: i32,
}

impl Walk {
    /// Extends `path` (its start already in it) along `ray`, whose direction the start drew
    /// with density `pdf_dir` per unit solid angle, with throughput `beta` and wavelengths
    /// `lambda` (pbrt's `RandomWalk`).
    fn extend(
        &self,
        ctx: &mut SampleContext,
        mut ray: Ray,
        mut beta: SampledSpectrum,
        mut pdf_dir: f32,
        mut lambda: SampledWavelengths,
        path: &mut Vec<Vertex>,
    ) {
        let world = ctx.world();
        let mut lobes = BxdfTree::empty();
        let mut reverse_lobes = BxdfTree::empty();
        let mut eta_scale = 1.0f32;
        let mut bounces = 0i32;
        while path.len() < self.max_vertices {
            let Some(si) = ctx.intersect(&ray) else {
                break;
            };
            let wo = -ray.d.normalize();
            let scattering = surface_scattering(world, &si, wo, &mut lambda, &mut lobes);
            let mut vertex = Vertex {
                point: Point::Surface(si),
                wo,
                beta,
                lambda,
                pdf_fwd: 0.0,
                pdf_rev: 0.0,
                delta: false,
                delta_light: false,
            };
            let previous = path.len() - 1;
            vertex.pdf_fwd = to_area(pdf_dir, path[previous].p(), &vertex);
            path.push(vertex);
            if path.len() >= self.max_vertices {
                break;
            }
            let u_lobe = ctx.sampler.next_1d();
            let u = ctx.sampler.next_2d();
            let Some(bs) = scattering.sample(u_lobe, u) else {
                break;
            };
            let mut weight = bs.weight;
            if self.adjoint {
                let Some(correction) = shading_correction(&si, wo, bs.wi) else {
                    break;
                };
                weight *= correction * bs.eta * bs.eta;
            }
            let (mut fwd, mut rev) = (bs.pdf, 0.0);
            if bs.flags.is_delta() {
                path[previous + 1].delta = true;
                fwd = 0.0;
            } else {
                rev = world
                    .material(&si)
                    .scattering(&si, bs.wi, &lambda, &mut reverse_lobes)
                    .eval(wo)
                    .pdf;
            }
            path[previous].pdf_rev = to_area(rev, si.p, &path[previous]);
            lambda = wavelengths_after(&lambda, &bs);
            beta *= weight;
            eta_scale *= bs.eta;
            if beta.is_black() {
                break;
            }
            ray = si.spawn_ray(bs.wi);
            pdf_dir = fwd;
            bounces += 1;
            if bounces >= self.rr_depth {
                let Some(factor) = russian_roulette(ctx, beta, eta_scale) else {
                    break;
                };
                beta *= factor;
            }
        }
    }
}

impl BdptIntegrator {
    /// The most vertices of a camera subpath and of a light subpath.
    fn max_vertices(&self) -> (usize, usize) {
        if self.max_depth < 0 {
            (usize::MAX, usize::MAX)
        } else {
            let depth = self.max_depth as usize;
            (depth + 1, depth)
        }
    }

    /// Traces one sample: the camera subpath along `ray` (drawn with the lens sample
    /// `sample.u_lens`) and a light subpath, and every connection between them. Returns the
    /// estimate of the strategies t ≥ 2 for the camera sample's pixel; those of t = 1 go to
    /// `out`.
    pub fn sample(
        &self,
        ctx: &mut SampleContext,
        sample: &LightPathSample,
        ray: Ray,
        out: &mut impl Splat,
    ) -> SampledSpectrum {
        let mut result = SampledSpectrum::ZERO;
        if self.max_depth == 0 {
            return result;
        }
        let (camera_max, light_max) = self.max_vertices();
        let camera = self.camera_subpath(ctx, sample, ray, camera_max);
        let light = self.light_subpath(ctx, sample, light_max);
        let connections = Connections {
            world: ctx.world(),
            camera: sample.camera,
            time: sample.time,
        };
        for t in 1..=camera.len() {
            for s in 0..=light.len() {
                let depth = s + t - 1;
                if s + t < 2
                    || (s == 1 && t == 1)
                    || (self.max_depth >= 0 && depth > self.max_depth as usize)
                    || (t == 1 && !self.light_image)
                    || (s == 0 && t == 2 && self.hide_emitters)
                {
                    continue;
                }
                result += self.connect(ctx, &connections, sample, &camera, &light, s, t, out);
            }
        }
        result
    }

    /// The camera subpath: the lens point and the vertices along `ray`.
    fn camera_subpath(
        &self,
        ctx: &mut SampleContext,
        sample: &LightPathSample,
        ray: Ray,
        max_vertices: usize,
    ) -> Vec<Vertex> {
        let mut path = vec![Vertex {
            point: Point::Camera {
                p: ray.o,
                u_lens: sample.u_lens,
            },
            wo: Vec3::ZERO,
            beta: SampledSpectrum::ONE,
            lambda: *sample.lambda,
            pdf_fwd: 1.0,
            pdf_rev: 0.0,
            delta: false,
            delta_light: false,
        }];
        let walk = Walk {
            adjoint: false,
            max_vertices,
            rr_depth: self.rr_depth,
        };
        walk.extend(
            ctx,
            ray,
            SampledSpectrum::ONE,
            0.0,
            *sample.lambda,
            &mut path,
        );
        if path.len() > 1 {
            let connections = Connections {
                world: ctx.world(),
                camera: sample.camera,
                time: sample.time,
            };
            path[1].pdf_fwd = connections.camera_pdf(sample.u_lens, &path[1]);
        }
        path
    }

    /// The light subpath: a light chosen by power, a point and a direction of its emission, and
    /// the vertices along that ray.
    fn light_subpath(
        &self,
        ctx: &mut SampleContext,
        sample: &LightPathSample,
        max_vertices: usize,
    ) -> Vec<Vertex> {
        let mut path = Vec::new();
        let world = ctx.world();
        let u_light = ctx.sampler.next_1d();
        let u_choice = ctx.sampler.next_1d();
        let u_position = ctx.sampler.next_2d();
        let u_direction = ctx.sampler.next_2d();
        if max_vertices == 0 {
            return path;
        }
        let Some((index, choice)) = ctx
            .light_sampler()
            .sample(u_light, &Receiver::point(Vec3::ZERO))
        else {
            return path;
        };
        let lambda = *sample.lambda;
        let connections = Connections {
            world,
            camera: sample.camera,
            time: sample.time,
        };
        let (start, d, pdf_dir, position_pdf) = match &world.lights[index] {
            Light::Area(area) => {
                let Some(s) = area.sample_position(
                    &world.geometry.primitives,
                    sample.time,
                    u_choice,
                    u_position,
                ) else {
                    return path;
                };
                // Cosine-distributed about the side of the geometric normal that emits.
                let side = if s.n.dot(s.shading_n) >= 0.0 {
                    s.n
                } else {
                    -s.n
                };
                let local = sample_cosine_hemisphere(u_direction);
                if !(local.z > 0.0) {
                    return path;
                }
                let d = Frame::from_normal(side).to_world(local);
                let point = Point::Light {
                    light: index as u32,
                    p: s.p,
                    n: s.n,
                    shading_n: s.shading_n,
                    uv: s.uv,
                };
                (point, d, local.z / PI, s.pdf)
            }
            Light::Point(point) => {
                let d = sample_uniform_sphere(u_direction);
                let point = Point::Light {
                    light: index as u32,
                    p: point.position,
                    n: Vec3::ZERO,
                    shading_n: Vec3::ZERO,
                    uv: Vec2::ZERO,
                };
                (point, d, uniform_sphere_pdf(), 1.0)
            }
            _ => return path,
        };
        let mut y0 = Vertex {
            point: start,
            wo: Vec3::ZERO,
            beta: SampledSpectrum::splat(1.0 / (choice * position_pdf)),
            lambda,
            pdf_fwd: 0.0,
            pdf_rev: 0.0,
            delta: false,
            delta_light: matches!(world.lights[index], Light::Point(_)),
        };
        y0.pdf_fwd = connections.light_origin_pdf(ctx, index as u32);
        let emitted = connections.emission_towards(&y0, d);
        path.push(y0);
        let beta = y0.beta * emitted * (1.0 / pdf_dir);
        if beta.is_black() || !beta.max_value().is_finite() {
            return path;
        }
        let origin = match y0.ng() {
            n if n == Vec3::ZERO => y0.p(),
            n => offset_ray_origin(y0.p(), if d.dot(n) >= 0.0 { n } else { -n }),
        };
        let walk = Walk {
            adjoint: true,
            max_vertices,
            rr_depth: self.rr_depth,
        };
        let ray = Ray::new(origin, d, f32::INFINITY, sample.time);
        walk.extend(ctx, ray, beta, pdf_dir, lambda, &mut path);
        path
    }

    /// Strategy (s, t): its weighted contribution to the camera sample's pixel, or, for t = 1,
    /// its splat (see the module's text).
    #[allow(clippy::too_many_arguments)]
    fn connect(
        &self,
        ctx: &mut SampleContext,
        connections: &Connections,
        sample: &LightPathSample,
        camera: &[Vertex],
        light: &[Vertex],
        s: usize,
        t: usize,
        out: &mut impl Splat,
    ) -> SampledSpectrum {
        let world = ctx.world();
        let started = sample.lambda;
        // The estimate for the sample's wavelengths of a path whose ends have wavelengths `a`
        // and `b`.
        let estimate = |value: SampledSpectrum, a: &SampledWavelengths, b: &SampledWavelengths| {
            if !started.secondary_terminated()
                && (a.secondary_terminated() || b.secondary_terminated())
            {
                hero_only(value)
            } else {
                value
            }
        };
        if s == 0 {
            let pt = &camera[t - 1];
            let Some(as_light) = connections.as_light(pt) else {
                return SampledSpectrum::ZERO;
            };
            let Point::Light {
                light: index,
                shading_n,
                uv,
                ..
            } = as_light.point
            else {
                return SampledSpectrum::ZERO;
            };
            let Light::Area(area) = &world.lights[index as usize] else {
                return SampledSpectrum::ZERO;
            };
            let value = pt.beta * area.emitted(uv, shading_n, pt.wo, &pt.lambda);
            if value.is_black() {
                return SampledSpectrum::ZERO;
            }
            let weight = connections.weight(ctx, camera, light, 0, t, None, self.light_image);
            return estimate(value * weight, &pt.lambda, &pt.lambda);
        }
        if t == 1 {
            let qs = &light[s - 1];
            let u_lens = ctx.sampler.next_2d();
            let Point::Surface(si) = &qs.point else {
                return SampledSpectrum::ZERO;
            };
            let Some(importance) = sample.camera.sample_importance(si.p, u_lens, sample.time)
            else {
                return SampledSpectrum::ZERO;
            };
            if !out.reaches(importance.film) {
                return SampledSpectrum::ZERO;
            }
            let value = qs.beta * connections.light_side(qs, importance.wi) * importance.weight;
            if value.is_black() || ctx.occluded(&si.spawn_ray_to(importance.p, Vec3::ZERO)) {
                return SampledSpectrum::ZERO;
            }
            let lens = Vertex {
                point: Point::Camera {
                    p: importance.p,
                    u_lens,
                },
                ..camera[0]
            };
            let weight =
                connections.weight(ctx, camera, light, s, 1, Some(&lens), self.light_image);
            out.splat(
                importance.film,
                estimate(value * weight, &qs.lambda, &qs.lambda),
            );
            return SampledSpectrum::ZERO;
        }
        let pt = &camera[t - 1];
        let Point::Surface(pt_si) = &pt.point else {
            return SampledSpectrum::ZERO;
        };
        if s == 1 && self.sample_direct {
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
                reference: pt_si.p,
                time: sample.time,
                u_choice,
                u,
                lambda: &pt.lambda,
            }) else {
                return SampledSpectrum::ZERO;
            };
            if !(ls.pdf > 0.0) {
                return SampledSpectrum::ZERO;
            }
            let value = pt.beta
                * connections.camera_side(pt, ls.wi)
                * ls.radiance
                * (1.0 / (choice * ls.pdf));
            if value.is_black() || ctx.occluded(&pt_si.spawn_ray_to(ls.p, ls.n)) {
                return SampledSpectrum::ZERO;
            }
            let sampled = Vertex {
                point: Point::Light {
                    light: index as u32,
                    p: ls.p,
                    n: ls.n,
                    shading_n: ls.n,
                    uv: Vec2::ZERO,
                },
                wo: Vec3::ZERO,
                beta: SampledSpectrum::ONE,
                lambda: pt.lambda,
                pdf_fwd: connections.light_origin_pdf(ctx, index as u32),
                pdf_rev: 0.0,
                delta: false,
                delta_light: ls.is_delta,
            };
            let weight =
                connections.weight(ctx, camera, light, 1, t, Some(&sampled), self.light_image);
            return estimate(value * weight, &pt.lambda, &pt.lambda);
        }
        let qs = &light[s - 1];
        let Some((w, r2)) = direction(pt_si.p, qs.p()) else {
            return SampledSpectrum::ZERO;
        };
        let value = pt.beta
            * connections.camera_side(pt, w)
            * connections.light_side(qs, -w)
            * qs.beta
            * (1.0 / r2);
        if value.is_black() || ctx.occluded(&pt_si.spawn_ray_to(qs.p(), qs.ng())) {
            return SampledSpectrum::ZERO;
        }
        let weight = connections.weight(ctx, camera, light, s, t, None, self.light_image);
        estimate(value * weight, &pt.lambda, &qs.lambda)
    }
}
