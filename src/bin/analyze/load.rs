//! Recordings to metrics, for `compare` and `metrics`: every input in order, the first unreadable
//! file stops with an error naming it; with `--recover`, damaged files give the metrics of their
//! intact part, a warning on stderr, and exit status 1 (numbers from a damaged file are never
//! reported as a plain success). Both read streamed: memory does not grow with the recordings.

use std::path::PathBuf;

use analyze::{read_run_metrics, read_run_metrics_recover, RunMetrics};
use anyhow::{Context, Result};
use cli::Verbosity;

/// The metrics of every input, and whether any of them was recovered from a damaged file.
pub fn metrics(inputs: &[PathBuf], recover: bool, v: Verbosity) -> Result<(Vec<RunMetrics>, bool)> {
    let mut damaged = false;
    let runs = cli::inputs::expand(inputs)?
        .iter()
        .map(|p| {
            let context = || format!("analyzing {}", p.display());
            if v.verbose > 0 {
                eprintln!("analyze: reading {}", p.display());
            }
            if !recover {
                return read_run_metrics(p).with_context(context);
            }
            let (m, report) = read_run_metrics_recover(p).with_context(context)?;
            if !report.complete {
                eprintln!("analyze: warning: {report}");
                damaged = true;
            }
            Ok(m)
        })
        .collect::<Result<Vec<_>>>()?;
    Ok((runs, damaged))
}
