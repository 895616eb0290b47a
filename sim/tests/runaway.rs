//! Every run ends: the cases that used to run for minutes with no sample and no message end
//! within seconds with a typed error that names the simulated time and says what to do
//! (issue 12). Each case is the paper scene with one value pushed out of range:
//!
//! - a nearly zero inductance (1e-9 H) with the scene's explicit integrator (dopri45): the
//!   circuits' time constant L/R ~ 1e-9 s bounds the explicit step by stability; the stiffness
//!   test of `dopri5.f` stops it ([`RunError::Stiff`], "use rosenbrock or imex");
//! - extreme joint damping (10^6 N m s/rad): the same, in the mechanics;
//! - rk4 with h = 1e-12 s: 5 10^12 steps, refused when the scene is validated
//!   (`integrator.step`, with the count);
//! - any run past its wall-time budget ([`Budget`]): [`RunError::OutOfTime`] with the time
//!   reached, recorded in the recording's result like every failure.
//!
//! Each must end (error included) within [`WALL_LIMIT`], far below the minutes they took.

use std::time::{Duration, Instant};

use schemas::RunStatus;
use serde_json::json;
use sim::error::RunError;
use sim::run::Budget;
use sim::scene::spec::PerJoint;
use sim::scene::Scene;

/// What a runaway case may take to end, in the test profile on a slow shared core.
const WALL_LIMIT: Duration = Duration::from_secs(30);

fn paper_with(edit: impl FnOnce(&mut sim::scene::SceneSpec)) -> Scene {
    Scene::paper().unwrap().vary(edit).unwrap()
}

/// Runs `scene`'s two-elbow run; the error and the wall time it took.
fn fails(scene: &Scene) -> (RunError, Duration) {
    let run = scene.run("two-elbow").unwrap().clone();
    let t0 = Instant::now();
    let err = sim::run::simulate(scene, &run, |_| Ok(())).expect_err("the run must fail");
    (err, t0.elapsed())
}

#[test]
fn a_nearly_zero_inductance_with_an_explicit_method_is_stopped_as_stiff() {
    let scene = paper_with(|s| s.motor.inductance = PerJoint::All(1e-9));
    assert_eq!(scene.integrator().method(), "dopri45");
    let (err, wall) = fails(&scene);
    eprintln!("L = 1e-9 H, dopri45: {wall:.2?}: {err}");
    assert!(matches!(err, RunError::Stiff { .. }), "{err}");
    let msg = err.to_string();
    assert!(msg.contains("stiff") && msg.contains("use rosenbrock or imex") && msg.starts_with("the integrator stopped at t = "), "{msg}");
    assert!(err.time().unwrap() < 1e-3, "detected early: {msg}");
    assert!(wall < WALL_LIMIT, "{wall:?}");
}

#[test]
fn extreme_damping_with_an_explicit_method_is_stopped_as_stiff() {
    let scene = paper_with(|s| s.joint_damping = PerJoint::All(1e6));
    let (err, wall) = fails(&scene);
    eprintln!("D = 1e6 N m s/rad, dopri45: {wall:.2?}: {err}");
    assert!(matches!(err, RunError::Stiff { .. }), "{err}");
    assert!(wall < WALL_LIMIT, "{wall:?}");
}

/// The implicit methods the message suggests do run the stiff case (1 ms of it, to keep the
/// test short).
#[test]
fn the_suggested_methods_run_the_stiff_case() {
    for method in ["rosenbrock", "imex"] {
        let scene = paper_with(|s| {
            s.motor.inductance = PerJoint::All(1e-9);
            s.duration = 1e-3;
            s.integrator = serde_json::from_value(json!({"method": method, "rtol": 1e-6, "atol": 1e-8})).unwrap();
        });
        let run = scene.run("two-elbow").unwrap().clone();
        let t0 = Instant::now();
        let rep = sim::run::simulate(&scene, &run, |_| Ok(())).unwrap_or_else(|e| panic!("{method}: {e}"));
        eprintln!("L = 1e-9 H, {method}, 1 ms: {} steps, {:.2?}", rep.stats.steps, t0.elapsed());
        assert_eq!(rep.samples, 2);
    }
}

#[test]
fn an_absurdly_small_fixed_step_is_refused_before_the_run() {
    let t0 = Instant::now();
    let err = Scene::paper().unwrap().vary(|s| s.integrator = sim::scene::spec::IntegratorSpec::rk4(1e-12)).unwrap_err();
    assert_eq!(err.field, "integrator.step");
    assert!(err.to_string().contains("gives 5.000e12 steps in duration = 5 s"), "{err}");
    assert!(t0.elapsed() < WALL_LIMIT);
}

/// A run past its wall-time budget fails with the time it reached, and its recording says so
/// (status failed, the error and its time), like any numerical failure.
#[test]
fn a_run_past_its_wall_time_fails_and_is_recorded_as_failed() {
    let scene = Scene::paper().unwrap();
    let run = scene.run("two-elbow").unwrap().clone();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("slow.mcap");
    let budget = Budget::wall_time(Duration::from_millis(200));
    let t0 = Instant::now();
    let err = sim::run::run_to_file_within(&scene, &run, &path, budget, |_| {}).unwrap_err();
    let wall = t0.elapsed();
    eprintln!("paper two-elbow within 0.2 s: {wall:.2?}: {err}");
    let RunError::OutOfTime { t, limit_s, method } = err else { panic!("{err}") };
    assert_eq!(method, "dopri45");
    assert_eq!(limit_s, 0.2);
    assert!(t > 0.0 && t < scene.duration(), "{t}");
    assert!(wall < Duration::from_secs(5), "{wall:?}");
    let msg = err.to_string();
    assert!(msg.contains("wall-time limit of 0.2 s with dopri45") && msg.contains("use rosenbrock or imex") && msg.contains("--max-wall-time"), "{msg}");
    let rec = schemas::read_recording(&path).unwrap();
    let result = rec.result().unwrap().unwrap();
    assert_eq!(result.status, RunStatus::Failed);
    assert_eq!(result.error_time_s, Some(t));
    assert!(result.error.unwrap().contains("wall-time limit"));
}

/// The step budget's error names the time, the setting and what to do.
#[test]
fn a_run_past_its_step_budget_says_when_and_what_to_do() {
    let scene = paper_with(|s| {
        s.integrator = serde_json::from_value(json!({"method": "dopri45", "rtol": 1e-10, "atol": 1e-12, "max_steps": 6000})).unwrap();
    });
    let (err, _) = fails(&scene);
    let msg = err.to_string();
    assert!(matches!(err, RunError::TooManySteps { max_steps: 6000, .. }), "{msg}");
    assert!(msg.starts_with("the integrator stopped at t = ") && msg.contains("integrator.max_steps) with dopri45") && msg.contains("use rosenbrock or imex"), "{msg}");
    // the hint fits the method: imex treats the mechanics explicitly, rosenbrock everything
    let imex = paper_with(|s| {
        s.joint_damping = PerJoint::All(1e6);
        s.integrator = serde_json::from_value(json!({"method": "imex", "rtol": 1e-6, "atol": 1e-8, "max_steps": 6000})).unwrap();
    });
    let msg = fails(&imex).0.to_string();
    assert!(msg.contains("with imex") && msg.contains("stiff mechanics, e.g. extreme damping, which imex treats explicitly: use rosenbrock"), "{msg}");
}

/// A run whose pace cannot make its budget stops when the pace is judged, not at the deadline:
/// the paper's two-elbow run stretched to 500 s (about a hundred times the wall time of the 5-s
/// run, about a minute here) with a budget of 1 s, its pace judged after 0.05 s, projects far
/// more than 2 s. Its error
/// gives the time, the projection and the flag; its recording says failed.
#[test]
fn a_run_that_cannot_make_its_budget_stops_when_its_pace_is_judged() {
    let scene = paper_with(|s| s.duration = 500.0);
    let run = scene.run("two-elbow").unwrap().clone();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("slow.mcap");
    let budget = Budget { wall_time: Duration::from_secs(1), judge_pace_after: Duration::from_millis(50) };
    let err = sim::run::run_to_file_within(&scene, &run, &path, budget, |_| {}).unwrap_err();
    let RunError::TooSlow { t, projected_s, limit_s, method } = err else { panic!("{err}") };
    assert_eq!((limit_s, method), (1.0, "dopri45"));
    assert!(projected_s > 2.0 && t > 0.0 && t < 500.0, "{projected_s} {t}");
    let msg = err.to_string();
    assert!(msg.contains("at its pace so far it would need about") && msg.contains("--max-wall-time"), "{msg}");
    let result = schemas::read_recording(&path).unwrap().result().unwrap().unwrap();
    assert_eq!(result.status, RunStatus::Failed);
    assert_eq!(result.error_time_s, Some(t));
    // with the pace judged only after the deadline, the same run ends at the deadline
    let late = Budget { wall_time: Duration::from_millis(200), judge_pace_after: Duration::from_secs(5) };
    let err = sim::run::simulate_within(&scene, &run, late, |_| Ok(())).unwrap_err();
    assert!(matches!(err, RunError::OutOfTime { .. }), "{err}");
}
