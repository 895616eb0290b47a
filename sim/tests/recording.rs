//! A run written to MCAP and read back through the generic, schema-driven reader: every
//! channel decodes, every sample is there, the numbers are the ones the simulator computed,
//! the metadata describes the run, and two runs give the same bytes.

use std::path::Path;

use schemas::{read_recording, topics, ConstraintState, EnergyState, HandState, JointState, MotorState, RunStatus};
use sim::scene::{Scene, SceneSpec};

fn small() -> Scene {
    Scene::load(Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/small/small.json"))).unwrap()
}

#[test]
fn every_channel_round_trips_through_the_generic_reader() {
    let scene = small();
    let run = scene.run("elbow").unwrap().clone();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("small-elbow.mcap");
    let mut outputs = Vec::new();
    // the same outputs as the recorder sees, collected through the plain simulation
    sim::run::simulate(&scene, &run, |o| {
        outputs.push(o.clone());
        Ok(())
    })
    .unwrap();
    let rep = sim::run::run_to_file(&scene, &run, &path, |_| {}).unwrap();
    assert_eq!(rep.path, path);
    let n = outputs.len();
    assert_eq!(n, 501);

    let rec = read_recording(&path).unwrap();
    for topic in topics::ALL {
        let ch = rec.channel(topic).unwrap_or_else(|| panic!("{topic} missing"));
        assert!(ch.undecoded.is_none(), "{topic}: {:?}", ch.undecoded);
        let expected = if topic == topics::ROBOT_DESCRIPTION { 1 } else { n };
        assert_eq!(ch.message_count, expected, "{topic}");
    }
    // exact values: encoding is lossless
    let motors = rec.read::<MotorState>().unwrap();
    let constraints = rec.read::<ConstraintState>().unwrap();
    let hands = rec.read::<HandState>().unwrap();
    let energy = rec.read::<EnergyState>().unwrap();
    let joints = rec.read::<JointState>().unwrap();
    for (k, o) in outputs.iter().enumerate() {
        assert_eq!(motors[k].0, o.t);
        assert_eq!(motors[k].1.current, o.current);
        assert_eq!(constraints[k].1.normal_force, o.normal_force);
        assert_eq!(hands[k].1.actual.z, o.hand.z);
        assert_eq!(energy[k].1.balance_residual, o.balance_residual);
        assert_eq!(joints[k].1.position, o.q);
        assert_eq!(joints[k].1.name, scene.model().joint_names());
    }
    // the transforms cover every URDF joint plus world -> root, each sample (the generic view)
    let tf = rec.messages(topics::TF).unwrap();
    let first = tf[0].1.get("transforms").and_then(|v| v.as_list()).unwrap();
    assert_eq!(first.len(), scene.model().urdf_joints.len() + 1);
    // the URDF is published as text
    let urdf = rec.messages(topics::ROBOT_DESCRIPTION).unwrap()[0].1.get("data").and_then(|v| v.as_str()).unwrap();
    assert_eq!(urdf, scene.urdf_xml());

    // metadata: enough to rebuild the same scene, and what ran
    let spec: SceneSpec = serde_json::from_str(&rec.scene().unwrap().json).unwrap();
    assert_eq!(&spec, scene.spec());
    assert_eq!(rec.urdf().unwrap().xml, scene.urdf_xml());
    let info = rec.run().unwrap();
    assert_eq!((info.run.as_str(), info.joint_names.clone()), ("elbow", scene.model().joint_names()));
    let setup = info.setup.unwrap();
    assert_eq!(setup.integrator.method, "dopri45");
    assert_eq!((setup.duration_s, setup.output_rate_hz), (scene.duration(), scene.output_rate()));
    assert_eq!(setup.model.contacts, run.contacts.len());
    let result = rec.result().unwrap().unwrap();
    assert_eq!(result.status, RunStatus::Complete);
    assert_eq!(result.steps, Some(rep.report.stats.steps));
    assert_eq!(rec.format_version(), Some(schemas::FORMAT_VERSION));
    // nothing but the recording is left in the directory (no temporary file)
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(names.len(), 1, "{names:?}");
}

/// Same scene, same version: byte-identical recordings, whether runs go one after another or
/// on two threads at once.
#[test]
fn identical_runs_give_identical_files() {
    let scene = small();
    let dir = tempfile::tempdir().unwrap();
    let run = scene.run("free").unwrap().clone();
    let a = dir.path().join("a.mcap");
    let b = dir.path().join("b.mcap");
    sim::run::run_to_file(&scene, &run, &a, |_| {}).unwrap();
    std::thread::scope(|s| {
        s.spawn(|| sim::run::run_to_file(&scene, &run, &b, |_| {}).unwrap());
        s.spawn(|| sim::run::simulate(&scene, &run, |_| Ok(())).unwrap());
    });
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
}

/// A scene file's `"$schema"` (for editors) changes no byte of a recording: the small scene
/// and the built-in paper scene, as shipped (with the key) and with the key's line removed,
/// give the same spec, the same stored scene JSON and the same recording, byte for byte.
#[test]
fn a_schema_key_changes_no_byte_of_a_recording() {
    let dir = tempfile::tempdir().unwrap();
    let without = |text: &str| -> String {
        assert!(text.starts_with("{\n  \"$schema\": "), "the shipped scene names its schema first");
        text.lines().filter(|l| !l.starts_with("  \"$schema\": ")).collect::<Vec<_>>().join("\n")
    };
    let small_dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/small"));
    let small_text = std::fs::read_to_string(small_dir.join("small.json")).unwrap();
    let paper_urdf = |name: &str| if name == "paper_arm.urdf" { Ok(sim::scene::PAPER_URDF.to_string()) } else { Err(format!("no {name}")) };
    let small_urdf = |name: &str| sim::scene::read_urdf_file(small_dir, name);
    for (label, text, run) in [("small", small_text.as_str(), "elbow"), ("paper", sim::scene::PAPER_SCENE_JSON, "two-elbow")] {
        let load = |t: &str| {
            let s = if label == "small" { Scene::from_json(t, "s.json", small_urdf) } else { Scene::from_json(t, "s.json", paper_urdf) };
            // a short run: the recording's every part is there (metadata, messages, summary)
            s.unwrap().vary(|sp| sp.duration = 0.02).unwrap()
        };
        let (with, plain) = (load(text), load(&without(text)));
        assert_eq!(with.spec(), plain.spec(), "{label}");
        let run = with.run(run).unwrap().clone();
        let (a, b) = (dir.path().join(format!("{label}-a.mcap")), dir.path().join(format!("{label}-b.mcap")));
        sim::run::run_to_file(&with, &run, &a, |_| {}).unwrap();
        sim::run::run_to_file(&plain, &run, &b, |_| {}).unwrap();
        let bytes = std::fs::read(&a).unwrap();
        assert_eq!(bytes, std::fs::read(&b).unwrap(), "{label}: the recordings differ");
        let stored = read_recording(&a).unwrap().scene().unwrap().json;
        assert!(!stored.contains("$schema") && stored == serde_json::to_string_pretty(plain.spec()).unwrap(), "{label}");
    }
    // the built-in paper scene is the one its recordings were made from
    assert_eq!(Scene::paper().unwrap().spec(), &sim::scene::read_spec(&without(sim::scene::PAPER_SCENE_JSON), "p").unwrap());
}

/// A run that fails numerically still closes a valid recording holding every sample up to
/// the failure and a result record saying when and why; the error names the time.
#[test]
fn a_failed_run_leaves_a_valid_recording_that_says_why() {
    // an unbounded voltage gain with a tiny inductance and a coarse RK4 step blows up
    let scene = small().vary(|s| s.integrator = sim::scene::spec::IntegratorSpec::rk4(5e-3)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.mcap");
    let run = scene.run("free").unwrap().clone();
    let err = sim::run::run_to_file(&scene, &run, &path, |_| {}).unwrap_err();
    let t = err.time().expect("a numerical failure has a time");
    assert!(t > 0.0 && t < scene.duration(), "{err}");
    let rec = read_recording(&path).unwrap();
    let result = rec.result().unwrap().unwrap();
    assert_eq!(result.status, RunStatus::Failed);
    assert!(result.error.unwrap().contains("t = "));
    assert_eq!(result.error_time_s, Some(t));
    let motors = rec.read::<MotorState>().unwrap();
    assert!(motors.last().map_or(0.0, |m| m.0) <= t);
}

/// `model.*` describes the model that ran, and the recorded signals agree with it: the full
/// paper model (L di/dt, friction, gravity, two contacts) stores magnetic energy, loses energy
/// to friction, moves in gravity and records two contact forces; the reduced one (L = 0, no
/// friction, no gravity, no contact) stores no magnetic energy, loses none to friction, has no
/// potential energy, records no contact, and its currents are the quasi-static ones,
/// v = R i + k_e ω (to 1e-12 of the terms) at every sample.
#[test]
fn model_metadata_describes_the_model_that_ran() {
    let dir = tempfile::tempdir().unwrap();
    let record = |scene: &Scene, run: &str| {
        let run = scene.run(run).unwrap().clone();
        let path = dir.path().join(format!("{}.mcap", run.name));
        sim::run::run_to_file(scene, &run, &path, |_| {}).unwrap();
        read_recording(&path).unwrap()
    };
    let full = Scene::paper().unwrap().vary(|s| s.duration = 0.2).unwrap();
    let rec = record(&full, "two-elbow");
    let model = rec.run().unwrap().setup.unwrap().model;
    assert_eq!(model.electrical, sim::dynamics::motor::Electrical::Inductive.describe());
    assert_eq!((model.contacts, model.friction, model.gravity), (2, true, true));
    let energy = rec.read::<EnergyState>().unwrap();
    let constraints = rec.read::<ConstraintState>().unwrap();
    assert!(energy.iter().any(|(_, e)| e.magnetic > 0.0));
    assert!(energy.last().unwrap().1.friction_loss > 0.0);
    assert!(energy.iter().any(|(_, e)| e.potential != energy[0].1.potential));
    assert!(constraints.iter().all(|(_, c)| c.normal_force.len() == 2));

    let reduced = full
        .vary(|s| {
            s.motor.inductance = sim::scene::spec::PerJoint::All(0.0);
            s.motor.gear_damping = sim::scene::spec::PerJoint::All(0.0);
            s.joint_damping = sim::scene::spec::PerJoint::All(0.0);
            s.gravity = [0.0; 3];
        })
        .unwrap();
    let rec = record(&reduced, "no-elbow");
    let model = rec.run().unwrap().setup.unwrap().model;
    assert_eq!(model.electrical, sim::dynamics::motor::Electrical::QuasiStatic.describe());
    assert_eq!((model.contacts, model.friction, model.gravity), (0, false, false));
    for (_, e) in rec.read::<EnergyState>().unwrap() {
        assert_eq!((e.magnetic, e.friction_loss, e.potential), (0.0, 0.0, 0.0));
    }
    assert!(rec.read::<ConstraintState>().unwrap().iter().all(|(_, c)| c.normal_force.is_empty()));
    let resistance = 1.1;
    let motors = rec.read::<MotorState>().unwrap();
    assert!(motors.iter().any(|(_, m)| m.current.iter().any(|&i| i.abs() > 0.1)));
    for (t, m) in motors {
        for j in 0..m.current.len() {
            let (v, ri, emf) = (m.voltage[j], resistance * m.current[j], m.back_emf[j]);
            assert!((v - ri - emf).abs() <= 1e-12 * (v.abs() + ri.abs() + emf.abs()).max(1e-3), "t = {t}, motor {j}: v {v} R i {ri} emf {emf}");
        }
    }
}
