//! `prism render`: load a scene, render it, write EXR and PNG, print a summary line.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Duration;

use clap::Args;

use crate::error::{Error, Result};
use crate::film::output::{ChannelImage, write_exr, write_png_srgb};
use crate::film::{CropWindow, Film};
use crate::render::stats::{pixel_relative_error, variance_of_mean};
use crate::render::{RenderOptions, StopReason, StopRule, render};
use crate::scene::mitsuba::load_scene;

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// The Mitsuba 3 XML scene file.
    pub scene: PathBuf,
    /// Output EXR file; the PNG goes beside it [default: the scene's name in the current folder;
    /// for a file called scene.xml, the name of its folder]
    #[arg(short, long, value_name = "OUT.exr")]
    pub output: Option<PathBuf>,
    /// Samples per pixel [default: the scene's sampler]
    #[arg(long, value_name = "N")]
    pub spp: Option<u32>,
    /// Worker threads [default: one per core]
    #[arg(long, value_name = "T")]
    pub threads: Option<usize>,
    /// Seed of the random numbers [default: the sampler's seed, else 0]
    #[arg(long, value_name = "S")]
    pub seed: Option<u64>,
    /// Set a scene parameter declared with `<default name=... value=...>` (repeatable)
    #[arg(short = 'D', value_name = "NAME=VALUE", value_parser = parse_define)]
    pub defines: Vec<(String, String)>,
    /// Render only the pixels x0 <= x < x1, y0 <= y < y1 of the film
    #[arg(long, value_name = "X0,Y0,X1,Y1", value_parser = parse_crop)]
    pub crop: Option<[u32; 4]>,
    /// Stop after this many seconds (the pass running then is dropped); without --spp the
    /// number of samples is open-ended
    #[arg(long, value_name = "SECONDS")]
    pub time_limit: Option<f64>,
    /// Render in passes until the image's mean relative standard error is at most E; without
    /// --spp the number of samples is open-ended
    #[arg(long, value_name = "E")]
    pub target_error: Option<f64>,
}

pub(crate) fn parse_define(text: &str) -> Result<(String, String), String> {
    match text.split_once('=') {
        Some((name, value)) if !name.is_empty() => Ok((name.to_string(), value.to_string())),
        _ => Err(format!("expected NAME=VALUE, got \"{text}\"")),
    }
}

fn parse_crop(text: &str) -> Result<[u32; 4], String> {
    let numbers: Vec<u32> = text
        .split(',')
        .map(|s| s.trim().parse::<u32>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("expected four non-negative integers x0,y0,x1,y1, got \"{text}\""))?;
    match numbers.as_slice() {
        [x0, y0, x1, y1] if x1 > x0 && y1 > y0 => Ok([*x0, *y0, *x1, *y1]),
        [_, _, _, _] => Err(format!(
            "the crop window \"{text}\" is empty: x1 must exceed x0 and y1 must exceed y0"
        )),
        _ => Err(format!("expected four numbers x0,y0,x1,y1, got \"{text}\"")),
    }
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

/// The stopping rule the arguments ask for. Without --time-limit or --target-error the render
/// takes exactly the requested samples; with either, --spp (if given) only caps the samples.
fn stop_rule(args: &RenderArgs, scene_spp: u32) -> Result<StopRule> {
    let time_limit = match args.time_limit {
        Some(t) if !(t > 0.0 && t.is_finite()) => {
            return Err(Error::usage(format!(
                "--time-limit must be a positive number of seconds, not {t}"
            )));
        }
        t => t.map(Duration::from_secs_f64),
    };
    if let Some(e) = args.target_error
        && !(e > 0.0 && e.is_finite())
    {
        return Err(Error::usage(format!(
            "--target-error must be positive, not {e}"
        )));
    }
    let open_ended = time_limit.is_some() || args.target_error.is_some();
    Ok(StopRule {
        samples_per_pixel: if open_ended {
            args.spp
        } else {
            Some(args.spp.unwrap_or(scene_spp))
        },
        time_limit,
        target_error: args.target_error,
    })
}

pub fn run(args: &RenderArgs) -> Result<()> {
    if args.spp == Some(0) {
        return Err(Error::usage("--spp must be at least 1"));
    }
    if args.threads == Some(0) {
        return Err(Error::usage("--threads must be at least 1"));
    }
    let loaded = load_scene(&args.scene, &args.defines)?;
    let mut scene = loaded.scene;
    if let Some([x0, y0, x1, y1]) = args.crop {
        let size = scene.film.size;
        if x1 > size.x || y1 > size.y {
            return Err(Error::usage(format!(
                "--crop {x0},{y0},{x1},{y1} reaches outside the {}×{} film",
                size.x, size.y
            )));
        }
        scene.film.crop = CropWindow {
            offset: glam::UVec2::new(x0, y0),
            size: glam::UVec2::new(x1 - x0, y1 - y0),
        };
    }
    let stop = stop_rule(args, scene.sampler.samples_per_pixel)?;
    let options = RenderOptions {
        samples_per_pixel: args.spp.unwrap_or(scene.sampler.samples_per_pixel),
        stop,
        threads: args.threads,
        seed: args.seed.unwrap_or(loaded.seed),
        progress: std::io::stderr().is_terminal(),
    };
    let output = render(&scene, &options)?;
    let (exr_path, png_path) = output_paths(args);
    write_images(&output.film, &exr_path, &png_path)?;

    let seconds = output.elapsed.as_secs_f64().max(1e-9);
    let (_, rejected) = output.film.sample_counts();
    let stopped = match output.stop {
        StopReason::Completed => "",
        StopReason::TimeLimit => ", stopped by the time limit",
        StopReason::TargetError => ", target error reached",
    };
    eprintln!(
        "prism: rendered {} ({}×{}, {} spp{stopped}) in {:.2} s: {:.3} M samples/s, {:.2} M rays/s, mean relative error {:.4}{} -> {}, {}",
        args.scene.display(),
        scene.film.crop.size.x,
        scene.film.crop.size.y,
        output.samples_per_pixel,
        seconds,
        output.samples as f64 / seconds / 1e6,
        output.rays as f64 / seconds / 1e6,
        output.relative_error,
        if rejected > 0 {
            format!(", {rejected} non-finite samples dropped")
        } else {
            String::new()
        },
        exr_path.display(),
        png_path.display(),
    );
    Ok(())
}

/// Writes the film as an EXR and as an sRGB PNG. The EXR's channels are `R`, `G`, `B` (linear
/// sRGB), `X`, `Y`, `Z` (CIE 1931), `variance.X`, `variance.Y`, `variance.Z` (the estimated
/// variance of each pixel's mean, see [`crate::render::stats`]) and `relative_error.Y` (the
/// pixel's relative standard error of luminance).
pub fn write_images(film: &Film, exr_path: &Path, png_path: &Path) -> Result<()> {
    let xyz = film.xyz();
    let rgb = film.linear_srgb();
    let channel = |values: &[[f32; 3]], c: usize| values.iter().map(|v| v[c]).collect::<Vec<f32>>();
    let variance = |c: usize| {
        film.pixels
            .iter()
            .map(|p| variance_of_mean(p, c) as f32)
            .collect::<Vec<f32>>()
    };
    let image = ChannelImage {
        width: film.crop.size.x as usize,
        height: film.crop.size.y as usize,
        channels: vec![
            ("R".to_string(), channel(&rgb, 0)),
            ("G".to_string(), channel(&rgb, 1)),
            ("B".to_string(), channel(&rgb, 2)),
            ("X".to_string(), channel(&xyz, 0)),
            ("Y".to_string(), channel(&xyz, 1)),
            ("Z".to_string(), channel(&xyz, 2)),
            ("variance.X".to_string(), variance(0)),
            ("variance.Y".to_string(), variance(1)),
            ("variance.Z".to_string(), variance(2)),
            (
                "relative_error.Y".to_string(),
                film.pixels
                    .iter()
                    .map(|p| pixel_relative_error(p) as f32)
                    .collect(),
            ),
        ],
    };
    write_exr(exr_path, &image)?;
    let interleaved: Vec<f32> = rgb.iter().flatten().copied().collect();
    write_png_srgb(png_path, image.width, image.height, &interleaved)
}
