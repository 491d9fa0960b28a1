//! The render driver: the image is rendered in passes, each adding samples to every pixel;
//! within a pass the tiles of the crop window are rendered in parallel on a rayon pool.
//!
//! Every pixel sample draws its random numbers from the sampler's stream for (seed, pixel,
//! sample index), and pixel sums are exact (order-free). Under the one-pixel reconstruction
//! every sample lands in its own pixel; under filter MIS ([`crate::film::reconstruction`]) the
//! samples of a batch of indices are first traced for every pixel within the filter's reach of
//! the crop window and kept, then every pixel gathers, index by index, what its neighbours'
//! samples bring it, always in the same order. Either way the image is bit-identical whatever
//! the number of threads, the order in which tiles finish, the way the samples are split into
//! passes and batches, the crop window, and whether the render was interrupted, resumed or
//! assembled from several renders of disjoint sample ranges.
//!
//! A pass is committed only when all its tiles are done: a pass cut short (by the time limit or
//! an interruption) is dropped whole, so every pixel always has the same number of samples and
//! the image stays an unbiased, correctly normalised estimate whenever the render stops.
//!
//! Stopping rules: the end of the requested sample range, a time limit, and a target for the
//! image's mean relative standard error ([`relative_error`]), whichever comes first; and an
//! interruption from outside (a signal).

pub mod state;

use std::ops::Range;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

use glam::{UVec2, Vec2, Vec4};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;

use crate::camera::CameraModel;
use crate::error::{Error, Result};
use crate::film::accumulation::{
    AOV_SUMS_PER_CHANNEL, acceptable_sample, add_aov_sample, add_shared_aov_sample,
};
pub use crate::film::stats::relative_error;
use crate::film::{Film, FilterMis, FilterSampler, PixelSums, ValueSum};
use crate::integrator::{PreparedIntegrator, RayCount};
use crate::sampling::sampler::Sampler;
use crate::scene::Scene;
use crate::spectrum::SampledWavelengths;

/// Stack of each worker thread: the distribution ray tracer recurses once per bounce, with a
/// vertex's BSDF on the stack (about 2 KiB a level), and its roulette lets long specular chains
/// run to depths of a few hundred. Only the pages used are ever touched.
const WORKER_STACK_BYTES: usize = 64 << 20;

/// Edge length of the square tiles the image is divided into.
const TILE_SIZE: u32 = 16;

/// Under filter MIS, the samples kept for one batch of sample indices take at most about this
/// many bytes (a batch has at least one index).
const SHARED_SAMPLES_BYTES: usize = 64 << 20;

/// A render made of several passes aims at passes of about this length, so that stopping rules,
/// checkpoints and interruptions are acted on promptly and little work is dropped.
const TARGET_PASS_TIME: Duration = Duration::from_secs(2);

/// When a render stops (besides an interruption).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StopRule {
    /// Stop before this sample index (None: no limit).
    pub sample_end: Option<u32>,
    /// Stop when this much time has passed; the pass running then is dropped.
    pub time_limit: Option<Duration>,
    /// Stop once the image's mean relative standard error is at most this.
    pub target_error: Option<f64>,
}

impl StopRule {
    /// Render the samples 0..n.
    pub fn samples(n: u32) -> StopRule {
        StopRule {
            sample_end: Some(n),
            ..StopRule::default()
        }
    }

    /// The rule for a render asked for `spp` samples per pixel (None: the scene's `scene_spp`),
    /// a time limit in seconds and a target for the mean relative error. Without a time limit
    /// or target error the render takes exactly the samples; with either, `spp` (if given) only
    /// caps them. Messages call the three settings by `names`, as the caller's user knows them.
    pub fn requested(
        spp: Option<u32>,
        scene_spp: u32,
        time_limit: Option<f64>,
        target_error: Option<f64>,
        names: &StopRuleNames,
    ) -> Result<StopRule> {
        if spp == Some(0) {
            return Err(Error::usage(format!("{} must be at least 1", names.spp)));
        }
        let time_limit = match time_limit {
            Some(t) if !(t > 0.0 && t.is_finite()) => {
                return Err(Error::usage(format!(
                    "{} must be a positive number of seconds, not {t}",
                    names.time_limit
                )));
            }
            t => t.map(Duration::from_secs_f64),
        };
        if let Some(e) = target_error
            && !(e > 0.0 && e.is_finite())
        {
            return Err(Error::usage(format!(
                "{} must be positive, not {e}",
                names.target_error
            )));
        }
        let open_ended = time_limit.is_some() || target_error.is_some();
        Ok(StopRule {
            sample_end: if open_ended {
                spp
            } else {
                Some(spp.unwrap_or(scene_spp))
            },
            time_limit,
            target_error,
        })
    }

    fn is_open_ended(&self) -> bool {
        self.time_limit.is_some() || self.target_error.is_some()
    }
}

/// What the settings of [`StopRule::requested`] are called where they were given (command-line
/// options, or a function's arguments).
pub struct StopRuleNames {
    pub spp: &'static str,
    pub time_limit: &'static str,
    pub target_error: &'static str,
}

/// How to render.
#[derive(Clone, Debug)]
pub struct RenderOptions {
    /// Samples per pixel over which the sampler stratifies (N); samples beyond N start new
    /// stratified blocks. Stratified samplers may round it up
    /// (see [`crate::sampling::sampler::SamplerKind::sample_count`]).
    pub samples_per_pixel: u32,
    /// Index of the first sample to take in every pixel (past a checkpoint, or the start of a
    /// range given to this render).
    pub first_sample: u32,
    /// Sums the render starts from (a resumed render's), row-major over the crop window: the
    /// image's, and the extra channels' (2K per pixel, as [`Film::aovs`] holds them).
    pub initial: Option<(Vec<PixelSums>, Vec<ValueSum>)>,
    pub stop: StopRule,
    /// Raised from outside (by a signal handler) to stop the render after dropping its pass.
    pub interrupt: Option<Arc<AtomicBool>>,
    /// Worker threads; None for one per core.
    pub threads: Option<usize>,
    /// Seed of every random stream.
    pub seed: u64,
    /// How to report progress.
    pub progress: Progress,
}

/// How a render reports its progress.
#[derive(Clone, Debug, Default)]
pub enum Progress {
    #[default]
    Hidden,
    /// A progress bar on standard error.
    Terminal,
    /// Counts kept in a shared [`ProgressCounter`], read by a caller that shows them itself
    /// (the Python module's progress bar).
    Counter(Arc<ProgressCounter>),
}

/// A render's progress, updated by the render as tiles finish and readable from any thread.
#[derive(Debug, Default)]
pub struct ProgressCounter {
    samples: AtomicU64,
    /// The camera samples the render will take, or 0 when it is open-ended.
    total: AtomicU64,
    /// The image's mean relative error after the last pass, as `f64` bits.
    error_bits: AtomicU64,
}

impl ProgressCounter {
    /// Camera samples taken so far.
    pub fn samples(&self) -> u64 {
        self.samples.load(Ordering::Relaxed)
    }

    /// Camera samples the render will take; None when a time limit or target error ends it.
    pub fn total(&self) -> Option<u64> {
        Some(self.total.load(Ordering::Relaxed)).filter(|&t| t > 0)
    }

    /// The image's mean relative standard error after the last finished pass (infinite
    /// before).
    pub fn relative_error(&self) -> f64 {
        match self.error_bits.load(Ordering::Relaxed) {
            0 => f64::INFINITY,
            bits => f64::from_bits(bits),
        }
    }
}

impl RenderOptions {
    /// Options for rendering the samples 0..spp in one go.
    pub fn fixed(spp: u32, seed: u64, threads: Option<usize>) -> RenderOptions {
        RenderOptions {
            samples_per_pixel: spp,
            first_sample: 0,
            initial: None,
            stop: StopRule::samples(spp),
            interrupt: None,
            threads,
            seed,
            progress: Progress::Hidden,
        }
    }

    /// Whether the render goes in several passes: when it can be stopped early or checkpointed.
    fn in_passes(&self, checkpoints: bool) -> bool {
        checkpoints || self.interrupt.is_some() || self.stop.is_open_ended()
    }
}

/// Why a render stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// All requested samples were taken.
    Completed,
    TimeLimit,
    TargetError,
    Interrupted,
}

/// The state of a render between two passes, handed to the checkpoint writer.
pub struct Snapshot<'a> {
    /// The sample indices every pixel has had in this render (after its initial state).
    pub samples: Range<u32>,
    /// Pixel sums, row-major over the crop window (including the initial state).
    pub pixels: &'a [PixelSums],
    /// The extra channels' sums, 2K per pixel in the same order.
    pub aovs: &'a [ValueSum],
}

/// Something that saves the render's state every so often.
pub struct Checkpoints<'a> {
    pub every: Duration,
    pub write: &'a mut dyn FnMut(&Snapshot) -> Result<()>,
}

/// What a render produced.
pub struct RenderOutput {
    /// Pixel sums, including the initial state.
    pub film: Film,
    /// The sample indices taken in this render.
    pub samples: Range<u32>,
    pub elapsed: Duration,
    /// Camera samples taken in this render.
    pub sample_count: u64,
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

/// Tells a pass to stop: raised by whoever notices the deadline first, or from outside.
struct Cancel<'a> {
    flag: &'a AtomicBool,
    external: Option<&'a AtomicBool>,
    deadline: Option<Instant>,
}

impl Cancel<'_> {
    fn raised(&self) -> bool {
        if self.deadline.is_some_and(|d| Instant::now() >= d)
            || self.external.is_some_and(|e| e.load(Ordering::Relaxed))
        {
            self.flag.store(true, Ordering::Relaxed);
        }
        self.flag.load(Ordering::Relaxed)
    }
}

/// What every camera sample of a render uses: the scene, its integrator prepared for the
/// scene's world, the sampler of the reconstruction filter, and filter MIS's weights when the
/// samples are shared between pixels.
pub struct SampleEstimator<'a> {
    scene: &'a Scene,
    integrator: PreparedIntegrator<'a>,
    filter: FilterSampler,
    shared: Option<FilterMis>,
}

impl<'a> SampleEstimator<'a> {
    pub fn new(scene: &'a Scene) -> SampleEstimator<'a> {
        let film = &scene.film;
        SampleEstimator {
            scene,
            integrator: scene.integrator.prepare(&scene.world),
            filter: FilterSampler::new(film.filter),
            shared: film
                .reconstruction
                .shares_samples(film.filter)
                .then(|| FilterMis::new(film.filter, film.size.x, film.size.y)),
        }
    }

    /// How many extra channels each sample writes.
    pub fn aov_count(&self) -> usize {
        self.integrator.aov_count()
    }

    /// Traces sample `index` of `pixel` (full-film coordinates): its film offset from the
    /// pixel's centre, the filter weight the one-pixel estimator gives it, and its CIE XYZ
    /// weighted by the shutter's filter; its extra channels, weighted alike, go to `aovs`.
    fn trace(
        &self,
        sampler: &mut Sampler,
        pixel: UVec2,
        index: u32,
        count: &mut RayCount,
        aovs: &mut [f32],
    ) -> (Vec2, f32, [f32; 3]) {
        let scene = self.scene;
        sampler.start_pixel_sample(pixel, index);
        let primary = sampler.camera_sample();
        let lambda = SampledWavelengths::sample(primary.wavelength, scene.film.wavelength_sampling);
        let (offset, filter_weight) = self.filter.sample(primary.film);
        let (time, time_weight) = scene.shutter.sample(primary.time);
        let film_position = pixel.as_vec2() + Vec2::splat(0.5) + offset;
        let ray = scene.camera.generate_ray(film_position, primary.lens, time);
        let radiance = self.integrator.radiance(ray, &lambda, sampler, count, aovs);
        for v in aovs.iter_mut() {
            *v *= time_weight;
        }
        let xyz = lambda.to_xyz(&radiance).map(|v| v * time_weight);
        (offset, filter_weight, xyz)
    }

    /// The one-pixel estimate of sample `index` of `pixel` (full-film coordinates): its
    /// filter-weighted CIE XYZ; the sample's extra channels, weighted by the same filter weight,
    /// go to `aovs`. Under filter MIS the same sample also feeds the pixels around.
    pub fn estimate(
        &self,
        sampler: &mut Sampler,
        pixel: UVec2,
        index: u32,
        count: &mut RayCount,
        aovs: &mut [f32],
    ) -> [f32; 3] {
        let (_, weight, xyz) = self.trace(sampler, pixel, index, count, aovs);
        for v in aovs.iter_mut() {
            *v *= weight;
        }
        xyz.map(|v| v * weight)
    }
}

/// The sums of a tile's pixels, row-major within the tile: the image's and the extra channels'
/// (2K per pixel).
#[derive(Clone, Debug, Default)]
struct TileSums {
    pixels: Vec<PixelSums>,
    aovs: Vec<ValueSum>,
}

/// Adds the samples `range` of every pixel of a tile to a copy of its sums; None when the pass
/// was cancelled before the tile was done.
fn render_tile(
    estimator: &SampleEstimator,
    tile: Tile,
    sums: &TileSums,
    range: Range<u32>,
    options: &RenderOptions,
    cancel: &Cancel,
) -> Option<(TileSums, u64)> {
    let scene = estimator.scene;
    let mut sampler = Sampler::new(scene.sampler.kind, options.samples_per_pixel, options.seed);
    let mut count = RayCount::default();
    let mut sums = sums.clone();
    let k = estimator.aov_count();
    let stride = AOV_SUMS_PER_CHANNEL * k;
    // One sample's extra channels, reused for every sample of the tile.
    let mut aovs = vec![0.0f32; k];
    let crop_offset = scene.film.crop.offset;
    for y in 0..tile.size.y {
        if cancel.raised() {
            return None;
        }
        for x in 0..tile.size.x {
            let pixel = crop_offset + tile.origin + UVec2::new(x, y);
            let i = (y * tile.size.x + x) as usize;
            for index in range.clone() {
                aovs.fill(0.0);
                let xyz = estimator.estimate(&mut sampler, pixel, index, &mut count, &mut aovs);
                sums.pixels[i].add(xyz);
                add_aov_sample(&mut sums.aovs[i * stride..i * stride + k], &aovs);
            }
        }
    }
    Some((sums, count.rays))
}

/// What every pass of a render works with.
struct Pass<'p, 's> {
    estimator: &'p SampleEstimator<'s>,
    tiles: &'p [Tile],
    options: &'p RenderOptions,
    cancel: &'p Cancel<'p>,
    progress: &'p ProgressSink,
}

impl Pass<'_, '_> {
    /// Adds the samples `range` of every pixel to copies of the tiles' `sums`, in parallel; None
    /// when the pass was cancelled.
    fn render(&self, sums: &[TileSums], range: Range<u32>) -> Option<(Vec<TileSums>, u64)> {
        match &self.estimator.shared {
            Some(mis) => self.render_shared(mis, sums, range),
            None => self.render_one_pixel(sums, range),
        }
    }

    /// The one-pixel reconstruction: every tile's pixels take their own samples.
    fn render_one_pixel(
        &self,
        sums: &[TileSums],
        range: Range<u32>,
    ) -> Option<(Vec<TileSums>, u64)> {
        let pass = u64::from(range.end - range.start);
        let (estimator, options, cancel) = (self.estimator, self.options, self.cancel);
        let results: Vec<Option<(TileSums, u64)>> = self
            .tiles
            .par_iter()
            .zip(sums)
            .map(|(&tile, tile_sums)| {
                let result =
                    render_tile(estimator, tile, tile_sums, range.clone(), options, cancel);
                if result.is_some() {
                    self.progress
                        .add(u64::from(tile.size.x * tile.size.y) * pass);
                }
                result
            })
            .collect();
        let mut rays = 0;
        let mut new_sums = Vec::with_capacity(results.len());
        for result in results {
            let (tile_sums, tile_rays) = result?;
            new_sums.push(tile_sums);
            rays += tile_rays;
        }
        Some((new_sums, rays))
    }

    /// Filter MIS: for each batch of sample indices, the samples of every pixel within reach of
    /// the crop window are traced, then every pixel of the crop gathers what each index brings
    /// it from the (2·reach + 1)² pixels around, always in the same order, and adds the totals
    /// of each index to its sums ([`PixelSums::add_shared`]).
    fn render_shared(
        &self,
        mis: &FilterMis,
        sums: &[TileSums],
        range: Range<u32>,
    ) -> Option<(Vec<TileSums>, u64)> {
        let estimator = self.estimator;
        let film = &estimator.scene.film;
        let reach = UVec2::splat(mis.reach());
        let origin = film.crop.offset.saturating_sub(reach);
        let end = (film.crop.offset + film.crop.size + reach).min(film.size);
        let size = end - origin;
        let k = estimator.aov_count();
        let bytes_per_index = SharedSamples::bytes_per_index(size, k, mis.reach());
        let batch = (SHARED_SAMPLES_BYTES / bytes_per_index)
            .clamp(1, (range.end - range.start) as usize) as u32;
        let mut samples = SharedSamples::new(origin, size, batch, k, mis.reach());
        let mut new_sums = sums.to_vec();
        let mut rays = 0;
        let mut start = range.start;
        while start < range.end {
            let batch_range = start..(start + batch).min(range.end);
            rays += samples.trace(
                estimator,
                mis,
                batch_range.clone(),
                self.options,
                self.cancel,
            )?;
            new_sums
                .par_iter_mut()
                .zip(self.tiles)
                .for_each(|(tile_sums, &tile)| {
                    gather_tile(
                        estimator,
                        mis,
                        &samples,
                        tile,
                        tile_sums,
                        batch_range.clone(),
                        self.options,
                    );
                    let pixels = u64::from(tile.size.x * tile.size.y);
                    self.progress
                        .add(pixels * u64::from(batch_range.end - batch_range.start));
                });
            start = batch_range.end;
        }
        Some((new_sums, rays))
    }
}

/// The samples of one batch of sample indices, traced for every pixel of a rectangle of the
/// film (the crop window and the filter's reach m around it). Per pixel and index: the factor
/// 1 / ((∫k)² D) of the sample (NaN: the sample was rejected), its XYZ and extra channels times
/// that factor, and the filter's values k(o − j) on each axis for the pixels j = −m..m away
/// (o the sample's offset from its pixel's centre), computed once here rather than by each of
/// the (2m + 1)² pixels that gather the sample.
struct SharedSamples {
    origin: UVec2,
    size: UVec2,
    indices: u32,
    /// Extra channels per sample (K).
    aovs: usize,
    /// Pixels the filter reaches on each side (m).
    reach: usize,
    /// Floats per sample: 4 + K + 2 (2m + 1).
    stride: usize,
    values: Vec<f32>,
}

impl SharedSamples {
    const SCALE: usize = 0;
    const XYZ: usize = 1;
    const AOVS: usize = 4;

    fn new(origin: UVec2, size: UVec2, indices: u32, aovs: usize, reach: u32) -> SharedSamples {
        let reach = reach as usize;
        let stride = Self::AOVS + aovs + 2 * (2 * reach + 1);
        SharedSamples {
            origin,
            size,
            indices,
            aovs,
            reach,
            stride,
            values: vec![0.0; size.x as usize * size.y as usize * indices as usize * stride],
        }
    }

    /// The bytes a batch takes per sample index.
    fn bytes_per_index(size: UVec2, aovs: usize, reach: u32) -> usize {
        let stride = Self::AOVS + aovs + 2 * (2 * reach as usize + 1);
        size.x as usize * size.y as usize * stride * std::mem::size_of::<f32>()
    }

    /// The first `n` samples of the batch of film pixel `pixel` (inside the rectangle).
    #[inline]
    fn records(&self, pixel: UVec2, n: usize) -> &[f32] {
        let local = pixel - self.origin;
        let i = (local.y * self.size.x + local.x) as usize * self.indices as usize * self.stride;
        &self.values[i..i + n * self.stride]
    }

    /// Where in a sample the filter's value on the x axis (then the y axis) for the pixel j − m
    /// away is, j = 0..2m.
    #[inline]
    fn kernel_x_at(&self, j: usize) -> usize {
        Self::AOVS + self.aovs + j
    }

    #[inline]
    fn kernel_y_at(&self, j: usize) -> usize {
        Self::AOVS + self.aovs + 2 * self.reach + 1 + j
    }

    /// Traces the samples `range` (at most `self.indices` of them) of every pixel, in parallel
    /// over rows. None when the pass was cancelled.
    fn trace(
        &mut self,
        estimator: &SampleEstimator,
        mis: &FilterMis,
        range: Range<u32>,
        options: &RenderOptions,
        cancel: &Cancel,
    ) -> Option<u64> {
        let (stride, origin, indices) = (self.stride, self.origin, self.indices as usize);
        let (k, reach) = (self.aovs, self.reach);
        let row_len = self.size.x as usize * indices * stride;
        let rays: Vec<Option<u64>> = self
            .values
            .par_chunks_mut(row_len)
            .enumerate()
            .map(|(row, values)| {
                if cancel.raised() {
                    return None;
                }
                let kind = estimator.scene.sampler.kind;
                let mut sampler = Sampler::new(kind, options.samples_per_pixel, options.seed);
                let mut count = RayCount::default();
                let mut aovs = vec![0.0f32; k];
                let batch = (range.end - range.start) as usize;
                let records = values
                    .chunks_exact_mut(indices * stride)
                    .enumerate()
                    .flat_map(|(column, records)| {
                        let pixel = origin + UVec2::new(column as u32, row as u32);
                        let records = records.chunks_exact_mut(stride).take(batch);
                        records.enumerate().map(move |(s, r)| (pixel, s, r))
                    });
                for (pixel, s, record) in records {
                    let index = range.start + s as u32;
                    aovs.fill(0.0);
                    let (offset, _, xyz) =
                        estimator.trace(&mut sampler, pixel, index, &mut count, &mut aovs);
                    if !acceptable_sample(&xyz) {
                        record[Self::SCALE] = f32::NAN;
                        continue;
                    }
                    // A point the density misses (none, for a sampled one) adds nothing.
                    let scale = mis.sample_scale(pixel, offset);
                    let scale = if scale.is_finite() { scale } else { 0.0 };
                    record[Self::SCALE] = scale;
                    for c in 0..3 {
                        record[Self::XYZ + c] = xyz[c] * scale;
                    }
                    let (channels, kernels) = record[Self::AOVS..].split_at_mut(k);
                    for (r, &v) in channels.iter_mut().zip(&aovs) {
                        *r = if acceptable_sample(&[v]) {
                            v * scale
                        } else {
                            0.0
                        };
                    }
                    // The layout of kernel_x_at and kernel_y_at.
                    let (kx, ky) = kernels.split_at_mut(2 * reach + 1);
                    for j in 0..=2 * reach {
                        let d = j as f32 - reach as f32;
                        kx[j] = mis.kernel(offset.x - d);
                        ky[j] = mis.kernel(offset.y - d);
                    }
                }
                Some(count.rays)
            })
            .collect();
        rays.into_iter().sum()
    }
}

/// Adds to every pixel of `tile` the totals of the sample indices `range` over the samples of
/// the pixels within reach, with its control variate's weight excess.
fn gather_tile(
    estimator: &SampleEstimator,
    mis: &FilterMis,
    samples: &SharedSamples,
    tile: Tile,
    sums: &mut TileSums,
    range: Range<u32>,
    options: &RenderOptions,
) {
    let film = &estimator.scene.film;
    let k = estimator.aov_count();
    let aov_stride = AOV_SUMS_PER_CHANNEL * k;
    let n = (range.end - range.start) as usize;
    let reach = mis.reach();
    let first = samples.origin;
    let last = samples.origin + samples.size - UVec2::ONE;
    // Per index: the weight total W and the XYZ total T, in the records' order (scale, XYZ).
    let mut totals = vec![Vec4::ZERO; n];
    let mut aovs = vec![0.0f32; n * k];
    let mut rejected = vec![false; n];
    let mut channels = vec![0.0f64; k];
    for y in 0..tile.size.y {
        for x in 0..tile.size.x {
            let pixel = film.crop.offset + tile.origin + UVec2::new(x, y);
            totals.fill(Vec4::ZERO);
            aovs.fill(0.0);
            rejected.fill(false);
            let from = pixel.saturating_sub(UVec2::splat(reach)).max(first);
            let to = (pixel + UVec2::splat(reach)).min(last);
            for sy in from.y..=to.y {
                let ky = samples.kernel_y_at((pixel.y + reach - sy) as usize);
                for sx in from.x..=to.x {
                    let kx = samples.kernel_x_at((pixel.x + reach - sx) as usize);
                    let source = UVec2::new(sx, sy);
                    let records = samples.records(source, n);
                    for (s, record) in records.chunks_exact(samples.stride).enumerate() {
                        let [scale, x, y, z] = [record[0], record[1], record[2], record[3]];
                        if scale.is_nan() {
                            rejected[s] |= source == pixel;
                            continue;
                        }
                        // Without a branch on w = 0 (half the neighbours' samples fall outside
                        // the pixel's support, unpredictably): adding zero is cheaper.
                        let w = record[kx] * record[ky];
                        totals[s] += w * Vec4::new(scale, x, y, z);
                        if k > 0 {
                            for (a, &v) in aovs[s * k..(s + 1) * k]
                                .iter_mut()
                                .zip(&record[SharedSamples::AOVS..SharedSamples::AOVS + k])
                            {
                                *a += w * v;
                            }
                        }
                    }
                }
            }
            let i = (y * tile.size.x + x) as usize;
            for s in 0..n {
                let index = range.start + s as u32;
                let second_half = (index / options.samples_per_pixel) % 2 == 1;
                let pixel_sums = &mut sums.pixels[i];
                let [weight, tx, ty, tz] = totals[s].to_array().map(f64::from);
                pixel_sums.add_shared([tx, ty, tz], weight - 1.0, second_half);
                if rejected[s] {
                    pixel_sums.count_rejected();
                }
                for (c, &v) in channels.iter_mut().zip(&aovs[s * k..(s + 1) * k]) {
                    *c = f64::from(v);
                }
                add_shared_aov_sample(
                    &mut sums.aovs[i * aov_stride..(i + 1) * aov_stride],
                    &channels,
                    second_half,
                );
            }
        }
    }
}

/// The number of samples per pixel of the next pass.
fn next_pass(
    in_passes: bool,
    done: u32,
    left: u32,
    stop: &StopRule,
    elapsed: Duration,
    error: f64,
) -> u32 {
    if !in_passes {
        return left;
    }
    // Passes grow geometrically from one sample, then keep to about TARGET_PASS_TIME.
    let mut pass = done.max(1);
    if done > 0 {
        let per_sample = elapsed.as_secs_f64() / f64::from(done);
        pass = pass.min((TARGET_PASS_TIME.as_secs_f64() / per_sample.max(1e-9)).ceil() as u32);
    }
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
    pass.clamp(1, left.max(1))
}

/// Renders the scene.
pub fn render(scene: &Scene, options: &RenderOptions) -> Result<RenderOutput> {
    render_with_checkpoints(scene, options, None)
}

/// Renders the scene, handing its state to `checkpoints` between passes every so often.
pub fn render_with_checkpoints(
    scene: &Scene,
    options: &RenderOptions,
    mut checkpoints: Option<Checkpoints>,
) -> Result<RenderOutput> {
    let crop = scene.film.crop;
    let estimator = SampleEstimator::new(scene);
    let tiles = tiles(crop.size);
    let pixel_count = u64::from(crop.size.x) * u64::from(crop.size.y);
    let options = RenderOptions {
        samples_per_pixel: scene.strata(options.samples_per_pixel),
        ..options.clone()
    };
    let stop = options.stop;
    let in_passes = options.in_passes(checkpoints.is_some());

    let mut builder = rayon::ThreadPoolBuilder::new().stack_size(WORKER_STACK_BYTES);
    if let Some(threads) = options.threads {
        builder = builder.num_threads(threads);
    }
    let pool = builder
        .build()
        .map_err(|e| Error::usage(format!("could not start the worker threads: {e}")))?;

    // Sums of extra channels per pixel.
    let k = AOV_SUMS_PER_CHANNEL * estimator.aov_count();
    let mut sums = tile_major(&tiles, crop.size, k, options.initial.as_ref())?;
    let progress = ProgressSink::new(&options, pixel_count);
    let rays = AtomicU64::new(0);
    let abort = AtomicBool::new(false);
    let start = Instant::now();
    let cancel = Cancel {
        flag: &abort,
        external: options.interrupt.as_deref(),
        deadline: stop.time_limit.map(|limit| start + limit),
    };
    let pass = Pass {
        estimator: &estimator,
        tiles: &tiles,
        options: &options,
        cancel: &cancel,
        progress: &progress,
    };
    let mut last_checkpoint = start;
    let first = options.first_sample;
    let mut next = first;
    let mut error = if options.initial.is_some() {
        relative_error(sums.iter().flat_map(|t| &t.pixels))
    } else {
        f64::INFINITY
    };
    let reason = loop {
        if stop.sample_end.is_some_and(|end| next >= end) {
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
        if options
            .interrupt
            .as_ref()
            .is_some_and(|i| i.load(Ordering::Relaxed))
        {
            break StopReason::Interrupted;
        }
        let left = stop.sample_end.map_or(u32::MAX - next, |end| end - next);
        let count = next_pass(in_passes, next - first, left, &stop, start.elapsed(), error);
        let range = next..next + count;
        let pass_result = pool.install(|| pass.render(&sums, range.clone()));
        let Some((new_sums, pass_rays)) = pass_result.filter(|_| !abort.load(Ordering::Relaxed))
        else {
            let interrupted = options
                .interrupt
                .as_ref()
                .is_some_and(|i| i.load(Ordering::Relaxed));
            break if interrupted {
                StopReason::Interrupted
            } else {
                StopReason::TimeLimit
            };
        };
        sums = new_sums;
        rays.fetch_add(pass_rays, Ordering::Relaxed);
        next += count;
        error = relative_error(sums.iter().flat_map(|t| &t.pixels));
        progress.pass_done(next - first, error);
        if let Some(checkpoint) = &mut checkpoints
            && last_checkpoint.elapsed() >= checkpoint.every
        {
            let (pixels, aovs) = row_major(&tiles, crop.size, k, &sums);
            (checkpoint.write)(&Snapshot {
                samples: first..next,
                pixels: &pixels,
                aovs: &aovs,
            })?;
            last_checkpoint = Instant::now();
        }
    };
    let elapsed = start.elapsed();
    progress.finish();

    let mut film = Film::with_aovs(scene.film.size, crop, scene.integrator.aov_names());
    (film.pixels, film.aovs) = row_major(&tiles, crop.size, k, &sums);
    if let Some(checkpoint) = &mut checkpoints {
        (checkpoint.write)(&Snapshot {
            samples: first..next,
            pixels: &film.pixels,
            aovs: &film.aovs,
        })?;
    }
    Ok(RenderOutput {
        film,
        samples: first..next,
        elapsed,
        sample_count: pixel_count * u64::from(next - first),
        rays: rays.into_inner(),
        stop: reason,
        relative_error: error,
    })
}

/// Pixel sums regrouped by tile (each tile's pixels row-major), from row-major sums with `k`
/// extra channels per pixel, or empty.
fn tile_major(
    tiles: &[Tile],
    size: UVec2,
    k: usize,
    initial: Option<&(Vec<PixelSums>, Vec<ValueSum>)>,
) -> Result<Vec<TileSums>> {
    let pixel_count = (size.x * size.y) as usize;
    if let Some((pixels, aovs)) = initial
        && (pixels.len() != pixel_count || aovs.len() != pixel_count * k)
    {
        return Err(Error::usage(
            "the initial state does not match the crop window and the integrator's channels",
        ));
    }
    Ok(tiles
        .iter()
        .map(|t| {
            let tile_pixels = (t.size.x * t.size.y) as usize;
            let mut sums = TileSums {
                pixels: Vec::with_capacity(tile_pixels),
                aovs: Vec::with_capacity(tile_pixels * k),
            };
            for y in 0..t.size.y {
                for x in 0..t.size.x {
                    let index = ((t.origin.y + y) * size.x + t.origin.x + x) as usize;
                    match initial {
                        Some((pixels, aovs)) => {
                            sums.pixels.push(pixels[index]);
                            sums.aovs
                                .extend_from_slice(&aovs[index * k..(index + 1) * k]);
                        }
                        None => {
                            sums.pixels.push(PixelSums::default());
                            sums.aovs.resize(sums.aovs.len() + k, ValueSum::default());
                        }
                    }
                }
            }
            sums
        })
        .collect())
}

/// Row-major pixel sums and extra channels' sums (`k` per pixel) from tile-major ones.
fn row_major(
    tiles: &[Tile],
    size: UVec2,
    k: usize,
    sums: &[TileSums],
) -> (Vec<PixelSums>, Vec<ValueSum>) {
    let pixel_count = (size.x * size.y) as usize;
    let mut pixels = vec![PixelSums::default(); pixel_count];
    let mut aovs = vec![ValueSum::default(); pixel_count * k];
    for (tile, tile_sums) in tiles.iter().zip(sums) {
        for y in 0..tile.size.y {
            for x in 0..tile.size.x {
                let index = ((tile.origin.y + y) * size.x + tile.origin.x + x) as usize;
                let i = (y * tile.size.x + x) as usize;
                pixels[index] = tile_sums.pixels[i];
                aovs[index * k..(index + 1) * k]
                    .copy_from_slice(&tile_sums.aovs[i * k..(i + 1) * k]);
            }
        }
    }
    (pixels, aovs)
}

/// Where a render's progress goes: a terminal bar, a shared counter, or nowhere.
struct ProgressSink {
    bar: ProgressBar,
    counter: Option<Arc<ProgressCounter>>,
}

impl ProgressSink {
    fn new(options: &RenderOptions, pixel_count: u64) -> ProgressSink {
        let total = options
            .stop
            .sample_end
            .filter(|_| !options.stop.is_open_ended())
            .map(|end| pixel_count * u64::from(end.saturating_sub(options.first_sample)));
        match &options.progress {
            Progress::Hidden => ProgressSink {
                bar: ProgressBar::hidden(),
                counter: None,
            },
            Progress::Terminal => ProgressSink {
                bar: terminal_bar(total),
                counter: None,
            },
            Progress::Counter(counter) => {
                counter.samples.store(0, Ordering::Relaxed);
                counter.total.store(total.unwrap_or(0), Ordering::Relaxed);
                counter.error_bits.store(0, Ordering::Relaxed);
                ProgressSink {
                    bar: ProgressBar::hidden(),
                    counter: Some(counter.clone()),
                }
            }
        }
    }

    /// A tile of `samples` camera samples is done.
    fn add(&self, samples: u64) {
        self.bar.inc(samples);
        if let Some(counter) = &self.counter {
            counter.samples.fetch_add(samples, Ordering::Relaxed);
        }
    }

    /// A pass is done: `spp` samples per pixel so far, with the image's mean relative `error`.
    fn pass_done(&self, spp: u32, error: f64) {
        self.bar.set_message(format!("{spp} spp, error {error:.4}"));
        if let Some(counter) = &self.counter {
            counter.error_bits.store(error.to_bits(), Ordering::Relaxed);
        }
    }

    fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

fn terminal_bar(total: Option<u64>) -> ProgressBar {
    let template = if total.is_some() {
        "{bar:40.cyan/blue} {percent:>3}% {human_pos}/{human_len} samples, {per_sec}, ETA {eta} — {msg}"
    } else {
        "{spinner} {elapsed_precise} {human_pos} samples, {per_sec} — {msg}"
    };
    let bar = ProgressBar::with_draw_target(total, ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template(template).unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}
