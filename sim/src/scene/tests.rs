//! The paper scene as SCENE.md fixes it, the IK against forward kinematics, and bad input.

use nalgebra::Vector3;

use super::*;
use crate::dynamics::kinematics::forward_kinematics;

fn paper() -> Scene {
    Scene::paper().expect("the built-in scene is valid")
}

/// SCENE.md: the elbows (joints 4 and 7) are on the table at t = 0, the hand starts 0.056 m
/// from the circle's centre, link masses sum to 1 kg. Tolerances: 1e-15 m for the elbows
/// (exact up to rounding of π/4), 1 mm for the quoted 0.056 m.
#[test]
fn paper_scene_matches_scene_md() {
    let s = paper();
    assert_eq!(s.model.nv, 10);
    assert_eq!(s.runs.iter().map(|r| r.name.as_str()).collect::<Vec<_>>(), ["two-elbow", "one-elbow", "no-elbow"]);
    assert!((s.model.total_mass() - 1.0).abs() < 1e-12);
    let mut data = Data::new(&s.model);
    forward_kinematics(&s.model, &mut data, &s.q0);
    for c in &s.contacts {
        assert!(c.position(&data).abs() < 1e-15, "{} at z = {}", c.name, c.position(&data));
    }
    // the target: a 0.1 m circle about (1.5, 1.5, 0.4) m, once in 5 s
    assert_eq!((s.circle().unwrap().center, s.circle().unwrap().radius, s.circle().unwrap().period), (nalgebra::Vector3::new(1.5, 1.5, 0.4), 0.1, 5.0));
    let hand = s.hand.position(&data);
    let dist = (hand - s.circle().unwrap().center).norm();
    assert!((dist - 0.056).abs() < 1e-3, "hand starts {dist} m from the centre");
    // and 0.054 m from where the target starts (the README's start-up transient)
    let offset = (hand - s.circle().unwrap().position(0.0)).norm();
    assert!((offset - 0.054).abs() < 1e-3, "hand starts {offset} m from r_d(0)");
    // the hand is in the vertical plane through x = y
    assert!((hand.x - hand.y).abs() < 1e-14);
    // drives: K_m = 0.609, J_m = 0.001476, D_m = 0.09 on every joint
    assert!(s.drives.km.iter().all(|&x| (x - 0.609).abs() < 1e-15));
    assert!(s.drives.jm.iter().all(|&x| (x - 0.001476).abs() < 1e-15));
}

/// IK then FK returns the target (1e-12 m) on the whole circle; the IK velocity equals the
/// central difference of the IK angles (h = 1e-6 s, tol 1e-7 rad/s); held joints keep q0;
/// the joint-10 angle is positive (the paper's branch).
#[test]
fn ik_inverts_forward_kinematics_on_the_circle() {
    let s = paper();
    let nv = s.model.nv;
    let mut data = Data::new(&s.model);
    let (mut q, mut qd) = (vec![0.0; nv], vec![0.0; nv]);
    let (mut qp, mut qm, mut scratch) = (vec![0.0; nv], vec![0.0; nv], vec![0.0; nv]);
    for k in 0..50 {
        let t = 5.0 * k as f64 / 50.0;
        let r = s.circle().unwrap().position(t);
        s.ik().unwrap().solve(&r, &s.circle().unwrap().velocity(t), &mut q, &mut qd).unwrap();
        forward_kinematics(&s.model, &mut data, &q);
        assert!((s.hand.position(&data) - r).norm() < 1e-12, "t = {t}");
        assert!(q[9] > 0.0);
        for j in 1..8 {
            assert_eq!(q[j], s.q0[j]);
            assert_eq!(qd[j], 0.0);
        }
        let h = 1e-6;
        s.ik().unwrap().solve(&s.circle().unwrap().position(t + h), &s.circle().unwrap().velocity(t + h), &mut qp, &mut scratch).unwrap();
        s.ik().unwrap().solve(&s.circle().unwrap().position(t - h), &s.circle().unwrap().velocity(t - h), &mut qm, &mut scratch).unwrap();
        for j in 0..nv {
            let fd = (qp[j] - qm[j]) / (2.0 * h);
            assert!((fd - qd[j]).abs() < 1e-7, "t = {t} joint {j}: {fd} vs {}", qd[j]);
        }
    }
}

/// The joint targets at t = 0 are continuous with the start: q_d1(0) = 0 (the circle starts
/// on the bisector), and joints 9, 10 are within 0.5 rad of q0 (the hand starts 0.056 m off the circle, near full reach).
#[test]
fn ik_start_is_near_the_initial_pose() {
    let s = paper();
    let (mut q, mut qd) = (vec![0.0; 10], vec![0.0; 10]);
    s.ik().unwrap().solve(&s.circle().unwrap().position(0.0), &s.circle().unwrap().velocity(0.0), &mut q, &mut qd).unwrap();
    assert!(q[0].abs() < 1e-14);
    assert!((q[8] - s.q0[8]).abs() < 0.5 && (q[9] - s.q0[9]).abs() < 0.5, "{q:?}");
}

fn with(edit: impl FnOnce(&mut serde_json::Value)) -> Result<Scene, SceneError> {
    let mut v: serde_json::Value = serde_json::from_str(PAPER_SCENE_JSON).unwrap();
    edit(&mut v);
    Scene::from_json(&v.to_string(), "edited.json", |_| Ok(PAPER_URDF.to_string()))
}

fn expect_err(edit: impl FnOnce(&mut serde_json::Value), field: &str, value: &str) {
    let err = with(edit).expect_err("must be rejected").to_string();
    assert!(err.starts_with("edited.json: "), "{err}");
    assert!(err.contains(field), "`{field}` not in: {err}");
    assert!(err.contains(value), "`{value}` not in: {err}");
}

#[test]
fn bad_scenes_name_file_field_and_value() {
    expect_err(|v| v["motor"]["resistance"] = (-1.1).into(), "motor.resistance", "-1.1");
    expect_err(|v| v["motor"]["inductance"] = serde_json::json!([0.0017, 0.0017]), "motor.inductance", "array of 2");
    expect_err(|v| v["motor"]["resistnce"] = 1.0.into(), "motor", "resistnce");
    expect_err(|v| v["duration"] = "five".into(), "duration", "five");
    expect_err(|v| v["contacts"][0]["point"]["joint"] = "joint42".into(), "contacts[0].point.joint", "joint42");
    expect_err(|v| v["runs"][0]["contacts"][1] = "elbow9".into(), "runs[0].contacts[1]", "elbow9");
    expect_err(|v| v["target"]["circle"]["radius"] = 0.0.into(), "target.circle.radius", "0");
    expect_err(|v| v["target"]["circle"]["center"] = serde_json::json!([3.5, 3.5, 0.4]), "target", "outside its reach");
    expect_err(|v| v["integrator"]["step"] = 1e-4.into(), "integrator.step", "0.0001");
    expect_err(|v| v["target"]["ik"]["yaw_joint"] = "joint2".into(), "target.ik", "joint2");
    // an elbow 1 cm above the table at the start is rejected, with the violation in the message
    expect_err(|v| v["contacts"][0]["plane"]["offset"] = (-0.01).into(), "contacts[0]", "C(q0) = 1.000e-2");
}

#[test]
fn per_joint_arrays_are_accepted() {
    let s = with(|v| v["joint_damping"] = serde_json::json!([0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.7])).unwrap();
    assert_eq!(s.drives.d[9], 0.7);
    assert_eq!(s.drives.d[0], 0.5);
    let _ = Vector3::<f64>::zeros();
}

/// The small scene in sim/scenes/small loads and starts with its elbow on the table and the
/// hand on the target (1e-12 m).
#[test]
fn small_scene_is_valid() {
    let s = Scene::load(std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/small/small.json"))).unwrap();
    let mut data = Data::new(&s.model);
    forward_kinematics(&s.model, &mut data, &s.q0);
    assert!((s.hand.position(&data) - s.circle().unwrap().position(0.0)).norm() < 1e-12);
}

/// Contact models (issue 11): bad models, keys and values are rejected naming the field and the
/// value; a unilateral elbow above the table is accepted (it starts separated) but one inside
/// it (g0 < −1e-9 m) is rejected with its gap; the table construct adds its points to every run.
#[test]
fn contact_models_are_validated() {
    expect_err(|v| v["contacts"][0]["model"] = "sticky".into(), "contacts[0].model", "sticky");
    expect_err(
        |v| {
            v["contacts"][0]["model"] = "unilateral".into();
            v["contacts"][0]["restitution"] = 1.5.into();
        },
        "contacts[0].restitution",
        "1.5",
    );
    expect_err(
        |v| {
            v["contacts"][1]["model"] = "unilateral".into();
            v["contacts"][1]["friction"] = (-0.1).into();
        },
        "contacts[1].friction",
        "-0.1",
    );
    expect_err(
        |v| {
            v["contacts"][0]["model"] = "unilateral".into();
            v["contacts"][0]["stiffness"] = 1e5.into();
        },
        "contacts[0].stiffness",
        "100000",
    );
    expect_err(|v| v["contacts"][0]["friction"] = 0.5.into(), "contacts[0].friction", "0.5");
    expect_err(|v| v["contacts"][0]["model"] = "compliant".into(), "contacts[0].stiffness", "(absent)");
    expect_err(
        |v| {
            v["contacts"][0]["model"] = "unilateral".into();
            v["contacts"][0]["plane"]["offset"] = 0.01.into();
        },
        "contacts[0]",
        "g(q0) = -1.000e-2",
    );
    // above the table: fine for a unilateral contact
    let s = with(|v| {
        v["contacts"][0]["model"] = "unilateral".into();
        v["contacts"][0]["plane"]["offset"] = (-0.01).into();
    })
    .expect("a unilateral elbow may start above the table");
    assert_eq!(s.contact_models()[0].model, crate::dynamics::contact::ContactModel::Unilateral { restitution: 0.0, friction: 0.0 });
    assert!(s.run_is_hybrid(&s.runs[0]) && !s.run_is_hybrid(&s.runs[2]));
    // the table: its points belong to every run; the spec without it re-serialises unchanged
    let s = with(|v| {
        v["table"] = serde_json::json!({"plane": {"normal": [0, 0, 1], "offset": 0}, "points": [{"name": "t5", "point": {"joint": "joint5"}}], "friction": 0.4});
    })
    .expect("a table under joint5");
    let k = s.contacts().iter().position(|c| c.name == "t5").expect("the table point is a contact");
    assert!(s.runs.iter().all(|r| r.contacts.contains(&k)));
    assert_eq!(s.contact_models()[k].model, crate::dynamics::contact::ContactModel::Unilateral { restitution: 0.0, friction: 0.4 });
    let paper_json = serde_json::to_value(paper().spec()).unwrap();
    assert!(paper_json.get("table").is_none() && paper_json.get("events").is_none() && paper_json["contacts"][0].get("model").is_none());
}
