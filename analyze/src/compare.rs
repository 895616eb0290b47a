//! Comparison of runs against a baseline: [`Comparison::new`].
//!
//! - **Baseline**: a run chosen by name, else the first run without contacts (the paper's
//!   no-elbow arm), else the first run. Every ratio is `run / baseline` (`None` when the
//!   baseline value is 0 or either is not finite).
//! - **Per run**: its [`RunMetrics`] and the ratios of the total electric energy `Σ E_j`, the
//!   total link work `Σ W_j` and the RMS z and norm hand errors to the baseline's.
//! - **Per link**: `W_j` and `E_j` of every run, matched by joint name, and `E_j / E_j,base`
//!   (the paper's Fig. 4-25 at t = end).
//! - **Findings**, plain sentences checking SCENE.md "The paper's conclusions": which run draws
//!   the least electric energy and which has the smallest z error; whether "more elbows → less
//!   electric energy and smaller z error" holds over runs ordered by number of contacts that
//!   carried the arm (every run with more contacts must be strictly lower than every run with
//!   fewer), within each scene ([`claims`]); when a bilateral run and a run of another scene with
//!   a unilateral table have the same contacts carrying force, how the conclusions change
//!   ([`claims`]); which links have the largest `|E_j - E_j,base|`; per contact, when and how long
//!   `f_n < 0` (the table pulls, which a real table cannot do; SCENE.md "Physics checks"); per
//!   unilateral or compliant contact what it did, the contacts that never touched the table
//!   collapsed into one sentence per run.

use serde::{Deserialize, Serialize};

use crate::metrics::{AxisError, HandError, RunMetrics, Status};
use crate::Error;

/// Ratios of one run to the baseline (`run / baseline`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ratios {
    /// `Σ E_j / Σ E_j,base`.
    pub electric_energy: Option<f64>,
    /// `Σ W_j / Σ W_j,base`.
    pub link_work: Option<f64>,
    /// RMS z error over the baseline's.
    pub error_z_rms: Option<f64>,
    /// RMS |error| over the baseline's.
    pub error_norm_rms: Option<f64>,
}

/// One run in the comparison.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunComparison {
    pub metrics: RunMetrics,
    pub to_baseline: Ratios,
    /// Why this run is not compared with the baseline (its ratios are `None`, and it is in no
    /// ranking, claim or gap): it failed before its first sample, or it covers another
    /// interval than the baseline (e.g. stopped at 1.33 s of 5 s: totals over different
    /// durations are not comparable). `None` for a run that is compared.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub not_compared: Option<String>,
}

/// One link of one run in the per-link table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinkCell {
    pub run: String,
    /// `W_j` at the end, J.
    pub work_j: f64,
    /// `E_j` at the end, J.
    pub electric_energy_j: f64,
    /// `E_j / E_j,base`.
    pub electric_energy_ratio: Option<f64>,
}

/// One link (joint) across the runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinkComparison {
    pub joint: String,
    /// One per run, in [`Comparison::runs`] order; `None` if that run has no such joint.
    pub runs: Vec<Option<LinkCell>>,
}

/// Runs side by side against a baseline. JSON keys are the field names (stable).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Comparison {
    /// The baseline's run name.
    pub baseline: String,
    /// The baseline's index in `runs`.
    pub baseline_index: usize,
    /// In the order given.
    pub runs: Vec<RunComparison>,
    /// Joints in order of first appearance over the runs.
    pub links: Vec<LinkComparison>,
    /// Plain sentences (see the module docs).
    pub findings: Vec<String>,
    /// The compared runs ranked by one quantity, least first ([`Comparison::ranked`],
    /// `analyze compare --rank-by`); absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ranking: Option<Ranking>,
}

/// What `analyze compare --rank-by` ranks the runs by (least first).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RankBy {
    /// E = Σ ∫ i v dt, the electric energy into the motors (an ideal regenerating supply).
    #[default]
    ElectricEnergy,
    /// The energy the supply delivers (scene `supply`: regeneration, the DC bus, brake
    /// resistors; issue 26); a run without a `supply` is ranked by its E, which is what an
    /// ideal regenerating supply delivers, and says so.
    SupplyEnergy,
    /// The hand error's RMS |r − r_d|.
    HandError,
}

impl RankBy {
    /// The quantity in words, for the finding.
    pub fn describe(self) -> &'static str {
        match self {
            RankBy::ElectricEnergy => "the electric energy E = Σ ∫ i v dt",
            RankBy::SupplyEnergy => "the energy the supply delivers",
            RankBy::HandError => "the hand error's RMS |r − r_d|",
        }
    }
}

/// The compared runs ranked by [`RankBy`], least first.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ranking {
    pub by: RankBy,
    pub runs: Vec<RankedRun>,
}

/// One run's place in a [`Ranking`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RankedRun {
    pub run: String,
    /// The ranked quantity: J for the energies, m for the hand error.
    pub value: f64,
    /// Ranked by its E because the run models no supply (`--rank-by supply-energy` only).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub ideal_supply: bool,
}

impl Comparison {
    /// Compares `runs` (kept in order) against `baseline`: a run name, a file path or a file
    /// stem; `None` picks the first run without contacts that has numbers, else the first run
    /// with numbers. Only runs over the baseline's interval (the same `t_end_s`, to
    /// [`SAME_END`]) are compared: the others keep their row, with no ratios and a reason
    /// ([`RunComparison::not_compared`]), and stay out of the rankings and claims.
    pub fn new(runs: &[RunMetrics], baseline: Option<&str>) -> Result<Self, Error> {
        if runs.is_empty() {
            return Err(Error::NoRuns);
        }
        let base = match baseline {
            Some(name) => {
                let k = find_run(runs, name).ok_or_else(|| Error::UnknownBaseline {
                    name: name.into(),
                    available: runs.iter().map(|r| r.run.clone()).collect(),
                })?;
                if !runs[k].measured() {
                    return Err(Error::UnmeasuredBaseline { name: name.into(), file: runs[k].file.clone(), why: failure(&runs[k]) });
                }
                k
            }
            None => runs
                .iter()
                .position(|r| r.contacts.is_empty() && r.measured())
                .or_else(|| runs.iter().position(RunMetrics::measured))
                .unwrap_or(0),
        };
        let b = &runs[base];
        let why_not: Vec<Option<String>> = runs.iter().map(|r| not_compared(r, b)).collect();
        let with_ratios = runs
            .iter()
            .zip(&why_not)
            .map(|(r, why)| RunComparison {
                metrics: r.clone(),
                to_baseline: match why {
                    Some(_) => Ratios { electric_energy: None, link_work: None, error_z_rms: None, error_norm_rms: None },
                    None => Ratios {
                        electric_energy: ratio(r.e_total(), b.e_total()),
                        link_work: ratio(r.w_total(), b.w_total()),
                        error_z_rms: ratio(r.hand().z.rms_m, b.hand().z.rms_m),
                        error_norm_rms: ratio(r.hand().norm.rms_m, b.hand().norm.rms_m),
                    },
                },
                not_compared: why.clone(),
            })
            .collect();
        let compared: Vec<bool> = why_not.iter().map(Option::is_none).collect();
        let links = link_table(runs, base, &compared);
        let findings = findings(runs, base, &links, &why_not);
        Ok(Self {
            baseline: b.run.clone(),
            baseline_index: base,
            runs: with_ratios,
            links,
            findings,
            ranking: None,
        })
    }

    /// [`Comparison::new`], with the compared runs (measured, over the baseline's interval)
    /// ranked by `by`, least first, in [`Comparison::ranking`] and as a finding. Ranking by the
    /// supply energy needs at least one compared run whose scene has a `supply`
    /// ([`Error::NothingToRank`]).
    pub fn ranked(runs: &[RunMetrics], baseline: Option<&str>, by: RankBy) -> Result<Self, Error> {
        let mut c = Self::new(runs, baseline)?;
        let mut order: Vec<RankedRun> = c
            .runs
            .iter()
            .filter(|r| r.not_compared.is_none())
            .map(|r| {
                let m = &r.metrics;
                let (value, ideal_supply) = match by {
                    RankBy::ElectricEnergy => (m.e_total(), false),
                    RankBy::SupplyEnergy => m.supply_energy_j().map_or((m.e_total(), true), |e| (e, false)),
                    RankBy::HandError => (m.hand().norm.rms_m, false),
                };
                RankedRun { run: m.run.clone(), value, ideal_supply }
            })
            .collect();
        if by == RankBy::SupplyEnergy && order.iter().all(|r| r.ideal_supply) {
            return Err(Error::NothingToRank {
                by: "supply-energy",
                why: "no compared run models its supply (scene `supply`, recordings with /supply): each delivers E; rank by electric-energy".into(),
            });
        }
        order.sort_by(|a, b| a.value.total_cmp(&b.value));
        let unit = |x: f64| match by {
            RankBy::HandError => format!("{} mm", fixed(x * 1e3, 3)),
            _ => format!("{} J", fixed(x, 3)),
        };
        let list: Vec<String> = order
            .iter()
            .enumerate()
            .map(|(k, r)| format!("{}. {} {}{}", k + 1, r.run, unit(r.value), if r.ideal_supply { " (no supply modelled: E)" } else { "" }))
            .collect();
        c.findings.push(format!("Ranked by {}, least first: {}.", by.describe(), list.join(", ")));
        c.ranking = Some(Ranking { by, runs: order });
        Ok(c)
    }

    /// The runs compared with the baseline (measured, over its interval), in order, and the
    /// baseline's index among them.
    pub(crate) fn compared(&self) -> (Vec<RunMetrics>, usize) {
        let mut base = 0;
        let mut out = Vec::new();
        for (k, r) in self.runs.iter().enumerate() {
            if k == self.baseline_index {
                base = out.len();
            }
            if r.not_compared.is_none() {
                out.push(r.metrics.clone());
            }
        }
        (out, base)
    }
}

/// Two runs cover the same interval when their last samples are this close, relative to
/// `max(1, t_end)` s (the tolerance of [`claims`]' pairs).
pub const SAME_END: f64 = 1e-9;

/// "failed at t = 0.000 s (reason)", from the run's `result` record.
pub(crate) fn failure(r: &RunMetrics) -> String {
    let at = r.error_time_s.map_or(String::new(), |t| format!(" at t = {t:.3} s"));
    format!("{}{at} ({})", crate::render::status(r.status), r.error.as_deref().unwrap_or("no reason recorded"))
}

/// Why `r` is not compared with the baseline `b` ([`RunComparison::not_compared`]).
fn not_compared(r: &RunMetrics, b: &RunMetrics) -> Option<String> {
    match (r.t_end_s, b.t_end_s) {
        (None, _) => Some(format!("{}: no sample, so no numbers to compare", failure(r))),
        (Some(_), None) => Some(format!("the baseline {} has no numbers ({})", b.run, failure(b))),
        (Some(t), Some(tb)) if (t - tb).abs() > SAME_END * tb.abs().max(1.0) => {
            let why = if r.status == Status::Complete { String::new() } else { format!(", {}", failure(r)) };
            Some(format!(
                "it ran to t = {} s{why}, the baseline {} to {} s: totals and RMS over different durations are not compared",
                crate::render::short_num(t),
                b.run,
                crate::render::short_num(tb)
            ))
        }
        _ => None,
    }
}

/// The numbers of a run that the comparison ranks and divides, for runs that have them: only
/// runs with samples are compared ([`Comparison::new`]), so the NaN of a run without them
/// never reaches a ratio, a ranking or an output.
pub(crate) trait Measured {
    fn hand(&self) -> &HandError;
    fn e_total(&self) -> f64;
    fn w_total(&self) -> f64;
    fn audit_rel(&self) -> Option<f64>;
    fn t_end(&self) -> f64;
}

const NO_AXIS: AxisError = AxisError { rms_m: f64::NAN, max_abs_m: f64::NAN, t_max_s: f64::NAN };
const NO_HAND: HandError = HandError { x: NO_AXIS, y: NO_AXIS, z: NO_AXIS, norm: NO_AXIS };

impl Measured for RunMetrics {
    fn hand(&self) -> &HandError {
        self.hand_error.as_ref().unwrap_or(&NO_HAND)
    }
    fn e_total(&self) -> f64 {
        self.electric_energy_total_j.unwrap_or(f64::NAN)
    }
    fn w_total(&self) -> f64 {
        self.link_work_total_j.unwrap_or(f64::NAN)
    }
    fn audit_rel(&self) -> Option<f64> {
        self.energy.as_ref().and_then(|e| e.max_abs_residual_rel)
    }
    fn t_end(&self) -> f64 {
        self.t_end_s.unwrap_or(f64::NAN)
    }
}

/// `x` with `d` decimals, in scientific notation from 1e6 on (a fixed-point 4e302 would be a
/// 300-digit number in a sentence).
pub(crate) fn fixed(x: f64, d: usize) -> String {
    if x.is_finite() && x.abs() >= 1e6 {
        format!("{x:.d$e}")
    } else {
        format!("{x:.d$}")
    }
}

/// `x / base`, if both are finite and `base != 0`.
fn ratio(x: f64, base: f64) -> Option<f64> {
    Some(x / base).filter(|q| x.is_finite() && base.is_finite() && base != 0.0 && q.is_finite())
}

/// The run called `name`, else the one read from file `name`, else whose file stem is `name`.
fn find_run(runs: &[RunMetrics], name: &str) -> Option<usize> {
    let stem = |f: &str| {
        std::path::Path::new(f)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
    };
    runs.iter()
        .position(|r| r.run == name)
        .or_else(|| runs.iter().position(|r| r.file == name))
        .or_else(|| {
            runs.iter()
                .position(|r| stem(&r.file).as_deref() == Some(name))
        })
}

fn link_table(runs: &[RunMetrics], base: usize, compared: &[bool]) -> Vec<LinkComparison> {
    let mut joints: Vec<&str> = Vec::new();
    for l in runs.iter().flat_map(|r| &r.links) {
        if !joints.contains(&l.joint.as_str()) {
            joints.push(&l.joint);
        }
    }
    let find = |r: &RunMetrics, j: &str| r.links.iter().find(|l| l.joint == j).cloned();
    // a link whose baseline energy is a rounding residue of the run's (a joint that never
    // moved) has no meaningful ratio
    let floor = 1e-9 * runs[base].e_total().abs();
    joints
        .into_iter()
        .map(|joint| {
            let base_e = find(&runs[base], joint)
                .map(|l| l.electric_energy_j)
                .filter(|b| b.abs() > floor);
            let cells = runs
                .iter()
                .zip(compared)
                .map(|(r, &compared)| {
                    find(r, joint).map(|l| LinkCell {
                        run: r.run.clone(),
                        work_j: l.work_j,
                        electric_energy_j: l.electric_energy_j,
                        electric_energy_ratio: base_e.filter(|_| compared).and_then(|b| ratio(l.electric_energy_j, b)),
                    })
                })
                .collect();
            LinkComparison {
                joint: joint.into(),
                runs: cells,
            }
        })
        .collect()
}

fn findings(all: &[RunMetrics], base: usize, links: &[LinkComparison], why_not: &[Option<String>]) -> Vec<String> {
    let mut out = Vec::new();
    let b = &all[base];
    let reason = if b.contacts.is_empty() {
        "no contacts"
    } else {
        "chosen"
    };
    out.push(format!(
        "Baseline: {} ({reason}); ratios are run / baseline.",
        b.run
    ));
    for r in all.iter().filter(|r| r.status == Status::Failed) {
        match r.t_end_s {
            Some(t) => out.push(format!("{} did not complete: {}; its totals stop at t = {t:.3} s.", r.run, failure(r))),
            None => out.push(format!("{} did not complete: {}; it has no sample, so no numbers.", r.run, failure(r))),
        }
    }
    // (a run without samples is named above: it has no numbers to leave out)
    for (r, why) in all.iter().zip(why_not).filter(|(r, _)| r.measured()) {
        if let Some(why) = why {
            out.push(format!("{} is not compared with the baseline (no ratios, not ranked): {why}.", r.run));
        }
    }
    // the rankings, claims and gaps below are over the runs compared (measured, over the
    // baseline's interval); the per-run facts over every run with numbers
    let measured: Vec<RunMetrics> = all.iter().filter(|r| r.measured()).cloned().collect();
    let runs = &measured[..];
    let compared_index: Vec<usize> = (0..all.len()).filter(|&k| why_not[k].is_none()).collect();
    let compared: Vec<RunMetrics> = compared_index.iter().map(|&k| all[k].clone()).collect();
    for r in runs.iter() {
        let Some(l) = r.limits.as_ref().filter(|l| !l.events.is_empty()) else { continue };
        let list: Vec<String> = l
            .events
            .iter()
            .map(|e| {
                let mut when: Vec<String> = e.intervals.iter().take(3).map(|[a, b]| format!("{a:.3}-{b:.3} s")).collect();
                if e.interval_count > when.len() as u64 {
                    when.push(format!("{} intervals in all", e.interval_count));
                }
                format!(
                    "{} {} (limit {}, first at {:.3} s, {:.3} s beyond, peak {}{})",
                    e.joint,
                    e.kind,
                    crate::render::short_num(e.limit),
                    e.first_time,
                    e.time_beyond,
                    crate::render::short_num(e.peak),
                    if when.is_empty() { String::new() } else { format!("; beyond {}", when.join(", ")) }
                )
            })
            .collect();
        out.push(format!("{}: {} (sampled every {} s): {}.", r.run, r.status_text(), l.resolution_s, list.join("; ")));
    }
    for r in runs.iter() {
        let Some(t) = &r.energy_terms else { continue };
        let mut parts = Vec::new();
        if let Some(c) = t.emf_conversion {
            parts.push(format!("back-EMF conversion ∫ Σ (K_e − K_t) k i q' dt = {c:.4e} J"));
        }
        if let (Some(e), Some(l)) = (t.stop_energy, t.stop_loss) {
            parts.push(format!("joint stops: stored {e:.4e} J, damping loss {l:.4e} J"));
        }
        if let Some(g) = t.gear_loss {
            parts.push(format!("gear Coulomb and efficiency loss {g:.4e} J"));
        }
        if !parts.is_empty() {
            out.push(format!("{}: the energy balance (residual above) also holds {}.", r.run, parts.join("; ")));
        }
    }
    for r in runs.iter().filter(|r| r.status == Status::Incomplete) {
        out.push(format!(
            "{} is incomplete (recovered from a damaged recording): its totals stop at t = {:.3} s.",
            r.run, r.t_end()
        ));
    }

    // least energy, smallest z error (over the runs compared; none when no run has numbers)
    let Some(cbase) = compared_index.iter().position(|&k| k == base) else {
        return out;
    };
    let argmin = |v: &dyn Fn(&RunMetrics) -> f64| {
        (0..compared.len())
            .min_by(|&i, &j| v(&compared[i]).total_cmp(&v(&compared[j])))
            .unwrap_or(0)
    };
    let e = argmin(&|r| r.e_total());
    let r = &compared[e];
    let rel = ratio(r.e_total(), b.e_total())
        .map_or(String::new(), |x| format!(", {x:.3} × baseline"));
    out.push(format!(
        "Least total electric energy: {} ({} J{rel}).",
        r.run,
        fixed(r.e_total(), 3)
    ));
    // the energy the supply delivers (issue 26), over the compared runs whose scene models it:
    // ranked beside E, as what a real arm draws (regeneration and the DC bus decide it)
    let supplied: Vec<(&RunMetrics, f64, f64)> = compared
        .iter()
        .filter_map(|r| {
            let t = r.energy_terms.as_ref()?;
            Some((r, t.supply_energy?, t.supply_dumped.unwrap_or(0.0)))
        })
        .collect();
    if !supplied.is_empty() {
        let mut order = supplied.clone();
        order.sort_by(|a, b| a.1.total_cmp(&b.1));
        let list: Vec<String> = order
            .iter()
            .map(|(r, es, dumped)| format!("{} {} J (E {} J, dumped {} J)", r.run, fixed(*es, 3), fixed(r.e_total(), 3), fixed(*dumped, 3)))
            .collect();
        out.push(format!("Least energy from the supply: {}; in order: {}.", order[0].0.run, list.join(", ")));
    }
    let z = argmin(&|r| r.hand().z.rms_m);
    let r = &compared[z];
    let (rms, max) = (r.hand().z.rms_m * 1e3, r.hand().z.max_abs_m * 1e3);
    out.push(format!(
        "Smallest z error: {} (RMS {rms:.3} mm, max {max:.3} mm).",
        r.run
    ));

    // the paper's claim, per scene, over runs ordered by the number of contacts that carried the
    // arm; then how it changes when the table can only push
    let verdicts = claims::claim_findings(&compared, &mut out);
    out.extend(claims::table_pairs(&compared, cbase, &verdicts));

    // largest per-link electric-energy gaps to the baseline
    for (k, r) in all.iter().enumerate().filter(|&(k, _)| k != base && why_not[k].is_none()) {
        let mut gaps: Vec<(&str, f64, Option<f64>)> = links
            .iter()
            .filter_map(|l| match (&l.runs[k], &l.runs[base]) {
                (Some(c), Some(bc)) => Some((
                    l.joint.as_str(),
                    c.electric_energy_j - bc.electric_energy_j,
                    c.electric_energy_ratio,
                )),
                _ => None,
            })
            .collect();
        gaps.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
        // a gap printed as ±0.000 J says nothing: only gaps that show at the 1 mJ printed
        let shown = |d: f64| d.abs() >= 5e-4;
        let top: Vec<String> = gaps
            .iter()
            .filter(|(_, d, _)| shown(*d))
            .take(3)
            .map(|(j, d, q)| {
                format!(
                    "{j} {}{} J{}",
                    if *d >= 0.0 { "+" } else { "" },
                    fixed(*d, 3),
                    q.map_or(String::new(), |q| format!(" ({:+.1} %)", (q - 1.0) * 100.0))
                )
            })
            .collect();
        if !top.is_empty() {
            out.push(format!(
                "Largest electric-energy gaps of {} to {}: {}.",
                r.run,
                b.run,
                top.join(", ")
            ));
        } else if !gaps.is_empty() {
            out.push(format!("No joint's electric energy differs by 1 mJ or more between {} and {}.", r.run, b.run));
        }
    }

    // contacts where the table pulls
    for r in runs.iter().filter(|r| !r.contact_forces.is_empty()) {
        let mut any = false;
        for c in r.contact_forces.iter().filter(|c| c.first_pull_s.is_some()) {
            any = true;
            out.push(format!(
                "{}, {}: the table pulls (f_n < 0) for {:.3} s in total, from t = {:.3} s; minimum f_n = {:.3} N at t = {:.3} s. A real table cannot pull.",
                r.run, c.contact, c.pull_time_s, c.first_pull_s.unwrap_or(f64::NAN), c.min_normal_force_n, c.t_min_normal_force_s
            ));
        }
        if !any {
            let min = r
                .contact_forces
                .iter()
                .map(|c| c.min_normal_force_n)
                .fold(f64::INFINITY, f64::min);
            out.push(format!(
                "{}: every normal force stays >= 0 (minimum {min:.3} N): the table only pushes.",
                r.run
            ));
        }
    }

    // contacts with a contact model (unilateral, compliant): what they did
    for r in runs.iter() {
        let mut untouched = Vec::new();
        for c in r.contact_states.iter().filter(|c| c.model.as_deref() != Some("bilateral")) {
            let ev = &c.events;
            if c.time_in_contact_s == 0.0 && ev.touch_downs == 0 && ev.impacts == 0 && ev.rests == 0 {
                untouched.push(c.contact.as_str());
                continue;
            }
            let model = match (&c.model, c.friction) {
                (Some(m), Some(mu)) => format!(" ({m}, μ = {mu})"),
                (Some(m), None) => format!(" ({m})"),
                _ => String::new(),
            };
            let stick = match (c.stick_friction_needed, c.contact_friction_needed) {
                (Some(s), Some(a)) => format!("; friction needed to stick {s:.3} (over every sample in contact {a:.3})"),
                (None, Some(a)) => format!("; never sticks (max |f_t|/f_n in contact {a:.3})"),
                _ => String::new(),
            };
            out.push(format!(
                "{}, {}{model}: in contact for {:.3} s of {:.3} s; {} lift-offs, {} touch-downs, {} impacts, {} rests, {} stick→slip, {} slip→stick; \
                 impacts lost {:.3e} J, friction dissipated {:.3e} J{stick}.",
                r.run,
                c.contact,
                c.time_in_contact_s,
                r.t_end(),
                ev.lift_offs,
                ev.touch_downs,
                ev.impacts,
                ev.rests,
                ev.stick_to_slip,
                ev.slip_to_stick,
                c.impact_loss_j,
                c.friction_work_j,
            ));
        }
        if !untouched.is_empty() {
            out.push(format!("{}: {} never touched the table.", r.run, untouched.join(", ")));
        }
    }

    // energy balance
    let worst = (0..runs.len())
        .filter_map(|k| runs[k].audit_rel().map(|x| (k, x)))
        .max_by(|a, b| a.1.total_cmp(&b.1));
    if let Some((k, x)) = worst {
        out.push(format!(
            "Energy balance: the largest |residual| is {x:.2e} of the electric energy ({}).",
            runs[k].run
        ));
    }
    out
}

mod claims;
mod headline;
pub use headline::LONG_PULL;
pub(crate) use headline::num;

#[cfg(test)]
pub(crate) mod tests;
