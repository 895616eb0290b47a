//! Output of a [`Comparison`] or of per-run [`RunMetrics`], for people and for machines.
//!
//! - [`Format::Table`]: aligned text in sections (runs, hand error in mm, energy totals,
//!   per-link energy `W_j`/`E_j` at the end, contacts, energy balance, findings), units in the
//!   headers, `-` where a value does not exist (e.g. a ratio to a zero baseline), `—` for the
//!   numbers of a run that has none (it failed before its first sample); never `inf` or `NaN`,
//!   and scientific notation from 10^6 on (no 300-digit cell). A run not compared with the
//!   baseline (another interval: [`crate::compare::RunComparison::not_compared`]) is marked `†`.
//! - [`Format::Json`]: the serde form of the structs, pretty-printed; keys are the field names
//!   and stable. Non-finite numbers come out as `null` (serde_json's rule), so only finite
//!   values round-trip.
//! - [`Format::Csv`]: one header row, one row per run (RFC 4180 quoting, the `csv` crate). Column
//!   names follow one scheme in every table of both tools: `<quantity>[.<joint or contact>]_<unit>`
//!   with the SI unit in lower case (`_m`, `_s`, `_j`, `_a`, `_n`) or `_ratio`/`_rel`: run-level
//!   `err_z_rms_m`, `E_total_j`, `E_total_ratio`, `peak_current_a`; per link `W.joint4_j`,
//!   `E.joint4_j`, `E.joint4_ratio`; per contact `fn_min.elbow4_n`, `pull.elbow4_s`,
//!   `first_pull.elbow4_s`; per contact with a contact model in some run (`/contacts`, issue 11)
//!   `in_contact.elbow4_s`, `lift_offs.elbow4`, `touch_downs.…`, `impacts.…`, `rests.…`,
//!   `stick_to_slip.…`, `slip_to_stick.…` (counts), `impact_loss.elbow4_j`, `friction_work.…_j`,
//!   `damping_loss.…_j`, `mu_stick.elbow4_ratio`, `mu_contact.…_ratio`, `fn_contact_min.…_n`,
//!   `fn_contact_max.…_n`. Empty cells where a run lacks the joint or contact or the value does
//!   not exist (or is not finite). Numbers use Rust's shortest round-trip form, in scientific
//!   notation below 1e-5 and from 1e16 on. A comparison ends with the column `not_compared`.
//!
//! Text fits a width when asked ([`render_comparison_fitted`], [`render_metrics_fitted`]: a
//! terminal's): a wide table is split into column groups that each fit, titles and findings
//! are wrapped; no cell changes. [`render_comparison_brief`] is the short form (`sim`'s
//! default): the headline findings and one table of the runs, every number as the full tables
//! print it.

use std::fmt;
use std::str::FromStr;

use crate::compare::{Comparison, Ratios};
use crate::metrics::{RunMetrics, Status};
use crate::Error;

mod brief;
mod csv;
mod table;
mod text;

pub use brief::FINDINGS;
pub use text::{wrap, TextTable};

/// Output format. `FromStr` accepts `table`, `json`, `csv` (any case); `Display` writes them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Format {
    /// Aligned text for people (the default).
    #[default]
    Table,
    /// Pretty JSON of the serde structs.
    Json,
    /// One header row and one row per run.
    Csv,
}

impl Format {
    /// Every format, in `--help` order.
    pub const ALL: [Format; 3] = [Format::Table, Format::Json, Format::Csv];

    /// The name `FromStr` accepts.
    pub fn as_str(self) -> &'static str {
        match self {
            Format::Table => "table",
            Format::Json => "json",
            Format::Csv => "csv",
        }
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A format name that is not `table`, `json` or `csv`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown format {0:?} (expected table, json or csv)")]
pub struct UnknownFormat(pub String);

impl FromStr for Format {
    type Err = UnknownFormat;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Format::ALL
            .into_iter()
            .find(|f| f.as_str().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| UnknownFormat(s.into()))
    }
}

/// Renders a comparison; text ends with a newline.
pub fn render_comparison(cmp: &Comparison, format: Format) -> Result<String, Error> {
    render_comparison_fitted(cmp, format, None)
}

/// [`render_comparison`], the text's lines fitted to `width` columns when given (JSON and CSV
/// are never changed by it).
pub fn render_comparison_fitted(cmp: &Comparison, format: Format, width: Option<usize>) -> Result<String, Error> {
    let runs: Vec<&RunMetrics> = cmp.runs.iter().map(|r| &r.metrics).collect();
    Ok(match format {
        Format::Table => table::render(&runs, Some(cmp), false, width),
        Format::Json => serde_json::to_string_pretty(cmp)? + "\n",
        Format::Csv => {
            let ratios: Vec<&Ratios> = cmp.runs.iter().map(|r| &r.to_baseline).collect();
            csv::render(&runs, Some((cmp, &ratios)))
        }
    })
}

/// A comparison's tables as Markdown (headings `###`, pipe tables; without the findings,
/// which the report puts first), for the report document.
pub fn render_comparison_markdown(cmp: &Comparison) -> String {
    let runs: Vec<&RunMetrics> = cmp.runs.iter().map(|r| &r.metrics).collect();
    table::render(&runs, Some(cmp), true, None)
}

/// The brief comparison as text fitted to `width` columns (module `brief`): the headline
/// findings (at most [`FINDINGS`]), then one table with a row per run (E, E / E_base, hand error
/// RMS and max, what each contact did); ends with a newline.
pub fn render_comparison_brief(cmp: &Comparison, width: usize) -> String {
    brief::render(cmp, width)
}

/// Renders per-run metrics (JSON: an array of [`RunMetrics`]); text ends with a newline.
pub fn render_metrics(runs: &[RunMetrics], format: Format) -> Result<String, Error> {
    render_metrics_fitted(runs, format, None)
}

/// [`render_metrics`], the text's lines fitted to `width` columns when given.
pub fn render_metrics_fitted(runs: &[RunMetrics], format: Format, width: Option<usize>) -> Result<String, Error> {
    let refs: Vec<&RunMetrics> = runs.iter().collect();
    Ok(match format {
        Format::Table => table::render(&refs, None, false, width),
        Format::Json => serde_json::to_string_pretty(runs)? + "\n",
        Format::Csv => csv::render(&refs, None),
    })
}

/// The name of each run in tables: its run name, followed by its file stem when another run
/// has the same name (the same run from two versions: `two-elbow (old)`, `two-elbow (new)`).
pub(crate) fn run_labels(runs: &[&RunMetrics]) -> Vec<String> {
    runs.iter()
        .map(|r| {
            if runs.iter().filter(|o| o.run == r.run).count() < 2 {
                return r.run.clone();
            }
            let stem = std::path::Path::new(&r.file)
                .file_stem()
                .map_or_else(|| r.file.clone(), |s| s.to_string_lossy().into_owned());
            format!("{} ({stem})", r.run)
        })
        .collect()
}

/// Joints in order of first appearance over the runs.
fn joints<'a>(runs: &[&'a RunMetrics]) -> Vec<&'a str> {
    union(
        runs.iter()
            .flat_map(|r| r.joint_names.iter().map(String::as_str)),
    )
}

/// Contacts in order of first appearance over the runs.
fn contacts<'a>(runs: &[&'a RunMetrics]) -> Vec<&'a str> {
    union(
        runs.iter()
            .flat_map(|r| r.contacts.iter().map(String::as_str)),
    )
}

fn union<'a>(names: impl Iterator<Item = &'a str>) -> Vec<&'a str> {
    let mut out: Vec<&str> = Vec::new();
    for n in names {
        if !out.contains(&n) {
            out.push(n);
        }
    }
    out
}

/// A number in at most 4 significant digits.
pub(crate) fn short_num(x: f64) -> String {
    format!("{}", format!("{x:.4e}").parse::<f64>().unwrap_or(x))
}

pub(crate) fn status(s: Status) -> &'static str {
    match s {
        Status::Complete => "complete",
        Status::Failed => "failed",
        Status::Incomplete => "incomplete",
    }
}

#[cfg(test)]
mod tests;
