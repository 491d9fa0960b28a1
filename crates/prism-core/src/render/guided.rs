//! The iterations of practical path guiding ([`crate::integrator::guided`]): the budget split
//! into iterations of 2ᵏ passes, the SD-tree refined before each and built after it, and the
//! final image chosen or combined from the iterations' images by `sampleCombination`.
//!
//! Pass p of the render takes the sample indices p·`sppPerPass` .. (p + 1)·`sppPerPass` of
//! every pixel, so no two samples of the render share random numbers. Within a pass the tiles
//! render in parallel from a tree that does not change; each tile keeps its paths' records,
//! and after the pass they are filed into the tree in the order of the tiles. So the image is
//! bit-identical for any thread count. A pass cut short (time limit, interruption) is
//! dropped whole; the image is then the one of the iteration running, if it has a pass, else
//! the last finished one's.
//!
//! The SD-tree and the iterations' images are not pixel sums a render state could hold:
//! checkpoints, `--resume`, merged sample ranges and a target error are refused. Every sample
//! counts for its own pixel (the one-pixel reconstruction, the filter importance-sampled),
//! whatever the film's `reconstruction`.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use glam::UVec2;
use rayon::prelude::*;

use super::estimator::SampleEstimator;
use super::progress::{ProgressReport, Silent};
use super::stop::Cancel;
use super::tiles::{Tile, TileSums, row_major, tile_major, tiles};
use super::{Checkpoints, Preview, RenderOptions, RenderOutput, Snapshot, StopReason};
use crate::error::{Error, Result};
use crate::film::accumulation::{AOV_SUMS_PER_CHANNEL, add_aov_sample};
use crate::film::{Film, PixelSums, ValueSum};
use crate::integrator::guided::sd_tree::SdTree;
use crate::integrator::guided::{
    Adrrs, Budget, Guide, GuidedPathIntegrator, NextEvent, Record, SampleCombination,
};
use crate::integrator::{RayCount, SampleContext};
use crate::render::relative_error;
use crate::sampling::sampler::Sampler;
use crate::scene::Scene;

/// Samples per pixel below which `nee` = `kickstart` takes light samples (the authors').
const KICKSTART_SPP: u64 = 128;
/// The authors' cap on a pixel's variance of Y in the mean variance of an image, which keeps
/// fireflies from deciding the sample combination.
const VARIANCE_CAP: f64 = 10_000.0;
/// `inversevar` combines at most this many of the last iterations' images.
const COMBINED_IMAGES: usize = 4;
/// `automatic` trusts an iteration's variance from this many samples per pixel on.
const TRUSTED_SPP: u64 = 256;

/// What the render may still spend.
#[derive(Clone, Copy, Debug)]
enum Plan {
    /// Passes over all iterations.
    Passes(u32),
    /// Seconds over all iterations.
    Seconds(f64),
}

/// An iteration's image: its tiles' sums, its pixels' sums of their samples' radiance (the
/// mean over the wavelengths, per tile), its passes, whether it has all it was planned to have,
/// and its mean pixel variance.
struct Image {
    sums: Vec<TileSums>,
    radiance: Vec<Vec<f64>>,
    passes: u32,
    complete: bool,
    variance: f64,
}

/// Where the iterations stand.
struct Iterations {
    /// Whether the tree has learned from an iteration.
    trained: bool,
    /// Passes rendered so far.
    passes_done: u32,
    rays: u64,
}

/// Renders the scene with `guided` (see the module's text).
pub(super) fn render(
    scene: &Scene,
    guided: &GuidedPathIntegrator,
    estimator: &SampleEstimator,
    options: &RenderOptions,
    pool: &rayon::ThreadPool,
    checkpoints: Option<Checkpoints>,
    mut preview: Option<Preview>,
) -> Result<RenderOutput> {
    let refuse = |what: &str| {
        Err(Error::usage(format!(
            "the guided_path integrator {what}: its SD-tree and the images of its training \
             iterations are not pixel sums"
        )))
    };
    if checkpoints.is_some() || options.initial.is_some() || options.first_sample != 0 {
        return refuse("cannot be checkpointed, resumed or merged from sample ranges");
    }
    if options.stop.target_error.is_some() {
        return refuse("cannot stop at a target error");
    }
    let plan = match guided.budget {
        Budget::Samples(Some(spp)) => Plan::Passes(spp.div_ceil(guided.spp_per_pass)),
        Budget::Seconds(Some(seconds)) => Plan::Seconds(seconds),
        Budget::Samples(None) | Budget::Seconds(None) => {
            match (
                guided.budget,
                options.stop.sample_end,
                options.stop.time_limit,
            ) {
                (Budget::Samples(_), Some(spp), _) => {
                    Plan::Passes(spp.div_ceil(guided.spp_per_pass))
                }
                (_, _, Some(limit)) => Plan::Seconds(limit.as_secs_f64()),
                (_, Some(spp), None) => Plan::Passes(spp.div_ceil(guided.spp_per_pass)),
                (_, None, None) => {
                    return Err(Error::usage(
                        "the guided_path integrator needs a budget: give it one, or a sample \
                         count or time limit to the render",
                    ));
                }
            }
        }
    };
    let film = &scene.film;
    let crop = film.crop;
    let tiles = tiles(crop.size);
    let k = AOV_SUMS_PER_CHANNEL * estimator.aov_count();
    let pixel_count = u64::from(crop.size.x) * u64::from(crop.size.y);
    let (lo, hi) = scene
        .world
        .geometry
        .bounds()
        .unwrap_or((glam::Vec3::ZERO, glam::Vec3::ONE));
    let progress: &dyn ProgressReport = options.progress.as_deref().unwrap_or(&Silent);
    let spp_per_pass = u64::from(guided.spp_per_pass);
    progress.begin(match plan {
        Plan::Passes(passes) => Some(pixel_count * spp_per_pass * u64::from(passes)),
        Plan::Seconds(_) => None,
    });
    let abort = AtomicBool::new(false);
    let start = Instant::now();
    let deadline = match plan {
        Plan::Seconds(seconds) => Some(start + std::time::Duration::from_secs_f64(seconds)),
        Plan::Passes(_) => None,
    };
    let deadline = match (deadline, options.stop.time_limit.map(|limit| start + limit)) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    };
    let cancel = Cancel {
        flag: &abort,
        external: options.interrupt.as_deref(),
        deadline,
    };
    let driver = Driver {
        guided,
        estimator,
        options,
        tiles: &tiles,
        cancel: &cancel,
        progress,
        pool,
        k,
    };
    let mut tree = SdTree::new(lo, hi);
    let mut state = Iterations {
        trained: false,
        passes_done: 0,
        rays: 0,
    };
    let mut iteration = 0u32;
    let mut images: Vec<Image> = Vec::new();
    let mut reason = StopReason::Completed;
    let mut extrapolated = f64::INFINITY;
    // The pixels' estimates from the last finished iteration, per tile, for the weight window.
    let mut estimates: Option<Vec<Vec<f32>>> = None;
    loop {
        let (passes, last) = match plan {
            Plan::Passes(total) => {
                let left = total - state.passes_done;
                if left == 0 {
                    break;
                }
                let mut passes = left.min(1u32 << iteration.min(31));
                // The last iteration takes at least half the budget.
                if left - passes < 2 * passes {
                    passes = left;
                }
                (passes, passes == left)
            }
            Plan::Seconds(_) => (1u32 << iteration.min(31), false),
        };
        let threshold = (f64::from(1u32 << iteration.min(31)) * spp_per_pass as f64 / 4.0).sqrt()
            * f64::from(guided.s_tree_threshold);
        tree.refine(
            threshold,
            guided.d_tree_threshold,
            guided.sd_tree_max_memory.map(|mb| mb as usize * 1_000_000),
        );
        let iteration_start = Instant::now();
        let light_samples = match guided.nee {
            NextEvent::Never => false,
            NextEvent::Kickstart => u64::from(state.passes_done) * spp_per_pass < KICKSTART_SPP,
            NextEvent::Always => true,
        };
        let mut image = driver.empty_image()?;
        let finished = driver.run(
            &mut tree,
            &mut image,
            passes,
            light_samples,
            !last,
            estimates.as_deref(),
            &mut state,
        );
        if !finished {
            images.push(image);
            reason = stop_reason(options);
            break;
        }
        // The variance the rest of the budget would reach at this iteration's rate.
        let previous_extrapolated = extrapolated;
        let spent = iteration_start.elapsed().as_secs_f64();
        let (left, this) = match plan {
            Plan::Passes(total) => (f64::from(total - state.passes_done), f64::from(passes)),
            Plan::Seconds(seconds) => (seconds - start.elapsed().as_secs_f64(), spent),
        };
        extrapolated = this * image.variance / (left + this);
        let spp_before = u64::from(state.passes_done - passes) * spp_per_pass;
        let stop_training = guided.sample_combination == SampleCombination::Automatic
            && left > 0.0
            && (left < this || (spp_before > TRUSTED_SPP && extrapolated > previous_extrapolated));
        if guided.adrrs != Adrrs::Off {
            estimates = Some(driver.estimates(&image));
        }
        images.push(image);
        if last {
            break;
        }
        if stop_training {
            let mut image = driver.empty_image()?;
            let rest = match plan {
                Plan::Passes(total) => total - state.passes_done,
                Plan::Seconds(_) => u32::MAX / guided.spp_per_pass - state.passes_done,
            };
            let finished = driver.run(
                &mut tree,
                &mut image,
                rest,
                light_samples,
                false,
                estimates.as_deref(),
                &mut state,
            );
            images.push(image);
            if !finished {
                reason = stop_reason(options);
            }
            break;
        }
        tree.build();
        state.trained = true;
        iteration += 1;
        if let Some(preview) = &mut preview {
            let film = driver.film_of(scene, &images);
            preview(&Snapshot {
                samples: 0..state.passes_done * guided.spp_per_pass,
                pixels: &film.pixels,
                aovs: &film.aovs,
                integrator_state: None,
            })?;
        }
    }
    if let Plan::Seconds(_) = plan
        && reason == StopReason::TimeLimit
        && deadline.is_some_and(|d| options.stop.time_limit.is_none_or(|l| d < start + l))
    {
        reason = StopReason::Completed;
    }
    let elapsed = start.elapsed();
    progress.end();
    let film = driver.film_of(scene, &images);
    let error = relative_error(film.pixels.iter());
    Ok(RenderOutput {
        film,
        samples: 0..state.passes_done * guided.spp_per_pass,
        elapsed,
        sample_count: pixel_count * u64::from(state.passes_done) * spp_per_pass,
        rays: state.rays,
        stop: reason,
        relative_error: error,
        lane_occupancy: None,
        integrator_state: None,
    })
}

/// Why a render whose pass was cancelled stopped.
fn stop_reason(options: &RenderOptions) -> StopReason {
    if options
        .interrupt
        .as_ref()
        .is_some_and(|i| i.load(Ordering::Relaxed))
    {
        StopReason::Interrupted
    } else {
        StopReason::TimeLimit
    }
}

/// What every pass works with.
struct Driver<'a> {
    guided: &'a GuidedPathIntegrator,
    estimator: &'a SampleEstimator<'a>,
    options: &'a RenderOptions,
    tiles: &'a [Tile],
    cancel: &'a Cancel<'a>,
    progress: &'a dyn ProgressReport,
    pool: &'a rayon::ThreadPool,
    /// Extra channels' sums per pixel.
    k: usize,
}

/// What a tile's pass returns: its sums, its pixels' radiance sums, its records, the rays
/// traced.
type TileResult = (TileSums, Vec<f64>, Vec<Record>, u64);

/// What a pass returns: the tiles' sums and radiance sums, their records in tile order, the
/// rays traced.
type PassResult = (Vec<TileSums>, Vec<Vec<f64>>, Vec<Vec<Record>>, u64);

impl Driver<'_> {
    /// An image without samples.
    fn empty_image(&self) -> Result<Image> {
        Ok(Image {
            sums: tile_major(
                self.tiles,
                self.estimator.scene.film.crop.size,
                self.k,
                None,
            )?,
            radiance: self
                .tiles
                .iter()
                .map(|t| vec![0.0; (t.size.x * t.size.y) as usize])
                .collect(),
            passes: 0,
            complete: false,
            variance: f64::INFINITY,
        })
    }

    /// Renders `passes` passes into `image`, with light samples or not, recording into the
    /// tree's recording trees or not, with the pixels' `estimates` (per tile) where the weight
    /// window uses them; returns whether all were rendered (false when one was cancelled).
    /// Sets the image's variance.
    #[allow(clippy::too_many_arguments)]
    fn run(
        &self,
        tree: &mut SdTree,
        image: &mut Image,
        passes: u32,
        light_samples: bool,
        record: bool,
        estimates: Option<&[Vec<f32>]>,
        state: &mut Iterations,
    ) -> bool {
        let spp = self.guided.spp_per_pass;
        for _ in 0..passes {
            let guide = Guide {
                tree,
                trained: state.trained,
                light_samples,
                record_weight: record.then_some(1.0),
            };
            let range = state.passes_done * spp..(state.passes_done + 1) * spp;
            let Some((sums, radiance, records, rays)) = self.pass(&guide, image, estimates, range)
            else {
                image.variance = self.mean_variance(image);
                return false;
            };
            image.sums = sums;
            image.radiance = radiance;
            image.passes += 1;
            state.passes_done += 1;
            state.rays += rays;
            for r in records.iter().flatten() {
                tree.file(r, self.guided.bsdf_sampling_fraction_loss);
            }
            self.progress
                .pass_done(state.passes_done * spp, f64::INFINITY);
        }
        image.complete = true;
        image.variance = self.mean_variance(image);
        true
    }

    /// The sums of `image` with the samples `range` of every pixel added, guided by `guide`
    /// (and the pixels' `estimates`, per tile), with the tiles' records; None when the pass
    /// was cancelled.
    fn pass(
        &self,
        guide: &Guide,
        image: &Image,
        estimates: Option<&[Vec<f32>]>,
        range: std::ops::Range<u32>,
    ) -> Option<PassResult> {
        let results: Vec<Option<TileResult>> = self.pool.install(|| {
            self.tiles
                .par_iter()
                .enumerate()
                .map(|(t, &tile)| {
                    self.tile(
                        guide,
                        tile,
                        &image.sums[t],
                        &image.radiance[t],
                        estimates.map(|e| e[t].as_slice()),
                        range.clone(),
                    )
                })
                .collect()
        });
        let mut out = Vec::with_capacity(results.len());
        let mut radiance = Vec::with_capacity(results.len());
        let mut records = Vec::with_capacity(results.len());
        let mut rays = 0;
        for result in results {
            let (tile_sums, tile_radiance, tile_records, tile_rays) = result?;
            out.push(tile_sums);
            radiance.push(tile_radiance);
            records.push(tile_records);
            rays += tile_rays;
        }
        if self.cancel.raised() {
            return None;
        }
        Some((out, radiance, records, rays))
    }

    /// The mean radiance (over the wavelengths) of each pixel's samples in `image`, per tile.
    fn estimates(&self, image: &Image) -> Vec<Vec<f32>> {
        let samples = f64::from(image.passes * self.guided.spp_per_pass).max(1.0);
        image
            .radiance
            .iter()
            .map(|tile| tile.iter().map(|&sum| (sum / samples) as f32).collect())
            .collect()
    }

    /// One tile's sums and radiance sums with the samples `range` of its pixels added (guided
    /// by `guide` and the pixels' `estimates`), and its records.
    fn tile(
        &self,
        guide: &Guide,
        tile: Tile,
        sums: &TileSums,
        radiance_sums: &[f64],
        estimates: Option<&[f32]>,
        range: std::ops::Range<u32>,
    ) -> Option<TileResult> {
        let estimator = self.estimator;
        let scene = estimator.scene;
        let mut sampler = Sampler::new(
            scene.sampler.kind,
            self.options.samples_per_pixel,
            self.options.seed,
        );
        let mut count = RayCount::default();
        let mut out = sums.clone();
        let mut radiance_out = radiance_sums.to_vec();
        let mut records = Vec::new();
        let aov_count = estimator.aov_count();
        let mut aovs = vec![0.0f32; aov_count];
        let crop_offset = scene.film.crop.offset;
        for y in 0..tile.size.y {
            if self.cancel.raised() {
                return None;
            }
            for x in 0..tile.size.x {
                let pixel = crop_offset + tile.origin + UVec2::new(x, y);
                let i = (y * tile.size.x + x) as usize;
                for index in range.clone() {
                    aovs.fill(0.0);
                    let sample =
                        estimator.camera_sample(&mut sampler, pixel, index, &mut count, &mut aovs);
                    let radiance = {
                        let ctx = &mut SampleContext {
                            prepared: &estimator.integrator,
                            sampler: &mut sampler,
                            count: &mut count,
                        };
                        self.guided.radiance(
                            ctx,
                            sample.ray,
                            &sample.lambda,
                            guide,
                            estimates.map(|e| e[i]),
                            &mut records,
                        )
                    };
                    radiance_out[i] += f64::from(radiance.average());
                    let (_, weight, xyz) = estimator.film_sample(&sample, radiance, &mut aovs);
                    out.pixels[i].add(xyz.map(|v| v * weight));
                    for v in aovs.iter_mut() {
                        *v *= weight;
                    }
                    let start = i * self.k;
                    add_aov_sample(&mut out.aovs[start..start + aov_count], &aovs);
                }
            }
        }
        self.progress
            .advance(u64::from(tile.size.x * tile.size.y) * u64::from(range.end - range.start));
        Some((out, radiance_out, records, count.rays))
    }

    /// The mean over the pixels of the variance of a sample's Y, each pixel's capped (the
    /// authors' measure of an image's noise); infinite with fewer than two samples.
    fn mean_variance(&self, image: &Image) -> f64 {
        let mut sum = 0.0;
        let mut pixels = 0usize;
        let mut n = 0;
        for p in image.sums.iter().flat_map(|t| &t.pixels) {
            n = p.samples;
            if n < 2 {
                return f64::INFINITY;
            }
            let mean = p.sum(1) / n as f64;
            let spread = (p.sum_of_squares(1) - mean * p.sum(1)).max(0.0);
            sum += spread.min(VARIANCE_CAP);
            pixels += 1;
        }
        if pixels == 0 || n < 2 {
            return f64::INFINITY;
        }
        sum / (pixels as f64 * (n - 1) as f64)
    }

    /// The final film from the iterations' images (the last one holds the newest samples;
    /// an image without passes is skipped).
    fn film_of(&self, scene: &Scene, images: &[Image]) -> Film {
        let crop = scene.film.crop;
        let mut film = Film::with_aovs(scene.film.size, crop, scene.aov_names());
        let rendered: Vec<&Image> = images.iter().filter(|i| i.passes > 0).collect();
        // An iteration cut short gives way to the one before where that has more samples.
        let last = match rendered[..] {
            [.., before, last] if !last.complete && before.passes > last.passes => before,
            [.., last] => last,
            [] => return film,
        };
        if self.guided.sample_combination != SampleCombination::InverseVariance
            || rendered.len() == 1
        {
            (film.pixels, film.aovs) = row_major(self.tiles, crop.size, self.k, &last.sums);
            return film;
        }
        let combined = &rendered[rendered.len().saturating_sub(COMBINED_IMAGES)..];
        let weights: Vec<f64> = combined
            .iter()
            .map(|i| {
                if i.variance > 0.0 && i.variance.is_finite() {
                    1.0 / i.variance
                } else {
                    0.0
                }
            })
            .collect();
        let total: f64 = weights.iter().sum();
        let weights: Vec<f64> = if total > 0.0 {
            weights.iter().map(|w| w / total).collect()
        } else {
            let mut w = vec![0.0; combined.len()];
            *w.last_mut().unwrap() = 1.0;
            w
        };
        let rows: Vec<(Vec<PixelSums>, Vec<ValueSum>)> = combined
            .iter()
            .map(|i| row_major(self.tiles, crop.size, self.k, &i.sums))
            .collect();
        let aov_count = self.k / AOV_SUMS_PER_CHANNEL;
        for (i, pixel) in film.pixels.iter_mut().enumerate() {
            let mut xyz = [0.0f64; 3];
            for ((pixels, _), w) in rows.iter().zip(&weights) {
                let mean = pixels[i].mean();
                for c in 0..3 {
                    xyz[c] += w * mean[c];
                }
            }
            pixel.add_total(xyz);
            let (last_pixels, last_aovs) = rows.last().unwrap();
            let n = last_pixels[i].samples.max(1) as f64;
            let values: Vec<f32> = last_aovs[i * self.k..i * self.k + aov_count]
                .iter()
                .map(|s| (s.value() / n) as f32)
                .collect();
            add_aov_sample(&mut film.aovs[i * self.k..i * self.k + aov_count], &values);
        }
        film
    }
}
