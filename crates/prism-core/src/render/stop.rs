//! When a render stops: the stopping rules (a sample count, a time limit, a target error), the
//! length of the next pass, and the flag that cancels a pass in flight.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use crate::error::{Error, Result};

/// A render made of several passes aims at passes of about this length, so that stopping rules,
/// checkpoints and interruptions are acted on promptly and little work is dropped.
const TARGET_PASS_TIME: Duration = Duration::from_secs(2);

/// When a render stops (besides an interruption).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StopRule {
    /// Stop before this sample index (None: no limit).
    pub sample_end: Option<u32>,
    /// Stop when this much time has passed; the pass running then is dropped.
    pub time_limit: Option<Duration>,
    /// Stop once the image's mean relative standard error is at most this.
    pub target_error: Option<f64>,
}

impl StopRule {
    /// Render the samples 0..n.
    pub fn samples(n: u32) -> StopRule {
        StopRule {
            sample_end: Some(n),
            ..StopRule::default()
        }
    }

    /// The rule for a render asked for `spp` samples per pixel (None: the scene's `scene_spp`),
    /// a time limit in seconds and a target for the mean relative error. Without a time limit
    /// or target error the render takes exactly the samples; with either, `spp` (if given) only
    /// caps them. Messages call the three settings by `names`, as the caller's user knows them.
    pub fn requested(
        spp: Option<u32>,
        scene_spp: u32,
        time_limit: Option<f64>,
        target_error: Option<f64>,
        names: &StopRuleNames,
    ) -> Result<StopRule> {
        if spp == Some(0) {
            return Err(Error::usage(format!("{} must be at least 1", names.spp)));
        }
        let time_limit = match time_limit {
            Some(t) if !(t > 0.0 && t.is_finite()) => {
                return Err(Error::usage(format!(
                    "{} must be a positive number of seconds, not {t}",
                    names.time_limit
                )));
            }
            t => t.map(Duration::from_secs_f64),
        };
        if let Some(e) = target_error
            && !(e > 0.0 && e.is_finite())
        {
            return Err(Error::usage(format!(
                "{} must be positive, not {e}",
                names.target_error
            )));
        }
        let open_ended = time_limit.is_some() || target_error.is_some();
        Ok(StopRule {
            sample_end: if open_ended {
                spp
            } else {
                Some(spp.unwrap_or(scene_spp))
            },
            time_limit,
            target_error,
        })
    }

    pub(super) fn is_open_ended(&self) -> bool {
        self.time_limit.is_some() || self.target_error.is_some()
    }
}

/// What the settings of [`StopRule::requested`] are called where they were given (command-line
/// options, or a function's arguments).
pub struct StopRuleNames {
    pub spp: &'static str,
    pub time_limit: &'static str,
    pub target_error: &'static str,
}

/// Why a render stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// All requested samples were taken.
    Completed,
    TimeLimit,
    TargetError,
    Interrupted,
}

/// Tells a pass to stop: raised by whoever notices the deadline first, or from outside.
pub(super) struct Cancel<'a> {
    pub(super) flag: &'a AtomicBool,
    pub(super) external: Option<&'a AtomicBool>,
    pub(super) deadline: Option<Instant>,
}

impl Cancel<'_> {
    pub(super) fn raised(&self) -> bool {
        if self.deadline.is_some_and(|d| Instant::now() >= d)
            || self.external.is_some_and(|e| e.load(Ordering::Relaxed))
        {
            self.flag.store(true, Ordering::Relaxed);
        }
        self.flag.load(Ordering::Relaxed)
    }
}

/// The number of samples per pixel of the next pass.
pub(super) fn next_pass(
    in_passes: bool,
    done: u32,
    left: u32,
    stop: &StopRule,
    elapsed: Duration,
    error: f64,
) -> u32 {
    if !in_passes {
        return left;
    }
    // Passes grow geometrically from one sample, then keep to about TARGET_PASS_TIME.
    let mut pass = done.max(1);
    if done > 0 {
        let per_sample = elapsed.as_secs_f64() / f64::from(done);
        pass = pass.min((TARGET_PASS_TIME.as_secs_f64() / per_sample.max(1e-9)).ceil() as u32);
    }
    if let Some(target) = stop.target_error
        && done > 0
        && error.is_finite()
    {
        // The error falls as 1/√n: n·(error/target)² samples reach the target.
        let needed = (f64::from(done) * (error / target).powi(2)).ceil() as u32;
        pass = pass.min(needed.saturating_sub(done).max(1));
    }
    if let Some(limit) = stop.time_limit
        && done > 0
    {
        let per_sample = elapsed.as_secs_f64() / f64::from(done);
        let remaining = limit.saturating_sub(elapsed).as_secs_f64();
        pass = pass.min(((remaining / per_sample) as u32).max(1));
    }
    pass.clamp(1, left.max(1))
}
