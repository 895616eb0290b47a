//! `analyze compare` (runs against a baseline) and `analyze metrics` (per-run numbers only).

use std::path::PathBuf;

use analyze::{render_comparison_fitted, render_metrics_fitted, Comparison, RankBy, RunMetrics, Status};
use anyhow::Result;
use cli::{exit, print_out, TableFormat, Verbosity};

/// Compare runs against a baseline: hand error, E and W totals and their ratios, per-link W_j
/// and E_j, contact forces, contact states (unilateral/compliant contacts), energy balance, and
/// findings in plain sentences.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
Output: sections (runs, hand error in mm, energy totals, per-link energy, contacts, contact
states, energy balance, findings) for people; -f json is the comparison as stable keys, -f csv
one row per run (columns such as err_z_rms_m, E_total_j, E.joint4_j, E.joint4_ratio,
fn_min.elbow4_n; for contacts with a contact model in_contact.elbow4_s, impacts.elbow4,
friction_work.elbow4_j, mu_stick.elbow4_ratio ...). Contact states: unilateral and compliant
contacts (recordings with /contacts): time in contact, lift-offs, touch-downs, impacts, rests,
stick/slip transitions, impact loss, friction work, damping loss, the friction needed to stick.
In a terminal every table fits its width (a wide one split into column groups, each repeating
the run); in a pipe or a file the tables keep their full width.

Examples:
  analyze compare out/
  analyze compare out/paper-no-elbow.mcap out/paper-two-elbow.mcap
  analyze compare out/ --baseline two-elbow -f json > comparison.json
  analyze compare --recover out/ out/.paper-no-elbow.mcap.*.partial
  analyze compare out/ --rank-by supply-energy    runs ranked by the energy the supply delivers")]
pub struct CompareArgs {
    /// Recordings (.mcap), or directories: every *.mcap directly in them, sorted by name.
    #[arg(required = true, value_name = "FILES_OR_DIRS")]
    pub inputs: Vec<PathBuf>,
    /// The baseline run, by run name, file path or file stem [default: the first run without
    /// contacts, else the first run].
    #[arg(long, value_name = "RUN")]
    pub baseline: Option<String>,
    /// Read what is intact of damaged (e.g. truncated) recordings; see `metrics --help`.
    #[arg(long)]
    pub recover: bool,
    /// Rank the compared runs by one quantity, least first (a finding, and `ranking` in JSON):
    /// the electric energy E = Σ ∫ i v dt, the energy the supply delivers (scenes with a
    /// `supply`: regeneration, the DC bus and brake resistors; a run without one is ranked by
    /// its E and marked), or the hand error's RMS.
    #[arg(long, value_enum, value_name = "QUANTITY")]
    pub rank_by: Option<RankByArg>,
    #[command(flatten)]
    pub format: TableFormat,
}

/// `--rank-by`'s values (clap's mirror of [`analyze::RankBy`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum RankByArg {
    ElectricEnergy,
    SupplyEnergy,
    HandError,
}

impl From<RankByArg> for RankBy {
    fn from(a: RankByArg) -> Self {
        match a {
            RankByArg::ElectricEnergy => RankBy::ElectricEnergy,
            RankByArg::SupplyEnergy => RankBy::SupplyEnergy,
            RankByArg::HandError => RankBy::HandError,
        }
    }
}

/// Per-run metrics only (no baseline, no findings), every number of each run; for many runs as
/// one filterable table use `summary`.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
Output: one section per quantity, one row per run; -f json is the list of runs with every
number under stable keys (what `analyze diff` reads back), -f csv one row per run.

Examples:
  analyze metrics out/paper-two-elbow.mcap
  analyze metrics out/ -f json > metrics.json
  analyze metrics --recover out/.paper-two-elbow.mcap.*.partial   what a killed run left")]
pub struct MetricsArgs {
    /// Recordings (.mcap), or directories: every *.mcap directly in them, sorted by name.
    #[arg(required = true, value_name = "FILES_OR_DIRS")]
    pub inputs: Vec<PathBuf>,
    /// Read what is intact of damaged (e.g. truncated) recordings: the messages of every
    /// complete chunk and the metadata before the damage. A warning on stderr names each
    /// damaged file, the byte offset where reading stopped and what was recovered; a run cut
    /// short before its result is reported as status `incomplete`. Nothing that failed a CRC
    /// is used (metadata that fails the data section's CRC is left out; a repeated chunk is
    /// read once). Exit status 1 when any file was damaged.
    #[arg(long)]
    pub recover: bool,
    /// Check the audits of every run and exit 1 when one fails: the contact laws at every
    /// sample (recomputed from `/contacts` against the bounds of the run's `contacts` record,
    /// and the run's own count) and the energy balance, whose largest residual must stay
    /// within ENERGY_BOUND of E (a run without samples, or damaged, fails too). Each failure
    /// is named on stderr with the law or the residual, its value, its bound and its time.
    #[arg(long)]
    pub check: bool,
    /// The energy balance's bound for `--check`: the largest |residual| over |E|.
    #[arg(long, value_name = "REL", default_value_t = 1e-6, requires = "check")]
    pub energy_bound: f64,
    #[command(flatten)]
    pub format: TableFormat,
}

pub fn compare(a: &CompareArgs, v: Verbosity) -> Result<u8> {
    let (runs, damaged) = crate::load::metrics(&a.inputs, a.recover, v)?;
    let cmp = match a.rank_by {
        Some(by) => Comparison::ranked(&runs, a.baseline.as_deref(), by.into())?,
        None => Comparison::new(&runs, a.baseline.as_deref())?,
    };
    print_out(&render_comparison_fitted(&cmp, a.format.format, cli::terminal_width())?)?;
    Ok(status(&runs, damaged, v))
}

pub fn metrics(a: &MetricsArgs, v: Verbosity) -> Result<u8> {
    if a.check && !(a.energy_bound.is_finite() && a.energy_bound > 0.0) {
        anyhow::bail!("--energy-bound {}: a relative bound must be a positive number", a.energy_bound);
    }
    let (runs, damaged) = crate::load::metrics(&a.inputs, a.recover, v)?;
    print_out(&render_metrics_fitted(&runs, a.format.format, cli::terminal_width())?)?;
    let code = status(&runs, damaged, v);
    if !a.check {
        return Ok(code);
    }
    let mut failed = false;
    for r in &runs {
        for why in audit_failures(r, a.energy_bound) {
            failed = true;
            eprintln!("analyze: --check: {}: run {}: {why}", r.file, r.run);
        }
    }
    Ok(if failed { code.max(exit::FAILED) } else { code })
}

/// Why `r` fails `--check` besides its contact laws (which [`status`] names): no samples, or
/// its energy balance beyond `energy_bound` of E.
fn audit_failures(r: &RunMetrics, energy_bound: f64) -> Vec<String> {
    let mut out = Vec::new();
    if !r.measured() {
        out.push("no samples to audit".into());
        return out;
    }
    // (broken contact laws are named, and fail, without --check: see `status`)
    match r.energy.as_ref() {
        Some(e) => match e.max_abs_residual_rel {
            Some(rel) if rel <= energy_bound => {}
            Some(rel) => out.push(format!(
                "the energy balance does not close: max |residual| {:.3e} J = {rel:.3e} of E at t = {} s (bound {energy_bound:e})",
                e.max_abs_residual_j, e.t_max_abs_residual_s
            )),
            None => out.push(format!("the energy balance has no relative residual (E = {:e} J)", e.electric_j)),
        },
        None => out.push("no energy balance".into()),
    }
    out
}

/// The exit status of a table of `runs`: 1 when a file was damaged, a run did not complete or
/// its contacts broke their laws at some sample (the contact audit; each such run is named on
/// stderr: its row has its status and reason), else 0.
pub fn status(runs: &[RunMetrics], damaged: bool, v: Verbosity) -> u8 {
    let failed: Vec<&RunMetrics> = runs.iter().filter(|r| r.status != Status::Complete).collect();
    let broken: Vec<(&RunMetrics, String)> =
        runs.iter().filter_map(|r| r.contact_law_failure().map(|why| (r, why))).collect();
    if !v.quiet {
        for r in &failed {
            let at = r.error_time_s.map_or(String::new(), |t| format!(" at t = {t:.3} s"));
            eprintln!("analyze: {}: run {} {}{at}: {}", r.file, r.run, r.status_text(), r.error.as_deref().unwrap_or("no reason recorded"));
        }
        for (r, why) in &broken {
            eprintln!("analyze: {}: run {}: the contact laws do not hold: {why}", r.file, r.run);
        }
    }
    if damaged || !failed.is_empty() || !broken.is_empty() {
        exit::FAILED
    } else {
        exit::SUCCESS
    }
}
