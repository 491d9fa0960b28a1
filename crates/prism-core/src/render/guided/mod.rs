//! The iterations of practical path guiding ([`crate::integrator::guided`]): the budget split
//! into iterations of 2ᵏ passes, the SD-tree refined before each and built after it, and the
//! final image chosen or combined from the iterations' images by `sampleCombination`.
//!
//! A run is the render of a sample range a..b (0..the sample count, unless `--sample-range`
//! says otherwise): its pass p takes the sample indices a + p·`sppPerPass` .. a + (p +
//! 1)·`sppPerPass` of every pixel, so no two samples of the run share random numbers. Within a
//! pass the tiles render in parallel from a tree that does not change; each tile keeps its
//! paths' records, and after the pass they are filed into the tree in the order of the tiles.
//! So the image is bit-identical for any thread count. A pass cut short (time limit,
//! interruption) is dropped whole; the image is then the one of the iteration running, if it
//! has a pass, else the last finished one's.
//!
//! **Budget.** In samples: the integrator's `budget`, else the render's sample count, rounded
//! up to whole passes; in seconds: `budget`, else the render's time limit. A run of the range
//! a..b with a > 0 spends b − a samples per pixel, a whole number of passes (its `budget` left
//! at −1); it trains a tree of its own, independent of the other ranges' runs.
//!
//! **Checkpoints and resume.** The run's state ([`run_state`]: the SD-tree, the images of the
//! finished iterations the final image may still be made of, the iteration under way with its
//! image so far, the passes done) travels in the render state as the integrator's; the state's
//! pixel sums are the image as it would be if the render stopped there. A checkpoint is
//! written between passes every `checkpoints.every` and at the end, and the render returns its
//! state however it stopped. With a budget in samples a resumed run goes on exactly: stopped
//! after any pass and resumed, it ends with the image and state of one uninterrupted run. With
//! a budget in seconds the state keeps the budget and the seconds spent, and a resumed render
//! spends what is left of the budget (a time limit given to it can only stop it earlier).
//!
//! **Merge.** `prism merge` of runs of disjoint ranges combines their final images
//! ([`merge_states`]); the merged state cannot be resumed. A target error is refused: the
//! final image may mix several iterations' images, which have no joint error estimate. Every
//! sample counts for its own pixel (the one-pixel reconstruction, the filter
//! importance-sampled), whatever the film's `reconstruction`.

mod run_state;

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use glam::UVec2;
use rayon::prelude::*;

use super::estimator::{OffsetDraw, SampleEstimator};
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
pub(crate) use run_state::merge_states;

/// Samples per pixel below which `nee` = `kickstart` takes light samples (the authors').
const KICKSTART_SPP: u64 = 128;
/// The authors' cap on a pixel's variance of Y in the mean variance of an image, which keeps
/// fireflies from deciding the sample combination.
const VARIANCE_CAP: f64 = 10_000.0;
/// `inversevar` combines at most this many of the last iterations' images.
const COMBINED_IMAGES: usize = 4;
/// `automatic` trusts an iteration's variance from this many samples per pixel on.
const TRUSTED_SPP: u64 = 256;

/// What the run may spend.
#[derive(Clone, Copy, Debug, PartialEq)]
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

/// What an iteration does.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Stage {
    /// Trains the tree with `passes` passes; `last` where they end the budget.
    Training { passes: u32, last: bool },
    /// Renders the rest of the budget, `passes` passes, from a tree that no longer learns.
    Final { passes: u32 },
}

impl Stage {
    fn passes(self) -> u32 {
        match self {
            Stage::Training { passes, .. } | Stage::Final { passes } => passes,
        }
    }

    /// Whether its paths record into the tree (all but the budget's last iteration's).
    fn records(self) -> bool {
        matches!(self, Stage::Training { last: false, .. })
    }
}

/// The iteration under way.
struct Current {
    stage: Stage,
    light_samples: bool,
    image: Image,
    /// Seconds spent on it by the renders this one resumed (time budgets only, else 0).
    seconds_before: f64,
}

/// Everything a guided run carries from one pass to the next: what its state holds
/// ([`run_state`]), and this render's clocks and ray count.
struct Run {
    /// The sample index of its first pass (the start of its sample range).
    first_sample: u32,
    plan: Plan,
    /// Seconds spent by the renders this one resumed (time budgets only, else 0).
    seconds_before: f64,
    tree: SdTree,
    /// Iterations that have trained the tree.
    iteration: u32,
    passes_done: u32,
    /// The variance the rest of the budget would reach at the last iteration's rate.
    extrapolated: f64,
    /// The last finished iterations' images, as many as the final image may be made of.
    images: Vec<Image>,
    current: Option<Current>,
    /// When this render started, and the iteration under way in it.
    started: Instant,
    iteration_started: Instant,
    /// Passes done when this render started, and rays traced in it.
    passes_before: u32,
    rays: u64,
}

impl Run {
    /// The end of the sample indices rendered.
    fn sample_end(&self, spp_per_pass: u32) -> u32 {
        self.first_sample + self.passes_done * spp_per_pass
    }

    /// Seconds spent on the run so far (time budgets only, else 0).
    fn seconds(&self) -> f64 {
        match self.plan {
            Plan::Seconds(_) => self.seconds_before + self.started.elapsed().as_secs_f64(),
            Plan::Passes(_) => 0.0,
        }
    }

    /// Seconds spent on the iteration under way (time budgets only, else 0).
    fn iteration_seconds(&self) -> f64 {
        match (self.plan, &self.current) {
            (Plan::Seconds(_), Some(current)) => {
                current.seconds_before + self.iteration_started.elapsed().as_secs_f64()
            }
            _ => 0.0,
        }
    }

    /// The images the final one is made of: the finished iterations' and the one under way.
    fn images(&self) -> Vec<&Image> {
        self.images
            .iter()
            .chain(self.current.as_ref().map(|c| &c.image))
            .collect()
    }

    /// Keeps `image` as the last finished one, and no more images than `combination` uses.
    fn finish(&mut self, image: Image, combination: SampleCombination) {
        self.images.push(image);
        let kept = kept_images(combination);
        if self.images.len() > kept {
            self.images.drain(..self.images.len() - kept);
        }
    }
}

/// How many finished iterations' images the final image may be made of.
fn kept_images(combination: SampleCombination) -> usize {
    if combination == SampleCombination::InverseVariance {
        COMBINED_IMAGES
    } else {
        1
    }
}

/// The budget of a run starting at sample `first_sample` (see the module's text).
fn plan(guided: &GuidedPathIntegrator, options: &RenderOptions, first_sample: u32) -> Result<Plan> {
    let spp_per_pass = guided.spp_per_pass;
    if first_sample != 0 {
        let range = |end: u32| format!("{first_sample}..{end}");
        return match (guided.budget, options.stop.sample_end) {
            (Budget::Samples(None), Some(end)) if end > first_sample => {
                let spp = end - first_sample;
                if !spp.is_multiple_of(spp_per_pass) {
                    return Err(Error::usage(format!(
                        "a guided_path render of the samples {} needs a multiple of \
                         sppPerPass ({spp_per_pass}) samples per pixel, not {spp}",
                        range(end)
                    )));
                }
                Ok(Plan::Passes(spp / spp_per_pass))
            }
            _ => Err(Error::usage(
                "a guided_path render of a sample range takes the range as its budget: give \
                 it the range's end, and leave its budget at -1",
            )),
        };
    }
    Ok(match guided.budget {
        Budget::Samples(Some(spp)) => Plan::Passes(spp.div_ceil(spp_per_pass)),
        Budget::Seconds(Some(seconds)) => Plan::Seconds(seconds),
        Budget::Samples(None) | Budget::Seconds(None) => {
            match (
                guided.budget,
                options.stop.sample_end,
                options.stop.time_limit,
            ) {
                (Budget::Samples(_), Some(spp), _) => Plan::Passes(spp.div_ceil(spp_per_pass)),
                (_, _, Some(limit)) => Plan::Seconds(limit.as_secs_f64()),
                (_, Some(spp), None) => Plan::Passes(spp.div_ceil(spp_per_pass)),
                (_, None, None) => {
                    return Err(Error::usage(
                        "the guided_path integrator needs a budget: give it one, or a sample \
                         count or time limit to the render",
                    ));
                }
            }
        }
    })
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
    if options.stop.target_error.is_some() {
        return Err(Error::usage(
            "the guided_path integrator cannot stop at a target error: its final image may \
             mix the images of several iterations, which have no joint error estimate",
        ));
    }
    let film = &scene.film;
    let crop = film.crop;
    let tiles = tiles(crop.size);
    let k = AOV_SUMS_PER_CHANNEL * estimator.aov_count();
    let pixel_count = u64::from(crop.size.x) * u64::from(crop.size.y);
    let progress: &dyn ProgressReport = options.progress.as_deref().unwrap_or(&Silent);
    let spp_per_pass = u64::from(guided.spp_per_pass);
    let mut run = match &options.initial {
        None => {
            let (lo, hi) = scene
                .world
                .geometry
                .bounds()
                .unwrap_or((glam::Vec3::ZERO, glam::Vec3::ONE));
            Run {
                first_sample: options.first_sample,
                plan: plan(guided, options, options.first_sample)?,
                seconds_before: 0.0,
                tree: SdTree::new(lo, hi),
                iteration: 0,
                passes_done: 0,
                extrapolated: f64::INFINITY,
                images: Vec::new(),
                current: None,
                started: Instant::now(),
                iteration_started: Instant::now(),
                passes_before: 0,
                rays: 0,
            }
        }
        Some(initial) => {
            let layout = run_state::Layout {
                guided,
                tiles: &tiles,
                size: crop.size,
                k,
            };
            run_state::resume(&layout, options, initial.integrator.as_ref())?
        }
    };
    progress.begin(match run.plan {
        Plan::Passes(passes) => {
            Some(pixel_count * spp_per_pass * u64::from(passes - run.passes_done))
        }
        Plan::Seconds(_) => None,
    });
    let start = run.started;
    // A budget too large for a clock sets no deadline.
    let deadline = match run.plan {
        Plan::Seconds(seconds) => {
            std::time::Duration::try_from_secs_f64((seconds - run.seconds_before).max(0.0))
                .ok()
                .and_then(|left| start.checked_add(left))
        }
        Plan::Passes(_) => None,
    };
    let deadline = match (deadline, options.stop.time_limit.map(|limit| start + limit)) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    };
    let abort = AtomicBool::new(false);
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
    let mut saver = Saver {
        checkpoints,
        last: start,
    };
    let mut reason = StopReason::Completed;
    // The pixels' estimates from the last finished iteration, per tile, for the weight window.
    let estimates_of = |run: &Run| {
        (guided.adrrs != Adrrs::Off)
            .then(|| run.images.last().map(|image| driver.estimates(image)))
            .flatten()
    };
    let mut estimates = estimates_of(&run);
    loop {
        if run.current.is_none() {
            let iteration = run.iteration;
            let stage = match run.plan {
                Plan::Passes(total) => {
                    let left = total - run.passes_done;
                    if left == 0 {
                        break;
                    }
                    let mut passes = left.min(1u32 << iteration.min(31));
                    // The last iteration takes at least half the budget.
                    if left - passes < 2 * passes {
                        passes = left;
                    }
                    Stage::Training {
                        passes,
                        last: passes == left,
                    }
                }
                Plan::Seconds(_) => Stage::Training {
                    passes: 1u32 << iteration.min(31),
                    last: false,
                },
            };
            let threshold = (f64::from(1u32 << iteration.min(31)) * spp_per_pass as f64 / 4.0)
                .sqrt()
                * f64::from(guided.s_tree_threshold);
            run.tree.refine(
                threshold,
                guided.d_tree_threshold,
                guided.sd_tree_max_memory.map(|mb| mb as usize * 1_000_000),
            );
            let light_samples = match guided.nee {
                NextEvent::Never => false,
                NextEvent::Kickstart => u64::from(run.passes_done) * spp_per_pass < KICKSTART_SPP,
                NextEvent::Always => true,
            };
            run.current = Some(Current {
                stage,
                light_samples,
                image: driver.empty_image()?,
                seconds_before: 0.0,
            });
            run.iteration_started = Instant::now();
        }
        if !driver.run(&mut run, estimates.as_deref(), &mut saver)? {
            reason = stop_reason(options);
            break;
        }
        let spent = run.iteration_seconds();
        let Some(current) = run.current.take() else {
            break;
        };
        let Stage::Training { passes, last } = current.stage else {
            run.finish(current.image, guided.sample_combination);
            break;
        };
        // The variance the rest of the budget would reach at this iteration's rate.
        let previous_extrapolated = run.extrapolated;
        let (left, this) = match run.plan {
            Plan::Passes(total) => (f64::from(total - run.passes_done), f64::from(passes)),
            Plan::Seconds(seconds) => (seconds - run.seconds(), spent),
        };
        run.extrapolated = this * current.image.variance / (left + this);
        let spp_before = u64::from(run.passes_done - passes) * spp_per_pass;
        let stop_training = guided.sample_combination == SampleCombination::Automatic
            && left > 0.0
            && (left < this
                || (spp_before > TRUSTED_SPP && run.extrapolated > previous_extrapolated));
        run.finish(current.image, guided.sample_combination);
        estimates = estimates_of(&run);
        if last {
            break;
        }
        if stop_training {
            let rest = match run.plan {
                Plan::Passes(total) => total - run.passes_done,
                Plan::Seconds(_) => u32::MAX / guided.spp_per_pass - run.passes_done,
            };
            run.current = Some(Current {
                stage: Stage::Final { passes: rest },
                light_samples: current.light_samples,
                image: driver.empty_image()?,
                seconds_before: 0.0,
            });
            run.iteration_started = Instant::now();
            continue;
        }
        run.tree.build();
        run.iteration += 1;
        if let Some(preview) = &mut preview {
            let film = driver.film_of(scene, &run.images());
            preview(&Snapshot {
                samples: options.first_sample..run.sample_end(guided.spp_per_pass),
                pixels: &film.pixels,
                aovs: &film.aovs,
                integrator_state: None,
            })?;
        }
    }
    if let Plan::Seconds(_) = run.plan
        && reason == StopReason::TimeLimit
        && deadline.is_some_and(|d| options.stop.time_limit.is_none_or(|l| d < start + l))
    {
        reason = StopReason::Completed;
    }
    let elapsed = start.elapsed();
    progress.end();
    let film = driver.film_of(scene, &run.images());
    let integrator_state = run_state::encode(&driver.layout(), &run);
    let samples = options.first_sample..run.sample_end(guided.spp_per_pass);
    if let Some(checkpoint) = &mut saver.checkpoints {
        (checkpoint.write)(&Snapshot {
            samples: samples.clone(),
            pixels: &film.pixels,
            aovs: &film.aovs,
            integrator_state: Some(&integrator_state),
        })?;
    }
    let error = relative_error(film.pixels.iter());
    Ok(RenderOutput {
        film,
        samples,
        elapsed,
        sample_count: pixel_count * u64::from(run.passes_done - run.passes_before) * spp_per_pass,
        rays: run.rays,
        stop: reason,
        relative_error: error,
        lane_occupancy: None,
        integrator_state: Some(integrator_state),
    })
}

/// Writes a checkpoint between passes every so often.
struct Saver<'a> {
    checkpoints: Option<Checkpoints<'a>>,
    /// When the last one was written.
    last: Instant,
}

impl Saver<'_> {
    /// Writes the run's state and image if a checkpoint is due.
    fn after_pass(&mut self, driver: &Driver, run: &Run) -> Result<()> {
        let Some(checkpoint) = &mut self.checkpoints else {
            return Ok(());
        };
        if self.last.elapsed() < checkpoint.every {
            return Ok(());
        }
        let film = driver.film_of(driver.estimator.scene, &run.images());
        let integrator_state = run_state::encode(&driver.layout(), run);
        (checkpoint.write)(&Snapshot {
            samples: driver.options.first_sample..run.sample_end(driver.guided.spp_per_pass),
            pixels: &film.pixels,
            aovs: &film.aovs,
            integrator_state: Some(&integrator_state),
        })?;
        self.last = Instant::now();
        Ok(())
    }
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
    /// What the run's images are laid out by.
    fn layout(&self) -> run_state::Layout<'_> {
        run_state::Layout {
            guided: self.guided,
            tiles: self.tiles,
            size: self.estimator.scene.film.crop.size,
            k: self.k,
        }
    }

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

    /// Renders the passes left of the iteration under way (light samples or not, recording
    /// into the tree's recording trees or not, as its stage says), with the pixels'
    /// `estimates` (per tile) where the weight window uses them, handing the run to `saver`
    /// after each; returns whether all were rendered (false when one was cancelled).
    fn run(
        &self,
        run: &mut Run,
        estimates: Option<&[Vec<f32>]>,
        saver: &mut Saver,
    ) -> Result<bool> {
        let spp = self.guided.spp_per_pass;
        loop {
            let Run {
                tree,
                current: Some(current),
                ..
            } = run
            else {
                return Ok(true);
            };
            if current.image.passes >= current.stage.passes() {
                current.image.complete = true;
                return Ok(true);
            }
            let guide = Guide {
                tree,
                trained: run.iteration > 0,
                light_samples: current.light_samples,
                record_weight: current.stage.records().then_some(1.0),
            };
            let start = run.first_sample + run.passes_done * spp;
            let Some((sums, radiance, records, rays)) =
                self.pass(&guide, &current.image, estimates, start..start + spp)
            else {
                return Ok(false);
            };
            let image = &mut current.image;
            image.sums = sums;
            image.radiance = radiance;
            image.passes += 1;
            image.complete = image.passes == current.stage.passes();
            image.variance = mean_variance(&image.sums);
            run.passes_done += 1;
            run.rays += rays;
            for r in records.iter().flatten() {
                tree.file(r, self.guided.bsdf_sampling_fraction_loss);
            }
            self.progress
                .pass_done((run.passes_done - run.passes_before) * spp, f64::INFINITY);
            saver.after_pass(self, run)?;
        }
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
                    let sample = estimator.camera_sample(
                        &mut sampler,
                        pixel,
                        index,
                        OffsetDraw::Filter,
                        &mut count,
                        &mut aovs,
                    );
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

    /// The final film from the iterations' images (the last one holds the newest samples;
    /// an image without passes is skipped).
    fn film_of(&self, scene: &Scene, images: &[&Image]) -> Film {
        let crop = scene.film.crop;
        let mut film = Film::with_aovs(scene.film.size, crop, scene.aov_names());
        let rendered: Vec<&Image> = images.iter().copied().filter(|i| i.passes > 0).collect();
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

/// The mean over the pixels of the variance of a sample's Y, each pixel's capped (the
/// authors' measure of an image's noise); infinite with fewer than two samples.
fn mean_variance(sums: &[TileSums]) -> f64 {
    let mut sum = 0.0;
    let mut pixels = 0usize;
    let mut n = 0;
    for p in sums.iter().flat_map(|t| &t.pixels) {
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
