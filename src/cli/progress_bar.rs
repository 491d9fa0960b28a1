//! The terminal's progress bar: a [`ProgressReport`] drawn by `indicatif` on standard error,
//! with the samples done, their rate and, once a pass is done, the image's mean relative error.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use prism_core::render::ProgressReport;

/// A progress bar on standard error.
#[derive(Debug)]
pub struct TerminalProgress {
    bar: ProgressBar,
}

impl Default for TerminalProgress {
    fn default() -> TerminalProgress {
        TerminalProgress {
            bar: ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr()),
        }
    }
}

impl ProgressReport for TerminalProgress {
    fn begin(&self, total: Option<u64>) {
        let template = if total.is_some() {
            "{bar:40.cyan/blue} {percent:>3}% {human_pos}/{human_len} samples, {per_sec}, ETA {eta} — {msg}"
        } else {
            "{spinner} {elapsed_precise} {human_pos} samples, {per_sec} — {msg}"
        };
        match total {
            Some(total) => self.bar.set_length(total),
            None => self.bar.unset_length(),
        }
        self.bar.set_style(
            ProgressStyle::with_template(template).unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
    }

    fn advance(&self, samples: u64) {
        self.bar.inc(samples);
    }

    fn pass_done(&self, spp: u32, error: f64) {
        self.bar.set_message(format!("{spp} spp, error {error:.4}"));
    }

    fn end(&self) {
        self.bar.finish_and_clear();
    }
}
