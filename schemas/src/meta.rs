//! The metadata records of a recording as typed values: what `sim` writes and what every reader
//! gets back, so no other crate spells a record name or a key.
//!
//! MCAP metadata is a map of strings per named record (<https://mcap.dev/spec#metadata-op0x0c>).
//! Each record here is a serde struct ([`MetadataRecord`]) whose fields are the keys; values are
//! text: numbers in Rust's `{:e}` form (`5e0`, `1e-3`, exact round trip), counts in decimal,
//! name lists as JSON arrays of strings. The layout by format version (see
//! [`crate::FORMAT_VERSION`]):
//!
//! | record | keys | since |
//! |---|---|---|
//! | `recording` | `format_version`, `tool` | 0 (`tool` since 1) |
//! | `run` | `scene`, `run`, `contacts` | 0 |
//! | `run` | `joint_names`, `integrator` and `integrator.*`, `duration`, `output_rate`, `mass_matrix`, `constraint_solver`, `stabilization`, `model.*`, `hand_frame`, `tool` | 1 |
//! | `scene` | `json` (the scene as run), `source` | 1 |
//! | `scene` | `target_csv` (the `joint-csv` target's file; only those scenes) | 2 |
//! | `urdf` | `file`, `xml` | 1 |
//! | `result` | `status` (`complete`/`failed`) | 0 |
//! | `result` | `rhs_evals`, `steps`, `rejected` (complete), `error`, `error_time` (failed) | 1 |
//! | `result` | `limits_exceeded`, `saturations` (only runs whose scene monitors limits) | 2 |
//! | `result` | `contact_law_breaches` (only runs with a non-bilateral contact) | 2+ |
//! | `limits` | `monitored`, `resolution`, `exceeded`, `saturations`, `events` (JSON array) — only runs whose scene monitors limits | 2 |
//! | `energy_terms` | `emf_conversion`, `stop_energy`, `stop_loss` — only the terms a scene has | 2 |
//! | `energy_terms` | `impact_loss`, `friction_work`, `damping_loss` (totals over the contacts) — only runs with a non-bilateral contact | 2+ |
//! | `energy_terms` | `gear_loss` (scenes with `gear_friction`), `supply_energy`, `supply_regenerated`, `supply_dumped`, `supply_loss` (scenes with a `supply`) | 3+ |
//! | `contacts` | `contacts` (JSON array of [`ContactInfo`]), `time_tolerance`, `gap_tolerance`, `velocity_tolerance`, `rest_velocity`, `max_events` — only runs with a non-bilateral contact | 2+ |
//! | `contacts` | each contact's `shape` (kind, radius, link, link-frame centre and rim axis: [`ContactShapeInfo`]; optional, issue 27) | 3+ |
//! | `contact_audit` | `bounds` (JSON), `contacts` (JSON array of [`ContactLaws`]), `samples`, `breaches` — only runs with a non-bilateral contact ([`ContactAuditor`], issue 23) | 2+ |
//!
//! `2+`: added within format 2 by issue 11 (contacts), with the topics `/contacts` and
//! `/contact_events`, all only in runs with a non-bilateral contact. The version was NOT bumped,
//! on purpose: the version is written into every recording (record `recording`, the MCAP
//! header's library), and the recordings of purely bilateral runs (the paper's archive) must
//! stay byte-identical; a format-2 reader ignores records and topics it does not know.
//!
//! Readers ignore keys they do not know (a newer writer may add some) and reject a record that
//! lacks a key its format version must have, naming the record and the key.

use std::collections::BTreeMap;

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

mod audit;
pub use audit::{AuditBounds, ContactAudit, ContactAuditRecord, ContactAuditor, ContactLaws, Worst};
mod contacts;
pub use contacts::{shape_kind, ContactInfo, ContactShapeInfo, ContactsRecord};
mod typed;
pub use typed::{typed_records, typed_value};

/// A metadata record: its MCAP name and its keys (the struct's fields, every value text).
pub trait MetadataRecord: Serialize + DeserializeOwned {
    /// The MCAP metadata record name.
    const NAME: &'static str;

    /// The record from its keys and text values (what [`crate::Visitor::metadata`] gets); the
    /// error names the missing or bad key.
    fn from_metadata(entries: &BTreeMap<String, String>) -> Result<Self, String> {
        from_entries(entries)
    }
}

/// Record `recording`: which format, written by which tool. [`crate::RecordingWriter::create`]
/// writes it first, with this crate's [`crate::FORMAT_VERSION`].
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct RecordingInfo {
    #[serde(with = "text")]
    pub format_version: u32,
    /// Name and version of the writing tool, e.g. `elbow-sim 0.1.0` (absent in format 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tool: Option<String>,
}

impl RecordingInfo {
    /// This crate's format version, written by `tool` (e.g. `elbow-sim 0.1.0`).
    pub fn new(tool: &str) -> Self {
        Self { format_version: crate::FORMAT_VERSION, tool: Some(tool.to_string()) }
    }
}

impl MetadataRecord for RecordingInfo {
    const NAME: &'static str = "recording";
}

/// Record `run`: what ran. The names give the order of every per-joint and per-contact array of
/// the messages ([`crate::topics::ArrayIndex`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunInfo {
    /// The scene's name.
    pub scene: String,
    /// The run's name, e.g. `two-elbow`.
    pub run: String,
    /// The active contacts, in `/constraints` array order.
    #[serde(with = "json_text")]
    pub contacts: Vec<String>,
    /// The actuated joints, in the order of `/motors`, `/energy` and `/joint_states`. Format 0
    /// did not record them: the reader names them `joint1` … `jointN` from the arrays.
    #[serde(with = "json_text")]
    pub joint_names: Vec<String>,
    /// How it ran (since format 1).
    #[serde(flatten)]
    pub setup: Setup,
}

/// The part of [`RunInfo`] that says how the run was computed (since format 1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Setup {
    #[serde(flatten)]
    pub integrator: IntegratorInfo,
    /// Simulated time, s.
    #[serde(rename = "duration", with = "sci")]
    pub duration_s: f64,
    /// Rate of the recorded samples, Hz.
    #[serde(rename = "output_rate", with = "sci")]
    pub output_rate_hz: f64,
    /// How M(q) was computed, e.g. `crba`.
    pub mass_matrix: String,
    /// How the constrained system was solved, e.g. `schur`.
    pub constraint_solver: String,
    /// The constraint stabilisation as JSON, e.g. `{"method":"none"}`.
    pub stabilization: String,
    #[serde(flatten)]
    pub model: ModelInfo,
    /// The frame of `/hand` positions.
    pub hand_frame: String,
    /// Name and version of the writing tool.
    pub tool: String,
}

/// The integrator and its settings: keys `integrator` (the method, possibly with a phrase, e.g.
/// `rosenbrock (ROS34PW2, structured Jacobian)`) and `integrator.<setting>` for each setting the
/// method has.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IntegratorInfo {
    #[serde(rename = "integrator")]
    pub method: String,
    /// Fixed step, s.
    #[serde(rename = "integrator.step", default, skip_serializing_if = "Option::is_none", with = "sci_opt")]
    pub step: Option<f64>,
    #[serde(rename = "integrator.rtol", default, skip_serializing_if = "Option::is_none", with = "sci_opt")]
    pub rtol: Option<f64>,
    #[serde(rename = "integrator.atol", default, skip_serializing_if = "Option::is_none", with = "sci_opt")]
    pub atol: Option<f64>,
    /// Largest step, s.
    #[serde(rename = "integrator.h_max", default, skip_serializing_if = "Option::is_none", with = "sci_opt")]
    pub h_max: Option<f64>,
    #[serde(rename = "integrator.max_steps", default, skip_serializing_if = "Option::is_none", with = "text_opt")]
    pub max_steps: Option<u64>,
    #[serde(rename = "integrator.jacobian_reuse", default, skip_serializing_if = "Option::is_none", with = "text_opt")]
    pub jacobian_reuse: Option<u64>,
}

impl IntegratorInfo {
    /// One phrase for people: `dopri45 rtol 1e-10 atol 1e-12 h_max 1e-3` (max_steps left out).
    pub fn phrase(&self) -> String {
        let mut s = self.method.clone();
        let settings = [("step", self.step), ("rtol", self.rtol), ("atol", self.atol), ("h_max", self.h_max)];
        for (name, v) in settings {
            if let Some(v) = v {
                s.push_str(&format!(" {name} {v:e}"));
            }
        }
        if let Some(k) = self.jacobian_reuse {
            s.push_str(&format!(" jacobian_reuse {k}"));
        }
        s
    }
}

/// The terms of the model that ran (a scene assembles only what it has): keys `model.*`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ModelInfo {
    /// The motors' electrical model, e.g. `L di/dt (one state per motor)`.
    #[serde(rename = "model.electrical")]
    pub electrical: String,
    /// Number of active contacts.
    #[serde(rename = "model.contacts", with = "text")]
    pub contacts: usize,
    /// Joint and gear friction terms assembled.
    #[serde(rename = "model.friction", with = "on_off")]
    pub friction: bool,
    /// Gravity non-zero.
    #[serde(rename = "model.gravity", with = "on_off")]
    pub gravity: bool,
}

/// The names part of the `run` record, as every format version has it (`joint_names` since 1):
/// what a producer that does not describe its integration writes (format 0, other tools).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunNames {
    pub scene: String,
    pub run: String,
    #[serde(with = "json_text")]
    pub contacts: Vec<String>,
    #[serde(default, skip_serializing_if = "Option::is_none", with = "json_text_opt")]
    pub joint_names: Option<Vec<String>>,
}

impl MetadataRecord for RunNames {
    const NAME: &'static str = "run";
}

/// The key whose presence says a `run` record has a [`Setup`].
pub(crate) const SETUP_KEY: &str = "integrator";

/// [`RunInfo`] as the reader finds it in a file of any format version.
#[derive(Debug, Clone, PartialEq)]
pub struct RunDescription {
    pub scene: String,
    pub run: String,
    pub contacts: Vec<String>,
    /// Recorded (format ≥ 1) or, for format 0, `joint1` … `jointN` from the arrays.
    pub joint_names: Vec<String>,
    /// `None` for format 0, and for files of other producers that do not say how they ran.
    pub setup: Option<Setup>,
}

impl MetadataRecord for RunInfo {
    const NAME: &'static str = "run";
}

/// Record `scene`: the scene exactly as it ran, so that the recording replays itself.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct SceneRecord {
    /// The scene JSON (with defaults filled in).
    pub json: String,
    /// Where it came from: a file name, or a label.
    pub source: String,
    /// The text of the file a `joint-csv` target reads (absent for every other target), so
    /// that a replay needs nothing but the recording.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target_csv: Option<String>,
}

impl MetadataRecord for SceneRecord {
    const NAME: &'static str = "scene";
}

/// Record `urdf`: the robot description exactly as read.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct UrdfRecord {
    /// The file name the scene gives.
    pub file: String,
    /// Its text (with `package://` and relative mesh references resolved to `file://` URIs
    /// when, and only when, the scene gives `robot.package_paths`).
    pub xml: String,
    /// What became of the URDF's `<mesh>` references (absent when it has none): whether they
    /// are resolved and present, or that the meshes are not embedded and why.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub meshes: Option<String>,
    /// Links whose implausible inertia the scene's `robot.repair_inertia` replaced, with the
    /// principal moments before and after (absent when none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub repaired_inertias: Option<String>,
}

impl MetadataRecord for UrdfRecord {
    const NAME: &'static str = "urdf";
}

/// How a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RunStatus {
    Complete,
    /// Stopped by a numerical failure; the file holds every sample up to it.
    Failed,
}

/// Record `result`, written last: the status and the solver's work, or the error and its time.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunResult {
    pub status: RunStatus,
    /// Right-hand-side evaluations (complete runs, since format 1).
    #[serde(default, skip_serializing_if = "Option::is_none", with = "text_opt")]
    pub rhs_evals: Option<u64>,
    /// Accepted steps.
    #[serde(default, skip_serializing_if = "Option::is_none", with = "text_opt")]
    pub steps: Option<u64>,
    /// Rejected step attempts.
    #[serde(default, skip_serializing_if = "Option::is_none", with = "text_opt")]
    pub rejected: Option<u64>,
    /// Why a failed run stopped.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// Simulated time of the failure, s, when known.
    #[serde(rename = "error_time", default, skip_serializing_if = "Option::is_none", with = "sci_opt")]
    pub error_time_s: Option<f64>,
    /// Joint and drive limits crossed (joint and kind counted once), when limits were
    /// monitored (the [`LimitsRecord`] has the details).
    #[serde(default, skip_serializing_if = "Option::is_none", with = "text_opt")]
    pub limits_exceeded: Option<u64>,
    /// Drive saturations (voltage, current window), when limits were monitored.
    #[serde(default, skip_serializing_if = "Option::is_none", with = "text_opt")]
    pub saturations: Option<u64>,
    /// Samples × laws the contact audit found broken (runs with a non-bilateral contact; the
    /// record `contact_audit` has the details). A run with breaches is not "complete".
    #[serde(default, skip_serializing_if = "Option::is_none", with = "text_opt")]
    pub contact_law_breaches: Option<u64>,
}

impl RunResult {
    /// "complete", "complete, 3 limits exceeded", "failed, 1 limit exceeded, 2 saturations":
    /// the status and what the limits monitor found (never silent).
    pub fn status_text(&self) -> String {
        let plural = |n: u64| if n == 1 { "" } else { "s" };
        let mut s = match (self.status, self.contact_law_breaches.filter(|&n| n > 0)) {
            (RunStatus::Complete, None) => "complete".to_string(),
            (RunStatus::Complete, Some(n)) => format!("ran to the end, contact laws broken ({n} sample{})", plural(n)),
            (RunStatus::Failed, None) => "failed".to_string(),
            (RunStatus::Failed, Some(n)) => format!("failed, contact laws broken ({n} sample{})", plural(n)),
        };
        if let Some(n) = self.limits_exceeded.filter(|&n| n > 0) {
            s += &format!(", {n} limit{} exceeded", plural(n));
        }
        if let Some(n) = self.saturations.filter(|&n| n > 0) {
            s += &format!(", {n} saturation{}", plural(n));
        }
        s
    }
}

/// One joint and kind that went beyond its limit (in [`LimitsRecord::events`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LimitEventInfo {
    pub joint: String,
    /// `position`, `velocity`, `effort`, `current`, `voltage-saturation`, `current-limit`.
    pub kind: String,
    /// The limit (rad, rad/s, N m, A, V; for positions the bound crossed first).
    pub limit: f64,
    /// First sample time beyond, s.
    pub first_time: f64,
    /// Samples beyond × the output interval, s.
    pub time_beyond: f64,
    /// The most extreme value (q for positions, else a magnitude).
    pub peak: f64,
    /// `[first, last]` sample time of each run of samples beyond, s (the first 100).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub intervals: Vec<[f64; 2]>,
    /// How many such runs there were.
    #[serde(default)]
    pub interval_count: u64,
}

/// Record `limits`: what the limits monitor found (only runs whose scene monitors limits).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LimitsRecord {
    /// What was monitored.
    pub monitored: String,
    /// The output interval, s: the resolution of every time.
    #[serde(with = "sci")]
    pub resolution: f64,
    #[serde(with = "text")]
    pub exceeded: u64,
    #[serde(with = "text")]
    pub saturations: u64,
    /// The events, a JSON array of [`LimitEventInfo`].
    #[serde(with = "json_events")]
    pub events: Vec<LimitEventInfo>,
}

impl MetadataRecord for LimitsRecord {
    const NAME: &'static str = "limits";
}

/// Record `energy_terms`: the final values of the energy balance's terms that only some scenes
/// have (the `/energy` messages keep their layout; their residual includes these terms).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct EnergyTermsRecord {
    /// `∫ Σ (K_e − K_t) k i q̇ dt`, J (scenes with K_e ≠ K_t).
    #[serde(default, skip_serializing_if = "Option::is_none", with = "sci_opt")]
    pub emf_conversion: Option<f64>,
    /// The soft stops' stored energy at the end, J (scenes with stops).
    #[serde(default, skip_serializing_if = "Option::is_none", with = "sci_opt")]
    pub stop_energy: Option<f64>,
    /// The soft stops' damping loss, J (scenes with stops).
    #[serde(default, skip_serializing_if = "Option::is_none", with = "sci_opt")]
    pub stop_loss: Option<f64>,
    /// Kinetic energy lost in the contacts' impacts, summed over the contacts, J (runs with a
    /// non-bilateral contact; per contact in `/contacts`).
    #[serde(default, skip_serializing_if = "Option::is_none", with = "sci_opt")]
    pub impact_loss: Option<f64>,
    /// Work dissipated by the contacts' friction, summed, J (runs with a non-bilateral contact).
    #[serde(default, skip_serializing_if = "Option::is_none", with = "sci_opt")]
    pub friction_work: Option<f64>,
    /// The compliant contacts' damping loss, summed, J (runs with a non-bilateral contact).
    #[serde(default, skip_serializing_if = "Option::is_none", with = "sci_opt")]
    pub damping_loss: Option<f64>,
    /// The gears' Coulomb and efficiency loss `∫ Σ (K_m i − τ_gear) q̇ dt`, J (scenes with
    /// `gear_friction`; a balance term beside the viscous `gear_friction_loss` of `/energy`).
    #[serde(default, skip_serializing_if = "Option::is_none", with = "sci_opt")]
    pub gear_loss: Option<f64>,
    /// Energy the supply delivered at the end, J (scenes with a `supply`; without one it is
    /// E = Σ ∫ i v dt: an ideal regenerating supply).
    #[serde(default, skip_serializing_if = "Option::is_none", with = "sci_opt")]
    pub supply_energy: Option<f64>,
    /// Energy the supply took back, J (scenes with a `supply`).
    #[serde(default, skip_serializing_if = "Option::is_none", with = "sci_opt")]
    pub supply_regenerated: Option<f64>,
    /// Energy dumped in brake resistors, J (scenes with a `supply`).
    #[serde(default, skip_serializing_if = "Option::is_none", with = "sci_opt")]
    pub supply_dumped: Option<f64>,
    /// The supply's conversion loss, J (scenes with a `supply`).
    #[serde(default, skip_serializing_if = "Option::is_none", with = "sci_opt")]
    pub supply_loss: Option<f64>,
    /// The heat stored in the motors at the end, `Σ C_w ΔT_w + C_h ΔT_h`, J (runs with the
    /// thermal model; with `heat_to_ambient` it books the resistive loss: E_R = the two).
    #[serde(default, skip_serializing_if = "Option::is_none", with = "sci_opt")]
    pub heat_stored: Option<f64>,
    /// The heat the motors' housings gave to the ambient, `∫ Σ (T_h − T_a) / R_th2 dt`, J
    /// (runs with the thermal model).
    #[serde(default, skip_serializing_if = "Option::is_none", with = "sci_opt")]
    pub heat_to_ambient: Option<f64>,
}

impl MetadataRecord for EnergyTermsRecord {
    const NAME: &'static str = "energy_terms";
}

/// [`LimitsRecord::events`] as JSON text.
mod json_events {
    use serde::{Deserialize, Deserializer, Serializer};

    use super::LimitEventInfo;

    pub fn serialize<S: Serializer>(v: &[LimitEventInfo], s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&serde_json::to_string(v).map_err(serde::ser::Error::custom)?)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<LimitEventInfo>, D::Error> {
        let s = String::deserialize(d)?;
        serde_json::from_str(&s).map_err(|e| serde::de::Error::custom(format!("{s:?} is not a JSON array of limit events: {e}")))
    }
}

impl RunResult {
    /// A complete run and the solver's work.
    pub fn complete(rhs_evals: u64, steps: u64, rejected: u64) -> Self {
        Self {
            status: RunStatus::Complete,
            rhs_evals: Some(rhs_evals),
            steps: Some(steps),
            rejected: Some(rejected),
            error: None,
            error_time_s: None,
            limits_exceeded: None,
            saturations: None,
            contact_law_breaches: None,
        }
    }

    /// A run stopped by `error` at `time_s` (if known).
    pub fn failed(error: String, time_s: Option<f64>) -> Self {
        Self {
            status: RunStatus::Failed,
            rhs_evals: None,
            steps: None,
            rejected: None,
            error: Some(error),
            error_time_s: time_s,
            limits_exceeded: None,
            saturations: None,
            contact_law_breaches: None,
        }
    }
}

impl MetadataRecord for RunResult {
    const NAME: &'static str = "result";
}

/// The keys and text values of `record`, or why a field did not serialise to text.
pub(crate) fn to_entries<R: MetadataRecord>(record: &R) -> Result<BTreeMap<String, String>, String> {
    match serde_json::to_value(record).map_err(|e| e.to_string())? {
        serde_json::Value::Object(map) => map
            .into_iter()
            .map(|(k, v)| match v {
                serde_json::Value::String(s) => Ok((k, s)),
                other => Err(format!("key `{k}` is not text: {other}")),
            })
            .collect(),
        other => Err(format!("not a map of keys: {other}")),
    }
}

/// The record from its keys and text values; the error names the missing or bad key.
pub(crate) fn from_entries<R: DeserializeOwned>(entries: &BTreeMap<String, String>) -> Result<R, String> {
    let map = entries.iter().map(|(k, v)| (k.clone(), serde_json::Value::String(v.clone()))).collect();
    serde_json::from_value(serde_json::Value::Object(map)).map_err(|e| e.to_string())
}

/// A value as its `Display` text, parsed back with `FromStr` (counts, versions).
mod text {
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<T: std::fmt::Display, S: Serializer>(v: &T, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(v)
    }

    pub fn deserialize<'de, T, D>(d: D) -> Result<T, D::Error>
    where
        T: std::str::FromStr,
        T::Err: std::fmt::Display,
        D: Deserializer<'de>,
    {
        let s = String::deserialize(d)?;
        s.trim().parse().map_err(|e| serde::de::Error::custom(format!("{s:?}: {e}")))
    }
}

/// [`text`] for optional values.
mod text_opt {
    use serde::{Deserializer, Serializer};

    pub fn serialize<T: std::fmt::Display, S: Serializer>(v: &Option<T>, s: S) -> Result<S::Ok, S::Error> {
        match v {
            Some(v) => super::text::serialize(v, s),
            None => s.serialize_none(),
        }
    }

    pub fn deserialize<'de, T, D>(d: D) -> Result<Option<T>, D::Error>
    where
        T: std::str::FromStr,
        T::Err: std::fmt::Display,
        D: Deserializer<'de>,
    {
        super::text::deserialize(d).map(Some)
    }
}

/// An f64 in Rust's `{:e}` form (`5e0`, `1e-3`): shortest text that parses back to the same bits.
mod sci {
    use serde::{Deserializer, Serializer};

    pub fn serialize<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(&format_args!("{v:e}"))
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        super::text::deserialize(d)
    }
}

/// [`sci`] for optional values.
mod sci_opt {
    use serde::{Deserializer, Serializer};

    pub fn serialize<S: Serializer>(v: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
        match v {
            Some(v) => super::sci::serialize(v, s),
            None => s.serialize_none(),
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
        super::sci::deserialize(d).map(Some)
    }
}

/// A list of names as a JSON array of strings.
mod json_text {
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(v: &[String], s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&serde_json::to_string(v).map_err(serde::ser::Error::custom)?)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<String>, D::Error> {
        let s = String::deserialize(d)?;
        serde_json::from_str(&s).map_err(|e| serde::de::Error::custom(format!("{s:?} is not a JSON array of strings: {e}")))
    }
}

/// [`json_text`] for an optional list.
mod json_text_opt {
    use serde::{Deserializer, Serializer};

    pub fn serialize<S: Serializer>(v: &Option<Vec<String>>, s: S) -> Result<S::Ok, S::Error> {
        match v {
            Some(v) => super::json_text::serialize(v, s),
            None => s.serialize_none(),
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Vec<String>>, D::Error> {
        super::json_text::deserialize(d).map(Some)
    }
}

/// A flag as `on`/`off`.
mod on_off {
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(v: &bool, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(if *v { "on" } else { "off" })
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<bool, D::Error> {
        match String::deserialize(d)?.as_str() {
            "on" => Ok(true),
            "off" => Ok(false),
            other => Err(serde::de::Error::custom(format!("{other:?}: expected on or off"))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run_info() -> RunInfo {
        RunInfo {
            scene: "paper".into(),
            run: "two-elbow".into(),
            contacts: vec!["elbow4".into(), "elbow7".into()],
            joint_names: vec!["joint1".into(), "joint2".into()],
            setup: Setup {
                integrator: IntegratorInfo {
                    method: "dopri45".into(),
                    step: None,
                    rtol: Some(1e-10),
                    atol: Some(1e-12),
                    h_max: Some(1e-3),
                    max_steps: Some(100_000_000),
                    jacobian_reuse: None,
                },
                duration_s: 5.0,
                output_rate_hz: 1000.0,
                mass_matrix: "crba".into(),
                constraint_solver: "schur".into(),
                stabilization: r#"{"method":"none"}"#.into(),
                model: ModelInfo { electrical: "L di/dt (one state per motor)".into(), contacts: 2, friction: true, gravity: true },
                hand_frame: "world".into(),
                tool: "elbow-sim 0.1.0".into(),
            },
        }
    }

    /// The keys and texts of format 2, exactly (the archived recordings hold these bytes).
    #[test]
    fn run_info_writes_the_format_2_keys() {
        let e = to_entries(&run_info()).unwrap();
        let want = [
            ("constraint_solver", "schur"),
            ("contacts", r#"["elbow4","elbow7"]"#),
            ("duration", "5e0"),
            ("hand_frame", "world"),
            ("integrator", "dopri45"),
            ("integrator.atol", "1e-12"),
            ("integrator.h_max", "1e-3"),
            ("integrator.max_steps", "100000000"),
            ("integrator.rtol", "1e-10"),
            ("joint_names", r#"["joint1","joint2"]"#),
            ("mass_matrix", "crba"),
            ("model.contacts", "2"),
            ("model.electrical", "L di/dt (one state per motor)"),
            ("model.friction", "on"),
            ("model.gravity", "on"),
            ("output_rate", "1e3"),
            ("run", "two-elbow"),
            ("scene", "paper"),
            ("stabilization", r#"{"method":"none"}"#),
            ("tool", "elbow-sim 0.1.0"),
        ];
        let got: Vec<(&str, &str)> = e.iter().map(|(k, v)| (k.as_str(), v.as_str())).collect();
        assert_eq!(got, want);
        assert_eq!(from_entries::<RunInfo>(&e).unwrap(), run_info());
    }

    #[test]
    fn results_round_trip_and_unknown_keys_are_ignored() {
        for r in [RunResult::complete(148_640, 24_770, 3), RunResult::failed("t = 0.5 s: NaN".into(), Some(0.5)), RunResult::failed("?".into(), None)] {
            let mut e = to_entries(&r).unwrap();
            e.insert("added_by_a_newer_writer".into(), "x".into());
            assert_eq!(from_entries::<RunResult>(&e).unwrap(), r);
        }
        let e = to_entries(&RunResult::failed("e".into(), Some(2.5e-3))).unwrap();
        assert_eq!(e.get("error_time").map(String::as_str), Some("2.5e-3"));
        assert_eq!(e.get("status").map(String::as_str), Some("failed"));
    }

    #[test]
    fn a_missing_or_bad_key_is_named() {
        let mut e = to_entries(&run_info()).unwrap();
        e.remove("joint_names");
        assert!(from_entries::<RunInfo>(&e).unwrap_err().contains("joint_names"));
        let mut e = to_entries(&run_info()).unwrap();
        e.insert("model.friction".into(), "maybe".into());
        assert!(from_entries::<RunInfo>(&e).unwrap_err().contains("maybe"));
        let mut e = to_entries(&run_info()).unwrap();
        e.insert("duration".into(), "five".into());
        assert!(from_entries::<RunInfo>(&e).unwrap_err().contains("five"));
        let e = BTreeMap::from([("status".to_string(), "maybe".to_string())]);
        assert!(from_entries::<RunResult>(&e).unwrap_err().contains("maybe"));
    }

    /// `{:e}` text parses back to the same f64, bit for bit.
    #[test]
    fn numbers_round_trip_exactly() {
        for x in [0.1f64 + 0.2, 1e-300, 5.0, 1.0 / 3.0, 123456.789e10, -2.5e-7] {
            let text = format!("{x:e}");
            assert_eq!(text.parse::<f64>().unwrap().to_bits(), x.to_bits(), "{text}");
        }
    }

    #[test]
    fn the_integrator_phrase_names_its_settings() {
        assert_eq!(run_info().setup.integrator.phrase(), "dopri45 rtol 1e-10 atol 1e-12 h_max 1e-3");
    }
}
