//! Many runs, one table (feature `tables`): `analyze summary` over a folder or a glob of
//! hundreds of recordings.
//!
//! 1. [`read_rows`] reads the recordings in parallel (rayon), each one through the generic
//!    reader decoding only the topics the metrics need ([`crate::metrics::METRIC_TOPICS`]),
//!    into a [`SummaryRow`]: the run's [`RunMetrics`], chosen scene parameters (dot paths into
//!    the scene JSON stored in the file, e.g. `controller.kp`), the integrator, the file size.
//! 2. [`summary_frame`] makes one polars DataFrame of them, one row per recording, every
//!    column in SI units with the unit as a suffix (`_m`, `_j`, `_a`, `_n`, `_s`).
//! 3. [`Query`] (filters, sort, columns, limit) runs on it as a polars `LazyFrame`, so the
//!    filters and the projection are optimised together before anything is materialised.

use std::path::{Path, PathBuf};

use polars::prelude::*;
use rayon::prelude::*;
use schemas::Recording;

pub use crate::filter::{Filter, Op};
use crate::metrics::{run_metrics, RunMetrics, METRIC_TOPICS};
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

/// One recording -> its row.
pub fn read_row(path: &Path, params: &[String]) -> Result<SummaryRow, Error> {
    let bytes = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    let rec = schemas::read_recording_topics(path, Some(&METRIC_TOPICS))?;
    row(&rec, bytes, params)
}

/// The row of a decoded recording of `bytes` bytes.
pub fn row(rec: &Recording, bytes: u64, params: &[String]) -> Result<SummaryRow, Error> {
    let metrics = run_metrics(rec)?;
    let scene: Option<serde_json::Value> = rec
        .metadata_value("scene", "json")
        .and_then(|s| serde_json::from_str(s).ok());
    let params = params
        .iter()
        .map(|p| scene.as_ref().and_then(|s| lookup(s, p)).cloned())
        .collect();
    Ok(SummaryRow {
        metrics,
        bytes,
        integrator: rec.metadata_value("run", "integrator").map(String::from),
        params,
    })
}

/// Follows a dot path (`controller.kp`, `motors.0.R`) into a JSON document.
fn lookup<'a>(doc: &'a serde_json::Value, path: &str) -> Option<&'a serde_json::Value> {
    path.split('.').try_fold(doc, |v, seg| match v {
        serde_json::Value::Object(m) => m.get(seg),
        serde_json::Value::Array(a) => a.get(seg.parse::<usize>().ok()?),
        _ => None,
    })
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
    "hand_rms_m",
    "hand_max_m",
    "z_rms_m",
    "z_max_m",
    "E_j",
    "W_j",
    "peak_current_a",
    "peak_current_joint",
    "min_normal_force_n",
    "pull_time_s",
    "residual_rel",
];

/// The columns a text table shows when none are chosen.
pub const DEFAULT_TABLE_COLUMNS: [&str; 10] = [
    "file",
    "run",
    "status",
    "hand_rms_m",
    "z_rms_m",
    "E_j",
    "W_j",
    "peak_current_a",
    "min_normal_force_n",
    "pull_time_s",
];

/// One DataFrame, one row per entry of `rows`: [`BASE_COLUMNS`] (`min_normal_force_n`: the lowest
/// over the contacts, `pull_time_s`: the longest; both null without contacts), then `error`, `bytes`,
/// `E.<joint>_j` and `W.<joint>_j` for every joint of any run (null where a run has no such
/// joint), then `p.<param>` for each of `params` (Float64 when every value is a number, else
/// text).
pub fn summary_frame(rows: &[SummaryRow], params: &[String]) -> PolarsResult<DataFrame> {
    let n = rows.len();
    let m = |f: &dyn Fn(&RunMetrics) -> f64| -> Vec<f64> { rows.iter().map(|r| f(&r.metrics)).collect() };
    let s = |f: &dyn Fn(&SummaryRow) -> Option<String>| -> Vec<Option<String>> { rows.iter().map(f).collect() };
    let min_force = |r: &RunMetrics| -> Option<f64> {
        r.contact_forces.iter().map(|c| c.min_normal_force_n).reduce(f64::min)
    };
    let mut cols = vec![
        Column::new("file".into(), s(&|r| Some(r.metrics.file.clone()))),
        Column::new("scene".into(), s(&|r| Some(r.metrics.scene.clone()))),
        Column::new("run".into(), s(&|r| Some(r.metrics.run.clone()))),
        Column::new("status".into(), s(&|r| Some(crate::render::status(r.metrics.status).to_string()))),
        Column::new("contacts".into(), s(&|r| Some(r.metrics.contacts.join(",")))),
        Column::new("n_contacts".into(), rows.iter().map(|r| r.metrics.contacts.len() as u32).collect::<Vec<_>>()),
        Column::new("integrator".into(), s(&|r| r.integrator.clone())),
        Column::new("t_end_s".into(), m(&|r| r.t_end_s)),
        Column::new("samples".into(), rows.iter().map(|r| r.metrics.samples as u64).collect::<Vec<_>>()),
        Column::new("hand_rms_m".into(), m(&|r| r.hand_error.norm.rms_m)),
        Column::new("hand_max_m".into(), m(&|r| r.hand_error.norm.max_abs_m)),
        Column::new("z_rms_m".into(), m(&|r| r.hand_error.z.rms_m)),
        Column::new("z_max_m".into(), m(&|r| r.hand_error.z.max_abs_m)),
        Column::new("E_j".into(), m(&|r| r.electric_energy_total_j)),
        Column::new("W_j".into(), m(&|r| r.link_work_total_j)),
        Column::new(
            "peak_current_a".into(),
            rows.iter().map(|r| r.metrics.peak_current.as_ref().map(|p| p.current_a)).collect::<Vec<_>>(),
        ),
        Column::new("peak_current_joint".into(), s(&|r| r.metrics.peak_current.as_ref().map(|p| p.joint.clone()))),
        Column::new("min_normal_force_n".into(), rows.iter().map(|r| min_force(&r.metrics)).collect::<Vec<_>>()),
        Column::new(
            "pull_time_s".into(),
            rows.iter()
                .map(|r| r.metrics.contact_forces.iter().map(|c| c.pull_time_s).reduce(f64::max))
                .collect::<Vec<_>>(),
        ),
        Column::new(
            "residual_rel".into(),
            rows.iter().map(|r| r.metrics.energy.max_abs_residual_rel).collect::<Vec<_>>(),
        ),
        Column::new("error".into(), s(&|r| r.metrics.error.clone())),
        Column::new("bytes".into(), rows.iter().map(|r| r.bytes).collect::<Vec<_>>()),
    ];
    // per-link columns over the union of joints, in first-seen order
    let mut joints: Vec<&str> = Vec::new();
    for r in rows {
        for l in &r.metrics.links {
            if !joints.contains(&l.joint.as_str()) {
                joints.push(&l.joint);
            }
        }
    }
    let link = |joint: &str, f: fn(&crate::metrics::LinkMetrics) -> f64| -> Vec<Option<f64>> {
        rows.iter()
            .map(|r| r.metrics.links.iter().find(|l| l.joint == joint).map(f))
            .collect()
    };
    for j in &joints {
        cols.push(Column::new(format!("E.{j}_j").into(), link(j, |l| l.electric_energy_j)));
    }
    for j in &joints {
        cols.push(Column::new(format!("W.{j}_j").into(), link(j, |l| l.work_j)));
    }
    for (k, p) in params.iter().enumerate() {
        let values: Vec<Option<&serde_json::Value>> = rows.iter().map(|r| r.params[k].as_ref()).collect();
        let name = format!("p.{p}");
        let numeric = values.iter().all(|v| v.is_none_or(|v| v.is_number()));
        cols.push(if numeric {
            Column::new(name.into(), values.iter().map(|v| v.and_then(|v| v.as_f64())).collect::<Vec<_>>())
        } else {
            let text = |v: &serde_json::Value| v.as_str().map_or_else(|| v.to_string(), String::from);
            Column::new(name.into(), values.iter().map(|v| v.map(text)).collect::<Vec<_>>())
        });
    }
    DataFrame::new(n, cols)
}

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

impl Query {
    /// Runs the query on `df` lazily; errors name the unknown column or the value that does
    /// not parse as a number for a numeric column.
    pub fn run(&self, df: DataFrame) -> Result<DataFrame, String> {
        let schema = df.schema().clone();
        let known = |c: &str| -> Result<DataType, String> {
            schema.get(c).cloned().ok_or_else(|| {
                let names: Vec<&str> = schema.iter_names().map(|n| n.as_str()).collect();
                format!("no column {c:?}; the columns are: {}", names.join(", "))
            })
        };
        let mut lf = df.lazy();
        for f in &self.filters {
            let dtype = known(&f.column)?;
            let value = if dtype.is_primitive_numeric() {
                let x: f64 = f.value.parse().map_err(|_| {
                    format!("filter {:?}: {:?} is not a number (the column is numeric)", f.column, f.value)
                })?;
                lit(x)
            } else {
                lit(f.value.clone())
            };
            let c = col(f.column.as_str());
            lf = lf.filter(match f.op {
                Op::Eq => c.eq(value),
                Op::Ne => c.neq(value),
                Op::Lt => c.lt(value),
                Op::Le => c.lt_eq(value),
                Op::Gt => c.gt(value),
                Op::Ge => c.gt_eq(value),
            });
        }
        if !self.sort.is_empty() {
            for s in &self.sort {
                known(s)?;
            }
            let by: Vec<PlSmallStr> = self.sort.iter().map(|s| s.as_str().into()).collect();
            let opts = SortMultipleOptions::default()
                .with_order_descending(self.descending)
                .with_nulls_last(true)
                .with_maintain_order(true);
            lf = lf.sort(by, opts);
        }
        if !self.columns.is_empty() {
            for c in &self.columns {
                known(c)?;
            }
            lf = lf.select(self.columns.iter().map(|c| col(c.as_str())).collect::<Vec<_>>());
        }
        if let Some(n) = self.limit {
            lf = lf.limit(n as IdxSize);
        }
        lf.collect().map_err(|e| e.to_string())
    }
}
mod render;
pub use render::render_frame;
