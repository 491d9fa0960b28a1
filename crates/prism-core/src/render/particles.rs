//! A pass of the particle tracer: for each sample index, one light-subpath sample per pixel of
//! the full film (keyed, as camera samples are, by the pixel and the index), splatted through
//! the reconstruction filter onto the crop window ([`crate::film::splat`]). Bidirectional path
//! tracing runs the same way, each sample also tracing a camera subpath from its pixel, whose
//! estimate adds to that pixel ([`Splatting`]).
//!
//! The light subpaths of one index are traced in parallel, a few hundred pixels' worth at a
//! time, in batches that bound the memory their contributions take before they are gathered
//! into exact sums; the sums make the order in which they finish irrelevant. The total that index s brings pixel j, T_s(j), is an unbiased estimate of
//! the pixel by itself: the image is the mean of the T_s over the indices, and the pixel's
//! variance is estimated from their spread (batch means, each index a batch of W·H light
//! subpaths). Per-sample variance does not apply, since one light subpath feeds many pixels
//! and a pixel gets contributions from subpaths started anywhere. The indices are independent
//! (each pixel's random stream is), so the estimate is honest; with a stratified sampler they
//! are negatively correlated within a pixel's stream and it is conservative.
//!
//! Every pixel of a sample index thus gets one "sample", whatever the number of subpaths
//! that reached it, so checkpoints, `--resume` and `prism merge` keep and add these sums as
//! they do a camera-sample render's, and the image is bit-identical whatever the thread count,
//! the passes and the sample ranges merged. The coverage alpha, where the film has one, is 1.

use std::ops::Range;

use glam::{UVec2, Vec2};
use rayon::prelude::*;

use super::pass::Pass;
use super::tiles::TileSums;
use crate::camera::{CameraModel, CameraRay};
use crate::film::accumulation::{AOV_SUMS_PER_CHANNEL, acceptable_sample, add_aov_sample};
use crate::film::{CropWindow, SplatSums, SplatValue, Splatter};
use crate::integrator::{
    BdptIntegrator, LightPathSample, ParticleTracer, RayCount, Splat, VcmIntegrator,
};
use crate::sampling::sampler::{CameraSample, Sampler};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// Light subpaths a worker traces at a time (pixels of the full film, row-major).
const PATHS_PER_TASK: u32 = 256;
/// Tasks traced before their contributions are gathered.
const TASKS_PER_BATCH: usize = 64;

/// The estimators whose samples are splatted.
#[derive(Clone, Copy, Debug)]
pub(super) enum Splatting<'a> {
    /// The particle tracer: light subpaths alone.
    Particle(&'a ParticleTracer),
    /// Bidirectional path tracing: a camera sample of the pixel the sample is keyed by, whose
    /// estimate adds to that pixel alone (weighted by the reconstruction filter as the
    /// one-pixel reconstruction weighs it), and a light subpath whose connections to the
    /// camera are splatted.
    Bidirectional(&'a BdptIntegrator),
    /// Vertex connection and merging: each sample index an iteration, all its light subpaths
    /// traced (their connections to the camera splatted) before its camera subpaths, which
    /// connect to their pixel's light subpath and merge with every light subpath's vertices
    /// ([`super::vcm`]).
    Vcm(&'a VcmIntegrator),
}

/// Gathers one task's contributions in CIE XYZ, spread over the pixels they reach.
pub(super) struct Collector<'a> {
    pub(super) splatter: &'a Splatter,
    pub(super) crop: CropWindow,
    /// The wavelengths of the sample at hand, and its shutter weight.
    pub(super) lambda: SampledWavelengths,
    pub(super) time_weight: f32,
    pub(super) values: Vec<SplatValue>,
}

impl<'a> Collector<'a> {
    /// A collector for the crop window `crop`, with no contribution yet.
    pub(super) fn new(
        splatter: &'a Splatter,
        crop: CropWindow,
        lambda: SampledWavelengths,
    ) -> Collector<'a> {
        Collector {
            splatter,
            crop,
            lambda,
            time_weight: 1.0,
            values: Vec::new(),
        }
    }

    /// Adds the CIE XYZ `xyz` to the full film's pixel `pixel` alone, if it is in the crop
    /// window.
    pub(super) fn add_to_pixel(&mut self, pixel: UVec2, xyz: [f32; 3]) {
        let (offset, size) = (self.crop.offset, self.crop.size);
        if pixel.x < offset.x
            || pixel.y < offset.y
            || pixel.x >= offset.x + size.x
            || pixel.y >= offset.y + size.y
            || !acceptable_sample(&xyz)
        {
            return;
        }
        let local = pixel - offset;
        self.values.push(SplatValue {
            pixel: local.y * size.x + local.x,
            xyz: xyz.map(f64::from),
        });
    }
}

impl Splat for Collector<'_> {
    #[inline]
    fn reaches(&self, film: Vec2) -> bool {
        self.splatter.reaches(film)
    }

    #[inline]
    fn splat(&mut self, film: Vec2, value: SampledSpectrum) {
        let xyz = self.lambda.to_xyz(&value).map(|v| v * self.time_weight);
        // A contribution that is not finite (a numerical failure) adds nothing.
        if !acceptable_sample(&xyz) {
            return;
        }
        let values = &mut self.values;
        self.splatter.for_each_pixel(film, |pixel, weight| {
            values.push(SplatValue {
                pixel: pixel as u32,
                xyz: xyz.map(|v| f64::from(v) * f64::from(weight)),
            });
        });
    }
}

impl Pass<'_, '_> {
    /// The camera sample of `pixel` for sample index `index` drawn from `sampler` (which the
    /// light and camera subpaths of that sample go on drawing from), with its time and shutter
    /// weight.
    pub(super) fn start_sample(
        &self,
        sampler: &mut Sampler,
        pixel: UVec2,
        index: u32,
    ) -> (CameraSample, f32, f32) {
        sampler.start_pixel_sample(pixel, index);
        let primary = sampler.camera_sample();
        let (time, time_weight) = self.estimator.scene.shutter.sample(primary.time);
        (primary, time, time_weight)
    }

    /// Writes into `out` the tiles' `sums` with the light subpaths of the sample indices
    /// `range` added (see the module's text); returns the rays traced, or None when the pass
    /// was cancelled.
    pub(super) fn render_particles(
        &self,
        splatting: Splatting,
        sums: &[TileSums],
        out: &mut [TileSums],
        range: Range<u32>,
    ) -> Option<u64> {
        let estimator = self.estimator;
        let scene = estimator.scene;
        let film = &scene.film;
        let crop = film.crop;
        let splatter = Splatter::new(film.filter, crop);
        let paths = film.size.x * film.size.y;
        let tasks: Vec<Range<u32>> = (0..paths)
            .step_by(PATHS_PER_TASK as usize)
            .map(|start| start..(start + PATHS_PER_TASK).min(paths))
            .collect();
        for (tile_out, tile_sums) in out.iter_mut().zip(sums) {
            tile_out.clone_from(tile_sums);
        }
        let k = estimator.aov_count();
        let stride = AOV_SUMS_PER_CHANNEL * k;
        let coverage = vec![1.0f32; k];
        let crop_pixels = u64::from(crop.size.x) * u64::from(crop.size.y);
        let mut image = SplatSums::default();
        let mut rays = 0;
        for index in range {
            image.clear(crop_pixels as usize);
            if let Splatting::Vcm(vcm) = splatting {
                rays += self.trace_vcm_iteration(vcm, &splatter, &tasks, index, &mut image)?;
            } else {
                for batch in tasks.chunks(TASKS_PER_BATCH) {
                    let traced: Vec<Option<(Vec<SplatValue>, u64)>> = batch
                        .par_iter()
                        .map(|pixels| self.trace_task(splatting, &splatter, pixels.clone(), index))
                        .collect();
                    for task in traced {
                        let (values, task_rays) = task?;
                        image.add(&values);
                        rays += task_rays;
                    }
                }
            }
            out.par_iter_mut()
                .zip(self.tiles)
                .for_each(|(tile_sums, tile)| {
                    for y in 0..tile.size.y {
                        for x in 0..tile.size.x {
                            let i = (y * tile.size.x + x) as usize;
                            let row_major =
                                ((tile.origin.y + y) * crop.size.x + tile.origin.x + x) as usize;
                            tile_sums.pixels[i].add_total(image.value(row_major));
                            add_aov_sample(
                                &mut tile_sums.aovs[i * stride..i * stride + k],
                                &coverage,
                            );
                        }
                    }
                });
            self.progress.advance(crop_pixels);
        }
        Some(rays)
    }

    /// Traces the light subpaths of sample `index` keyed by the full film's pixels `pixels`
    /// (row-major indices); returns their contributions and the rays traced, or None when the
    /// pass was cancelled.
    fn trace_task(
        &self,
        splatting: Splatting,
        splatter: &Splatter,
        pixels: Range<u32>,
        index: u32,
    ) -> Option<(Vec<SplatValue>, u64)> {
        if self.cancel.raised() {
            return None;
        }
        let scene = self.estimator.scene;
        let film = &scene.film;
        let mut sampler = Sampler::new(
            scene.sampler.kind,
            self.options.samples_per_pixel,
            self.options.seed,
        );
        let mut count = RayCount::default();
        let mut collector = Collector::new(
            splatter,
            film.crop,
            SampledWavelengths::sample(0.5, film.wavelength_sampling),
        );
        let integrator = &self.estimator.integrator;
        for pixel in pixels {
            let pixel = UVec2::new(pixel % film.size.x, pixel / film.size.x);
            let (primary, time, time_weight) = self.start_sample(&mut sampler, pixel, index);
            let lambda = SampledWavelengths::sample(primary.wavelength, film.wavelength_sampling);
            collector.lambda = lambda;
            collector.time_weight = time_weight;
            let sample = LightPathSample {
                camera: &scene.camera,
                lambda: &lambda,
                time,
                u_lens: primary.lens,
            };
            match splatting {
                Splatting::Particle(ptracer) => integrator.trace_light_paths(
                    ptracer,
                    &sample,
                    &mut sampler,
                    &mut count,
                    &mut collector,
                ),
                Splatting::Bidirectional(bdpt) => {
                    let (film_position, filter_weight) =
                        self.estimator.film_position(pixel, primary.film);
                    let CameraRay { ray, weight } =
                        scene.camera.generate_ray(film_position, primary.lens, time);
                    let radiance = integrator.trace_bidirectional(
                        bdpt,
                        &sample,
                        ray,
                        &mut sampler,
                        &mut count,
                        &mut collector,
                    );
                    let scale = weight * time_weight * filter_weight;
                    let xyz = lambda.to_xyz(&radiance).map(|v| v * scale);
                    collector.add_to_pixel(pixel, xyz);
                }
                Splatting::Vcm(_) => unreachable!("vcm's iterations are traced whole"),
            }
        }
        Some((collector.values, count.rays))
    }
}
