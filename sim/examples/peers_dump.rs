//! Prints, as JSON, what a peer simulator (MuJoCo, Pinocchio) needs to rebuild one run of a
//! scene and to check that its model is ours: the drive and PD parameters, the initial state, the
//! joint targets at t = 0, at a few q the hand position and the joint-space inertia M(q) (CRBA,
//! without the rotor inertia J_m), at a few states the constrained accelerations of eq 21 with the
//! run's contacts, and optionally the reference hand path (`sim::precision::reference`: the same
//! Dormand–Prince rtol 1e-12 run that `sim precision` measures against), one sample per output
//! interval. Used by `bench/peers/peers.py`.
//!
//! ```text
//! cargo run --release -p sim --example peers_dump -- SCENE RUN [--reference] [--targets] [--states N]
//! ```
//!
//! `--targets` adds the joint targets q_d(t), q̇_d(t) (eqs 28–29) on the output grid, for a
//! peer that tracks the circle (its controller is fed them; the contact scene of the peers).
use std::process::ExitCode;

use nalgebra::DMatrix;
use serde_json::{json, Value};
use sim::dynamics::crba::crba;
use sim::dynamics::forward::{forward_dynamics, ForwardData, Plant};
use sim::dynamics::kinematics::forward_kinematics;
use sim::dynamics::samples::SplitMix64;
use sim::dynamics::Data;
use sim::scene::Scene;

fn matrix(m: &DMatrix<f64>) -> Value {
    Value::from((0..m.nrows()).map(|i| (0..m.ncols()).map(|j| m[(i, j)]).collect::<Vec<_>>()).collect::<Vec<_>>())
}

fn main() -> ExitCode {
    match dump() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("peers_dump: {e}");
            ExitCode::from(2)
        }
    }
}

fn dump() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: peers_dump SCENE RUN [--reference] [--targets] [--states N]";
    let (path, run_name) = match (args.first(), args.get(1)) {
        (Some(p), Some(r)) if !p.starts_with("--") && !r.starts_with("--") => (p, r),
        _ => return Err(usage.into()),
    };
    let with_reference = args.iter().any(|a| a == "--reference");
    let with_targets = args.iter().any(|a| a == "--targets");
    let n_states: usize = match args.iter().position(|a| a == "--states") {
        Some(k) => args.get(k + 1).and_then(|v| v.parse().ok()).ok_or(usage)?,
        None => 4,
    };
    let scene = Scene::load(std::path::Path::new(path)).map_err(|e| e.to_string())?;
    let run = scene.run(run_name).ok_or_else(|| format!("{path}: no run named {run_name:?}"))?.clone();
    let model = scene.model();
    let nv = model.nv;
    let drives = scene.drives();
    let gains = scene.gains();

    // joint targets (eqs 28-29) at t = 0 and at the end (equal for a constant target)
    let (Some(circle), Some(ik)) = (scene.circle(), scene.ik()) else {
        return Err(format!("{path}: the peers compare the paper's circle target only"));
    };
    let targets = |t: f64| -> Result<(Vec<f64>, Vec<f64>), String> {
        let (mut q_des, mut qd_des) = (vec![0.0; nv], vec![0.0; nv]);
        ik.solve(&circle.position(t), &circle.velocity(t), &mut q_des, &mut qd_des).map_err(|why| format!("the target at t = {t} s: {why}"))?;
        Ok((q_des, qd_des))
    };
    let (q_des, qd_des0) = targets(0.0)?;
    let (q_des_end, _) = targets(scene.duration())?;

    // kinematics and inertia at q0 and a few states around it
    // the sample states: deterministic, the same on every run (the benches' generator)
    let mut rng = SplitMix64(2024);
    let mut data = Data::new(model);
    let mut qs: Vec<Vec<f64>> = vec![scene.q0().to_vec()];
    for _ in 1..n_states {
        qs.push(scene.q0().iter().map(|q| q + rng.range(-0.5, 0.5)).collect());
    }
    let mut kin = Vec::new();
    for q in &qs {
        forward_kinematics(model, &mut data, q);
        let hand = scene.hand().position(&data);
        let m = crba(model, &mut data, q).clone();
        kin.push(json!({ "q": q, "hand": [hand.x, hand.y, hand.z], "mass_matrix": matrix(&m) }));
    }

    // constrained forward dynamics (eq 21) with the run's contacts, at states with speeds and currents
    let contacts = scene.run_contacts(&run);
    let plant = Plant {
        model,
        drives,
        contacts: &contacts,
        mass_matrix: scene.mass_matrix(),
        solver: scene.solver(),
        stabilization: scene.stabilization(),
    };
    let mut fd = ForwardData::new(nv, contacts.len());
    let mut dynamics = Vec::new();
    for q in &qs {
        let qd = rng.vector(nv, -1.0, 1.0);
        let current = rng.vector(nv, -2.0, 2.0);
        let voltage = vec![0.0; nv];
        forward_dynamics(&plant, &mut data, &mut fd, 0.0, q, &qd, &current, &voltage).map_err(|e| e.to_string())?;
        // the generalised force of the drives: K_m i − (D + D_m) q̇ (eq 12 without the J_m q̈ term)
        let tau: Vec<f64> = (0..nv).map(|j| drives.km[j] * current[j] - (drives.d[j] + drives.dm[j]) * qd[j]).collect();
        dynamics.push(json!({
            "q": q, "qd": qd, "current": current, "tau_drive": tau,
            "qdd": fd.qdd.as_slice(), "normal_force": fd.f_n.as_slice(),
        }));
    }
    let names = model.joint_names();
    let contact_json: Vec<Value> = contacts
        .iter()
        .zip(&run.contacts)
        .map(|(c, &k)| {
            let n = c.normal_world.into_inner();
            let law = match scene.contact_models()[k].model {
                sim::dynamics::contact::ContactModel::Bilateral => json!({ "model": "bilateral" }),
                sim::dynamics::contact::ContactModel::Unilateral { restitution, friction } => {
                    json!({ "model": "unilateral", "restitution": restitution, "friction": friction })
                }
                sim::dynamics::contact::ContactModel::Compliant { stiffness, damping, friction, slip_velocity } => json!({
                    "model": "compliant", "stiffness": stiffness, "damping": damping, "friction": friction, "slip_velocity": slip_velocity,
                }),
            };
            json!({
                "name": c.name,
                "joint": c.point.body.map(|b| names[b].clone()),
                "point_in_body": [c.point.p_body.x, c.point.p_body.y, c.point.p_body.z],
                "normal": [n.x, n.y, n.z], "offset": c.offset,
                "law": law,
            })
        })
        .collect();
    let hand = scene.hand();
    let mut out = json!({
        "scene": path, "run": run_name,
        "joint_names": names,
        "gravity": scene.spec().gravity,
        "duration": scene.duration(), "output_rate": scene.output_rate(),
        "hand": { "joint": hand.body.map(|b| names[b].clone()), "point_in_body": [hand.p_body.x, hand.p_body.y, hand.p_body.z] },
        "drives": {
            "km": drives.km.as_slice(), "r": drives.r.as_slice(), "l": drives.l.as_slice(),
            "jm": drives.jm.as_slice(), "dm": drives.dm.as_slice(), "d": drives.d.as_slice(),
        },
        "gains": { "kp": gains.kp.as_slice(), "kd": gains.kd.as_slice() },
        "q0": scene.q0(), "qd0": scene.qd0(), "current0": scene.current0(),
        "q_des0": q_des, "qd_des0": qd_des0, "q_des_end": q_des_end,
        "contacts": contact_json,
        "kinematics": kin,
        "dynamics": dynamics,
    });
    if with_targets {
        // on the output grid t_k = k / output_rate, k = 0 … duration · output_rate
        let dt = 1.0 / scene.output_rate();
        let n = (scene.duration() * scene.output_rate()).round() as usize;
        let (mut qs, mut qds) = (Vec::with_capacity(n + 1), Vec::with_capacity(n + 1));
        for k in 0..=n {
            let (q, qd) = targets(k as f64 * dt)?;
            qs.push(q);
            qds.push(qd);
        }
        out["targets"] = json!({ "dt": dt, "q_des": qs, "qd_des": qds });
    }
    if with_reference {
        let r = sim::precision::reference(&scene, &run).map_err(|e| e.to_string())?;
        out["reference_hand"] = Value::from(r.hand.iter().map(|h| vec![h.x, h.y, h.z]).collect::<Vec<_>>());
    }
    println!("{out}");
    Ok(())
}
