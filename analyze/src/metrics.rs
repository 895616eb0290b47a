//! Per-run metrics of one recording: [`run_metrics`] -> [`RunMetrics`].
//!
//! Everything is read through the schema-driven reader of `schemas`, typed: the metadata
//! ([`Recording::run`], [`Recording::result`]) and the messages of each topic as the format's
//! structs ([`Recording::read_sized`]); nothing assumes which program wrote the file, only the
//! recording format that `schemas` owns.
//! What is computed, following SCENE.md "What to report per run" (the paper's Fig. 1-25):
//!
//! - **Hand error** `e(t) = r(t) - r_d(t)` (`/hand` `error.{x,y,z}` and `error_norm`), per axis
//!   and in norm: `RMS = sqrt((1/N) Σ_k e(t_k)^2)`, the plain mean over the N recorded samples
//!   (which lie on a uniform output grid), and `max_k |e(t_k)|` with its time.
//! - **Work and electric energy per link** at the last sample (`/energy`):
//!   `W_j = ∫ τ_j q'_j dt` (`link_work`, Fig. 4, 6-24 even) and `E_j = ∫ i_j v_j dt`
//!   (`electric_energy`, Fig. 5, 7-25 odd), and their recorded totals.
//! - **Peak motor current** `max_k |i_j(t_k)|` per motor (`/motors` `current`) and overall.
//! - **Per contact** (`/constraints`, one array entry per contact in `run.contacts`): the
//!   minimum normal force `f_n` and its time; the time the table *pulls* (`f_n < 0`, which a
//!   real table cannot do; SCENE.md "Physics checks"), by the trapezoid rule on the indicator
//!   `1[f_n < 0]` (see [`ContactMetrics::pull_time_s`]); the first sample with `f_n < 0`;
//!   the drift `max |C|` and `max |C'|`.
//! - **Energy audit** at the last sample (SCENE.md "Energy balance"): electric energy in,
//!   changes of kinetic, potential and magnetic energy since the first sample (t = 0),
//!   resistive and friction losses, the recorded residual
//!   `E - (ΔT + ΔV + ΔL i^2/2 + R-loss + friction-loss)`, and `max_k |residual|`, also
//!   relative to the final electric energy.
//!
//! Each message is checked before it counts (see [`Reductions`]): array sizes against the `run`
//! record, finite values (a NaN or an infinity is an error, never a `null` peak), times on the
//! output grid, and a complete run must reach its duration. The recording is streamed, so the
//! memory of `analyze metrics` and `summary` does not grow with the run.

use std::path::Path;

use schemas::{topics, Recording, RecoverReport};
use serde::{Deserialize, Serialize};

use crate::Error;

mod contacts;
mod reductions;
mod signal;
pub use contacts::{ContactStateMetrics, EventCounts};
pub use reductions::Reductions;

/// How the run ended (metadata `result.status`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    Complete,
    Failed,
    /// Read with `--recover` from a damaged recording that has no `result` record (the run
    /// was cut short, e.g. killed): the metrics cover the recovered part only, and `error`
    /// says where the recording stops.
    Incomplete,
}

/// RMS and largest magnitude of one error component, m.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisError {
    /// `sqrt(mean_k e(t_k)^2)`, m.
    pub rms_m: f64,
    /// `max_k |e(t_k)|`, m.
    pub max_abs_m: f64,
    /// Time of that maximum (the first, if tied), s.
    pub t_max_s: f64,
}

/// Hand error `r - r_d` per world axis and in norm.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HandError {
    pub x: AxisError,
    pub y: AxisError,
    pub z: AxisError,
    /// Of `|r - r_d|` (so `norm.rms_m^2 = x.rms_m^2 + y.rms_m^2 + z.rms_m^2`).
    pub norm: AxisError,
}

/// One link (actuated joint) at the end of the run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinkMetrics {
    /// Joint name (metadata `run.joint_names`).
    pub joint: String,
    /// `W_j = ∫ τ_j q'_j dt` at the last sample, J.
    pub work_j: f64,
    /// `E_j = ∫ i_j v_j dt` at the last sample, J.
    pub electric_energy_j: f64,
    /// `max_k |i_j(t_k)|`, A.
    pub peak_current_a: f64,
    /// Time of that peak, s.
    pub t_peak_current_s: f64,
}

/// The largest motor current of the run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PeakCurrent {
    pub joint: String,
    /// `max_{j,k} |i_j(t_k)|`, A.
    pub current_a: f64,
    pub t_s: f64,
}

/// One contact ("elbow") over the run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactMetrics {
    /// Contact name (metadata `run.contacts`).
    pub contact: String,
    /// `min_k f_n(t_k)`, N (negative: the table pulls).
    pub min_normal_force_n: f64,
    /// Time of that minimum (the first, if tied), s.
    pub t_min_normal_force_s: f64,
    /// Total time with `f_n < 0`, s: the trapezoid rule on the indicator `1[f_n < 0]`, i.e.
    /// each interval `[t_k, t_k+1]` counts fully when `f_n` is negative at both ends and half
    /// when at one end (the sign change is put at the midpoint). For a force negative on the
    /// samples `t_a..=t_b` only, this is `t_b - t_a + dt`; each sign change adds at most
    /// `dt/2` of error.
    pub pull_time_s: f64,
    /// First sample time with `f_n < 0`, s; `None` if the table never pulls.
    pub first_pull_s: Option<f64>,
    /// Drift `max_k |C(t_k)|`, m.
    pub max_abs_position_m: f64,
    /// Drift rate `max_k |C'(t_k)|`, m/s.
    pub max_abs_velocity_m_s: f64,
}

/// Energy balance at the last sample, J (SCENE.md "Energy balance").
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnergyAudit {
    /// Electric energy in, `Σ_j E_j`.
    pub electric_j: f64,
    /// Kinetic energy at the end minus at the first sample.
    pub kinetic_change_j: f64,
    /// Potential energy at the end minus at the first sample.
    pub potential_change_j: f64,
    /// Magnetic energy `Σ L i^2 / 2` at the end minus at the first sample.
    pub magnetic_change_j: f64,
    /// `∫ Σ R i^2 dt`.
    pub resistive_loss_j: f64,
    /// `∫ Σ (D + D_m) q'^2 dt`.
    pub friction_loss_j: f64,
    /// Its gear part `∫ Σ D_m q'^2 dt` (the joints' own part `∫ Σ D q'^2 dt` is the rest);
    /// `None` for recordings of format version < 2, which have only the sum.
    #[serde(default)]
    pub gear_friction_loss_j: Option<f64>,
    /// Recorded balance residual at the end.
    pub residual_j: f64,
    /// `max_k |residual(t_k)|`.
    pub max_abs_residual_j: f64,
    /// Time of that maximum, s.
    pub t_max_abs_residual_s: f64,
    /// `max_abs_residual_j / |electric_j|`; `None` when no electric energy was drawn or the
    /// quotient is not a finite number (a denominator of ~0: the absolute residual above is
    /// the number to read; never `inf` or NaN).
    pub max_abs_residual_rel: Option<f64>,
}

/// Everything reported about one run. JSON keys are the field names (stable).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunMetrics {
    /// Where the recording was read from.
    pub file: String,
    /// Metadata `run.scene`.
    pub scene: String,
    /// Metadata `run.run`, e.g. `two-elbow`.
    pub run: String,
    /// Metadata `run.contacts`, in `/constraints` array order.
    pub contacts: Vec<String>,
    /// Metadata `run.joint_names`, in `/motors` and `/energy` array order.
    pub joint_names: Vec<String>,
    /// Number of `/hand` messages.
    pub samples: usize,
    /// Time of the last `/hand` message, s; `None` when the run failed before its first sample
    /// (e.g. at t = 0: no message at all).
    pub t_end_s: Option<f64>,
    pub status: Status,
    /// Metadata `result.error`, if the run failed.
    pub error: Option<String>,
    /// Metadata `result.error_time`, s, if the run failed and the time is known.
    pub error_time_s: Option<f64>,
    /// `None` when the run failed before its first sample (so for every number below: absent,
    /// never made up; `null` in JSON).
    pub hand_error: Option<HandError>,
    /// One per joint, in `joint_names` order; empty when the run failed before its first sample.
    pub links: Vec<LinkMetrics>,
    /// `Σ_j W_j` at the end (recorded total), J.
    pub link_work_total_j: Option<f64>,
    /// `Σ_j E_j` at the end (recorded total), J.
    pub electric_energy_total_j: Option<f64>,
    /// `None` only for a run without motors.
    pub peak_current: Option<PeakCurrent>,
    /// One per contact, in `contacts` order; empty when the run failed before its first sample.
    pub contact_forces: Vec<ContactMetrics>,
    pub energy: Option<EnergyAudit>,
    /// What the limits monitor found (metadata `limits`), for runs whose scene monitors
    /// joint or drive limits; absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub limits: Option<LimitsMetrics>,
    /// The energy balance's terms that only some scenes have (metadata `energy_terms`: the
    /// back-EMF conversion when K_e ≠ K_t, the soft stops' stored energy and loss, the contacts'
    /// impact loss, friction work and damping loss), at the end.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub energy_terms: Option<schemas::EnergyTermsRecord>,
    /// Per contact, from `/contacts` and `/contact_events` (runs with a unilateral or compliant
    /// contact; empty for the paper's bilateral runs): time in contact, events, losses, the
    /// friction needed to stick ([`contacts`] module docs).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub contact_states: Vec<ContactStateMetrics>,
    /// The contact laws checked at every `/contacts` sample (runs with a unilateral or
    /// compliant contact): recomputed from the samples, beside what the run recorded.
    #[serde(default)]
    pub contact_audit: Option<ContactAuditMetrics>,
}

/// The contact audit of a run ([`schemas::ContactAuditor`]: each law of each contact's model,
/// its worst value and the samples beyond its bound).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactAuditMetrics {
    /// Computed here from the samples, with the bounds of the run's `contacts` record.
    pub audit: schemas::ContactAudit,
    /// What the run itself counted (`result.contact_law_breaches`), when it did.
    pub recorded_breaches: Option<u64>,
}

impl ContactAuditMetrics {
    /// Why the audit fails: a law broken at some sample (named, with its worst value, bound
    /// and times), or the run's own count disagreeing with the samples; `None` when every law
    /// held at every sample and the run says so.
    pub fn failure(&self) -> Option<String> {
        let mut why = self.audit.verdict();
        match self.recorded_breaches {
            Some(n) if n != self.audit.breaches => {
                let s = format!("the run recorded {n} breaches, its samples show {}", self.audit.breaches);
                why = Some(why.map_or(s.clone(), |w| format!("{w}; {s}")));
            }
            _ => {}
        }
        why
    }
}

/// The `limits` record of a run: limits exceeded and drive saturations, joint and kind each
/// counted once, and every event.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LimitsMetrics {
    pub exceeded: u64,
    pub saturations: u64,
    /// The times' resolution (the output interval), s.
    pub resolution_s: f64,
    pub events: Vec<schemas::LimitEventInfo>,
}

impl RunMetrics {
    /// Why the run's contacts fail their audit ([`ContactAuditMetrics::failure`]); `None` for a
    /// run without a non-bilateral contact or one whose contacts held every law.
    pub fn contact_law_failure(&self) -> Option<String> {
        self.contact_audit.as_ref().and_then(ContactAuditMetrics::failure)
    }

    /// The energy the supply delivered by the end, `E_supply = ∫ P_s dt`, J (metadata
    /// `energy_terms.supply_energy`): only runs whose scene has a `supply` (issue 26); without
    /// one the supply is ideal and regenerating, and what it delivers is E = Σ ∫ i v dt.
    pub fn supply_energy_j(&self) -> Option<f64> {
        self.energy_terms.as_ref()?.supply_energy
    }
    /// The energy the supply took back (regenerated), J (runs with a `supply`).
    pub fn supply_regenerated_j(&self) -> Option<f64> {
        self.energy_terms.as_ref()?.supply_regenerated
    }
    /// The energy dumped in brake resistors, J (runs with a `supply`).
    pub fn supply_dumped_j(&self) -> Option<f64> {
        self.energy_terms.as_ref()?.supply_dumped
    }
    /// A run that failed before its first sample: its names, status, error and time from the
    /// metadata, and no numbers (`samples` = 0, every measured value `None` or empty).
    pub fn without_samples(file: String, run: schemas::RunDescription, status: Status, error: Option<String>, error_time_s: Option<f64>) -> Self {
        RunMetrics {
            file,
            scene: run.scene,
            run: run.run,
            contacts: run.contacts,
            joint_names: run.joint_names,
            samples: 0,
            t_end_s: None,
            status,
            error,
            error_time_s,
            hand_error: None,
            links: Vec::new(),
            link_work_total_j: None,
            electric_energy_total_j: None,
            peak_current: None,
            contact_forces: Vec::new(),
            energy: None,
            limits: None,
            energy_terms: None,
            contact_states: Vec::new(),
            contact_audit: None,
        }
    }

    /// Whether the run has numbers (it did not fail before its first sample).
    pub fn measured(&self) -> bool {
        self.samples > 0
    }

    /// The status with what the limits monitor found: "complete", "complete, 3 limits
    /// exceeded", "complete, 1 saturation" (never silent about a limit).
    pub fn status_text(&self) -> String {
        let s = crate::render::status(self.status).to_string();
        let s = match self.contact_audit.as_ref().map(|a| a.audit.breaches.max(a.recorded_breaches.unwrap_or(0))) {
            Some(n) if n > 0 => format!("{s}, contact laws broken ({n} sample{})", if n == 1 { "" } else { "s" }),
            _ => s,
        };
        match &self.limits {
            Some(l) => schemas::RunResult {
                limits_exceeded: Some(l.exceeded),
                saturations: Some(l.saturations),
                ..schemas::RunResult::complete(0, 0, 0)
            }
            .status_text()
            .replacen("complete", &s, 1),
            None => s,
        }
    }
}

/// The topics [`run_metrics`] reads; [`read_run_metrics`] decodes only these (the transforms
/// and joint states, most of a recording, are skipped). The last two exist only in runs with a
/// unilateral or compliant contact; the others are [`REQUIRED_METRIC_TOPICS`].
pub const METRIC_TOPICS: [&str; 6] = [topics::HAND, topics::MOTORS, topics::CONSTRAINTS, topics::ENERGY, topics::CONTACT_EVENTS, topics::CONTACTS];

/// The topics every recording must have for its metrics.
pub const REQUIRED_METRIC_TOPICS: [&str; 4] = [topics::HAND, topics::MOTORS, topics::CONSTRAINTS, topics::ENERGY];

/// Reads the recording at `path` and computes its metrics; errors name the file.
///
/// The file is streamed ([`schemas::stream_recording`]): memory does not grow with the
/// length of the run (running sums and extremes per joint and contact, see [`Reductions`]).
pub fn read_run_metrics(path: &Path) -> Result<RunMetrics, Error> {
    stream_run_metrics(path).map(|(m, _)| m)
}

/// [`read_run_metrics`], and the recording's metadata and channels (no messages), for callers
/// that also want the scene or the setup.
pub fn stream_run_metrics(path: &Path) -> Result<(RunMetrics, Recording), Error> {
    let mut acc = Reductions::default();
    let rec = schemas::stream_recording(path, Some(&METRIC_TOPICS), &mut acc).map_err(|e| acc.take_error(e))?;
    let m = acc.finish(&rec, None)?;
    Ok((m, rec))
}

/// Reads the intact part of a possibly damaged recording at `path`
/// ([`schemas::stream_recording_recover`], streamed too) and computes its metrics (see
/// [`run_metrics_recovered`]). The report says how much was read; print it when it is not
/// `complete`.
pub fn read_run_metrics_recover(path: &Path) -> Result<(RunMetrics, RecoverReport), Error> {
    let mut acc = Reductions::default();
    let (rec, report) = schemas::stream_recording_recover(path, Some(&METRIC_TOPICS), &mut acc).map_err(|e| acc.take_error(e))?;
    match incomplete(&rec, &report).and_then(|why| acc.finish(&rec, why)) {
        Ok(m) => Ok((m, report)),
        Err(e) if !report.complete => Err(Error::Damaged { report: Box::new(report), source: Box::new(e) }),
        Err(e) => Err(e),
    }
}

/// [`run_metrics`] of a recording read by [`schemas::read_recording_recover`]: the same,
/// except that a damaged recording without a `result` record is [`Status::Incomplete`], its
/// `error` stating where the recording stops and why. The metrics cover the messages
/// recovered (`t_end_s` is the last recovered `/hand` sample).
pub fn run_metrics_recovered(rec: &Recording, report: &RecoverReport) -> Result<RunMetrics, Error> {
    metrics(rec, incomplete(rec, report)?)
}

/// Why a recovered recording is [`Status::Incomplete`], if it is.
fn incomplete(rec: &Recording, report: &RecoverReport) -> Result<Option<String>, Error> {
    Ok((!report.complete && rec.result()?.is_none()).then(|| {
        format!(
            "recording damaged, stops at byte {} of {}: {}",
            report.stopped_at,
            report.file_len,
            report.reason.as_deref().unwrap_or("unknown")
        )
    }))
}

/// Computes the metrics of one decoded recording (see the module docs for the formulas).
///
/// Needs the metadata records `run` (names of the run, contacts and joints; format 0 names its
/// joints `joint1..jointN`) and `result` (the status), and at least
/// one message on each of `/hand`, `/motors`, `/constraints` and `/energy`, with one array
/// entry per joint (motors, energy) or per contact (constraints).
pub fn run_metrics(rec: &Recording) -> Result<RunMetrics, Error> {
    metrics(rec, None)
}

/// `incomplete`: the recording was recovered without its `result` record; the reason.
fn metrics(rec: &Recording, incomplete: Option<String>) -> Result<RunMetrics, Error> {
    let mut acc = Reductions::default();
    // the contact topics only when the file has them (events first: file order)
    let present: Vec<&str> = METRIC_TOPICS.iter().copied().filter(|t| REQUIRED_METRIC_TOPICS.contains(t) || rec.channel(t).is_some()).collect();
    rec.replay(&present, &mut acc).map_err(|e| acc.take_error(e))?;
    acc.finish(rec, incomplete)
}

#[cfg(test)]
mod tests;
