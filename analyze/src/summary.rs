//! Many runs, one table (feature `tables`): `analyze summary` over a folder or a glob of
//! hundreds of recordings.
//!
//! 1. [`read_rows`] reads the recordings in parallel (rayon), each one through the generic
//!    reader decoding only the topics the metrics need ([`crate::metrics::METRIC_TOPICS`]),
//!    into a [`SummaryRow`]: the run's [`RunMetrics`], chosen scene parameters (dot paths into
//!    the scene JSON stored in the file, e.g. `controller.kp`), the integrator, the file size.
//! 2. `summary_frame` (feature `tables`) makes one polars DataFrame of them, one row per recording, every
//!    column in SI units with the unit as a suffix (`_m`, `_j`, `_a`, `_n`, `_s`).
//! 3. [`Query`] (filters, sort, columns, limit) runs on it with polars' eager API (polars is
//!    built without its `lazy` feature, which would bring an HTTP/TLS stack into an offline tool).

use std::path::{Path, PathBuf};

use rayon::prelude::*;
use schemas::Recording;

pub use crate::filter::{Filter, Op};
use crate::Format;
use crate::metrics::{run_metrics, RunMetrics};
use crate::Error;

/// One recording's entry in the summary.
#[derive(Debug, Clone)]
pub struct SummaryRow {
    pub metrics: RunMetrics,
    /// Bytes of the file.
    pub bytes: u64,
    /// Metadata `run.integrator` (method name), if present.
    pub integrator: Option<String>,
    /// The requested scene parameters, in the order asked (`None`: not in this scene).
    pub params: Vec<Option<serde_json::Value>>,
}

/// Reads `paths` on `threads` worker threads (0: one per core); `progress` is called once per
/// file read, from the workers. Results are in the order of `paths`.
pub fn read_rows(
    paths: &[PathBuf],
    params: &[String],
    threads: usize,
    progress: &(dyn Fn() + Sync),
) -> Vec<Result<SummaryRow, Error>> {
    let work = || {
        paths
            .par_iter()
            .map(|p| {
                let row = read_row(p, params);
                progress();
                row
            })
            .collect()
    };
    match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
        Ok(pool) => pool.install(work),
        Err(_) => work(), // the global pool
    }
}

/// One recording -> its row, streamed ([`crate::stream_run_metrics`]: memory does not grow
/// with the recording).
pub fn read_row(path: &Path, params: &[String]) -> Result<SummaryRow, Error> {
    let bytes = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    let (metrics, rec) = crate::metrics::stream_run_metrics(path)?;
    row_of(metrics, &rec, bytes, params)
}

/// The row of a decoded recording of `bytes` bytes.
pub fn row(rec: &Recording, bytes: u64, params: &[String]) -> Result<SummaryRow, Error> {
    row_of(run_metrics(rec)?, rec, bytes, params)
}

/// The row of a recording's metrics; `rec` gives its metadata (scene, setup).
fn row_of(metrics: RunMetrics, rec: &Recording, bytes: u64, params: &[String]) -> Result<SummaryRow, Error> {
    let scene: Option<serde_json::Value> = rec.scene().ok().and_then(|s| serde_json::from_str(&s.json).ok());
    let params = params.iter().map(|p| scene.as_ref().and_then(|s| s.pointer(&json_pointer(p))).cloned()).collect();
    Ok(SummaryRow {
        metrics,
        bytes,
        integrator: rec.run().ok().and_then(|r| r.setup).map(|s| s.integrator.method),
        params,
    })
}

/// A note when the rows cover different intervals (their `t_end_s` differ, or a run has none):
/// totals and RMS are each over the run's own interval, so ranking them by a column compares
/// unlike things. `None` when every run ends at the same time.
pub fn duration_note(rows: &[SummaryRow]) -> Option<String> {
    let ends: Vec<f64> = rows.iter().filter_map(|r| r.metrics.t_end_s).collect();
    let (lo, hi) = ends.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &t| (lo.min(t), hi.max(t)));
    let without = rows.iter().filter(|r| r.metrics.t_end_s.is_none()).count();
    let differ = !ends.is_empty() && hi - lo > crate::compare::SAME_END * hi.abs().max(1.0);
    if !differ && without == 0 {
        return None;
    }
    let mut parts = Vec::new();
    if differ {
        let short: Vec<String> = rows
            .iter()
            .filter(|r| r.metrics.t_end_s.is_some_and(|t| hi - t > crate::compare::SAME_END * hi.abs().max(1.0)))
            .map(|r| format!("{} ({}, t_end {} s)", r.metrics.run, r.metrics.status_text(), crate::render::short_num(r.metrics.t_end_s.unwrap_or_default())))
            .collect();
        parts.push(format!(
            "the runs end at different times ({} to {} s; shorter: {}): each total and RMS is over its run's own interval, so rows with different t_end_s are not comparable and a sort by them does not rank like with like",
            crate::render::short_num(lo),
            crate::render::short_num(hi),
            short.join(", ")
        ));
    }
    if without > 0 {
        parts.push(format!("{without} run(s) failed before their first sample and have no numbers (empty cells)"));
    }
    Some(format!("Note: {}.", parts.join("; ")))
}

/// A dot path (`controller.kp`, `contacts.0.plane.offset`) or a JSON pointer (`/controller/kp`,
/// RFC 6901) as a JSON pointer.
pub fn json_pointer(path: &str) -> String {
    if path.starts_with('/') || path.is_empty() {
        return path.to_string();
    }
    path.split('.').map(|seg| format!("/{}", seg.replace('~', "~0").replace('/', "~1"))).collect()
}

/// The columns every summary has, in order (per-link and parameter columns follow).
pub const BASE_COLUMNS: [&str; 20] = [
    "file",
    "scene",
    "run",
    "status",
    "contacts",
    "n_contacts",
    "integrator",
    "t_end_s",
    "samples",
    "err_norm_rms_m",
    "err_norm_max_m",
    "err_z_rms_m",
    "err_z_max_m",
    "E_total_j",
    "W_total_j",
    "peak_current_a",
    "peak_current_joint",
    "fn_min_n",
    "pull_max_s",
    "residual_max_rel",
];

/// The columns a text table shows when none are chosen.
pub const DEFAULT_TABLE_COLUMNS: [&str; 10] = [
    "file",
    "run",
    "status",
    "err_norm_rms_m",
    "err_z_rms_m",
    "E_total_j",
    "W_total_j",
    "peak_current_a",
    "fn_min_n",
    "pull_max_s",
];

/// What to show of the summary.
#[derive(Debug, Clone, Default)]
pub struct Query {
    /// All must hold.
    pub filters: Vec<Filter>,
    /// Sort keys, in order; ties keep the input (file) order.
    pub sort: Vec<String>,
    pub descending: bool,
    /// Columns to keep, in this order (empty: all).
    pub columns: Vec<String>,
    pub limit: Option<usize>,
}

#[cfg(feature = "tables")]
mod frame;
#[cfg(feature = "tables")]
mod render;
#[cfg(feature = "tables")]
pub use frame::summary_frame;
#[cfg(feature = "tables")]
pub use render::render_frame;
#[cfg(test)]
mod tests;

/// The summary of `rows` as `format` text: the table of [`summary_frame`] with `params` columns,
/// `query` applied. Needs the feature `tables` (polars); without it, an error that says so.
pub fn render(rows: &[SummaryRow], params: &[String], query: &Query, format: Format) -> Result<String, Error> {
    #[cfg(feature = "tables")]
    {
        let table = Error::Summary;
        let df = summary_frame(rows, params).map_err(|e| table(e.to_string()))?;
        let mut out = query.run(df).map_err(table)?;
        render_frame(&mut out, format).map_err(|e| table(e.to_string()))
    }
    #[cfg(not(feature = "tables"))]
    {
        let _ = (rows, params, query, format);
        Err(Error::TablesUnavailable)
    }
}
