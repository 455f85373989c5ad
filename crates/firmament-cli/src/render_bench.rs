//! Frame timings for `firmament bench` (filled in with the renderer).

use anyhow::Result;

use crate::bench::BenchArgs;

/// Add render timings to the benchmark result.
pub fn extend(_result: &mut serde_json::Value, _args: &BenchArgs) -> Result<()> {
    Ok(())
}
