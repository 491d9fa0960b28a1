//! Filter MIS in the render driver ([`crate::film::reconstruction`] has the estimator): the
//! samples of a batch of indices traced for every pixel within the filter's reach of the crop
//! window and kept, then gathered by every pixel from its neighbours, always in the same order.

use std::ops::Range;

use glam::{UVec2, Vec2, Vec4};
use rayon::prelude::*;

use super::RenderOptions;
use super::estimator::{OffsetDraw, SampleEstimator};
use super::lanes::{LaneCounter, SampleSink, trace_in_lanes};
use super::stop::Cancel;
use super::tiles::{Tile, TileSums};
use crate::film::FilterMis;
use crate::film::accumulation::{AOV_SUMS_PER_CHANNEL, acceptable_sample, add_shared_aov_sample};
use crate::integrator::RayCount;
use crate::sampling::sampler::Sampler;

/// The samples of one batch of sample indices, traced for every pixel of a rectangle of the
/// film (the crop window and the filter's reach m around it). Per pixel and index: the factor
/// 1 / ((∫k)² D) of the sample (NaN: the sample was rejected), its XYZ and extra channels times
/// that factor, and the filter's values k(o − j) on each axis for the pixels j = −m..m away
/// (o the sample's offset from its pixel's centre), computed once here rather than by each of
/// the (2m + 1)² pixels that gather the sample.
pub(super) struct SharedSamples {
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

    pub(super) fn new(
        origin: UVec2,
        size: UVec2,
        indices: u32,
        aovs: usize,
        reach: u32,
    ) -> SharedSamples {
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
    pub(super) fn bytes_per_index(size: UVec2, aovs: usize, reach: u32) -> usize {
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
    /// over rows (the path tracer's in lanes, adding their occupancy to `occupancy`). None
    /// when the pass was cancelled.
    pub(super) fn trace(
        &mut self,
        estimator: &SampleEstimator,
        mis: &FilterMis,
        range: Range<u32>,
        options: &RenderOptions,
        cancel: &Cancel,
        occupancy: &LaneCounter,
    ) -> Option<u64> {
        let (stride, origin, indices) = (self.stride, self.origin, self.indices as usize);
        let (k, reach) = (self.aovs, self.reach);
        let row_len = self.size.x as usize * indices * stride;
        let path = estimator.integrator.stepped();
        let rays: Vec<Option<u64>> = self
            .values
            .par_chunks_mut(row_len)
            .enumerate()
            .map(|(row, values)| {
                if cancel.raised() {
                    return None;
                }
                if let Some(path) = &path {
                    let columns = values.len() / (indices * stride);
                    let pixels = (0..columns)
                        .map(|column| (column, origin + UVec2::new(column as u32, row as u32)));
                    let mut sink = RecordSink {
                        values,
                        row_start: origin + UVec2::new(0, row as u32),
                        mis,
                        first: range.start,
                        per_pixel: indices * stride,
                        stride,
                        reach,
                    };
                    let (rays, lanes) = trace_in_lanes(
                        estimator,
                        path,
                        pixels,
                        range.clone(),
                        options.samples_per_pixel,
                        options.seed,
                        cancel,
                        &mut sink,
                    )?;
                    occupancy.add(lanes);
                    return Some(rays);
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
                    let (offset, _, xyz) = estimator.trace(
                        &mut sampler,
                        pixel,
                        index,
                        OffsetDraw::Shared,
                        &mut count,
                        &mut aovs,
                    );
                    write_record(record, mis, pixel, offset, xyz, &aovs, reach);
                }
                Some(count.rays)
            })
            .collect();
        rays.into_iter().sum()
    }
}

/// Writes into `record` what filter MIS keeps of a sample of `pixel` drawn at `offset` from
/// its centre, with its XYZ and extra channels `aovs`, for a filter reaching `reach` pixels
/// (the layout of [`SharedSamples`]).
fn write_record(
    record: &mut [f32],
    mis: &FilterMis,
    pixel: UVec2,
    offset: Vec2,
    xyz: [f32; 3],
    aovs: &[f32],
    reach: usize,
) {
    if !acceptable_sample(&xyz) {
        record[SharedSamples::SCALE] = f32::NAN;
        return;
    }
    // A point the density misses (none, for a sampled one) adds nothing.
    let scale = mis.sample_scale(pixel, offset);
    let scale = if scale.is_finite() { scale } else { 0.0 };
    record[SharedSamples::SCALE] = scale;
    for c in 0..3 {
        record[SharedSamples::XYZ + c] = xyz[c] * scale;
    }
    let (channels, kernels) = record[SharedSamples::AOVS..].split_at_mut(aovs.len());
    for (r, &v) in channels.iter_mut().zip(aovs) {
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

/// The lanes' sink for a row of shared samples: each sample written to its record.
struct RecordSink<'v, 'm> {
    /// The row's records: per pixel, per sample index of the batch.
    values: &'v mut [f32],
    /// The film position of the row's first pixel (its slot 0).
    row_start: UVec2,
    mis: &'m FilterMis,
    /// The batch's first sample index.
    first: u32,
    /// Floats per pixel of the row.
    per_pixel: usize,
    /// Floats per sample.
    stride: usize,
    reach: usize,
}

impl SampleSink for RecordSink<'_, '_> {
    fn add(
        &mut self,
        slot: usize,
        index: u32,
        offset: Vec2,
        _filter_weight: f32,
        xyz: [f32; 3],
        aovs: &mut [f32],
    ) {
        let start = slot * self.per_pixel + (index - self.first) as usize * self.stride;
        let record = &mut self.values[start..start + self.stride];
        let pixel = self.row_start + UVec2::new(slot as u32, 0);
        write_record(record, self.mis, pixel, offset, xyz, aovs, self.reach);
    }
}

/// Adds to every pixel of `tile` the totals of the sample indices `range` over the samples of
/// the pixels within reach, with its control variate's weight excess.
pub(super) fn gather_tile(
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
