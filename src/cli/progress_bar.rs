//! The terminal's progress bar: a [`ProgressReport`] drawn by `indicatif` on standard error,
//! with the samples done, their rate and, once a pass is done, the image's mean relative error
//! and, under a time limit, the time left.

use std::time::Duration;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use prism_core::render::ProgressReport;

/// A progress bar on standard error.
#[derive(Debug)]
pub struct TerminalProgress {
    bar: ProgressBar,
    /// The render's time limit, counted from the bar's start.
    time_limit: Option<Duration>,
}

impl TerminalProgress {
    /// A bar for a render that stops after `time_limit`, if it has one.
    pub fn new(time_limit: Option<Duration>) -> TerminalProgress {
        TerminalProgress {
            bar: ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr()),
            time_limit,
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
        let mut message = format!("{spp} spp, error {error:.4}");
        if let Some(limit) = self.time_limit {
            let left = limit.saturating_sub(self.bar.elapsed()).as_secs_f64();
            message += &format!(", {left:.0} s left");
        }
        self.bar.set_message(message);
    }

    fn end(&self) {
        self.bar.finish_and_clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn under_a_time_limit_the_message_gives_the_time_left() {
        let progress = TerminalProgress::new(Some(Duration::from_secs(60)));
        progress.begin(None);
        progress.pass_done(4, 0.05);
        let message = progress.bar.message();
        assert!(message.starts_with("4 spp, error 0.0500, "), "{message}");
        assert!(message.ends_with(" s left"), "{message}");
        let left: f64 = message["4 spp, error 0.0500, ".len()..message.len() - " s left".len()]
            .parse()
            .unwrap();
        assert!((59.0..=60.0).contains(&left), "{message}");

        let unlimited = TerminalProgress::new(None);
        unlimited.begin(Some(100));
        unlimited.pass_done(1, 0.5);
        assert_eq!(unlimited.bar.message(), "1 spp, error 0.5000");
    }
}
