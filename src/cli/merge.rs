//! `prism merge`: combines render states of disjoint sample ranges (from `--sample-range` renders
//! on several machines) into the image one render of all their samples gives — bit for bit,
//! since pixel sums are exact. It reads the states, not the renders' EXR files, so how those
//! were stored (half floats, luminance only) does not matter; the merged EXR holds R, G, B,
//! X, Y, Z, their statistics and the extra channels the states carry (the coverage alpha
//! among them), as 32-bit floats or, with `--half`, half floats. States of `sppm` chains are
//! averaged instead (their statistics are no sums); the summary then says how biased the image
//! is.

use std::path::PathBuf;

use clap::Args;

use prism_core::error::{Error, Result};
use prism_core::film::stats::rejected_report;
use prism_core::film::{
    ComponentFormat, ExrOutput, Film, ImageOutput, LdrOutput, RenderMetadata, write_images_with,
};
use prism_core::render::sppm;
use prism_core::render::state::RenderState;

#[derive(Args, Debug)]
pub struct MergeArgs {
    /// Render states written by `prism render --sample-range ... --checkpoint ...`
    #[arg(required = true, value_name = "STATE")]
    pub states: Vec<PathBuf>,
    /// The merged image (EXR; the PNG goes beside it)
    #[arg(short, long, value_name = "OUT.exr")]
    pub output: PathBuf,
    /// Also write the merged render state here
    #[arg(long, value_name = "PATH")]
    pub state: Option<PathBuf>,
    /// Store the EXR's colour and extra channels as half floats; the variances stay 32-bit
    #[arg(long)]
    pub half: bool,
}

pub fn run(args: &MergeArgs) -> Result<()> {
    let states = args
        .states
        .iter()
        .map(|p| RenderState::read(p))
        .collect::<Result<Vec<_>>>()?;
    let paths: Vec<&std::path::Path> = args.states.iter().map(PathBuf::as_path).collect();
    let merged = RenderState::merge(&states, &paths)?;
    let identity = &merged.identity;
    let mut film = Film::with_aovs(identity.film_size, identity.crop, merged.aov_names.clone());
    if film.pixels.len() != merged.pixels.len() || film.aovs.len() != merged.aovs.len() {
        return Err(Error::usage(
            "the merged state does not match its crop window",
        ));
    }
    film.pixels = merged.pixels.clone();
    film.aovs = merged.aovs.clone();
    let exr = if args
        .output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
    {
        args.output.clone()
    } else {
        args.output.with_extension("exr")
    };
    let png = exr.with_extension("png");
    let output = ImageOutput {
        exr: ExrOutput {
            component_format: if args.half {
                ComponentFormat::Float16
            } else {
                ComponentFormat::Float32
            },
            ..ExrOutput::default()
        },
        ldr: LdrOutput::default(),
        metadata: Some(RenderMetadata {
            spp: merged.sample_count(),
            seed: identity.seed,
            seconds: None,
        }),
    };
    write_images_with(&film, &exr, &png, &output)?;
    if let Some(path) = &args.state {
        merged.write(path)?;
    }
    let ranges: Vec<String> = merged
        .ranges
        .iter()
        .map(|r| format!("{}..{}", r.start, r.end))
        .collect();
    eprintln!(
        "prism: merged {} states (samples {}, {} spp) -> {}, {}",
        states.len(),
        ranges.join(", "),
        merged.sample_count(),
        exr.display(),
        png.display()
    );
    if let Some(note) = (merged.integrator_state.as_ref()).and_then(sppm::merge_summary) {
        eprintln!("prism: {note}");
    }
    if let Some(line) = rejected_report(&film) {
        eprintln!("{line}");
    }
    Ok(())
}
