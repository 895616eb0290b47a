//! Properties that hold for every input, checked on generated inputs (proptest):
//!
//! - on random chains and branching trees (1–16 joints, random axes, placements and physically
//!   valid inertias; `dynamics::samples`), all revolute or mixed (about a third of the joints
//!   prismatic), at random states: M is symmetric positive definite,
//!   Walker–Orin's M equals CRBA's, `M q'' + bias = RNEA(q, q', q'')`, and a point's Jacobian is
//!   the derivative of its position (central differences) — 256 cases each;
//! - on random variations of the small scene (motor constants, gains, damping, gear, gravity,
//!   initial speeds) that validate: a short run completes without panic and closes its energy
//!   balance — 64 cases (each a simulation of 0.2 s).
//!
//! proptest shrinks a failure to a small case and prints its seed; tolerances are stated per
//! property.

use std::path::Path;

use nalgebra::{DMatrix, DVector};
use proptest::prelude::*;
use sim::dynamics::crba::crba;
use sim::dynamics::kinematics::{forward_kinematics, BodyPoint};
use sim::dynamics::rnea::{bias_forces, rnea};
use sim::dynamics::samples::{random_branching_tree, random_chain, random_mixed_chain, random_mixed_tree, SplitMix64};
use sim::dynamics::walker_orin;
use sim::dynamics::{Data, Model};
use sim::scene::spec::PerJoint;
use sim::scene::Scene;

/// A random chain or tree of `n` joints, revolute only or `mixed` (about a third prismatic).
fn model(n: usize, seed: u64, tree: bool, mixed: bool) -> Model {
    match (tree, mixed) {
        (false, false) => random_chain(n, seed),
        (true, false) => random_branching_tree(n, seed),
        (false, true) => random_mixed_chain(n, seed),
        (true, true) => random_mixed_tree(n, seed),
    }
}

fn state(nv: usize, seed: u64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut rng = SplitMix64(seed ^ 0x5EED);
    (rng.vector(nv, -3.0, 3.0), rng.vector(nv, -2.0, 2.0), rng.vector(nv, -5.0, 5.0))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// M is symmetric (to 1e-12 of its largest entry) and positive definite (Cholesky exists and
    /// its smallest pivot is positive), from CRBA and from Walker–Orin alike, and the two agree
    /// to 1e-12 of the largest entry (both are exact algorithms; rounding only).
    #[test]
    fn mass_matrix_is_spd_and_both_algorithms_agree(n in 1usize..=16, seed in any::<u64>(), tree in any::<bool>(), mixed in any::<bool>()) {
        let m = model(n, seed, tree, mixed);
        let mut data = Data::new(&m);
        let (q, _, _) = state(m.nv, seed);
        let a = crba(&m, &mut data, &q).clone();
        let b = walker_orin::mass_matrix(&m, &mut data, &q).clone();
        let scale = a.amax().max(1e-300);
        prop_assert!((&a - a.transpose()).amax() <= 1e-12 * scale);
        prop_assert!((&a - &b).amax() <= 1e-12 * scale, "CRBA vs Walker-Orin: {:e}", (&a - &b).amax() / scale);
        let chol = nalgebra::Cholesky::new(a.clone());
        prop_assert!(chol.is_some(), "not positive definite");
        let l = chol.unwrap().l();
        prop_assert!((0..m.nv).all(|k| l[(k, k)] > 0.0));
    }

    /// Inverse dynamics by RNEA equals `M q'' + h(q, q')` from CRBA and RNEA at q'' = 0, to 1e-10
    /// of the largest term (a sum of up to 16 chained products of rounded values).
    #[test]
    fn crba_plus_bias_is_rnea(n in 1usize..=16, seed in any::<u64>(), tree in any::<bool>(), mixed in any::<bool>()) {
        let m = model(n, seed, tree, mixed);
        let mut data = Data::new(&m);
        let (q, qd, qdd) = state(m.nv, seed);
        let mass = crba(&m, &mut data, &q).clone();
        let bias = bias_forces(&m, &mut data, &q, &qd).clone();
        let tau = rnea(&m, &mut data, &q, &qd, &qdd, &m.gravity).clone();
        let lhs = &mass * DVector::from_vec(qdd) + &bias;
        let scale = tau.amax().max(lhs.amax()).max(1.0);
        prop_assert!((&lhs - &tau).amax() <= 1e-10 * scale, "{:e}", (&lhs - &tau).amax() / scale);
    }

    /// A point's Jacobian (3 x nv) is the derivative of its world position: central differences
    /// with h = 1e-6 rad (m for a prismatic joint) agree to 1e-8 m/rad (their error h² |p'''| ≈ 1e-12 m plus rounding
    /// ε |p| / h ≈ 1e-10 m).
    #[test]
    fn point_jacobian_is_the_derivative_of_the_position(n in 1usize..=16, seed in any::<u64>(), tree in any::<bool>(), mixed in any::<bool>()) {
        let m = model(n, seed, tree, mixed);
        let mut data = Data::new(&m);
        let (q, _, _) = state(m.nv, seed);
        let mut rng = SplitMix64(seed.rotate_left(17));
        let point = BodyPoint { body: Some((rng.next_u64() % m.nv as u64) as usize), p_body: nalgebra::Vector3::new(rng.range(-0.2, 0.2), rng.range(-0.2, 0.2), rng.range(0.0, 0.4)) };
        let mut jac = DMatrix::zeros(3, m.nv);
        forward_kinematics(&m, &mut data, &q);
        point.jacobian(&m, &data, &mut jac);
        let h = 1e-6;
        for j in 0..m.nv {
            let mut qp = q.clone();
            qp[j] += h;
            forward_kinematics(&m, &mut data, &qp);
            let plus = point.position(&data);
            qp[j] -= 2.0 * h;
            forward_kinematics(&m, &mut data, &qp);
            let minus = point.position(&data);
            let col = (plus - minus) / (2.0 * h);
            prop_assert!((col - jac.column(j)).amax() < 1e-8, "column {j}");
        }
    }
}

fn small() -> Scene {
    Scene::load(Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/small/small.json"))).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// A scene that validates simulates: 0.2 s of the small scene's free run with random motor
    /// constants, gains, damping, gear, gravity and initial speeds (a random fraction of such
    /// scenes is rejected by validation, which is its own test) completes without panic or
    /// error and closes the energy balance to 1e-6 of the energy moved (the integrator's rtol
    /// is 1e-9 on states of that size; the stiffest draws ring at ~1e5 1/s).
    #[test]
    fn a_scene_that_validates_simulates_and_closes_its_energy_balance(
        k in 0.05f64..0.5, r in 0.3f64..5.0, l in 1e-4f64..1e-2, im in 1e-6f64..1e-3,
        gear in 1.0f64..50.0, dm in 0.0f64..0.05, d in 0.0f64..2.0,
        kp in 0.0f64..800.0, kd in 0.0f64..40.0, g in -12.0f64..0.0, qd0 in -1.0f64..1.0,
    ) {
        let Ok(scene) = small().vary(|s| {
            s.duration = 0.2;
            s.motor.torque_constant = PerJoint::All(k);
            s.motor.resistance = PerJoint::All(r);
            s.motor.inductance = PerJoint::All(l);
            s.motor.rotor_inertia = PerJoint::All(im);
            s.motor.gear_ratio = PerJoint::All(gear);
            s.motor.gear_damping = PerJoint::All(dm);
            s.joint_damping = PerJoint::All(d);
            s.controller.kp = PerJoint::All(kp);
            s.controller.kd = PerJoint::All(kd);
            s.gravity = [0.0, 0.0, g];
            s.initial.qd = PerJoint::Each(vec![qd0, 0.0, 0.0, 0.0]);
        }) else {
            return Ok(());
        };
        let run = scene.run("free").unwrap().clone();
        let (mut worst, mut moved) = (0.0f64, 0.0f64);
        let rep = sim::run::simulate(&scene, &run, |o| {
            worst = worst.max(o.balance_residual.abs());
            moved = moved.max(o.electric_energy.iter().map(|e| e.abs()).sum::<f64>() + o.kinetic.abs() + o.loss_resistance);
            Ok(())
        });
        prop_assert!(rep.is_ok(), "{:?}", rep.err());
        prop_assert!(worst <= 1e-6 * moved.max(1e-3), "residual {worst:e} J of {moved:e} J");
    }
}
