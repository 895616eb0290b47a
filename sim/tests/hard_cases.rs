//! The hard cases in sim/scenes/hard: each completes with its energy balance closed (to the
//! stated fraction of the electric energy), or stops with a typed error naming time and cause.
//! Durations are shortened where the full run only repeats the same physics.

use std::path::Path;

use sim::scene::spec::{IntegratorSpec, PerJoint};
use sim::scene::Scene;

fn hard(name: &str) -> Result<Scene, sim::error::SceneError> {
    Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/hard").join(format!("{name}.json")))
}

struct Result_ {
    residual_rel: f64,
    max_drift: f64,
    max_drift_first: f64,
    max_drift_last: f64,
    finite: bool,
}

fn run(scene: &Scene, run: &str) -> Result_ {
    let run = scene.run(run).unwrap().clone();
    let (mut res, mut drift, mut first, mut last, mut finite) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, true);
    let t_end = scene.duration();
    let rep = sim::run::simulate(scene, &run, |o| {
        res = res.max(o.balance_residual.abs());
        let d = o.constraint_position.iter().fold(0.0f64, |m, c| m.max(c.abs()));
        drift = drift.max(d);
        if o.t <= t_end / 6.0 {
            first = first.max(d);
        }
        if o.t >= t_end * 5.0 / 6.0 {
            last = last.max(d);
        }
        finite &= o.qdd.iter().chain(&o.normal_force).all(|x| x.is_finite());
        Ok(())
    })
    .unwrap_or_else(|e| panic!("{}: {e}", run.name));
    let e: f64 = rep.last.electric_energy.iter().sum();
    Result_ { residual_rel: res / e, max_drift: drift, max_drift_first: first, max_drift_last: last, finite }
}

/// L 100x smaller: an electrical pole near −65000 1/s; balance to 1e-6.
#[test]
fn stiff_motor() {
    let s = hard("stiff-motor").unwrap().vary(|sp| sp.duration = 0.3).unwrap();
    let paper = Scene::paper().unwrap();
    assert!(s.drives().l.iter().zip(&paper.drives().l).all(|(a, b)| (a / b - 0.01).abs() < 1e-12));
    for r in ["two-elbow", "no-elbow"] {
        assert!(run(&s, r).residual_rel <= 1e-6);
    }
}

/// PD gains x10; balance to 1e-6.
#[test]
fn gains_x10() {
    let s = hard("gains-x10").unwrap().vary(|sp| sp.duration = 1.0).unwrap();
    let paper = Scene::paper().unwrap();
    let (gains, paper) = (&s.spec().controller, &paper.spec().controller);
    for (a, b) in [(&gains.kp, &paper.kp), (&gains.kd, &paper.kd)] {
        assert!(matches!((a, b), (PerJoint::All(a), PerJoint::All(b)) if *a == 10.0 * b), "{a:?} against {b:?}");
    }
    assert!(run(&s, "two-elbow").residual_rel <= 1e-6);
}

/// 60 s, twelve turns, with Baumgarte stabilisation (and a looser tolerance than the paper
/// scene, to keep the test short): the drift stays bounded — below 1e-8 m throughout and no
/// larger in the last 10 s than 10x the first 10 s — and the balance closes to 1e-6.
#[test]
fn sixty_seconds_with_bounded_drift() {
    let s = hard("long-60s").unwrap().vary(|sp| sp.integrator = IntegratorSpec::adaptive("dopri45", 1e-8, Some(1e-3)).unwrap()).unwrap();
    let r = run(&s, "two-elbow");
    assert!(r.residual_rel <= 1e-6, "{}", r.residual_rel);
    assert!(r.max_drift <= 1e-8, "drift {:e}", r.max_drift);
    assert!(r.max_drift_last <= 10.0 * r.max_drift_first.max(1e-14), "first {:e} last {:e}", r.max_drift_first, r.max_drift_last);
}

/// 60 s, twelve turns, of the paper scene at reference accuracy (Dormand–Prince rtol 1e-10, the
/// scene file's own setting) without stabilisation: eq 15 alone. Its drift is the integral of the
/// acceleration-level error, so it can grow at most quadratically in time; from the bound at that
/// tolerance (|C| < 1e-13 m over 5 s; measured 1.4e-14 m) that gives (60/5)² × 1e-13 m = 1.44e-11 m over 60 s (measured
/// 1.4e-13 m: it grows about linearly). The balance closes to 1e-11 of E, as on the paper scene
/// (measured 2.2e-13).
#[test]
fn sixty_seconds_without_stabilisation() {
    let s = hard("long-60s-plain").unwrap();
    assert_eq!(s.duration(), 60.0);
    assert_eq!(s.spec().dynamics.stabilization, sim::dynamics::forward::Stabilization::None);
    let r = run(&s, "two-elbow");
    assert!(r.finite);
    assert!(r.max_drift <= (60.0f64 / 5.0).powi(2) * 1e-13, "drift {:e}", r.max_drift);
    assert!(r.residual_rel <= 1e-11, "{:e}", r.residual_rel);
}

/// The target touches 0.9999 of the reach of the planar pair: the farthest point of the circle,
/// found by sampling it every 0.1 ms through the IK, is 0.9999 of joint 9's reach (to 1e-6).
/// The near-singular IK gives large but finite joint rates; the run completes and balances to
/// 1e-6.
#[test]
fn near_the_reach_limit() {
    let s = hard("reach-limit").unwrap();
    let (model, ik, circle) = (s.model(), s.ik().unwrap(), s.circle().unwrap());
    let mut data = sim::dynamics::Data::new(model);
    let (mut q, mut qd) = (vec![0.0; model.nv], vec![0.0; model.nv]);
    let joint9 = model.bodies.iter().position(|b| b.joint == "joint9").unwrap();
    let farthest = (0..50_000)
        .map(|k| {
            let t = circle.period * k as f64 / 50_000.0;
            let r = circle.position(t);
            ik.solve(&r, &circle.velocity(t), &mut q, &mut qd).unwrap();
            sim::dynamics::kinematics::forward_kinematics(model, &mut data, &q);
            (r - data.x_world_body[joint9].translation.vector).norm()
        })
        .fold(0.0, f64::max);
    assert!((farthest / ik.reach() - 0.9999).abs() < 1e-6, "farthest target at {} of the reach", farthest / ik.reach());
    let s = s.vary(|sp| sp.duration = 0.5).unwrap();
    let r = run(&s, "two-elbow");
    assert!(r.finite && r.residual_rel <= 1e-6);
}

/// A 5 cm step of the target at t = 2.5 s: the adaptive integrator steps through the jump.
#[test]
fn target_step() {
    let s = hard("target-step").unwrap().vary(|sp| sp.duration = 3.0).unwrap();
    assert!(run(&s, "two-elbow").residual_rel <= 1e-6);
}

/// The same elbow twice (and with a third row): no NaN, constraints hold (1e-8 m over 1 s:
/// the regularisation leaves an O(1e-10) relative acceleration residual that integrates to a
/// few nm), balance 1e-6.
#[test]
fn redundant_contacts() {
    let s = hard("redundant-contacts").unwrap().vary(|sp| sp.duration = 1.0).unwrap();
    for name in ["elbow4-twice", "three-rows"] {
        let r = run(&s, name);
        assert!(r.finite, "{name}");
        assert!(r.max_drift <= 1e-8, "{name}: drift {:e}", r.max_drift);
        assert!(r.residual_rel <= 1e-6, "{name}: {}", r.residual_rel);
    }
}

/// An elbow 1 cm above its table at t = 0 is rejected before running, naming the contact,
/// the violation and what to do.
#[test]
fn inconsistent_start_is_rejected() {
    let err = hard("inconsistent-start").unwrap_err().to_string();
    assert!(err.contains("inconsistent-start.json"), "{err}");
    assert!(err.contains("contacts[0]") && err.contains("elbow4"), "{err}");
    assert!(err.contains("C(q0) = 1.000e-2 m"), "{err}");
}

/// Chains of 30 and 100 joints complete and balance to 1e-6.
#[test]
fn long_chains() {
    for (name, t) in [("chain30", 0.5), ("chain100", 0.1)] {
        let s = hard(name).unwrap().vary(|sp| sp.duration = t).unwrap();
        assert_eq!(s.model().nv, if name == "chain30" { 30 } else { 100 });
        let r = run(&s, "free");
        assert!(r.finite && r.residual_rel <= 1e-6, "{name}: {}", r.residual_rel);
    }
}
