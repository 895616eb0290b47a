//! The state file of a study (`<out>/study-state.json`): the optimiser's ask/tell state and
//! every evaluation so far, written after every generation (temporary name, then rename:
//! `schemas::atomic`), so that a killed study resumes where it stopped and gives the same
//! result as one that was not. A shard of a job array writes the evaluations of its part of a
//! generation to `gen-<g>.shard-<i>-of-<n>.json` ([`ShardResult`]); the next unsharded run takes
//! them instead of evaluating again.

use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::optimizer::{Optimizer, Point};

/// One evaluated candidate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Evaluation {
    /// Its index among all evaluations (its name is `<study>-<index>`).
    pub index: usize,
    /// The generation it was asked in.
    pub generation: usize,
    pub point: Point,
    /// The variables' values, in the study's order.
    pub values: Vec<(String, Value)>,
    /// Electric energy summed over the runs, J.
    pub energy_j: Option<f64>,
    /// The hand error norm's RMS (the largest over the runs), m.
    pub hand_error_rms_m: Option<f64>,
    /// The hand error norm's largest value over the runs, m.
    pub hand_error_max_m: Option<f64>,
    /// The largest motor current over the runs, A.
    pub peak_current_a: Option<f64>,
    /// The smallest normal force of any contact over the runs, N.
    pub min_normal_force_n: Option<f64>,
    /// The objective, or none for an infeasible design.
    pub objective: Option<f64>,
    /// Why the design is infeasible.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub infeasible: Option<String>,
}

impl Evaluation {
    /// The value the optimiser is told: +∞ when infeasible.
    pub fn told(&self) -> f64 {
        self.objective.unwrap_or(f64::INFINITY)
    }
}

/// How the evaluations' tolerance was chosen (the book: "Find where to brace", cost control).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Calibration {
    /// The rtol the evaluations run at.
    pub loose: f64,
    /// The rtol of the re-runs.
    pub tight: f64,
    /// The baseline's objective at each rtol tried, loose to tight: (rtol, objective).
    pub ladder: Vec<(f64, f64)>,
    /// The stated error bar of an evaluation, J: [`ERROR_BAR_FACTOR`] × the largest
    /// |objective(loose) − objective(tight)| over the baseline and the calibration designs
    /// ([`crate::study::Study::calibration_points`]).
    pub error_j: f64,
    /// The designs the error bar was measured at, the baseline first.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub designs: Vec<CalibrationDesign>,
}

/// The stated error bar is this factor times the largest loose − tight difference measured at
/// the calibration designs: a few designs sample the design space, the factor covers the
/// designs between them (the book: "Find where to brace", cost control).
pub const ERROR_BAR_FACTOR: f64 = 2.0;

/// One design of the calibration: its objective at the loose and at the tight rtol (none when
/// infeasible there; such a design does not count towards the error bar).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CalibrationDesign {
    /// What it is: `baseline`, or the design's variables.
    pub design: String,
    pub loose: Option<f64>,
    pub tight: Option<f64>,
}

impl CalibrationDesign {
    /// |loose − tight|, when both are feasible.
    pub fn error(&self) -> Option<f64> {
        Some((self.loose? - self.tight?).abs())
    }
}

/// A study's state file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct State {
    /// The study's name.
    pub study: String,
    /// The study file's text, as read (a state is resumed only by the same study).
    pub spec: Value,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub calibration: Option<Calibration>,
    pub optimizer: Optimizer,
    pub evaluations: Vec<Evaluation>,
}

/// The evaluations of one shard of one generation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ShardResult {
    pub study: String,
    pub generation: usize,
    pub shard: crate::sweep::Shard,
    pub evaluations: Vec<Evaluation>,
}

/// The file name of a shard's result.
pub fn shard_file(generation: usize, shard: crate::sweep::Shard) -> String {
    format!("gen-{generation:04}.shard-{}-of-{}.json", shard.index, shard.count)
}

/// The state file's name in the output directory.
pub const STATE_FILE: &str = "study-state.json";
