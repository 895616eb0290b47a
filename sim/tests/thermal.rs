//! Datasheet drives and the motors' winding temperature (issue 26 items 1, 2): a stalled motor
//! against the two-node closed form, the energy balance and the heat balance with R(T_w), the
//! convergence orders and the stiff methods' Jacobian with the thermal model on, the limits
//! monitor on the max winding temperature, and the scene's validation of the new fields.

use std::ops::Range;
use std::path::Path;

use sim::dynamics::thermal::{step_response, ThermalParams};
use sim::ode::ArmSystem;
use sim::scene::spec::{AdaptiveSpec, IntegratorSpec};
use sim::scene::spec_drive::MotorDatasheet;
use sim::scene::Scene;

use crate::convergence::slope;
use crate::drives_support::{assert_blocks_match, assert_orders};
use crate::stiff_methods::jacobian_and_differences;

fn paper_thermal() -> Scene {
    Scene::load(Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/drives/paper_thermal.json"))).unwrap()
}

/// The RE 40's datasheet from the catalogue, edited.
fn re40(edit: impl FnOnce(&mut MotorDatasheet)) -> MotorDatasheet {
    let mut m = sim::scene::catalogue::catalogue().motor("maxon-re40-148877").unwrap().1.clone();
    edit(&mut m);
    m
}

/// One revolute joint about z (no gravity torque), its link's point (0.5, 0, 0) held on the
/// plane y = 0 by a bilateral contact: the rotor is locked at q = 0. The PD asks for q = 0.1
/// rad, so v = k_p 0.1 = 1 V for ever, and the initial current is v / R: the current stays
/// v / R and the copper loss v² / R is constant.
const STALL_URDF: &str = r#"<robot name="stall">
  <link name="base"/>
  <link name="arm"><inertial><origin xyz="0.25 0 0"/><mass value="1"/><inertia ixx="0.001" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="yaw" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="100" velocity="10"/></joint>
</robot>"#;

fn stall_scene(thermal_json: &str, motor_json: &str, current0: f64) -> Scene {
    let text = format!(
        r#"{{
  "name": "stall", "urdf": "stall.urdf", "gravity": [0, 0, -9.81], "duration": 60.0, "output_rate": 10.0,
  "joint_damping": 0.0,
  "motor": {{"torque_constant": 0.1, "resistance": 1.0, "inductance": 0.001, "rotor_inertia": 1e-5, "gear_ratio": 1.0, "gear_damping": 0.0}},
  "drives": [{{"joints": ["yaw"], "motor_data": {motor_json}}}],
  "thermal": {thermal_json},
  "controller": {{"kp": 10.0, "kd": 0.0}},
  "hand": {{"link": "arm", "offset": [0.5, 0, 0]}},
  "target": {{"kind": "joint-spline", "waypoints": [{{"t": 0, "q": [0.1]}}, {{"t": 60, "q": [0.1]}}]}},
  "initial": {{"q": [0.0], "qd": 0.0, "current": {current0}}},
  "contacts": [{{"name": "lock", "point": {{"link": "arm", "offset": [0.5, 0, 0]}}, "plane": {{"normal": [0, 1, 0], "offset": 0}}}}],
  "integrator": {{"method": "dopri45", "rtol": 1e-12, "atol": 1e-12}},
  "runs": [{{"name": "stalled", "contacts": ["lock"]}}]
}}"#
    );
    Scene::from_json(&text, "stall.json", |_| Ok(STALL_URDF.to_string())).unwrap()
}

/// A stalled motor at constant current with α = 0 (a constant copper loss P = R i²; with α ≠ 0
/// and constant voltage the problem is nonlinear: i = v / R(T_w)): the winding and housing
/// temperatures against the two-node network's closed form (`thermal::step_response`, the
/// eigen-decomposition of the linear ODE, itself checked against the ODE in the unit tests), at
/// every sample of 60 s (1.4 τ_w, 0.05 τ_s), to 1e-9 of the rise (from 5 s on; of the final
/// rise before), dopri45 at rtol 1e-12. Ambient = initial = 25 °C.
#[test]
fn a_stalled_motor_heats_as_the_two_node_closed_form() {
    let m = re40(|m| {
        m.resistance_temperature_coefficient_per_k = Some(0.0);
        m.no_load_speed_rpm = None;
        m.no_load_current_ma = None;
    });
    let (r, v) = (m.terminal_resistance_ohm, 1.0);
    let scene = stall_scene(r#"{"ambient_temperature_c": 25.0}"#, &serde_json::to_string(&m).unwrap(), v / r);
    let p: ThermalParams = scene.thermal().unwrap().params[0].unwrap();
    let heat = v * v / r;
    let (mut worst, mut worst_end): (f64, f64) = (0.0, 0.0);
    let (xw_end, xh_end) = step_response(&p, heat, 60.0);
    let mut n = 0;
    let run = scene.runs()[0].clone();
    sim::run::simulate(&scene, &run, |o| {
        // the rotor is locked and the current constant: the premise of the closed form
        assert!(o.qd[0].abs() < 1e-12 && (o.current[0] - v / r).abs() < 1e-10 * v / r, "t = {}: q' = {}, i = {}", o.t, o.qd[0], o.current[0]);
        assert!((o.copper_loss[0] - heat).abs() < 1e-10 * heat, "t = {}: P = {}, v^2 / R = {heat}, v = {}", o.t, o.copper_loss[0], o.voltage[0]);
        let (xw, xh) = step_response(&p, heat, o.t);
        let (ew, eh) = (o.winding_temperature[0] - 25.0 - xw, o.housing_temperature[0] - 25.0 - xh);
        // relative to the rise at that time from 5 s on (before, the housing's rise is under
        // 1e-4 K and the state's own rounding, 25 °C × 1e-16, is a larger part of it), and to
        // the final rise throughout
        if o.t >= 5.0 {
            worst = worst.max(ew.abs() / xw).max(eh.abs() / xh);
        }
        worst_end = worst_end.max(ew.abs() / xw_end).max(eh.abs() / xh_end);
        n += 1;
        Ok(())
    })
    .unwrap();
    assert_eq!(n, 601);
    assert!(worst < 1e-9 && worst_end < 1e-9, "largest relative error of the rises {worst:e}, of the final rises {worst_end:e}");
    // and the closed form is not trivial here: after 60 s the winding has risen by more than
    // half its rise against the housing, the housing by 2 % of its final rise
    let (xw, xh) = step_response(&p, heat, 60.0);
    assert!(xw > 0.5 * heat * p.r_winding_housing && xh > 0.02 * heat * p.r_housing_ambient, "{xw} {xh}");
}

/// With R(T_w) (α = 0.00393 /K) and constant voltage the heating slows as the winding warms
/// (i = v / R(T_w) falls); the current stays v / R(T_w) at every sample (eq 11's fixed point
/// with the resistance of the temperature reached), below the α = 0 closed form's heating.
#[test]
fn the_resistance_follows_the_winding_temperature() {
    let m = re40(|m| {
        m.no_load_speed_rpm = None;
        m.no_load_current_ma = None;
        m.thermal_time_constant_winding_s = Some(4.0);
    });
    let (r, v) = (m.terminal_resistance_ohm, 1.0);
    let scene = stall_scene(r#"{"ambient_temperature_c": 25.0}"#, &serde_json::to_string(&m).unwrap(), v / r);
    let p = scene.thermal().unwrap().params[0].unwrap();
    let run = scene.runs()[0].clone();
    let mut last = 0.0;
    sim::run::simulate(&scene, &run, |o| {
        let rt = r * (1.0 + 0.00393 * (o.winding_temperature[0] - 20.0)) / (1.0 + 0.00393 * 5.0);
        assert!((o.resistance[0] - rt).abs() < 1e-14 * rt);
        // L = 0.33 mH, R ~ 1.2 ohm: the current follows R(T_w) within a few L/R
        if o.t >= 1.0 {
            assert!((o.current[0] - v / rt).abs() < 1e-6 * v / rt, "t = {}: i = {}, v / R(T) = {}", o.t, o.current[0], v / rt);
        }
        last = o.winding_temperature[0] - 25.0;
        Ok(())
    })
    .unwrap();
    let (xw, _) = step_response(&p, v * v / r, 60.0);
    assert!(last < xw && last > 0.9 * xw, "rise {last} against {xw} at α = 0");
}

/// The energy balance closes with R(T_w) in eq 11 and the copper loss: |residual| ≤ 1e-9 of E
/// at every sample, rtol 1e-12 (the paper arm, every joint an RE 40 with GP 42 C 12:1, 1 s of
/// the no-elbow run, the one that spends the most); and the heat balance E_R = Σ C ΔT + Q_a at
/// every sample to 1e-9 of E_R.
#[test]
fn the_energy_and_heat_balances_close_with_the_thermal_model() {
    let scene = paper_thermal()
        .vary(|s| {
            s.duration = 1.0;
            s.integrator = IntegratorSpec::Dopri45(AdaptiveSpec { rtol: 1e-12, atol: 1e-12, h_max: Some(1e-3), max_steps: None });
        })
        .unwrap();
    let run = scene.run("no-elbow").unwrap().clone();
    let mut rows = Vec::new();
    let rep = sim::run::simulate(&scene, &run, |o| {
        rows.push((o.t, o.electric_energy.iter().sum::<f64>(), o.balance_residual, o.loss_resistance, o.heat_stored + o.heat_to_ambient));
        assert_eq!(o.winding_temperature.len(), 10);
        Ok(())
    })
    .unwrap();
    let e_end = rep.last.electric_energy.iter().sum::<f64>();
    let e_r = rep.last.loss_resistance;
    assert!(e_end > 100.0 && e_r > 0.5 * e_end, "E = {e_end}, E_R = {e_r}");
    for (t, _, res, er, heat) in &rows {
        assert!(res.abs() <= 1e-9 * e_end, "t = {t}: residual {res:e} of E = {e_end}");
        assert!((er - heat).abs() <= 1e-9 * e_r, "t = {t}: E_R = {er}, heat = {heat}");
    }
    // the winding warmed enough for R(T) to matter: > 1 % on the hottest joint
    let hottest = rep.last.resistance.iter().zip(scene.drives().r.iter()).map(|(a, b)| a / b - 1.0).fold(0.0, f64::max);
    assert!(hottest > 0.01, "R rose by {hottest}");
}

/// The paper arm with the paper's motor as a datasheet (K = 203 mNm/A, R = 1.1 ohm at 25 °C,
/// L = 1.7 mH, I_m = 1640 g cm², a 3:1 gear) and the RE 40's thermal data made fast (τ_w =
/// 0.2 s, τ_s = 2 s: the temperatures move within the 0.3 s of the convergence harness). The
/// paper's electrical time constant keeps the problem what `convergence.rs` measures (with the
/// RE 40's L / R = 0.28 ms dopri45's steps are bounded by stability, not accuracy, and its
/// error falls faster than N^-5).
pub(crate) fn fast_thermal(integrator: IntegratorSpec) -> Scene {
    paper_thermal()
        .vary(|s| {
            s.duration = 0.3;
            s.integrator = integrator;
            let d = &mut s.drives[0];
            d.motor = None;
            d.gearhead = None;
            d.gearhead_data = Some(sim::scene::spec_drive::GearheadDatasheet {
                reduction: 3.0,
                max_efficiency_percent: None,
                inertia_gcm2: None,
                max_continuous_torque_nm: None,
                max_intermittent_torque_nm: None,
            });
            d.motor_data = Some(re40(|m| {
                m.nominal_voltage_v = 48.0;
                m.terminal_resistance_ohm = 1.1;
                m.terminal_inductance_mh = 1.7;
                m.torque_constant_mnm_per_a = 203.0;
                m.speed_constant_rpm_per_v = None;
                m.rotor_inertia_gcm2 = 1640.0;
                m.no_load_speed_rpm = None;
                m.no_load_current_ma = None;
                m.thermal_time_constant_winding_s = Some(0.2);
                m.thermal_time_constant_motor_s = Some(2.0);
            }));
        })
        .unwrap()
}

/// One sample: the hand, the winding temperatures.
type Sample = (nalgebra::Vector3<f64>, Vec<f64>);

/// The samples of the two-elbow run, and the work.
fn trace(scene: &Scene) -> (Vec<Sample>, u64) {
    let run = scene.run("two-elbow").unwrap().clone();
    let mut h = Vec::new();
    let rep = sim::run::simulate(scene, &run, |o| {
        h.push((o.hand, o.winding_temperature.clone()));
        Ok(())
    })
    .unwrap();
    (h, rep.stats.rhs_evals)
}

/// The convergence harness of `convergence.rs` with the thermal model on (the same bands and
/// the same error, the hand's largest distance from the reference at the samples: RK4 h⁴ ±
/// 0.3; dopri45 N^-5, rosenbrock N^-3, imex N^-4, each ± 0.5; error ∝ rtol ± 0.15). R(T_w)
/// feeds back into the currents, so the temperatures are part of what converges; their own
/// error is checked to fall with the tolerance (every method's tightest run within 1e-5 K of
/// the reference, its loosest not). The winding temperatures' error alone converges faster
/// than the hand's for dopri45 (slope −6.6 measured: the temperatures are smooth integrals of
/// i²), which is why it is not mixed into the slope.
#[test]
fn every_method_keeps_its_order_with_the_thermal_model_on() {
    let (reference, _) = trace(&fast_thermal(IntegratorSpec::Dopri45(AdaptiveSpec { rtol: 1e-13, atol: 1e-15, h_max: Some(1e-4), max_steps: None })));
    // the temperatures do move: the hottest winding rises by more than 1 K in 0.3 s
    let rise = reference.last().unwrap().1.iter().fold(0.0f64, |a, t| a.max(t - 25.0));
    assert!(rise > 1.0, "rise {rise} K");
    let err = |h: &[Sample]| h.iter().zip(&reference).map(|((a, _), (b, _))| (a - b).norm()).fold(0.0, f64::max);
    let err_t = |h: &[Sample]| {
        h.iter().zip(&reference).flat_map(|((_, ta), (_, tb))| ta.iter().zip(tb).map(|(x, y)| (x - y).abs())).fold(0.0, f64::max)
    };
    let steps = [2e-4, 1e-4, 5e-5];
    let e: Vec<f64> = steps.iter().map(|&h| err(&trace(&fast_thermal(IntegratorSpec::rk4(h))).0)).collect();
    let p = slope(&steps, &e);
    assert!((p - 4.0).abs() <= 0.3, "rk4: error ~ h^{p:.2} ({e:?})");
    for (method, order, tols) in [
        ("dopri45", 5.0, &[1e-6, 1e-7, 1e-8, 1e-9, 1e-10][..]),
        ("rosenbrock", 3.0, &[1e-6, 1e-7, 1e-8, 1e-9][..]),
        ("imex", 4.0, &[1e-6, 1e-7, 1e-8, 1e-9, 1e-10][..]),
    ] {
        let mut et = Vec::new();
        let runs: Vec<(f64, f64)> = tols
            .iter()
            .map(|&tol| {
                let (h, n) = trace(&fast_thermal(IntegratorSpec::adaptive(method, tol, Some(0.1)).unwrap()));
                et.push(err_t(&h));
                (err(&h), n as f64)
            })
            .collect();
        assert!(et[et.len() - 1] < 1e-5 && et[0] > et[et.len() - 1], "{method}: temperature errors {et:?} K");
        assert_orders(method, order, tols, &runs);
    }
}

/// The structured Jacobian of the stiff methods with the thermal model on, against central
/// differences (as `stiff_methods.rs`: at rest, currents ≠ 0, each entry to 1e-7 of its size
/// plus 1e-7 of its block's scale plus the differences' rounding), on the blocks it models
/// exactly, the thermal ones included: the temperature rows against q, q̇, i and the
/// temperatures, and the current rates against the winding temperatures (−R' i / L), at
/// warmed windings (T_w = 25 … 115 °C, T_h between): every run of the paper arm with the
/// RE 40 drives.
#[test]
fn structured_jacobian_matches_differences_with_the_thermal_model_on() {
    let scene = paper_thermal();
    for run in scene.runs() {
        let mut sys = ArmSystem::new(&scene, run);
        let l = sys.layout();
        assert_eq!(l.winding_temperature().len(), l.nv);
        let mut y = sys.initial_state();
        for (k, v) in y[l.current()].iter_mut().enumerate() {
            *v = 0.3 * (k as f64 - 4.0);
        }
        for j in 0..l.nv {
            y[l.winding_temperature().start + j] = 25.0 + 10.0 * j as f64;
            y[l.housing_temperature().start + j] = 25.0 + 4.0 * j as f64;
        }
        let t = 0.37;
        let (f, j, fd) = jacobian_and_differences(&mut sys, t, &y);
        let temps = l.winding_temperature().start..l.housing_temperature().end;
        let blocks: [(Range<usize>, Vec<Range<usize>>); 4] = [
            (l.qd(), vec![l.qd(), l.current(), temps.clone()]),
            (l.current(), vec![l.q(), l.qd(), l.current(), temps.clone()]),
            (l.winding_temperature(), vec![l.q(), l.qd(), l.current(), temps.clone()]),
            (l.housing_temperature(), vec![l.q(), l.qd(), l.current(), temps.clone()]),
        ];
        let mut nonzero = 0;
        assert_blocks_match(&format!("run {}", run.name), &y, &f, &j, &fd, &blocks, |r, c, b| {
            if temps.contains(&r) || temps.contains(&c) {
                nonzero += usize::from(b != 0.0);
            }
        });
        // per joint: dT_w/dT_w, dT_w/dT_h, dT_w/di, dT_h/dT_w, dT_h/dT_h, di/dT_w
        // (joint5 has i = 0: its dT_w/di and di/dT_w vanish)
        assert!(nonzero >= 6 * l.nv - 2, "run {}: {nonzero} thermal entries", run.name);
    }
}

/// The max winding temperature is monitored through the `limits` record: a motor rated for
/// 26 °C crosses it, the record says when, by how much, on which joint; without the thermal
/// model nothing of it is recorded.
#[test]
fn the_max_winding_temperature_is_monitored() {
    let scene = paper_thermal()
        .vary(|s| {
            s.duration = 1.0;
            s.drives[0].motor = None;
            s.drives[0].motor_data = Some(re40(|m| m.max_winding_temperature_c = Some(26.0)));
        })
        .unwrap();
    let run = scene.run("no-elbow").unwrap().clone();
    let mut peak: Vec<f64> = vec![f64::NEG_INFINITY; 10];
    let rep = sim::run::simulate(&scene, &run, |o| {
        for (p, t) in peak.iter_mut().zip(&o.winding_temperature) {
            *p = p.max(*t);
        }
        Ok(())
    })
    .unwrap();
    let lim = rep.limits.expect("monitored");
    let events: Vec<_> = lim.events.iter().filter(|e| e.kind.name() == "winding-temperature").collect();
    let hot: Vec<usize> = (0..10).filter(|&j| peak[j] > 26.0).collect();
    assert!(!hot.is_empty());
    assert_eq!(events.len(), hot.len(), "{events:?}");
    for e in events {
        let j = scene.model().joint_names().iter().position(|n| *n == e.joint).unwrap();
        assert_eq!((e.limit, e.peak), (26.0, peak[j]), "{}", e.joint);
    }
}

/// Errors name the file, the field and the value: an unknown catalogue name (with the list),
/// a joint twice, the thermal model without thermal data, both motor and motor_data.
#[test]
fn datasheet_and_thermal_errors_name_the_field() {
    let paper = Scene::paper().unwrap();
    let err = |edit: &dyn Fn(&mut sim::scene::SceneSpec)| paper.vary(edit).unwrap_err().to_string();
    let drive = |joints: &[&str], motor: &str| sim::scene::spec_drive::DatasheetDriveSpec {
        joints: joints.iter().map(|s| s.to_string()).collect(),
        motor: Some(motor.into()),
        motor_data: None,
        gearhead: None,
        gearhead_data: None,
    };
    let e = err(&|s| s.drives = vec![drive(&["joint1"], "maxon-re99")]);
    assert!(e.contains("built-in paper scene") && e.contains("drives[0].motor") && e.contains("maxon-re99") && e.contains("maxon-re40-148877"), "{e}");
    let e = err(&|s| s.drives = vec![drive(&["joint1", "joint2"], "maxon-re40-148877"), drive(&["joint2"], "maxon-re30-310007")]);
    assert!(e.contains("drives[1].joints[0]") && e.contains("joint2"), "{e}");
    let e = err(&|s| s.thermal = Some(sim::scene::spec_drive::ThermalSpec { ambient_temperature_c: 25.0, initial_temperature_c: None }));
    assert!(e.contains("thermal") && e.contains("joint1") && e.contains("no thermal data"), "{e}");
    let e = err(&|s| {
        s.drives = vec![drive(&["joint1"], "maxon-re40-148877")];
        s.drives[0].motor_data = Some(re40(|_| {}));
    });
    assert!(e.contains("drives[0].motor") && e.contains("exactly one"), "{e}");
    let e = err(&|s| {
        s.drives = (1..=10).map(|k| drive(&[&format!("joint{k}")], "maxon-re40-148877")).collect();
        s.thermal = Some(sim::scene::spec_drive::ThermalSpec { ambient_temperature_c: 900.0, initial_temperature_c: None });
    });
    assert!(e.contains("thermal.ambient_temperature_c") && e.contains("900"), "{e}");
}
