//! The stiff methods on the arm: the structured Jacobian against finite differences, the
//! Rosenbrock-W and IMEX runs against the Dormand–Prince reference, and constraint drift with
//! no stabilisation, Baumgarte and projection.

use sim::dynamics::forward::Stabilization;
use sim::integrate::{fd_jacobian, OdeJacobian, OdeSystem};
use sim::scene::{IntegratorSettings, Scene};
use sim::system::ArmSystem;

/// The exact columns of the structured Jacobian — every ∂f/∂i (the motor torque through the
/// constrained inverse inertia, and −R/L) and the ∂i̇/∂q, ∂i̇/∂q̇ rows — equal a forward-difference
/// Jacobian to 1e-4 of the largest entry (the forward difference's own error is ~3e-5 here).
#[test]
fn structured_jacobian_matches_finite_differences_where_exact() {
    let scene = Scene::paper().unwrap();
    let run = scene.run("two-elbow").unwrap().clone();
    let mut sys = ArmSystem::new(&scene, &run);
    let l = sys.layout;
    let dim = l.dim();
    let mut y = sys.initial_state();
    // a state off the start: some motion and current, still on the constraints' velocity level
    for (k, v) in y[l.current()].iter_mut().enumerate() {
        *v = 0.3 * (k as f64 - 4.0);
    }
    let t = 0.37;
    let mut f = vec![0.0; dim];
    sys.rhs(t, &y, &mut f).unwrap();
    let mut j_struct = vec![0.0; dim * dim];
    sys.jacobian(t, &y, &f, &mut j_struct).unwrap();
    let (mut sy, mut sf) = (vec![0.0; dim], vec![0.0; dim]);
    let mut j_fd = vec![0.0; dim * dim];
    fd_jacobian(&mut sys, t, &y, &f, &mut j_fd, &mut sy, &mut sf).unwrap();
    let scale = j_fd.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let check = |r: usize, c: usize| {
        let (a, b) = (j_struct[r * dim + c], j_fd[r * dim + c]);
        assert!((a - b).abs() <= 1e-4 * scale.max(1.0), "d f[{r}] / d y[{c}]: structured {a}, fd {b}");
    };
    for c in l.current() {
        for r in l.qd().chain(l.current()) {
            check(r, c);
        }
    }
    for r in l.current() {
        for c in l.q().chain(l.qd()) {
            check(r, c);
        }
    }
}

fn hand_path(scene: &Scene) -> (Vec<nalgebra::Vector3<f64>>, f64) {
    let run = scene.run("two-elbow").unwrap().clone();
    let mut hand = Vec::new();
    let mut res = 0.0f64;
    let rep = sim::run::simulate(scene, &run, |o| {
        hand.push(o.hand);
        res = res.max(o.balance_residual.abs());
        Ok(())
    })
    .unwrap();
    (hand, res / rep.last.electric_energy.iter().sum::<f64>())
}

/// Rosenbrock-W (rtol 1e-8) and IMEX (rtol 1e-8) follow the Dormand–Prince (rtol 1e-11) hand
/// path to 1e-8 m over 1 s, and close the energy balance to 1e-6.
#[test]
fn stiff_methods_agree_with_the_reference() {
    let mut scene = Scene::paper().unwrap();
    scene.duration = 1.0;
    scene.integrator = IntegratorSettings::Dopri45 { rtol: 1e-11, atol: 1e-13, h_max: 1e-3, max_steps: usize::MAX };
    let (reference, _) = hand_path(&scene);
    for integrator in [
        IntegratorSettings::Rosenbrock { rtol: 1e-8, atol: 1e-10, h_max: 0.1, max_steps: usize::MAX, jacobian_reuse: 1 },
        IntegratorSettings::Imex { rtol: 1e-8, atol: 1e-10, h_max: 0.1, max_steps: usize::MAX },
    ] {
        scene.integrator = integrator;
        let (hand, res) = hand_path(&scene);
        let err = hand.iter().zip(&reference).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
        assert!(err < 1e-8, "{integrator:?}: {err:e} m");
        assert!(res < 1e-6, "{integrator:?}: balance {res:e}");
    }
}

fn drift(scene: &Scene) -> f64 {
    let run = scene.run("two-elbow").unwrap().clone();
    let mut d = 0.0f64;
    sim::run::simulate(scene, &run, |o| {
        d = o.constraint_position.iter().fold(d, |m, c| m.max(c.abs()));
        Ok(())
    })
    .unwrap();
    d
}

/// At a loose tolerance (rtol 1e-6) over 10 s, eq 15 alone lets the elbows drift; Baumgarte
/// (α = β = 20 1/s) keeps the drift smaller, and projection after every step keeps |C| below
/// 1e-12 m.
#[test]
fn stabilisation_bounds_the_drift() {
    let mut scene = Scene::paper().unwrap();
    scene.duration = 10.0;
    scene.integrator = IntegratorSettings::Dopri45 { rtol: 1e-6, atol: 1e-8, h_max: 1e-3, max_steps: usize::MAX };
    let plain = drift(&scene);
    scene.stabilization = Stabilization::Baumgarte { alpha: 20.0, beta: 20.0 };
    let baumgarte = drift(&scene);
    scene.stabilization = Stabilization::Projection;
    let projected = drift(&scene);
    assert!(baumgarte < plain, "plain {plain:e}, baumgarte {baumgarte:e}");
    assert!(projected < 1e-12 && projected < plain, "plain {plain:e}, projected {projected:e}");
}
