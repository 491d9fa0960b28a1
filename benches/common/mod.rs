//! What the benchmarks share: Criterion's timing.

use std::time::Duration;

use criterion::Criterion;

/// One second of warm-up and three of measurement per benchmark, so that a whole run stays
/// short; a benchmark that needs fewer or longer samples sets them on its group.
pub fn criterion() -> Criterion {
    Criterion::default()
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3))
}
