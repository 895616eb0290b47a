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
//! the norm; E and W totals; the energy the supply delivered (runs with a `supply`); the peak motor current; the energy balance residual at the end and
//! its max |·|; per link (matched by joint name) W_j, E_j and the peak current; per contact
//! (matched by name) the minimum normal force and the time the table pulls.
//!
//! A quantity **moved** when `|B − A| > atol + rtol · max(|A|, |B|)` (numpy.isclose's formula,
//! made symmetric in A and B). Defaults: `rtol` = 1e-9, `atol` = 1e-12 ([`Tolerance`]). Two NaNs
//! are equal, a NaN and a number are not. The relative difference shown is
//! `|B − A| / max(|A|, |B|)` (0 when both are 0). A quantity one run has and the other lacks
//! (a joint or contact only on one side, no motors) is **missing**, which counts as a
//! difference; one that the other input's *format* does not carry (e.g. per-link peak currents
//! in a CSV table, or a section left out of a JSON table) is **not compared**, which also counts
//! as a difference unless the caller asks for the common quantities only
//! ([`Diff::common_only`], `analyze diff --common-only`): "no differences" is never said of
//! quantities that were not compared.

use serde::{Deserialize, Serialize};

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
        Some("E_total_j"),
    ),
    kind(
        "energy_terms.supply_energy",
        "E supply",
        "J",
        Per::Run,
        Some("E_supply_j"),
    ),
    kind(
        "link_work_total_j",
        "W total",
        "J",
        Per::Run,
        Some("W_total_j"),
    ),
    kind(
        "peak_current.current_a",
        "peak current",
        "A",
        Per::Run,
        Some("peak_current_a"),
    ),
    kind(
        "energy.residual_j",
        "energy residual",
        "J",
        Per::Run,
        Some("residual_j"),
    ),
    kind(
        "energy.max_abs_residual_j",
        "energy residual max |.|",
        "J",
        Per::Run,
        Some("residual_max_abs_j"),
    ),
    kind("work_j", "W_j", "J", Per::Joint, Some("W.{}_j")),
    kind("electric_energy_j", "E_j", "J", Per::Joint, Some("E.{}_j")),
    kind("peak_current_a", "peak current_j", "A", Per::Joint, None),
    kind(
        "min_normal_force_n",
        "min f_n",
        "N",
        Per::Contact,
        Some("fn_min.{}_n"),
    ),
    kind(
        "pull_time_s",
        "f_n < 0 for",
        "s",
        Per::Contact,
        Some("pull.{}_s"),
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

mod input;
mod render;
#[cfg(test)]
mod tests;

pub use input::*;
pub use render::render_diff;

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
    /// Quantities that only one input's format carries are left out of the verdict.
    #[serde(default)]
    pub common_only: bool,
}

impl Diff {
    /// True when something moved beyond the tolerances or is missing on one side (or, unless
    /// [`Diff::common_only`], is carried by one input's format only).
    pub fn differs(&self) -> bool {
        let uncompared = if self.common_only { 0 } else { self.not_compared };
        self.moved + self.missing + uncompared + self.only_in_a.len() + self.only_in_b.len() > 0
    }

    /// Judges only the quantities both inputs carry (`--common-only`).
    pub fn common_only(mut self, yes: bool) -> Self {
        self.common_only = yes;
        self
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
        common_only: false,
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
