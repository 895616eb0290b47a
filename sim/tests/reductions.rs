//! Model reductions (quasi-static motors, no friction, no gravity) against the full model.

use sim::scene::{Scene, PAPER_SCENE_JSON, PAPER_URDF};

fn paper_with(edit: impl FnOnce(&mut serde_json::Value)) -> Scene {
    let mut v: serde_json::Value = serde_json::from_str(PAPER_SCENE_JSON).unwrap();
    v["duration"] = 1.0.into();
    edit(&mut v);
    Scene::from_json(&v.to_string(), "edited paper scene", |_| Ok(PAPER_URDF.to_string())).unwrap()
}

fn final_q(scene: &Scene, run: &str) -> (Vec<f64>, f64, f64) {
    let run = scene.run(run).unwrap().clone();
    let mut worst = 0.0f64;
    let rep = sim::run::simulate(scene, &run, |o| {
        worst = worst.max(o.balance_residual.abs());
        Ok(())
    })
    .unwrap();
    (rep.last.q.clone(), worst, rep.last.electric_energy.iter().sum())
}

/// L = 0 (the "mechanical" variant, no electrical states): the state has 4n + 2 components,
/// the energy balance closes without a magnetic term (1e-6 of E), and the solution is the
/// limit of the electrical model as L -> 0: the difference in the final angles shrinks
/// linearly with L (a singular perturbation of order L/R): from L/10 to L/100 by a factor
/// 10^(1 ± 0.15), i.e. 7.1–14.1 (the observed order 1 ± 0.15, as the convergence tests state
/// orders).
#[test]
fn quasi_static_motors_are_the_small_inductance_limit() {
    let qs = paper_with(|v| v["motor"]["inductance"] = 0.0.into());
    assert_eq!(qs.drives().electrical, sim::dynamics::motor::Electrical::QuasiStatic);
    let run = qs.run("no-elbow").unwrap().clone();
    // q, q', W_j, E_j and the R, D and D_m losses: no current states
    assert_eq!(sim::ode::ArmSystem::new(&qs, &run).layout().dim(), 4 * 10 + 3);
    let (q0, res, e) = final_q(&qs, "no-elbow");
    assert!(res <= 1e-6 * e, "residual {res} of {e}");
    let diff = |l: f64| {
        let s = paper_with(|v| v["motor"]["inductance"] = l.into());
        let (q, _, _) = final_q(&s, "no-elbow");
        q.iter().zip(&q0).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max)
    };
    let (d10, d100) = (diff(0.0017 / 10.0), diff(0.0017 / 100.0));
    let order = (d10 / d100).log10();
    eprintln!("L -> 0: L/10 {d10:e}, L/100 {d100:e}, observed order {order:.3}");
    assert!((order - 1.0).abs() <= 0.15 && d100 < 1e-3, "L/10: {d10:e}, L/100: {d100:e}: order {order}");
}

/// Without friction and gravity the reduced terms are skipped and the energy still balances.
#[test]
fn frictionless_weightless_scene_balances() {
    let s = paper_with(|v| {
        v["joint_damping"] = 0.0.into();
        v["motor"]["gear_damping"] = 0.0.into();
        v["gravity"] = serde_json::json!([0.0, 0.0, 0.0]);
    });
    assert!(!s.drives().has_friction);
    let (_, res, e) = final_q(&s, "two-elbow");
    assert!(res <= 1e-6 * e, "residual {res} of {e}");
}
