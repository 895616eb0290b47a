//! The state file of a study (`<out>/study-state.json`): the optimiser's ask/tell state and
//! every evaluation so far, written after every generation (temporary name, then rename:
//! `schemas::atomic`), so that a killed study resumes where it stopped and gives the same
//! result as one that was not. A shard of a job array writes the evaluations of its part of a
//! generation to `gen-<g>.shard-<i>-of-<n>.json` ([`ShardResult`]); the next unsharded run takes
//! them instead of evaluating again.

use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::calibration::Calibration;
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
