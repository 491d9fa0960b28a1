//! The passes of stochastic progressive photon mapping ([`crate::integrator::sppm`]): each pass
//! traces its photons, builds their map, traces one camera path per pixel of the crop window
//! and updates the pixel's statistics (its search radius r, accumulated photon count N, flux τ
//! in CIE XYZ and the sum of its direct estimates) by the progressive rule; the image after P
//! passes is the radiance estimate L = Σ L_direct / P + τ / (P · photonCount · π r²).
//!
//! Sample index s of a render is pass s: the camera path of pixel j in pass s draws its random
//! numbers from the scene's sampler for (j, s), photon i of pass s from an independent stream
//! for (i, s), and the pass's wavelengths from one more stream for s. Photons are traced in
//! parallel tasks and joined in the order of their indices; each pixel's update reads only the
//! map and its own state. So the image is bit-identical for any thread count and task size.
//!
//! A pass cut short by the time limit or an interruption is dropped whole. The statistics are
//! not pixel sums: a render state could not hold them, so checkpoints, `--resume` and merged
//! sample ranges are refused, and so is a target error, since nothing estimates the error of
//! this biased estimate. The film gets each pixel's estimate as its one sample, so the EXR's
//! variance channels are infinite (no error estimate), never an error bar.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

use glam::{UVec2, Vec2};
use rayon::prelude::*;

use super::estimator::SampleEstimator;
use super::progress::{ProgressReport, Silent};
use super::stop::Cancel;
use super::{Checkpoints, Preview, RenderOptions, RenderOutput, Snapshot, StopReason};
use crate::camera::{CameraModel, CameraRay};
use crate::error::{Error, Result};
use crate::film::accumulation::{AOV_SUMS_PER_CHANNEL, add_aov_sample};
use crate::film::{Film, FilterSampler};
use crate::integrator::RayCount;
use crate::integrator::photon_map::PhotonMap;
use crate::integrator::sppm::{Photon, SppmIntegrator};
use crate::light::BoundingSphere;
use crate::render::relative_error;
use crate::sampling::rng::{Pcg32, hash_u64s};
use crate::sampling::sampler::{Sampler, SamplerKind};
use crate::scene::Scene;
use crate::spectrum::SampledWavelengths;

/// Photons a task traces when `granularity` leaves it to the renderer.
const DEFAULT_GRANULARITY: u32 = 4096;
/// Streams of the photons' random numbers and of the passes' wavelengths.
const PHOTON_STREAM: u64 = 0x5050_4d5f_7068_6f74;
const WAVELENGTH_STREAM: u64 = 0x5050_4d5f_6c61_6d62;

/// One pixel's statistics between passes.
#[derive(Clone, Copy, Debug)]
struct PixelState {
    radius: f64,
    /// The accumulated photon count N.
    photons: f64,
    /// The accumulated flux τ, CIE XYZ.
    flux: [f64; 3],
    /// The sum of the passes' direct estimates, CIE XYZ.
    direct: [f64; 3],
}

impl PixelState {
    /// The pixel's estimate after `passes` passes of `photon_count` photons.
    fn radiance(&self, passes: u32, photon_count: u32) -> [f64; 3] {
        if passes == 0 {
            return [0.0; 3];
        }
        let p = f64::from(passes);
        let area = std::f64::consts::PI * self.radius * self.radius;
        let emitted = p * f64::from(photon_count);
        [0, 1, 2].map(|c| self.direct[c] / p + self.flux[c] / (emitted * area))
    }

    /// The progressive update with the flux `flux` of `found` photons (Hachisuka & Jensen
    /// 2009, eqs. 5–8).
    fn gather(&mut self, alpha: f64, flux: [f64; 3], found: u32) {
        if found == 0 {
            return;
        }
        let m = f64::from(found);
        let ratio = (self.photons + alpha * m) / (self.photons + m);
        self.radius *= ratio.sqrt();
        self.photons += alpha * m;
        for (tau, phi) in self.flux.iter_mut().zip(flux) {
            *tau = (*tau + phi) * ratio;
        }
    }
}

/// The random number that draws the wavelengths of pass `pass` of a render with seed `seed`:
/// the radical inverse of the pass in base 2, rotated by a number drawn from the seed
/// (Cranley–Patterson), so that every run of 2ᵏ passes covers the wavelengths evenly.
pub(super) fn pass_wavelength(seed: u64, pass: u32) -> f32 {
    let rotation = Pcg32::new(hash_u64s(&[seed]), WAVELENGTH_STREAM).next_f64();
    let u = f64::from(pass.reverse_bits()) / 2f64.powi(32) + rotation;
    (u.fract() as f32).min(1.0f32.next_down())
}

/// Mitsuba 0.6's initial radius: five times the scene's bounding radius over the film's larger
/// side.
fn automatic_radius(scene: &Scene) -> f32 {
    let sphere = BoundingSphere::around_box(scene.world.geometry.bounds());
    let size = scene.film.size;
    5.0 * sphere.radius / size.x.max(size.y) as f32
}

/// Renders the scene with `sppm` (see the module's text).
pub(super) fn render(
    scene: &Scene,
    sppm: &SppmIntegrator,
    estimator: &SampleEstimator,
    options: &RenderOptions,
    pool: &rayon::ThreadPool,
    checkpoints: Option<Checkpoints>,
    mut preview: Option<Preview>,
) -> Result<RenderOutput> {
    let refuse = |what: &str| {
        Err(Error::usage(format!(
            "the sppm integrator {what}: its per-pixel radii and photon statistics are not \
             pixel sums"
        )))
    };
    if checkpoints.is_some() || options.initial.is_some() || options.first_sample != 0 {
        return refuse("cannot be checkpointed, resumed or merged from sample ranges");
    }
    if options.stop.target_error.is_some() {
        return refuse("has no error estimate to stop at");
    }
    if !scene.film.bands.is_empty() {
        return refuse("writes no spectral bands");
    }
    let film = &scene.film;
    let crop = film.crop;
    let width = crop.size.x as usize;
    let pixel_count = u64::from(crop.size.x) * u64::from(crop.size.y);
    let end = sppm.max_passes.or(options.stop.sample_end);
    let radius = f64::from(
        sppm.initial_radius
            .unwrap_or_else(|| automatic_radius(scene)),
    );
    let mut state = vec![
        PixelState {
            radius,
            photons: 0.0,
            flux: [0.0; 3],
            direct: [0.0; 3],
        };
        pixel_count as usize
    ];
    let mut next_state = state.clone();
    let aov_count = estimator.aov_count();
    let progress: &dyn ProgressReport = options.progress.as_deref().unwrap_or(&Silent);
    progress.begin(end.map(|end| pixel_count * u64::from(end)));
    let abort = AtomicBool::new(false);
    let rays = AtomicU64::new(0);
    let start = Instant::now();
    let cancel = Cancel {
        flag: &abort,
        external: options.interrupt.as_deref(),
        deadline: options.stop.time_limit.map(|limit| start + limit),
    };
    let pass = PassContext {
        scene,
        sppm,
        estimator,
        options,
        cancel: &cancel,
        progress,
    };
    let mut passes = 0u32;
    let reason = loop {
        if end.is_some_and(|end| passes >= end) {
            break StopReason::Completed;
        }
        if options
            .stop
            .time_limit
            .is_some_and(|limit| start.elapsed() >= limit)
        {
            break StopReason::TimeLimit;
        }
        let interrupted = || {
            options
                .interrupt
                .as_ref()
                .is_some_and(|i| i.load(Ordering::Relaxed))
        };
        if interrupted() {
            break StopReason::Interrupted;
        }
        next_state.copy_from_slice(&state);
        let done = pool.install(|| pass.run(passes, &mut next_state, width));
        let Some(pass_rays) = done.filter(|_| !abort.load(Ordering::Relaxed)) else {
            break if interrupted() {
                StopReason::Interrupted
            } else {
                StopReason::TimeLimit
            };
        };
        std::mem::swap(&mut state, &mut next_state);
        rays.fetch_add(pass_rays, Ordering::Relaxed);
        passes += 1;
        progress.pass_done(passes, f64::INFINITY);
        if let Some(preview) = &mut preview {
            let film = film_of(scene, sppm, &state, passes, aov_count);
            preview(&Snapshot {
                samples: 0..passes,
                pixels: &film.pixels,
                aovs: &film.aovs,
                integrator_state: None,
            })?;
        }
    };
    let elapsed = start.elapsed();
    progress.end();
    let film = film_of(scene, sppm, &state, passes, aov_count);
    let error = relative_error(film.pixels.iter());
    Ok(RenderOutput {
        film,
        samples: 0..passes,
        elapsed,
        sample_count: pixel_count * u64::from(passes),
        rays: rays.into_inner(),
        stop: reason,
        relative_error: error,
        lane_occupancy: None,
        integrator_state: None,
    })
}

/// The film holding each pixel's estimate after `passes` passes as its one sample (and a
/// coverage of 1 in every extra channel: sppm writes only the alpha).
fn film_of(
    scene: &Scene,
    sppm: &SppmIntegrator,
    state: &[PixelState],
    passes: u32,
    aov_count: usize,
) -> Film {
    let mut film = Film::with_aovs(scene.film.size, scene.film.crop, scene.aov_names());
    let stride = AOV_SUMS_PER_CHANNEL * aov_count;
    let coverage = vec![1.0f32; aov_count];
    for (i, (pixel, s)) in film.pixels.iter_mut().zip(state).enumerate() {
        pixel.add_total(s.radiance(passes, sppm.photon_count));
        add_aov_sample(
            &mut film.aovs[i * stride..i * stride + aov_count],
            &coverage,
        );
    }
    film
}

/// What every pass works with.
struct PassContext<'a> {
    scene: &'a Scene,
    sppm: &'a SppmIntegrator,
    estimator: &'a SampleEstimator<'a>,
    options: &'a RenderOptions,
    cancel: &'a Cancel<'a>,
    progress: &'a dyn ProgressReport,
}

impl PassContext<'_> {
    /// Runs pass `pass`, updating `state` (row-major over the crop window, rows `width` wide);
    /// returns the rays traced, or None when the pass was cancelled.
    fn run(&self, pass: u32, state: &mut [PixelState], width: usize) -> Option<u64> {
        let film = &self.scene.film;
        let lambda = SampledWavelengths::sample(
            pass_wavelength(self.options.seed, pass),
            film.wavelength_sampling,
        );
        let (photons, mut rays) = self.trace_photons(pass, &lambda)?;
        let largest = state.iter().map(|s| s.radius).fold(0.0, f64::max) as f32;
        let map = PhotonMap::new(&photons, largest);
        let filter = FilterSampler::new(film.filter);
        let rows: Vec<Option<u64>> = state
            .par_chunks_mut(width)
            .enumerate()
            .map(|(y, row)| self.gather_row(pass, y as u32, row, &lambda, &map, &filter))
            .collect();
        for row in rows {
            rays += row?;
        }
        Some(rays)
    }

    /// The photons of pass `pass`, in the order of their indices, and the rays traced.
    fn trace_photons(&self, pass: u32, lambda: &SampledWavelengths) -> Option<(Vec<Photon>, u64)> {
        let count = self.sppm.photon_count;
        let granularity = self.sppm.granularity.unwrap_or(DEFAULT_GRANULARITY).max(1);
        let tasks: Vec<(u32, u32)> = (0..count)
            .step_by(granularity as usize)
            .map(|first| (first, (first + granularity).min(count)))
            .collect();
        let traced: Vec<Option<(Vec<Photon>, u64)>> = tasks
            .par_iter()
            .map(|&(first, end)| {
                if self.cancel.raised() {
                    return None;
                }
                let scene = self.scene;
                let prepared = &self.estimator.integrator;
                let seed = hash_u64s(&[self.options.seed, PHOTON_STREAM]);
                let mut sampler = Sampler::new(SamplerKind::Independent, 1, seed);
                let mut count = RayCount::default();
                let mut photons = Vec::new();
                for index in first..end {
                    sampler.start_pixel_sample(UVec2::new(index, 0), pass);
                    let (time, time_weight) = scene.shutter.sample(sampler.next_1d());
                    self.sppm.trace_photon(
                        prepared,
                        &mut sampler,
                        &mut count,
                        lambda,
                        time,
                        time_weight,
                        &mut photons,
                    );
                }
                Some((photons, count.rays))
            })
            .collect();
        let mut photons = Vec::new();
        let mut rays = 0;
        for task in traced {
            let (task_photons, task_rays) = task?;
            photons.extend(task_photons);
            rays += task_rays;
        }
        Some((photons, rays))
    }

    /// Traces the camera paths of row `y` of the crop window in pass `pass` and updates its
    /// pixels' statistics; returns the rays traced, or None when the pass was cancelled.
    fn gather_row(
        &self,
        pass: u32,
        y: u32,
        row: &mut [PixelState],
        lambda: &SampledWavelengths,
        map: &PhotonMap<Photon>,
        filter: &FilterSampler,
    ) -> Option<u64> {
        if self.cancel.raised() {
            return None;
        }
        let scene = self.scene;
        let film = &scene.film;
        let prepared = &self.estimator.integrator;
        let alpha = f64::from(self.sppm.alpha);
        let mut sampler = Sampler::new(
            scene.sampler.kind,
            self.options.samples_per_pixel,
            self.options.seed,
        );
        let mut count = RayCount::default();
        for (x, state) in row.iter_mut().enumerate() {
            let pixel = film.crop.offset + UVec2::new(x as u32, y);
            sampler.start_pixel_sample(pixel, pass);
            let primary = sampler.camera_sample();
            let (offset, filter_weight) = filter.sample(primary.film);
            let (time, time_weight) = scene.shutter.sample(primary.time);
            let film_position = pixel.as_vec2() + Vec2::splat(0.5) + offset;
            let CameraRay { ray, weight } =
                scene.camera.generate_ray(film_position, primary.lens, time);
            let mut estimate = self.sppm.estimate(
                prepared,
                &mut sampler,
                &mut count,
                ray,
                weight * filter_weight * time_weight,
                lambda,
                map,
                state.radius as f32,
            );
            if let Some(response) = &film.response {
                let response = response.sample(lambda);
                estimate.direct *= response;
                estimate.flux *= response;
            }
            let direct = lambda.to_xyz(&estimate.direct);
            let flux = lambda.to_xyz(&estimate.flux);
            if !direct.iter().chain(&flux).all(|v| v.is_finite()) {
                continue;
            }
            for (sum, v) in state.direct.iter_mut().zip(direct) {
                *sum += f64::from(v);
            }
            state.gather(alpha, flux.map(f64::from), estimate.photons);
        }
        self.progress.advance(row.len() as u64);
        Some(count.rays)
    }
}
