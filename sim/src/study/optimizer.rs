//! The study's optimiser as one ask/tell state ([`Optimizer`]): discrete choices (integer and
//! categorical variables) enumerated; a start design, if the study gives one (CMA-ES's x₀,
//! Hansen 2016 §2 / Fig. 7's inputs), evaluated first in every combination; every combination
//! searched by CMA-ES ([`super::cmaes`]), its mean starting at the start design (else the
//! box's centre), over the continuous variables scaled to [0, 1]^n with an equal share of the
//! global budget,
//! then a compass search ([`super::compass`]) from the best point of every combination in turn
//! (each load of a study is resolved, not only the overall best), each with an equal share of
//! what is left (what one leaves goes to the next).
//! Without continuous variables the study is the enumeration (one generation).
//!
//! `ask` gives the next generation and changes nothing but the random numbers it draws; `tell`
//! takes their values (+∞ for an infeasible candidate) and moves on. The state serialises
//! exactly: written after every `tell`, it resumes a study after a kill, and every shard of a
//! job array that reads it asks the same generation.

use serde::{Deserialize, Serialize};

use super::cmaes::{default_lambda, Cmaes};
use super::compass::Compass;
use super::rng::Rng;

/// One candidate: the index of its discrete combination and its continuous coordinates in
/// [0, 1]^n.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Point {
    pub combo: usize,
    pub u: Vec<f64>,
}

/// Where the search is.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "phase", rename_all = "kebab-case")]
pub enum Phase {
    /// Every combination once (no continuous variables).
    Enumerate,
    /// The start design, once in every combination.
    Start,
    /// CMA-ES on combination `combo`, `used` evaluations of its share so far.
    Global { combo: usize, used: usize, cmaes: Cmaes },
    /// Compass search on combination `combo`, `used` evaluations so far of its `share`.
    Local {
        combo: usize,
        used: usize,
        compass: Compass,
        /// Evaluations this combination's refinement may use (a state without it: the rest).
        #[serde(default = "unlimited")]
        share: usize,
    },
    Done,
}

fn unlimited() -> usize {
    usize::MAX
}

/// The settings of an optimiser (from the study's `method`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    pub seed: u64,
    /// Continuous variables.
    pub dims: usize,
    /// Discrete combinations.
    pub combos: usize,
    /// Evaluations at most.
    pub evaluations: usize,
    /// CMA-ES population λ.
    pub population: usize,
    /// Share of the evaluations kept for the local refinement, in [0, 1).
    pub local_fraction: f64,
    /// Initial CMA-ES step size on [0, 1]^n.
    pub sigma0: f64,
    /// The compass search's first step and the step it stops below, on [0, 1]^n.
    pub local_step: f64,
    pub min_step: f64,
    /// Evaluations of the start design before the global phase (one per combination; 0
    /// without a start design).
    #[serde(default)]
    pub starts: usize,
}

impl Settings {
    /// Evaluations of the global phase per combination.
    pub fn global_share(&self) -> usize {
        let local = (self.evaluations as f64 * self.local_fraction).round() as usize;
        self.evaluations.saturating_sub(local).saturating_sub(self.starts) / self.combos.max(1)
    }

    /// Why these settings cannot run, if they cannot.
    pub fn check(&self) -> Result<(), String> {
        if self.dims == 0 {
            return Ok(());
        }
        if self.global_share() < self.population {
            return Err(format!(
                "{} evaluation(s) leave {} per discrete combination ({} combination(s){}) for the global search, fewer than one generation of {}: raise `method.evaluations` or lower `method.population`",
                self.evaluations,
                self.global_share(),
                self.combos,
                if self.starts > 0 { ", each with its start design" } else { "" },
                self.population
            ));
        }
        Ok(())
    }

    pub fn default_population(dims: usize) -> usize {
        default_lambda(dims.max(1))
    }
}

/// The optimiser's state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Optimizer {
    pub settings: Settings,
    pub rng: Rng,
    /// Generations told.
    pub generation: usize,
    /// Evaluations told.
    pub evaluations: usize,
    /// The best feasible candidate so far and its value (the first of equals).
    pub best: Option<(Point, f64)>,
    /// The best feasible candidate of every discrete combination (the first of equals).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub best_per_combo: Vec<Option<(Point, f64)>>,
    /// The start design on [0, 1]^n (empty: the box's centre, not evaluated).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub start: Vec<f64>,
    pub phase: Phase,
}

impl Optimizer {
    /// An optimiser from its settings, without a start design.
    pub fn new(settings: Settings) -> Optimizer {
        Self::with_start(settings, Vec::new())
    }

    /// An optimiser whose search starts at `start` (on [0, 1]^n; empty: the box's centre, not
    /// evaluated); `settings.starts` must be the combinations' count with a start, 0 without.
    pub fn with_start(settings: Settings, start: Vec<f64>) -> Optimizer {
        assert!(start.is_empty() || (start.len() == settings.dims && settings.starts == settings.combos), "a start design has one coordinate per dimension and is evaluated once per combination");
        let mut o = Optimizer { settings, rng: Rng(settings.seed), generation: 0, evaluations: 0, best: None, best_per_combo: vec![None; settings.combos], start, phase: Phase::Done };
        o.phase = if settings.dims == 0 {
            Phase::Enumerate
        } else if o.start.is_empty() {
            o.global(0)
        } else {
            Phase::Start
        };
        o
    }

    fn global(&self, combo: usize) -> Phase {
        let s = &self.settings;
        let mean = if self.start.is_empty() { vec![0.5; s.dims] } else { self.start.clone() };
        Phase::Global { combo, used: 0, cmaes: Cmaes::new(mean, s.sigma0, s.population) }
    }

    pub fn done(&self) -> bool {
        self.phase == Phase::Done
    }

    /// The next generation (empty when done). Draws random numbers: ask once per tell.
    pub fn ask(&mut self) -> Vec<Point> {
        match &self.phase {
            Phase::Enumerate => (0..self.settings.combos).map(|combo| Point { combo, u: Vec::new() }).collect(),
            Phase::Start => (0..self.settings.combos).map(|combo| Point { combo, u: self.start.clone() }).collect(),
            Phase::Global { combo, cmaes, .. } => cmaes.ask(&mut self.rng).into_iter().map(|u| Point { combo: *combo, u }).collect(),
            Phase::Local { combo, compass, .. } => compass.ask().into_iter().map(|u| Point { combo: *combo, u }).collect(),
            Phase::Done => Vec::new(),
        }
    }

    /// The values of the generation `points` (as asked): +∞ for an infeasible candidate.
    pub fn tell(&mut self, points: &[Point], f: &[f64]) {
        assert_eq!(points.len(), f.len(), "one value per point");
        for (p, &v) in points.iter().zip(f) {
            if v.is_finite() && self.best.as_ref().is_none_or(|(_, b)| v < *b) {
                self.best = Some((p.clone(), v));
            }
            if self.best_per_combo.len() < self.settings.combos {
                self.best_per_combo.resize(self.settings.combos, None);
            }
            if let Some(b) = self.best_per_combo.get_mut(p.combo) {
                if v.is_finite() && b.as_ref().is_none_or(|(_, b)| v < *b) {
                    *b = Some((p.clone(), v));
                }
            }
        }
        self.generation += 1;
        self.evaluations += points.len();
        let s = self.settings;
        let us: Vec<Vec<f64>> = points.iter().map(|p| p.u.clone()).collect();
        let budget_left = s.evaluations.saturating_sub(self.evaluations);
        self.phase = match std::mem::replace(&mut self.phase, Phase::Done) {
            Phase::Enumerate | Phase::Done => Phase::Done,
            // the start design's values are kept as the best so far, not told to CMA-ES (its
            // update learns from its own samples around the mean)
            Phase::Start => self.global(0),
            Phase::Global { combo, used, mut cmaes } => {
                cmaes.tell(&us, f);
                let used = used + points.len();
                if used + s.population <= s.global_share() {
                    Phase::Global { combo, used, cmaes }
                } else if combo + 1 < s.combos {
                    self.global(combo + 1)
                } else {
                    self.local_phase(0, budget_left)
                }
            }
            Phase::Local { combo, used, mut compass, share } => {
                compass.tell(&us, f);
                let used = used + points.len();
                if compass.done() || used + 2 * s.dims > share || 2 * s.dims > budget_left {
                    self.local_phase(combo + 1, budget_left)
                } else {
                    Phase::Local { combo, used, compass, share }
                }
            }
        };
    }

    /// The compass search of the first combination from `from` on with a feasible point, with
    /// an equal share of the `budget_left` among it and the combinations after it that have one.
    fn local_phase(&self, from: usize, budget_left: usize) -> Phase {
        let s = self.settings;
        if s.local_step < s.min_step {
            return Phase::Done;
        }
        let with_point: Vec<(usize, &(Point, f64))> = (from..s.combos).filter_map(|k| self.best_per_combo.get(k).and_then(Option::as_ref).map(|b| (k, b))).collect();
        let Some(&(combo, (p, f))) = with_point.first() else { return Phase::Done };
        let share = budget_left / with_point.len();
        if 2 * s.dims > share {
            return Phase::Done;
        }
        Phase::Local { combo, used: 0, compass: Compass { x: p.u.clone(), f: *f, step: s.local_step, min_step: s.min_step }, share }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings(dims: usize, combos: usize, evaluations: usize) -> Settings {
        Settings {
            seed: 3,
            dims,
            combos,
            evaluations,
            population: Settings::default_population(dims),
            local_fraction: 0.3,
            sigma0: 0.3,
            local_step: 0.05,
            min_step: 1e-4,
            starts: 0,
        }
    }

    /// Run the optimiser on `f` to the end; the best point and value and the evaluations used.
    fn minimise(s: Settings, f: impl Fn(usize, &[f64]) -> f64) -> (Point, f64, usize) {
        let mut o = Optimizer::new(s);
        while !o.done() {
            let pts = o.ask();
            let v: Vec<f64> = pts.iter().map(|p| f(p.combo, &p.u)).collect();
            o.tell(&pts, &v);
        }
        let (p, v) = o.best.clone().expect("a feasible point");
        (p, v, o.evaluations)
    }

    #[test]
    fn finds_the_minimum_of_a_shifted_ellipsoid_within_the_budget() {
        // f = Σ 10^{i} (u_i - c_i)², minimum 0 at c (inside the box): 400 evaluations in 3-D
        // reach |u - c| < 1e-3 in every coordinate
        let c = [0.3, 0.71, 0.55];
        let (p, v, used) = minimise(settings(3, 1, 400), |_, u| (0..3).map(|i| 10f64.powi(i as i32) * (u[i] - c[i]).powi(2)).sum());
        assert!(used <= 400, "{used} evaluations");
        for i in 0..3 {
            assert!((p.u[i] - c[i]).abs() < 1e-3, "u = {:?}, f = {v}", p.u);
        }
    }

    #[test]
    fn finds_the_global_minimum_of_rastrigin_in_2d() {
        // Rastrigin on [-5.12, 5.12]² (many local minima 1 apart), shifted so that the global
        // minimum 0 sits at x = (0.5, -1.2): 2000 evaluations with λ = 60 find it to 0.01
        let x_of = |u: f64| -5.12 + 10.24 * u;
        let xs = [0.5, -1.2];
        let f = |_: usize, u: &[f64]| {
            (0..2)
                .map(|i| {
                    let x = x_of(u[i]) - xs[i];
                    x * x - 10.0 * (std::f64::consts::TAU * x).cos() + 10.0
                })
                .sum::<f64>()
        };
        let mut s = settings(2, 1, 2000);
        s.population = 60; // a larger population for a multimodal function (Hansen & Kern 2004)
        let (p, v, _) = minimise(s, f);
        for i in 0..2 {
            assert!((x_of(p.u[i]) - xs[i]).abs() < 0.01, "x = {}, {}; f = {v}", x_of(p.u[0]), x_of(p.u[1]));
        }
    }

    #[test]
    fn discrete_combinations_are_each_searched_and_the_best_wins() {
        // combination k has minimum k - 2.5)² + ... : the best is combo 2 (|k - 2.4| smallest)
        let f = |k: usize, u: &[f64]| (k as f64 - 2.4).powi(2) + (u[0] - 0.2).powi(2);
        let (p, _, used) = minimise(settings(1, 4, 200), f);
        assert_eq!(p.combo, 2);
        assert!((p.u[0] - 0.2).abs() < 1e-3, "{:?}", p.u);
        assert!(used <= 200);
    }

    #[test]
    fn every_combination_is_refined_to_the_resolution_not_only_the_best() {
        // combination k has its minimum k + |u - c_k| (a kink: CMA-ES's few samples do not
        // reach it to 1e-3), the last one at the bound u = 1 (a load whose optimum is at the end
        // of the range): after the compass searches each combination's best is within the
        // resolution of its c_k, within the budget
        let c = [0.3, 0.8137, 1.0];
        let f = |k: usize, u: &[f64]| k as f64 + (u[0] - c[k]).abs();
        let mut s = settings(1, 3, 120);
        s.local_fraction = 0.5;
        s.min_step = 1e-3;
        let mut o = Optimizer::new(s);
        while !o.done() {
            let pts = o.ask();
            let v: Vec<f64> = pts.iter().map(|p| f(p.combo, &p.u)).collect();
            o.tell(&pts, &v);
        }
        assert!(o.evaluations <= 120, "{} evaluations", o.evaluations);
        for (k, ck) in c.iter().enumerate() {
            let (p, v) = o.best_per_combo[k].clone().expect("a feasible point");
            assert_eq!(p.combo, k);
            assert!((p.u[0] - ck).abs() <= 1e-3, "combination {k}: u = {}, f = {v}, the minimum at {ck}", p.u[0]);
        }
    }

    #[test]
    fn infeasible_points_are_never_the_best_and_bounds_hold() {
        // the minimum of (u - 0.9)² lies in the infeasible region u > 0.6: the best feasible is
        // at the border, 0.6
        let f = |_: usize, u: &[f64]| {
            assert!(u.iter().all(|x| (0.0..=1.0).contains(x)), "{u:?} outside the box");
            if u[0] > 0.6 {
                f64::INFINITY
            } else {
                (u[0] - 0.9).powi(2)
            }
        };
        let (p, _, _) = minimise(settings(1, 1, 150), f);
        assert!((p.u[0] - 0.6).abs() < 2e-3, "{:?}", p.u);
    }

    /// A broad bowl with its minimum 1 at (0.3, 0.3) and a narrow well (radius ≈ 0.03) going
    /// down to 0 at (0.8, 0.75): the shape of the pair study's landscape, where the best design
    /// sits in a valley a few hundredths of the box wide.
    fn bowl_and_well(u: &[f64]) -> f64 {
        let bowl = 1.0 + (u[0] - 0.3).powi(2) + (u[1] - 0.3).powi(2);
        let well = 1000.0 * ((u[0] - 0.8).powi(2) + (u[1] - 0.75).powi(2));
        bowl.min(well)
    }

    #[test]
    fn a_start_design_is_evaluated_first_in_every_combination_and_the_search_starts_there() {
        let mut s = settings(2, 2, 120);
        s.starts = 2;
        let start = vec![0.78, 0.76];
        let mut o = Optimizer::with_start(s, start.clone());
        let first = o.ask();
        assert_eq!(first, vec![Point { combo: 0, u: start.clone() }, Point { combo: 1, u: start.clone() }]);
        o.tell(&first, &[2.0, 1.0]);
        // both start values are kept as each combination's best so far
        assert_eq!(o.best, Some((first[1].clone(), 1.0)));
        assert_eq!(o.best_per_combo[0], Some((first[0].clone(), 2.0)));
        match &o.phase {
            Phase::Global { combo: 0, used: 0, cmaes } => assert_eq!(cmaes.mean, start),
            p => panic!("after the start design: {p:?}"),
        }
        // the start's evaluations come out of the global budget: 120 in all
        let mut n = 2;
        while !o.done() {
            let pts = o.ask();
            n += pts.len();
            let v: Vec<f64> = pts.iter().map(|p| p.combo as f64 + bowl_and_well(&p.u)).collect();
            o.tell(&pts, &v);
        }
        assert!(n <= 120 && o.evaluations == n, "{n} evaluations");
    }

    #[test]
    fn a_narrow_well_the_centre_start_misses_is_resolved_from_a_start_design_in_it() {
        let s = settings(2, 1, 120);
        // from the centre (seed 3, 120 evaluations) the search settles in the broad bowl ...
        let (p, v, _) = minimise(s, |_, u| bowl_and_well(u));
        assert!(v > 0.99 && (p.u[0] - 0.3).abs() < 0.02, "from the centre: u = {:?}, f = {v}", p.u);
        // ... and from a start design inside the well (f = 0.8 there) it reaches the well's
        // bottom to 2e-3 (the compass search, 30 % of the 120 evaluations, ends on its budget)
        let mut s = s;
        s.starts = 1;
        let mut o = Optimizer::with_start(s, vec![0.78, 0.77]);
        while !o.done() {
            let pts = o.ask();
            let v: Vec<f64> = pts.iter().map(|p| bowl_and_well(&p.u)).collect();
            o.tell(&pts, &v);
        }
        let (p, v) = o.best.clone().unwrap();
        assert!(o.evaluations <= 120);
        assert!((p.u[0] - 0.8).abs() < 2e-3 && (p.u[1] - 0.75).abs() < 2e-3, "from the start: u = {:?}, f = {v}", p.u);
    }

    #[test]
    fn the_state_resumes_exactly_through_json() {
        let f = |_: usize, u: &[f64]| (u[0] - 0.3).powi(2) + 3.0 * (u[1] - 0.6).powi(2);
        let mut s = settings(2, 1, 120);
        s.starts = 1;
        let mut a = Optimizer::with_start(s, vec![0.2, 0.9]);
        let mut b = a.clone();
        let mut g = 0;
        while !a.done() {
            let pts = a.ask();
            let v: Vec<f64> = pts.iter().map(|p| f(p.combo, &p.u)).collect();
            a.tell(&pts, &v);
            // b is written and read back before every generation (a kill between generations)
            b = serde_json::from_str(&serde_json::to_string(&b).unwrap()).unwrap();
            let pb = b.ask();
            assert_eq!(pb, pts, "generation {g}");
            b.tell(&pb, &v);
            g += 1;
        }
        assert_eq!(a, b);
        assert!(g > 3);
    }
}
