//! `prism bench`: the fixed benchmark suite (see [`crate::bench`]), printed as a table or as
//! JSON lines.

use std::path::PathBuf;
use std::time::Duration;

use clap::Args;

use crate::bench::{BenchOptions, Measurement, SCENE_NAMES, measure, suite};
use prism_core::error::{Error, Result};

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Worker threads
    #[arg(long, value_name = "T", default_value_t = 2)]
    pub threads: usize,
    /// Seconds of rendering per scene for the relMSE and efficiency figures
    #[arg(long, value_name = "SECONDS", default_value_t = 10.0)]
    pub seconds: f64,
    /// Samples per pixel of the references (rendered once, on all cores, and cached)
    #[arg(long, value_name = "N", default_value_t = 1024)]
    pub reference_spp: u32,
    /// Incoherent rays per pass of the traversal measurement
    #[arg(long, value_name = "N", default_value_t = 1 << 20)]
    pub rays: usize,
    /// Only the scene of this name, or if none has it, the scenes whose names contain it
    /// (repeatable)
    #[arg(long, value_name = "NAME")]
    pub only: Vec<String>,
    /// Where the generated scene and the references are kept
    #[arg(long, value_name = "DIR", default_value = "target/prism-bench")]
    pub cache: PathBuf,
    /// Print one JSON object per scene instead of a table
    #[arg(long)]
    pub json: bool,
    /// Only list the scenes: name, file and -D values, tab-separated (writes the generated
    /// scene; tools/bench-vs-mitsuba reads this)
    #[arg(long)]
    pub list: bool,
}

/// Whether `--only pattern` selects the scene `name`: a pattern that is a scene's whole name
/// selects that scene alone (`smoke-box`, not also `smoke-box-volpathmis`); any other selects
/// the names containing it.
fn selects(pattern: &str, name: &str) -> bool {
    if SCENE_NAMES.contains(&pattern) {
        name == pattern
    } else {
        name.contains(pattern)
    }
}

pub fn run(args: &BenchArgs) -> Result<()> {
    if args.threads == 0 {
        return Err(Error::usage("--threads must be at least 1"));
    }
    if !(args.seconds > 0.0 && args.seconds <= 86_400.0) {
        return Err(Error::usage(
            "--seconds must be more than 0 and at most a day",
        ));
    }
    if !(1..=1 << 20).contains(&args.reference_spp) || args.rays == 0 {
        return Err(Error::usage(
            "--reference-spp must be between 1 and 2^20, and --rays at least 1",
        ));
    }
    let options = BenchOptions {
        threads: args.threads,
        budget: Duration::from_secs_f64(args.seconds),
        reference_spp: args.reference_spp,
        ray_count: args.rays,
        cache: args.cache.clone(),
    };
    // The bundled scenes, from the repository we are run in, else the one we were built from.
    let repository = if std::path::Path::new("scenes/cornell-box/scene.xml").exists() {
        PathBuf::from(".")
    } else {
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
    };
    let scenes = suite(&repository, &args.cache, |name| {
        args.only.is_empty() || args.only.iter().any(|o| selects(o, name))
    })?;
    if scenes.is_empty() {
        return Err(Error::usage("--only matches none of the suite's scenes")
            .with_help(format!("the scenes are {}", SCENE_NAMES.join(", "))));
    }
    if args.list {
        for scene in &scenes {
            let defines: Vec<String> = scene
                .defines
                .iter()
                .map(|(name, value)| format!("{name}={value}"))
                .collect();
            println!(
                "{}\t{}\t{}",
                scene.name,
                scene.path.display(),
                defines.join(" ")
            );
        }
        return Ok(());
    }
    if !args.json {
        println!(
            "{} threads, {} s per scene, references at {} spp",
            args.threads, args.seconds, args.reference_spp
        );
        println!(
            "{:<20} {:>10} {:>9} {:>8} {:>9} {:>10} {:>6} {:>10} {:>10}",
            "scene",
            "primitives",
            "build s",
            "B/prim",
            "Mrays/s",
            "Msamples/s",
            "spp",
            "relMSE",
            "efficiency"
        );
    }
    for scene in &scenes {
        let m = measure(scene, &options)?;
        if args.json {
            println!("{}", json(&m, args.threads));
        } else {
            println!(
                "{:<20} {:>10} {:>9.3} {:>8.1} {:>9.3} {:>10.3} {:>6} {:>10.3e} {:>10.1}",
                m.scene,
                m.primitives,
                m.bvh_build_seconds,
                m.bytes_per_primitive(),
                m.rays_per_second / 1e6,
                m.samples_per_second / 1e6,
                m.spp,
                m.rel_mse,
                m.efficiency
            );
            println!(
                "{:<20} shadow rays: {:.3} Mrays/s",
                "",
                m.shadow_rays_per_second / 1e6
            );
            if let Some(occupancy) = m.lane_occupancy {
                println!(
                    "{:<20} lanes: {:.1} of {} hold a path per step on average",
                    "",
                    occupancy * prism_core::render::LANES as f64,
                    prism_core::render::LANES
                );
            }
            if let (Some(rate), Some(shadow_rate)) =
                (m.embree_rays_per_second, m.embree_shadow_rays_per_second)
            {
                println!(
                    "{:<20} Embree {:.3} Mrays/s on the same rays: ours are {:.2}x; \
                     shadow rays {:.3} Mrays/s: ours are {:.2}x",
                    "",
                    rate / 1e6,
                    m.rays_per_second / rate,
                    shadow_rate / 1e6,
                    m.shadow_rays_per_second / shadow_rate
                );
            }
        }
    }
    Ok(())
}

/// One scene's measurement as a JSON object (on one line); a measurement without a value (an
/// Embree rate in a build without Embree) is `null`.
fn json(m: &Measurement, threads: usize) -> String {
    serde_json::json!({
        "scene": m.scene,
        "threads": threads,
        "primitives": m.primitives,
        "bvh_build_seconds": m.bvh_build_seconds,
        "geometry_bytes": m.geometry_bytes,
        "bytes_per_primitive": m.bytes_per_primitive(),
        "rays_per_second": m.rays_per_second,
        "samples_per_second": m.samples_per_second,
        "lanes": prism_core::render::LANES,
        "lane_occupancy": m.lane_occupancy,
        "spp": m.spp,
        "render_seconds": m.render_seconds,
        "rel_mse": m.rel_mse,
        "efficiency": m.efficiency,
        "embree_rays_per_second": m.embree_rays_per_second,
        "shadow_rays_per_second": m.shadow_rays_per_second,
        "embree_shadow_rays_per_second": m.embree_shadow_rays_per_second,
    })
    .to_string()
}
