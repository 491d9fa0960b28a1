//! A pass of a render: the samples of a range of indices added to every pixel of the crop
//! window, the tiles in parallel, by the one-pixel reconstruction or by filter MIS (or, for the
//! particle tracer and bidirectional path tracing, by splatting: [`super::particles`]).

use std::ops::Range;

use glam::{UVec2, Vec2};
use rayon::prelude::*;

use super::RenderOptions;
use super::estimator::{OffsetDraw, SampleEstimator};
use super::filter_mis::{SharedSamples, gather_tile};
use super::lanes::{LaneCounter, SampleSink, trace_in_lanes};
use super::progress::ProgressReport;
use super::stop::Cancel;
use super::tiles::{Tile, TileSums};
use crate::film::FilterMis;
use crate::film::accumulation::{AOV_SUMS_PER_CHANNEL, add_aov_sample};
use crate::integrator::RayCount;
use crate::sampling::sampler::Sampler;

/// Under filter MIS, the samples kept for one batch of sample indices take at most about this
/// many bytes (a batch has at least one index).
const SHARED_SAMPLES_BYTES: usize = 64 << 20;

/// Writes into `out` the sums of a tile with the samples `range` of every pixel added; returns
/// the rays traced, or None when the pass was cancelled before the tile was done.
fn render_tile(
    estimator: &SampleEstimator,
    tile: Tile,
    sums: &TileSums,
    out: &mut TileSums,
    range: Range<u32>,
    options: &RenderOptions,
    cancel: &Cancel,
) -> Option<u64> {
    let scene = estimator.scene;
    let mut sampler = Sampler::new(scene.sampler.kind, options.samples_per_pixel, options.seed);
    let mut count = RayCount::default();
    out.clone_from(sums);
    let sums = out;
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
                let xyz = estimator.estimate(
                    &mut sampler,
                    pixel,
                    index,
                    OffsetDraw::Filter,
                    &mut count,
                    &mut aovs,
                );
                sums.pixels[i].add(xyz);
                add_aov_sample(&mut sums.aovs[i * stride..i * stride + k], &aovs);
            }
        }
    }
    Some(count.rays)
}

/// The pixels of `tile` (crop-window coordinates, the crop window at `crop_offset` on the
/// film), row-major: each one's index in the tile and its film position.
fn tile_pixels(tile: Tile, crop_offset: UVec2) -> impl Iterator<Item = (usize, UVec2)> {
    (0..tile.size.y).flat_map(move |y| {
        (0..tile.size.x).map(move |x| {
            let i = (y * tile.size.x + x) as usize;
            (i, crop_offset + tile.origin + UVec2::new(x, y))
        })
    })
}

/// The one-pixel reconstruction's sink for the lanes: a sample counts for its own pixel of
/// the tile, weighted by the filter.
struct PixelSink<'s> {
    sums: &'s mut TileSums,
    /// Extra channels per sample.
    k: usize,
}

impl SampleSink for PixelSink<'_> {
    fn add(
        &mut self,
        slot: usize,
        _index: u32,
        _offset: Vec2,
        filter_weight: f32,
        xyz: [f32; 3],
        aovs: &mut [f32],
    ) {
        self.sums.pixels[slot].add(xyz.map(|v| v * filter_weight));
        for v in aovs.iter_mut() {
            *v *= filter_weight;
        }
        let start = slot * AOV_SUMS_PER_CHANNEL * self.k;
        add_aov_sample(&mut self.sums.aovs[start..start + self.k], aovs);
    }
}

/// What every pass of a render works with.
pub(super) struct Pass<'p, 's> {
    pub(super) estimator: &'p SampleEstimator<'s>,
    pub(super) tiles: &'p [Tile],
    pub(super) options: &'p RenderOptions,
    pub(super) cancel: &'p Cancel<'p>,
    pub(super) progress: &'p dyn ProgressReport,
    /// How full the lanes of the path tracer's tiles were.
    pub(super) occupancy: &'p LaneCounter,
}

impl Pass<'_, '_> {
    /// Writes into `out` the tiles' `sums` with the samples `range` of every pixel added, the
    /// tiles in parallel; returns the rays traced, or None when the pass was cancelled (`out`
    /// then holds no useful sums). `out`'s allocations are reused.
    pub(super) fn render(
        &self,
        sums: &[TileSums],
        out: &mut Vec<TileSums>,
        range: Range<u32>,
    ) -> Option<u64> {
        out.resize_with(sums.len(), TileSums::default);
        if let Some(splatting) = self.estimator.splatting() {
            return self.render_particles(splatting, sums, out, range);
        }
        match &self.estimator.shared {
            Some(mis) => self.render_shared(mis, sums, out, range),
            None => self.render_one_pixel(sums, out, range),
        }
    }

    /// The one-pixel reconstruction: every tile's pixels take their own samples.
    fn render_one_pixel(
        &self,
        sums: &[TileSums],
        out: &mut [TileSums],
        range: Range<u32>,
    ) -> Option<u64> {
        let pass = u64::from(range.end - range.start);
        let (estimator, options, cancel) = (self.estimator, self.options, self.cancel);
        let path = estimator.integrator.stepped();
        let results: Vec<Option<u64>> = self
            .tiles
            .par_iter()
            .zip(sums)
            .zip(out)
            .map(|((&tile, tile_sums), tile_out)| {
                let result = match &path {
                    Some(path) => {
                        tile_out.clone_from(tile_sums);
                        let k = estimator.aov_count();
                        let mut sink = PixelSink { sums: tile_out, k };
                        let (rays, occupancy) = trace_in_lanes(
                            estimator,
                            path,
                            tile_pixels(tile, estimator.scene.film.crop.offset),
                            range.clone(),
                            options.samples_per_pixel,
                            options.seed,
                            cancel,
                            &mut sink,
                        )?;
                        self.occupancy.add(occupancy);
                        Some(rays)
                    }
                    None => render_tile(
                        estimator,
                        tile,
                        tile_sums,
                        tile_out,
                        range.clone(),
                        options,
                        cancel,
                    ),
                };
                if result.is_some() {
                    self.progress
                        .advance(u64::from(tile.size.x * tile.size.y) * pass);
                }
                result
            })
            .collect();
        results.into_iter().sum()
    }

    /// Filter MIS: for each batch of sample indices, the samples of every pixel within reach of
    /// the crop window are traced, then every pixel of the crop gathers what each index brings
    /// it from the (2·reach + 1)² pixels around, always in the same order, and adds the totals
    /// of each index to its sums ([`PixelSums::add_shared`]).
    fn render_shared(
        &self,
        mis: &FilterMis,
        sums: &[TileSums],
        out: &mut [TileSums],
        range: Range<u32>,
    ) -> Option<u64> {
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
        for (tile_out, tile_sums) in out.iter_mut().zip(sums) {
            tile_out.clone_from(tile_sums);
        }
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
                self.occupancy,
            )?;
            out.par_iter_mut()
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
                        .advance(pixels * u64::from(batch_range.end - batch_range.start));
                });
            start = batch_range.end;
        }
        Some(rays)
    }
}
