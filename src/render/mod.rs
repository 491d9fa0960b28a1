//! The render driver: tiles of the crop window rendered in parallel on a rayon pool, each pixel
//! sample estimated by the scene's integrator and accumulated in the film.
//!
//! Every pixel sample draws its random numbers from the sampler's stream for (seed, pixel,
//! sample index), and every sample lands in its own pixel, so the image is bit-identical
//! whatever the number of threads and the order in which tiles finish.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use glam::{UVec2, Vec2};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::film::{Film, FilterSampler, PixelSums};
use crate::integrator::RayCount;
use crate::sampling::sampler::Sampler;
use crate::scene::Scene;
use crate::spectrum::SampledWavelengths;

/// Edge length of the square tiles the image is divided into.
const TILE_SIZE: u32 = 16;

/// How to render.
#[derive(Clone, Debug)]
pub struct RenderOptions {
    /// Samples per pixel requested (the scene's sampler gives the default); stratified samplers
    /// may round it up (see [`crate::sampling::sampler::SamplerKind::sample_count`]).
    pub samples_per_pixel: u32,
    /// Worker threads; None for one per core.
    pub threads: Option<usize>,
    /// Seed of every random stream.
    pub seed: u64,
    /// Whether to draw a progress bar on standard error.
    pub progress: bool,
}

/// What a render produced.
pub struct RenderOutput {
    pub film: Film,
    /// Samples per pixel taken.
    pub samples_per_pixel: u32,
    pub elapsed: Duration,
    /// Camera samples taken.
    pub samples: u64,
    /// Rays traced (camera, bounce and shadow rays).
    pub rays: u64,
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

/// Renders all samples of one tile; returns its pixels (row-major) and the rays traced.
fn render_tile(
    scene: &Scene,
    filter: &FilterSampler,
    tile: Tile,
    options: &RenderOptions,
) -> (Vec<PixelSums>, u64) {
    let mut sampler = Sampler::new(scene.sampler.kind, options.samples_per_pixel, options.seed);
    let samples_per_pixel = sampler.sample_count();
    let mut count = RayCount::default();
    let mut pixels = vec![PixelSums::default(); (tile.size.x * tile.size.y) as usize];
    let crop_offset = scene.film.crop.offset;
    for y in 0..tile.size.y {
        for x in 0..tile.size.x {
            let pixel = crop_offset + tile.origin + UVec2::new(x, y);
            let sums = &mut pixels[(y * tile.size.x + x) as usize];
            for index in 0..samples_per_pixel {
                sampler.start_pixel_sample(pixel, index);
                let primary = sampler.camera_sample();
                let lambda =
                    SampledWavelengths::sample(primary.wavelength, scene.wavelength_sampling);
                let (offset, filter_weight) = filter.sample(primary.film);
                let (time, time_weight) = scene.shutter.sample(primary.time);
                let film_position = pixel.as_vec2() + Vec2::splat(0.5) + offset;
                let ray = scene.camera.generate_ray(film_position, primary.lens, time);
                let radiance =
                    scene
                        .integrator
                        .radiance(scene, ray, &lambda, &mut sampler, &mut count);
                let weight = filter_weight * time_weight;
                let xyz = lambda.to_xyz(&radiance).map(|v| v * weight);
                sums.add(xyz);
            }
        }
    }
    (pixels, count.rays)
}

/// Renders the scene.
pub fn render(scene: &Scene, options: &RenderOptions) -> Result<RenderOutput> {
    let crop = scene.film.crop;
    let mut film = Film::new(scene.film.size, crop);
    let filter = FilterSampler::new(scene.film.filter);
    let tiles = tiles(crop.size);
    let samples_per_pixel = scene.sampler.kind.sample_count(options.samples_per_pixel);
    let total_samples =
        u64::from(crop.size.x) * u64::from(crop.size.y) * u64::from(samples_per_pixel);

    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(threads) = options.threads {
        builder = builder.num_threads(threads);
    }
    let pool = builder
        .build()
        .map_err(|e| Error::usage(format!("could not start the worker threads: {e}")))?;

    let progress = if options.progress {
        let bar = ProgressBar::with_draw_target(Some(total_samples), ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template(
                "{bar:40.cyan/blue} {percent:>3}% {human_pos}/{human_len} samples, {per_sec}, ETA {eta}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        bar
    } else {
        ProgressBar::hidden()
    };
    let rays = AtomicU64::new(0);
    let start = Instant::now();
    let rendered: Vec<(Tile, Vec<PixelSums>)> = pool.install(|| {
        tiles
            .par_iter()
            .map(|&tile| {
                let (pixels, tile_rays) = render_tile(scene, &filter, tile, options);
                rays.fetch_add(tile_rays, Ordering::Relaxed);
                progress.inc(u64::from(tile.size.x * tile.size.y) * u64::from(samples_per_pixel));
                (tile, pixels)
            })
            .collect()
    });
    let elapsed = start.elapsed();
    progress.finish_and_clear();

    for (tile, pixels) in rendered {
        for y in 0..tile.size.y {
            for x in 0..tile.size.x {
                let index = film.index(tile.origin.x + x, tile.origin.y + y);
                film.pixels[index] = pixels[(y * tile.size.x + x) as usize];
            }
        }
    }
    Ok(RenderOutput {
        film,
        samples_per_pixel,
        elapsed,
        samples: total_samples,
        rays: rays.into_inner(),
    })
}
