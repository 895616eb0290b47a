//! The scene's `hand_load` (issue 25 item 1): a payload at the hand, merged into the hand's
//! body. Checked in closed form on the paper arm: the holding torque a point load adds at every
//! joint is the moment of its weight about the joint's axis, −a_j · ((c − o_j) × m g), at
//! every sampled posture; with an inertia, M(q) and g(q) equal those of the URDF with the load
//! written into the hand link's `<inertial>`; absent, nothing changes; bad loads are refused
//! naming the file, the field and the value.

use nalgebra::{Point3, Vector3};
use serde_json::json;
use sim::dynamics::crba::crba;
use sim::dynamics::kinematics::forward_kinematics;
use sim::dynamics::rnea::bias_forces;
use sim::dynamics::Data;
use sim::scene::{Scene, PAPER_SCENE_JSON, PAPER_URDF};

fn with_load(load: Option<serde_json::Value>) -> String {
    let mut v: serde_json::Value = serde_json::from_str(PAPER_SCENE_JSON).unwrap();
    if let Some(l) = load {
        v["hand_load"] = l;
    }
    v.to_string()
}

fn scene(load: Option<serde_json::Value>) -> Result<Scene, sim::error::SceneError> {
    Scene::from_json(&with_load(load), "loaded.json", |name| (name == "paper_arm.urdf").then(|| PAPER_URDF.to_string()).ok_or_else(|| format!("no {name}")))
}

/// Postures of the paper arm: q0 and 20 pseudo-random ones (a fixed LCG, no dependency).
fn postures(q0: &[f64]) -> Vec<Vec<f64>> {
    let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut next = || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 * std::f64::consts::PI - std::f64::consts::PI
    };
    let mut out = vec![q0.to_vec()];
    out.extend((0..20).map(|_| (0..q0.len()).map(|_| next()).collect()));
    out
}

#[test]
fn a_point_load_adds_the_moment_of_its_weight_about_every_joint_axis() {
    let bare = scene(None).unwrap();
    let (m, com) = (0.5, [0.01, -0.02, 0.03]);
    let loaded = scene(Some(json!({"mass": m, "com": com}))).unwrap();
    let (mb, ml) = (bare.model(), loaded.model());
    let g = mb.gravity;
    let zero = vec![0.0; mb.nv];
    let mut checked = 0;
    for q in postures(bare.q0()) {
        let gb = bias_forces(mb, &mut Data::new(mb), &q, &zero).clone();
        let gl = bias_forces(ml, &mut Data::new(ml), &q, &zero).clone();
        // the load's centre in the world: `com` in the hand link's frame
        let mut d = Data::new(mb);
        forward_kinematics(mb, &mut d, &q);
        let hand = mb.frame("hand").unwrap();
        let x_world_hand = d.x_world_body[hand.body.unwrap()] * hand.x_body_frame;
        let c = (x_world_hand * Point3::from(Vector3::from(com))).coords;
        for j in 0..mb.nv {
            let x = d.x_world_body[j];
            let (o, a) = (x.translation.vector, x.rotation * mb.bodies[j].axis.into_inner());
            // the torque the joint must supply to hold the weight m g at c
            let hold = -a.dot(&(c - o).cross(&(g * m)));
            let added = gl[j] - gb[j];
            assert!((added - hold).abs() < 1e-12 * (1.0 + hold.abs()), "q = {q:?}, joint {j}: added {added} N m, m g r gives {hold} N m");
            checked += 1;
        }
    }
    assert_eq!(checked, 21 * 10);
    // at q0 the far joints hold the load's weight on a lever of the horizontal distance:
    // joint10's axis is horizontal (y), the load 0.3 m out along the last link
    let q0 = bare.q0();
    let mut d = Data::new(mb);
    forward_kinematics(mb, &mut d, q0);
    let gb = bias_forces(mb, &mut Data::new(mb), q0, &zero)[9];
    let gl = bias_forces(ml, &mut Data::new(ml), q0, &zero)[9];
    let hand = mb.frame("hand").unwrap();
    let c = (d.x_world_body[9] * hand.x_body_frame * Point3::from(Vector3::from(com))).coords;
    let o = d.x_world_body[9].translation.vector;
    let a = d.x_world_body[9].rotation * mb.bodies[9].axis.into_inner();
    // lever: the horizontal offset of c from the axis, perpendicular to it
    let r = c - o;
    let lever = (r - a * a.dot(&r) - Vector3::z() * r.z).norm();
    assert!(((gl - gb).abs() - m * 9.81 * lever).abs() < 1e-12, "joint10 holds {} N m, m g r = {}", (gl - gb).abs(), m * 9.81 * lever);
}

#[test]
fn a_load_with_inertia_is_the_urdf_with_the_load_in_the_hand_links_inertial() {
    let (m, com) = (1.0, [0.02, 0.0, 0.05]);
    let (ixx, iyy, izz, ixy, ixz, iyz) = (2e-3, 3e-3, 4e-3, 1e-4, -2e-4, 5e-5);
    let loaded = scene(Some(json!({"mass": m, "com": com, "inertia": {"ixx": ixx, "iyy": iyy, "izz": izz, "ixy": ixy, "ixz": ixz, "iyz": iyz}}))).unwrap();
    // the same load written into the URDF: the hand link gets an <inertial>
    let urdf = PAPER_URDF.replace(
        "<link name=\"hand\">",
        &format!(
            "<link name=\"hand\">\n    <inertial><origin xyz=\"{} {} {}\" rpy=\"0 0 0\"/><mass value=\"{m}\"/><inertia ixx=\"{ixx}\" ixy=\"{ixy}\" ixz=\"{ixz}\" iyy=\"{iyy}\" iyz=\"{iyz}\" izz=\"{izz}\"/></inertial>",
            com[0], com[1], com[2]
        ),
    );
    assert_ne!(urdf, PAPER_URDF);
    let merged = Scene::from_json(&with_load(None), "merged.json", |_| Ok(urdf.clone())).unwrap();
    let (ml, mm) = (loaded.model(), merged.model());
    let zero = vec![0.0; ml.nv];
    for q in postures(loaded.q0()) {
        let a = crba(ml, &mut Data::new(ml), &q).clone();
        let b = crba(mm, &mut Data::new(mm), &q).clone();
        assert!((&a - &b).amax() < 1e-12 * b.amax(), "M(q) differs by {:e}", (&a - &b).amax());
        let qd: Vec<f64> = q.iter().map(|x| 0.3 * x).collect();
        for v in [&zero, &qd] {
            let ga = bias_forces(ml, &mut Data::new(ml), &q, v).clone();
            let gb = bias_forces(mm, &mut Data::new(mm), &q, v).clone();
            assert!((&ga - &gb).amax() < 1e-12 * (1.0 + gb.amax()), "bias forces differ by {:e}", (&ga - &gb).amax());
        }
    }
    // and the load is a real change: M grows by at least m |J_v|² at the last joint
    let bare = scene(None).unwrap();
    let mb = bare.model();
    let a = crba(ml, &mut Data::new(ml), bare.q0())[(9, 9)];
    let b = crba(mb, &mut Data::new(mb), bare.q0())[(9, 9)];
    assert!(a - b > m * 0.3f64.powi(2), "M[9,9] {b} → {a}");
}

#[test]
fn no_load_is_the_urdf_bit_for_bit_and_is_not_serialised() {
    let bare = scene(None).unwrap();
    let paper = Scene::paper().unwrap();
    assert!(!serde_json::to_string(bare.spec()).unwrap().contains("hand_load"));
    let zero = scene(Some(json!({"mass": 0.0}))).unwrap();
    for q in postures(bare.q0()) {
        let a = crba(bare.model(), &mut Data::new(bare.model()), &q).clone();
        assert_eq!(a, crba(paper.model(), &mut Data::new(paper.model()), &q).clone());
        // a massless point load adds exact zeros
        assert_eq!(a, crba(zero.model(), &mut Data::new(zero.model()), &q).clone());
    }
}

#[test]
fn bad_loads_are_refused_naming_the_file_the_field_and_the_value() {
    let cases = [
        (json!({"mass": -1.0}), "hand_load.mass", "-1"),
        (json!({"mass": 2e4}), "hand_load.mass", "20000"),
        (json!({"mass": 1.0, "com": [0.0, null, 0.0]}), "hand_load.com", ""),
        (json!({"mass": 1.0, "inertia": {"ixx": -1e-3, "iyy": 1e-3, "izz": 1e-3}}), "hand_load.inertia", "ixx=-0.001"),
        (json!({"mass": 1.0, "inertia": {"ixx": 1e-3, "iyy": 1e-3, "izz": 5e-3}}), "hand_load.inertia", "izz=0.005"),
        (json!({"mass": 0.0, "inertia": {"ixx": 1e-3, "iyy": 1e-3, "izz": 1e-3}}), "hand_load.inertia", "ixx=0.001"),
        (json!({"mass": 1.0, "weight": 3}), "hand_load.weight", ""),
        (json!({"mass": 1.0, "inertia": {"ixx": 1e-3, "ixy": "a"}}), "hand_load.inertia.ixy", ""),
    ];
    for (k, (load, field, value)) in cases.iter().enumerate() {
        let e = scene(Some(load.clone())).err().unwrap_or_else(|| panic!("case {k}: {load} was accepted")).to_string();
        for s in ["loaded.json", field, value] {
            assert!(e.contains(s), "case {k}: `{s}` not in: {e}");
        }
    }
    // the hand on the base cannot carry a load that moves
    let mut v: serde_json::Value = serde_json::from_str(&with_load(Some(json!({"mass": 1.0})))).unwrap();
    v["hand"] = json!({"link": "base_link"});
    let e = Scene::from_json(&v.to_string(), "base.json", |_| Ok(PAPER_URDF.to_string())).err().map(|e| e.to_string()).unwrap_or_default();
    assert!(e.contains("base.json") && e.contains("hand_load") && e.contains("fixed to the base"), "{e}");
}
