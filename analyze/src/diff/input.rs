//! Reading a diff input: a recording, a directory of recordings, or an exported JSON/CSV
//! table of any version (read by key and column name).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::*;
use crate::{read_run_metrics, Error, RunMetrics};

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
    pub(super) fn get(&self, k: usize, item: &Option<String>) -> Option<f64> {
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

/// The largest JSON or CSV table `analyze diff` reads (8 MiB: several thousand runs; a table is
/// parsed whole, and its parsed form takes several times its size).
pub const MAX_TABLE_BYTES: u64 = 8 << 20;

/// Reads one input: a recording, a directory of recordings, or a JSON or CSV table (told
/// apart by content: a `.mcap` name or the MCAP magic, then a leading `[` or `{`, else CSV).
/// Before any byte is read the path must be a regular file (FIFOs, devices and links to them
/// are refused), and a table at most [`MAX_TABLE_BYTES`]; a recording is read streamed.
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
    // the guard of every reader: a regular file (no FIFO, device or directory), then MCAP by
    // its magic or name, else a table no larger than MAX_TABLE_BYTES, read only then
    let (file, len) = schemas::open_regular(path).map_err(Error::from)?;
    let is_mcap_name = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("mcap"));
    if is_mcap_name || schemas::starts_with_mcap_magic(path).map_err(Error::from)? {
        let runs = vec![from_metrics(&read_run_metrics(path)?)];
        return checked(source, InputKind::Recording, runs);
    }
    if len > MAX_TABLE_BYTES {
        return Err(DiffError::BadTable {
            file: source.clone(),
            detail: format!(
                "{len} bytes: not a recording (no MCAP magic), and over the {MAX_TABLE_BYTES}-byte limit of a JSON or CSV table"
            ),
        });
    }
    let mut bytes = Vec::with_capacity(len as usize);
    std::io::Read::read_to_end(&mut std::io::Read::take(file, MAX_TABLE_BYTES + 1), &mut bytes).map_err(io)?;
    if bytes.len() as u64 > MAX_TABLE_BYTES {
        return Err(DiffError::BadTable {
            file: source.clone(),
            detail: format!("grew past the {MAX_TABLE_BYTES}-byte limit of a JSON or CSV table while it was read"),
        });
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

/// Splits CSV text into rows of cells (RFC 4180, the `csv` crate); rows may differ in length.
pub(super) fn csv_rows(text: &str) -> Result<Vec<Vec<String>>, String> {
    let mut reader = csv::ReaderBuilder::new().has_headers(false).flexible(true).from_reader(text.as_bytes());
    reader
        .records()
        .map(|r| r.map(|r| r.iter().map(str::to_string).collect()).map_err(|e| format!("CSV: {e}")))
        .collect()
}

/// A column name of an older table in the current scheme (`render` module docs): units in
/// lower case (`E_total_J` → `E_total_j`), per-item columns with a dot (`E_joint4_J` →
/// `E.joint4_j`, `fn_min_elbow4_N` → `fn_min.elbow4_n`), `E_ratio` → `E_total_ratio`.
fn current_name(h: &str) -> String {
    let lower_unit = |h: &str| match h.rsplit_once('_') {
        Some((stem, unit @ ("J" | "A" | "N"))) => format!("{stem}_{}", unit.to_lowercase()),
        _ => h.to_string(),
    };
    let h = lower_unit(h);
    match h.as_str() {
        "E_ratio" | "W_ratio" => return h.replace("_ratio", "_total_ratio"),
        _ if h.contains('.') || h.starts_with("E_total") || h.starts_with("W_total") => return h,
        _ => {}
    }
    for prefix in ["first_pull_", "fn_min_", "pull_", "W_", "E_"] {
        if let Some(rest) = h.strip_prefix(prefix) {
            if let Some((item, unit)) = rest.rsplit_once('_').filter(|(item, _)| !item.is_empty()) {
                return format!("{}.{item}_{unit}", prefix.trim_end_matches('_'));
            }
        }
    }
    h
}

pub(super) fn from_csv(text: &str) -> Result<Vec<RunValues>, String> {
    let rows = csv_rows(text)?;
    let Some((head, body)) = rows.split_first() else {
        return Err("empty CSV".into());
    };
    let head: Vec<String> = head.iter().map(|h| current_name(h)).collect();
    let run_col = head
        .iter()
        .position(|h| h == "run")
        .ok_or("neither a recording, JSON, nor a CSV table with a \"run\" column")?;
    let file_col = head.iter().position(|h| h == "file");
    // column -> (kind, item); exact run-level names first (E_total_J is not E_{joint}_J)
    let mut cols: Vec<(usize, usize, Option<String>)> = Vec::new();
    let mut carried = vec![false; KINDS.len()];
    for (c, h) in head.iter().enumerate() {
        let exact = KINDS.iter().position(|k| k.per == Per::Run && k.csv == Some(h.as_str()));
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
