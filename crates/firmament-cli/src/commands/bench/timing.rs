//! Wall-clock timing of repeated runs and their median.

use std::time::Instant;

use anyhow::Result;

use crate::common::median_of_sorted;

/// Median of a sample of seconds.
pub fn median(mut seconds: Vec<f64>) -> f64 {
    seconds.sort_by(f64::total_cmp);
    median_of_sorted(&seconds)
}

/// Run `f` `runs` times (at least once); the seconds of each.
pub fn time_runs(runs: usize, mut f: impl FnMut() -> Result<()>) -> Result<Vec<f64>> {
    let mut seconds = Vec::with_capacity(runs);
    for _ in 0..runs.max(1) {
        let started = Instant::now();
        f()?;
        seconds.push(started.elapsed().as_secs_f64());
    }
    Ok(seconds)
}
