//! The benchmark suite behind `prism bench`: fixed scenes, and for each the BVH build time, its
//! memory, incoherent rays/s, samples/s and the relative MSE reached in a fixed time.
//!
//! Efficiency is 1 / (relMSE × seconds) (Veach's thesis §2.3 calls the inverse the cost of an
//! estimator): relMSE falls as 1/N, so the product is independent of how long one renders and
//! compares renderers (or integrators) that trade speed for noise. relMSE is measured against a
//! high-sample reference rendered by Prism itself with another seed, so it is the estimator's
//! variance (plus the reference's own, which its sample count makes small); a bias between two
//! renderers is the business of parity tests, not of this benchmark.

pub mod generated;
pub mod rays;

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use prism_core::error::{Error, Result};
use prism_core::film::write_images;
use prism_core::geometry::Geometry;
use prism_core::image::compare::rel_mse_rgb;
use prism_core::image::read_exr;
use prism_core::math::Ray;
use prism_core::render::{RenderOptions, render};
use prism_core::scene::Scene;
use prism_mitsuba::load_scene;

/// One scene of the suite: a file and the `-D` values that set its resolution.
#[derive(Clone, Debug)]
pub struct BenchScene {
    pub name: &'static str,
    pub path: PathBuf,
    pub defines: Vec<(String, String)>,
}

/// The names of the suite's scenes, in its order.
pub const SCENE_NAMES: [&str; 6] = [
    "cornell-box",
    "veach-mis",
    "veach-bidir",
    "smoke-box",
    "smoke-box-volpathmis",
    "million-triangles",
];

/// The fixed suite, of the scenes bundled in the repository's `scenes/`: the Cornell box
/// (256 × 256), Veach's MIS and bidirectional scenes (at 320 × 180 and 256 × 256, a twentieth
/// and a sixteenth of their pixels, so that references take minutes), a heterogeneous medium
/// (`scenes/media/smoke-box.xml`, 128 × 128, rendered by `volpath` and, as
/// `smoke-box-volpathmis`, by `volpathmis`), and the generated
/// million-triangle scene (256 × 256), written into `cache` on first use. Only the scenes
/// `wanted` accepts are set up.
pub fn suite(
    repository: &Path,
    cache: &Path,
    wanted: impl Fn(&str) -> bool,
) -> Result<Vec<BenchScene>> {
    let resolution = |x: u32, y: u32| {
        vec![
            ("resx".to_string(), x.to_string()),
            ("resy".to_string(), y.to_string()),
        ]
    };
    let mut scenes = Vec::new();
    for (name, file, x, y, integrator) in [
        ("cornell-box", "cornell-box/scene.xml", 256, 256, None),
        ("veach-mis", "veach-mis/scene.xml", 320, 180, None),
        ("veach-bidir", "veach-bidir/scene.xml", 256, 256, None),
        ("smoke-box", "media/smoke-box.xml", 128, 128, None),
        (
            "smoke-box-volpathmis",
            "media/smoke-box.xml",
            128,
            128,
            Some("volpathmis"),
        ),
    ] {
        if wanted(name) {
            let mut defines = resolution(x, y);
            if let Some(integrator) = integrator {
                defines.push(("integrator".to_string(), integrator.to_string()));
            }
            scenes.push(BenchScene {
                name,
                path: repository.join("scenes").join(file),
                defines,
            });
        }
    }
    if wanted("million-triangles") {
        scenes.push(BenchScene {
            name: "million-triangles",
            path: generated::write_million_triangle_scene(cache)?,
            defines: resolution(256, 256),
        });
    }
    Ok(scenes)
}

/// How to measure.
#[derive(Clone, Debug)]
pub struct BenchOptions {
    pub threads: usize,
    /// Render time of the relMSE measurement.
    pub budget: Duration,
    /// Samples per pixel of the references.
    pub reference_spp: u32,
    /// Incoherent rays traced for the rays/s figure (each timed pass traces them all).
    pub ray_count: usize,
    /// Where references are kept between runs.
    pub cache: PathBuf,
}

/// What was measured on one scene.
#[derive(Clone, Debug)]
pub struct Measurement {
    pub scene: String,
    /// Triangles in the BVH (after dropping degenerate ones) plus analytic shapes.
    pub primitives: usize,
    /// Building the BVH over all shapes (scene loading excluded), the fastest of three builds.
    pub bvh_build_seconds: f64,
    /// Shapes plus BVH, from [`Geometry::memory_bytes`].
    pub geometry_bytes: usize,
    /// Closest-hit queries per second on incoherent rays ([`rays::incoherent_rays`]), without
    /// building surface interactions: the fastest pass over them ([`trace_rates`]).
    pub rays_per_second: f64,
    /// The same with Embree on the same rays (builds with the cargo feature `embree` only).
    pub embree_rays_per_second: Option<f64>,
    /// Occlusion queries per second on shadow rays ([`rays::shadow_rays`]); 0 for a scene
    /// without lights to sample.
    pub shadow_rays_per_second: f64,
    /// The same with Embree.
    pub embree_shadow_rays_per_second: Option<f64>,
    pub samples_per_second: f64,
    /// The mean share of the lanes that held a path per step, where the scene's paths run in
    /// lanes (the path tracer's).
    pub lane_occupancy: Option<f64>,
    /// Samples per pixel rendered in the budget.
    pub spp: u32,
    pub render_seconds: f64,
    /// Relative MSE of that render against the reference (mean over R, G, B).
    pub rel_mse: f64,
    /// 1 / (relMSE × seconds).
    pub efficiency: f64,
}

impl Measurement {
    /// Memory per BVH primitive.
    pub fn bytes_per_primitive(&self) -> f64 {
        self.geometry_bytes as f64 / self.primitives.max(1) as f64
    }
}

/// A rayon pool of `threads` workers, for the parts that are not renders.
fn pool(threads: usize) -> Result<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::usage(format!("could not start the worker threads: {e}")))
}

/// Queries per second of each of `queries` over the same `rays` (a closest hit or an
/// occlusion test: a query says whether the ray hit), traced in parallel, and each one's number
/// of hits. The queries take turns, one pass over the rays each, for at least a second per
/// query and three turns, and each one's rate is that of its fastest pass: on a machine whose
/// speed drifts by tens of percent within seconds (a shared virtual machine), one after the
/// other for a second each made the ratio of two unchanged structures vary by ±15 %.
pub fn trace_rates(
    threads: usize,
    rays: &[Ray],
    queries: &[&(dyn Fn(&Ray) -> bool + Sync)],
) -> Result<Vec<(f64, usize)>> {
    use rayon::prelude::*;
    let pool = pool(threads)?;
    let mut results = vec![(0.0f64, 0usize); queries.len()];
    let budget = Duration::from_secs(queries.len() as u64);
    let start = Instant::now();
    let mut turns = 0;
    while turns < 3 || start.elapsed() < budget {
        for (query, (rate, hits)) in queries.iter().zip(&mut results) {
            let pass = Instant::now();
            *hits = pool.install(|| {
                rays.par_chunks(1024)
                    .map(|chunk| chunk.iter().filter(|ray| query(ray)).count())
                    .sum()
            });
            *rate = rate.max(rays.len() as f64 / pass.elapsed().as_secs_f64());
        }
        turns += 1;
    }
    Ok(results)
}

/// The closest-hit query of `geometry`, as [`trace_rates`] takes it.
fn closest_hit(geometry: &Geometry) -> impl Fn(&Ray) -> bool + Sync + '_ {
    move |ray| geometry.closest_hit(ray).is_some()
}

/// The occlusion query of `geometry`, as [`trace_rates`] takes it.
fn occluded(geometry: &Geometry) -> impl Fn(&Ray) -> bool + Sync + '_ {
    move |ray| geometry.occluded(ray)
}

/// The reference image of `scene` at `spp`, read from the cache or rendered (once) into it.
fn reference(
    scene: &Scene,
    bench: &BenchScene,
    options: &BenchOptions,
) -> Result<prism_core::image::ChannelImage> {
    // The scene's fingerprint covers its files and -D values: an edited scene gets a new one.
    let path = options.cache.join(format!(
        "{}-{:016x}-{}spp.exr",
        bench.name, scene.fingerprint, options.reference_spp
    ));
    if !path.exists() {
        eprintln!(
            "prism bench: rendering the reference of {} at {} spp (once; kept in {})",
            bench.name,
            options.reference_spp,
            path.display()
        );
        // Another seed than the measured renders', so the two are independent.
        let seed = 0x5eed_0f4e;
        let threads = std::thread::available_parallelism().map_or(options.threads, |n| n.get());
        let output = render(
            scene,
            &RenderOptions::fixed(options.reference_spp, seed, Some(threads)),
        )?;
        std::fs::create_dir_all(&options.cache)
            .map_err(|e| Error::io(&options.cache, &e, "create the directory"))?;
        let partial = path.with_extension("partial.exr");
        write_images(&output.film, &partial, &path.with_extension("png"))?;
        std::fs::rename(&partial, &path).map_err(|e| Error::io(&path, &e, "write"))?;
    }
    read_exr(&path)
}

/// Measures one scene.
pub fn measure(bench: &BenchScene, options: &BenchOptions) -> Result<Measurement> {
    let scene = load_scene(&bench.path, &bench.defines)?.scene;

    // The BVH again, timed alone (the scene's own was built while loading): the fastest of
    // three builds, for the reason given at `trace_rates`.
    let pool = pool(options.threads)?;
    let mut bvh_build_seconds = f64::INFINITY;
    let (mut primitives, mut geometry_bytes) = (0, 0);
    for _ in 0..3 {
        let shapes = scene.world.geometry.primitives.clone();
        let start = Instant::now();
        let rebuilt = pool.install(|| Geometry::new(shapes));
        bvh_build_seconds = bvh_build_seconds.min(start.elapsed().as_secs_f64());
        primitives = rebuilt.primitive_count();
        geometry_bytes = rebuilt.memory_bytes();
    }

    let rays = rays::incoherent_rays(&scene, options.ray_count, 1);
    let shadow_rays = rays::shadow_rays(&scene, options.ray_count, 2);
    let ours = &scene.world.geometry;
    let embree = if cfg!(feature = "embree") {
        let mut embree = scene.world.geometry.clone();
        crate::accel::Accel::Embree.apply(&mut embree)?;
        Some(embree)
    } else {
        None
    };
    let (ours_closest, ours_occluded) = (closest_hit(ours), occluded(ours));
    let mut closest: Vec<&(dyn Fn(&Ray) -> bool + Sync)> = vec![&ours_closest];
    let mut shadow: Vec<&(dyn Fn(&Ray) -> bool + Sync)> = vec![&ours_occluded];
    let embree_queries = embree.as_ref().map(|e| (closest_hit(e), occluded(e)));
    if let Some((embree_closest, embree_occluded)) = &embree_queries {
        closest.push(embree_closest);
        shadow.push(embree_occluded);
    }
    let closest = trace_rates(options.threads, &rays, &closest)?;
    let shadow = if shadow_rays.is_empty() {
        vec![(0.0, 0); closest.len()]
    } else {
        trace_rates(options.threads, &shadow_rays, &shadow)?
    };
    let (rays_per_second, hits) = closest[0];
    let (shadow_rays_per_second, occluded_count) = shadow[0];
    let (embree_rays_per_second, embree_shadow_rays_per_second) = if embree.is_some() {
        let ((rate, embree_hits), (shadow_rate, embree_occluded)) = (closest[1], shadow[1]);
        // The two structures must agree, or the comparison means nothing (a ray grazing an
        // edge may rarely go either way).
        for (what, theirs, ours, count) in [
            ("hit", embree_hits, hits, rays.len()),
            (
                "found occluded",
                embree_occluded,
                occluded_count,
                shadow_rays.len(),
            ),
        ] {
            if theirs.abs_diff(ours) > count / 10_000 {
                return Err(Error::usage(format!(
                    "Embree {what} {theirs} of the {count} rays and our BVH {ours}"
                )));
            }
        }
        (Some(rate), Some(shadow_rate))
    } else {
        (None, None)
    };

    let reference = reference(&scene, bench, options)?;
    // One sample per pixel says how long a sample takes; the measured render then fills the
    // budget with a fixed sample count (so that no pass is cut short).
    let probe = render(&scene, &RenderOptions::fixed(1, 1, Some(options.threads)))?;
    let spp = ((options.budget.as_secs_f64() / probe.elapsed.as_secs_f64().max(1e-6)) as u32)
        .clamp(1, 1 << 16);
    let output = render(&scene, &RenderOptions::fixed(spp, 2, Some(options.threads)))?;
    let render_seconds = output.elapsed.as_secs_f64();
    let rel_mse = rel_mse_rgb(&output.film.linear_srgb(), &reference)?;
    Ok(Measurement {
        scene: bench.name.to_string(),
        primitives,
        bvh_build_seconds,
        geometry_bytes,
        rays_per_second,
        embree_rays_per_second,
        shadow_rays_per_second,
        embree_shadow_rays_per_second,
        samples_per_second: output.sample_count as f64 / render_seconds,
        lane_occupancy: output.lane_occupancy,
        spp,
        render_seconds,
        rel_mse,
        efficiency: 1.0 / (rel_mse * render_seconds),
    })
}
