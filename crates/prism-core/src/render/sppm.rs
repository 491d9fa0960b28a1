//! The passes of stochastic progressive photon mapping ([`crate::integrator::sppm`]): each pass
//! traces its photons, builds their map, traces one camera path per pixel of the crop window
//! and updates the pixel's statistics (its search radius r, accumulated photon count N, flux τ
//! in CIE XYZ and the sum of its direct estimates) by the progressive rule; the image after P
//! passes is the radiance estimate L = Σ L_direct / P + τ / (P · photonCount · π r²).
//!
//! **Chains.** A render is a progressive chain of passes starting at sample index a (0, or the
//! start of the sample range asked for): its pass i draws the random numbers of sample index
//! a + i — the camera path of pixel j from the scene's sampler for (j, a + i), photon k from an
//! independent stream for (k, a + i), the pass's wavelengths from one more stream for a + i —
//! while its radii start at the initial radius and P counts its own passes. It ends at sample
//! index a + `maxPasses` where that is set (which replaces the sample count, so a sample range
//! a..b then still renders `maxPasses` passes), else at the end of the sample range. Photons are
//! traced in parallel tasks and joined in the order of their indices; each pixel's update reads
//! only the map and its own state. So the image is bit-identical for any thread count and task
//! size.
//!
//! **Checkpoints and resume.** A pass cut short by the time limit or an interruption is
//! dropped whole. Between passes (every `checkpoints.every`) and at the end, the render hands
//! out the film and its integrator state ([`IntegratorState`], named `sppm`): the chain's first
//! sample index a, its pass count P and every pixel's statistics (r, N, τ, Σ L_direct as eight
//! little-endian f64, 64 bytes a pixel), all a later pass depends on. A render resumed from it
//! continues the chain where it stopped and is bit-identical, film and state, to one that never
//! stopped. A resumed state must be sppm's, hold the crop window's pixel count and end at the
//! sample index the render starts at (a + P).
//!
//! **Merge.** Chains of disjoint sample ranges are independent estimates of the same image;
//! `merge_states` combines them as the pass-weighted mean L = Σ P_c L_c / Σ P_c of their images
//! (in the order of their first sample index): chains of equal length are averaged, and a chain
//! cut short by a time limit, whose estimate is noisier and more biased, counts less. The mean of
//! k chains of P passes has about 1/k of one chain's variance but the bias of one chain of P
//! passes, not that of kP passes: merging is no substitute for more passes. A merged state
//! records only the chains' count and passes (P in all, fewest and most per chain), so it can be
//! merged again (with the same weights) but not resumed.
//!
//! **No error bar.** The film gets each pixel's estimate — a chain's or a merge's — as its one
//! sample, so the EXR's variance channels are infinite, never an error bar: nothing estimates the
//! error of this biased estimate, and a target error is refused.

use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

use glam::{UVec2, Vec2};
use rayon::prelude::*;

use super::estimator::SampleEstimator;
use super::progress::{ProgressReport, Silent};
use super::state::{IntegratorState, RenderState};
use super::stop::Cancel;
use super::{Checkpoints, Preview, RenderOptions, RenderOutput, Snapshot, StopReason};
use crate::camera::{CameraModel, CameraRay};
use crate::error::{Error, Result};
use crate::film::accumulation::{AOV_SUMS_PER_CHANNEL, PixelSums, ValueSum, add_aov_sample};
use crate::film::{Film, FilterSampler};
use crate::integrator::photon_map::PhotonMap;
use crate::integrator::sppm::{Photon, SppmIntegrator};
use crate::integrator::{Integrator, RayCount};
use crate::light::BoundingSphere;
use crate::render::relative_error;
use crate::sampling::rng::{Pcg32, hash_u64s};
use crate::sampling::sampler::{Sampler, SamplerKind};
use crate::scene::Scene;
use crate::spectrum::SampledWavelengths;

/// Photons a task traces when `granularity` leaves it to the renderer.
const DEFAULT_GRANULARITY: u32 = 4096;
/// Streams of the photons' random numbers and of the passes' wavelengths.
const PHOTON_STREAM: u64 = 0x5050_4d5f_7068_6f74;
const WAVELENGTH_STREAM: u64 = 0x5050_4d5f_6c61_6d62;

/// One pixel's statistics between passes.
#[derive(Clone, Copy, Debug)]
struct PixelState {
    radius: f64,
    /// The accumulated photon count N.
    photons: f64,
    /// The accumulated flux τ, CIE XYZ.
    flux: [f64; 3],
    /// The sum of the passes' direct estimates, CIE XYZ.
    direct: [f64; 3],
}

impl PixelState {
    /// A pixel before its first pass.
    fn new(radius: f64) -> PixelState {
        PixelState {
            radius,
            photons: 0.0,
            flux: [0.0; 3],
            direct: [0.0; 3],
        }
    }

    /// The pixel's estimate after `passes` passes of `photon_count` photons.
    fn radiance(&self, passes: u32, photon_count: u32) -> [f64; 3] {
        if passes == 0 {
            return [0.0; 3];
        }
        let p = f64::from(passes);
        let area = std::f64::consts::PI * self.radius * self.radius;
        let emitted = p * f64::from(photon_count);
        [0, 1, 2].map(|c| self.direct[c] / p + self.flux[c] / (emitted * area))
    }

    /// The progressive update with the flux `flux` of `found` photons (Hachisuka & Jensen
    /// 2009, eqs. 5–8).
    fn gather(&mut self, alpha: f64, flux: [f64; 3], found: u32) {
        if found == 0 {
            return;
        }
        let m = f64::from(found);
        let ratio = (self.photons + alpha * m) / (self.photons + m);
        self.radius *= ratio.sqrt();
        self.photons += alpha * m;
        for (tau, phi) in self.flux.iter_mut().zip(flux) {
            *tau = (*tau + phi) * ratio;
        }
    }
}

/// The integrator's type name, which its states carry ([`IntegratorState::integrator`]).
const INTEGRATOR: &str = "sppm";
/// The first byte of a state: a chain's, or a merge's.
const CHAIN_TAG: u8 = 1;
const MERGED_TAG: u8 = 2;
/// Bytes of one pixel's statistics in a chain's state: r, N, τ and Σ L_direct as f64.
const PIXEL_STATE_BYTES: usize = 8 * 8;

/// A progressive chain of passes, as far as it got: all its next pass depends on.
struct Chain {
    /// The sample index of its first pass.
    origin: u32,
    /// The passes done.
    passes: u32,
    /// Every pixel's statistics, row-major over the crop window.
    pixels: Vec<PixelState>,
}

/// What a merge of chains records: their count and passes, enough to weigh it in a later merge
/// and to say how biased its image is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct MergedChains {
    chains: u32,
    /// The passes of all the chains together.
    passes: u32,
    /// The fewest and most passes of one chain.
    fewest: u32,
    most: u32,
}

/// sppm's integrator state: a chain, which a render can continue, or a merge, which it cannot.
enum SppmState {
    Chain(Chain),
    Merged(MergedChains),
}

impl Chain {
    /// The chain's state: [`CHAIN_TAG`], the first sample index and the pass count (u32), the
    /// pixel count (u64), and each pixel's r, N, τ (X, Y, Z) and Σ L_direct (X, Y, Z) as f64,
    /// all little endian.
    fn encode(&self) -> IntegratorState {
        let mut bytes = Vec::with_capacity(17 + self.pixels.len() * PIXEL_STATE_BYTES);
        bytes.push(CHAIN_TAG);
        bytes.extend_from_slice(&self.origin.to_le_bytes());
        bytes.extend_from_slice(&self.passes.to_le_bytes());
        bytes.extend_from_slice(&(self.pixels.len() as u64).to_le_bytes());
        for p in &self.pixels {
            for v in [p.radius, p.photons].iter().chain(&p.flux).chain(&p.direct) {
                bytes.extend_from_slice(&v.to_le_bytes());
            }
        }
        IntegratorState {
            integrator: INTEGRATOR.into(),
            bytes,
        }
    }
}

impl MergedChains {
    /// The merge's state: [`MERGED_TAG`], then the chain count, the passes in all, the fewest
    /// and the most passes of one chain (u32, little endian).
    fn encode(&self) -> IntegratorState {
        let mut bytes = vec![MERGED_TAG];
        for v in [self.chains, self.passes, self.fewest, self.most] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        IntegratorState {
            integrator: INTEGRATOR.into(),
            bytes,
        }
    }
}

/// Splits `n` bytes off the front of `bytes`.
fn take<'a>(bytes: &mut &'a [u8], n: usize) -> Option<&'a [u8]> {
    let (head, rest) = bytes.split_at_checked(n)?;
    *bytes = rest;
    Some(head)
}

fn take_u32(bytes: &mut &[u8]) -> Option<u32> {
    take(bytes, 4).and_then(|b| Some(u32::from_le_bytes(b.try_into().ok()?)))
}

fn take_f64(bytes: &mut &[u8]) -> Option<f64> {
    take(bytes, 8).and_then(|b| Some(f64::from_le_bytes(b.try_into().ok()?)))
}

impl SppmState {
    /// Reads a state of a crop window of `pixel_count` pixels (the layouts of [`Chain::encode`]
    /// and [`MergedChains::encode`]); what is wrong with it, in words, when it is not one.
    /// Sizes are checked before anything is allocated.
    fn decode(bytes: &[u8], pixel_count: u64) -> std::result::Result<SppmState, String> {
        let mut rest = bytes;
        let truncated = || "end too early".to_string();
        match take(&mut rest, 1) {
            Some([CHAIN_TAG]) => {}
            Some([MERGED_TAG]) => {
                let mut v = [0u32; 4];
                for value in &mut v {
                    *value = take_u32(&mut rest).ok_or_else(truncated)?;
                }
                let [chains, passes, fewest, most] = v;
                let total = u64::from(passes);
                if !rest.is_empty()
                    || chains == 0
                    || fewest == 0
                    || fewest > most
                    || total < u64::from(chains) * u64::from(fewest)
                    || total > u64::from(chains) * u64::from(most)
                {
                    return Err("are not those of a merge of chains".into());
                }
                return Ok(SppmState::Merged(MergedChains {
                    chains,
                    passes,
                    fewest,
                    most,
                }));
            }
            _ => return Err("are of an unknown kind".into()),
        }
        let origin = take_u32(&mut rest).ok_or_else(truncated)?;
        let passes = take_u32(&mut rest).ok_or_else(truncated)?;
        if origin.checked_add(passes).is_none() {
            return Err(format!("claim {passes} passes from sample {origin}"));
        }
        let count = take(&mut rest, 8)
            .and_then(|b| Some(u64::from_le_bytes(b.try_into().ok()?)))
            .ok_or_else(truncated)?;
        if count != pixel_count
            || count.checked_mul(PIXEL_STATE_BYTES as u64) != Some(rest.len() as u64)
        {
            return Err(format!(
                "hold {count} pixels in {} bytes, for a crop window of {pixel_count} pixels",
                rest.len()
            ));
        }
        let mut pixels = Vec::with_capacity(count as usize);
        while !rest.is_empty() {
            let mut v = [0.0; 8];
            for value in &mut v {
                *value = take_f64(&mut rest).ok_or_else(truncated)?;
            }
            if !(v.iter().all(|v| v.is_finite()) && v[0] > 0.0 && v[1] >= 0.0) {
                return Err("hold a pixel whose radius, photon count or sums are invalid".into());
            }
            let [radius, photons, fx, fy, fz, dx, dy, dz] = v;
            pixels.push(PixelState {
                radius,
                photons,
                flux: [fx, fy, fz],
                direct: [dx, dy, dz],
            });
        }
        Ok(SppmState::Chain(Chain {
            origin,
            passes,
            pixels,
        }))
    }
}

/// Merges states of sppm chains (or of merges of them) over disjoint sample ranges, after
/// [`RenderState::merge`]'s checks of identity, channels and overlap: each pixel of the merged
/// image is the pass-weighted mean Σ P_c L_c / Σ P_c of the chains' images L_c (summed in the order
/// of their first sample index), held as its one sample, as a chain's is; its state records the
/// chains' count and passes and cannot be resumed.
pub(super) fn merge_states(states: &[RenderState], paths: &[&Path]) -> Result<RenderState> {
    let mut parts = Vec::with_capacity(states.len());
    for (index, (state, path)) in states.iter().zip(paths).enumerate() {
        let invalid = |reason: String| {
            Err(Error::usage(format!(
                "\"{}\" cannot be merged: its sppm statistics {reason}",
                path.display()
            )))
        };
        let pixel_count = state.pixels.len() as u64;
        let bytes = state
            .integrator_state
            .as_ref()
            .map_or(&[][..], |s| &s.bytes);
        let chains = match SppmState::decode(bytes, pixel_count) {
            Err(reason) => return invalid(reason),
            Ok(SppmState::Chain(chain)) => {
                let claimed = chain.origin..chain.origin + chain.passes;
                if state.ranges != [claimed] {
                    return invalid(format!(
                        "are of passes {}..{}, not of the samples the state holds",
                        chain.origin,
                        chain.origin + chain.passes
                    ));
                }
                MergedChains {
                    chains: 1,
                    passes: chain.passes,
                    fewest: chain.passes,
                    most: chain.passes,
                }
            }
            Ok(SppmState::Merged(merged)) => {
                if state.sample_count() != merged.passes {
                    return invalid(format!(
                        "are of {} passes, not of the {} samples the state holds",
                        merged.passes,
                        state.sample_count()
                    ));
                }
                merged
            }
        };
        parts.push((state.ranges[0].start, chains, index));
    }
    let sums: Vec<RenderState> = states
        .iter()
        .map(|state| RenderState {
            integrator_state: None,
            ..state.clone()
        })
        .collect();
    let mut merged = RenderState::merge(&sums, paths)?;
    parts.sort_by_key(|&(start, ..)| start);
    let total = parts.iter().map(|(_, c, _)| c.passes).sum::<u32>();
    let weighted = |value: &dyn Fn(&RenderState) -> f64| {
        parts
            .iter()
            .map(|&(_, chains, index)| f64::from(chains.passes) * value(&states[index]))
            .sum::<f64>()
            / f64::from(total)
    };
    for (i, pixel) in merged.pixels.iter_mut().enumerate() {
        *pixel = PixelSums::default();
        pixel.add_total([0, 1, 2].map(|c| weighted(&|s| s.pixels[i].mean()[c])));
        for state in states {
            pixel.rejected = pixel.rejected.max(state.pixels[i].rejected);
        }
    }
    for (i, sum) in merged.aovs.iter_mut().enumerate() {
        *sum = ValueSum::default();
        sum.add(weighted(&|s| s.aovs[i].value()));
    }
    merged.integrator_state = Some(
        MergedChains {
            chains: parts.iter().map(|(_, c, _)| c.chains).sum(),
            passes: total,
            fewest: parts.iter().map(|(_, c, _)| c.fewest).min().unwrap_or(0),
            most: parts.iter().map(|(_, c, _)| c.most).max().unwrap_or(0),
        }
        .encode(),
    );
    Ok(merged)
}

/// What the image of a merged sppm state is, for `prism merge` to say: None for a state that is
/// no merge of sppm chains.
pub fn merge_summary(state: &IntegratorState) -> Option<String> {
    if state.integrator != INTEGRATOR {
        return None;
    }
    let SppmState::Merged(merged) = SppmState::decode(&state.bytes, 0).ok()? else {
        return None;
    };
    let per_chain = if merged.fewest == merged.most {
        format!("{} passes each", merged.most)
    } else {
        format!("{} to {} passes", merged.fewest, merged.most)
    };
    Some(format!(
        "the image is the pass-weighted mean of {} independent sppm chains of {per_chain}: it \
         is biased as one chain of that many passes is, not as one of {} passes, and has no \
         error estimate (its variance channels are infinite); the merged state cannot be \
         resumed",
        merged.chains, merged.passes
    ))
}

/// The random number that draws the wavelengths of pass `pass` of a render with seed `seed`:
/// the radical inverse of the pass in base 2, rotated by a number drawn from the seed
/// (Cranley–Patterson), so that every run of 2ᵏ passes covers the wavelengths evenly.
pub(super) fn pass_wavelength(seed: u64, pass: u32) -> f32 {
    let rotation = Pcg32::new(hash_u64s(&[seed]), WAVELENGTH_STREAM).next_f64();
    let u = f64::from(pass.reverse_bits()) / 2f64.powi(32) + rotation;
    (u.fract() as f32).min(1.0f32.next_down())
}

/// Mitsuba 0.6's initial radius: five times the scene's bounding radius over the film's larger
/// side.
fn automatic_radius(scene: &Scene) -> f32 {
    let sphere = BoundingSphere::around_box(scene.world.geometry.bounds());
    let size = scene.film.size;
    5.0 * sphere.radius / size.x.max(size.y) as f32
}

/// Where a chain of `scene` whose first pass is sample index `origin` ends when the scene's sppm
/// sets `maxPasses`, which replaces the sample count: `origin + maxPasses`. None for any other
/// scene, whose sample count or range decides. A caller that checks whether anything is left to
/// render (a resumed render) asks this first.
pub fn chain_end(scene: &Scene, origin: u32) -> Option<u32> {
    match &scene.integrator {
        Integrator::Sppm(sppm) => sppm.max_passes.map(|passes| origin.saturating_add(passes)),
        _ => None,
    }
}

/// Renders the scene with `sppm` (see the module's text).
pub(super) fn render(
    scene: &Scene,
    sppm: &SppmIntegrator,
    estimator: &SampleEstimator,
    options: &RenderOptions,
    pool: &rayon::ThreadPool,
    mut checkpoints: Option<Checkpoints>,
    mut preview: Option<Preview>,
) -> Result<RenderOutput> {
    let refuse = |what: &str| Err(Error::usage(format!("the sppm integrator {what}")));
    if options.stop.target_error.is_some() {
        return refuse(
            "has no error estimate to stop at: its image is biased at any finite pass count",
        );
    }
    if !scene.film.bands.is_empty() {
        return refuse("writes no spectral bands");
    }
    let film = &scene.film;
    let crop = film.crop;
    let width = crop.size.x as usize;
    let pixel_count = u64::from(crop.size.x) * u64::from(crop.size.y);
    let first = options.first_sample;
    let mut chain = match &options.initial {
        Some(initial) => resumed_chain(initial.integrator.as_ref(), pixel_count, first)?,
        None => {
            let radius = f64::from(
                sppm.initial_radius
                    .unwrap_or_else(|| automatic_radius(scene)),
            );
            Chain {
                origin: first,
                passes: 0,
                pixels: vec![PixelState::new(radius); pixel_count as usize],
            }
        }
    };
    let end = chain_end(scene, chain.origin).or(options.stop.sample_end);
    let mut next_state = chain.pixels.clone();
    let aov_count = estimator.aov_count();
    let progress: &dyn ProgressReport = options.progress.as_deref().unwrap_or(&Silent);
    progress.begin(end.map(|end| pixel_count * u64::from(end.saturating_sub(first))));
    let abort = AtomicBool::new(false);
    let rays = AtomicU64::new(0);
    let start = Instant::now();
    let cancel = Cancel {
        flag: &abort,
        external: options.interrupt.as_deref(),
        deadline: options.stop.time_limit.map(|limit| start + limit),
    };
    let pass = PassContext {
        scene,
        sppm,
        estimator,
        options,
        cancel: &cancel,
        progress,
    };
    let mut last_checkpoint = start;
    let mut next = first;
    let reason = loop {
        if end.is_some_and(|end| next >= end) {
            break StopReason::Completed;
        }
        if options
            .stop
            .time_limit
            .is_some_and(|limit| start.elapsed() >= limit)
        {
            break StopReason::TimeLimit;
        }
        let interrupted = || {
            options
                .interrupt
                .as_ref()
                .is_some_and(|i| i.load(Ordering::Relaxed))
        };
        if interrupted() {
            break StopReason::Interrupted;
        }
        next_state.copy_from_slice(&chain.pixels);
        let done = pool.install(|| pass.run(next, &mut next_state, width));
        let Some(pass_rays) = done.filter(|_| !abort.load(Ordering::Relaxed)) else {
            break if interrupted() {
                StopReason::Interrupted
            } else {
                StopReason::TimeLimit
            };
        };
        std::mem::swap(&mut chain.pixels, &mut next_state);
        rays.fetch_add(pass_rays, Ordering::Relaxed);
        chain.passes += 1;
        next += 1;
        progress.pass_done(next - first, f64::INFINITY);
        let checkpoint_due = (checkpoints.as_ref())
            .is_some_and(|checkpoint| last_checkpoint.elapsed() >= checkpoint.every);
        if checkpoint_due || preview.is_some() {
            let film = film_of(scene, sppm, &chain, aov_count);
            let integrator_state = chain.encode();
            let snapshot = Snapshot {
                samples: first..next,
                pixels: &film.pixels,
                aovs: &film.aovs,
                integrator_state: Some(&integrator_state),
            };
            if let Some(preview) = &mut preview {
                preview(&snapshot)?;
            }
            if let Some(checkpoint) = &mut checkpoints
                && checkpoint_due
            {
                (checkpoint.write)(&snapshot)?;
                last_checkpoint = Instant::now();
            }
        }
    };
    let elapsed = start.elapsed();
    progress.end();
    let film = film_of(scene, sppm, &chain, aov_count);
    let integrator_state = chain.encode();
    if let Some(checkpoint) = &mut checkpoints {
        (checkpoint.write)(&Snapshot {
            samples: first..next,
            pixels: &film.pixels,
            aovs: &film.aovs,
            integrator_state: Some(&integrator_state),
        })?;
    }
    let error = relative_error(film.pixels.iter());
    Ok(RenderOutput {
        film,
        samples: first..next,
        elapsed,
        sample_count: pixel_count * u64::from(next - first),
        rays: rays.into_inner(),
        stop: reason,
        relative_error: error,
        lane_occupancy: None,
        integrator_state: Some(integrator_state),
    })
}

/// The chain a render resumed from `state` continues: sppm's, of `pixel_count` pixels, and
/// ending at sample index `first_sample`, where the render starts.
fn resumed_chain(
    state: Option<&IntegratorState>,
    pixel_count: u64,
    first_sample: u32,
) -> Result<Chain> {
    let cannot = |reason: String| {
        Err(
            Error::usage(format!("cannot resume this sppm render: {reason}"))
                .with_help("resume from a state written by an sppm render of the same scene"),
        )
    };
    let state = match state {
        None => {
            return cannot(
                "the state holds no sppm statistics (another integrator rendered it)".into(),
            );
        }
        Some(state) if state.integrator != INTEGRATOR => {
            return cannot(format!("the state is of a {} render", state.integrator));
        }
        Some(state) => state,
    };
    let chain = match SppmState::decode(&state.bytes, pixel_count) {
        Err(reason) => return cannot(format!("its sppm statistics {reason}")),
        Ok(SppmState::Merged(merged)) => {
            return cannot(format!(
                "the state is a merge of {} sppm chains, whose pixel statistics it does not \
                 keep: resume one of the chains instead",
                merged.chains
            ));
        }
        Ok(SppmState::Chain(chain)) => chain,
    };
    let end = chain.origin + chain.passes;
    if end != first_sample {
        return cannot(format!(
            "its statistics are of passes {}..{end}, which do not end where this render starts \
             ({first_sample})",
            chain.origin
        ));
    }
    Ok(chain)
}

/// The film holding each pixel's estimate after the chain's passes as its one sample (and a
/// coverage of 1 in every extra channel: sppm writes only the alpha).
fn film_of(scene: &Scene, sppm: &SppmIntegrator, chain: &Chain, aov_count: usize) -> Film {
    let mut film = Film::with_aovs(scene.film.size, scene.film.crop, scene.aov_names());
    let stride = AOV_SUMS_PER_CHANNEL * aov_count;
    let coverage = vec![1.0f32; aov_count];
    for (i, (pixel, s)) in film.pixels.iter_mut().zip(&chain.pixels).enumerate() {
        pixel.add_total(s.radiance(chain.passes, sppm.photon_count));
        add_aov_sample(
            &mut film.aovs[i * stride..i * stride + aov_count],
            &coverage,
        );
    }
    film
}

/// What every pass works with.
struct PassContext<'a> {
    scene: &'a Scene,
    sppm: &'a SppmIntegrator,
    estimator: &'a SampleEstimator<'a>,
    options: &'a RenderOptions,
    cancel: &'a Cancel<'a>,
    progress: &'a dyn ProgressReport,
}

impl PassContext<'_> {
    /// Runs the pass of sample index `sample`, updating `state` (row-major over the crop window, rows `width` wide);
    /// returns the rays traced, or None when the pass was cancelled.
    fn run(&self, sample: u32, state: &mut [PixelState], width: usize) -> Option<u64> {
        let film = &self.scene.film;
        let lambda = SampledWavelengths::sample(
            pass_wavelength(self.options.seed, sample),
            film.wavelength_sampling,
        );
        let (photons, mut rays) = self.trace_photons(sample, &lambda)?;
        let largest = state.iter().map(|s| s.radius).fold(0.0, f64::max) as f32;
        let map = PhotonMap::new(&photons, largest);
        let filter = FilterSampler::new(film.filter);
        let rows: Vec<Option<u64>> = state
            .par_chunks_mut(width)
            .enumerate()
            .map(|(y, row)| self.gather_row(sample, y as u32, row, &lambda, &map, &filter))
            .collect();
        for row in rows {
            rays += row?;
        }
        Some(rays)
    }

    /// The photons of the pass of sample index `sample`, in the order of their indices, and the rays traced.
    fn trace_photons(
        &self,
        sample: u32,
        lambda: &SampledWavelengths,
    ) -> Option<(Vec<Photon>, u64)> {
        let count = self.sppm.photon_count;
        let granularity = self.sppm.granularity.unwrap_or(DEFAULT_GRANULARITY).max(1);
        let tasks: Vec<(u32, u32)> = (0..count)
            .step_by(granularity as usize)
            .map(|first| (first, (first + granularity).min(count)))
            .collect();
        let traced: Vec<Option<(Vec<Photon>, u64)>> = tasks
            .par_iter()
            .map(|&(first, end)| {
                if self.cancel.raised() {
                    return None;
                }
                let scene = self.scene;
                let prepared = &self.estimator.integrator;
                let seed = hash_u64s(&[self.options.seed, PHOTON_STREAM]);
                let mut sampler = Sampler::new(SamplerKind::Independent, 1, seed);
                let mut count = RayCount::default();
                let mut photons = Vec::new();
                for index in first..end {
                    sampler.start_pixel_sample(UVec2::new(index, 0), sample);
                    let (time, time_weight) = scene.shutter.sample(sampler.next_1d());
                    self.sppm.trace_photon(
                        prepared,
                        &mut sampler,
                        &mut count,
                        lambda,
                        time,
                        time_weight,
                        &mut photons,
                    );
                }
                Some((photons, count.rays))
            })
            .collect();
        let mut photons = Vec::new();
        let mut rays = 0;
        for task in traced {
            let (task_photons, task_rays) = task?;
            photons.extend(task_photons);
            rays += task_rays;
        }
        Some((photons, rays))
    }

    /// Traces the camera paths of row `y` of the crop window in the pass of sample index `sample` and updates its
    /// pixels' statistics; returns the rays traced, or None when the pass was cancelled.
    fn gather_row(
        &self,
        sample: u32,
        y: u32,
        row: &mut [PixelState],
        lambda: &SampledWavelengths,
        map: &PhotonMap<Photon>,
        filter: &FilterSampler,
    ) -> Option<u64> {
        if self.cancel.raised() {
            return None;
        }
        let scene = self.scene;
        let film = &scene.film;
        let prepared = &self.estimator.integrator;
        let alpha = f64::from(self.sppm.alpha);
        let mut sampler = Sampler::new(
            scene.sampler.kind,
            self.options.samples_per_pixel,
            self.options.seed,
        );
        let mut count = RayCount::default();
        for (x, state) in row.iter_mut().enumerate() {
            let pixel = film.crop.offset + UVec2::new(x as u32, y);
            sampler.start_pixel_sample(pixel, sample);
            let primary = sampler.camera_sample();
            let (offset, filter_weight) = filter.sample(primary.film);
            let (time, time_weight) = scene.shutter.sample(primary.time);
            let film_position = pixel.as_vec2() + Vec2::splat(0.5) + offset;
            let CameraRay { ray, weight } =
                scene.camera.generate_ray(film_position, primary.lens, time);
            let mut estimate = self.sppm.estimate(
                prepared,
                &mut sampler,
                &mut count,
                ray,
                weight * filter_weight * time_weight,
                lambda,
                map,
                state.radius as f32,
            );
            if let Some(response) = &film.response {
                let response = response.sample(lambda);
                estimate.direct *= response;
                estimate.flux *= response;
            }
            let direct = lambda.to_xyz(&estimate.direct);
            let flux = lambda.to_xyz(&estimate.flux);
            if !direct.iter().chain(&flux).all(|v| v.is_finite()) {
                continue;
            }
            for (sum, v) in state.direct.iter_mut().zip(direct) {
                *sum += f64::from(v);
            }
            state.gather(alpha, flux.map(f64::from), estimate.photons);
        }
        self.progress.advance(row.len() as u64);
        Some(count.rays)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chain() -> Chain {
        let mut pixels = vec![PixelState::new(0.25); 3];
        pixels[1].gather(0.7, [1.0, 2.0, 3.0], 4);
        pixels[2].direct = [0.5, 0.25, 0.125];
        Chain {
            origin: 8,
            passes: 5,
            pixels,
        }
    }

    fn merged() -> MergedChains {
        MergedChains {
            chains: 3,
            passes: 20,
            fewest: 4,
            most: 8,
        }
    }

    #[test]
    fn states_round_trip() {
        let bytes = chain().encode().bytes;
        assert_eq!(bytes.len(), 17 + 3 * PIXEL_STATE_BYTES);
        let Ok(SppmState::Chain(decoded)) = SppmState::decode(&bytes, 3) else {
            panic!("not a chain");
        };
        assert_eq!((decoded.origin, decoded.passes), (8, 5));
        for (a, b) in decoded.pixels.iter().zip(&chain().pixels) {
            assert_eq!(
                (a.radius, a.photons, a.flux, a.direct),
                (b.radius, b.photons, b.flux, b.direct)
            );
        }
        let bytes = merged().encode().bytes;
        assert!(matches!(
            SppmState::decode(&bytes, 3),
            Ok(SppmState::Merged(m)) if m == merged()
        ));
    }

    /// Every truncation, an extra byte, another pixel count and a flip of any byte's high bit
    /// are refused or read without a panic; the damage sizes cannot make it allocate.
    #[test]
    fn damaged_states_are_refused() {
        for bytes in [chain().encode().bytes, merged().encode().bytes] {
            for n in 0..bytes.len() {
                assert!(
                    SppmState::decode(&bytes[..n], 3).is_err(),
                    "truncated to {n}"
                );
            }
            let mut longer = bytes.clone();
            longer.push(0);
            assert!(SppmState::decode(&longer, 3).is_err());
            for i in 0..bytes.len() {
                let mut damaged = bytes.clone();
                damaged[i] ^= 0x80;
                let _ = SppmState::decode(&damaged, 3);
            }
        }
        assert!(SppmState::decode(&chain().encode().bytes, 4).is_err());
        let mut huge = chain().encode().bytes;
        huge[9..17].copy_from_slice(&u64::MAX.to_le_bytes());
        assert!(SppmState::decode(&huge, u64::MAX).is_err());
        let mut overflowing = chain().encode().bytes;
        overflowing[1..5].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(SppmState::decode(&overflowing, 3).is_err());
    }

    /// The merge summary names the chains' passes and the bias; a chain's state has none.
    #[test]
    fn the_merge_summary_says_how_biased_the_image_is() {
        let summary = merge_summary(&merged().encode()).unwrap();
        assert!(summary.contains("3 independent sppm chains of 4 to 8 passes"));
        assert!(summary.contains("not as one of 20 passes"));
        assert!(merge_summary(&chain().encode()).is_none());
    }
}
