//! The study file (`sim optimize STUDY.json`) as written: its serde types, unknown keys
//! refused, every field with its description (the schema `sim schema study` prints and the
//! book's "Study fields" page). [`super::Study`] is it checked.

use std::collections::BTreeMap;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// A study file: a base scene, its design variables, objective, constraints and method (the
/// book: "Find where to brace").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StudySpec {
    /// Short name: the candidates are `<name>-<k>`.
    pub name: String,
    /// What the study asks (default: empty).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub description: String,
    /// Scene file, relative to the study file (default: the built-in paper scene).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scene: Option<String>,
    /// The runs of the scene every candidate runs; the objective sums over them (default: all).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub runs: Option<Vec<String>>,
    /// Simulated time of every run, s (default: the scene's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duration: Option<f64>,
    /// The design variables (at least one).
    pub variables: Vec<VariableSpec>,
    /// What is minimised (default: the electric energy of all joints, no weights).
    #[serde(default)]
    pub objective: ObjectiveSpec,
    /// What a feasible design keeps to (default: the contact laws hold and the run completes).
    #[serde(default)]
    pub constraints: ConstraintsSpec,
    /// The optimiser's settings (default: seed 1, 200 evaluations).
    #[serde(default)]
    pub method: MethodSpec,
    /// The tolerances of the evaluations and of the optimum's re-run (default: the scene's for
    /// both).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<ToleranceSpec>,
}

/// A design variable: a scene field by its dot path and the values it may take.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum VariableSpec {
    /// A number in [min, max] (e.g. `contacts.0.point.offset.2`, a contact's place along its
    /// link).
    Continuous {
        /// A dot path into the scene JSON.
        field: String,
        /// Lower bound.
        min: f64,
        /// Upper bound (> min).
        max: f64,
    },
    /// A whole number in [min, max], each one tried (enumerated with the other discrete
    /// variables).
    Integer {
        /// A dot path into the scene JSON.
        field: String,
        /// Lower bound.
        min: i64,
        /// Upper bound (>= min).
        max: i64,
    },
    /// One of a list of JSON values, each one tried: e.g. which candidate elbows rest, as
    /// alternative `table.points` lists.
    Categorical {
        /// A dot path into the scene JSON.
        field: String,
        /// The values (at least one).
        values: Vec<Value>,
        /// A short label per value for tables (default: the values' JSON).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        labels: Option<Vec<String>>,
    },
    /// Where a contact sits on the arm: a position along a chain of links (link k of `links`
    /// for t in [k, k + 1]) and an angle around the link, on the link's collision cylinder or
    /// capsule when it has one, else on the segment between its joint origins (the book:
    /// "Find where to brace"). Sets `contacts.<k>.point` and, with `support`, the plane's
    /// offset.
    OnLink {
        /// The contact's name in the scene's `contacts` (a point contact, no `shape`).
        contact: String,
        /// The links, in order along the arm (URDF names; at least one).
        links: Vec<String>,
        /// The range of the position t along the chain, in links: [min, max] within
        /// [0, number of links] (default: the whole chain).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        along: Option<[f64; 2]>,
        /// The range of the angle around the link's axis, rad, from the collision frame's x
        /// axis towards its y axis (default: none, the side that faces the plane at the
        /// initial state).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        around: Option<[f64; 2]>,
        /// Move the contact's plane through the point at the initial state: a brace under the
        /// point (default: true; false keeps the plane, and a point off it rests only if the
        /// motion brings it down).
        #[serde(default = "yes")]
        support: bool,
    },
}

impl VariableSpec {
    /// The variable's name in tables: its dot path (an `on-link` variable: `<contact>@links`).
    pub fn field(&self) -> &str {
        match self {
            VariableSpec::Continuous { field, .. } | VariableSpec::Integer { field, .. } | VariableSpec::Categorical { field, .. } => field,
            VariableSpec::OnLink { contact, .. } => contact,
        }
    }
}

/// The objective: electric energy summed over the runs, J, plus weighted penalties.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ObjectiveSpec {
    /// Weight of the hand error's RMS norm, J/m (default 0).
    #[serde(default)]
    pub hand_error_rms: f64,
    /// Weight of the hand error's largest norm, J/m (default 0).
    #[serde(default)]
    pub hand_error_max: f64,
    /// Weight of the peak motor current, J/A (default 0).
    #[serde(default)]
    pub peak_current: f64,
}

/// The constraints of a feasible design (a run that fails, or whose contact laws do not hold,
/// is always infeasible, with its reason).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ConstraintsSpec {
    /// Largest hand error norm allowed, m (default: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hand_error_max: Option<f64>,
    /// Largest motor current allowed, A (default: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_current: Option<f64>,
    /// Every contact must press with at least this normal force throughout, N: a contact that
    /// must stay closed (default: none, contacts may lift off).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_normal_force: Option<f64>,
    /// Drive limits (the scene's `limits`) must not be exceeded (default: true).
    #[serde(default = "yes")]
    pub drive_limits: bool,
}

fn yes() -> bool {
    true
}

/// The optimiser's settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MethodSpec {
    /// Seed of the random numbers: the same seed gives the same study, byte for byte (default 1).
    #[serde(default = "one")]
    pub seed: u64,
    /// Evaluations at most (default 200).
    #[serde(default = "two_hundred")]
    pub evaluations: usize,
    /// CMA-ES population λ (default 4 + ⌊3 ln n⌋ for n continuous variables).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub population: Option<usize>,
    /// Share of the evaluations for the local refinement (compass search), in [0, 0.9]
    /// (default 0.3).
    #[serde(default = "three_tenths")]
    pub local_fraction: f64,
    /// The refinement stops when its step falls below this fraction of every variable's range
    /// (default 1e-3).
    #[serde(default = "a_thousandth")]
    pub resolution: f64,
    /// A design to start from (CMA-ES's x₀): values of some or all continuous dimensions, by
    /// their names in the tables (a continuous variable's dot path, `<contact>.along`,
    /// `<contact>.around`); the others start at their range's centre. It is evaluated first, in
    /// every discrete combination, and each combination's CMA-ES starts its mean there. E.g. a
    /// pair study started from the best single brace (default: every range's centre, not
    /// evaluated).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start: Option<BTreeMap<String, f64>>,
    /// CMA-ES's initial step size σ₀, a fraction of every continuous range, in (0, 1]
    /// (default 0.3).
    #[serde(default = "three_tenths", skip_serializing_if = "is_three_tenths")]
    pub sigma0: f64,
}

fn one() -> u64 {
    1
}
fn two_hundred() -> usize {
    200
}
fn three_tenths() -> f64 {
    0.3
}
// a default σ₀ is left out of the study as written into its state file, so that a state
// written before the field existed still resumes
fn is_three_tenths(x: &f64) -> bool {
    *x == three_tenths()
}
fn a_thousandth() -> f64 {
    1e-3
}

impl Default for MethodSpec {
    fn default() -> Self {
        MethodSpec {
            seed: one(),
            evaluations: two_hundred(),
            population: None,
            local_fraction: three_tenths(),
            resolution: a_thousandth(),
            start: None,
            sigma0: three_tenths(),
        }
    }
}

/// The integrator tolerances: `loose` for the evaluations, `tight` for the optimum's and the
/// baseline's re-runs (atol = rtol / 100 for both; the scene's integrator must be adaptive).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ToleranceSpec {
    /// rtol of the evaluations.
    pub loose: f64,
    /// rtol of the re-runs (< loose).
    pub tight: f64,
}

