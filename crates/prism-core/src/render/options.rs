//! How to render: the sample range, the stopping rule, the seed, the threads, where progress
//! goes, and the sums a resumed render starts from.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use super::progress::ProgressReport;
use super::resume::InitialState;
use super::stop::StopRule;

/// How to render.
#[derive(Clone, Debug)]
pub struct RenderOptions {
    /// Samples per pixel over which the sampler stratifies (N); samples beyond N start new
    /// stratified blocks. Stratified samplers may round it up
    /// (see [`crate::sampling::sampler::SamplerKind::sample_count`]).
    pub samples_per_pixel: u32,
    /// Index of the first sample to take in every pixel (past a checkpoint, or the start of a
    /// range given to this render).
    pub first_sample: u32,
    /// What the render starts from (a resumed render's sums and integrator state).
    pub initial: Option<InitialState>,
    pub stop: StopRule,
    /// Raised from outside (by a signal handler) to stop the render after dropping its pass.
    pub interrupt: Option<Arc<AtomicBool>>,
    /// Worker threads; None for one per core.
    pub threads: Option<usize>,
    /// Seed of every random stream.
    pub seed: u64,
    /// Where progress goes (None: nowhere).
    pub progress: Option<Arc<dyn ProgressReport>>,
}

impl RenderOptions {
    /// Options for rendering the samples 0..spp in one go.
    pub fn fixed(spp: u32, seed: u64, threads: Option<usize>) -> RenderOptions {
        RenderOptions {
            samples_per_pixel: spp,
            first_sample: 0,
            initial: None,
            stop: StopRule::samples(spp),
            interrupt: None,
            threads,
            seed,
            progress: None,
        }
    }

    /// Whether the render goes in several passes: when it can be stopped early or checkpointed.
    pub(super) fn in_passes(&self, checkpoints: bool) -> bool {
        checkpoints || self.interrupt.is_some() || self.stop.is_open_ended()
    }
}
