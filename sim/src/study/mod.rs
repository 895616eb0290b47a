//! Design studies (`sim optimize`): a study file ([`StudySpec`], unknown keys rejected) names a
//! base scene and its runs, the design variables (any scene field by its dot path: continuous
//! within bounds, integer, or one of a list of JSON values), the objective (electric energy with
//! optional weights) and the constraints; [`Study`] is it validated once. The optimiser is
//! [`optimizer`] (CMA-ES, then compass search; discrete choices enumerated), an ask/tell state
//! that a state file carries between generations.
//!
//! A candidate is a sweep variant ([`crate::sweep::Variant`]): its variables are replacements
//! of the base scene's JSON, validated into a [`Scene`] by the sweep's code; the tolerance of
//! the evaluations is two more (`integrator.rtol`, `integrator.atol`). Running the candidates
//! and reading their metrics is the binary's (`src/bin/sim/optimize.rs`).
//!
//! Sources: the optimisers' own (`cmaes.rs`, `compass.rs`); the study's questions are those of
//! the paper's group on bracing position and energy (the issue tracker, issue 25).

pub mod cmaes;
pub mod compass;
pub mod optimizer;
pub mod rng;
pub mod state;

use std::path::Path;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::error::SceneError;
use crate::limits::{read_text, MAX_INPUT_BYTES};
use crate::scene::Scene;
use crate::sweep::{check_replacement, compact, parse_spec, valid_name, BadReplacement, Sweep, SweepError, SweepSpec, Variant};
use optimizer::{Point, Settings};

/// Most discrete combinations a study enumerates.
pub const MAX_COMBINATIONS: usize = 64;
/// Most evaluations of one study.
pub const MAX_EVALUATIONS: usize = 100_000;

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
}

impl VariableSpec {
    pub fn field(&self) -> &str {
        match self {
            VariableSpec::Continuous { field, .. } | VariableSpec::Integer { field, .. } | VariableSpec::Categorical { field, .. } => field,
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
fn a_thousandth() -> f64 {
    1e-3
}

impl Default for MethodSpec {
    fn default() -> Self {
        MethodSpec { seed: one(), evaluations: two_hundred(), population: None, local_fraction: three_tenths(), resolution: a_thousandth() }
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

/// What a study file is, checked: the base scene (through a [`Sweep`] without axes), the
/// variables and the optimiser's settings.
#[derive(Clone, Debug)]
pub struct Study {
    pub spec: StudySpec,
    /// The study file.
    pub file: String,
    /// The base scene, its runs and its URDF.
    pub base: Sweep,
    /// The discrete variables' indices in `spec.variables`, in order, and their counts.
    pub discrete: Vec<(usize, usize)>,
    /// The continuous variables' indices in `spec.variables`, in order.
    pub continuous: Vec<usize>,
    pub settings: Settings,
}

impl Study {
    /// Read and check a study file; its `scene` is relative to the file's directory.
    pub fn load(path: &Path) -> Result<Study, SweepError> {
        let file = path.display().to_string();
        let text = read_text(path, MAX_INPUT_BYTES).map_err(|e| SceneError::new(&file, "(file)", "", e.to_string()))?;
        let spec: StudySpec = parse_spec(&text, &file)?;
        let base_spec = SweepSpec {
            name: spec.name.clone(),
            description: String::new(),
            scene: spec.scene.clone(),
            runs: spec.runs.clone(),
            duration: spec.duration,
            axes: Vec::new(),
        };
        let base = Sweep::from_spec_at(base_spec, path)?;
        Self::check(spec, file, base)
    }

    fn check(spec: StudySpec, file: String, base: Sweep) -> Result<Study, SweepError> {
        let err = |field: &str, value: &dyn std::fmt::Display, why: String| -> SweepError { SceneError::new(&file, field, value, why).into() };
        if !valid_name(&spec.name) {
            return Err(err("name", &format!("{:?}", spec.name), "must be non-empty and use only letters, digits, '-', '_' and '.' (it names output files)".into()));
        }
        if spec.variables.is_empty() {
            return Err(err("variables", &"[]", "needs at least one design variable".into()));
        }
        let (mut discrete, mut continuous) = (Vec::new(), Vec::new());
        for (i, v) in spec.variables.iter().enumerate() {
            let f = format!("variables[{i}].field");
            if v.field() == "name" {
                return Err(err(&f, &v.field(), "the study names its candidates; it cannot be a variable".into()));
            }
            if let Some(j) = spec.variables[..i].iter().position(|w| w.field() == v.field()) {
                return Err(err(&f, &v.field(), format!("is also variables[{j}]")));
            }
            // the values the variable can take, each checked against the scene's keys and types
            let samples: Vec<(String, Value)> = match v {
                VariableSpec::Continuous { min, max, .. } => {
                    if !(min.is_finite() && max.is_finite()) {
                        let (k, x) = if min.is_finite() { ("max", max) } else { ("min", min) };
                        return Err(err(&format!("variables[{i}].{k}"), x, "must be a finite number".into()));
                    }
                    if max <= min {
                        return Err(err(&format!("variables[{i}].max"), max, format!("must be above min ({min})")));
                    }
                    continuous.push(i);
                    vec![(format!("variables[{i}].min"), Value::from(*min)), (format!("variables[{i}].max"), Value::from(*max))]
                }
                VariableSpec::Integer { min, max, .. } => {
                    if max < min {
                        return Err(err(&format!("variables[{i}].max"), max, format!("must be at least min ({min})")));
                    }
                    let n = (*max as i128 - *min as i128 + 1) as u128;
                    discrete.push((i, n.min(u128::from(u32::MAX)) as usize));
                    vec![(format!("variables[{i}].min"), Value::from(*min)), (format!("variables[{i}].max"), Value::from(*max))]
                }
                VariableSpec::Categorical { values, labels, .. } => {
                    if values.is_empty() {
                        return Err(err(&format!("variables[{i}].values"), &"[]", "needs at least one value".into()));
                    }
                    if let Some(l) = labels {
                        if l.len() != values.len() {
                            return Err(err(&format!("variables[{i}].labels"), &l.len(), format!("needs one label per value ({})", values.len())));
                        }
                    }
                    discrete.push((i, values.len()));
                    values.iter().enumerate().map(|(j, x)| (format!("variables[{i}].values[{j}]"), x.clone())).collect()
                }
            };
            for (at, x) in samples {
                check_replacement(&base.base, v.field(), &x).map_err(|bad| match bad {
                    BadReplacement::Field(why) => err(&f, &v.field(), why),
                    BadReplacement::Value(why) => err(&at, &compact(&x), why),
                })?;
            }
        }
        let combos = discrete.iter().try_fold(1usize, |a, &(_, n)| a.checked_mul(n)).filter(|&c| c <= MAX_COMBINATIONS);
        let Some(combos) = combos else {
            return Err(err(
                "variables",
                &discrete.iter().map(|&(i, n)| format!("variables[{i}]: {n}")).collect::<Vec<_>>().join(", "),
                format!("the integer and categorical variables make more than {MAX_COMBINATIONS} combinations, each searched in turn: narrow them, or make a wide integer variable continuous"),
            ));
        };
        let m = &spec.method;
        if m.evaluations == 0 || m.evaluations > MAX_EVALUATIONS {
            return Err(err("method.evaluations", &m.evaluations, format!("must be in [1, {MAX_EVALUATIONS}]")));
        }
        if let Some(p) = m.population {
            if !(2..=1000).contains(&p) {
                return Err(err("method.population", &p, "must be in [2, 1000]".into()));
            }
        }
        if !(0.0..=0.9).contains(&m.local_fraction) {
            return Err(err("method.local_fraction", &m.local_fraction, "must be in [0, 0.9]".into()));
        }
        if !(m.resolution > 0.0 && m.resolution < 0.5) {
            return Err(err("method.resolution", &m.resolution, "must be in (0, 0.5): a fraction of each variable's range".into()));
        }
        if continuous.is_empty() && m.evaluations < combos {
            return Err(err("method.evaluations", &m.evaluations, format!("fewer than the {combos} discrete combinations, each evaluated once")));
        }
        let o = &spec.objective;
        for (k, w) in [("hand_error_rms", o.hand_error_rms), ("hand_error_max", o.hand_error_max), ("peak_current", o.peak_current)] {
            if !(w >= 0.0 && w.is_finite()) {
                return Err(err(&format!("objective.{k}"), &w, "a weight must be a finite number >= 0".into()));
            }
        }
        let c = &spec.constraints;
        for (k, b) in [("hand_error_max", c.hand_error_max), ("peak_current", c.peak_current)] {
            if let Some(b) = b {
                if !(b > 0.0 && b.is_finite()) {
                    return Err(err(&format!("constraints.{k}"), &b, "a bound must be a positive number".into()));
                }
            }
        }
        if let Some(b) = c.min_normal_force {
            if !(b >= 0.0 && b.is_finite()) {
                return Err(err("constraints.min_normal_force", &b, "must be a number >= 0, N".into()));
            }
        }
        if let Some(t) = &spec.tolerance {
            for (k, r) in [("loose", t.loose), ("tight", t.tight)] {
                if !(r > 0.0 && r < 1.0) {
                    return Err(err(&format!("tolerance.{k}"), &r, "an rtol must be in (0, 1)".into()));
                }
            }
            if t.tight >= t.loose {
                return Err(err("tolerance.tight", &t.tight, format!("must be below loose ({})", t.loose)));
            }
            if base.base.pointer("/integrator/rtol").is_none() {
                return Err(err("tolerance", &"(set)", format!("the scene {} has no adaptive integrator with an `rtol` to set", base.scene_source)));
            }
        }
        let dims = continuous.len();
        let settings = Settings {
            seed: m.seed,
            dims,
            combos,
            evaluations: m.evaluations,
            population: m.population.unwrap_or_else(|| Settings::default_population(dims)),
            local_fraction: m.local_fraction,
            sigma0: 0.3,
            local_step: 0.1,
            min_step: m.resolution,
        };
        settings.check().map_err(|why| err("method.evaluations", &m.evaluations, why))?;
        let study = Study { spec, file: file.clone(), base, discrete, continuous, settings };
        // the corners of the design space validate as scenes (numbers too), before anything runs
        let corners = [0.0, 1.0].map(|u| Point { combo: 0, u: vec![u; dims] });
        for p in corners.iter().chain([&Point { combo: combos - 1, u: vec![0.5; dims] }]) {
            study.scene(&study.variant(0, p), None)?;
        }
        Ok(study)
    }

    /// The replacements of candidate `p`: every variable's value, in the study's order.
    pub fn values(&self, p: &Point) -> Vec<(String, Value)> {
        let mut digits = vec![0usize; self.discrete.len()];
        let mut k = p.combo;
        for (d, &(_, n)) in self.discrete.iter().enumerate().rev() {
            digits[d] = k % n;
            k /= n;
        }
        self.spec
            .variables
            .iter()
            .enumerate()
            .map(|(i, v)| {
                let x = match v {
                    VariableSpec::Continuous { min, max, .. } => {
                        let c = self.continuous.iter().position(|&j| j == i).expect("a continuous variable");
                        Value::from(min + p.u[c] * (max - min))
                    }
                    VariableSpec::Integer { min, .. } => {
                        let d = self.discrete.iter().position(|&(j, _)| j == i).expect("a discrete variable");
                        Value::from(min + digits[d] as i64)
                    }
                    VariableSpec::Categorical { values, .. } => {
                        let d = self.discrete.iter().position(|&(j, _)| j == i).expect("a discrete variable");
                        values[digits[d]].clone()
                    }
                };
                (v.field().to_string(), x)
            })
            .collect()
    }

    /// A variable's value as a table shows it (a categorical variable by its label).
    pub fn label(&self, i: usize, x: &Value) -> String {
        match &self.spec.variables[i] {
            VariableSpec::Categorical { values, labels: Some(l), .. } => values.iter().position(|v| v == x).map_or_else(|| compact(x), |j| l[j].clone()),
            _ => match x {
                Value::Number(n) if n.is_f64() => format!("{:.4}", n.as_f64().unwrap_or(f64::NAN)),
                Value::String(s) => s.clone(),
                other => compact(other),
            },
        }
    }

    /// Candidate `index` at `p`: a sweep variant named `<study>-<index>`.
    pub fn variant(&self, index: usize, p: &Point) -> Variant {
        Variant { index, name: format!("{}-{index:05}", self.spec.name), replacements: self.values(p) }
    }

    /// The variant's scene at the relative tolerance `rtol` (atol = rtol / 100; `None`: the
    /// scene's own).
    pub fn scene(&self, v: &Variant, rtol: Option<f64>) -> Result<Scene, SweepError> {
        self.base.scene(&self.with_tolerance(v, rtol))
    }

    /// The variant with the tolerance replacements added.
    pub fn with_tolerance(&self, v: &Variant, rtol: Option<f64>) -> Variant {
        let mut v = v.clone();
        if let Some(r) = rtol {
            // the scene's keys `integrator` → `rtol`/`atol` as dot paths (joined here: the
            // recording's metadata names of the same spelling belong to `schemas`)
            v.replacements.push((["integrator", "rtol"].join("."), Value::from(r)));
            v.replacements.push((["integrator", "atol"].join("."), Value::from(r * 1e-2)));
        }
        v
    }
}
