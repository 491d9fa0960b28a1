//! The stages of a camera sample that the other benchmarks leave out, each alone, per second
//! (`tools/profile-stages` gives their share of a render's time; `traversal`, `bsdf` and
//! `lights` measure ray queries with the surface interaction, BSDFs and light sampling):
//! - `camera_sample`: the sampler's numbers for one pixel sample (its stream started at the
//!   pixel and index), the four wavelengths drawn from the film's density, the filter offset
//!   drawn from the tent's closed form, the shutter time and the camera ray;
//! - `to_xyz`: a sample's spectral radiance at its four wavelengths turned into CIE XYZ;
//! - `pixel_sums`: an XYZ value added to the exact sums (and sums of squares) of a pixel;
//! - `cosine_hemisphere_one_lane` and `cosine_hemisphere_lanes`: the cosine-weighted direction
//!   of a diffuse bounce, written once ([`prism_core::math::lanes::Real`]), one sample at a
//!   time and [`F32s::LANES`] at a time (the gain of running a stage in lanes).
//!
//! The camera is the bundled Cornell box's at 256 × 256, the sampler `independent`; each
//! iteration covers 4,096 samples (a 64 × 64 block of pixels, one sample each, at sample index
//! 3), and Criterion reports samples (elements) per second.

mod common;

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::{UVec2, Vec2};
use prism_core::camera::CameraModel;
use prism_core::film::{Filter, FilterSampler, PixelSums, TentFilter};
use prism_core::math::lanes::{F32s, Real};
use prism_core::sampling::rng::Pcg32;
use prism_core::sampling::sampler::Sampler;
use prism_core::sampling::warp::cosine_hemisphere;
use prism_core::spectrum::{SampledSpectrum, SampledWavelengths};
use prism_mitsuba::load_scene;

/// Samples per iteration: a 64 × 64 block of pixels.
const BLOCK: u32 = 64;

fn stages(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell-box/scene.xml");
    let defines = [
        ("resx".to_string(), "256".to_string()),
        ("resy".to_string(), "256".to_string()),
        ("sampler".to_string(), "independent".to_string()),
    ];
    let scene = load_scene(&path, &defines)
        .unwrap_or_else(|e| panic!("{e}"))
        .scene;
    let mut group = c.benchmark_group("stages");
    group.throughput(Throughput::Elements(u64::from(BLOCK * BLOCK)));

    let filter = FilterSampler::new(Filter::Tent(TentFilter { radius: 1.0 }));
    let mut sampler = Sampler::new(scene.sampler.kind, 64, 0);
    group.bench_function("camera_sample", |b| {
        b.iter(|| {
            for y in 0..BLOCK {
                for x in 0..BLOCK {
                    let pixel = UVec2::new(x + 96, y + 96);
                    sampler.start_pixel_sample(pixel, 3);
                    let primary = sampler.camera_sample();
                    let lambda = SampledWavelengths::sample(
                        primary.wavelength,
                        scene.film.wavelength_sampling,
                    );
                    let (offset, weight) = filter.sample(primary.film);
                    let (time, _) = scene.shutter.sample(primary.time);
                    let film = pixel.as_vec2() + Vec2::splat(0.5) + offset;
                    let ray = scene.camera.generate_ray(film, primary.lens, time).ray;
                    black_box((lambda, weight, ray));
                }
            }
        });
    });

    // Fixed wavelengths and radiances, drawn once outside the timed loop.
    let mut rng = Pcg32::seeded(7);
    let samples: Vec<(SampledWavelengths, SampledSpectrum)> = (0..BLOCK * BLOCK)
        .map(|_| {
            let lambda = SampledWavelengths::sample(rng.next_f32(), scene.film.wavelength_sampling);
            let radiance = SampledSpectrum::from_fn(|_| rng.next_f32());
            (lambda, radiance)
        })
        .collect();
    group.bench_function("to_xyz", |b| {
        b.iter(|| {
            for (lambda, radiance) in &samples {
                black_box(lambda.to_xyz(black_box(radiance)));
            }
        });
    });

    let values: Vec<[f32; 3]> = samples
        .iter()
        .map(|(lambda, radiance)| lambda.to_xyz(radiance))
        .collect();
    let mut pixels = vec![PixelSums::default(); (BLOCK * BLOCK) as usize];
    group.bench_function("pixel_sums", |b| {
        b.iter(|| {
            for (pixel, xyz) in pixels.iter_mut().zip(&values) {
                pixel.add(*xyz);
            }
        });
    });

    let us: Vec<f32> = (0..BLOCK * BLOCK).map(|_| rng.next_f32()).collect();
    let vs: Vec<f32> = (0..BLOCK * BLOCK).map(|_| rng.next_f32()).collect();
    let mut zs = vec![0.0f32; us.len()];
    group.bench_function("cosine_hemisphere_one_lane", |b| {
        b.iter(|| {
            for ((z, &u), &v) in zs.iter_mut().zip(&us).zip(&vs) {
                let (x, y, w) = cosine_hemisphere((black_box(u), v));
                *z = x + y + w;
            }
        });
    });
    group.bench_function("cosine_hemisphere_lanes", |b| {
        b.iter(|| {
            let lanes = us
                .chunks_exact(F32s::LANES)
                .zip(vs.chunks_exact(F32s::LANES));
            for (z, (u, v)) in zs.chunks_exact_mut(F32s::LANES).zip(lanes) {
                let (x, y, w) =
                    cosine_hemisphere((F32s::from_lanes(black_box(u)), F32s::from_lanes(v)));
                (x + y + w).write_lanes(z);
            }
        });
    });
    black_box(&zs);
    group.finish();
}

criterion_group! {
    name = benches;
    config = common::criterion();
    targets = stages
}
criterion_main!(benches);
