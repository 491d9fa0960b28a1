//! Filter MIS in the render driver ([`crate::film::reconstruction`] has the estimator): the
//! samples of a batch of indices traced for every pixel within the filter's reach of the crop
//! window and kept, then gathered by every pixel from its neighbours, always in the same order.

use std::ops::Range;

use glam::{UVec2, Vec4};
use rayon::prelude::*;

use super::RenderOptions;
use super::estimator::SampleEstimator;
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
    /// over rows. None when the pass was cancelled.
    pub(super) fn trace(
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
