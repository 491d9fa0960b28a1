//! Full-scene throughput: the bundled Cornell box rendered at 64 × 64 pixels and 16 samples per
//! pixel (the scene's path integrator, unbounded depth with Russian roulette, independent
//! sampler) through [`prism_core::render::render`], as `prism render` does it but without writing
//! images. One iteration is one whole render of 65,536 camera samples; Criterion reports
//! samples (elements) per second, once on one thread (the cost of a sample) and once on all
//! cores (the scaling of the tile scheduler).

mod common;

use std::path::Path;

use criterion::{Criterion, SamplingMode, Throughput, criterion_group, criterion_main};
use prism_core::render::{RenderOptions, render};
use prism_mitsuba::load_scene;

const RESOLUTION: u32 = 64;
const SPP: u32 = 16;

fn cornell_box(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell-box/scene.xml");
    let defines = [
        ("resx".to_string(), RESOLUTION.to_string()),
        ("resy".to_string(), RESOLUTION.to_string()),
        ("spp".to_string(), SPP.to_string()),
    ];
    let scene = load_scene(&path, &defines)
        .unwrap_or_else(|e| panic!("{e}"))
        .scene;
    let mut group = c.benchmark_group("render/cornell-box");
    group.throughput(Throughput::Elements(u64::from(
        RESOLUTION * RESOLUTION * SPP,
    )));
    // An iteration takes a tenth of a second or more: few samples of the same iteration count.
    group.sample_size(10).sampling_mode(SamplingMode::Flat);
    for (id, threads) in [("1_thread", Some(1)), ("all_threads", None)] {
        let options = RenderOptions::fixed(SPP, 0, threads);
        group.bench_function(id, |b| {
            b.iter(|| render(&scene, &options).unwrap_or_else(|e| panic!("{e}")));
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = common::criterion();
    targets = cornell_box
}
criterion_main!(benches);
