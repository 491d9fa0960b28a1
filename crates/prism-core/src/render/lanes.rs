//! Camera paths in lanes: a worker holds [`LANES`] paths of its tile at once and advances them
//! together, one vertex per step, each stage run for every active lane before the next stage
//! begins (docs/architecture.md, Paths in lanes).
//!
//! A step traces the ray of every active lane to its closest hit (the trace stage, the lanes'
//! BVH traversals interleaved so that one ray's cache misses overlap another's:
//! [`crate::geometry::Aggregate::closest_hits`]), then turns each hit into its surface
//! interaction and runs the estimator's step on it ([`SteppedPath::step`]: the path tracer's
//! vertex, a volumetric path tracer's next event, a ray of `distrib`'s tree; the vertex
//! stage). A lane whose path ends writes its sample to the film and regenerates: it takes its
//! pixel's next sample index, or, when its pixel has all the pass's samples, the next pixel of
//! the tile that no lane has taken, so that a few long paths do not idle the others. A lane keeps its pixel's samples in order, which keeps its sampler's walk along the
//! pixel's random stream one step per sample.
//!
//! Where the samples come from and go is the caller's: the one-pixel reconstruction hands
//! the lanes a tile's pixels and adds each sample to its pixel's sums; filter MIS hands them a
//! row of the pixels within the filter's reach and keeps each sample for the pixels around.
//!
//! The random numbers are keyed by (pixel, sample index, dimension) and the film's sums are
//! exact, so the image is the same for any number of lanes, thread count and tile order, and
//! the same as the one-path-at-a-time estimate ([`SampleEstimator::estimate`]) gives.

use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering};

use glam::{UVec2, Vec2};

use super::estimator::{CameraSampleRay, SampleEstimator};
use super::stop::Cancel;
use crate::geometry::aggregate::Hit;
use crate::integrator::stepped::SteppedIntegrator;
use crate::integrator::{RayCount, SampleContext, SteppedPath};
use crate::math::Ray;
use crate::math::lanes::{F32s, Real};
use crate::sampling::sampler::Sampler;
use crate::spectrum::SampledSpectrum;

/// Paths a worker advances together: the lane vectors' width.
pub const LANES: usize = F32s::LANES;

/// How full a tile's lanes were: lane steps taken and, of them, those with a path.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Occupancy {
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
    pub(super) fn add(&self, occupancy: Occupancy) {
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

/// Where the lanes' finished samples go.
pub(super) trait SampleSink {
    /// Takes sample `index` of the pixel its source named `slot`: the film offset from the
    /// pixel's centre, the weight the one-pixel estimator gives the sample, its CIE XYZ and its
    /// extra channels (weighted by the shutter, not by the filter; the sink may scale them in
    /// place).
    fn add(
        &mut self,
        slot: usize,
        index: u32,
        offset: Vec2,
        filter_weight: f32,
        xyz: [f32; 3],
        aovs: &mut [f32],
    );
}

/// One lane: the pixel it works on (as its source named it, and on the film), the sample index
/// being traced, its random numbers, the camera sample and the path (of state `S`), None when
/// the lane has no sample left.
struct Lane<S> {
    slot: usize,
    pixel: UVec2,
    index: u32,
    sampler: Sampler,
    camera: Option<CameraSampleRay>,
    path: Option<S>,
    /// The sample's extra channels (the coverage alpha drawn with the camera sample, the
    /// spectral film's bands written at the end).
    aovs: Vec<f32>,
}

/// What the lanes of one run share: the estimator, the stepped estimator `T`, the sample
/// indices of every pixel, where the pixels come from and the samples go, and the counts.
struct LaneRun<'e, 'a, T, P, S> {
    estimator: &'e SampleEstimator<'a>,
    path: &'e T,
    range: Range<u32>,
    pixels: P,
    sink: &'e mut S,
    count: RayCount,
    /// Whether the pass was cancelled before the run was done.
    cancelled: bool,
}

impl<T: SteppedPath, P: Iterator<Item = (usize, UVec2)>, S: SampleSink> LaneRun<'_, '_, T, P, S> {
    /// Hands the lane's finished sample `camera`, with the path's `radiance`, to the sink.
    fn add(
        &mut self,
        lane: &mut Lane<T::State>,
        camera: &CameraSampleRay,
        radiance: SampledSpectrum,
    ) {
        let (offset, weight, xyz) = self.estimator.film_sample(camera, radiance, &mut lane.aovs);
        self.sink
            .add(lane.slot, lane.index, offset, weight, xyz, &mut lane.aovs);
    }

    /// Starts the lane's sample, or the first of the following indices of its pixel whose
    /// path does not end before its first vertex (`max_depth` 0: those go to the sink at
    /// once); returns false when the pixel has no sample left.
    fn start(&mut self, lane: &mut Lane<T::State>) -> bool {
        while lane.index < self.range.end {
            lane.aovs.fill(0.0);
            let camera = self.estimator.camera_sample(
                &mut lane.sampler,
                lane.pixel,
                lane.index,
                self.estimator.offset_draw(),
                &mut self.count,
                &mut lane.aovs,
            );
            lane.path = self
                .path
                .start(&self.estimator.scene.world, camera.ray, &camera.lambda);
            if lane.path.is_some() {
                lane.camera = Some(camera);
                return true;
            }
            self.add(lane, &camera, SampledSpectrum::ZERO);
            lane.index += 1;
        }
        false
    }

    /// Gives the lane the first sample of the next pixel that has one; returns false when no
    /// pixel is left or the pass is cancelled (then `cancelled` is set).
    fn take_pixel(&mut self, lane: &mut Lane<T::State>, cancel: &Cancel) -> bool {
        loop {
            if cancel.raised() {
                self.cancelled = true;
                return false;
            }
            let Some((slot, pixel)) = self.pixels.next() else {
                return false;
            };
            (lane.slot, lane.pixel, lane.index) = (slot, pixel, self.range.start);
            if self.start(lane) {
                return true;
            }
        }
    }

    /// Hands the lane's finished sample to the sink and gives the lane the next: its pixel's
    /// next index, else [`Self::take_pixel`].
    fn finish(&mut self, lane: &mut Lane<T::State>, cancel: &Cancel) {
        if let (Some(path), Some(camera)) = (lane.path.take(), lane.camera.take()) {
            self.add(lane, &camera, self.path.estimate(&path));
        }
        lane.index += 1;
        if !self.start(lane) {
            self.take_pixel(lane, cancel);
        }
    }
}

/// Traces the samples `range` of every pixel `pixels` yields (a slot the sink knows it by, and
/// its film position), the camera paths of `paths` [`LANES`] at a time, handing each finished
/// sample to `sink`; the random numbers are the sampler's for `samples_per_pixel` and `seed`.
/// Returns the rays traced and the lanes' occupancy, or None when the pass was cancelled
/// before the pixels were done.
#[allow(clippy::too_many_arguments)]
pub(super) fn trace_in_lanes(
    estimator: &SampleEstimator,
    paths: &SteppedIntegrator,
    pixels: impl Iterator<Item = (usize, UVec2)>,
    range: Range<u32>,
    samples_per_pixel: u32,
    seed: u64,
    cancel: &Cancel,
    sink: &mut impl SampleSink,
) -> Option<(u64, Occupancy)> {
    macro_rules! trace {
        ($stepped:expr) => {
            trace_stepped(
                estimator,
                $stepped,
                pixels,
                range,
                samples_per_pixel,
                seed,
                cancel,
                sink,
            )
        };
    }
    match paths {
        SteppedIntegrator::Path(path) => trace!(*path),
        SteppedIntegrator::Direct(direct) => trace!(*direct),
        SteppedIntegrator::Distribution(distrib) => trace!(*distrib),
        SteppedIntegrator::VolPath(volpath) => trace!(volpath),
        SteppedIntegrator::VolPathMis(volpath) => trace!(volpath),
    }
}

/// [`trace_in_lanes`] for the stepped estimator `path`.
#[allow(clippy::too_many_arguments)]
fn trace_stepped<T: SteppedPath>(
    estimator: &SampleEstimator,
    path: &T,
    pixels: impl Iterator<Item = (usize, UVec2)>,
    range: Range<u32>,
    samples_per_pixel: u32,
    seed: u64,
    cancel: &Cancel,
    sink: &mut impl SampleSink,
) -> Option<(u64, Occupancy)> {
    let scene = estimator.scene;
    let mut run = LaneRun {
        estimator,
        path,
        range,
        pixels,
        sink,
        count: RayCount::default(),
        cancelled: false,
    };
    let mut lanes: Vec<Lane<T::State>> = (0..LANES)
        .map(|_| {
            let mut lane = Lane {
                slot: 0,
                pixel: UVec2::ZERO,
                index: 0,
                sampler: Sampler::new(scene.sampler.kind, samples_per_pixel, seed),
                camera: None,
                path: None,
                aovs: vec![0.0; estimator.aov_count()],
            };
            run.take_pixel(&mut lane, cancel);
            lane
        })
        .collect();
    let mut hits: Vec<Option<Hit>> = vec![None; LANES];
    let mut occupancy = Occupancy::default();
    while !run.cancelled {
        // The trace stage: every active lane's ray to its closest hit, the traversals
        // interleaved.
        let rays: [Option<&Ray>; LANES] =
            std::array::from_fn(|i| lanes[i].path.as_ref().map(T::ray));
        let active = rays.iter().flatten().count() as u64;
        if active == 0 {
            return Some((run.count.rays, occupancy));
        }
        scene.world.geometry.closest_hits(&rays, &mut hits);
        run.count.rays += active;
        occupancy.lane_steps += LANES as u64;
        occupancy.active += active;
        // The vertex stage: every active lane's hit as a surface interaction, and the path's
        // vertex there; ended paths go to the sink and their lanes take the next samples.
        for (lane, hit) in lanes.iter_mut().zip(hits.iter_mut()) {
            let Some(state) = &mut lane.path else {
                continue;
            };
            let si = hit
                .take()
                .and_then(|hit| scene.world.geometry.interaction(T::ray(state), &hit));
            let ctx = &mut SampleContext {
                prepared: &estimator.integrator,
                sampler: &mut lane.sampler,
                count: &mut run.count,
            };
            if !path.step(ctx, state, si) {
                run.finish(lane, cancel);
            }
        }
    }
    None
}
