//! The render driver: the image is rendered in passes, each adding samples to every pixel;
//! within a pass the tiles of the crop window are rendered in parallel on a rayon pool.
//!
//! Every pixel sample draws its random numbers from the sampler's stream for (seed, pixel,
//! sample index), every sample lands in its own pixel, and each pixel adds its samples to its
//! sums in index order, pass after pass. The image is therefore bit-identical whatever the
//! number of threads, the order in which tiles finish, and the way the samples are split into
//! passes.
//!
//! A pass is committed only when all its tiles are done: a pass cut short (by the time limit or
//! an interruption) is dropped whole, so every pixel always has the same number of samples and
//! the image stays an unbiased, correctly normalised estimate whenever the render stops.
//!
//! Stopping rules: a fixed number of samples per pixel, a time limit, and a target for the mean
//! relative standard error of the image ([`relative_error`]), whichever comes first.

pub mod stats;

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

use glam::{UVec2, Vec2};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::film::{Film, FilterSampler, PixelSums};
use crate::integrator::RayCount;
use crate::sampling::sampler::Sampler;
use crate::scene::Scene;
use crate::spectrum::SampledWavelengths;
pub use stats::relative_error;

/// Edge length of the square tiles the image is divided into.
const TILE_SIZE: u32 = 16;

/// Largest pass, in samples per pixel, of a render with a stopping rule (so that the rule is
/// checked often enough).
const MAX_PASS: u32 = 64;

/// When a render stops.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StopRule {
    /// Stop after this many samples per pixel (None: no limit).
    pub samples_per_pixel: Option<u32>,
    /// Stop when this much time has passed; the pass running then is dropped.
    pub time_limit: Option<Duration>,
    /// Stop once the image's mean relative standard error is at most this.
    pub target_error: Option<f64>,
}

impl StopRule {
    /// Render exactly `n` samples per pixel.
    pub fn samples(n: u32) -> StopRule {
        StopRule {
            samples_per_pixel: Some(n),
            ..StopRule::default()
        }
    }

    fn is_open_ended(&self) -> bool {
        self.time_limit.is_some() || self.target_error.is_some()
    }
}

/// How to render.
#[derive(Clone, Debug)]
pub struct RenderOptions {
    /// Samples per pixel over which the sampler stratifies (N); samples beyond N start new
    /// stratified blocks. Stratified samplers may round it up
    /// (see [`crate::sampling::sampler::SamplerKind::sample_count`]).
    pub samples_per_pixel: u32,
    pub stop: StopRule,
    /// Worker threads; None for one per core.
    pub threads: Option<usize>,
    /// Seed of every random stream.
    pub seed: u64,
    /// Whether to draw a progress bar on standard error.
    pub progress: bool,
}

impl RenderOptions {
    /// Options for rendering exactly `spp` samples per pixel.
    pub fn fixed(spp: u32, seed: u64, threads: Option<usize>) -> RenderOptions {
        RenderOptions {
            samples_per_pixel: spp,
            stop: StopRule::samples(spp),
            threads,
            seed,
            progress: false,
        }
    }
}

/// Why a render stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// All requested samples were taken.
    Completed,
    TimeLimit,
    TargetError,
}

/// What a render produced.
pub struct RenderOutput {
    pub film: Film,
    /// Samples per pixel taken (the same in every pixel).
    pub samples_per_pixel: u32,
    pub elapsed: Duration,
    /// Camera samples taken.
    pub samples: u64,
    /// Rays traced (camera, bounce and shadow rays).
    pub rays: u64,
    pub stop: StopReason,
    /// The mean relative standard error of the image at the end.
    pub relative_error: f64,
}

/// A rectangle of pixels, in crop-window coordinates.
#[derive(Clone, Copy, Debug)]
struct Tile {
    origin: UVec2,
    size: UVec2,
}

fn tiles(size: UVec2) -> Vec<Tile> {
    let mut tiles = Vec::new();
    for y in (0..size.y).step_by(TILE_SIZE as usize) {
        for x in (0..size.x).step_by(TILE_SIZE as usize) {
            let origin = UVec2::new(x, y);
            tiles.push(Tile {
                origin,
                size: (size - origin).min(UVec2::splat(TILE_SIZE)),
            });
        }
    }
    tiles
}

/// Tells a pass to stop: raised by whoever notices the deadline first (or from outside).
struct Cancel<'a> {
    flag: &'a AtomicBool,
    deadline: Option<Instant>,
}

impl Cancel<'_> {
    fn raised(&self) -> bool {
        if self.deadline.is_some_and(|d| Instant::now() >= d) {
            self.flag.store(true, Ordering::Relaxed);
        }
        self.flag.load(Ordering::Relaxed)
    }
}

/// Adds the samples `range` of every pixel of a tile to a copy of its sums; None when the pass
/// was cancelled before the tile was done.
fn render_tile(
    scene: &Scene,
    filter: &FilterSampler,
    tile: Tile,
    sums: &[PixelSums],
    range: std::ops::Range<u32>,
    options: &RenderOptions,
    cancel: &Cancel,
) -> Option<(Vec<PixelSums>, u64)> {
    let mut sampler = Sampler::new(scene.sampler.kind, options.samples_per_pixel, options.seed);
    let mut count = RayCount::default();
    let mut pixels = sums.to_vec();
    let crop_offset = scene.film.crop.offset;
    for y in 0..tile.size.y {
        if cancel.raised() {
            return None;
        }
        for x in 0..tile.size.x {
            let pixel = crop_offset + tile.origin + UVec2::new(x, y);
            let pixel_sums = &mut pixels[(y * tile.size.x + x) as usize];
            for index in range.clone() {
                sampler.start_pixel_sample(pixel, index);
                let primary = sampler.camera_sample();
                let lambda =
                    SampledWavelengths::sample(primary.wavelength, scene.wavelength_sampling);
                let (offset, filter_weight) = filter.sample(primary.film);
                let (time, time_weight) = scene.shutter.sample(primary.time);
                let film_position = pixel.as_vec2() + Vec2::splat(0.5) + offset;
                let ray = scene.camera.generate_ray(film_position, primary.lens, time);
                let radiance =
                    scene
                        .integrator
                        .radiance(scene, ray, &lambda, &mut sampler, &mut count);
                let weight = filter_weight * time_weight;
                pixel_sums.add(lambda.to_xyz(&radiance).map(|v| v * weight));
            }
        }
    }
    Some((pixels, count.rays))
}

/// The number of samples per pixel of the next pass.
fn next_pass(done: u32, stop: &StopRule, elapsed: Duration, error: f64) -> u32 {
    let left = stop
        .samples_per_pixel
        .map_or(u32::MAX, |limit| limit.saturating_sub(done));
    if !stop.is_open_ended() {
        return left;
    }
    // Passes grow geometrically from one sample, so the rules are checked early and often.
    let mut pass = done.clamp(1, MAX_PASS);
    if let Some(target) = stop.target_error
        && done > 0
        && error.is_finite()
    {
        // The error falls as 1/√n: n·(error/target)² samples reach the target.
        let needed = (f64::from(done) * (error / target).powi(2)).ceil() as u32;
        pass = pass.min(needed.saturating_sub(done).max(1));
    }
    if let Some(limit) = stop.time_limit
        && done > 0
    {
        let per_sample = elapsed.as_secs_f64() / f64::from(done);
        let remaining = limit.saturating_sub(elapsed).as_secs_f64();
        pass = pass.min(((remaining / per_sample) as u32).max(1));
    }
    pass.min(left)
}

/// Renders the scene.
pub fn render(scene: &Scene, options: &RenderOptions) -> Result<RenderOutput> {
    let crop = scene.film.crop;
    let filter = FilterSampler::new(scene.film.filter);
    let tiles = tiles(crop.size);
    let pixel_count = u64::from(crop.size.x) * u64::from(crop.size.y);
    let mut stop = options.stop;
    if let Some(limit) = &mut stop.samples_per_pixel {
        *limit = scene.sampler.kind.sample_count(*limit);
    }
    let options = RenderOptions {
        samples_per_pixel: scene.sampler.kind.sample_count(options.samples_per_pixel),
        stop,
        ..options.clone()
    };

    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(threads) = options.threads {
        builder = builder.num_threads(threads);
    }
    let pool = builder
        .build()
        .map_err(|e| Error::usage(format!("could not start the worker threads: {e}")))?;

    let progress = progress_bar(&options, pixel_count);
    let mut sums: Vec<Vec<PixelSums>> = tiles
        .iter()
        .map(|t| vec![PixelSums::default(); (t.size.x * t.size.y) as usize])
        .collect();
    let rays = AtomicU64::new(0);
    let abort = AtomicBool::new(false);
    let start = Instant::now();
    let mut done = 0u32;
    let mut error = f64::INFINITY;
    let reason = loop {
        if stop.samples_per_pixel.is_some_and(|limit| done >= limit) {
            break StopReason::Completed;
        }
        if stop.target_error.is_some_and(|target| error <= target) {
            break StopReason::TargetError;
        }
        if stop
            .time_limit
            .is_some_and(|limit| start.elapsed() >= limit)
        {
            break StopReason::TimeLimit;
        }
        let pass = next_pass(done, &stop, start.elapsed(), error);
        let range = done..done + pass;
        let cancel = Cancel {
            flag: &abort,
            deadline: stop.time_limit.map(|limit| start + limit),
        };
        let results: Vec<Option<(Vec<PixelSums>, u64)>> = pool.install(|| {
            tiles
                .par_iter()
                .zip(&sums)
                .map(|(&tile, tile_sums)| {
                    let result = render_tile(
                        scene,
                        &filter,
                        tile,
                        tile_sums,
                        range.clone(),
                        &options,
                        &cancel,
                    );
                    if result.is_some() {
                        progress.inc(u64::from(tile.size.x * tile.size.y) * u64::from(pass));
                    }
                    result
                })
                .collect()
        });
        if abort.load(Ordering::Relaxed) || results.iter().any(Option::is_none) {
            break StopReason::TimeLimit;
        }
        for (tile_sums, (new_sums, tile_rays)) in sums.iter_mut().zip(results.into_iter().flatten())
        {
            *tile_sums = new_sums;
            rays.fetch_add(tile_rays, Ordering::Relaxed);
        }
        done += pass;
        error = relative_error(sums.iter().flatten());
        if stop.is_open_ended() {
            progress.set_message(format!("{done} spp, error {error:.4}"));
        }
    };
    let elapsed = start.elapsed();
    progress.finish_and_clear();

    let mut film = Film::new(scene.film.size, crop);
    for (tile, tile_sums) in tiles.iter().zip(&sums) {
        for y in 0..tile.size.y {
            for x in 0..tile.size.x {
                let index = film.index(tile.origin.x + x, tile.origin.y + y);
                film.pixels[index] = tile_sums[(y * tile.size.x + x) as usize];
            }
        }
    }
    Ok(RenderOutput {
        film,
        samples_per_pixel: done,
        elapsed,
        samples: pixel_count * u64::from(done),
        rays: rays.into_inner(),
        stop: reason,
        relative_error: error,
    })
}

fn progress_bar(options: &RenderOptions, pixel_count: u64) -> ProgressBar {
    if !options.progress {
        return ProgressBar::hidden();
    }
    let template = if options.stop.is_open_ended() {
        "{spinner} {elapsed_precise} {human_pos} samples, {per_sec} — {msg}"
    } else {
        "{bar:40.cyan/blue} {percent:>3}% {human_pos}/{human_len} samples, {per_sec}, ETA {eta}"
    };
    let total = options
        .stop
        .samples_per_pixel
        .filter(|_| !options.stop.is_open_ended())
        .map(|n| pixel_count * u64::from(n));
    let bar = ProgressBar::with_draw_target(total, ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template(template).unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}
