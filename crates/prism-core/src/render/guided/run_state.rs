//! A guided run's state in a render state file ([`IntegratorState`] named `guided_path`): what
//! a checkpoint saves, what `--resume` continues, and what `prism merge` makes of several runs.
//!
//! Layout (little endian, [`crate::integrator::guided::encoding`]): the tag `PPG\0`, a format
//! version (u32), the kind (0: a run, 1: a merge of runs) and `sampleCombination` (0 discard,
//! 1 automatic, 2 inversevar). A merge holds no more. A run goes on with `sppPerPass`, the crop
//! size and the extra sums per pixel it was rendered with, the first sample index of its range,
//! its budget (0 and passes, or 1 and seconds), the seconds spent (time budgets only), the
//! iterations that have trained the tree, the passes done, the extrapolated variance, the
//! images of the finished iterations the final image may still be made of (those `inversevar`
//! mixes, else the last), the iteration under way if any (its stage: 0 training with its passes
//! and whether it is the budget's last, or 1 the final one with its passes; whether it takes
//! light samples; the seconds spent on it; its image so far), and the SD-tree
//! ([`SdTree::encode`]). An image is its passes, whether it is complete, and per pixel in the
//! order of the tiles its sums of X, Y, Z and of their squares, its sample and rejected
//! counts, its extra channels' sums and its sum of radiance; the control variate's sums are
//! not kept: they are zero, every sample counting for its own pixel.

use std::path::Path;

use glam::UVec2;

use super::{Current, Image, Plan, Run, Stage, kept_images, mean_variance, plan};
use crate::error::{Error, ErrorKind, Result};
use crate::film::accumulation::{AOV_SUMS_PER_CHANNEL, ExactSum, add_aov_sample};
use crate::film::{PixelSums, ValueSum};
use crate::integrator::guided::encoding::{Decoder, Encoder, Malformed};
use crate::integrator::guided::sd_tree::SdTree;
use crate::integrator::guided::{GuidedPathIntegrator, SampleCombination};
use crate::render::RenderOptions;
use crate::render::state::{IntegratorState, RenderState};
use crate::render::tiles::{Tile, TileSums};

/// The integrator's name in a render state.
const NAME: &str = "guided_path";
const TAG: &[u8; 4] = b"PPG\0";
const VERSION: u32 = 1;
const RUN: u8 = 0;
const MERGE: u8 = 1;
/// Bytes per pixel of an image besides its extra channels: six 128-bit sums, two counts and
/// the radiance sum.
const PIXEL_BYTES: usize = 6 * 16 + 2 * 8 + 8;

/// What a run's images are laid out by.
pub(super) struct Layout<'a> {
    pub(super) guided: &'a GuidedPathIntegrator,
    pub(super) tiles: &'a [Tile],
    /// The crop window's size.
    pub(super) size: UVec2,
    /// Extra channels' sums per pixel.
    pub(super) k: usize,
}

fn combination_code(combination: SampleCombination) -> u8 {
    match combination {
        SampleCombination::Discard => 0,
        SampleCombination::Automatic => 1,
        SampleCombination::InverseVariance => 2,
    }
}

fn header(out: &mut Encoder, kind: u8, combination: SampleCombination) {
    out.bytes.extend_from_slice(TAG);
    out.u32(VERSION);
    out.u8(kind);
    out.u8(combination_code(combination));
}

/// The kind and sample combination of a state.
fn read_header(input: &mut Decoder) -> std::result::Result<(u8, SampleCombination), Malformed> {
    let tag = [input.u8()?, input.u8()?, input.u8()?, input.u8()?];
    if &tag != TAG {
        return Err("it does not start with the guided_path state's tag".into());
    }
    let version = input.u32()?;
    if version != VERSION {
        return Err(format!(
            "it is of format version {version}; this Prism reads version {VERSION}"
        ));
    }
    let kind = input.u8()?;
    if kind != RUN && kind != MERGE {
        return Err(format!("it is of kind {kind}"));
    }
    let combination = match input.u8()? {
        0 => SampleCombination::Discard,
        1 => SampleCombination::Automatic,
        2 => SampleCombination::InverseVariance,
        code => return Err(format!("its sample combination is {code}")),
    };
    Ok((kind, combination))
}

fn damaged(path: Option<&Path>, why: &str) -> Error {
    let which = path.map_or(String::new(), |p| format!(" in \"{}\"", p.display()));
    Error {
        kind: ErrorKind::Input,
        location: None,
        message: format!("the guided_path state{which} is damaged: {why}"),
        help: Some("use a state written by a guided_path render, or render again".into()),
    }
}

/// The run's state (the layout above).
pub(super) fn encode(layout: &Layout, run: &Run) -> IntegratorState {
    let mut out = Encoder::default();
    header(&mut out, RUN, layout.guided.sample_combination);
    out.u32(layout.guided.spp_per_pass);
    out.u32(layout.size.x);
    out.u32(layout.size.y);
    out.length(layout.k);
    out.u32(run.first_sample);
    match run.plan {
        Plan::Passes(passes) => {
            out.u8(0);
            out.u32(passes);
        }
        Plan::Seconds(seconds) => {
            out.u8(1);
            out.f64(seconds);
        }
    }
    out.f64(run.seconds());
    out.u32(run.iteration);
    out.u32(run.passes_done);
    out.f64(run.extrapolated);
    out.length(run.images.len());
    for image in &run.images {
        encode_image(&mut out, layout, image);
    }
    match &run.current {
        None => out.u8(0),
        Some(current) => {
            out.u8(1);
            match current.stage {
                Stage::Training { passes, last } => {
                    out.u8(0);
                    out.u32(passes);
                    out.bool(last);
                }
                Stage::Final { passes } => {
                    out.u8(1);
                    out.u32(passes);
                }
            }
            out.bool(current.light_samples);
            out.f64(run.iteration_seconds());
            encode_image(&mut out, layout, &current.image);
        }
    }
    run.tree.encode(&mut out);
    IntegratorState {
        integrator: NAME.into(),
        bytes: out.bytes,
    }
}

fn encode_image(out: &mut Encoder, layout: &Layout, image: &Image) {
    out.u32(image.passes);
    out.bool(image.complete);
    for (sums, radiance) in image.sums.iter().zip(&image.radiance) {
        for (i, p) in sums.pixels.iter().enumerate() {
            for s in &p.xyz {
                out.i128(s.0);
            }
            for s in &p.xyz_squared {
                out.i128(s.0);
            }
            out.u64(p.samples);
            out.u64(p.rejected);
            for s in &sums.aovs[i * layout.k..(i + 1) * layout.k] {
                out.i128(s.0);
            }
            out.f64(radiance[i]);
        }
    }
}

fn decode_image(input: &mut Decoder, layout: &Layout) -> std::result::Result<Image, Malformed> {
    let passes = input.u32()?;
    let complete = input.bool("an image's completeness")?;
    let pixel_bytes = PIXEL_BYTES + 16 * layout.k;
    let pixel_count = layout.size.x as usize * layout.size.y as usize;
    if pixel_count.saturating_mul(pixel_bytes) > input.left() {
        return Err("it ends within an image".into());
    }
    let mut sums = Vec::with_capacity(layout.tiles.len());
    let mut radiance = Vec::with_capacity(layout.tiles.len());
    for tile in layout.tiles {
        let n = (tile.size.x * tile.size.y) as usize;
        let mut tile_sums = TileSums {
            pixels: Vec::with_capacity(n),
            aovs: Vec::with_capacity(n * layout.k),
        };
        let mut tile_radiance = Vec::with_capacity(n);
        for _ in 0..n {
            let mut p = PixelSums::default();
            for s in &mut p.xyz {
                s.0 = input.i128()?;
            }
            for s in &mut p.xyz_squared {
                s.0 = input.i128()?;
            }
            p.samples = input.u64()?;
            p.rejected = input.u64()?;
            if p.rejected > p.samples {
                return Err("a pixel has more rejected samples than samples".into());
            }
            tile_sums.pixels.push(p);
            for _ in 0..layout.k {
                tile_sums.aovs.push(ExactSum(input.i128()?));
            }
            tile_radiance.push(input.f64()?);
        }
        sums.push(tile_sums);
        radiance.push(tile_radiance);
    }
    let variance = mean_variance(&sums);
    Ok(Image {
        sums,
        radiance,
        passes,
        complete,
        variance,
    })
}

/// The run a render continues from `state` (the resumed render's `options`), checked against
/// this render: the state must be a guided run's (not a merge's), of the same parameters,
/// crop and budget, and end where the render starts.
pub(super) fn resume(
    layout: &Layout,
    options: &RenderOptions,
    state: Option<&IntegratorState>,
) -> Result<Run> {
    let cannot =
        |why: String| Error::usage(format!("cannot resume this guided_path render: {why}"));
    let state = match state {
        Some(state) if state.integrator == NAME => state,
        Some(state) => {
            return Err(cannot(format!(
                "the state is a {} render's",
                state.integrator
            )));
        }
        None => {
            return Err(cannot(
                "the state is of a render by an integrator without a guided_path state".into(),
            ));
        }
    };
    let mut input = Decoder::new(&state.bytes);
    let run = decode_run(&mut input, layout, options, &cannot)?;
    input.finish().map_err(|why| damaged(None, &why))?;
    let start = run.sample_end(layout.guided.spp_per_pass);
    if options.first_sample != start {
        return Err(cannot(format!(
            "its run ends at sample {start}, and this render starts at {}",
            options.first_sample
        )));
    }
    Ok(run)
}

fn decode_run(
    input: &mut Decoder,
    layout: &Layout,
    options: &RenderOptions,
    cannot: &dyn Fn(String) -> Error,
) -> Result<Run> {
    let bad = |why: Malformed| damaged(None, &why);
    let guided = layout.guided;
    let (kind, combination) = read_header(input).map_err(bad)?;
    if kind == MERGE {
        return Err(cannot(
            "the state is a merge of runs (prism merge), which keeps no run's SD-tree".into(),
        )
        .with_help("render more samples as a run of a sample range of its own, and merge it in"));
    }
    let spp_per_pass = input.u32().map_err(bad)?;
    if combination != guided.sample_combination || spp_per_pass != guided.spp_per_pass {
        return Err(cannot(
            "the state was rendered with another sampleCombination or sppPerPass".into(),
        ));
    }
    let size = UVec2::new(input.u32().map_err(bad)?, input.u32().map_err(bad)?);
    let k = input.length(0, "extra sums").map_err(bad)?;
    if size != layout.size || k != layout.k {
        return Err(cannot(format!(
            "the state holds a {}×{} crop with {k} extra sums per pixel, not a {}×{} one with {}",
            size.x, size.y, layout.size.x, layout.size.y, layout.k
        )));
    }
    let first_sample = input.u32().map_err(bad)?;
    let plan_in_state = match input.u8().map_err(bad)? {
        0 => Plan::Passes(input.u32().map_err(bad)?),
        1 => Plan::Seconds(input.f64_at_least(0.0, "the budget").map_err(bad)?),
        code => return Err(bad(format!("its budget is of kind {code}"))),
    };
    if let Plan::Passes(passes) = plan_in_state {
        let asked = plan(guided, options, first_sample)?;
        if asked != plan_in_state {
            return Err(cannot(format!(
                "its run was planned for {} samples per pixel, this render for {}",
                u64::from(passes) * u64::from(spp_per_pass),
                match asked {
                    Plan::Passes(p) => format!("{}", u64::from(p) * u64::from(spp_per_pass)),
                    Plan::Seconds(s) => format!("{s} seconds"),
                }
            ))
            .with_help("resume with the sample count (--spp) or budget the run started with"));
        }
    }
    let seconds_before = input.f64_at_least(0.0, "the seconds spent").map_err(bad)?;
    let iteration = input.u32().map_err(bad)?;
    let passes_done = input.u32().map_err(bad)?;
    let extrapolated = input.f64().map_err(bad)?;
    if extrapolated.is_nan() || extrapolated < 0.0 {
        return Err(bad(format!("its extrapolated variance is {extrapolated}")));
    }
    let image_count = input.length(PIXEL_BYTES, "finished images").map_err(bad)?;
    if image_count > kept_images(combination) {
        return Err(bad(format!("it keeps {image_count} finished images")));
    }
    let mut images = Vec::with_capacity(image_count);
    for _ in 0..image_count {
        images.push(decode_image(input, layout).map_err(bad)?);
    }
    let current = match input.u8().map_err(bad)? {
        0 => None,
        1 => {
            let stage = match input.u8().map_err(bad)? {
                0 => Stage::Training {
                    passes: input.u32().map_err(bad)?,
                    last: input.bool("an iteration's lastness").map_err(bad)?,
                },
                1 => Stage::Final {
                    passes: input.u32().map_err(bad)?,
                },
                code => return Err(bad(format!("its iteration is of stage {code}"))),
            };
            let light_samples = input.bool("light sampling").map_err(bad)?;
            let seconds_before = input
                .f64_at_least(0.0, "the iteration's seconds")
                .map_err(bad)?;
            let image = decode_image(input, layout).map_err(bad)?;
            Some(Current {
                stage,
                light_samples,
                image,
                seconds_before,
            })
        }
        code => return Err(bad(format!("its iteration under way is marked {code}"))),
    };
    // The passes the run will have done once the iteration under way ends, and the sample
    // indices they reach.
    let (done_in_iteration, planned) = current
        .as_ref()
        .map_or((0, 0), |c| (c.image.passes, c.stage.passes()));
    let end_of_iteration = u64::from(passes_done) + u64::from(planned.max(done_in_iteration))
        - u64::from(done_in_iteration);
    let last_pass = match plan_in_state {
        Plan::Passes(total) => u64::from(total),
        Plan::Seconds(_) => end_of_iteration,
    };
    // Every finished iteration has at least one pass.
    let consistent = done_in_iteration <= planned
        && iteration <= passes_done
        && done_in_iteration <= passes_done
        && images.iter().all(|image| image.passes <= passes_done)
        && end_of_iteration <= last_pass
        && u64::from(first_sample) + last_pass * u64::from(spp_per_pass) <= u64::from(u32::MAX);
    if !consistent {
        return Err(bad(format!(
            "its {passes_done} passes, {done_in_iteration} of {planned} in the iteration under \
             way, do not fit its budget"
        )));
    }
    let tree = SdTree::decode(input).map_err(bad)?;
    let now = std::time::Instant::now();
    Ok(Run {
        first_sample,
        plan: plan_in_state,
        seconds_before,
        tree,
        iteration,
        passes_done,
        extrapolated,
        images,
        current,
        started: now,
        iteration_started: now,
        passes_before: passes_done,
        rays: 0,
    })
}

/// Merges the states of guided runs of disjoint sample ranges (of the same render, checked
/// by [`RenderState::merge`]). Each run's final image is unbiased given the tree it learned,
/// so a mean of them weighted by anything fixed in advance is unbiased: with `discard` and
/// `automatic` the runs' pixel sums are added (the mean of their final images weighted by the
/// samples each holds); with `inversevar`, whose images are one value per pixel, the merged
/// pixel is the mean of the runs' pixels weighted by the samples per pixel of their ranges,
/// again one value per pixel (no error bar). The merged state cannot be resumed.
pub(crate) fn merge_states(states: &[RenderState], paths: &[&Path]) -> Result<RenderState> {
    let mut combination = None;
    for (i, state) in states.iter().enumerate() {
        let bytes = state
            .integrator_state
            .as_ref()
            .filter(|s| s.integrator == NAME)
            .map(|s| s.bytes.as_slice())
            .unwrap_or_default();
        let (_, own) =
            read_header(&mut Decoder::new(bytes)).map_err(|why| damaged(Some(paths[i]), &why))?;
        if combination.is_some_and(|c| c != own) {
            return Err(Error::usage(format!(
                "\"{}\" cannot be merged with \"{}\": their runs combine their iterations' \
                 images differently (sampleCombination)",
                paths[i].display(),
                paths[0].display()
            )));
        }
        combination = Some(own);
    }
    let combination = combination.unwrap_or(SampleCombination::Discard);
    let plain: Vec<RenderState> = states
        .iter()
        .map(|s| RenderState {
            integrator_state: None,
            ..s.clone()
        })
        .collect();
    let mut merged = RenderState::merge(&plain, paths)?;
    if combination == SampleCombination::InverseVariance {
        let total: f64 = states.iter().map(|s| f64::from(s.sample_count())).sum();
        let aov_count = merged.aov_names.len();
        let k = aov_count * AOV_SUMS_PER_CHANNEL;
        if merged.aovs.len() != merged.pixels.len() * k {
            return Err(Error::usage(
                "the merged states' extra channels do not match their pixels",
            ));
        }
        let mut xyz = vec![[0.0f64; 3]; merged.pixels.len()];
        let mut aovs = vec![0.0f64; merged.pixels.len() * aov_count];
        for state in states {
            let weight = f64::from(state.sample_count()) / total;
            for (p, pixel) in state.pixels.iter().enumerate().take(xyz.len()) {
                let mean = pixel.mean();
                for c in 0..3 {
                    xyz[p][c] += weight * mean[c];
                }
                let n = pixel.samples.max(1) as f64;
                let sums = state.aovs.get(p * k..p * k + aov_count).unwrap_or_default();
                for (a, s) in aovs[p * aov_count..].iter_mut().zip(sums) {
                    *a += weight * s.value() / n;
                }
            }
        }
        for (p, pixel) in merged.pixels.iter_mut().enumerate() {
            *pixel = PixelSums::default();
            pixel.add_total(xyz[p]);
            let values: Vec<f32> = aovs[p * aov_count..(p + 1) * aov_count]
                .iter()
                .map(|&v| v as f32)
                .collect();
            let sums = &mut merged.aovs[p * k..(p + 1) * k];
            sums.fill(ValueSum::default());
            add_aov_sample(&mut sums[..aov_count], &values);
        }
    }
    let mut out = Encoder::default();
    header(&mut out, MERGE, combination);
    merged.integrator_state = Some(IntegratorState {
        integrator: NAME.into(),
        bytes: out.bytes,
    });
    Ok(merged)
}
