//! How a render reports its progress: through [`ProgressReport`], called from the render's
//! worker threads as tiles and passes finish. The command line draws a terminal bar with it;
//! the Python module's [`ProgressCounter`] keeps counts that its own bar reads.

use std::fmt::Debug;
use std::sync::atomic::{AtomicU64, Ordering};

/// Receives a render's progress. Its methods are called from the render's threads, so they
/// should be quick (an atomic add, a bar's update).
pub trait ProgressReport: Debug + Send + Sync {
    /// The render starts; it will take `total` camera samples (None when a time limit or a
    /// target error ends it).
    fn begin(&self, total: Option<u64>);
    /// `samples` more camera samples are done.
    fn advance(&self, samples: u64);
    /// A pass is done: `spp` samples per pixel so far, with the image's mean relative standard
    /// `error`.
    fn pass_done(&self, spp: u32, error: f64);
    /// The render has stopped.
    fn end(&self);
}

/// Progress that goes nowhere.
#[derive(Debug)]
pub(super) struct Silent;

impl ProgressReport for Silent {
    fn begin(&self, _total: Option<u64>) {}
    fn advance(&self, _samples: u64) {}
    fn pass_done(&self, _spp: u32, _error: f64) {}
    fn end(&self) {}
}

/// A render's progress kept in counters, updated by the render as tiles finish and readable
/// from any thread.
#[derive(Debug, Default)]
pub struct ProgressCounter {
    samples: AtomicU64,
    /// The camera samples the render will take, or 0 when it is open-ended.
    total: AtomicU64,
    /// The image's mean relative error after the last pass, as `f64` bits.
    error_bits: AtomicU64,
}

impl ProgressCounter {
    /// Camera samples taken so far.
    pub fn samples(&self) -> u64 {
        self.samples.load(Ordering::Relaxed)
    }

    /// Camera samples the render will take; None when a time limit or target error ends it.
    pub fn total(&self) -> Option<u64> {
        Some(self.total.load(Ordering::Relaxed)).filter(|&t| t > 0)
    }

    /// The image's mean relative standard error after the last finished pass (infinite
    /// before).
    pub fn relative_error(&self) -> f64 {
        match self.error_bits.load(Ordering::Relaxed) {
            0 => f64::INFINITY,
            bits => f64::from_bits(bits),
        }
    }
}

impl ProgressReport for ProgressCounter {
    fn begin(&self, total: Option<u64>) {
        self.samples.store(0, Ordering::Relaxed);
        self.total.store(total.unwrap_or(0), Ordering::Relaxed);
        self.error_bits.store(0, Ordering::Relaxed);
    }

    fn advance(&self, samples: u64) {
        self.samples.fetch_add(samples, Ordering::Relaxed);
    }

    fn pass_done(&self, _spp: u32, error: f64) {
        self.error_bits.store(error.to_bits(), Ordering::Relaxed);
    }

    fn end(&self) {}
}
