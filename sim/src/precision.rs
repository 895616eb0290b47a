//! Speed against error: run one scene with every method over a ladder of tolerances or steps
//! (and with each model reduction) against a tight reference run of the same scene, and
//! measure wall time, work (RHS evaluations, steps, rejections) and error (max hand error,
//! worst per-link energy error, max constraint drift). A work–precision diagram in the sense of
//! Hairer & Wanner, *Solving ODEs II*, §IV.10.
//!
//! All runs share the output grid, so errors are compared sample by sample; wall time is the
//! best of `repeats` runs without recording (the simulation itself, with the per-sample
//! outputs at [`OutputLevel::Kinematic`]: the hand, the quadratures and C, as the errors need).
//!
//! A run that finished but left the physics is marked `diverged` ([`Row::status`], with the
//! reason): a non-finite hand or energy, a max hand error above the reach of the reference
//! hand (the largest |r_hand| of the reference run: an error that large means the simulated
//! arm is anywhere in its workspace), or a max energy error above the largest electric energy
//! the reference motors took in (`max_j max_t |E_j,ref|`, at least 1 J): the energy balance no
//! longer means anything. [`recommend`] picks the cheapest `ok` run within a requested error.
//!
//! Scenes with unilateral or compliant contacts run event-driven (`run.rs`: the same path as
//! `sim run`), the reference and every variant alike. The errors are still measured on the
//! shared output grid, so they include the shift of the event times: a sample between a run's
//! event and the reference's compares states on either side of the jump. Positions are
//! continuous at events (impacts jump velocities only), so the hand error there is about
//! `|Δt_event| × |v_hand|` and stays a fair trajectory error; the link works `W_j` jump at an
//! impact by the rotors' impulsive work, so the energy error near an event can reach that jump.
//! Hence the event times are compared directly as well: [`Row::max_event_time_error_s`], the
//! largest `|t − t_ref|` over events matched by contact and kind (the k-th event of a contact
//! and kind in the run with the k-th of the same contact and kind in the reference), and
//! [`Row::unmatched_events`], how many events of the run or the reference had no partner
//! (a bounce more or less, a missed lift-off). Both are absent (`None`) when neither the run
//! nor the reference had an event (every bilateral scene).

use std::time::Instant;

use nalgebra::Vector3;
use serde::Serialize;

use crate::dynamics::contact::{ContactEventKind, ContactMode};
use crate::dynamics::forward::{ConstraintSolver, MassMatrixMethod};
use crate::dynamics::motor::Electrical;
use crate::error::{RunError, SceneError};
use crate::ode::OutputLevel;
use crate::scene::spec::{AdaptiveSpec, IntegratorSpec, PerJoint, SceneSpec};
use crate::scene::{Run, Scene};

/// One configuration to measure: a variation of the scene, validated like any scene.
#[derive(Clone, Debug)]
pub struct Variant {
    /// Series name in the table and the plot (method + model).
    pub series: String,
    /// The rung on the ladder: a tolerance or a step, as text.
    pub setting: String,
    /// The scene with this integrator, mass-matrix method, constraint solver and model.
    pub scene: Scene,
}

/// The measurement of one variant.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    pub series: String,
    pub setting: String,
    pub status: String,
    /// Best wall time of the simulation, s.
    pub wall_s: f64,
    pub rhs_evals: u64,
    pub steps: u64,
    pub rejected: u64,
    /// max over samples of |r_hand − r_hand,ref|, m.
    pub max_hand_error_m: f64,
    /// max over samples and joints of |W_j − W_j,ref| and |E_j − E_j,ref|, J.
    pub max_link_energy_error_j: f64,
    /// max over samples and contacts of |C|, m (event-driven runs: contacts in touch only).
    pub max_drift_m: f64,
    /// Largest |r_hand| of the reference, m: the hand error above which the run is `diverged`.
    pub reach_m: f64,
    /// Simulated time / wall time.
    pub speed_vs_real_time: f64,
    /// max over matched contact events of |t − t_ref|, s (module doc); `None` without events.
    pub max_event_time_error_s: Option<f64>,
    /// Events of the run or of the reference without a partner of the same contact and kind;
    /// `None` without events.
    pub unmatched_events: Option<u64>,
}

/// The reference trajectory: per sample, the hand and every W_j, E_j; and the contact events
/// (time, contact index, kind), in time order.
pub struct Reference {
    pub hand: Vec<Vector3<f64>>,
    pub energies: Vec<Vec<f64>>,
    pub events: Vec<(f64, usize, ContactEventKind)>,
    /// Wall time the reference run took, s: sets the variants' budget ([`Reference::budget`]).
    pub wall_s: f64,
}

fn collect(scene: &Scene, run: &Run, budget: crate::run::Budget) -> Result<(Reference, crate::integrate::Stats, f64), RunError> {
    let mut r = Reference { hand: Vec::new(), energies: Vec::new(), events: Vec::new(), wall_s: 0.0 };
    let mut drift = 0.0f64;
    let t0 = Instant::now();
    // the hand, the quadratures and C need forward kinematics only, not a right-hand side
    let rep = crate::run::simulate_outputs(scene, run, budget, OutputLevel::Kinematic, |o| {
        r.hand.push(o.hand);
        let mut e = o.link_work.clone();
        e.extend_from_slice(&o.electric_energy);
        r.energies.push(e);
        drift = o.constraint_position.iter().enumerate().filter(|&(k, _)| held(o, k)).fold(drift, |m, (_, c)| m.max(c.abs()));
        r.events.extend(o.events.iter().map(|e| (e.t, e.contact, e.kind)));
        Ok(())
    })?;
    r.wall_s = t0.elapsed().as_secs_f64();
    Ok((r, rep.stats, drift))
}

/// Whether contact `k`'s position is a constraint at this sample, so that `|C|` is drift: every
/// contact of a bilateral run (`o.contacts` empty); in an event-driven run only a contact in
/// touch (sticking, sliding, bilateral) — an open contact's gap is no error. (A compliant
/// contact has no discrete mode: at `OutputLevel::Kinematic`, which precision uses, the
/// outputs carry no forces and report its stored mode, always separated, so its penetration
/// never counts as drift — rightly, as penetration is the compliant model's state, not a
/// constraint violation. Only at the Full level is a compliant contact with f_n > 0 reported
/// as sliding.)
fn held(o: &crate::ode::Outputs, k: usize) -> bool {
    o.contacts.get(k).is_none_or(|c| c.mode != ContactMode::Separated)
}

/// An adaptive `method` at `rtol` (atol = rtol / 100), steps of at most `h_max`.
fn adaptive(method: &str, rtol: f64, h_max: Option<f64>) -> IntegratorSpec {
    IntegratorSpec::adaptive(method, rtol, h_max).expect("a method of the ladder")
}

/// `scene` with `integrator`, `mass_matrix`, `solver` and `reduce` applied to its spec.
fn variation(
    scene: &Scene,
    integrator: IntegratorSpec,
    mass_matrix: MassMatrixMethod,
    solver: ConstraintSolver,
    reduce: impl FnOnce(&mut SceneSpec),
) -> Result<Scene, SceneError> {
    scene.vary(|s| {
        s.integrator = integrator;
        s.dynamics.mass_matrix = mass_matrix;
        s.dynamics.constraint_solver = solver;
        reduce(s);
    })
}

/// Why the reference run could not be made (`method`: the reference's method and tolerance).
#[derive(Debug, thiserror::Error)]
pub enum ReferenceError {
    #[error("the reference scene ({method}): {source}")]
    Scene { method: &'static str, source: SceneError },
    #[error("the reference run ({method}): {source}")]
    Run { method: &'static str, source: RunError },
}

/// The tight reference: Dormand–Prince at rtol 1e-12, atol 1e-14, steps of at most the output
/// interval, CRBA + Schur. A run with a frictional rigid contact is referenced by RODAS5P at the
/// same tolerances instead: a slowly sliding contact is stiff (the direction of isotropic Coulomb
/// friction turns at a rate that grows without bound as the slip stops), where an explicit method
/// crawls at its stability limit.
pub fn reference(scene: &Scene, run: &Run) -> Result<Reference, ReferenceError> {
    let adaptive = AdaptiveSpec { rtol: 1e-12, atol: 1e-14, h_max: Some(1.0 / scene.output_rate), max_steps: None };
    let method = reference_method(scene, run);
    let spec = if method.starts_with("rodas5p") {
        let r = crate::scene::spec::RosenbrockSpec { rtol: adaptive.rtol, atol: adaptive.atol, h_max: adaptive.h_max, max_steps: None, jacobian_reuse: None, step_size_control: None };
        IntegratorSpec::Rodas5p(r)
    } else {
        IntegratorSpec::Dopri45(adaptive)
    };
    let s = variation(scene, spec, MassMatrixMethod::Crba, ConstraintSolver::Schur, |_| {}).map_err(|source| ReferenceError::Scene { method, source })?;
    Ok(collect(&s, run, reference_budget()).map_err(|source| ReferenceError::Run { method, source })?.0)
}

/// The reference's budget: the default wall time of a run ([`crate::limits::DEFAULT_MAX_WALL_TIME`],
/// 600 s) with no pace judgment before it (`judge_pace_after` = the whole budget,
/// [`crate::integrate::too_slow`]). The pace rule projects from the run's start, and the
/// reference's start is its slowest part (on the unilateral scene, rodas5p at rtol 1e-12:
/// the first 0.03 % of 0.3 s cost ~11 % of its work), so on a loaded machine the rule stopped a
/// reference that completes in ~8–25 s ("stopped at t = 0.000024283 s … more than twice its
/// limit of 600 s"), which made the command's result depend on the load. The bound is the
/// deadline alone.
pub fn reference_budget() -> crate::run::Budget {
    let wall_time = crate::limits::DEFAULT_MAX_WALL_TIME;
    crate::run::Budget { wall_time, judge_pace_after: wall_time }
}

/// The method and tolerance of [`reference`] for `run` of `scene`: "rodas5p, rtol 1e-12" when
/// the run has a frictional rigid contact, else "dopri45, rtol 1e-12".
pub fn reference_method(scene: &Scene, run: &Run) -> &'static str {
    let frictional = run.contacts.iter().any(|&k| {
        matches!(scene.contact_models()[k].model, crate::dynamics::contact::ContactModel::Unilateral { friction, .. } if friction > 0.0)
    });
    if frictional {
        "rodas5p, rtol 1e-12"
    } else {
        "dopri45, rtol 1e-12"
    }
}

/// Measure one variant against the reference.
pub fn measure(v: &Variant, run: &Run, reference: &Reference, repeats: usize) -> Row {
    let s = &v.scene;
    let mut row = Row {
        series: v.series.clone(),
        setting: v.setting.clone(),
        status: "ok".into(),
        wall_s: f64::INFINITY,
        rhs_evals: 0,
        steps: 0,
        rejected: 0,
        max_hand_error_m: f64::NAN,
        max_link_energy_error_j: f64::NAN,
        max_drift_m: f64::NAN,
        reach_m: reference.reach_m(),
        speed_vs_real_time: f64::NAN,
        max_event_time_error_s: None,
        unmatched_events: None,
    };
    // timing: the simulation alone, best of `repeats`
    for _ in 0..repeats.max(1) {
        let t0 = Instant::now();
        match crate::run::simulate_outputs(s, run, reference.budget(), OutputLevel::Kinematic, |_| Ok(())) {
            Ok(rep) => {
                row.wall_s = row.wall_s.min(t0.elapsed().as_secs_f64());
                row.rhs_evals = rep.stats.rhs_evals;
                row.steps = rep.stats.steps;
                row.rejected = rep.stats.rejected;
            }
            Err(e) => {
                row.status = format!("failed: {e}");
                return row;
            }
        }
    }
    row.speed_vs_real_time = s.duration / row.wall_s;
    // errors: one more run that keeps the samples
    match collect(s, run, reference.budget()) {
        Ok((r, _, drift)) => {
            row.max_drift_m = drift;
            row.max_hand_error_m = r.hand.iter().zip(&reference.hand).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
            row.max_link_energy_error_j = r
                .energies
                .iter()
                .zip(&reference.energies)
                .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs()))
                .fold(0.0, f64::max);
            (row.max_event_time_error_s, row.unmatched_events) = match_events(&r.events, &reference.events);
        }
        Err(e) => row.status = format!("failed: {e}"),
    }
    if row.status == "ok" {
        if let Some(why) = divergence(row.max_hand_error_m, row.max_link_energy_error_j, reference) {
            row.status = format!("diverged: {why}");
        }
    }
    row
}

impl Reference {
    /// What a variant may spend: 50 times the reference's wall time, at least 30 s and at most
    /// the default budget of a run. A variant slower than that is of no use in a work–precision
    /// diagram (the reference is the tightest run), and a method that crawls (an explicit method
    /// on a stiff sliding contact) fails in bounded time instead of after the full budget.
    ///
    /// The pace is judged only once a variant has run as long as the reference did (at least
    /// [`crate::integrate::PACE_AFTER`]): the reference's wall time was measured under the same
    /// load, so the rule scales with it, and a variant that has not outlasted the tightest run
    /// is not slow; before, a variant with a slow start (as the reference's, see
    /// [`reference_budget`]) was judged after 5 s whatever the load.
    pub fn budget(&self) -> crate::run::Budget {
        let limit = crate::limits::DEFAULT_MAX_WALL_TIME.as_secs_f64();
        let s = (50.0 * self.wall_s).clamp(30.0, limit);
        let judge = crate::integrate::PACE_AFTER.max(std::time::Duration::from_secs_f64(self.wall_s.min(s)));
        crate::run::Budget { wall_time: std::time::Duration::from_secs_f64(s), judge_pace_after: judge }
    }

    /// Largest |r_hand| over the reference samples, m.
    pub fn reach_m(&self) -> f64 {
        self.hand.iter().map(|h| h.norm()).fold(0.0, f64::max)
    }

    /// Largest |E_j| or |W_j| of the reference, J, at least 1 J.
    pub fn energy_scale_j(&self) -> f64 {
        self.energies.iter().flatten().fold(1.0, |m, e| m.max(e.abs()))
    }
}

/// The event times of a run against the reference's (module doc): the largest `|t − t_ref|`
/// over events paired by contact and kind in order, and the number without a partner; `None`s
/// when neither has an event.
pub fn match_events(run: &[(f64, usize, ContactEventKind)], reference: &[(f64, usize, ContactEventKind)]) -> (Option<f64>, Option<u64>) {
    if run.is_empty() && reference.is_empty() {
        return (None, None);
    }
    let mut worst = 0.0f64;
    let mut unmatched = 0u64;
    // every (contact, kind) that occurs in either list
    let mut keys: Vec<(usize, ContactEventKind)> = Vec::new();
    for &(_, c, k) in run.iter().chain(reference) {
        if !keys.contains(&(c, k)) {
            keys.push((c, k));
        }
    }
    for key in keys {
        let times = |list: &[(f64, usize, ContactEventKind)]| -> Vec<f64> { list.iter().filter(|e| (e.1, e.2) == key).map(|e| e.0).collect() };
        let (a, b) = (times(run), times(reference));
        for (x, y) in a.iter().zip(&b) {
            worst = worst.max((x - y).abs());
        }
        unmatched += a.len().abs_diff(b.len()) as u64;
    }
    (Some(worst), Some(unmatched))
}

/// Why a run with these max errors against `reference` has diverged, or `None` (module docs).
pub fn divergence(hand_error_m: f64, energy_error_j: f64, reference: &Reference) -> Option<String> {
    if !hand_error_m.is_finite() || !energy_error_j.is_finite() {
        return Some("non-finite hand or energy".into());
    }
    let reach = reference.reach_m();
    if hand_error_m > reach {
        return Some(format!("hand error {hand_error_m:.1e} m > reach {reach:.2} m"));
    }
    let e = reference.energy_scale_j();
    if energy_error_j > e {
        return Some(format!("energy error {energy_error_j:.1e} J > {e:.2e} J"));
    }
    None
}

/// The recommendation for a requested max hand error: the cheapest `ok` run within it by wall
/// time, and the one with the fewest right-hand sides (work that does not depend on the load).
#[derive(Clone, Debug)]
pub struct Recommendation<'r> {
    pub by_wall: &'r Row,
    pub by_rhs: &'r Row,
}

/// The cheapest `ok` runs with `max_hand_error_m <= accuracy_m` (see [`Recommendation`]);
/// `None` if no run reaches it.
pub fn recommend(rows: &[Row], accuracy_m: f64) -> Option<Recommendation<'_>> {
    let within = || rows.iter().filter(|r| r.status == "ok" && r.max_hand_error_m <= accuracy_m);
    let by_wall = within().min_by(|a, b| a.wall_s.total_cmp(&b.wall_s))?;
    let by_rhs = within().min_by_key(|r| r.rhs_evals)?;
    Some(Recommendation { by_wall, by_rhs })
}

/// The default ladder for a scene: RK4 over steps, Dormand–Prince over tolerances, the
/// paper-style baseline (Walker–Orin + the full block solve + RK4), and the model reductions
/// that apply (quasi-static motors when the scene has inductance). Every variant is the scene's
/// spec changed and validated again.
pub fn default_ladder(scene: &Scene) -> Result<Vec<Variant>, SceneError> {
    use ConstraintSolver::{Kkt, Schur};
    use MassMatrixMethod::{Crba, WalkerOrin};
    let h_out = Some(1.0 / scene.output_rate);
    // the stiff methods may take steps far longer than the output interval; so may dopri45,
    // up to its stability limit
    let h_long = Some(scene.duration / 10.0);
    let mut v = Vec::new();
    let mut push = |series: &str, setting: String, spec: IntegratorSpec, mm, solver, reduce: &dyn Fn(&mut SceneSpec)| -> Result<(), SceneError> {
        let scene = variation(scene, spec, mm, solver, reduce)?;
        v.push(Variant { series: series.into(), setting, scene });
        Ok(())
    };
    let none = &|_: &mut SceneSpec| {};
    for tol in [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10] {
        push("dopri45", format!("rtol {tol:.0e}"), adaptive("dopri45", tol, h_out), Crba, Schur, none)?;
    }
    for tol in [1e-4, 1e-6, 1e-8] {
        push("dopri45 (h_max free)", format!("rtol {tol:.0e}"), adaptive("dopri45", tol, h_long), Crba, Schur, none)?;
    }
    for tol in [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9] {
        push("rosenbrock (structured J)", format!("rtol {tol:.0e}"), adaptive("rosenbrock", tol, h_long), Crba, Schur, none)?;
    }
    for tol in [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10] {
        push("rodas5p (exact J)", format!("rtol {tol:.0e}"), adaptive("rodas5p", tol, h_long), Crba, Schur, none)?;
    }
    for tol in [1e-4, 1e-6, 1e-8] {
        push("rodas5p (h_max = output interval)", format!("rtol {tol:.0e}"), adaptive("rodas5p", tol, h_out), Crba, Schur, none)?;
    }
    for tol in [1e-4, 1e-6, 1e-8] {
        let mut spec = adaptive("rodas5p", tol, h_long);
        if let IntegratorSpec::Rodas5p(r) = &mut spec {
            r.jacobian_reuse = Some(3);
        }
        push("rodas5p (J kept 3 steps)", format!("rtol {tol:.0e}"), spec, Crba, Schur, none)?;
    }
    for tol in [1e-4, 1e-6, 1e-8] {
        push("rodas4 (exact J)", format!("rtol {tol:.0e}"), adaptive("rodas4", tol, h_long), Crba, Schur, none)?;
    }
    for tol in [1e-4, 1e-6, 1e-8] {
        push("imex (circuits implicit)", format!("rtol {tol:.0e}"), adaptive("imex", tol, h_long), Crba, Schur, none)?;
    }
    for h in [5e-4, 2e-4, 1e-4, 5e-5, 2e-5] {
        push("rk4", format!("h {h:.0e} s"), IntegratorSpec::rk4(h), Crba, Schur, none)?;
    }
    for h in [5e-4, 2e-4, 1e-4, 5e-5, 2e-5] {
        push("paper baseline (walker-orin + kkt + rk4)", format!("h {h:.0e} s"), IntegratorSpec::rk4(h), WalkerOrin, Kkt, none)?;
    }
    if scene.drives.electrical == Electrical::Inductive {
        // the quasi-static reduction: L = 0 on every motor, no current state
        let quasi_static = &|s: &mut SceneSpec| {
            s.motor.inductance = PerJoint::All(0.0);
            s.initial.current = PerJoint::All(0.0);
        };
        for tol in [1e-6, 1e-8, 1e-10] {
            push("dopri45, L = 0 (quasi-static)", format!("rtol {tol:.0e}"), adaptive("dopri45", tol, h_out), Crba, Schur, quasi_static)?;
        }
    }
    Ok(v)
}

/// Per series, the cheapest run whose max hand error is at most `target_m`.
pub fn cheapest_within<'r>(rows: &'r [Row], target_m: f64) -> Vec<&'r Row> {
    let mut best: Vec<&Row> = Vec::new();
    for r in rows.iter().filter(|r| r.status == "ok" && r.max_hand_error_m <= target_m) {
        match best.iter_mut().find(|b| b.series == r.series) {
            Some(b) if r.wall_s < b.wall_s => *b = r,
            Some(_) => {}
            None => best.push(r),
        }
    }
    best.sort_by(|a, b| a.wall_s.total_cmp(&b.wall_s));
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(series: &str, status: &str, wall_s: f64, rhs_evals: u64, hand: f64) -> Row {
        Row {
            series: series.into(),
            setting: "s".into(),
            status: status.into(),
            wall_s,
            rhs_evals,
            steps: 0,
            rejected: 0,
            max_hand_error_m: hand,
            max_link_energy_error_j: 0.0,
            max_drift_m: 0.0,
            reach_m: 2.0,
            speed_vs_real_time: 1.0,
            max_event_time_error_s: None,
            unmatched_events: None,
        }
    }

    /// A reference hand at 1.5 m and 2.0 m from the origin, energies up to 40 J.
    fn reference() -> Reference {
        Reference {
            hand: vec![Vector3::new(1.5, 0.0, 0.0), Vector3::new(0.0, 2.0, 0.0)],
            energies: vec![vec![1.0, -40.0], vec![3.0, 12.0]],
            events: Vec::new(),
            wall_s: 1.0,
        }
    }

    // Drift counts every contact of a bilateral run (no contact outputs), and in an
    // event-driven run only the contacts in touch: an open contact's gap is not an error.
    #[test]
    fn drift_counts_only_held_contacts() {
        use crate::dynamics::contact::ContactOutput;
        let mut o = crate::ode::Outputs { constraint_position: vec![1e-9, 0.3], ..Default::default() };
        assert!(held(&o, 0) && held(&o, 1));
        let c = |mode| ContactOutput { mode, ..Default::default() };
        o.contacts = vec![c(ContactMode::Sticking), c(ContactMode::Separated)];
        assert!(held(&o, 0) && !held(&o, 1));
        o.contacts = vec![c(ContactMode::Sliding), c(ContactMode::Bilateral)];
        assert!(held(&o, 0) && held(&o, 1));
    }

    // Events are paired by contact and kind in order: the largest time difference over the
    // pairs, and the count of events without a partner (here one extra impact at contact 1).
    #[test]
    fn events_are_matched_by_contact_and_kind() {
        use ContactEventKind::{Impact, LiftOff};
        assert_eq!(match_events(&[], &[]), (None, None));
        let reference = [(0.5, 0, LiftOff), (0.7, 1, Impact), (0.9, 1, Impact)];
        let run = [(0.5 + 2e-9, 0, LiftOff), (0.7 - 5e-9, 1, Impact), (0.9 + 1e-9, 1, Impact), (0.95, 1, Impact)];
        let (worst, unmatched) = match_events(&run, &reference);
        assert!((worst.unwrap() - 5e-9).abs() < 1e-15, "{worst:?}");
        assert_eq!(unmatched, Some(1));
        // a lift-off is never paired with an impact, nor contact 0 with contact 1
        let (worst, unmatched) = match_events(&[(0.5, 1, LiftOff)], &[(0.5, 0, LiftOff)]);
        assert_eq!((worst, unmatched), (Some(0.0), Some(2)));
    }

    // The bounds of the module docs: the reach (2 m here) and the energy scale (40 J here);
    // a run at the bounds is not diverged, one just past either is, and so is a NaN.
    #[test]
    fn divergence_bounds_are_the_reach_and_the_energy_scale() {
        let r = reference();
        assert_eq!(r.reach_m(), 2.0);
        assert_eq!(r.energy_scale_j(), 40.0);
        assert_eq!(divergence(2.0, 40.0, &r), None);
        assert_eq!(divergence(1e-6, 1e-3, &r), None);
        let hand = divergence(4.9, 1.0, &r).unwrap();
        assert!(hand.contains("hand error 4.9e0 m > reach 2.00 m"), "{hand}");
        let energy = divergence(1e-3, 4.5e9, &r).unwrap();
        assert!(energy.contains("energy error 4.5e9 J"), "{energy}");
        assert!(divergence(f64::NAN, 0.0, &r).unwrap().contains("non-finite"));
        assert!(divergence(0.0, f64::INFINITY, &r).unwrap().contains("non-finite"));
    }

    // The recommendation: among ok runs within the request, the fastest and the fewest RHS
    // (here different runs); diverged or failed runs never, even when "within"; nothing
    // within the request -> None.
    #[test]
    fn recommendation_is_the_cheapest_ok_run_within_the_request() {
        let rows = vec![
            row("a", "ok", 0.010, 900, 5e-7),
            row("b", "ok", 0.008, 1200, 9e-7),
            row("c", "ok", 0.001, 100, 2e-6),
            row("d", "diverged: hand error", 0.0001, 10, 1e-9),
            row("e", "failed: x", 0.0001, 10, 1e-9),
        ];
        let rec = recommend(&rows, 1e-6).unwrap();
        assert_eq!(rec.by_wall.series, "b");
        assert_eq!(rec.by_rhs.series, "a");
        let rec = recommend(&rows, 1e-5).unwrap();
        assert_eq!((rec.by_wall.series.as_str(), rec.by_rhs.series.as_str()), ("c", "c"));
        assert!(recommend(&rows, 1e-7).is_none());
    }
}
