//! The volumetric path tracer (Mitsuba 3's `volpath`): the path tracer of [`super::path`] with
//! participating media between the surfaces.
//!
//! ```xml
//! <integrator type="volpath">
//!     <integer name="max_depth" value="-1"/>
//!     <integer name="rr_depth" value="5"/>
//!     <boolean name="hide_emitters" value="false"/>
//! </integrator>
//! ```
//!
//! Each segment of a path that runs through a medium is tracked with one majorant for the
//! path's four wavelengths ([`crate::medium`], spectral tracking): null collisions fly on, a
//! real collision scatters by the medium's phase function. At surfaces the path behaves as in
//! `path`. A scattering vertex in a medium samples a light (when the medium's
//! `sample_emitters` is set) and the phase function, and the two are combined by multiple
//! importance sampling with the power heuristic on their solid-angle densities, exactly as a
//! BSDF and a light are at a surface (Mitsuba's volpath does the same). Shadow rays carry the
//! transmittance of every medium they cross (closed form for homogeneous media, ratio tracking
//! for heterogeneous ones) and pass through index-matched boundaries (`null` BSDFs); any other
//! surface blocks them.
//!
//! * Media change where a path crosses a shape that names an `interior` or `exterior`
//!   medium: the medium on the side the path leaves to; shapes that name none leave it as it
//!   is. The camera sits in the sensor's medium.
//! * A `null` surface is not a bounce: the path crosses it without changing direction, depth,
//!   or the vertex its MIS weights refer to (Mitsuba's treatment of null-BSDF interactions).
//! * Depth counts surface and medium scattering vertices; a path of depth d has d bounces,
//!   `max_depth` as in `path`. Russian roulette on the path's potential (throughput times η²)
//!   starts after `rr_depth` bounces (depth > rr_depth, as Mitsuba's volpath).
//! * Chromatic media keep all four wavelengths unbiased (see [`crate::medium`] for why one
//!   majorant over the four rather than hero-wavelength tracking).
//!
//! The path loop below is shared with `volpathmis` ([`super::volpathmis`]): what differs is how
//! free flights are drawn and how the path's weights and its estimate are kept, the
//! [`PathWeights`] of each ([`SpectralTracking`] here).

use glam::Vec3;

use crate::bsdf::{BxdfTree, Scattering};
use crate::geometry::interaction::SHADOW_EPSILON;
use crate::geometry::offset::offset_ray_origin;
use crate::geometry::{SurfaceInteraction, SurfaceSample};
use crate::integrator::mis::power_heuristic;
use crate::integrator::{PreparedIntegrator, RayCount, hero_only};
use crate::light::{Light, LightSample, LightSelection, Receiver};
use crate::math::Ray;
use crate::medium::{Collision, Medium, PhaseFunction, choose_collision, sample_free_flight};
use crate::sampling::sampler::Sampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::world::World;

#[derive(Clone, Debug)]
pub struct VolPathIntegrator {
    /// Longest path in vertices after the camera; negative for unbounded.
    pub max_depth: i32,
    /// Bounces after which Russian roulette is used.
    pub rr_depth: i32,
    /// Whether emitters seen directly by the camera are left black.
    pub hide_emitters: bool,
    /// How one light is chosen for each light sample.
    pub light_selection: LightSelection,
    /// How free flights are drawn and weighted: `volpath` or `volpathmis`.
    pub tracking: Tracking,
}

impl Default for VolPathIntegrator {
    fn default() -> Self {
        VolPathIntegrator {
            max_depth: -1,
            rr_depth: 5,
            hide_emitters: false,
            light_selection: LightSelection::Exhaustive,
            tracking: Tracking::Spectral,
        }
    }
}

/// The two volumetric path tracers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tracking {
    /// `volpath`: spectral tracking with one majorant for the four wavelengths, light and
    /// directional samples combined by the power heuristic.
    Spectral,
    /// `volpathmis`: the hero wavelength's free flights, and the balance heuristic over the
    /// light and directional samples and (with `spectral_mis`, Mitsuba's default) over the
    /// four wavelengths' densities ([`super::volpathmis`]).
    HeroMis { spectral_mis: bool },
}

/// What a volumetric path keeps besides its geometry: its weights, the state its MIS weights
/// need, and the estimate it sums. The loop in [`VolPathIntegrator`] calls these at each event.
pub(super) trait PathWeights {
    /// The factor by which the path's further contributions are weighted (before MIS against
    /// light samples): Russian roulette and termination look at it.
    fn throughput(&self) -> SampledSpectrum;

    /// Multiplies the path's weight by `factor` (Russian roulette's 1/survival).
    fn scale(&mut self, factor: f32);

    /// Tracks the path along `ray` (unit direction) through `medium` up to the surface at
    /// `t_surface`: the distance of a real collision, or `None` when the path reaches the
    /// surface (or leaves the medium's extent) first.
    fn free_flight(
        &mut self,
        medium: &Medium,
        ray: &Ray,
        t_surface: f32,
        lambda: &SampledWavelengths,
        sampler: &mut Sampler,
    ) -> Option<f32>;

    /// A directional sample at a scattering vertex: value over density `weight`, solid-angle
    /// density `pdf`; `unweighted` when no light sample could have found what it finds (a
    /// delta lobe, or a medium without `sample_emitters`), whose emission then counts in full.
    fn scatter(&mut self, weight: SampledSpectrum, pdf: f32, unweighted: bool);

    /// Whether emission found next is weighted against light sampling (so its light density
    /// is needed).
    fn weights_emission(&self) -> bool;

    /// Adds emitted radiance `emitted` found by the path, which light sampling from the last
    /// vertex finds with solid-angle density `light_pdf` (ignored when unweighted).
    fn add_emission(&mut self, emitted: SampledSpectrum, light_pdf: f32);

    /// Adds a light sample taken at the path's current vertex.
    fn add_light_sample(&mut self, sample: &LightSampleTerms);

    /// The path's estimate for the caller's wavelengths; `lambda_was_whole` when the path
    /// started with all four.
    fn estimate(&self, lambda: &SampledWavelengths, lambda_was_whole: bool) -> SampledSpectrum;
}

/// The factors of one light sample at a vertex: the BSDF's or phase function's value towards
/// the light, the solid-angle densities of sampling that direction by the vertex and by the
/// light (the light's choice included), the transmittance of the shadow ray and the radiance.
pub(super) struct LightSampleTerms {
    pub value: SampledSpectrum,
    pub direction_pdf: f32,
    pub light_pdf: f32,
    pub is_delta: bool,
    pub transmittance: SampledSpectrum,
    pub radiance: SampledSpectrum,
}

/// `volpath`'s weights: the throughput of spectral tracking and the density of the last
/// directional sample, for the power heuristic against light samples.
pub(super) struct SpectralTracking {
    throughput: SampledSpectrum,
    /// Solid-angle density of the last directional sample.
    pdf: f32,
    unweighted: bool,
    result: SampledSpectrum,
}

impl SpectralTracking {
    pub(super) fn new() -> Self {
        SpectralTracking {
            throughput: SampledSpectrum::ONE,
            pdf: 0.0,
            unweighted: true,
            result: SampledSpectrum::ZERO,
        }
    }
}

impl PathWeights for SpectralTracking {
    #[inline]
    fn throughput(&self) -> SampledSpectrum {
        self.throughput
    }

    #[inline]
    fn scale(&mut self, factor: f32) {
        self.throughput *= factor;
    }

    #[inline]
    fn free_flight(
        &mut self,
        medium: &Medium,
        ray: &Ray,
        t_surface: f32,
        lambda: &SampledWavelengths,
        sampler: &mut Sampler,
    ) -> Option<f32> {
        spectral_tracking(
            medium,
            ray,
            t_surface,
            lambda,
            &mut self.throughput,
            sampler,
        )
    }

    #[inline]
    fn scatter(&mut self, weight: SampledSpectrum, pdf: f32, unweighted: bool) {
        self.throughput *= weight;
        self.pdf = pdf;
        self.unweighted = unweighted;
    }

    #[inline]
    fn weights_emission(&self) -> bool {
        !self.unweighted
    }

    #[inline]
    fn add_emission(&mut self, emitted: SampledSpectrum, light_pdf: f32) {
        let weight = if self.unweighted {
            1.0
        } else {
            power_heuristic(self.pdf, light_pdf)
        };
        self.result += self.throughput * emitted * weight;
    }

    /// f·Tr·L·w / p_light, w the power heuristic against the directional density.
    #[inline]
    fn add_light_sample(&mut self, s: &LightSampleTerms) {
        let weight = if s.is_delta {
            1.0
        } else {
            power_heuristic(s.light_pdf, s.direction_pdf)
        };
        self.result +=
            self.throughput * s.value * s.transmittance * s.radiance * (weight / s.light_pdf);
    }

    #[inline]
    fn estimate(&self, lambda: &SampledWavelengths, lambda_was_whole: bool) -> SampledSpectrum {
        if lambda_was_whole && lambda.secondary_terminated() {
            hero_only(self.result)
        } else {
            self.result
        }
    }
}

/// The medium a ray leaving `si` in direction `d` travels in, when it was in `current`.
#[inline]
pub(super) fn medium_after(
    world: &World,
    si: &SurfaceInteraction,
    d: Vec3,
    current: Option<u32>,
) -> Option<u32> {
    let interface = world.medium_interface(si.shape);
    if interface.is_transition() {
        interface.target(si.n, d)
    } else {
        current
    }
}

/// The throughput of the wavelengths that still count: the hero alone once the companions
/// have been dropped at a dispersive interface.
#[inline]
fn counted(throughput: SampledSpectrum, lambda: &SampledWavelengths) -> SampledSpectrum {
    if lambda.secondary_terminated() {
        let mut hero = SampledSpectrum::ZERO;
        hero[0] = throughput[0];
        hero
    } else {
        throughput
    }
}

/// Spectral tracking along `ray` (unit direction) in `medium` up to the surface at `t_surface`:
/// the distance of a real collision, or `None` when the path reaches the surface (or leaves
/// the medium's extent) first. The throughput is multiplied by each event's weight.
#[inline]
fn spectral_tracking(
    medium: &Medium,
    ray: &Ray,
    t_surface: f32,
    lambda: &SampledWavelengths,
    throughput: &mut SampledSpectrum,
    sampler: &mut Sampler,
) -> Option<f32> {
    let (t0, t1) = medium.ray_extent(ray, t_surface)?;
    let majorant = medium.majorant(lambda);
    let mut t = t0;
    loop {
        t = sample_free_flight(t, t1, majorant, sampler.next_1d())?;
        let c = medium.coefficients(ray.at(t), lambda);
        match choose_collision(
            counted(*throughput, lambda),
            &c,
            majorant,
            sampler.next_1d(),
        ) {
            Collision::Real(weight) => {
                *throughput *= weight;
                return Some(t);
            }
            Collision::Null(weight) => {
                *throughput *= weight;
                if throughput.is_black() {
                    return None;
                }
            }
        }
    }
}

/// The transmittance from `origin` to `end` for a path in `medium` at `origin`: the product of
/// the transmittances of the media crossed, through index-matched (`null`) boundaries; zero
/// when another surface is in the way.
#[allow(clippy::too_many_arguments)] // the segment, its medium and the path's state
fn shadow_transmittance(
    world: &World,
    origin: Vec3,
    end: Vec3,
    time: f32,
    mut medium: Option<u32>,
    lambda: &SampledWavelengths,
    sampler: &mut Sampler,
    count: &mut RayCount,
) -> SampledSpectrum {
    let d = (end - origin).normalize();
    let mut o = origin;
    let mut transmittance = SampledSpectrum::ONE;
    loop {
        let remaining = (end - o).dot(d);
        if !(remaining > 0.0) {
            return transmittance;
        }
        count.rays += 1;
        let segment = Ray::new(o, d, remaining, time);
        let hit = world.geometry.intersect(&segment);
        if let Some(m) = medium {
            let t = hit.map_or(remaining, |si| si.t);
            transmittance *=
                world.media[m as usize].transmittance(&segment, t, lambda, || sampler.next_1d());
            if transmittance.is_black() {
                return transmittance;
            }
        }
        let Some(si) = hit else {
            return transmittance;
        };
        let info = world.shape_info[si.shape as usize];
        if !world.materials[info.material as usize].is_null() {
            return SampledSpectrum::ZERO;
        }
        medium = medium_after(world, &si, d, medium);
        o = si.spawn_ray(d).o;
    }
}

/// Where a shadow ray towards light sample `ls` ends: just off the light's surface, short of
/// it by the shadow epsilon.
#[inline]
fn shadow_end(origin: Vec3, ls: &LightSample) -> Vec3 {
    let target = if ls.n == Vec3::ZERO {
        ls.p
    } else {
        let m = if (ls.p - origin).dot(ls.n) <= 0.0 {
            ls.n
        } else {
            -ls.n
        };
        offset_ray_origin(ls.p, m)
    };
    origin + (target - origin) * (1.0 - SHADOW_EPSILON)
}

impl VolPathIntegrator {
    fn depth_allows_next_vertex(&self, depth: i32) -> bool {
        self.max_depth < 0 || depth + 1 < self.max_depth
    }

    /// The path loop of both volumetric path tracers, keeping the path's weights in `weights`.
    pub(super) fn trace<W: PathWeights>(
        &self,
        mut weights: W,
        prepared: &PreparedIntegrator,
        camera_ray: Ray,
        wavelengths: &SampledWavelengths,
        sampler: &mut Sampler,
        count: &mut RayCount,
    ) -> SampledSpectrum {
        let world = prepared.world;
        let mut lambda = *wavelengths;
        let lambda_was_whole = !wavelengths.secondary_terminated();
        let mut eta_scale = 1.0f32;
        // The last scattering vertex, which light sampling would have started from.
        let mut previous = Receiver::point(Vec3::ZERO);
        let mut depth = 0i32;
        let mut medium = world.camera_medium;
        let mut ray = Ray {
            d: camera_ray.d.normalize(),
            ..camera_ray
        };
        let mut lobes = BxdfTree::empty();
        if self.max_depth == 0 {
            return SampledSpectrum::ZERO;
        }
        loop {
            count.rays += 1;
            let hit = world.geometry.intersect(&ray);

            // The medium between here and the surface: a real collision scatters.
            if let Some(m) = medium {
                let med = &world.media[m as usize];
                let t_surface = hit.map_or(f32::INFINITY, |si| si.t);
                let collision = weights.free_flight(med, &ray, t_surface, &lambda, sampler);
                if weights.throughput().is_black() {
                    break;
                }
                if let Some(t) = collision {
                    if !self.depth_allows_next_vertex(depth) {
                        break;
                    }
                    let p = ray.at(t);
                    let wo = -ray.d;
                    if med.sample_emitters
                        && let Some(terms) = Self::sample_direct_medium(
                            prepared, p, wo, ray.time, &med.phase, medium, &lambda, sampler, count,
                        )
                    {
                        weights.add_light_sample(&terms);
                    }
                    let ps = med.phase.sample(wo, sampler.next_2d());
                    if !(ps.pdf > 0.0) {
                        break;
                    }
                    ray = Ray::new(p, ps.wi, f32::INFINITY, ray.time);
                    weights.scatter(SampledSpectrum::ONE, ps.pdf, !med.sample_emitters);
                    previous = Receiver::point(p);
                    depth += 1;
                    if !self.survives_roulette(depth, &mut weights, eta_scale, sampler) {
                        break;
                    }
                    continue;
                }
            }

            let Some(si) = hit else {
                if let Some(env) = world.environment
                    && !(self.hide_emitters && depth == 0)
                {
                    let light = &world.lights[env as usize];
                    let emitted = light.environment_radiance(ray.d, &lambda);
                    if !emitted.is_black() {
                        let light_pdf = if weights.weights_emission() {
                            prepared.light_sampler.pmf(env as usize, &previous)
                                * light.environment_pdf(ray.d)
                        } else {
                            0.0
                        };
                        weights.add_emission(emitted, light_pdf);
                    }
                }
                break;
            };
            let wo = -ray.d;
            let info = world.shape_info[si.shape as usize];

            // Emission found by the previous directional sample (or by the camera ray).
            if let Some(light_index) = info.light
                && !(self.hide_emitters && depth == 0)
            {
                let Light::Area(light) = &world.lights[light_index as usize] else {
                    unreachable!("only area lights are attached to shapes");
                };
                let emitted = light.emitted(si.uv, si.shading.n, wo, &lambda);
                if !emitted.is_black() {
                    let light_pdf = if weights.weights_emission() {
                        prepared.light_sampler.pmf(light_index as usize, &previous)
                            * light.pdf_from(
                                &world.geometry.primitives,
                                previous.p,
                                si.time,
                                &SurfaceSample::at(&si),
                            )
                    } else {
                        0.0
                    };
                    weights.add_emission(emitted, light_pdf);
                }
            }

            let material = &world.materials[info.material as usize];
            // An index-matched boundary: cross it without a bounce.
            if material.is_null() {
                medium = medium_after(world, &si, ray.d, medium);
                ray = si.spawn_ray(ray.d);
                continue;
            }
            if !self.depth_allows_next_vertex(depth) {
                break;
            }

            let scattering = material.scattering(&si, wo, &lambda, &mut lobes);
            let smooth = scattering.flags().has_smooth_lobe();
            if smooth && scattering.is_dispersive() {
                lambda.terminate_secondary();
            }
            if smooth
                && let Some(terms) = Self::sample_direct_surface(
                    prepared,
                    &si,
                    &scattering,
                    medium,
                    &lambda,
                    sampler,
                    count,
                )
            {
                weights.add_light_sample(&terms);
            }

            let u_lobe = sampler.next_1d();
            let u = sampler.next_2d();
            let Some(bs) = scattering.sample(u_lobe, u) else {
                break;
            };
            if bs.terminates_secondary {
                lambda.terminate_secondary();
            }
            weights.scatter(bs.weight, bs.pdf, bs.flags.is_delta());
            eta_scale *= bs.eta;
            if weights.throughput().is_black() {
                break;
            }
            let wi = bs.wi.normalize();
            medium = medium_after(world, &si, wi, medium);
            ray = si.spawn_ray(wi);
            previous = Receiver::surface(si.p, si.shading.n);
            depth += 1;
            if !self.survives_roulette(depth, &mut weights, eta_scale, sampler) {
                break;
            }
        }
        weights.estimate(&lambda, lambda_was_whole)
    }

    /// Russian roulette after `rr_depth` bounces: survival s = min(max throughput · η², 0.95),
    /// the survivor's weight divided by s.
    #[inline]
    fn survives_roulette(
        &self,
        depth: i32,
        weights: &mut impl PathWeights,
        eta_scale: f32,
        sampler: &mut Sampler,
    ) -> bool {
        if depth <= self.rr_depth {
            return true;
        }
        let survival = (weights.throughput().max_value() * eta_scale * eta_scale).min(0.95);
        if !(sampler.next_1d() < survival) {
            return false;
        }
        weights.scale(1.0 / survival);
        true
    }

    /// A light chosen by the light sampler and a point on it, seen from `receiver`, with the
    /// probability of having chosen that light.
    #[inline]
    fn sample_light(
        prepared: &PreparedIntegrator,
        receiver: &Receiver,
        time: f32,
        lambda: &SampledWavelengths,
        sampler: &mut Sampler,
    ) -> Option<(LightSample, f32)> {
        let world = prepared.world;
        let u_light = sampler.next_1d();
        let u_choice = sampler.next_1d();
        let u = sampler.next_2d();
        let (light_index, choice_pmf) = prepared.light_sampler.sample(u_light, receiver)?;
        let ls = world.lights[light_index].sample_incident(
            &world.geometry.primitives,
            receiver.p,
            time,
            u_choice,
            u,
            lambda,
        )?;
        Some((ls, choice_pmf))
    }

    /// One light sample at the surface point `si`, with the transmittance Tr of the media the
    /// shadow ray crosses; `None` when it contributes nothing.
    fn sample_direct_surface(
        prepared: &PreparedIntegrator,
        si: &SurfaceInteraction,
        scattering: &Scattering,
        medium: Option<u32>,
        lambda: &SampledWavelengths,
        sampler: &mut Sampler,
        count: &mut RayCount,
    ) -> Option<LightSampleTerms> {
        let world = prepared.world;
        let (ls, choice_pmf) = Self::sample_light(
            prepared,
            &Receiver::surface(si.p, si.shading.n),
            si.time,
            lambda,
            sampler,
        )?;
        let f = scattering.eval(ls.wi);
        if f.value.is_black() {
            return None;
        }
        let shadow = si.spawn_ray_to(ls.p, ls.n);
        let end = shadow.o + shadow.d * shadow.t_max;
        let transmittance = shadow_transmittance(
            world,
            shadow.o,
            end,
            si.time,
            medium_after(world, si, ls.wi, medium),
            lambda,
            sampler,
            count,
        );
        if transmittance.is_black() {
            return None;
        }
        Some(LightSampleTerms {
            value: f.value,
            direction_pdf: f.pdf,
            light_pdf: choice_pmf * ls.pdf,
            is_delta: ls.is_delta,
            transmittance,
            radiance: ls.radiance,
        })
    }

    /// One light sample at the point `p` of `medium`, scattered towards `wo` by `phase` (the
    /// path's weight already carries σ_s of the real collision); `None` when it contributes
    /// nothing.
    #[allow(clippy::too_many_arguments)] // the vertex, its medium and the path's state
    fn sample_direct_medium(
        prepared: &PreparedIntegrator,
        p: Vec3,
        wo: Vec3,
        time: f32,
        phase: &PhaseFunction,
        medium: Option<u32>,
        lambda: &SampledWavelengths,
        sampler: &mut Sampler,
        count: &mut RayCount,
    ) -> Option<LightSampleTerms> {
        let world = prepared.world;
        let (ls, choice_pmf) =
            Self::sample_light(prepared, &Receiver::point(p), time, lambda, sampler)?;
        let phase_value = phase.eval(wo, ls.wi);
        if !(phase_value > 0.0) {
            return None;
        }
        let transmittance = shadow_transmittance(
            world,
            p,
            shadow_end(p, &ls),
            time,
            medium,
            lambda,
            sampler,
            count,
        );
        if transmittance.is_black() {
            return None;
        }
        Some(LightSampleTerms {
            value: SampledSpectrum::splat(phase_value),
            direction_pdf: phase_value,
            light_pdf: choice_pmf * ls.pdf,
            is_delta: ls.is_delta,
            transmittance,
            radiance: ls.radiance,
        })
    }
}
