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

use glam::Vec3;

use crate::bsdf::{BxdfTree, Scattering};
use crate::geometry::SurfaceInteraction;
use crate::geometry::interaction::SHADOW_EPSILON;
use crate::geometry::offset::offset_ray_origin;
use crate::integrator::path::power_heuristic;
use crate::integrator::{PreparedIntegrator, RayCount, hero_only};
use crate::light::{Light, LightSample, LightSelection};
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
}

impl Default for VolPathIntegrator {
    fn default() -> Self {
        VolPathIntegrator {
            max_depth: -1,
            rr_depth: 5,
            hide_emitters: false,
            light_selection: LightSelection::Power,
        }
    }
}

/// The last scattering vertex (on a surface or in a medium), which emitters found by its
/// directional sample are MIS-weighted against.
#[derive(Clone, Copy)]
struct Previous {
    p: Vec3,
    /// Solid-angle density of the sampled direction.
    pdf: f32,
    /// Whether no light sample could have found what the direction finds (a delta lobe, or a
    /// medium without `sample_emitters`): its emission then counts in full.
    unweighted: bool,
}

/// The medium a ray leaving `si` in direction `d` travels in, when it was in `current`.
#[inline]
fn medium_after(
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
fn free_flight(
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

    pub(super) fn radiance(
        &self,
        prepared: &PreparedIntegrator,
        camera_ray: Ray,
        wavelengths: &SampledWavelengths,
        sampler: &mut Sampler,
        count: &mut RayCount,
    ) -> SampledSpectrum {
        let world = prepared.world;
        let mut lambda = *wavelengths;
        let lambda_was_whole = !wavelengths.secondary_terminated();
        let mut result = SampledSpectrum::ZERO;
        let mut throughput = SampledSpectrum::ONE;
        let mut eta_scale = 1.0f32;
        let mut previous: Option<Previous> = None;
        let mut depth = 0i32;
        let mut medium = world.camera_medium;
        let mut ray = Ray {
            d: camera_ray.d.normalize(),
            ..camera_ray
        };
        let mut lobes = BxdfTree::empty();
        if self.max_depth == 0 {
            return result;
        }
        loop {
            count.rays += 1;
            let hit = world.geometry.intersect(&ray);

            // The medium between here and the surface: a real collision scatters.
            if let Some(m) = medium {
                let med = &world.media[m as usize];
                let t_surface = hit.map_or(f32::INFINITY, |si| si.t);
                let collision =
                    free_flight(med, &ray, t_surface, &lambda, &mut throughput, sampler);
                if throughput.is_black() {
                    break;
                }
                if let Some(t) = collision {
                    if !self.depth_allows_next_vertex(depth) {
                        break;
                    }
                    let p = ray.at(t);
                    let wo = -ray.d;
                    if med.sample_emitters {
                        result += throughput
                            * Self::sample_direct_medium(
                                prepared, p, wo, ray.time, &med.phase, medium, &lambda, sampler,
                                count,
                            );
                    }
                    let ps = med.phase.sample(wo, sampler.next_2d());
                    if !(ps.pdf > 0.0) {
                        break;
                    }
                    ray = Ray::new(p, ps.wi, f32::INFINITY, ray.time);
                    previous = Some(Previous {
                        p,
                        pdf: ps.pdf,
                        unweighted: !med.sample_emitters,
                    });
                    depth += 1;
                    if !self.survives_roulette(depth, &mut throughput, eta_scale, sampler) {
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
                    let weight = match &previous {
                        Some(prev) if !prev.unweighted && !emitted.is_black() => {
                            let light_pdf = prepared.light_sampler.pmf(env as usize)
                                * light.environment_pdf(ray.d);
                            power_heuristic(prev.pdf, light_pdf)
                        }
                        _ => 1.0,
                    };
                    result += throughput * emitted * weight;
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
                let emitted = light.emitted(si.shading.n, wo, &lambda);
                if !emitted.is_black() {
                    let weight = match &previous {
                        Some(prev) if !prev.unweighted => {
                            let shape = &world.geometry.primitives[si.shape as usize];
                            let light_pdf = prepared.light_sampler.pmf(light_index as usize)
                                * shape.pdf_from(prev.p, si.time, si.p, si.n);
                            power_heuristic(prev.pdf, light_pdf)
                        }
                        _ => 1.0,
                    };
                    result += throughput * emitted * weight;
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
            if smooth {
                result += throughput
                    * Self::sample_direct_surface(
                        prepared,
                        &si,
                        &scattering,
                        medium,
                        &lambda,
                        sampler,
                        count,
                    );
            }

            let u_lobe = sampler.next_1d();
            let u = sampler.next_2d();
            let Some(bs) = scattering.sample(u_lobe, u) else {
                break;
            };
            if bs.terminates_secondary {
                lambda.terminate_secondary();
            }
            throughput *= bs.weight;
            eta_scale *= bs.eta;
            if throughput.is_black() {
                break;
            }
            let wi = bs.wi.normalize();
            medium = medium_after(world, &si, wi, medium);
            ray = si.spawn_ray(wi);
            previous = Some(Previous {
                p: si.p,
                pdf: bs.pdf,
                unweighted: bs.flags.is_delta(),
            });
            depth += 1;
            if !self.survives_roulette(depth, &mut throughput, eta_scale, sampler) {
                break;
            }
        }
        if lambda_was_whole && lambda.secondary_terminated() {
            return hero_only(result);
        }
        result
    }

    /// Russian roulette after `rr_depth` bounces: survival s = min(max throughput · η², 0.95),
    /// the survivor's throughput divided by s.
    #[inline]
    fn survives_roulette(
        &self,
        depth: i32,
        throughput: &mut SampledSpectrum,
        eta_scale: f32,
        sampler: &mut Sampler,
    ) -> bool {
        if depth <= self.rr_depth {
            return true;
        }
        let survival = (throughput.max_value() * eta_scale * eta_scale).min(0.95);
        if !(sampler.next_1d() < survival) {
            return false;
        }
        *throughput *= 1.0 / survival;
        true
    }

    /// A light chosen by the light sampler and a point on it, seen from `p`, with the
    /// probability of having chosen that light.
    #[inline]
    fn sample_light(
        prepared: &PreparedIntegrator,
        p: Vec3,
        time: f32,
        lambda: &SampledWavelengths,
        sampler: &mut Sampler,
    ) -> Option<(LightSample, f32)> {
        let world = prepared.world;
        let u_light = sampler.next_1d();
        let u_choice = sampler.next_1d();
        let u = sampler.next_2d();
        let (light_index, choice_pmf) = prepared.light_sampler.sample(u_light)?;
        let ls = world.lights[light_index].sample_incident(
            &world.geometry.primitives,
            p,
            time,
            u_choice,
            u,
            lambda,
        )?;
        Some((ls, choice_pmf))
    }

    /// One light sample at the surface point `si`: f·Tr·L·w / (p_light · p_choice), with the
    /// transmittance Tr of the media the shadow ray crosses.
    fn sample_direct_surface(
        prepared: &PreparedIntegrator,
        si: &SurfaceInteraction,
        scattering: &Scattering,
        medium: Option<u32>,
        lambda: &SampledWavelengths,
        sampler: &mut Sampler,
        count: &mut RayCount,
    ) -> SampledSpectrum {
        let world = prepared.world;
        let Some((ls, choice_pmf)) = Self::sample_light(prepared, si.p, si.time, lambda, sampler)
        else {
            return SampledSpectrum::ZERO;
        };
        let f = scattering.eval(ls.wi);
        if f.value.is_black() {
            return SampledSpectrum::ZERO;
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
            return SampledSpectrum::ZERO;
        }
        let light_pdf = choice_pmf * ls.pdf;
        let weight = if ls.is_delta {
            1.0
        } else {
            power_heuristic(light_pdf, f.pdf)
        };
        f.value * transmittance * ls.radiance * (weight / light_pdf)
    }

    /// One light sample at the point `p` of `medium`, scattered towards `wo` by `phase`:
    /// σ_s-weighted phase value times Tr·L·w / (p_light · p_choice). (The path throughput
    /// already carries σ_s/σ_t of the real collision.)
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
    ) -> SampledSpectrum {
        let world = prepared.world;
        let Some((ls, choice_pmf)) = Self::sample_light(prepared, p, time, lambda, sampler) else {
            return SampledSpectrum::ZERO;
        };
        let phase_value = phase.eval(wo, ls.wi);
        if !(phase_value > 0.0) {
            return SampledSpectrum::ZERO;
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
            return SampledSpectrum::ZERO;
        }
        let light_pdf = choice_pmf * ls.pdf;
        let weight = if ls.is_delta {
            1.0
        } else {
            power_heuristic(light_pdf, phase_value)
        };
        transmittance * ls.radiance * (phase_value * weight / light_pdf)
    }
}
