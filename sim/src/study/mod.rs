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

pub mod calibration;
pub mod cmaes;
pub mod compass;
pub mod optimizer;
pub mod place;
pub mod rng;
pub mod spec;
pub mod state;

pub use spec::{ConstraintsSpec, MethodSpec, ObjectiveSpec, StudySpec, ToleranceSpec, VariableSpec};

use std::path::Path;

use serde_json::Value;

use crate::error::SceneError;
use crate::limits::{read_text, MAX_INPUT_BYTES};
use crate::scene::Scene;
use crate::sweep::{check_replacement, compact, parse_spec, valid_name, BadReplacement, Sweep, SweepError, SweepSpec, Variant};
use optimizer::{Point, Settings};
use place::Placement;

/// Most discrete combinations a study enumerates.
pub const MAX_COMBINATIONS: usize = 64;
/// Most evaluations of one study.
pub const MAX_EVALUATIONS: usize = 100_000;

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
    /// The continuous dimensions, in the variables' order (a continuous variable is one, an
    /// `on-link` variable one or two).
    pub continuous: Vec<Dim>,
    /// Per variable: the geometry of an `on-link` variable, read from the base scene.
    pub placements: Vec<Option<Placement>>,
    pub settings: Settings,
    /// The start design on [0, 1]^n (`method.start`; empty without one).
    pub start: Vec<f64>,
}

/// One continuous dimension of the design space: `x = lo + u (hi − lo)` for `u ∈ [0, 1]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Dim {
    /// The variable's index in `spec.variables`.
    pub var: usize,
    /// Its name in tables and figures (a dot path, or `<contact>.along` / `<contact>.around`).
    pub name: String,
    pub lo: f64,
    pub hi: f64,
}

impl Dim {
    pub fn at(&self, u: f64) -> f64 {
        self.lo + u * (self.hi - self.lo)
    }
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
        let mut placements: Vec<Option<Placement>> = vec![None; spec.variables.len()];
        let mut base_scene: Option<Scene> = None;
        for (i, v) in spec.variables.iter().enumerate() {
            if let VariableSpec::OnLink { contact, links, along, around, support } = v {
                let scene = match &base_scene {
                    Some(s) => s,
                    None => base_scene.insert(base.scene(&Variant { index: 0, name: format!("{}-base", spec.name), replacements: Vec::new() })?),
                };
                let (placement, dims) = on_link(&err, i, &base.base, scene, contact, links, *along, *around, *support)?;
                continuous.extend(dims);
                placements[i] = Some(placement);
                continue;
            }
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
                    continuous.push(Dim { var: i, name: v.field().to_string(), lo: *min, hi: *max });
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
                VariableSpec::OnLink { .. } => unreachable!("on-link variables are checked above"),
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
        if !(m.sigma0 > 0.0 && m.sigma0 <= 1.0) {
            return Err(err("method.sigma0", &m.sigma0, "must be in (0, 1]: a fraction of each continuous range".into()));
        }
        let start = match &m.start {
            None => Vec::new(),
            Some(values) => {
                if continuous.is_empty() {
                    return Err(err("method.start", &"(set)", "the study has no continuous variable to start from: its discrete combinations are each evaluated once".into()));
                }
                for (name, &x) in values {
                    let Some(d) = continuous.iter().find(|d| &d.name == name) else {
                        let names: Vec<&str> = continuous.iter().map(|d| d.name.as_str()).collect();
                        return Err(err(&format!("method.start.{name}"), &x, format!("names no continuous dimension of the study; its dimensions are {}", names.join(", "))));
                    };
                    if !(x.is_finite() && d.lo <= x && x <= d.hi) {
                        return Err(err(&format!("method.start.{name}"), &x, format!("must be within the dimension's range [{}, {}]", d.lo, d.hi)));
                    }
                }
                continuous.iter().map(|d| values.get(&d.name).map_or(0.5, |&x| (x - d.lo) / (d.hi - d.lo))).collect()
            }
        };
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
            sigma0: m.sigma0,
            local_step: 0.1,
            min_step: m.resolution,
            starts: if start.is_empty() { 0 } else { combos },
        };
        settings.check().map_err(|why| err("method.evaluations", &m.evaluations, why))?;
        let study = Study { spec, file: file.clone(), base, discrete, continuous, placements, settings, start };
        // the corners of the design space validate as scenes (numbers too), before anything runs
        let corners = [0.0, 1.0].map(|u| Point { combo: 0, u: vec![u; dims] });
        let centre = Point { combo: combos - 1, u: if study.start.is_empty() { vec![0.5; dims] } else { study.start.clone() } };
        for p in corners.iter().chain([&centre]) {
            study.scene(&study.variant(0, p), None)?;
        }
        Ok(study)
    }

    /// The digit of every discrete variable in combination `combo` (in `discrete`'s order).
    fn digits(&self, combo: usize) -> Vec<usize> {
        let mut digits = vec![0usize; self.discrete.len()];
        let mut k = combo;
        for (d, &(_, n)) in self.discrete.iter().enumerate().rev() {
            digits[d] = k % n;
            k /= n;
        }
        digits
    }

    /// The continuous coordinates of candidate `p`, one per dimension of `continuous`.
    pub fn coordinates(&self, p: &Point) -> Vec<f64> {
        self.continuous.iter().zip(&p.u).map(|(d, &u)| d.at(u)).collect()
    }

    /// The replacements of candidate `p`: every variable's, in the study's order (an `on-link`
    /// variable gives the contact's point and, with `support`, its plane's offset).
    pub fn values(&self, p: &Point) -> Vec<(String, Value)> {
        let digits = self.digits(p.combo);
        let x = self.coordinates(p);
        let mut out = Vec::with_capacity(self.spec.variables.len() + 1);
        for (i, v) in self.spec.variables.iter().enumerate() {
            let dims: Vec<f64> = self.continuous.iter().zip(&x).filter(|(d, _)| d.var == i).map(|(_, &x)| x).collect();
            let digit = || digits[self.discrete.iter().position(|&(j, _)| j == i).expect("a discrete variable")];
            match v {
                VariableSpec::Continuous { field, .. } => out.push((field.clone(), Value::from(dims[0]))),
                VariableSpec::Integer { field, min, .. } => out.push((field.clone(), Value::from(min + digit() as i64))),
                VariableSpec::Categorical { field, values, .. } => out.push((field.clone(), values[digit()].clone())),
                VariableSpec::OnLink { .. } => {
                    let placement = self.placements[i].as_ref().expect("an on-link variable has its placement");
                    out.extend(placement.replacements(dims[0], dims.get(1).copied()));
                }
            }
        }
        out
    }

    /// The design's columns in tables: one per discrete variable and per continuous dimension,
    /// in the variables' order (an `on-link` variable adds `<contact>.link`, the link and the
    /// fraction s along it).
    pub fn columns(&self) -> Vec<String> {
        let mut out = Vec::new();
        for (i, v) in self.spec.variables.iter().enumerate() {
            match v {
                VariableSpec::OnLink { contact, .. } => {
                    out.extend(self.continuous.iter().filter(|d| d.var == i).map(|d| d.name.clone()));
                    out.push(format!("{contact}.link"));
                }
                _ => out.push(v.field().to_string()),
            }
        }
        out
    }

    /// The design of candidate `p` as table cells, in [`Study::columns`]' order (a categorical
    /// variable by its label).
    pub fn cells(&self, p: &Point) -> Vec<String> {
        let digits = self.digits(p.combo);
        let x = self.coordinates(p);
        let mut out = Vec::new();
        for (i, v) in self.spec.variables.iter().enumerate() {
            let dims: Vec<f64> = self.continuous.iter().zip(&x).filter(|(d, _)| d.var == i).map(|(_, &x)| x).collect();
            let digit = || digits[self.discrete.iter().position(|&(j, _)| j == i).expect("a discrete variable")];
            match v {
                VariableSpec::Continuous { .. } => out.push(format!("{:.4}", dims[0])),
                VariableSpec::Integer { min, .. } => out.push((min + digit() as i64).to_string()),
                VariableSpec::Categorical { values, labels, .. } => {
                    let j = digit();
                    out.push(labels.as_ref().map_or_else(|| match &values[j] {
                        Value::String(s) => s.clone(),
                        other => compact(other),
                    }, |l| l[j].clone()));
                }
                VariableSpec::OnLink { .. } => {
                    out.extend(dims.iter().map(|x| format!("{x:.4}")));
                    let placement = self.placements[i].as_ref().expect("an on-link variable has its placement");
                    let t = dims[0].clamp(0.0, placement.links.len() as f64);
                    let k = (t.floor() as usize).min(placement.links.len() - 1);
                    out.push(format!("{} s={:.3}", placement.links[k].link, t - k as f64));
                }
            }
        }
        out
    }

    /// The labels of the discrete variables in combination `combo`, joined.
    pub fn combo_label(&self, combo: usize) -> String {
        let p = Point { combo, u: vec![0.5; self.continuous.len()] };
        let cells = self.cells(&p);
        let cols = self.columns();
        // the discrete variables' cells, found by their columns (their fields)
        self.discrete.iter().filter_map(|&(i, _)| cols.iter().position(|c| c == self.spec.variables[i].field()).map(|k| cells[k].clone())).collect::<Vec<_>>().join(", ")
    }

    /// The baseline: the base scene as it is.
    pub fn baseline(&self) -> Variant {
        Variant { index: 0, name: format!("{}-baseline", self.spec.name), replacements: Vec::new() }
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

/// An `on-link` variable (`variables[i]`), checked: its placement (the geometry, from the
/// base scene) and its continuous dimensions (along, and around when it has a range).
#[allow(clippy::too_many_arguments)]
fn on_link(
    err: &dyn Fn(&str, &dyn std::fmt::Display, String) -> SweepError,
    i: usize,
    base: &Value,
    scene: &Scene,
    contact: &str,
    links: &[String],
    along: Option<[f64; 2]>,
    around: Option<[f64; 2]>,
    support: bool,
) -> Result<(Placement, Vec<Dim>), SweepError> {
    let contacts = base.get("contacts").and_then(Value::as_array).map(Vec::as_slice).unwrap_or_default();
    let names = || contacts.iter().filter_map(|c| c.get("name").and_then(Value::as_str)).collect::<Vec<_>>().join(", ");
    let Some(k) = contacts.iter().position(|c| c.get("name").and_then(Value::as_str) == Some(contact)) else {
        return Err(err(&format!("variables[{i}].contact"), &contact, format!("no contact of that name in the scene's `contacts` (contacts: {})", names())));
    };
    if let Some(shape) = contacts[k].get("shape") {
        return Err(err(&format!("variables[{i}].contact"), &contact, format!("has a shape ({}): an on-link variable places a point contact; the point is already on the link's surface", compact(shape))));
    }
    let normal: [f64; 3] = contacts[k].pointer("/plane/normal").and_then(|n| serde_json::from_value(n.clone()).ok()).unwrap_or([0.0, 0.0, 1.0]);
    if links.is_empty() {
        return Err(err(&format!("variables[{i}].links"), &"[]", "needs at least one link".into()));
    }
    for (j, l) in links.iter().enumerate() {
        if links[..j].contains(l) {
            return Err(err(&format!("variables[{i}].links[{j}]"), l, "is listed twice".into()));
        }
    }
    let placement = Placement::new(scene, k, normal, links, support).map_err(|(j, why)| err(&format!("variables[{i}].links[{j}]"), &links[j], why))?;
    let n = links.len() as f64;
    let [lo, hi] = along.unwrap_or([0.0, n]);
    for (key, x) in [("along[0]", lo), ("along[1]", hi)] {
        if !(x.is_finite() && (0.0..=n).contains(&x)) {
            return Err(err(&format!("variables[{i}].{key}"), &x, format!("must be in [0, {n}]: the position along the {n} link(s), in links")));
        }
    }
    if hi <= lo {
        return Err(err(&format!("variables[{i}].along[1]"), &hi, format!("must be above along[0] ({lo})")));
    }
    let mut dims = vec![Dim { var: i, name: format!("{contact}.along"), lo, hi }];
    if let Some([a, b]) = around {
        for (key, x) in [("around[0]", a), ("around[1]", b)] {
            if !(x.is_finite() && x.abs() <= 4.0 * std::f64::consts::PI) {
                return Err(err(&format!("variables[{i}].{key}"), &x, "must be an angle in [-4π, 4π] rad".into()));
            }
        }
        if b <= a {
            return Err(err(&format!("variables[{i}].around[1]"), &b, format!("must be above around[0] ({a})")));
        }
        dims.push(Dim { var: i, name: format!("{contact}.around"), lo: a, hi: b });
    }
    Ok((placement, dims))
}
