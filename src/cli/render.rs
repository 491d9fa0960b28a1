//! `prism render`: load a scene, render it, write EXR and PNG, print a summary line.
//!
//! Long renders are safe to interrupt: on SIGINT or SIGTERM the pass in flight is dropped, the
//! image and a render state are written, and the program exits with 130 or 143, saying how to
//! resume; a second signal exits at once (state files are only ever replaced atomically, so
//! nothing is corrupted). `--checkpoint` writes the state every `--checkpoint-every` seconds,
//! `--resume` continues from a state, and `--sample-range` renders part of the samples for
//! `prism merge` (see docs/render-farm.md).

use std::io::IsTerminal;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};
use std::time::{Duration, Instant};

use clap::Args;
use glam::UVec2;

use super::denoise::write_denoised_images;
use super::display_server::{DisplayServer, parse_address};
use super::progress_bar::TerminalProgress;
use crate::accel::Accel;
use prism_core::error::{Error, Result};
use prism_core::film::stats::rejected_report;
use prism_core::film::{
    ComponentFormat, CropWindow, ImageOutput, PixelSums, Reconstruction, RenderMetadata,
    write_images_with,
};
use prism_core::integrator::{Integrator, RayCount};
use prism_core::render::resume::Continuation;
use prism_core::render::sppm;
use prism_core::render::{
    Checkpoints, Preview, ProgressReport, RenderOptions, SampleEstimator, Snapshot, StopReason,
    StopRule, StopRuleNames, render_with_preview,
};
use prism_core::sampling::sampler::Sampler;
use prism_core::scene::Scene;
use prism_core::spectrum::WavelengthSampling;
use prism_mitsuba::fingerprint::{override_reconstruction, override_wavelengths};
use prism_mitsuba::load_scene;

/// The headings grouping `prism render --help`'s options.
const SCENE: &str = "Scene";
const OUTPUT: &str = "Output";
const SAMPLING: &str = "Sampling";
const STOPPING: &str = "Stopping";
const CHECKPOINTS: &str = "Checkpoints and render farms";
const PROGRESS: &str = "Progress and preview";
const PERFORMANCE: &str = "Performance";
const DEBUGGING: &str = "Debugging";

/// The examples at the end of `prism render --help`.
pub const EXAMPLES: &str = "\
Examples:
  prism render scenes/cornell-box/scene.xml --spp 64
      the Cornell box at 64 samples per pixel: cornell-box.exr and .png
  prism render scene.xml --time-limit 600 --checkpoint run.state
      ten minutes of samples; `--resume run.state --spp 4096` carries on
  prism render scene.xml -D resx=1920 --display-server 127.0.0.1:14158
      a parameter set, the image shown as it develops in tev";

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// The scene file: Mitsuba 3 XML, or pbrt-v4 for a name ending in .pbrt.
    pub scene: PathBuf,
    /// Set a scene parameter declared with `<default name=... value=...>` (repeatable)
    #[arg(short = 'D', long = "define", value_name = "NAME=VALUE", value_parser = parse_define, help_heading = SCENE)]
    pub defines: Vec<(String, String)>,
    /// Render through this sensor of a scene with several: its id, or its index from 0 in
    /// document order [default: the first]
    #[arg(long, value_name = "INDEX|ID", help_heading = SCENE)]
    pub sensor: Option<String>,
    /// Output EXR file; the PNG goes beside it [default: the scene's name in the current folder;
    /// for a file called scene.xml, the name of its folder]
    #[arg(short, long, value_name = "OUT.exr", help_heading = OUTPUT)]
    pub output: Option<PathBuf>,
    /// Samples per pixel [default: the scene's sampler]
    #[arg(long, value_name = "N", help_heading = SAMPLING)]
    pub spp: Option<u32>,
    /// Seed of the random numbers [default: the sampler's seed, else 0]
    #[arg(long, value_name = "S", help_heading = SAMPLING)]
    pub seed: Option<u64>,
    /// Render only the pixels x0 <= x < x1, y0 <= y < y1 of the film
    #[arg(long, value_name = "X0,Y0,X1,Y1", value_parser = parse_crop, help_heading = OUTPUT)]
    pub crop: Option<[u32; 4]>,
    /// Stop after this many seconds (the pass running then is dropped); without --spp the
    /// number of samples is open-ended
    #[arg(long, value_name = "SECONDS", help_heading = STOPPING)]
    pub time_limit: Option<f64>,
    /// Render in passes until the image's mean relative standard error is at most E; without
    /// --spp the number of samples is open-ended
    #[arg(long, value_name = "E", help_heading = STOPPING)]
    pub target_error: Option<f64>,
    /// Save the render state here every --checkpoint-every seconds and at the end
    #[arg(long, value_name = "PATH", help_heading = CHECKPOINTS)]
    pub checkpoint: Option<PathBuf>,
    /// Seconds between checkpoints
    #[arg(long, value_name = "SECONDS", default_value_t = 60.0, help_heading = CHECKPOINTS)]
    pub checkpoint_every: f64,
    /// Continue the render saved in this state (to the requested samples per pixel)
    #[arg(long, value_name = "PATH", help_heading = CHECKPOINTS)]
    pub resume: Option<PathBuf>,
    /// Render only the sample indices START..END of every pixel, for `prism merge`
    #[arg(long, value_name = "START..END", value_parser = parse_range, help_heading = CHECKPOINTS)]
    pub sample_range: Option<Range<u32>>,
    /// Render only pixel x,y and print every sample's value (to find the source of NaNs)
    #[arg(long, value_name = "X,Y", value_parser = parse_pixel, help_heading = DEBUGGING)]
    pub pixel: Option<[u32; 2]>,
    /// Worker threads [default: one per core]
    #[arg(long, value_name = "T", help_heading = PERFORMANCE)]
    pub threads: Option<usize>,
    /// Trace rays with our BVH (bvh) or, for comparison, with Embree (embree; needs a build
    /// with `--features embree`)
    #[arg(long, value_name = "ACCEL", default_value = "bvh", help_heading = PERFORMANCE)]
    pub accel: Accel,
    /// Draw wavelengths from this density instead of the film's `wavelength_sampling`:
    /// balanced, cie_sum, visible or uniform
    #[arg(long, value_name = "DENSITY", value_parser = parse_wavelengths, help_heading = SAMPLING)]
    pub wavelengths: Option<WavelengthSampling>,
    /// How samples become pixels, instead of the film's `reconstruction`: filter_mis (every
    /// sample feeds every pixel its filter covers) or pixel (the lecture's one-pixel estimator)
    #[arg(long, value_name = "METHOD", value_parser = parse_reconstruction, help_heading = SAMPLING)]
    pub reconstruction: Option<Reconstruction>,
    /// Also write the image denoised by Open Image Denoise: as the EXR's channels denoised.R,
    /// .G, .B (the noisy ones stay) and as the PNG; needs a build with `--features denoise`
    #[arg(long, conflicts_with = "pixel", help_heading = OUTPUT)]
    pub denoise: bool,
    /// Store the EXR's colour and extra channels as half floats (the film's component_format
    /// float16); the variances stay 32-bit
    #[arg(long)]
    pub half: bool,
    /// Print no progress bar and no summary line (warnings, errors and how to resume an
    /// interrupted render are still printed)
    #[arg(short, long, help_heading = PROGRESS)]
    pub quiet: bool,
    /// Print how long loading the scene, building its BVH and rendering took
    #[arg(short, long, conflicts_with = "quiet", help_heading = PROGRESS)]
    pub verbose: bool,
    /// Show the image in a viewer speaking tev's protocol at HOST:PORT (tev listens on
    /// 127.0.0.1:14158): sent when the render starts, after every pass and at the end
    #[arg(long, value_name = "HOST:PORT", value_parser = parse_address, help_heading = PROGRESS)]
    pub display_server: Option<String>,
    /// Replace the EXR and PNG with the image so far every --checkpoint-every seconds
    #[arg(long, help_heading = PROGRESS)]
    pub write_partial_images: bool,
}

pub(crate) fn parse_define(text: &str) -> Result<(String, String), String> {
    match text.split_once('=') {
        Some((name, value)) if !name.is_empty() => Ok((name.to_string(), value.to_string())),
        _ => Err(format!("expected NAME=VALUE, got \"{text}\"")),
    }
}

fn parse_numbers(
    text: &str,
    separator: &str,
    count: usize,
    what: &str,
) -> Result<Vec<u32>, String> {
    let numbers: Vec<u32> = text
        .split(separator)
        .map(|s| s.trim().parse::<u32>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("expected {what}, got \"{text}\""))?;
    if numbers.len() != count {
        return Err(format!("expected {what}, got \"{text}\""));
    }
    Ok(numbers)
}

pub(crate) fn parse_reconstruction(text: &str) -> Result<Reconstruction, String> {
    parse_name(text, Reconstruction::from_name, &Reconstruction::NAMES)
}

pub(crate) fn parse_wavelengths(text: &str) -> Result<WavelengthSampling, String> {
    parse_name(
        text,
        WavelengthSampling::from_name,
        &WavelengthSampling::NAMES,
    )
}

/// The value called `text`, read by `from_name`, one of `names`.
fn parse_name<T>(
    text: &str,
    from_name: fn(&str) -> Option<T>,
    names: &[&str],
) -> Result<T, String> {
    from_name(text).ok_or_else(|| format!("expected one of {}, got \"{text}\"", names.join(", ")))
}

fn parse_crop(text: &str) -> Result<[u32; 4], String> {
    let n = parse_numbers(text, ",", 4, "four non-negative integers x0,y0,x1,y1")?;
    if n[2] > n[0] && n[3] > n[1] {
        Ok([n[0], n[1], n[2], n[3]])
    } else {
        Err(format!(
            "the crop window \"{text}\" is empty: x1 must exceed x0 and y1 must exceed y0"
        ))
    }
}

fn parse_range(text: &str) -> Result<Range<u32>, String> {
    let n = parse_numbers(text, "..", 2, "a range START..END of sample indices")?;
    if n[1] > n[0] {
        Ok(n[0]..n[1])
    } else {
        Err(format!(
            "the sample range \"{text}\" is empty: END must exceed START"
        ))
    }
}

fn parse_pixel(text: &str) -> Result<[u32; 2], String> {
    let n = parse_numbers(text, ",", 2, "a pixel x,y")?;
    Ok([n[0], n[1]])
}

/// The EXR and PNG paths for a render.
fn output_paths(args: &RenderArgs) -> (PathBuf, PathBuf) {
    let exr = match &args.output {
        Some(path)
            if path
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("exr")) =>
        {
            path.clone()
        }
        Some(path) => path.with_extension("exr"),
        None => PathBuf::from(format!("{}.exr", default_name(&args.scene))),
    };
    let png = exr.with_extension("png");
    (exr, png)
}

/// The scene's file stem, or its folder's name for the common `<name>/scene.xml` layout.
fn default_name(scene: &Path) -> String {
    let stem = scene
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("render");
    if stem == "scene"
        && let Some(folder) = scene.canonicalize().ok().and_then(|p| {
            p.parent()
                .and_then(|d| d.file_name())
                .map(|n| n.to_string_lossy().into_owned())
        })
    {
        return folder;
    }
    stem.to_string()
}

/// The stopping rule the arguments ask for (see [`StopRule::requested`]); a --sample-range
/// ends where the range does.
fn stop_rule(args: &RenderArgs, scene_spp: u32) -> Result<StopRule> {
    let names = StopRuleNames {
        spp: "--spp",
        time_limit: "--time-limit",
        target_error: "--target-error",
    };
    let mut rule = StopRule::requested(
        args.spp,
        scene_spp,
        args.time_limit,
        args.target_error,
        &names,
    )?;
    if let Some(range) = &args.sample_range {
        rule.sample_end = Some(range.end);
    }
    Ok(rule)
}

/// Signals that stop a render: the first raises `interrupt` (and records its number), a second
/// exits at once with the conventional status.
fn install_signal_handlers(interrupt: Arc<AtomicBool>, signal: Arc<AtomicI32>) -> Result<()> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM])
        .map_err(|e| Error::usage(format!("could not install the signal handlers: {e}")))?;
    std::thread::spawn(move || {
        for received in signals.forever() {
            if interrupt.swap(true, Ordering::SeqCst) {
                eprintln!("\nprism: second interruption, exiting at once");
                std::process::exit(128 + received);
            }
            signal.store(received, Ordering::SeqCst);
            eprintln!(
                "\nprism: interrupted; finishing the pass in flight (interrupt again to exit at once)"
            );
        }
    });
    Ok(())
}

pub fn run(args: &RenderArgs) -> Result<()> {
    if args.spp == Some(0) {
        return Err(Error::usage("--spp must be at least 1"));
    }
    if args.threads == Some(0) {
        return Err(Error::usage("--threads must be at least 1"));
    }
    if !(args.checkpoint_every > 0.0 && args.checkpoint_every.is_finite()) {
        return Err(Error::usage(
            "--checkpoint-every must be a positive number of seconds",
        ));
    }
    args.accel.check_available()?;
    if args.denoise {
        crate::denoise::check_available()?;
    }
    let load_start = Instant::now();
    let mut loaded = load_scene(&args.scene, &args.defines)?;
    let load_time = load_start.elapsed();
    for warning in &loaded.warnings {
        eprintln!("{warning}");
    }
    if let Some(choice) = &args.sensor {
        loaded.select_sensor(loaded.find_sensor(choice)?)?;
    }
    let mut scene = loaded.scene;
    let accel_start = Instant::now();
    args.accel.apply(&mut scene.world.geometry)?;
    if args.verbose {
        print_load_times(&scene, load_time, accel_start.elapsed());
    }
    let crop = match (args.crop, args.pixel) {
        (Some(_), Some(_)) => return Err(Error::usage("give either --crop or --pixel, not both")),
        (Some([x0, y0, x1, y1]), None) => Some([x0, y0, x1, y1]),
        (None, Some([x, y])) => Some([x, y, x + 1, y + 1]),
        (None, None) => None,
    };
    if let Some([x0, y0, x1, y1]) = crop {
        let size = scene.film.size;
        if x1 > size.x || y1 > size.y {
            return Err(Error::usage(format!(
                "pixels {x0},{y0} to {x1},{y1} reach outside the {}×{} film",
                size.x, size.y
            )));
        }
        scene.film.crop = CropWindow {
            offset: UVec2::new(x0, y0),
            size: UVec2::new(x1 - x0, y1 - y0),
        };
    }
    if let Some(density) = args.wavelengths {
        override_wavelengths(&mut scene, density);
    }
    if let Some(reconstruction) = args.reconstruction {
        override_reconstruction(&mut scene, reconstruction);
    }
    if args.half {
        scene.exr_output.component_format = ComponentFormat::Float16;
    }
    let seed = args.seed.unwrap_or(loaded.seed);
    // The pixel's samples (a count the sampler can stratify), and the blocks its stratification
    // works in: under filter MIS two blocks of half as many, the control variate's halves.
    let spp = scene
        .sampler
        .kind
        .sample_count(args.spp.unwrap_or(scene.sampler.samples_per_pixel));
    let strata = scene.strata(spp);
    if let Some([x, y]) = args.pixel {
        let samples = args.sample_range.clone().unwrap_or(0..spp);
        return trace_pixel(&scene, UVec2::new(x, y), strata, samples, seed);
    }
    // Where the samples start: the range asked for, or past a resumed state's samples.
    let mut continuation = Continuation::new(&scene, seed, strata);
    let range_start = args.sample_range.as_ref().map_or(0, |r| r.start);
    let mut first_sample = range_start;
    let mut initial = None;
    if let Some(path) = &args.resume {
        let (end, sums) = continuation.resume(path, first_sample)?;
        first_sample = end;
        initial = Some(sums);
    }
    let mut stop = stop_rule(args, spp)?;
    if let Some(end) = sppm::chain_end(&scene, range_start) {
        stop.sample_end = Some(end);
    }
    if let Some(end) = stop.sample_end
        && first_sample >= end
    {
        return Err(Error::usage(format!(
            "nothing to render: the samples before {end} are done already"
        ))
        .with_help("ask for more with --spp"));
    }

    let interrupt = Arc::new(AtomicBool::new(false));
    let signal = Arc::new(AtomicI32::new(0));
    install_signal_handlers(interrupt.clone(), signal.clone())?;
    let options = RenderOptions {
        samples_per_pixel: spp,
        first_sample,
        initial,
        stop,
        interrupt: Some(interrupt),
        threads: args.threads,
        seed,
        progress: (!args.quiet && std::io::stderr().is_terminal())
            .then(|| Arc::new(TerminalProgress::new(stop.time_limit)) as Arc<dyn ProgressReport>),
    };
    let (exr_path, png_path) = output_paths(args);
    let png_path = png_path.with_extension(scene.ldr_output.format.extension());
    let state_path = args
        .checkpoint
        .clone()
        .or_else(|| args.resume.clone())
        .unwrap_or_else(|| exr_path.with_extension("state"));
    let mut write_checkpoint = |snapshot: &Snapshot| continuation.save(snapshot, &state_path);
    let checkpoints =
        args.checkpoint.is_some() || args.resume.is_some() || args.sample_range.is_some();
    let every = Duration::from_secs_f64(args.checkpoint_every);
    let mut display = args.display_server.as_deref().map(|address| {
        let size = scene.film.crop.size;
        DisplayServer::connect(address, &exr_path.display().to_string(), size.x, size.y)
    });
    let previewing = display.is_some() || args.write_partial_images;
    let mut last_partial_images = Instant::now();
    let mut preview = |snapshot: &Snapshot| -> Result<()> {
        let partial_images_due =
            args.write_partial_images && last_partial_images.elapsed() >= every;
        if display.is_none() && !partial_images_due {
            return Ok(());
        }
        let film = snapshot.film(&scene);
        if let Some(display) = &mut display {
            display.show(&film);
        }
        if partial_images_due {
            let images = ImageOutput {
                exr: scene.exr_output,
                ldr: scene.ldr_output,
                metadata: Some(RenderMetadata {
                    spp: film.pixels.first().map_or(0, |p| p.samples) as u32,
                    seed,
                    seconds: None,
                }),
            };
            write_images_with(&film, &exr_path, &png_path, &images)?;
            last_partial_images = Instant::now();
        }
        Ok(())
    };
    let output = render_with_preview(
        &scene,
        &options,
        checkpoints.then_some(Checkpoints {
            every,
            write: &mut write_checkpoint,
        }),
        previewing.then_some(&mut preview as Preview),
    )?;
    if let Some(display) = &mut display {
        display.show(&output.film);
    }
    if args.verbose {
        eprintln!(
            "prism: rendering took {:.3} s",
            output.elapsed.as_secs_f64()
        );
        if let Some(occupancy) = output.lane_occupancy {
            eprintln!(
                "prism: paths in lanes: {:.1} of {} lanes held a path per step on average",
                occupancy * prism_core::render::LANES as f64,
                prism_core::render::LANES
            );
        }
    }
    let images = ImageOutput {
        exr: scene.exr_output,
        ldr: scene.ldr_output,
        metadata: Some(RenderMetadata {
            spp: output.film.pixels.first().map_or(0, |p| p.samples) as u32,
            seed,
            seconds: Some(output.elapsed.as_secs_f64()),
        }),
    };
    if args.denoise {
        write_denoised_images(
            &mut scene,
            &output.film,
            seed,
            args.threads,
            &exr_path,
            &png_path,
            &images,
        )?;
    } else {
        write_images_with(&output.film, &exr_path, &png_path, &images)?;
    }
    if output.stop == StopReason::Interrupted && !checkpoints {
        // An interrupted render always leaves a state to resume from.
        let snapshot = Snapshot {
            samples: output.samples.clone(),
            pixels: &output.film.pixels,
            aovs: &output.film.aovs,
            integrator_state: output.integrator_state.as_ref(),
        };
        continuation.state(&snapshot).write(&state_path)?;
    }
    report(args, &scene, &output, &exr_path, &png_path);
    if output.stop == StopReason::Interrupted {
        let received = signal.load(Ordering::SeqCst);
        eprintln!(
            "prism: interrupted after {} spp; the image so far is in {}. Resume with:\n  prism render {} --resume {}{}",
            output.film.pixels.first().map_or(0, |p| p.samples),
            exr_path.display(),
            args.scene.display(),
            state_path.display(),
            resume_arguments(args)
        );
        std::process::exit(128 + if received == 0 { 2 } else { received });
    }
    Ok(())
}

/// `--verbose`: how long reading the scene and its meshes took, and building the BVH (which
/// loading includes), and Embree's scene when it answers the queries (`embree_time`).
fn print_load_times(scene: &Scene, load_time: Duration, embree_time: Duration) {
    let geometry = &scene.world.geometry;
    let bvh_time = geometry.build_time();
    eprintln!(
        "prism: loading the scene took {:.3} s (the scene file and its meshes)",
        load_time.saturating_sub(bvh_time).as_secs_f64()
    );
    eprintln!(
        "prism: building the BVH took {:.3} s ({} primitives)",
        bvh_time.as_secs_f64(),
        geometry.primitive_count()
    );
    if Accel::of(geometry) == Accel::Embree {
        eprintln!(
            "prism: building Embree's scene took {:.3} s",
            embree_time.as_secs_f64()
        );
    }
}

/// The arguments a resumed render must repeat.
fn resume_arguments(args: &RenderArgs) -> String {
    let mut text = String::new();
    for (name, value) in &args.defines {
        text += &format!(" -D {name}={value}");
    }
    if let Some(spp) = args.spp {
        text += &format!(" --spp {spp}");
    }
    if let Some(seed) = args.seed {
        text += &format!(" --seed {seed}");
    }
    if let Some([a, b, c, d]) = args.crop {
        text += &format!(" --crop {a},{b},{c},{d}");
    }
    if let Some(range) = &args.sample_range {
        text += &format!(" --sample-range {}..{}", range.start, range.end);
    }
    if let Some(output) = &args.output {
        text += &format!(" -o {}", output.display());
    }
    text
}

/// The pixels where samples were dropped as non-finite, and (unless `--quiet`) the summary
/// line.
fn report(
    args: &RenderArgs,
    scene: &Scene,
    output: &prism_core::render::RenderOutput,
    exr: &Path,
    png: &Path,
) {
    if let Some(line) = rejected_report(&output.film) {
        eprintln!("{line}");
    }
    if args.quiet {
        return;
    }
    let seconds = output.elapsed.as_secs_f64().max(1e-9);
    let stopped = match output.stop {
        StopReason::Completed => "",
        StopReason::TimeLimit => ", stopped by the time limit",
        StopReason::TargetError => ", target error reached",
        StopReason::Interrupted => ", interrupted",
    };
    // sppm's pixels hold one estimate each: its count is the passes.
    let (count, unit) = match scene.integrator {
        Integrator::Sppm(_) => (
            u64::from(output.samples.end - output.samples.start),
            "passes",
        ),
        _ => (output.film.pixels.first().map_or(0, |p| p.samples), "spp"),
    };
    eprintln!(
        "prism: rendered {} ({}×{}, {count} {unit}{stopped}{}) in {:.2} s: {:.3} M samples/s, {:.2} M rays/s, mean relative error {:.4}{} -> {}, {}",
        args.scene.display(),
        scene.film.crop.size.x,
        scene.film.crop.size.y,
        match Accel::of(&scene.world.geometry) {
            Accel::Bvh => "",
            Accel::Embree => ", traced by Embree",
        },
        seconds,
        output.sample_count as f64 / seconds / 1e6,
        output.rays as f64 / seconds / 1e6,
        output.relative_error,
        match scene.integrator {
            // Light subpaths feed many pixels: the error is estimated from whole sample indices.
            Integrator::Particle(_) | Integrator::Bdpt(_) => {
                " (by batch means over sample indices)"
            }
            // A biased estimate with one value per pixel: there is no error to report.
            Integrator::Sppm(_) => " (sppm: biased, no error estimate)",
            Integrator::Vcm(ref vcm) if vcm.merging => {
                " (vcm: biased; the spread over sample indices leaves out the merges' bias)"
            }
            Integrator::Vcm(_) => " (by batch means over sample indices)",
            _ => "",
        },
        exr.display(),
        png.display(),
    );
}

/// `--pixel x,y`: renders the samples `range` drawn for one pixel, as the render draws them,
/// and prints each, marking the non-finite ones: weighted by its one-pixel weight, or under
/// filter MIS, where each sample feeds the pixels around by the balance heuristic, unweighted
/// (their mean is then not the pixel's value).
fn trace_pixel(
    scene: &Scene,
    pixel: UVec2,
    strata: u32,
    range: Range<u32>,
    seed: u64,
) -> Result<()> {
    let estimator = SampleEstimator::new(scene);
    if estimator.particle_tracer().is_some() {
        return Err(Error::usage(
            "--pixel prints a pixel's camera samples, and ptracer takes none: its light \
             subpaths reach pixels anywhere on the film",
        )
        .with_help("render a --crop around the pixel instead"));
    }
    if let Integrator::Bdpt(_) | Integrator::Vcm(_) = scene.integrator {
        return Err(Error::usage(
            "--pixel prints a pixel's camera samples, and bdpt's and vcm's are not the pixel's \
             whole estimate: their light subpaths reach pixels anywhere on the film",
        )
        .with_help("render a --crop around the pixel instead"));
    }
    if matches!(scene.integrator, Integrator::Sppm(_)) {
        return Err(Error::usage(
            "--pixel prints a pixel's camera samples, and sppm's passes depend on the photons \
             of the whole scene",
        )
        .with_help("render a --crop around the pixel instead"));
    }
    if matches!(scene.integrator, Integrator::Guided(_)) {
        return Err(Error::usage(
            "--pixel prints a pixel's camera samples, and guided_path's depend on what the \
             whole image taught its SD-tree",
        )
        .with_help("render a --crop around the pixel instead"));
    }
    let mut sampler = Sampler::new(scene.sampler.kind, strata, seed);
    let mut count = RayCount::default();
    let mut sums = PixelSums::default();
    let mut aovs = vec![0.0f32; estimator.aov_count()];
    println!(
        "pixel ({}, {}), samples {}..{}, seed {seed}:",
        pixel.x, pixel.y, range.start, range.end
    );
    println!("{:>8} {:>14} {:>14} {:>14}", "sample", "X", "Y", "Z");
    for index in range {
        let draw = estimator.offset_draw();
        let xyz = estimator.estimate(&mut sampler, pixel, index, draw, &mut count, &mut aovs);
        let bad = !xyz.iter().all(|v| v.is_finite());
        println!(
            "{index:>8} {:>14.6e} {:>14.6e} {:>14.6e}{}",
            xyz[0],
            xyz[1],
            xyz[2],
            if bad { "   <- not finite" } else { "" }
        );
        sums.add(xyz);
    }
    let mean = sums.mean();
    println!(
        "mean XYZ {:.6e} {:.6e} {:.6e}; {} of {} samples not finite",
        mean[0], mean[1], mean[2], sums.rejected, sums.samples
    );
    Ok(())
}
