//! The render driver: the image is rendered in passes, each adding samples to every pixel;
//! within a pass the tiles of the crop window are rendered in parallel on a rayon pool.
//!
//! Every pixel sample draws its random numbers from the sampler's stream for (seed, pixel,
//! sample index), and pixel sums are exact (order-free). The particle tracer's samples are
//! light subpaths keyed the same way, splatted wherever they reach the film and gathered per
//! sample index ([`particles`]). Under the one-pixel reconstruction every camera sample lands
//! in its own pixel; under filter MIS ([`crate::film::reconstruction`]) the
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

mod estimator;
mod filter_mis;
mod guided;
mod lanes;
mod options;
mod particles;
mod pass;
mod progress;
pub mod resume;
pub mod sppm;
pub mod state;
mod stop;
mod tiles;
mod vcm;

use std::ops::Range;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

use crate::error::{Error, Result};
use crate::film::accumulation::AOV_SUMS_PER_CHANNEL;
pub use crate::film::stats::relative_error;
use crate::film::{Film, PixelSums, ValueSum};
use crate::scene::Scene;
pub use estimator::{OffsetDraw, SampleEstimator};
pub use lanes::LANES;
use lanes::LaneCounter;
pub use options::RenderOptions;
use pass::Pass;
use progress::Silent;
pub use progress::{ProgressCounter, ProgressReport};
use state::IntegratorState;
use stop::{Cancel, next_pass};
pub use stop::{StopReason, StopRule, StopRuleNames};
use tiles::{row_major, tile_major, tiles};

/// Stack of each worker thread: the distribution ray tracer recurses once per bounce, with a
/// vertex's BSDF on the stack (about 2 KiB a level), and its roulette lets long specular chains
/// run to depths of a few hundred. Only the pages used are ever touched.
const WORKER_STACK_BYTES: usize = 64 << 20;

/// The state of a render between two passes, handed to the checkpoint writer and the preview.
pub struct Snapshot<'a> {
    /// The sample indices every pixel has had in this render (after its initial state).
    pub samples: Range<u32>,
    /// Pixel sums, row-major over the crop window (including the initial state).
    pub pixels: &'a [PixelSums],
    /// The extra channels' sums, 2K per pixel in the same order.
    pub aovs: &'a [ValueSum],
    /// A progressive integrator's state after the same passes.
    pub integrator_state: Option<&'a IntegratorState>,
}

impl Snapshot<'_> {
    /// What a render resumed from this snapshot starts from.
    pub fn initial_state(&self) -> resume::InitialState {
        resume::InitialState {
            pixels: self.pixels.to_vec(),
            aovs: self.aovs.to_vec(),
            integrator: self.integrator_state.cloned(),
        }
    }

    /// The developing image: the film of `scene` holding the snapshot's sums.
    pub fn film(&self, scene: &Scene) -> Film {
        Film {
            size: scene.film.size,
            crop: scene.film.crop,
            pixels: self.pixels.to_vec(),
            aov_names: scene.integrator.aov_names(),
            aovs: self.aovs.to_vec(),
        }
    }
}

/// Something that saves the render's state every so often.
pub struct Checkpoints<'a> {
    pub every: Duration,
    pub write: &'a mut dyn FnMut(&Snapshot) -> Result<()>,
}

/// Receives the developing image after every pass (see [`render_with_preview`]).
pub type Preview<'a> = &'a mut dyn FnMut(&Snapshot) -> Result<()>;

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
    /// The mean share of the lanes that held a path per step, where the integrator's paths
    /// ran in lanes.
    pub lane_occupancy: Option<f64>,
    /// A progressive integrator's state at the end, for a state file.
    pub integrator_state: Option<IntegratorState>,
}

impl RenderOutput {
    /// What a render resumed from this one's end starts from (what an interrupted render's
    /// state file holds).
    pub fn initial_state(&self) -> resume::InitialState {
        resume::InitialState {
            pixels: self.film.pixels.clone(),
            aovs: self.film.aovs.clone(),
            integrator: self.integrator_state.clone(),
        }
    }
}

/// Renders the scene.
pub fn render(scene: &Scene, options: &RenderOptions) -> Result<RenderOutput> {
    render_with_checkpoints(scene, options, None)
}

/// Renders the scene, handing its state to `checkpoints` between passes every so often.
pub fn render_with_checkpoints(
    scene: &Scene,
    options: &RenderOptions,
    checkpoints: Option<Checkpoints>,
) -> Result<RenderOutput> {
    render_with_preview(scene, options, checkpoints, None)
}

/// As [`render_with_checkpoints`], also handing the developing image to `preview` after every
/// pass (for a live preview or partial images; [`Snapshot::film`] makes it a film). An error
/// from `preview` ends the render with that error.
pub fn render_with_preview(
    scene: &Scene,
    options: &RenderOptions,
    mut checkpoints: Option<Checkpoints>,
    mut preview: Option<Preview>,
) -> Result<RenderOutput> {
    let crop = scene.film.crop;
    let estimator = SampleEstimator::new(scene);
    // The particle tracer's bound on a pass's sample indices.
    let samples_per_pass = estimator
        .particle_tracer()
        .and_then(|ptracer| ptracer.samples_per_pass)
        .unwrap_or(u32::MAX);
    let tiles = tiles(crop.size);
    let pixel_count = u64::from(crop.size.x) * u64::from(crop.size.y);
    let options = RenderOptions {
        samples_per_pixel: scene.strata(options.samples_per_pixel),
        ..options.clone()
    };
    let stop = options.stop;
    let in_passes = options.in_passes(checkpoints.is_some() || preview.is_some());

    let mut builder = rayon::ThreadPoolBuilder::new().stack_size(WORKER_STACK_BYTES);
    if let Some(threads) = options.threads {
        builder = builder.num_threads(threads);
    }
    let pool = builder
        .build()
        .map_err(|e| Error::usage(format!("could not start the worker threads: {e}")))?;

    if let Some(sppm) = estimator.integrator.sppm() {
        return sppm::render(
            scene,
            sppm,
            &estimator,
            &options,
            &pool,
            checkpoints,
            preview,
        );
    }
    if let Some(guided) = estimator.integrator.guided() {
        return guided::render(
            scene,
            guided,
            &estimator,
            &options,
            &pool,
            checkpoints,
            preview,
        );
    }
    if estimator.integrator.vcm().is_some_and(|vcm| vcm.merging) && stop.target_error.is_some() {
        return Err(Error::usage(
            "the vcm integrator has no error estimate to stop at: its merges are biased at any \
             finite sample count (set use_vm to false for an unbiased estimate)",
        ));
    }
    if let Some(state) = options.initial.as_ref().and_then(|i| i.integrator.as_ref()) {
        return Err(Error::usage(format!(
            "cannot resume this render from the state of a {} render",
            state.integrator
        )));
    }
    // Sums of extra channels per pixel.
    let k = AOV_SUMS_PER_CHANNEL * estimator.aov_count();
    let mut sums = tile_major(&tiles, crop.size, k, options.initial.as_ref())?;
    // What a pass writes into: the sums before it stay whole until it completes.
    let mut spare = Vec::new();
    let progress = options.progress.as_deref().unwrap_or(&Silent);
    let total = stop
        .sample_end
        .filter(|_| !stop.is_open_ended())
        .map(|end| pixel_count * u64::from(end.saturating_sub(options.first_sample)));
    progress.begin(total);
    let rays = AtomicU64::new(0);
    let abort = AtomicBool::new(false);
    let start = Instant::now();
    let cancel = Cancel {
        flag: &abort,
        external: options.interrupt.as_deref(),
        deadline: stop.time_limit.map(|limit| start + limit),
    };
    let occupancy = LaneCounter::default();
    let pass = Pass {
        estimator: &estimator,
        tiles: &tiles,
        options: &options,
        cancel: &cancel,
        progress,
        occupancy: &occupancy,
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
        let count = next_pass(in_passes, next - first, left, &stop, start.elapsed(), error)
            .min(samples_per_pass);
        let range = next..next + count;
        let pass_result = pool.install(|| pass.render(&sums, &mut spare, range.clone()));
        let Some(pass_rays) = pass_result.filter(|_| !abort.load(Ordering::Relaxed)) else {
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
        std::mem::swap(&mut sums, &mut spare);
        rays.fetch_add(pass_rays, Ordering::Relaxed);
        next += count;
        error = relative_error(sums.iter().flat_map(|t| &t.pixels));
        progress.pass_done(next - first, error);
        let checkpoint_due = (checkpoints.as_ref())
            .is_some_and(|checkpoint| last_checkpoint.elapsed() >= checkpoint.every);
        if checkpoint_due || preview.is_some() {
            let (pixels, aovs) = row_major(&tiles, crop.size, k, &sums);
            let snapshot = Snapshot {
                samples: first..next,
                pixels: &pixels,
                aovs: &aovs,
                integrator_state: None,
            };
            if let Some(preview) = &mut preview {
                preview(&snapshot)?;
            }
            if let Some(checkpoint) = &mut checkpoints
                && checkpoint_due
            {
                (checkpoint.write)(&snapshot)?;
                last_checkpoint = Instant::now();
            }
        }
    };
    let elapsed = start.elapsed();
    progress.end();

    let mut film = Film::with_aovs(scene.film.size, crop, scene.aov_names());
    (film.pixels, film.aovs) = row_major(&tiles, crop.size, k, &sums);
    if let Some(checkpoint) = &mut checkpoints {
        (checkpoint.write)(&Snapshot {
            samples: first..next,
            pixels: &film.pixels,
            aovs: &film.aovs,
            integrator_state: None,
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
        lane_occupancy: occupancy.mean(),
        integrator_state: None,
    })
}
