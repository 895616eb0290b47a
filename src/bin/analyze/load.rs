//! Recordings to metrics, for `compare` and `metrics`: every input in order, the first unreadable
//! file stops with an error naming it; with `--recover`, damaged files give the metrics of their
//! intact part and a warning on stderr.

use std::path::PathBuf;

use analyze::{read_run_metrics, run_metrics_recovered, RunMetrics};
use anyhow::{Context, Result};
use cli::Verbosity;

pub fn metrics(inputs: &[PathBuf], recover: bool, v: Verbosity) -> Result<Vec<RunMetrics>> {
    cli::inputs::expand(inputs)?
        .iter()
        .map(|p| {
            let context = || format!("analyzing {}", p.display());
            if v.verbose > 0 {
                eprintln!("analyze: reading {}", p.display());
            }
            if !recover {
                return read_run_metrics(p).with_context(context);
            }
            let (rec, report) = schemas::read_recording_recover(p).with_context(context)?;
            if !report.complete {
                eprintln!("analyze: warning: {report}");
            }
            run_metrics_recovered(&rec, &report).with_context(|| {
                format!("analyzing {} (recovered {} messages from its first {} bytes)", p.display(), report.messages, report.stopped_at)
            })
        })
        .collect()
}
