//! The volumetric path tracer (Mitsuba 3's `volpath`): the path tracer of [`super::path`] with
//! participating media between the surfaces.
//!
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! Each segment of a path that runs through a medium is tracked with one majorant for the
//! path's four wavelengths ([`crate::medium`], spectral tracking): null collisions fly on, a
//! real collision scatters by the medium's phase function. At surfaces the path behaves as in
//! `path`. A scattering vertex in a medium samples a light (when the medium's
//! `sample_emitters` is set) and the phase function, and the two are combined by multiple
//! importance sampling with the power heuristic on their solid-angle densities, exactly as a
//! BSDF and a light are at a surface (Mitsuba's volpath does the same). Shadow rays carry the
//! transmittance of every medium they cross (closed form for homogeneous media, ratio tracking
//! for heterogeneous ones) and pass through the surfaces that have a null lobe, weighted by its
//! value (Mitsuba 3's `eval_null_transmission`: 1 for `null`, 1 − R' for `thindielectric`,
//! 1 − α(1 − t_nested) for `mask`; [`super::transmittance`]); any other surface blocks them.
//!
//! * Media change where a path crosses a shape that names an `interior` or `exterior`
//!   medium: the medium on the side the path leaves to; shapes that name none leave it as it
//!   is. The camera sits in the sensor's medium.
//! * A null interaction is not a bounce (Mitsuba 3's `volpath` and `volpathmis`): where the
//!   BSDF sample is a null lobe (a `null` surface, the pass-through of `thindielectric` or
//!   `mask`), the path crosses the surface with the sample's weight and without changing
//!   direction, depth, or the vertex its MIS weights refer to. A surface with a null lobe is
//!   sampled even at the last depth, where only a null sample lets the path go on; light
//!   sampling there needs a bounce left, as at any surface.
//! * Depth counts surface and medium scattering vertices; a path of depth d has d bounces,
//!   `max_depth` as in `path`. Russian roulette on the path's potential (throughput times η²)
//!   starts after `rr_depth` bounces (depth > rr_depth, as Mitsuba's volpath).
//! * Chromatic media keep all four wavelengths unbiased (see [`crate::medium`] for why one
//!   majorant over the four rather than hero-wavelength tracking).
//!
//! The path's step below is shared with `volpathmis` ([`super::volpathmis`]): what differs is how
//! free flights are drawn and how the path's weights and its estimate are kept, the
//! [`PathWeights`] of each ([`SpectralTracking`] here). Both are written over what the path
//! carries ([`super::throughput`]): a spectrum, or in scenes that polarize a Mueller matrix per
//! wavelength ([`super::polarized_volpath`]).

use glam::Vec3;

use crate::bsdf::{BsdfEval, BxdfTree};
use crate::geometry::SurfaceInteraction;
use crate::integrator::SampleContext;
use crate::integrator::mis::{LightSampleTerms, emission_along, power_heuristic, sample_light};
use crate::integrator::stepped::SteppedPath;
use crate::integrator::throughput::{Estimate, Throughput};
use crate::integrator::transmittance::{medium_after, shadow_end};
use crate::integrator::vertex::{
    allows_next_vertex, russian_roulette, surface_scattering, wavelengths_after,
};
use crate::light::{LightSelection, Receiver};
use crate::math::Ray;
use crate::medium::{Collision, Medium, PhaseModel, choose_collision, sample_free_flight};
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
/// need, and the estimate it sums. The step of [`VolPathWith`] calls these at each event.
pub(crate) trait PathWeights {
    /// What the path carries: a spectrum, or a Mueller matrix per wavelength.
    type Throughput: Throughput;

    /// The intensity of the factor by which the path's further contributions are weighted
    /// (before MIS against light samples): Russian roulette and termination look at it.
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
    fn scatter(&mut self, weight: Self::Throughput, pdf: f32, unweighted: bool);

    /// A surface crossed by a null lobe with the sample's `weight`: not a scattering vertex, so
    /// the densities that MIS refers to stay those of the last one. The crossing is weighed
    /// outside MIS, as the light sample's factor of null transmission is.
    fn pass_through(&mut self, weight: Self::Throughput);

    /// Whether emission found next is weighted against light sampling (so its light density
    /// is needed).
    fn weights_emission(&self) -> bool;

    /// Adds emitted radiance `emitted` found by the path, which light sampling from the last
    /// vertex finds with solid-angle density `light_pdf` (ignored when unweighted).
    fn add_emission(&mut self, emitted: SampledSpectrum, light_pdf: f32);

    /// Adds a light sample taken at the path's current vertex, whose vertex and shadow ray also
    /// do `transfer`.
    fn add_light_sample(
        &mut self,
        sample: &LightSampleTerms,
        transfer: &<Self::Throughput as Throughput>::LightTransfer,
    );

    /// The path's estimate for the caller's wavelengths; `lambda_was_whole` when the path
    /// started with all four.
    fn estimate(
        &self,
        lambda: &SampledWavelengths,
        lambda_was_whole: bool,
    ) -> <Self::Throughput as Throughput>::Estimate;
}

/// `volpath`'s weights: the throughput of spectral tracking and the density of the last
/// directional sample, for the power heuristic against light samples.
#[derive(Clone)]
pub(crate) struct SpectralTracking<T: Throughput = SampledSpectrum> {
    throughput: T,
    /// Solid-angle density of the last directional sample.
    pdf: f32,
    unweighted: bool,
    result: T::Estimate,
}

impl<T: Throughput> SpectralTracking<T> {
    pub(crate) fn new() -> Self {
        SpectralTracking {
            throughput: T::ONE,
            pdf: 0.0,
            unweighted: true,
            result: T::Estimate::ZERO,
        }
    }
}

impl<T: Throughput> PathWeights for SpectralTracking<T> {
    type Throughput = T;

    #[inline]
    fn throughput(&self) -> SampledSpectrum {
        self.throughput.intensity()
    }

    #[inline]
    fn scale(&mut self, factor: f32) {
        self.throughput.scale_all(factor);
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
    fn scatter(&mut self, weight: T, pdf: f32, unweighted: bool) {
        self.throughput.then(weight);
        self.pdf = pdf;
        self.unweighted = unweighted;
    }

    #[inline]
    fn pass_through(&mut self, weight: T) {
        self.throughput.then(weight);
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
        self.result
            .add(self.throughput.gathers(emitted).scaled(weight));
    }

    /// f·Tr·L·w / p_light, w the power heuristic against the directional density.
    #[inline]
    fn add_light_sample(&mut self, s: &LightSampleTerms, transfer: &T::LightTransfer) {
        let weight = if s.is_delta {
            1.0
        } else {
            power_heuristic(s.light_pdf, s.direction_pdf)
        };
        self.result.add(
            self.throughput
                .gathers_light(s, transfer)
                .scaled(weight / s.light_pdf),
        );
    }

    #[inline]
    fn estimate(&self, lambda: &SampledWavelengths, lambda_was_whole: bool) -> T::Estimate {
        if lambda_was_whole && lambda.secondary_terminated() {
            self.result.hero_only()
        } else {
            self.result
        }
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
fn spectral_tracking<T: Throughput>(
    medium: &Medium,
    ray: &Ray,
    t_surface: f32,
    lambda: &SampledWavelengths,
    throughput: &mut T,
    sampler: &mut Sampler,
) -> Option<f32> {
    let (t0, t1) = medium.ray_extent(ray, t_surface)?;
    let majorant = medium.majorant(ray.d, lambda);
    let mut t = t0;
    loop {
        t = sample_free_flight(t, t1, majorant, sampler.next_1d())?;
        let c = medium.coefficients(ray.at(t), ray.d, lambda);
        match choose_collision(
            counted(throughput.intensity(), lambda),
            &c,
            majorant,
            sampler.next_1d(),
        ) {
            Collision::Real(weight) => {
                throughput.scale(weight);
                return Some(t);
            }
            Collision::Null(weight) => {
                throughput.scale(weight);
                if throughput.intensity().is_black() {
                    return None;
                }
            }
        }
    }
}

/// `volpath` or `volpathmis`: the volumetric path tracer with the weights `W` of one of them,
/// `weights` being those a path starts with.
pub(crate) struct VolPathWith<'a, W> {
    pub(crate) integrator: &'a VolPathIntegrator,
    pub(crate) weights: W,
}

/// A volumetric path between two ray queries: everything one step of it hands the next.
pub(crate) struct VolPathState<W> {
    /// The ray to the next surface (unit direction), through `medium`.
    ray: Ray,
    medium: Option<u32>,
    weights: W,
    /// The path's own copy of the wavelengths: a dispersive interface may drop the companions.
    lambda: SampledWavelengths,
    /// Whether the path started with all four wavelengths.
    lambda_was_whole: bool,
    /// Product of the relative indices of refraction crossed (Mitsuba's η).
    eta_scale: f32,
    /// The last scattering vertex, which light sampling would have started from.
    previous: Receiver,
    depth: i32,
}

impl<W: PathWeights + Clone> SteppedPath for VolPathWith<'_, W> {
    type State = VolPathState<W>;

    /// The path before its first query, in the camera's medium; None when `max_depth` is 0.
    #[inline]
    fn start(
        &self,
        world: &World,
        ray: Ray,
        wavelengths: &SampledWavelengths,
    ) -> Option<VolPathState<W>> {
        (self.integrator.max_depth != 0).then(|| VolPathState {
            ray: Ray {
                d: ray.d.normalize(),
                ..ray
            },
            medium: world.camera_medium,
            weights: self.weights.clone(),
            lambda: *wavelengths,
            lambda_was_whole: !wavelengths.secondary_terminated(),
            eta_scale: 1.0,
            previous: Receiver::point(Vec3::ZERO),
            depth: 0,
        })
    }

    #[inline]
    fn ray(state: &VolPathState<W>) -> &Ray {
        &state.ray
    }

    /// One event of the path: a real collision in the medium before `hit` (a light sample and
    /// a phase function sample), or the surface `hit` (the emission found there, a null
    /// crossing, or a light sample and a BSDF sample), and Russian roulette after a bounce.
    fn step(
        &self,
        ctx: &mut SampleContext,
        state: &mut VolPathState<W>,
        hit: Option<SurfaceInteraction>,
    ) -> bool {
        let integrator = self.integrator;
        let world = ctx.world();
        let VolPathState {
            ray,
            medium,
            weights,
            lambda,
            eta_scale,
            previous,
            depth,
            ..
        } = state;

        // The medium between here and the surface: a real collision scatters.
        if let Some(m) = *medium {
            let med = &world.media[m as usize];
            let t_surface = hit.as_ref().map_or(f32::INFINITY, |si| si.t);
            let collision = weights.free_flight(med, ray, t_surface, lambda, ctx.sampler);
            if weights.throughput().is_black() {
                return false;
            }
            if let Some(t) = collision {
                if !allows_next_vertex(integrator.max_depth, *depth) {
                    return false;
                }
                let p = ray.at(t);
                let wo = -ray.d;
                if med.sample_emitters
                    && let Some((terms, transfer)) =
                        VolPathIntegrator::light_sample_in_medium::<W::Throughput>(
                            ctx, p, wo, ray.time, med, *medium, lambda,
                        )
                {
                    weights.add_light_sample(&terms, &transfer);
                }
                let ps = med.phase.sample(wo, ctx.sampler.next_2d());
                if !(ps.pdf > 0.0) {
                    return false;
                }
                *ray = Ray::new(p, ps.wi, f32::INFINITY, ray.time);
                weights.scatter(W::Throughput::ONE, ps.pdf, !med.sample_emitters);
                *previous = Receiver::point(p);
                *depth += 1;
                return integrator.survives_roulette(ctx, *depth, weights, *eta_scale);
            }
        }

        // Emission found by the previous directional sample (or by the camera ray).
        if !(integrator.hide_emitters && *depth == 0)
            && let Some(found) = emission_along(world, ray.d, hit.as_ref(), lambda)
            && !found.radiance.is_black()
        {
            let light_pdf = if weights.weights_emission() {
                found.light_pdf(ctx, previous)
            } else {
                0.0
            };
            weights.add_emission(found.radiance, light_pdf);
        }
        let Some(si) = hit else {
            return false;
        };
        let wo = -ray.d;

        // An index-matched boundary: cross it without a bounce.
        let material = world.material(&si);
        if material.is_null() {
            *medium = medium_after(world, &si, ray.d, *medium);
            *ray = si.spawn_ray(ray.d);
            return true;
        }
        // Without a bounce left, only a null lobe lets the path go on.
        let may_bounce = allows_next_vertex(integrator.max_depth, *depth);
        if !may_bounce && !material.has_null_lobe() {
            return false;
        }

        let mut lobes = BxdfTree::empty();
        let scattering = surface_scattering(world, &si, wo, lambda, &mut lobes);
        if may_bounce && scattering.flags().has_smooth_lobe() {
            let receiver = Receiver::surface(si.p, si.shading.n);
            let current = *medium;
            let mut transfer = None;
            let terms = sample_light(ctx, &receiver, si.time, lambda, |ctx, ls| {
                let f = scattering.eval(ls.wi);
                if f.value.is_black() {
                    return None;
                }
                let shadow = si.spawn_ray_to(ls.p, ls.n);
                let end = shadow.o + shadow.d * shadow.t_max;
                let shadow_medium = medium_after(world, &si, ls.wi, current);
                let (tr, surfaces) =
                    W::Throughput::shadow(ctx, shadow.o, end, si.time, shadow_medium, lambda);
                if tr.is_black() {
                    return None;
                }
                transfer = Some(W::Throughput::at_surface(&scattering, ls.wi, &f, surfaces));
                Some((f, tr))
            });
            if let (Some(terms), Some(transfer)) = (terms, transfer) {
                weights.add_light_sample(&terms, &transfer);
            }
        }

        let u_lobe = ctx.sampler.next_1d();
        let u = ctx.sampler.next_2d();
        let Some(bs) = scattering.sample(u_lobe, u) else {
            return false;
        };
        if bs.flags.has_null_lobe() {
            weights.pass_through(W::Throughput::sampled(&scattering, &bs));
            if weights.throughput().is_black() {
                return false;
            }
            *medium = medium_after(world, &si, ray.d, *medium);
            *ray = si.spawn_ray(ray.d);
            return true;
        }
        if !may_bounce {
            return false;
        }
        *lambda = wavelengths_after(lambda, &bs);
        weights.scatter(
            W::Throughput::sampled(&scattering, &bs),
            bs.pdf,
            bs.flags.is_delta(),
        );
        *eta_scale *= bs.eta;
        if weights.throughput().is_black() {
            return false;
        }
        let wi = bs.wi.normalize();
        *medium = medium_after(world, &si, wi, *medium);
        *ray = si.spawn_ray(wi);
        *previous = Receiver::surface(si.p, si.shading.n);
        *depth += 1;
        integrator.survives_roulette(ctx, *depth, weights, *eta_scale)
    }

    #[inline]
    fn estimate(&self, state: &VolPathState<W>) -> SampledSpectrum {
        self.full_estimate(state).intensity()
    }
}

impl<W: PathWeights + Clone> VolPathWith<'_, W> {
    /// The estimate of a path that has ended, for the wavelengths it started with: radiance,
    /// or a Stokes vector per wavelength.
    #[inline]
    pub(crate) fn full_estimate(
        &self,
        state: &VolPathState<W>,
    ) -> <W::Throughput as Throughput>::Estimate {
        state
            .weights
            .estimate(&state.lambda, state.lambda_was_whole)
    }
}

impl VolPathIntegrator {
    /// Russian roulette ([`russian_roulette`]) after `rr_depth` bounces (depth > rr_depth, as
    /// Mitsuba's volpath counts them).
    #[inline]
    fn survives_roulette(
        &self,
        ctx: &mut SampleContext,
        depth: i32,
        weights: &mut impl PathWeights,
        eta_scale: f32,
    ) -> bool {
        if depth <= self.rr_depth {
            return true;
        }
        let Some(factor) = russian_roulette(ctx, weights.throughput(), eta_scale) else {
            return false;
        };
        weights.scale(factor);
        true
    }

    /// One light sample at the point `p` of `med` (index `medium`), scattered towards `wo` by
    /// its phase function (the path's weight already carries σ_s of the real collision), with
    /// the transmittance of the media and null surfaces the shadow ray crosses, and what the
    /// phase function and those surfaces do to the light beyond that.
    fn light_sample_in_medium<T: Throughput>(
        ctx: &mut SampleContext,
        p: Vec3,
        wo: Vec3,
        time: f32,
        med: &Medium,
        medium: Option<u32>,
        lambda: &SampledWavelengths,
    ) -> Option<(LightSampleTerms, T::LightTransfer)> {
        let mut transfer = None;
        let terms = sample_light(ctx, &Receiver::point(p), time, lambda, |ctx, ls| {
            let phase_value = med.phase.eval(wo, ls.wi);
            if !(phase_value > 0.0) {
                return None;
            }
            let (tr, surfaces) = T::shadow(ctx, p, shadow_end(p, ls), time, medium, lambda);
            if tr.is_black() {
                return None;
            }
            transfer = Some(T::in_medium(phase_value, surfaces));
            let f = BsdfEval {
                value: SampledSpectrum::splat(phase_value),
                pdf: phase_value,
            };
            Some((f, tr))
        })?;
        Some((terms, transfer?))
    }
}
