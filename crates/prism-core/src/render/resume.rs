//! A render that continues a saved state or saves its own: what it is (its
//! [`RenderIdentity`]), the sums and sample ranges a resumed render starts from, and the
//! [`RenderState`] of each of its snapshots. `prism render --resume/--checkpoint` and Python's
//! `render(resume=..., checkpoint=...)` go through it, so that their states are the same files.

use std::ops::Range;
use std::path::Path;

use super::Snapshot;
use super::state::{IntegratorState, RenderIdentity, RenderState};
use crate::error::{Error, Result};
use crate::film::{PixelSums, ValueSum};
use crate::scene::Scene;

/// What a resumed render starts from ([`super::RenderOptions::initial`]).
#[derive(Clone, Debug)]
pub struct InitialState {
    /// The image's sums, row-major over the crop window.
    pub pixels: Vec<PixelSums>,
    /// The extra channels' sums, 2K per pixel, as [`crate::film::Film::aovs`] holds them.
    pub aovs: Vec<ValueSum>,
    /// A progressive integrator's state, where the render had one.
    pub integrator: Option<IntegratorState>,
}

impl InitialState {
    /// The sums of a render whose integrator keeps no state of its own.
    pub fn sums(pixels: Vec<PixelSums>, aovs: Vec<ValueSum>) -> InitialState {
        InitialState {
            pixels,
            aovs,
            integrator: None,
        }
    }
}

/// A render's identity and the samples it continues.
#[derive(Clone, Debug)]
pub struct Continuation {
    pub identity: RenderIdentity,
    aov_names: Vec<String>,
    /// The sample ranges of the state it resumed (none for a fresh render).
    previous: Vec<Range<u32>>,
}

impl Continuation {
    /// A fresh render of `scene` (its film's crop window as set) with random numbers of `seed`
    /// and `strata` samples per pixel of the sampler's stratification ([`Scene::strata`]).
    pub fn new(scene: &Scene, seed: u64, strata: u32) -> Continuation {
        Continuation {
            identity: RenderIdentity {
                scene: scene.fingerprint,
                seed,
                sampler: scene.sampler.kind.name().to_string(),
                samples_per_pixel: strata,
                film_size: scene.film.size,
                crop: scene.film.crop,
            },
            aov_names: scene.aov_names(),
            previous: Vec::new(),
        }
    }

    /// Continues the render saved at `path`, whose samples must start at `first_sample` (0,
    /// or the start of the sample range asked for): checks that the state is of this render,
    /// and gives the sample index its samples end at, where this render starts, with its sums.
    pub fn resume(&mut self, path: &Path, first_sample: u32) -> Result<(u32, InitialState)> {
        let state = RenderState::read(path)?;
        let cannot = |reason: String| {
            Error::usage(format!(
                "cannot resume from \"{}\": {reason}",
                path.display()
            ))
        };
        if let Some(reason) = self.identity.mismatch(&state.identity) {
            return Err(cannot(reason).with_help(
                "resume with the same scene, parameters, samples per pixel, seed, crop, \
                 wavelength density and reconstruction as the interrupted render",
            ));
        }
        let [range] = state.ranges.as_slice() else {
            return Err(cannot(
                "it holds several sample ranges (a merge), which cannot be continued".into(),
            ));
        };
        if range.start != first_sample {
            return Err(cannot(format!(
                "it holds samples {}..{}, which do not start where this render's range starts \
                 ({first_sample})",
                range.start, range.end
            )));
        }
        if state.aov_names != self.aov_names {
            return Err(cannot(
                "its integrator (or film) wrote other extra channels".into(),
            ));
        }
        self.previous = vec![range.clone()];
        Ok((
            range.end,
            InitialState {
                pixels: state.pixels,
                aovs: state.aovs,
                integrator: state.integrator_state,
            },
        ))
    }

    /// Saves the state of `snapshot` ([`Continuation::state`]) to `path`, unless it holds no
    /// samples at all.
    pub fn save(&self, snapshot: &Snapshot, path: &Path) -> Result<()> {
        let state = self.state(snapshot);
        if state.ranges.is_empty() {
            return Ok(());
        }
        state.write(path)
    }

    /// The state of the render when it holds `snapshot`'s sums: the samples of the state it
    /// resumed and the snapshot's.
    pub fn state(&self, snapshot: &Snapshot) -> RenderState {
        let mut ranges = self.previous.clone();
        if !snapshot.samples.is_empty() {
            match ranges.last_mut() {
                Some(last) if last.end == snapshot.samples.start => last.end = snapshot.samples.end,
                _ => ranges.push(snapshot.samples.clone()),
            }
        }
        RenderState {
            identity: self.identity.clone(),
            ranges,
            pixels: snapshot.pixels.to_vec(),
            aov_names: self.aov_names.clone(),
            aovs: snapshot.aovs.to_vec(),
            integrator_state: snapshot.integrator_state.cloned(),
        }
    }
}
