//! Every drive feature of issue 26 on at once — datasheet drives with the two-node thermal
//! model, gear Coulomb/Stribeck friction with both efficiencies, and a supply without
//! regeneration on a shared bus — on the paper arm: how every method converges, the energy
//! balance at every sample, and the coupled stick decisions of the closed chains.

#![allow(clippy::result_large_err)] // the sinks return RunError, as in convergence.rs

use sim::scene::spec::{AdaptiveSpec, GearFrictionSpec, IntegratorSpec};
use sim::scene::Scene;

use crate::convergence::slope;
use crate::drives_support::{assert_blocks_match, assert_rodas_differences, dumping_bus, gears, lift};
use crate::thermal::fast_thermal;

/// `fast_thermal` (thermal.rs: the paper's motor as a datasheet, winding time constant 0.2 s)
/// with the gears and the supply on.
fn everything(integrator: IntegratorSpec, duration: f64) -> Scene {
    fast_thermal(integrator)
        .vary(|s| {
            s.duration = duration;
            s.gear_friction = Some(gears());
            s.supply = Some(dumping_bus());
        })
        .unwrap()
}

/// The hand at every sample and the right-hand sides (a failed run: one NaN sample, printed).
fn trace(scene: &Scene, run: &str) -> (Vec<nalgebra::Vector3<f64>>, u64) {
    let run = scene.run(run).unwrap().clone();
    let mut h = Vec::new();
    match sim::run::simulate(scene, &run, |o| {
        h.push(o.hand);
        Ok(())
    }) {
        Ok(rep) => (h, rep.stats.rhs_evals),
        Err(e) => {
            eprintln!("ERR {e}");
            (vec![nalgebra::Vector3::new(f64::NAN, 0.0, 0.0)], 0)
        }
    }
}

fn dopri(rtol: f64) -> IntegratorSpec {
    IntegratorSpec::Dopri45(AdaptiveSpec { rtol, atol: rtol * 1e-2, h_max: None, max_steps: None })
}

/// The convergence harness of `convergence.rs` (the same bands as `thermal.rs`: error ∝ rtol
/// ± 0.15 for dopri45, rosenbrock, imex, rodas5p and rodas4; rk4 below) with every feature on, over 0.3 s of
/// the paper arm's open-chain run, whose first 11 ms alone hold 40 gear mode changes
/// (breakaways, stops, power reversals on 9 of the 10 joints) and the supply's sign changes,
/// each located on the method's dense output.
///
/// At t = 11.825 ms joint 2 reaches its breakaway torque while joints 4 and others stick; the
/// consistent modes there are joint 2 sticking and joint 4 sliding (the joints' modes are
/// decided together, `ode/drive_modes.rs`). Taken one joint at a time, as before, a state
/// error of 1e-9 chose another sequence and every method ended 6.04e-5 m from its reference at
/// every rtol (a plateau, error ∝ rtol^0); now each method takes the reference's sequence and
/// the error falls with rtol over the whole 0.3 s (measured slopes 0.92, 0.99, 0.93).
///
/// RODAS5P and RODAS4 (classical Rosenbrock methods: their order needs the exact Jacobian,
/// which they take by forward differences) in the same band over rtol 1e-6 … 1e-9: measured
/// 1.08 and 1.03 (4.8e-10 … 2.6e-13 m, 3.6e-10 … 3.0e-13 m). With the increment
/// `sqrt(eps) max(|y_j|, atol / rtol)` (1.5e-10 for an angle or a speed near 0) the
/// differences' rounding error, up to 1e-4 of a row, gave RODAS4 rtol^0.55 (an error that
/// stalled at 1.2e-11, 4.9e-12 m at rtol 1e-8, 1e-9); the arm now states its components'
/// scale and its rounding noise (`ode/jacobian.rs`, `ArmSystem::difference_increment`).
///
/// rk4 with the Stribeck term (v_s = 0.05 rad/s): slope 4 ± 0.3 over h = 5e-5, 2.5e-5, 1.25e-5 s
/// and the first 20 ms (measured 4.05: 1.87e-9, 5.62e-11, 6.77e-12 m). At the harness's h = 2e-4,
/// 1e-4 s the steps do not resolve the Stribeck curve (a joint at |q̈| ≈ 300–500 rad/s² crosses
/// v_s in 0.1–0.2 ms) and the located mode changes drift from the reference's (measured h^3.13
/// over 2e-4 … 5e-5 s; h^3.84 there with v_s = 0.5 rad/s; `explanation/drives-and-heat.md`).
#[test]
fn every_method_keeps_its_order_with_every_drive_feature_on() {
    let dur = 0.3;
    let reference_scene = everything(IntegratorSpec::Dopri45(AdaptiveSpec { rtol: 1e-13, atol: 1e-15, h_max: Some(1e-4), max_steps: None }), dur);
    let (reference, _) = trace(&reference_scene, "no-elbow");
    assert_eq!(reference.len(), 301);
    // the interval is not smooth: the gears change modes in it, on most joints, two of them at
    // one instant at 11.825 ms
    let log = crate::gear_supply::gear_log(&reference_scene, "no-elbow");
    let moving: Vec<_> = log.iter().filter(|e| e.t > 0.0).collect();
    let joints: std::collections::BTreeSet<usize> = moving.iter().map(|e| e.joint).collect();
    assert!(moving.len() >= 30 && joints.len() >= 8, "{} gear events on {joints:?}", moving.len());
    let together: Vec<_> = moving.iter().filter(|e| (e.t - 0.011825).abs() < 1e-6).map(|e| (e.joint, e.mode)).collect();
    assert!(together.len() >= 2, "the decision at 11.825 ms: {together:?}");
    let err = |h: &[nalgebra::Vector3<f64>]| h.iter().zip(&reference).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
    for (method, tols) in [
        ("dopri45", &[1e-6, 1e-7, 1e-8, 1e-9, 1e-10][..]),
        ("rosenbrock", &[1e-6, 1e-7, 1e-8, 1e-9][..]),
        ("imex", &[1e-6, 1e-7, 1e-8, 1e-9, 1e-10][..]),
        ("rodas5p", &[1e-6, 1e-7, 1e-8, 1e-9][..]),
        ("rodas4", &[1e-6, 1e-7, 1e-8, 1e-9][..]),
    ] {
        let e: Vec<f64> = tols.iter().map(|&tol| err(&trace(&everything(IntegratorSpec::adaptive(method, tol, Some(0.1)).unwrap(), dur), "no-elbow").0)).collect();
        let q = slope(tols, &e);
        eprintln!("{method}: error ~ rtol^{q:.3} ({e:?})");
        assert!((q - 1.0).abs() <= 0.15, "{method}: error ~ rtol^{q:.2} ({e:?})");
    }
    // rk4 (fixed step, events located on its cubic Hermite interpolant) with the Stribeck term:
    // h^4 once its steps resolve the Stribeck curve (below)
    let steps = [5e-5, 2.5e-5, 1.25e-5];
    let e: Vec<f64> = steps.iter().map(|&h| err(&trace(&everything(IntegratorSpec::rk4(h), 0.02), "no-elbow").0)).collect();
    let p = slope(&steps, &e);
    eprintln!("rk4 with Stribeck: error ~ h^{p:.3} ({e:?})");
    assert!((p - 4.0).abs() <= 0.3, "rk4: error ~ h^{p:.2} ({e:?})");
}

/// rk4 keeps its order h^4 (± 0.3, the harness's band) with every drive feature on but the
/// Stribeck term — Coulomb and static gear friction with both efficiencies, the thermal model,
/// a supply without regeneration on a dumping bus — over the first 20 ms of the paper arm's
/// open chain, which hold the start-up's cascade of breakaways and stops and the joint
/// decision at 11.8 ms (measured h^3.96: 1.39e-7, 8.8e-9, 5.7e-10 m).
#[test]
fn rk4_keeps_its_order_with_coulomb_gears_and_every_other_drive_feature() {
    let dur = 0.02;
    let coulomb = |i: IntegratorSpec| everything(i, dur).vary(|s| s.gear_friction = Some(GearFrictionSpec { stribeck_velocity: None, ..gears() })).unwrap();
    let reference_scene = coulomb(IntegratorSpec::Dopri45(AdaptiveSpec { rtol: 1e-13, atol: 1e-15, h_max: Some(1e-4), max_steps: None }));
    let (reference, _) = trace(&reference_scene, "no-elbow");
    assert_eq!(reference.len(), 21);
    let log = crate::gear_supply::gear_log(&reference_scene, "no-elbow");
    assert!(log.iter().filter(|e| e.t > 0.0).count() >= 20, "{} gear events", log.len());
    let err = |h: &[nalgebra::Vector3<f64>]| h.iter().zip(&reference).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
    let steps = [2e-4, 1e-4, 5e-5];
    let e: Vec<f64> = steps.iter().map(|&h| err(&trace(&coulomb(IntegratorSpec::rk4(h)), "no-elbow").0)).collect();
    let p = slope(&steps, &e);
    eprintln!("rk4 without Stribeck: error ~ h^{p:.3} ({e:?})");
    assert!((p - 4.0).abs() <= 0.3 && e[2] < 1e-8, "rk4: error ~ h^{p:.2} ({e:?})");
}

/// The energy balance with every term of issue 26 — R(T_w) in the copper loss, the gear loss
/// E_g, the supply's identity — closes at every sample to 1e-9 of the electric energy drawn
/// (Σ ∫ |i v| dt), at rtol 1e-12, on the full paper arm: the open chain and the two-elbow
/// closed chain (the one-elbow run chatters: see below), 0.3 s. Every feature does something:
/// windings warm, the gears lose energy, the brake resistor dumps some.
#[test]
fn the_energy_balance_closes_with_every_drive_feature_on() {
    let scene = everything(dopri(1e-12), 0.3);
    for run in ["no-elbow", "two-elbow"] {
        let r = scene.run(run).unwrap().clone();
        let mut out: Vec<sim::ode::Outputs> = Vec::new();
        sim::run::simulate(&scene, &r, |o| {
            out.push(o.clone());
            Ok(())
        })
        .unwrap();
        let mut drawn = 0.0;
        let p = |o: &sim::ode::Outputs| o.electric_power.iter().map(|x| x.abs()).sum::<f64>();
        let last = out.last().unwrap();
        for w in out.windows(2) {
            drawn += 0.5 * (w[1].t - w[0].t) * (p(&w[0]) + p(&w[1]));
        }
        let sup = last.supply.unwrap();
        let rise = last.winding_temperature.iter().fold(0.0f64, |a, t| a.max(t - 25.0));
        assert!(last.loss_gear > 1e-3 * drawn && sup.dumped > 0.0 && rise > 0.1, "{run}: gear loss {}, dumped {}, rise {rise} K", last.loss_gear, sup.dumped);
        let mut worst = 0.0f64;
        for o in &out {
            worst = worst.max(o.balance_residual.abs());
            assert!(o.balance_residual.abs() <= 1e-9 * drawn, "{run}, t = {}: residual {} of {drawn} J", o.t, o.balance_residual);
            let s = o.supply.unwrap();
            assert!(s.residual.abs() <= 1e-12 * drawn.max(1.0), "{run}, t = {}: supply identity {}", o.t, s.residual);
            // the heat balance E_R = heat stored + heat to the ambient
            assert!((o.loss_resistance - o.heat_stored - o.heat_to_ambient).abs() <= 1e-9 * drawn, "{run}, t = {}: heat balance", o.t);
        }
        eprintln!("{run}: drawn {drawn:.4} J, worst residual {worst:.3e} J, gear loss {:.4} J, dumped {:.4} J, rise {rise:.3} K", last.loss_gear, sup.dumped);
    }
}

/// Gear friction on every joint of the paper arm's one-elbow run (a closed chain through the
/// table): decided one joint at a time, the coupled joints' stick decisions contradicted each
/// other at t < 0.1 ms and the run stopped (`RunError::GearsChatter` naming joint7); decided
/// together (`ode/drive_modes.rs`) the run goes to its end, with the gears sticking and
/// sliding on several joints and the energy balance closing at every sample. The error that is
/// left for no consistent combination names the gears, the time and the remedy.
#[test]
fn coupled_gears_on_a_closed_chain_are_decided_together_and_run() {
    let scene = everything(dopri(1e-8), 0.3);
    let r = scene.run("one-elbow").unwrap().clone();
    let mut worst = 0.0f64;
    let mut drawn = 0.0f64;
    let mut stuck_samples = 0;
    let rep = sim::run::simulate(&scene, &r, |o| {
        worst = worst.max(o.balance_residual.abs());
        drawn = drawn.max(o.electric_energy.iter().map(|e| e.abs()).sum::<f64>());
        stuck_samples += o.gear_stuck.iter().filter(|&&s| s).count();
        Ok(())
    })
    .unwrap();
    assert_eq!(rep.samples, 301);
    assert!(stuck_samples > 0, "no joint ever sticks");
    assert!(worst <= 1e-6 * drawn, "balance residual {worst} of {drawn} J");
    let err = sim::error::RunError::GearsChatter { t: 1e-3, count: 27, window: 0.0, limit: 0, joints: "joint4, joint7".into(), breakaway: true };
    let text = err.to_string();
    for part in ["t = 0.001000000 s", "the gears of joint4, joint7 have no consistent stick/slide modes", "27 combinations", "coupled", "coulomb and breakaway 0"] {
        assert!(text.contains(part), "{part:?} not in {text}");
    }
    assert!(!text.contains("compliant"), "{text}");
    // efficiency-only gears have no Coulomb friction to leave off: the remedy says what they
    // hold and offers a breakaway torque instead
    let err = sim::error::RunError::GearsChatter { t: 1e-3, count: 27, window: 0.0, limit: 0, joints: "joint4, joint7".into(), breakaway: false };
    let text = err.to_string();
    for part in ["the gears of joint4, joint7 have no consistent stick/slide modes", "efficiency only", "nothing at zero current", "gear_friction.breakaway > 0"] {
        assert!(text.contains(part), "{part:?} not in {text}");
    }
    assert!(!text.contains("leave the Coulomb") && !text.contains("lower their breakaway"), "{text}");
}

/// The stiff methods' structured Jacobian against central differences with every drive feature
/// on at once — datasheet drives with the thermal model, gear friction (Stribeck, η 0.85,
/// η_b 0.7) and a supply on a dumping bus — on the blocks it models exactly (as
/// `stiff_methods.rs` and `thermal.rs`: each entry to 1e-7 of its size plus 1e-7 of its
/// block's scale plus the differences' rounding), at warmed windings (T_w 25 … 115 °C) and
/// currents of both signs: (a) every run of the paper arm with the RE 40 drives at rest (the
/// efficiency factor on K_m in `∂q̈/∂i`, the temperature rows, `−R' i / L`); (b) a lead screw
/// on a datasheet drive lifting a slider at 0.03 m/s (no Coriolis, no gravity stiffness: every
/// entry of its q̈ row is modelled), where the Stribeck slope enters `∂q̈/∂q̇` as well. Then
/// RODAS's forward differences (the arm's increment) over the coupled columns against the
/// central ones (`drives_support.rs`).
#[test]
fn jacobians_match_differences_with_every_drive_feature_on() {
    use std::ops::Range;
    let with_gears = |s: &mut sim::scene::SceneSpec| {
        s.gear_friction = Some(gears());
        s.supply = Some(dumping_bus());
    };
    let paper = Scene::load(std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/drives/paper_thermal.json"))).unwrap().vary(with_gears).unwrap();
    let datasheet = r#""drives":[{"joints":["screw"],"motor":"maxon-re40-148877","gearhead_data":{"reduction":1256.6370614359173}}],
        "thermal":{"ambient_temperature_c":25.0},"#;
    let lift = lift(0.001, datasheet).vary(with_gears).unwrap();
    let mut checked = 0;
    for (scene, speed) in [(&paper, 0.0), (&lift, 0.03)] {
        for run in scene.runs() {
            let mut sys = sim::ode::ArmSystem::new(scene, run);
            let l = sys.layout();
            assert!(l.ni() > 0 && l.winding_temperature().len() == l.nv && l.loss_gear().is_some() && l.supply().is_some());
            let mut y = sys.initial_state();
            for (k, v) in y[l.current()].iter_mut().enumerate() {
                *v = 0.3 * (k as f64 - 4.0);
            }
            for j in 0..l.nv {
                y[l.qd().start + j] = speed;
                y[l.winding_temperature().start + j] = 25.0 + 10.0 * j as f64;
                y[l.housing_temperature().start + j] = 25.0 + 4.0 * j as f64;
            }
            let t = 0.37;
            let (f, j, fd) = crate::stiff_methods::jacobian_and_differences(&mut sys, t, &y);
            let temps = l.winding_temperature().start..l.housing_temperature().end;
            let blocks: [(Range<usize>, Vec<Range<usize>>); 5] = [
                (l.q(), vec![l.q(), l.qd(), l.current(), temps.clone()]),
                (l.qd(), vec![l.qd(), l.current(), temps.clone()]),
                (l.current(), vec![l.q(), l.qd(), l.current(), temps.clone()]),
                (l.winding_temperature(), vec![l.q(), l.qd(), l.current(), temps.clone()]),
                (l.housing_temperature(), vec![l.q(), l.qd(), l.current(), temps.clone()]),
            ];
            let what = format!("{} run {}", scene.spec().name, run.name);
            checked += assert_blocks_match(&what, &y, &f, &j, &fd, &blocks, |_, _, _| {});
            // RODAS: its forward differences over the coupled columns, the quadratures' columns 0
            assert_rodas_differences(&mut sys, t, &y, &f, &fd, &what);
        }
    }
    assert!(checked > 1000, "{checked} entries");
}
