//! Camera paths in lanes: a worker holds [`LANES`] paths of its tile at once and advances them
//! together, one vertex per step, each stage run for every active lane before the next stage
//! begins (docs/architecture.md, Paths in lanes).
//!
//! A step traces the ray of every active lane to its closest hit, then turns each hit into
//! its surface interaction and runs the path tracer's vertex ([`PathIntegrator::step`]) on
//! it. A lane whose path ends writes its sample to the film and regenerates: it takes its
//! pixel's next sample index, or, when its pixel has all the pass's samples, the next pixel of
//! the tile that no lane has taken, so that a few long paths do not idle the others. A lane keeps its pixel's samples in order, which keeps its
//! sampler's walk along the pixel's random stream one step per sample.
//!
//! The random numbers are keyed by (pixel, sample index, dimension) and the film's sums are
//! exact, so the image is the same for any number of lanes, thread count and tile order, and
//! the same as the one-path-at-a-time estimate ([`SampleEstimator::estimate`]) gives.

use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering};

use glam::UVec2;

use super::estimator::{CameraSampleRay, SampleEstimator};
use super::pass::Pass;
use super::stop::Cancel;
use super::tiles::{Tile, TileSums};
use crate::film::accumulation::{AOV_SUMS_PER_CHANNEL, add_aov_sample};
use crate::geometry::aggregate::Hit;
use crate::integrator::path::PathState;
use crate::integrator::{PathIntegrator, RayCount, SampleContext};
use crate::math::lanes::{F32s, Real};
use crate::sampling::sampler::Sampler;
use crate::spectrum::SampledSpectrum;

/// Paths a worker advances together: the lane vectors' width.
pub const LANES: usize = F32s::LANES;

/// How full a tile's lanes were: lane steps taken and, of them, those with a path.
#[derive(Clone, Copy, Debug, Default)]
struct Occupancy {
    /// Steps times lanes.
    lane_steps: u64,
    /// Lane steps that advanced a path.
    active: u64,
}

/// The occupancy of a render's lanes, added up from its worker threads.
#[derive(Debug, Default)]
pub(super) struct LaneCounter {
    lane_steps: AtomicU64,
    active: AtomicU64,
}

impl LaneCounter {
    fn add(&self, occupancy: Occupancy) {
        self.lane_steps
            .fetch_add(occupancy.lane_steps, Ordering::Relaxed);
        self.active.fetch_add(occupancy.active, Ordering::Relaxed);
    }

    /// The mean share of the lanes that held a path per step, or None when no path ran in
    /// lanes.
    pub(super) fn mean(&self) -> Option<f64> {
        let lane_steps = self.lane_steps.load(Ordering::Relaxed);
        (lane_steps > 0).then(|| self.active.load(Ordering::Relaxed) as f64 / lane_steps as f64)
    }
}

/// One lane: the pixel it works on (its index in the tile and on the film), the sample index
/// being traced, its random numbers, the camera sample and the path, None when the lane has
/// no sample left.
struct Lane {
    slot: usize,
    pixel: UVec2,
    index: u32,
    sampler: Sampler,
    camera: Option<CameraSampleRay>,
    path: Option<PathState>,
}

/// The tile's pixels not yet taken by a lane, in row-major order.
struct PixelQueue {
    tile: Tile,
    crop_offset: UVec2,
    next: u32,
}

impl PixelQueue {
    fn take(&mut self) -> Option<(usize, UVec2)> {
        let count = self.tile.size.x * self.tile.size.y;
        (self.next < count).then(|| {
            let i = self.next;
            self.next += 1;
            let local = UVec2::new(i % self.tile.size.x, i / self.tile.size.x);
            (i as usize, self.crop_offset + self.tile.origin + local)
        })
    }
}

/// What a tile's lanes share: the estimator, the path tracer, the pass's sample indices, the
/// tile's sums and the counts.
struct TileRun<'e, 'a, 's> {
    estimator: &'e SampleEstimator<'a>,
    path: &'e PathIntegrator,
    range: Range<u32>,
    sums: &'s mut TileSums,
    /// One sample's extra channels, reused.
    aovs: Vec<f32>,
    count: RayCount,
    /// Whether the pass was cancelled before the tile was done.
    cancelled: bool,
}

impl TileRun<'_, '_, '_> {
    /// Adds the finished sample `camera` of the tile's pixel `slot`, with the path's
    /// `radiance`, to the pixel's sums.
    fn add_to_film(&mut self, slot: usize, camera: &CameraSampleRay, radiance: SampledSpectrum) {
        let k = self.aovs.len();
        let (_, weight, xyz) = self.estimator.film_sample(camera, radiance, &mut self.aovs);
        self.sums.pixels[slot].add(xyz.map(|v| v * weight));
        for v in self.aovs.iter_mut() {
            *v *= weight;
        }
        let start = slot * AOV_SUMS_PER_CHANNEL * k;
        add_aov_sample(&mut self.sums.aovs[start..start + k], &self.aovs);
    }

    /// Starts the lane's sample, or the first of the following indices of its pixel whose
    /// path does not end before its first vertex (`max_depth` 0: those go to the film at
    /// once); returns false when the pixel has no sample left.
    fn start(&mut self, lane: &mut Lane) -> bool {
        while lane.index < self.range.end {
            self.aovs.fill(0.0);
            let camera = self.estimator.camera_sample(
                &mut lane.sampler,
                lane.pixel,
                lane.index,
                &mut self.count,
                &mut self.aovs,
            );
            lane.path = self.path.start(camera.ray, &camera.lambda);
            if lane.path.is_some() {
                lane.camera = Some(camera);
                return true;
            }
            self.add_to_film(lane.slot, &camera, SampledSpectrum::ZERO);
            lane.index += 1;
        }
        false
    }

    /// Gives the lane the first sample of the queue's next pixel that has one; returns false
    /// when the tile has no sample left or the pass is cancelled (then `cancelled` is set).
    fn take_pixel(&mut self, lane: &mut Lane, queue: &mut PixelQueue, cancel: &Cancel) -> bool {
        loop {
            if cancel.raised() {
                self.cancelled = true;
                return false;
            }
            let Some((slot, pixel)) = queue.take() else {
                return false;
            };
            (lane.slot, lane.pixel, lane.index) = (slot, pixel, self.range.start);
            if self.start(lane) {
                return true;
            }
        }
    }

    /// Adds the lane's finished sample to the film and gives the lane the next: its pixel's
    /// next index, else [`Self::take_pixel`].
    fn finish(&mut self, lane: &mut Lane, queue: &mut PixelQueue, cancel: &Cancel) {
        if let (Some(path), Some(camera)) = (lane.path.take(), lane.camera.take()) {
            self.add_to_film(lane.slot, &camera, self.path.estimate(&path));
        }
        lane.index += 1;
        if !self.start(lane) {
            self.take_pixel(lane, queue, cancel);
        }
    }
}

/// Writes into `out` the sums of a tile with the samples `range` of every pixel added, tracing
/// the path tracer `path`'s camera paths [`LANES`] at a time and adding the lanes' occupancy
/// to the pass's; returns the rays traced, or None when the pass was cancelled before the tile
/// was done.
pub(super) fn render_tile_in_lanes(
    pass: &Pass,
    path: &PathIntegrator,
    tile: Tile,
    sums: &TileSums,
    out: &mut TileSums,
    range: Range<u32>,
) -> Option<u64> {
    let (estimator, options, cancel) = (pass.estimator, pass.options, pass.cancel);
    let scene = estimator.scene;
    out.clone_from(sums);
    let mut run = TileRun {
        estimator,
        path,
        range,
        sums: out,
        aovs: vec![0.0; estimator.aov_count()],
        count: RayCount::default(),
        cancelled: false,
    };
    let mut queue = PixelQueue {
        tile,
        crop_offset: scene.film.crop.offset,
        next: 0,
    };
    let mut lanes: Vec<Lane> = (0..LANES)
        .map(|_| {
            let mut lane = Lane {
                slot: 0,
                pixel: UVec2::ZERO,
                index: 0,
                sampler: Sampler::new(scene.sampler.kind, options.samples_per_pixel, options.seed),
                camera: None,
                path: None,
            };
            run.take_pixel(&mut lane, &mut queue, cancel);
            lane
        })
        .collect();
    let mut hits: Vec<Option<Hit>> = vec![None; LANES];
    let mut occupancy = Occupancy::default();
    while !run.cancelled {
        // The trace stage: every active lane's ray to its closest hit.
        let mut active = 0;
        for (lane, hit) in lanes.iter().zip(hits.iter_mut()) {
            if let Some(path) = &lane.path {
                active += 1;
                run.count.rays += 1;
                *hit = scene.world.geometry.closest_hit(&path.ray);
            }
        }
        if active == 0 {
            pass.occupancy.add(occupancy);
            return Some(run.count.rays);
        }
        occupancy.lane_steps += LANES as u64;
        occupancy.active += active;
        // The vertex stage: every active lane's hit as a surface interaction, and the path's
        // vertex there; ended paths go to the film and their lanes take the next samples.
        for (lane, hit) in lanes.iter_mut().zip(hits.iter_mut()) {
            let Some(state) = &mut lane.path else {
                continue;
            };
            let si = hit
                .take()
                .and_then(|hit| scene.world.geometry.interaction(&state.ray, &hit));
            let ctx = &mut SampleContext {
                prepared: &estimator.integrator,
                sampler: &mut lane.sampler,
                count: &mut run.count,
            };
            if !path.step(ctx, state, si) {
                run.finish(lane, &mut queue, cancel);
            }
        }
    }
    None
}
