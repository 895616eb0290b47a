//! Speed against error: run one scene with every method over a ladder of tolerances or steps
//! (and with each model reduction) against a tight reference run of the same scene, and
//! measure wall time, work (RHS evaluations, steps, rejections) and error (max hand error,
//! worst per-link energy error, max constraint drift). A work–precision diagram in the sense of
//! Hairer & Wanner, *Solving ODEs II*, §IV.10.
//!
//! All runs share the output grid, so errors are compared sample by sample; wall time is the
//! best of `repeats` runs without recording (the simulation itself, with the per-sample
//! outputs at [`OutputLevel::Kinematic`]: the hand, the quadratures and C, as the errors need).

use std::time::Instant;

use nalgebra::Vector3;
use serde::Serialize;

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
    /// max over samples and contacts of |C|, m.
    pub max_drift_m: f64,
    /// Simulated time / wall time.
    pub speed_vs_real_time: f64,
}

/// The reference trajectory: per sample, the hand and every W_j, E_j.
pub struct Reference {
    pub hand: Vec<Vector3<f64>>,
    pub energies: Vec<Vec<f64>>,
}

fn collect(scene: &Scene, run: &Run) -> Result<(Reference, crate::integrate::Stats, f64), RunError> {
    let mut r = Reference { hand: Vec::new(), energies: Vec::new() };
    let mut drift = 0.0f64;
    // the hand, the quadratures and C need forward kinematics only, not a right-hand side
    let rep = crate::run::simulate_outputs(scene, run, Default::default(), OutputLevel::Kinematic, |o| {
        r.hand.push(o.hand);
        let mut e = o.link_work.clone();
        e.extend_from_slice(&o.electric_energy);
        r.energies.push(e);
        drift = o.constraint_position.iter().fold(drift, |m, c| m.max(c.abs()));
        Ok(())
    })?;
    Ok((r, rep.stats, drift))
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

/// Why the reference run could not be made.
#[derive(Debug, thiserror::Error)]
pub enum ReferenceError {
    #[error("the reference scene (dopri45, rtol 1e-12): {0}")]
    Scene(#[from] SceneError),
    #[error("the reference run (dopri45, rtol 1e-12): {0}")]
    Run(#[from] RunError),
}

/// The tight reference: Dormand–Prince at rtol 1e-12, atol 1e-14, steps of at most the output
/// interval, CRBA + Schur.
pub fn reference(scene: &Scene, run: &Run) -> Result<Reference, ReferenceError> {
    let spec = IntegratorSpec::Dopri45(AdaptiveSpec { rtol: 1e-12, atol: 1e-14, h_max: Some(1.0 / scene.output_rate), max_steps: None });
    let s = variation(scene, spec, MassMatrixMethod::Crba, ConstraintSolver::Schur, |_| {})?;
    Ok(collect(&s, run)?.0)
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
        speed_vs_real_time: f64::NAN,
    };
    // timing: the simulation alone, best of `repeats`
    for _ in 0..repeats.max(1) {
        let t0 = Instant::now();
        match crate::run::simulate_outputs(s, run, Default::default(), OutputLevel::Kinematic, |_| Ok(())) {
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
    match collect(s, run) {
        Ok((r, _, drift)) => {
            row.max_drift_m = drift;
            row.max_hand_error_m = r.hand.iter().zip(&reference.hand).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
            row.max_link_energy_error_j = r
                .energies
                .iter()
                .zip(&reference.energies)
                .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs()))
                .fold(0.0, f64::max);
        }
        Err(e) => row.status = format!("failed: {e}"),
    }
    row
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
