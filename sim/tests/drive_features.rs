//! Every drive feature of issue 26 on at once — datasheet drives with the two-node thermal
//! model, gear Coulomb/Stribeck friction with both efficiencies, and a supply without
//! regeneration on a shared bus — on the paper arm: how every method converges, the energy
//! balance at every sample, and the coupled stick decisions of the closed chains.

#![allow(clippy::result_large_err)] // the sinks return RunError, as in convergence.rs

use sim::scene::spec::{AdaptiveSpec, BusSpec, GearFrictionSpec, IntegratorSpec, PerJoint, PerJointFlag, SupplySpec};
use sim::scene::Scene;

use crate::convergence::slope;
use crate::thermal::fast_thermal;

/// The gear law used throughout: τ_c 0.2, τ_s 0.3 N m, Stribeck speed 0.05 rad/s, η 0.85,
/// η_b 0.7 (a small gearbox's range, issue 26).
fn gears() -> GearFrictionSpec {
    GearFrictionSpec {
        coulomb: Some(PerJoint::All(0.2)),
        breakaway: Some(PerJoint::All(0.3)),
        stribeck_velocity: Some(PerJoint::All(0.05)),
        efficiency: Some(PerJoint::All(0.85)),
        back_efficiency: Some(PerJoint::All(0.7)),
    }
}

/// No regeneration in the drives, a bus of η_s 0.9 that dumps its surplus.
fn supply() -> SupplySpec {
    SupplySpec { regeneration: Some(PerJointFlag::All(false)), bus: Some(BusSpec { efficiency: Some(0.9), regeneration: false }) }
}

/// `fast_thermal` (thermal.rs: the paper's motor as a datasheet, winding time constant 0.2 s)
/// with the gears and the supply on.
fn everything(integrator: IntegratorSpec, duration: f64) -> Scene {
    fast_thermal(integrator)
        .vary(|s| {
            s.duration = duration;
            s.gear_friction = Some(gears());
            s.supply = Some(supply());
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

/// The convergence harness of `convergence.rs` (the same bands as `thermal.rs`: dopri45 N^-5,
/// rosenbrock N^-3, imex N^-4 ± 0.5; error ∝ rtol ± 0.15; rk4 below) with every feature
/// on, over the first 11 ms of the paper arm's open-chain run, which hold 40 gear mode changes
/// (breakaways, stops, power reversals on 9 of the 10 joints) and the supply's sign changes,
/// each located on the method's dense output.
///
/// Why 11 ms and not the 0.3 s of the other harnesses: at t = 11.825 ms joint 2 breaks away,
/// which frees joint 4, which lets joint 2 stick again, all at one instant. Those are
/// per-joint stick decisions of joints that one mass matrix couples, taken in sequence; a
/// state error of 1e-9 takes another sequence there (measured: rk4 with h = 2e-4 … 5e-5 ends
/// 6.03e-5 m from the reference for all three steps, a plateau, not an order; with h =
/// 2.5e-5 it takes the reference's sequence and ends 8e-11 m from it). That plateau read as
/// an order is part of the "h^3.1" measured before. Over an interval whose decisions are well
/// separated the adaptive methods keep their orders, which is what this test shows; the
/// coupled decision and rk4 (below) are TESTING.md's open items.
#[test]
fn every_method_keeps_its_order_with_every_drive_feature_on() {
    let dur = 0.011;
    let reference_scene = everything(IntegratorSpec::Dopri45(AdaptiveSpec { rtol: 1e-13, atol: 1e-15, h_max: Some(1e-4), max_steps: None }), dur);
    let (reference, _) = trace(&reference_scene, "no-elbow");
    assert_eq!(reference.len(), 12);
    // the interval is not smooth: the gears change modes in it, on most joints
    let log = crate::gear_supply::gear_log(&reference_scene, "no-elbow");
    let moving: Vec<_> = log.iter().filter(|e| e.t > 0.0).collect();
    let joints: std::collections::BTreeSet<usize> = moving.iter().map(|e| e.joint).collect();
    assert!(moving.len() >= 30 && joints.len() >= 8, "{} gear events on {joints:?}", moving.len());
    let err = |h: &[nalgebra::Vector3<f64>]| h.iter().zip(&reference).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
    // (over 0.3 s, with the thermal model on, dopri45 at every rtol from 1e-6 to 1e-10 takes
    // the other sequence at 11.8 ms than its rtol-1e-13 reference: 6.038e-5 m at all five, a
    // plateau; so the orders are measured before it)
    // every adaptive method over the 11 ms: error ∝ rtol (there the work is the events'
    // location and restarts, 40 of them, so N says little: dopri45's error falls as N^-7.7)
    for (method, tols) in [("dopri45", &[1e-6, 1e-7, 1e-8, 1e-9, 1e-10][..]), ("rosenbrock", &[1e-6, 1e-7, 1e-8, 1e-9][..]), ("imex", &[1e-6, 1e-7, 1e-8, 1e-9, 1e-10][..])] {
        let e: Vec<f64> = tols.iter().map(|&tol| err(&trace(&everything(IntegratorSpec::adaptive(method, tol, Some(0.1)).unwrap(), dur), "no-elbow").0)).collect();
        let q = slope(tols, &e);
        assert!((q - 1.0).abs() <= 0.15, "{method}: error ~ rtol^{q:.2} ({e:?})");
    }
    // rk4 (fixed step, events located on its cubic Hermite interpolant) converges, but below
    // its order: measured h^3.13 (1.45e-7, 1.54e-8, 1.89e-9 m at h = 2e-4, 1e-4, 5e-5 s), where
    // the thermal model alone and the supply alone keep h^4.0 (measured 4.00, 4.08): an open
    // item (TESTING.md), bounded here so that a further loss shows
    let steps = [2e-4, 1e-4, 5e-5];
    let e: Vec<f64> = steps.iter().map(|&h| err(&trace(&everything(IntegratorSpec::rk4(h), dur), "no-elbow").0)).collect();
    let p = slope(&steps, &e);
    assert!(p >= 2.8 && e[2] < 1e-8, "rk4: error ~ h^{p:.2} ({e:?})");
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
/// table) makes the per-joint stick decisions contradict each other at the start: the run
/// fails, exit status 1 in `sim`, with an error that names the gears, the time and what to
/// change (not the contacts' remedies); taking the Coulomb and static friction off the named
/// joint (keeping the efficiencies) runs to its end. The two-elbow and no-elbow runs do not
/// chatter (`the_energy_balance_closes_with_every_drive_feature_on`).
#[test]
fn coupled_gears_that_chatter_fail_naming_the_joints_and_the_remedy() {
    let scene = everything(dopri(1e-8), 0.3);
    let r = scene.run("one-elbow").unwrap().clone();
    let err = sim::run::simulate(&scene, &r, |_| Ok(())).unwrap_err();
    let text = err.to_string();
    let sim::error::RunError::GearsChatter { t, ref joints, .. } = err else { panic!("{text}") };
    assert!(t < 1e-4 && joints == "joint7", "{t} {joints}");
    for part in ["the gears of joint7 switched between stick and slide", "coupled", "coulomb and breakaway 0"] {
        assert!(text.contains(part), "{part:?} not in {text}");
    }
    assert!(!text.contains("compliant"), "{text}");
    let fixed = scene
        .vary(|s| {
            let mut g = gears();
            let per = |v: f64| PerJoint::Each((1..=10).map(|j| if j == 7 { 0.0 } else { v }).collect());
            g.coulomb = Some(per(0.2));
            g.breakaway = Some(per(0.3));
            s.gear_friction = Some(g);
        })
        .unwrap();
    let rep = sim::run::simulate(&fixed, &r, |_| Ok(())).unwrap();
    assert!(rep.samples == 301, "{}", rep.samples);
}
