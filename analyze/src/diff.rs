//! `analyze diff A B`: the per-run quantities of two inputs side by side, with absolute and
//! relative differences against tolerances.
//!
//! An input ([`read_input`]) is one of
//! - a recording (`.mcap`; recognised by the MCAP magic, whatever its name): the
//!   [`RunMetrics`] of its run ([`crate::read_run_metrics`]);
//! - a directory: every `*.mcap` directly in it;
//! - a table exported by `analyze metrics|compare --format json` (an array of [`RunMetrics`],
//!   a [`crate::Comparison`], or one [`RunMetrics`] object) or `--format csv` (one row per
//!   run, the columns of [`crate::render`]). Tables are read by key / column name, not into the
//!   current structs, so a table from another version with fields added or removed still reads;
//!   a quantity its format does not carry is reported as *not compared*.
//!
//! Runs are matched by run name (when each input holds exactly one run they are compared
//! whatever their names). Compared per run ([`KINDS`]): hand error RMS and max per axis and of
//! the norm; E and W totals; the peak motor current; the energy balance residual at the end and
//! its max |·|; per link (matched by joint name) W_j, E_j and the peak current; per contact
//! (matched by name) the minimum normal force and the time the table pulls.
//!
//! A quantity **moved** when `|B − A| > atol + rtol · max(|A|, |B|)` (numpy.isclose's formula,
//! made symmetric in A and B). Defaults: `rtol` = 1e-9, `atol` = 1e-12 ([`Tolerance`]). Two NaNs
//! are equal, a NaN and a number are not. The relative difference shown is
//! `|B − A| / max(|A|, |B|)` (0 when both are 0). A quantity one run has and the other lacks
//! (a joint or contact only on one side, no motors) is **missing**, which counts as a
//! difference; one that the other input's *format* does not carry (e.g. per-link peak currents
//! in a CSV table) is **not compared** and does not.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::render::Format;
use crate::{read_run_metrics, Error, RunMetrics};

/// What a quantity is attached to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Per {
    Run,
    /// One per joint (link), matched by joint name.
    Joint,
    /// One per contact, matched by contact name.
    Contact,
}

/// One kind of compared quantity.
#[derive(Debug, Clone, Copy)]
pub struct Kind {
    /// Stable id (JSON `quantity`): the [`RunMetrics`] JSON path, per item relative to the item.
    pub id: &'static str,
    /// Short name for people.
    pub label: &'static str,
    pub unit: &'static str,
    pub per: Per,
    /// CSV column; `{}` stands for the joint or contact name. `None`: CSV does not carry it.
    pub csv: Option<&'static str>,
}

const fn kind(
    id: &'static str,
    label: &'static str,
    unit: &'static str,
    per: Per,
    csv: Option<&'static str>,
) -> Kind {
    Kind {
        id,
        label,
        unit,
        per,
        csv,
    }
}

/// Every compared quantity, in output order.
pub const KINDS: &[Kind] = &[
    kind(
        "hand_error.x.rms_m",
        "hand error x rms",
        "m",
        Per::Run,
        Some("err_x_rms_m"),
    ),
    kind(
        "hand_error.y.rms_m",
        "hand error y rms",
        "m",
        Per::Run,
        Some("err_y_rms_m"),
    ),
    kind(
        "hand_error.z.rms_m",
        "hand error z rms",
        "m",
        Per::Run,
        Some("err_z_rms_m"),
    ),
    kind(
        "hand_error.norm.rms_m",
        "hand error |e| rms",
        "m",
        Per::Run,
        Some("err_norm_rms_m"),
    ),
    kind(
        "hand_error.x.max_abs_m",
        "hand error x max",
        "m",
        Per::Run,
        Some("err_x_max_m"),
    ),
    kind(
        "hand_error.y.max_abs_m",
        "hand error y max",
        "m",
        Per::Run,
        Some("err_y_max_m"),
    ),
    kind(
        "hand_error.z.max_abs_m",
        "hand error z max",
        "m",
        Per::Run,
        Some("err_z_max_m"),
    ),
    kind(
        "hand_error.norm.max_abs_m",
        "hand error |e| max",
        "m",
        Per::Run,
        Some("err_norm_max_m"),
    ),
    kind(
        "electric_energy_total_j",
        "E total",
        "J",
        Per::Run,
        Some("E_total_J"),
    ),
    kind(
        "link_work_total_j",
        "W total",
        "J",
        Per::Run,
        Some("W_total_J"),
    ),
    kind(
        "peak_current.current_a",
        "peak current",
        "A",
        Per::Run,
        Some("peak_current_A"),
    ),
    kind(
        "energy.residual_j",
        "energy residual",
        "J",
        Per::Run,
        Some("residual_J"),
    ),
    kind(
        "energy.max_abs_residual_j",
        "energy residual max |.|",
        "J",
        Per::Run,
        Some("residual_max_abs_J"),
    ),
    kind("work_j", "W_j", "J", Per::Joint, Some("W_{}_J")),
    kind("electric_energy_j", "E_j", "J", Per::Joint, Some("E_{}_J")),
    kind("peak_current_a", "peak current_j", "A", Per::Joint, None),
    kind(
        "min_normal_force_n",
        "min f_n",
        "N",
        Per::Contact,
        Some("fn_min_{}_N"),
    ),
    kind(
        "pull_time_s",
        "f_n < 0 for",
        "s",
        Per::Contact,
        Some("pull_{}_s"),
    ),
];

/// Tolerances: a quantity moved when `|B − A| > atol + rtol · max(|A|, |B|)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Tolerance {
    pub rtol: f64,
    pub atol: f64,
}

impl Default for Tolerance {
    /// rtol 1e-9, atol 1e-12: tight enough that any change of a model parameter shows, loose
    /// enough for the last-bit differences of another build or platform.
    fn default() -> Self {
        Self {
            rtol: 1e-9,
            atol: 1e-12,
        }
    }
}

impl Tolerance {
    /// True when `a` and `b` agree within the tolerances (two NaNs agree).
    pub fn close(&self, a: f64, b: f64) -> bool {
        a == b
            || (a.is_nan() && b.is_nan())
            || ((b - a).is_finite()
                && (b - a).abs() <= self.atol + self.rtol * a.abs().max(b.abs()))
    }
}

/// How an input was read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum InputKind {
    /// One `.mcap` file or a directory of them.
    Recording,
    /// A JSON table (`analyze metrics|compare --format json`).
    Json,
    /// A CSV table (`analyze metrics|compare --format csv`).
    Csv,
}

/// The compared values of one run.
#[derive(Debug, Clone, PartialEq)]
pub struct RunValues {
    pub run: String,
    /// The recording the run came from (as the input states it).
    pub file: String,
    /// `(index into KINDS, joint or contact name, value)`, in output order; NaN is a value.
    pub values: Vec<(usize, Option<String>, f64)>,
    /// Per entry of [`KINDS`]: whether this run's input format carries it.
    pub carried: Vec<bool>,
}

impl RunValues {
    fn get(&self, k: usize, item: &Option<String>) -> Option<f64> {
        self.values
            .iter()
            .find(|(kk, i, _)| *kk == k && i == item)
            .map(|v| v.2)
    }
}

/// One input of `analyze diff`.
#[derive(Debug, Clone, PartialEq)]
pub struct Input {
    /// The path as given.
    pub source: String,
    pub kind: InputKind,
    pub runs: Vec<RunValues>,
}

/// Errors of reading diff inputs and matching their runs; each names the input.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DiffError {
    /// A recording could not be read or its metrics not computed (boxed: it is large).
    #[error(transparent)]
    Metrics(Box<Error>),
    #[error("{file}: {source}")]
    Io {
        file: String,
        source: std::io::Error,
    },
    /// Not a recording, nor a JSON or CSV table of runs.
    #[error("{file}: {detail}")]
    BadTable { file: String, detail: String },
    #[error("{dir}: no *.mcap files in this directory")]
    EmptyDirectory { dir: String },
    #[error("{file}: run {run:?} appears more than once")]
    DuplicateRun { file: String, run: String },
    #[error("no run is in both inputs (A has {a:?}, B has {b:?})")]
    NoCommonRuns { a: Vec<String>, b: Vec<String> },
    #[error("bad tolerance: {0}")]
    BadTolerance(String),
}

impl From<Error> for DiffError {
    fn from(e: Error) -> Self {
        Self::Metrics(Box::new(e))
    }
}

/// Reads one input: a recording, a directory of recordings, or a JSON or CSV table (told
/// apart by content: MCAP magic, then a leading `[` or `{`, else CSV).
pub fn read_input(path: &Path) -> Result<Input, DiffError> {
    let source = path.display().to_string();
    let io = |e| DiffError::Io {
        file: source.clone(),
        source: e,
    };
    if path.is_dir() {
        let mut files: Vec<PathBuf> = Vec::new();
        for entry in std::fs::read_dir(path).map_err(io)? {
            let p = entry.map_err(io)?.path();
            let mcap = p
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("mcap"));
            if mcap && p.is_file() {
                files.push(p);
            }
        }
        if files.is_empty() {
            return Err(DiffError::EmptyDirectory { dir: source });
        }
        files.sort();
        let runs = files
            .iter()
            .map(|p| Ok(from_metrics(&read_run_metrics(p)?)))
            .collect::<Result<Vec<_>, DiffError>>()?;
        return checked(source, InputKind::Recording, runs);
    }
    let bytes = std::fs::read(path).map_err(io)?;
    if bytes.starts_with(b"\x89MCAP") {
        let runs = vec![from_metrics(&read_run_metrics(path)?)];
        return checked(source, InputKind::Recording, runs);
    }
    let text = String::from_utf8(bytes).map_err(|_| DiffError::BadTable {
        file: source.clone(),
        detail: "neither a recording (MCAP) nor a JSON or CSV table (not UTF-8 text)".into(),
    })?;
    let bad = |detail: String| DiffError::BadTable {
        file: source.clone(),
        detail,
    };
    match text.trim_start().chars().next() {
        Some('[' | '{') => {
            let v: Value = serde_json::from_str(&text).map_err(|e| bad(format!("JSON: {e}")))?;
            let runs = from_json(&v).map_err(bad)?;
            checked(source, InputKind::Json, runs)
        }
        Some(_) => {
            let runs = from_csv(&text).map_err(bad)?;
            checked(source, InputKind::Csv, runs)
        }
        None => Err(bad("empty file".into())),
    }
}

fn checked(source: String, kind: InputKind, runs: Vec<RunValues>) -> Result<Input, DiffError> {
    let mut seen = BTreeSet::new();
    for r in &runs {
        if !seen.insert(r.run.as_str()) {
            return Err(DiffError::DuplicateRun {
                file: source,
                run: r.run.clone(),
            });
        }
    }
    if runs.is_empty() {
        return Err(DiffError::BadTable {
            file: source,
            detail: "no runs in this table".into(),
        });
    }
    Ok(Input { source, kind, runs })
}

/// The compared values of computed metrics (every kind carried).
pub fn from_metrics(m: &RunMetrics) -> RunValues {
    // serde_json turns a non-finite number into null, which `from_json_run` reads back as NaN
    let v = serde_json::to_value(m).unwrap_or(Value::Null);
    let mut r = from_json_run(&v).unwrap_or_else(|_| RunValues {
        run: m.run.clone(),
        file: m.file.clone(),
        values: Vec::new(),
        carried: vec![true; KINDS.len()],
    });
    r.carried = vec![true; KINDS.len()];
    r
}

/// Runs of an exported JSON table: an array of runs, a comparison (`runs[].metrics`) or one run.
fn from_json(v: &Value) -> Result<Vec<RunValues>, String> {
    let runs: Vec<&Value> = match v {
        Value::Array(a) => a.iter().collect(),
        Value::Object(o) if o.contains_key("runs") => match &o["runs"] {
            Value::Array(a) => a.iter().map(|r| r.get("metrics").unwrap_or(r)).collect(),
            _ => return Err("\"runs\" is not an array".into()),
        },
        Value::Object(_) => vec![v],
        _ => return Err("expected a JSON array of runs or an object".into()),
    };
    runs.into_iter()
        .enumerate()
        .map(|(i, r)| from_json_run(r).map_err(|e| format!("run #{i}: {e}")))
        .collect()
}

/// A number, null (NaN: non-finite numbers are exported as null), or absent.
fn number(v: Option<&Value>) -> Option<f64> {
    match v? {
        Value::Null => Some(f64::NAN),
        v => v.as_f64(),
    }
}

/// Follows a dotted path; `None` when a step is absent or not an object.
fn path<'a>(v: &'a Value, p: &str) -> Option<&'a Value> {
    p.split('.').try_fold(v, |v, k| v.as_object()?.get(k))
}

fn from_json_run(v: &Value) -> Result<RunValues, String> {
    let text = |k: &str| v.get(k).and_then(Value::as_str).map(str::to_string);
    let run = text("run").ok_or("no \"run\" name")?;
    let file = text("file").unwrap_or_default();
    let mut values = Vec::new();
    let mut carried = vec![false; KINDS.len()];
    let lists = [
        (Per::Joint, "links", "joint"),
        (Per::Contact, "contact_forces", "contact"),
    ];
    for (k, kind) in KINDS.iter().enumerate() {
        if kind.per == Per::Run {
            let first = kind.id.split('.').next().unwrap_or(kind.id);
            carried[k] = v.get(first).is_some();
            // null at the leaf is NaN; a null object (no motors: peak_current) is absent
            let parent = kind.id.rsplit_once('.').map(|(p, _)| p);
            let leaf_ok = parent.is_none_or(|p| path(v, p).is_some_and(Value::is_object));
            if leaf_ok {
                if let Some(x) = number(path(v, kind.id)) {
                    values.push((k, None, x));
                }
            }
        }
    }
    for (per, list, name_key) in lists {
        let items: &[Value] = v.get(list).and_then(Value::as_array).map_or(&[], |a| a);
        for (k, kind) in KINDS.iter().enumerate().filter(|(_, k)| k.per == per) {
            carried[k] = v.get(list).is_some()
                && (items.is_empty() || items.iter().any(|i| i.get(kind.id).is_some()));
        }
        for item in items {
            let name = item
                .get(name_key)
                .and_then(Value::as_str)
                .ok_or_else(|| format!("an entry of {list:?} has no {name_key:?}"))?;
            for (k, kind) in KINDS.iter().enumerate().filter(|(_, k)| k.per == per) {
                if let Some(x) = number(item.get(kind.id)) {
                    values.push((k, Some(name.to_string()), x));
                }
            }
        }
    }
    values.sort_by_key(|v| v.0); // KINDS order; items keep their order within a kind
    Ok(RunValues {
        run,
        file,
        values,
        carried,
    })
}

/// Splits CSV text (RFC 4180: quoted fields, `""` for a quote, line breaks inside quotes).
fn csv_rows(text: &str) -> Result<Vec<Vec<String>>, String> {
    let mut rows = Vec::new();
    let (mut row, mut cell) = (Vec::new(), String::new());
    let (mut quoted, mut any) = (false, false);
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        any = true;
        match (quoted, c) {
            (true, '"') if chars.peek() == Some(&'"') => {
                chars.next();
                cell.push('"');
            }
            (true, '"') => quoted = false,
            (true, c) => cell.push(c),
            (false, '"') if cell.is_empty() => quoted = true,
            (false, ',') => row.push(std::mem::take(&mut cell)),
            (false, '\r') if chars.peek() == Some(&'\n') => {}
            (false, '\n') => {
                row.push(std::mem::take(&mut cell));
                rows.push(std::mem::take(&mut row));
                any = false;
            }
            (false, c) => cell.push(c),
        }
    }
    if quoted {
        return Err("CSV: a quoted field is not closed".into());
    }
    if any {
        row.push(cell);
        rows.push(row);
    }
    Ok(rows)
}

fn from_csv(text: &str) -> Result<Vec<RunValues>, String> {
    let rows = csv_rows(text)?;
    let Some((head, body)) = rows.split_first() else {
        return Err("empty CSV".into());
    };
    let run_col = head
        .iter()
        .position(|h| h == "run")
        .ok_or("neither a recording, JSON, nor a CSV table with a \"run\" column")?;
    let file_col = head.iter().position(|h| h == "file");
    // column -> (kind, item); exact run-level names first (E_total_J is not E_{joint}_J)
    let mut cols: Vec<(usize, usize, Option<String>)> = Vec::new();
    let mut carried = vec![false; KINDS.len()];
    for (c, h) in head.iter().enumerate() {
        let exact = KINDS
            .iter()
            .position(|k| k.per == Per::Run && k.csv == Some(h.as_str()));
        if let Some(k) = exact {
            cols.push((c, k, None));
            carried[k] = true;
            continue;
        }
        for (k, kind) in KINDS.iter().enumerate().filter(|(_, k)| k.per != Per::Run) {
            let Some((pre, post)) = kind.csv.and_then(|p| p.split_once("{}")) else {
                continue;
            };
            let item = h
                .strip_prefix(pre)
                .and_then(|r| r.strip_suffix(post))
                .filter(|i| !i.is_empty());
            if let Some(item) = item {
                cols.push((c, k, Some(item.to_string())));
                break;
            }
        }
    }
    for (k, kind) in KINDS.iter().enumerate() {
        if kind.per != Per::Run {
            carried[k] = kind.csv.is_some();
        }
    }
    let mut runs = Vec::new();
    for (i, row) in body.iter().enumerate() {
        if row.len() == 1 && row[0].is_empty() {
            continue; // a blank line
        }
        if row.len() != head.len() {
            return Err(format!(
                "CSV row {} has {} cells, the header {}",
                i + 2,
                row.len(),
                head.len()
            ));
        }
        let mut values = Vec::new();
        for (c, k, item) in &cols {
            let cell = row[*c].trim();
            if cell.is_empty() {
                continue;
            }
            let x: f64 = cell.parse().map_err(|_| {
                format!(
                    "CSV row {}, column {}: {cell:?} is not a number",
                    i + 2,
                    head[*c]
                )
            })?;
            values.push((*k, item.clone(), x));
        }
        values.sort_by_key(|v| v.0);
        runs.push(RunValues {
            run: row[run_col].clone(),
            file: file_col.map(|c| row[c].clone()).unwrap_or_default(),
            values,
            carried: carried.clone(),
        });
    }
    Ok(runs)
}

/// How a quantity compares.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DiffStatus {
    /// Within the tolerances.
    Same,
    /// Beyond the tolerances.
    Moved,
    /// B has it, A's run lacks it (A's format carries it).
    MissingInA,
    /// A has it, B's run lacks it.
    MissingInB,
    /// Only one input's format carries this quantity.
    NotCompared,
}

impl DiffStatus {
    /// A difference that makes `analyze diff` exit non-zero.
    pub fn differs(self) -> bool {
        matches!(self, Self::Moved | Self::MissingInA | Self::MissingInB)
    }

    pub fn as_str(self) -> &'static str {
        match self {
            Self::Same => "same",
            Self::Moved => "moved",
            Self::MissingInA => "missing in A",
            Self::MissingInB => "missing in B",
            Self::NotCompared => "not compared",
        }
    }
}

/// One compared quantity of one run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct QuantityDiff {
    /// Run name (A's, when the two single runs have different names).
    pub run: String,
    /// [`Kind::id`].
    pub quantity: String,
    /// [`Kind::label`].
    pub label: String,
    pub unit: String,
    /// The joint, for per-link quantities.
    pub joint: Option<String>,
    /// The contact, for per-contact quantities.
    pub contact: Option<String>,
    pub a: Option<f64>,
    pub b: Option<f64>,
    /// `b - a`.
    pub diff: Option<f64>,
    /// `|b - a|`.
    pub abs_diff: Option<f64>,
    /// `|b - a| / max(|a|, |b|)`, 0 when both are 0.
    pub rel_diff: Option<f64>,
    pub status: DiffStatus,
}

/// A matched pair of runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunPair {
    pub run_a: String,
    pub run_b: String,
    pub file_a: String,
    pub file_b: String,
}

/// The result of comparing two inputs. JSON keys are the field names.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Diff {
    pub a: String,
    pub b: String,
    pub a_kind: InputKind,
    pub b_kind: InputKind,
    pub rtol: f64,
    pub atol: f64,
    pub runs: Vec<RunPair>,
    /// Runs of A with no match in B (a difference).
    pub only_in_a: Vec<String>,
    /// Runs of B with no match in A (a difference).
    pub only_in_b: Vec<String>,
    /// Every quantity of every matched run.
    pub quantities: Vec<QuantityDiff>,
    pub moved: usize,
    pub missing: usize,
    pub same: usize,
    pub not_compared: usize,
}

impl Diff {
    /// True when something moved beyond the tolerances or is missing on one side.
    pub fn differs(&self) -> bool {
        self.moved + self.missing + self.only_in_a.len() + self.only_in_b.len() > 0
    }
}

/// Compares the runs of `a` and `b` (see the module docs).
pub fn diff(a: &Input, b: &Input, tol: Tolerance) -> Result<Diff, DiffError> {
    for (name, x) in [("rtol", tol.rtol), ("atol", tol.atol)] {
        if !(x >= 0.0 && x.is_finite()) {
            return Err(DiffError::BadTolerance(format!(
                "{name} = {x}, expected a finite number >= 0"
            )));
        }
    }
    let names = |i: &Input| i.runs.iter().map(|r| r.run.clone()).collect::<Vec<_>>();
    let pairs: Vec<(&RunValues, &RunValues)> = if a.runs.len() == 1 && b.runs.len() == 1 {
        vec![(&a.runs[0], &b.runs[0])]
    } else {
        a.runs
            .iter()
            .filter_map(|ra| b.runs.iter().find(|rb| rb.run == ra.run).map(|rb| (ra, rb)))
            .collect()
    };
    if pairs.is_empty() {
        return Err(DiffError::NoCommonRuns {
            a: names(a),
            b: names(b),
        });
    }
    let unmatched = |x: &Input, side_a: bool| -> Vec<String> {
        x.runs
            .iter()
            .filter(|r| {
                !pairs
                    .iter()
                    .any(|(pa, pb)| std::ptr::eq(if side_a { *pa } else { *pb }, *r))
            })
            .map(|r| r.run.clone())
            .collect()
    };
    let mut out = Diff {
        a: a.source.clone(),
        b: b.source.clone(),
        a_kind: a.kind,
        b_kind: b.kind,
        rtol: tol.rtol,
        atol: tol.atol,
        runs: Vec::new(),
        only_in_a: unmatched(a, true),
        only_in_b: unmatched(b, false),
        quantities: Vec::new(),
        moved: 0,
        missing: 0,
        same: 0,
        not_compared: 0,
    };
    for (ra, rb) in pairs {
        out.runs.push(RunPair {
            run_a: ra.run.clone(),
            run_b: rb.run.clone(),
            file_a: ra.file.clone(),
            file_b: rb.file.clone(),
        });
        // A's quantities in order, then B's extra ones, kept in KINDS order
        let mut keys: Vec<(usize, Option<String>)> =
            ra.values.iter().map(|(k, i, _)| (*k, i.clone())).collect();
        for (k, i, _) in &rb.values {
            if !keys.iter().any(|(kk, ii)| kk == k && ii == i) {
                let at = keys
                    .iter()
                    .rposition(|(kk, _)| kk <= k)
                    .map_or(0, |p| p + 1);
                keys.insert(at, (*k, i.clone()));
            }
        }
        for (k, item) in keys {
            let (va, vb) = (ra.get(k, &item), rb.get(k, &item));
            let kind = &KINDS[k];
            let status = match (va, vb) {
                (Some(x), Some(y)) if tol.close(x, y) => DiffStatus::Same,
                (Some(_), Some(_)) => DiffStatus::Moved,
                _ if !(ra.carried[k] && rb.carried[k]) => DiffStatus::NotCompared,
                (None, _) => DiffStatus::MissingInA,
                (_, None) => DiffStatus::MissingInB,
            };
            match status {
                DiffStatus::Same => out.same += 1,
                DiffStatus::Moved => out.moved += 1,
                DiffStatus::MissingInA | DiffStatus::MissingInB => out.missing += 1,
                DiffStatus::NotCompared => out.not_compared += 1,
            }
            let d = va.zip(vb).map(|(x, y)| y - x);
            let scale = va.zip(vb).map(|(x, y)| x.abs().max(y.abs()));
            let rel = d
                .zip(scale)
                .map(|(d, s)| if s == 0.0 { 0.0 } else { d.abs() / s });
            out.quantities.push(QuantityDiff {
                run: ra.run.clone(),
                quantity: kind.id.to_string(),
                label: kind.label.to_string(),
                unit: kind.unit.to_string(),
                joint: item.clone().filter(|_| kind.per == Per::Joint),
                contact: item.filter(|_| kind.per == Per::Contact),
                a: va,
                b: vb,
                diff: d,
                abs_diff: d.map(f64::abs),
                rel_diff: rel,
                status,
            });
        }
    }
    Ok(out)
}

/// Renders a diff. Table: the differences (moved, missing) first, or every quantity with
/// `all`, then the counts and a final line `N quantities moved beyond rtol …, atol …` or
/// `no differences beyond rtol …, atol …`. JSON: the whole [`Diff`]. CSV: one row per
/// quantity (every one).
pub fn render_diff(d: &Diff, format: Format, all: bool) -> Result<String, Error> {
    let num = |x: Option<f64>, p: usize| x.map_or("-".to_string(), |x| format!("{x:.p$e}"));
    Ok(match format {
        Format::Json => serde_json::to_string_pretty(d)? + "\n",
        Format::Csv => {
            let mut out =
                String::from("run,quantity,joint,contact,unit,a,b,diff,abs_diff,rel_diff,status\n");
            let cell = |x: Option<f64>| x.map_or(String::new(), |x| x.to_string());
            let quote = |s: &str| {
                if s.contains([',', '"', '\n', '\r']) {
                    format!("\"{}\"", s.replace('"', "\"\""))
                } else {
                    s.to_string()
                }
            };
            for q in &d.quantities {
                let cells = [
                    quote(&q.run),
                    q.quantity.clone(),
                    quote(q.joint.as_deref().unwrap_or("")),
                    quote(q.contact.as_deref().unwrap_or("")),
                    q.unit.clone(),
                    cell(q.a),
                    cell(q.b),
                    cell(q.diff),
                    cell(q.abs_diff),
                    cell(q.rel_diff),
                    q.status.as_str().replace(' ', "_"),
                ];
                out += &(cells.join(",") + "\n");
            }
            out
        }
        Format::Table => {
            let mut out = format!("A: {} ({:?})\nB: {} ({:?})\n", d.a, d.a_kind, d.b, d.b_kind)
                .replace("(Recording)", "(recording)")
                .replace("(Json)", "(JSON table)")
                .replace("(Csv)", "(CSV table)");
            for p in d.runs.iter().filter(|p| p.run_a != p.run_b) {
                out += &format!(
                    "run {:?} of A compared with run {:?} of B (the only run of each)\n",
                    p.run_a, p.run_b
                );
            }
            for (side, runs) in [("A", &d.only_in_a), ("B", &d.only_in_b)] {
                if !runs.is_empty() {
                    out += &format!("runs only in {side}: {}\n", runs.join(", "));
                }
            }
            out.push('\n');
            let shown: Vec<&QuantityDiff> = d
                .quantities
                .iter()
                .filter(|q| all || q.status.differs())
                .collect();
            if !shown.is_empty() {
                let head = [
                    "run",
                    "quantity",
                    "link/contact",
                    "A",
                    "B",
                    "B - A",
                    "rel",
                    "status",
                ];
                let rows: Vec<[String; 8]> = shown
                    .iter()
                    .map(|q| {
                        [
                            q.run.clone(),
                            format!("{} [{}]", q.label, q.unit),
                            q.joint.clone().or(q.contact.clone()).unwrap_or_default(),
                            num(q.a, 9),
                            num(q.b, 9),
                            num(q.diff, 3),
                            num(q.rel_diff, 2),
                            q.status.as_str().to_string(),
                        ]
                    })
                    .collect();
                let mut w: Vec<usize> = head.iter().map(|h| h.chars().count()).collect();
                for r in &rows {
                    for (c, s) in r.iter().enumerate() {
                        w[c] = w[c].max(s.chars().count());
                    }
                }
                let line = |cells: &[String]| {
                    let parts: Vec<String> = cells
                        .iter()
                        .enumerate()
                        .map(|(c, s)| {
                            let pad = " ".repeat(w[c] - s.chars().count());
                            if c < 3 || c == 7 {
                                format!("{s}{pad}")
                            } else {
                                format!("{pad}{s}")
                            }
                        })
                        .collect();
                    parts.join("  ").trim_end().to_string() + "\n"
                };
                out += &line(&head.map(String::from));
                out += &line(&w.iter().map(|&n| "-".repeat(n)).collect::<Vec<_>>());
                for r in &rows {
                    out += &line(r);
                }
                out.push('\n');
            }
            if !all && d.same > 0 {
                out += &format!(
                    "{} quantities within the tolerances (--all shows them)\n",
                    d.same
                );
            }
            if d.not_compared > 0 {
                out += &format!(
                    "{} quantities not compared (only one input's format carries them)\n",
                    d.not_compared
                );
            }
            let tol = format!("rtol {:e}, atol {:e}", d.rtol, d.atol);
            if d.differs() {
                let mut what = vec![format!("{} quantities moved beyond {tol}", d.moved)];
                if d.missing > 0 {
                    what.push(format!("{} missing on one side", d.missing));
                }
                let runs = d.only_in_a.len() + d.only_in_b.len();
                if runs > 0 {
                    what.push(format!("{runs} runs in one input only"));
                }
                out += &what.join("; ");
                out.push('\n');
            } else {
                out += &format!("no differences beyond {tol}\n");
            }
            out
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tolerance_is_symmetric_and_nan_aware() {
        let t = Tolerance::default();
        assert!(t.close(1.0, 1.0 + 5e-10) && t.close(1.0 + 5e-10, 1.0));
        assert!(!t.close(1.0, 1.01) && !t.close(0.0, 1e-11));
        assert!(t.close(f64::NAN, f64::NAN) && !t.close(f64::NAN, 1.0));
        assert!(t.close(f64::INFINITY, f64::INFINITY) && !t.close(f64::INFINITY, 1.0));
    }

    #[test]
    fn csv_rows_follow_rfc_4180() {
        let rows = csv_rows("a,\"b,\"\"c\"\"\",d\r\n\"x\ny\",,z\n").unwrap();
        assert_eq!(rows, [vec!["a", "b,\"c\"", "d"], vec!["x\ny", "", "z"]]);
        assert!(csv_rows("\"open").is_err());
    }

    #[test]
    fn csv_columns_map_to_quantities() {
        let text = "run,file,E_total_J,W_total_J,W_j1_J,E_j1_J,E_j1_ratio,fn_min_elbow_4_N,\
                    first_pull_elbow_4_s,pull_elbow_4_s\nr,f.mcap,3,2,1,NaN,,-1,,0.5\n";
        let runs = from_csv(text).unwrap();
        let got: Vec<(&str, Option<&str>, f64)> = runs[0]
            .values
            .iter()
            .map(|(k, i, x)| (KINDS[*k].id, i.as_deref(), *x))
            .collect();
        assert_eq!(got.len(), 6);
        assert_eq!(got[0], ("electric_energy_total_j", None, 3.0));
        assert_eq!(got[2], ("work_j", Some("j1"), 1.0));
        assert!(got[3].2.is_nan() && got[3].1 == Some("j1"));
        assert_eq!(got[4], ("min_normal_force_n", Some("elbow_4"), -1.0));
        assert_eq!(got[5], ("pull_time_s", Some("elbow_4"), 0.5));
        let peak = KINDS.iter().position(|k| k.id == "peak_current_a").unwrap();
        assert!(!runs[0].carried[peak]);
    }
}
