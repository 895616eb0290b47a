//! Gear Coulomb friction and efficiency, and the supply (issue 26, items 3 and 4), against
//! closed forms written by hand in this file:
//!
//! - a joint with Coulomb gear friction coasting to a stop: `ω(t) = ω0 − τ_c t / I` until
//!   `t* = I ω0 / τ_c`, where it sticks at `θ* = θ0 + I ω0² / (2 τ_c)` (the stop located as an
//!   event to 1e-9 s, the angle to 1e-9 relative), the kinetic energy all booked as gear loss;
//! - a lead-screw drive lifting a load at a constant voltage, `η K_m i = m g + τ_c`, and lowering
//!   it while regenerating, `K_m i / η_b = m g − τ_c` (steady currents to 1e-9 relative), the
//!   change of power direction at the closed-form time, and the supply's energies against the
//!   hand integrals of the two exponential phases: without regeneration the supply delivers
//!   `∫ max(p, 0) dt` and the brake resistor takes the rest; on a bus of efficiency η_s that
//!   regenerates, `E_s = E₊ / η_s + η_s E₋`;
//! - the energy balance closing with every new term (gear loss, supply identity) to 1e-9 of E on
//!   the small arm with every feature on, at tight tolerance.

#![allow(clippy::result_large_err)] // the sinks return RunError, as `sim::run`'s

use std::f64::consts::PI;

use sim::dynamics::gear_friction::GearMode;
use sim::integrate::EventSettings;
use sim::ode::{ArmSystem, Outputs};
use sim::scene::spec::{BusSpec, GearFrictionSpec, PerJoint, PerJointFlag, SupplySpec};
use sim::scene::{Scene, SceneSpec};

const G: f64 = 9.81;

fn resting() -> Scene {
    Scene::load(std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/checks/resting.json"))).unwrap()
}

/// Every output sample of a run, integrated as `sim` does.
pub(crate) fn samples(scene: &Scene, run: &str) -> Vec<Outputs> {
    let run = scene.run(run).unwrap().clone();
    let mut out = Vec::new();
    sim::run::simulate(scene, &run, |o| {
        out.push(o.clone());
        Ok(())
    })
    .unwrap();
    out
}

/// The gear log of a run, integrated as `sim` does (the scene's integrator, default event
/// settings).
pub(crate) fn gear_log(scene: &Scene, run: &str) -> Vec<sim::ode::GearEvent> {
    let run = scene.run(run).unwrap().clone();
    let mut sys = ArmSystem::new(scene, &run);
    let y0 = sys.initial_state();
    scene
        .integrator()
        .integrate_hybrid(&mut sys, &y0, scene.spec().duration, 1.0 / scene.spec().output_rate, None, EventSettings::default(), |_, _, _| Ok(()))
        .unwrap();
    sys.gear_events().to_vec()
}

/// The resting arm's yaw about z at q = 0 (rods along +x), by hand from its URDF: link1's
/// I_zz, link2 `m l²/12 + m (l/2)²` (2 kg, 0.4 m), link3 `m l²/12 + m (0.4 + l/2)²` (1 kg, 0.3 m).
const YAW_INERTIA: f64 = 0.000625 + (0.02666666666666667 + 2.0 * 0.2 * 0.2) + (0.0075 + 1.0 * 0.55 * 0.55);

#[test]
fn a_joint_with_coulomb_gear_friction_coasts_to_a_stop_at_the_closed_form_time_and_angle() {
    let (w0, tau_c, theta0) = (2.0, 1.0, 0.1);
    let scene = resting()
        .vary(|s| {
            s.duration = 1.5;
            s.joint_damping = PerJoint::All(0.0);
            s.passive = vec!["joint1".into()];
            s.initial.q = sim::scene::spec::InitialQ::Values(PerJoint::Each(vec![theta0, 0.0, 0.0]));
            s.initial.qd = PerJoint::Each(vec![w0, 0.0, 0.0]);
            s.gear_friction = Some(GearFrictionSpec { coulomb: Some(PerJoint::Each(vec![tau_c, 0.0, 0.0])), breakaway: None, stribeck_velocity: None, efficiency: None, back_efficiency: None });
            s.integrator = sim::scene::spec::IntegratorSpec::Dopri45(sim::scene::spec::AdaptiveSpec { rtol: 1e-12, atol: 1e-14, h_max: None, max_steps: None });
        })
        .unwrap();
    let i = YAW_INERTIA;
    let (t_stop, theta_stop) = (i * w0 / tau_c, theta0 + i * w0 * w0 / (2.0 * tau_c));
    // the stop, located as an event
    let log = gear_log(&scene, "resting");
    let stops: Vec<_> = log.iter().filter(|e| e.joint == 0 && e.mode == GearMode::Stick).collect();
    assert_eq!(stops.len(), 1, "{log:?}");
    assert!((stops[0].t - t_stop).abs() < 1e-9, "stop at {} s, closed form {t_stop} s", stops[0].t);
    // every sample against the closed form; after the stop the joint is at rest exactly
    let out = samples(&scene, "resting");
    let e0 = 0.5 * i * w0 * w0;
    for o in &out {
        let (q, w) = if o.t < t_stop { (theta0 + w0 * o.t - 0.5 * tau_c / i * o.t * o.t, w0 - tau_c / i * o.t) } else { (theta_stop, 0.0) };
        assert!((o.q[0] - q).abs() < 1e-9 * theta_stop, "t = {}: q {} vs {q}", o.t, o.q[0]);
        assert!((o.qd[0] - w).abs() < 1e-9 * w0, "t = {}: q' {} vs {w}", o.t, o.qd[0]);
        assert_eq!(o.gear_stuck[0], o.t >= t_stop, "t = {}", o.t);
        if o.t >= t_stop {
            assert_eq!(o.qd[0], 0.0, "t = {}: not at rest", o.t);
        }
        // the kinetic energy lost so far is the gear loss, and the balance closes
        let lost = e0 - 0.5 * i * w * w;
        assert!((o.loss_gear - lost).abs() < 1e-9 * e0, "t = {}: E_g {} vs {lost}", o.t, o.loss_gear);
        assert!(o.balance_residual.abs() < 1e-9 * e0, "t = {}: residual {}", o.t, o.balance_residual);
    }
}

/// A lead screw (5 mm per turn) lifting a 2 kg slider along z.
const LIFT_URDF: &str = r#"<robot name="lift"><link name="base"/>
<joint name="screw" type="prismatic"><parent link="base"/><child link="slider"/><axis xyz="0 0 1"/><limit lower="-1e4" upper="1e4" effort="1e4" velocity="1e3"/></joint>
<link name="slider"><inertial><mass value="2"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>"#;

const MASS: f64 = 2.0;
const K_T: f64 = 0.05;
const R: f64 = 1.0;
const I_M: f64 = 1e-6;
const TAU_C: f64 = 2.0;
const ETA: f64 = 0.7;
const ETA_B: f64 = 0.5;
const V: f64 = 24.0;

fn ratio() -> f64 {
    2.0 * PI / 0.005
}

/// The lift with the PD saturated at ±V: the target is 1000 m away (`target` sign), so the
/// drive applies a constant voltage.
fn lift(target: f64, supply: Option<SupplySpec>) -> Scene {
    let json = format!(
        r#"{{"name":"lift","urdf":"lift.urdf","gravity":[0,0,-9.81],"duration":0.3,"output_rate":1000,"joint_damping":0,
        "motor":{{"torque_constant":{K_T},"resistance":{R},"inductance":0,"rotor_inertia":{I_M},"gear_ratio":{k},"gear_damping":0,"voltage_limit":{V}}},
        "controller":{{"kp":1000,"kd":0}},"hand":{{"link":"slider"}},
        "target":{{"kind":"joint-spline","waypoints":[{{"t":0,"q":[{target}]}},{{"t":1,"q":[{target}]}}]}},
        "initial":{{"q":0}},
        "integrator":{{"method":"dopri45","rtol":1e-12,"atol":1e-14}},
        "runs":[{{"name":"lift","contacts":[]}}]}}"#,
        k = ratio()
    );
    let scene = Scene::from_json(&json, "lift.json", |_| Ok(LIFT_URDF.to_string())).unwrap();
    scene
        .vary(|s: &mut SceneSpec| {
            s.gear_friction = Some(GearFrictionSpec {
                coulomb: Some(PerJoint::All(TAU_C)),
                breakaway: None,
                stribeck_velocity: None,
                efficiency: Some(PerJoint::All(ETA)),
                back_efficiency: Some(PerJoint::All(ETA_B)),
            });
            s.supply = supply;
        })
        .unwrap()
}

#[test]
fn a_drive_lifts_and_lowers_a_load_with_the_hand_currents_of_both_power_directions() {
    let km = K_T * ratio();
    // lifting: the motor drives the load, η K_m i = m g + τ_c
    let out = samples(&lift(1000.0, None), "lift");
    let last = out.last().unwrap();
    let i_lift = (MASS * G + TAU_C) / (ETA * km);
    assert!((last.current[0] - i_lift).abs() < 1e-9 * i_lift, "lifting: i = {} A, hand {i_lift} A", last.current[0]);
    assert!((last.qd[0] - (V - R * i_lift) / km).abs() < 1e-9, "lifting speed {}", last.qd[0]);
    // lowering against the motor's −V: the load drives it, K_m i / η_b = m g − τ_c
    let out = samples(&lift(-1000.0, None), "lift");
    let last = out.last().unwrap();
    let i_lower = ETA_B * (MASS * G - TAU_C) / km;
    assert!((last.current[0] - i_lower).abs() < 1e-9 * i_lower, "lowering: i = {} A, hand {i_lower} A", last.current[0]);
    assert!(last.voltage[0] * last.current[0] < 0.0, "lowering at −V regenerates: p = {}", last.voltage[0] * last.current[0]);
    // the balance with the gear loss, at every sample
    for o in &out {
        assert!(o.balance_residual.abs() < 1e-9 * o.electric_energy[0].abs().max(1.0), "t = {}: {}", o.t, o.balance_residual);
    }
}

/// The lowering run in closed form: two exponential phases of `u = q̇` (quasi-static current
/// `i = (v − K_m u)/R`, `M_J u̇ = c K_m i + τ_c − m g` with c = η driving, 1/η_b back-driving),
/// switching where i = 0 (u = v/K_m). Returns (t1, E₊ = ∫₀^t1 p, E₋ = ∫_t1^T p).
fn lowering_by_hand(t_end: f64) -> (f64, f64, f64) {
    let km = K_T * ratio();
    let m_j = MASS + I_M * ratio() * ratio();
    let v = -V;
    let phase = |c: f64| {
        let a = (c * km * v / R + TAU_C - MASS * G) / m_j;
        let b = -c * km * km / (R * m_j);
        (a, b)
    };
    // x(t) of u̇ = a + b u from (x0, u0)
    let x_of = |a: f64, b: f64, u0: f64, t: f64| {
        let u_inf = -a / b;
        u_inf * t + (u0 - u_inf) * ((b * t).exp() - 1.0) / b
    };
    let (a1, b1) = phase(ETA);
    let u1 = v / km;
    let u_inf1 = -a1 / b1;
    let t1 = ((u1 - u_inf1) / (0.0 - u_inf1)).ln() / b1;
    let x1 = x_of(a1, b1, 0.0, t1);
    let (a2, b2) = phase(1.0 / ETA_B);
    let x2 = x1 + x_of(a2, b2, u1, t_end - t1);
    let e_plus = v / R * (v * t1 - km * x1);
    let e_minus = v / R * (v * (t_end - t1) - km * (x2 - x1));
    (t1, e_plus, e_minus)
}

#[test]
fn a_regenerating_joints_supply_energy_matches_the_hand_integral() {
    let (t1, e_plus, e_minus) = lowering_by_hand(0.3);
    assert!(e_plus > 0.0 && e_minus < 0.0, "{e_plus} {e_minus}: the case does not test");
    // the change of power direction, located as an event at the closed-form time
    let no_regen = lift(-1000.0, Some(SupplySpec { regeneration: Some(PerJointFlag::All(false)), bus: None }));
    let log = gear_log(&no_regen, "lift");
    let flip = log.iter().find(|e| matches!(e.mode, GearMode::Slide { driving: false, .. })).expect("a change to back-driving");
    assert!((flip.t - t1).abs() < 1e-9, "back-driving from {} s, closed form {t1} s", flip.t);
    // without regeneration: the supply delivers E₊, the brake resistor takes −E₋
    let last = samples(&no_regen, "lift").pop().unwrap();
    let s = last.supply.unwrap();
    let scale = e_plus.abs() + e_minus.abs();
    assert!((s.energy - e_plus).abs() < 1e-9 * scale, "supply {} J, hand {e_plus} J", s.energy);
    assert!((s.dumped + e_minus).abs() < 1e-9 * scale, "dumped {} J, hand {} J", s.dumped, -e_minus);
    assert!(s.regenerated == 0.0 && s.residual.abs() < 1e-12 * scale, "{s:?}");
    assert!((last.electric_energy[0] - (e_plus + e_minus)).abs() < 1e-9 * scale);
    // a regenerating drive on a bus of 0.9 that regenerates: E_s = E₊/0.9 + 0.9 E₋
    let bus = lift(-1000.0, Some(SupplySpec { regeneration: None, bus: Some(BusSpec { efficiency: Some(0.9), regeneration: true }) }));
    let s = samples(&bus, "lift").pop().unwrap().supply.unwrap();
    assert!((s.energy - (e_plus / 0.9 + 0.9 * e_minus)).abs() < 1e-9 * scale, "supply {} J", s.energy);
    assert!((s.regenerated + 0.9 * e_minus).abs() < 1e-9 * scale, "regenerated {} J", s.regenerated);
    assert!((s.loss - (e_plus / 0.9 - e_plus - 0.1 * e_minus)).abs() < 1e-9 * scale && s.dumped == 0.0);
    // the same bus without regeneration dumps the surplus
    let dump = lift(-1000.0, Some(SupplySpec { regeneration: None, bus: Some(BusSpec { efficiency: Some(0.9), regeneration: false }) }));
    let s = samples(&dump, "lift").pop().unwrap().supply.unwrap();
    assert!((s.energy - e_plus / 0.9).abs() < 1e-9 * scale && (s.dumped + e_minus).abs() < 1e-9 * scale, "{s:?}");
}

/// The small arm with every new feature on (Stribeck gear friction with efficiencies, two
/// drives without regeneration on a bus that dumps): the balance with the gear loss, and the
/// supply identity, at every sample, to 1e-9 of the electric energy drawn, at rtol 1e-12.
#[test]
fn the_energy_balance_closes_with_every_new_term() {
    let small = Scene::load(std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/small/small.json"))).unwrap();
    let scene = small
        .vary(|s| {
            s.gear_friction = Some(GearFrictionSpec {
                coulomb: Some(PerJoint::All(0.05)),
                breakaway: Some(PerJoint::All(0.08)),
                stribeck_velocity: Some(PerJoint::All(0.05)),
                efficiency: Some(PerJoint::All(0.8)),
                back_efficiency: Some(PerJoint::All(0.6)),
            });
            s.supply = Some(SupplySpec { regeneration: Some(PerJointFlag::Each(vec![true, false, true, false])), bus: Some(BusSpec { efficiency: Some(0.95), regeneration: false }) });
            s.integrator = sim::scene::spec::IntegratorSpec::Dopri45(sim::scene::spec::AdaptiveSpec { rtol: 1e-12, atol: 1e-14, h_max: None, max_steps: None });
        })
        .unwrap();
    for run in ["elbow", "free"] {
        let out = samples(&scene, run);
        let mut drawn = 0.0;
        for w in out.windows(2) {
            let p = |o: &Outputs| o.electric_power.iter().map(|x| x.abs()).sum::<f64>();
            drawn += 0.5 * (w[1].t - w[0].t) * (p(&w[0]) + p(&w[1]));
        }
        let last = out.last().unwrap();
        assert!(last.loss_gear > 0.0 && last.supply.unwrap().dumped > 0.0, "{run}: the features do nothing: {:?}", last.supply);
        for o in &out {
            assert!(o.balance_residual.abs() <= 1e-9 * drawn, "{run}, t = {}: residual {} of {drawn} J", o.t, o.balance_residual);
            let s = o.supply.unwrap();
            assert!(s.residual.abs() <= 1e-12 * drawn, "{run}, t = {}: supply identity {}", o.t, s.residual);
        }
        eprintln!("{run}: E = {:.6} J, supply {:.6} J, dumped {:.6} J, gear loss {:.6} J", last.electric_energy.iter().sum::<f64>(), last.supply.unwrap().energy, last.supply.unwrap().dumped, last.loss_gear);
    }
}

/// The recording: `/supply` every sample (energy non-decreasing without regeneration, the last
/// one the hand integral) and the `energy_terms` record with the supply's and the gears' totals;
/// a scene without a supply has no `/supply` topic and none of those keys.
#[test]
fn the_supply_and_the_gear_loss_are_recorded() {
    let (_, e_plus, e_minus) = lowering_by_hand(0.3);
    let scale = e_plus.abs() + e_minus.abs();
    let dir = tempfile::tempdir().unwrap();
    for (with_supply, name) in [(true, "supply"), (false, "plain")] {
        let supply = with_supply.then_some(SupplySpec { regeneration: Some(PerJointFlag::All(false)), bus: None });
        let scene = lift(-1000.0, supply);
        let path = dir.path().join(format!("{name}.mcap"));
        sim::run::run_to_file(&scene, scene.run("lift").unwrap(), &path, |_| {}).unwrap();
        let rec = schemas::read_recording(&path).unwrap();
        let terms: schemas::EnergyTermsRecord = rec.record_opt().unwrap().expect("energy_terms (the scene has gear friction)");
        assert!(terms.gear_loss.unwrap() > 0.0, "{terms:?}");
        if !with_supply {
            assert!(rec.read::<schemas::SupplyState>().is_err() && terms.supply_energy.is_none(), "{name}: {terms:?}");
            continue;
        }
        let supply: Vec<(f64, schemas::SupplyState)> = rec.read().unwrap();
        assert_eq!(supply.len(), 301, "one message per sample");
        assert!(supply.windows(2).all(|w| w[1].1.energy >= w[0].1.energy - 1e-15), "the energy delivered without regeneration never falls");
        let last = &supply.last().unwrap().1;
        assert!((last.energy - e_plus).abs() < 1e-9 * scale && (last.dumped + e_minus).abs() < 1e-9 * scale, "{last:?}");
        assert!(last.power == 0.0 && last.bus_power == 0.0, "regenerating at the end: the drive clips to 0 W: {last:?}");
        assert_eq!(terms.supply_energy, Some(last.energy));
        assert_eq!((terms.supply_dumped, terms.supply_regenerated), (Some(last.dumped), Some(0.0)));
    }
}
