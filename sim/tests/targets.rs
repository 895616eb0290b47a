//! Targets (issue 10, item 2): the general IK on 6- and 7-DoF arms built here, reachable and
//! unreachable targets, the general IK against the paper's closed-form IK, joint-space splines
//! and CSVs through the scene file, `"initial": {"q": "from-target"}`, and a short run of a
//! Cartesian target. Tolerances are stated at each assertion.

use nalgebra::{UnitQuaternion, Vector3};
use serde_json::{json, Value};
use sim::control::general_ik::{track, GeneralIk};
use sim::control::path::{CartesianPath, CirclePath};
use sim::control::{Target, TargetScratch};
use sim::dynamics::kinematics::{body_point, forward_kinematics};
use sim::dynamics::{Data, Model};
use sim::scene::{Scene, PAPER_SCENE_JSON, PAPER_URDF};

use crate::rng_support::Lcg;

/// A serial arm from (axis, origin xyz) pairs: unit boxes of 1 kg, links named l0..ln, the
/// hand link `hand` 0.1 m beyond the last joint.
fn arm_urdf(joints: &[([f64; 3], [f64; 3])], limits: Option<(f64, f64)>) -> String {
    let mut x = String::from("<robot name=\"t\"><link name=\"l0\"/>\n");
    for (i, (axis, xyz)) in joints.iter().enumerate() {
        let lim = match limits {
            Some((lo, hi)) => format!("<limit lower=\"{lo}\" upper=\"{hi}\" effort=\"100\" velocity=\"3\"/>"),
            None => String::new(),
        };
        let kind = if limits.is_some() { "revolute" } else { "continuous" };
        x += &format!(
            "<link name=\"l{n}\"><inertial><mass value=\"1\"/><origin xyz=\"0 0 0.05\"/><inertia ixx=\"0.01\" iyy=\"0.01\" izz=\"0.01\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link>\n\
             <joint name=\"j{n}\" type=\"{kind}\"><parent link=\"l{i}\"/><child link=\"l{n}\"/><origin xyz=\"{} {} {}\"/><axis xyz=\"{} {} {}\"/>{lim}</joint>\n",
            xyz[0], xyz[1], xyz[2], axis[0], axis[1], axis[2], n = i + 1
        );
    }
    x += &format!(
        "<link name=\"hand\"/><joint name=\"jh\" type=\"fixed\"><parent link=\"l{}\"/><child link=\"hand\"/><origin xyz=\"0 0 0.1\"/></joint></robot>",
        joints.len()
    );
    x
}

/// UR-like 6-DoF arm with a shoulder offset (link lengths of the order of a UR5's).
fn six_dof() -> Model {
    let j = [
        ([0.0, 0.0, 1.0], [0.0, 0.0, 0.09]),
        ([0.0, 1.0, 0.0], [0.0, 0.135, 0.0]),
        ([0.0, 1.0, 0.0], [0.0, -0.12, 0.425]),
        ([0.0, 1.0, 0.0], [0.0, 0.0, 0.39]),
        ([0.0, 0.0, 1.0], [0.0, 0.093, 0.0]),
        ([0.0, 1.0, 0.0], [0.0, 0.0, 0.095]),
    ];
    Model::from_urdf(&arm_urdf(&j, None), "six.urdf", Vector3::new(0.0, 0.0, -9.81)).unwrap()
}

/// Panda-like 7-DoF arm with anti-parallel axes, joint limits ±2.8 rad.
fn seven_dof() -> Model {
    let j = [
        ([0.0, 0.0, 1.0], [0.0, 0.0, 0.333]),
        ([0.0, 1.0, 0.0], [0.0, 0.0, 0.0]),
        ([0.0, 0.0, 1.0], [0.0, 0.0, 0.316]),
        ([0.0, -1.0, 0.0], [0.0825, 0.0, 0.0]),
        ([0.0, 0.0, 1.0], [-0.0825, 0.0, 0.384]),
        ([0.0, -1.0, 0.0], [0.0, 0.0, 0.0]),
        ([0.0, 0.0, 1.0], [0.088, 0.0, 0.0]),
    ];
    Model::from_urdf(&arm_urdf(&j, Some((-2.8, 2.8))), "seven.urdf", Vector3::new(0.0, 0.0, -9.81)).unwrap()
}

fn hand_at(model: &Model, q: &[f64]) -> Vector3<f64> {
    let hand = body_point(model, "hand", Vector3::zeros()).unwrap();
    let mut data = Data::new(model);
    forward_kinematics(model, &mut data, q);
    hand.position(&data)
}

/// 20 random reachable targets (the hand at random angles within ±2 rad) per arm, solved from
/// the angles 0.4 rad away in every joint: the hand reaches each to 1e-9 m, checked by an
/// independent forward kinematics; with an orientation task too (the 7-DoF arm), the hand
/// frame's orientation is reached to 1e-9 rad; and the solution respects the joint limits.
#[test]
fn general_ik_reaches_random_reachable_targets() {
    let mut rng = Lcg(7);
    for model in [six_dof(), seven_dof()] {
        let nv = model.nv;
        let hand = body_point(&model, "hand", Vector3::zeros()).unwrap();
        for case in 0..20 {
            let q_goal: Vec<f64> = (0..nv).map(|_| 4.0 * rng.unit() - 2.0).collect();
            let r = hand_at(&model, &q_goal);
            let orient = nv == 7 && case % 2 == 0;
            let mut data = Data::new(&model);
            forward_kinematics(&model, &mut data, &q_goal);
            let r_goal = data.x_world_body[nv - 1].rotation;
            let ik = GeneralIk {
                hand,
                orientation: orient.then_some((UnitQuaternion::identity(), r_goal)),
                contacts: vec![],
                active: vec![true; nv],
                posture: q_goal.iter().map(|q| q + 0.4).collect(),
            };
            let mut q: Vec<f64> = q_goal.iter().map(|q| q + 0.4).collect();
            let mut s = ik.scratch(&model);
            let st = ik.solve(&model, &mut s, &r, &mut q).unwrap_or_else(|e| panic!("nv {nv} case {case}: {e:?}"));
            let miss = (hand_at(&model, &q) - r).norm();
            assert!(miss <= 1e-9, "nv {nv} case {case}: missed by {miss} m ({st:?})");
            if orient {
                forward_kinematics(&model, &mut data, &q);
                let err = data.x_world_body[nv - 1].rotation.angle_to(&r_goal);
                assert!(err <= 1e-9, "orientation off by {err} rad");
            }
            if nv == 7 {
                assert!(q.iter().all(|x| (-2.8..=2.8).contains(x)), "limits: {q:?}");
            }
        }
    }
}

/// An unreachable point (3 m away on arms of ~1 m reach) fails with the residual of the
/// closest point (> 1.5 m); a path that leaves the workspace at t ≈ 1 s fails in `track` at a
/// time within one grid step of where it leaves.
#[test]
fn general_ik_reports_unreachable_targets() {
    let model = six_dof();
    let nv = model.nv;
    let hand = body_point(&model, "hand", Vector3::zeros()).unwrap();
    let ik = GeneralIk { hand, orientation: None, contacts: vec![], active: vec![true; nv], posture: vec![0.3; nv] };
    let mut q = vec![0.3; nv];
    let mut s = ik.scratch(&model);
    let e = ik.solve(&model, &mut s, &Vector3::new(3.0, 0.0, 0.5), &mut q).unwrap_err();
    assert!(e.residual > 1.5, "{e:?}");
    // a line from a reachable point outwards at 0.5 m/s: it leaves the ~1.05 m reach shortly
    // after the hand passes 1.05 m from the shoulder
    let start = hand_at(&model, &[0.3; 6]);
    let dir = Vector3::new(start.x, start.y, 0.0).normalize();
    let path = CartesianPath::lines(&[start.into(), (start + dir * 1.5).into()], &[0.0, 3.0]).unwrap();
    let err = track(&ik, &model, &path, &[0.3; 6], 3.0, 0.01).unwrap_err();
    let reach_limit = {
        // the first time on the path farther than the arm can reach: scan the path itself
        let sh = Vector3::new(0.0, 0.0, 0.09);
        let reach = 0.425 + 0.39 + 0.095 + 0.1 + 0.2;
        (0..3000).map(|k| k as f64 * 1e-3).find(|&t| (path.position(t) - sh).norm() > reach).unwrap_or(3.0)
    };
    assert!(err.t > 0.0 && err.t <= reach_limit + 0.01, "failed at t = {} s (reach lost by t = {reach_limit} s)", err.t);
    assert!(err.stats.residual > 1e-10);
}

fn paper_json() -> Value {
    serde_json::from_str(PAPER_SCENE_JSON).unwrap()
}

fn scene_from(v: &Value, csv: Option<&'static str>) -> Result<Scene, sim::error::SceneError> {
    Scene::from_json(&v.to_string(), "test.json", move |name| match (name, csv) {
        ("paper_arm.urdf", _) => Ok(PAPER_URDF.to_string()),
        (_, Some(text)) => Ok(text.to_string()),
        _ => Err(format!("no file {name}")),
    })
}

fn eval(s: &Scene, t: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let nv = s.model().nv;
    let (mut q, mut qd, mut qdd) = (vec![0.0; nv], vec![0.0; nv], vec![0.0; nv]);
    let mut scratch = TargetScratch::new(s.model());
    s.target().eval(t, s.model(), s.hand(), &mut scratch, &mut q, &mut qd, Some(&mut qdd)).unwrap();
    (q, qd, qdd)
}

/// The paper's circle as a Cartesian target with the general IK moving only the closed form's
/// three joints (the others held at initial.q by the posture): q_d agrees with the closed-form
/// IK to 1e-9 rad at 101 times (knots and between), q̇_d to 1e-6 rad/s (the spline's O(h³)
/// derivative), and the spline's task error between knots is below 1e-9 m.
#[test]
fn general_ik_reproduces_the_closed_form_on_the_paper_arm() {
    let paper = Scene::paper().unwrap();
    let mut v = paper_json();
    let c = v["target"]["circle"].clone();
    v["target"] = json!({
        "kind": "cartesian",
        "path": {"shape": "circle", "center": c["center"], "normal": [0, 0, 1], "radius": c["radius"],
                 "period": c["period"], "phase": c["phase"], "direction": c["direction"]},
        "ik": {"joints": ["joint1", "joint9", "joint10"]}
    });
    let s = scene_from(&v, None).unwrap();
    let stats = *s.target().track_stats().unwrap();
    eprintln!("paper circle, general IK on joints 1, 9, 10: {stats:?}");
    assert!(stats.between_knots <= 1e-9 && stats.at_knots <= 1e-12, "{stats:?}");
    let nv = 10;
    let (circle, ik) = (paper.circle().unwrap(), paper.ik().unwrap());
    let (mut qc, mut qdc) = (vec![0.0; nv], vec![0.0; nv]);
    let mut worst = (0.0f64, 0.0f64);
    for k in 0..=100 {
        let t = 5.0 * k as f64 / 100.0 + if k % 2 == 1 { 0.0007 } else { 0.0 };
        let t = t.min(5.0);
        ik.solve(&circle.position(t), &circle.velocity(t), &mut qc, &mut qdc).unwrap();
        let (q, qd, _) = eval(&s, t);
        for j in 0..nv {
            worst.0 = worst.0.max((q[j] - qc[j]).abs());
            worst.1 = worst.1.max((qd[j] - qdc[j]).abs());
        }
    }
    assert!(worst.0 <= 1e-9, "q_d differs by {} rad", worst.0);
    assert!(worst.1 <= 1e-6, "q̇_d differs by {} rad/s", worst.1);
    // the recorded desired hand is the path, which is the paper's circle
    let mut scratch = TargetScratch::new(s.model());
    let d = s.target().hand_desired(1.3, s.model(), s.hand(), &mut scratch) - circle.position(1.3);
    assert!(d.norm() < 1e-15);
}

/// The paper target's q̈_d (J₃⁻¹ (r̈ − J̇ q̇)) is the derivative of its closed-form q̇_d
/// (central differences, h = 1e-5 s, tolerance 1e-6 rad/s² as a cross-check only), and its
/// q_d, q̇_d put the hand on the circle with the circle's velocity, by the model's forward
/// kinematics and point Jacobian (not the closed form itself): 1e-12 m and 1e-12 m/s (the
/// closed form is exact; rounding of trigonometry on lengths ~1 m).
#[test]
fn paper_target_acceleration() {
    let s = Scene::paper().unwrap();
    let circle = s.circle().unwrap();
    let h = 1e-5;
    let mut data = Data::new(s.model());
    let mut jac = nalgebra::DMatrix::zeros(3, 10);
    for t in [0.3, 1.7, 4.2] {
        let (q, qd, qdd) = eval(&s, t);
        forward_kinematics(s.model(), &mut data, &q);
        let miss = (s.hand().position(&data) - circle.position(t)).norm();
        assert!(miss <= 1e-12, "t = {t}: the hand is {miss:e} m off the circle");
        s.hand().jacobian(s.model(), &data, &mut jac);
        let v_miss = (&jac * nalgebra::DVector::from_column_slice(&qd) - nalgebra::DVector::from_column_slice(circle.velocity(t).as_slice())).norm();
        assert!(v_miss <= 1e-12, "t = {t}: J q̇_d is {v_miss:e} m/s off the circle's velocity");
        let (_, qp, _) = eval(&s, t + h);
        let (_, qm, _) = eval(&s, t - h);
        for j in 0..10 {
            assert!(((qp[j] - qm[j]) / (2.0 * h) - qdd[j]).abs() < 1e-6, "t = {t}, joint {j}");
        }
    }
}

/// All ten joints free, the elbows kept on the table (`keep_contacts`): along the whole
/// circle the elbows stay on z = 0 to 1e-9 m and the hand on the path to 1e-9 m, q_d(0) is
/// near q0 (the posture), and a 0.3 s run of the two-elbow case tracks the target.
#[test]
fn cartesian_target_keeps_the_elbows_on_the_table() {
    let mut v = paper_json();
    let c = v["target"]["circle"].clone();
    v["target"] = json!({
        "kind": "cartesian",
        "path": {"shape": "circle", "center": c["center"], "normal": [0, 0, 1], "radius": c["radius"],
                 "period": c["period"], "phase": c["phase"]},
        "ik": {"solver": "dls", "keep_contacts": ["elbow4", "elbow7"]}
    });
    v["duration"] = json!(0.3);
    let built = std::time::Instant::now();
    let s = scene_from(&v, None).unwrap();
    eprintln!("paper circle, all joints, elbows kept: {:?}, built in {:?}", s.target().track_stats().unwrap(), built.elapsed());
    let mut data = Data::new(s.model());
    for k in 0..=30 {
        let t = 0.01 * k as f64 + 0.0013;
        let (q, _, _) = eval(&s, t);
        forward_kinematics(s.model(), &mut data, &q);
        for contact in s.contacts() {
            assert!(contact.position(&data).abs() <= 1e-9, "t = {t}: {} at {}", contact.name, contact.position(&data));
        }
        let mut scratch = TargetScratch::new(s.model());
        let r = s.target().hand_desired(t, s.model(), s.hand(), &mut scratch);
        assert!((s.hand().position(&data) - r).norm() <= 1e-9);
    }
    let run = s.run("two-elbow").unwrap().clone();
    let mut last = 0.0;
    sim::run::simulate(&s, &run, |out| {
        last = (out.hand - out.hand_desired).norm();
        Ok(())
    })
    .unwrap();
    // the PD starts 0.054 m off the path; after 0.3 s the hand is within 5 cm of it
    assert!(last < 0.05, "hand {last} m from the target at the end");
}

/// The tagged forms re-serialize to what was read (absent optional keys stay absent), and the
/// paper scene's spec is unchanged by a round trip.
#[test]
fn target_specs_round_trip() {
    let paper = Scene::paper().unwrap();
    let back: Value = serde_json::to_value(paper.spec()).unwrap();
    assert_eq!(back["target"], paper_json()["target"]);
    assert_eq!(back["initial"]["q"], paper_json()["initial"]["q"]);
    let mut v = paper_json();
    let q0 = v["initial"]["q"].clone();
    v["target"] = json!({"kind": "joint-spline", "interpolation": "quintic", "waypoints": [{"t": 0.0, "q": q0}, {"t": 2.0, "q": q0}]});
    let s = scene_from(&v, None).unwrap();
    assert_eq!(serde_json::to_value(s.spec()).unwrap()["target"], v["target"]);
}

/// A joint spline through the paper's q0 and two more waypoints, started with
/// `"initial": {"q": "from-target"}`: q0 = q_d(0), the waypoints are met exactly, q̇_d is zero
/// at the ends; the recorded desired hand is the FK of q_d.
#[test]
fn joint_spline_scene_and_initial_from_target() {
    let mut v = paper_json();
    let q0: Vec<f64> = serde_json::from_value(v["initial"]["q"].clone()).unwrap();
    let mut q1 = q0.clone();
    q1[0] += 0.2;
    q1[9] += 0.1;
    let mut q2 = q1.clone();
    q2[8] -= 0.1;
    v["target"] = json!({"kind": "joint-spline", "waypoints": [{"t": 0.0, "q": q0}, {"t": 1.0, "q": q1}, {"t": 2.5, "q": q2}]});
    v["initial"]["q"] = json!("from-target");
    let s = scene_from(&v, None).unwrap();
    assert_eq!(s.q0(), &q0[..]);
    let (q, qd, _) = eval(&s, 1.0);
    assert!(q.iter().zip(&q1).all(|(a, b)| (a - b).abs() < 1e-15));
    assert!(qd[0] != 0.0);
    let (q, qd, qdd) = eval(&s, 2.5);
    assert!(q.iter().zip(&q2).all(|(a, b)| (a - b).abs() < 1e-15) && qd.iter().all(|x| x.abs() < 1e-14));
    let (qe, qde, qdde) = eval(&s, 4.0);
    assert_eq!(qe, q2);
    assert!(qde.iter().chain(&qdde).all(|&x| x == 0.0) && qdd.len() == 10);
    let mut scratch = TargetScratch::new(s.model());
    let r = s.target().hand_desired(1.0, s.model(), s.hand(), &mut scratch);
    assert!((r - hand_of(&s, &q1)).norm() < 1e-15);
    // from-target is refused for the paper's target (its held joints come from initial.q)
    let mut v = paper_json();
    v["initial"]["q"] = json!("from-target");
    let e = scene_from(&v, None).unwrap_err().to_string();
    assert!(e.contains("initial.q") && e.contains("numeric"), "{e}");
    let mut v = paper_json();
    v["initial"]["q"] = json!("from-targets");
    let e = scene_from(&v, None).unwrap_err().to_string();
    assert!(e.contains("initial.q") && e.contains("from-target"), "{e}");
}

fn hand_of(s: &Scene, q: &[f64]) -> Vector3<f64> {
    let mut data = Data::new(s.model());
    forward_kinematics(s.model(), &mut data, q);
    s.hand().position(&data)
}

/// A CSV with joints in any order and some missing (they hold initial.q): the samples are met;
/// bad files are reported with file, line and column.
#[test]
fn joint_csv_targets_and_their_errors() {
    let mut v = paper_json();
    v["target"] = json!({"kind": "joint-csv", "file": "traj.csv"});
    let q0: Vec<f64> = serde_json::from_value(v["initial"]["q"].clone()).unwrap();
    let csv = "t, joint10 ,joint1\n0,0.7853981633974483,0.0\n1.0,0.9,0.1\n\n2.0,0.8,0.2\n";
    let s = scene_from(&v, Some(csv)).unwrap();
    let (q, _, _) = eval(&s, 1.0);
    assert_eq!((q[0], q[9]), (0.1, 0.9));
    assert_eq!(&q[1..9], &q0[1..9]);
    let cases: [(&'static str, &str); 6] = [
        ("t,joint1\n0,0\n1,x\n", "traj.csv, line 3, column 3: `x` is not a finite number"),
        ("t,joint1,jointX\n0,0,0\n", "traj.csv, line 1, column 10: `jointX` is not a movable joint"),
        ("t,joint1\n0,0\n0,1\n", "traj.csv, line 3, column 1: t = 0 s is not after"),
        ("time,joint1\n0,0\n", "line 1, column 1: the first column must be `t`"),
        ("t,joint1,joint1\n0,0,0\n", "joint `joint1` is listed twice"),
        ("t,joint1\n0,0\n1,2,3\n", "line 3, column 1: 3 fields, the header has 2"),
    ];
    for (text, want) in cases {
        let e = scene_from(&v, Some(text)).unwrap_err().to_string();
        assert!(e.contains("target.file") && e.contains(want), "{e}\nwanted {want}");
    }
}

/// Bad values in the tagged forms name their field and value.
#[test]
fn target_errors_name_the_field() {
    let cases = [
        (json!({"kind": "cartesian", "path": {"shape": "circle", "center": [1.5, 1.5, 0.4], "normal": [0, 0, 1], "radius": 0.0, "period": 5.0}}), "target.path.radius` = 0: must be > 0 m"),
        (json!({"kind": "cartesian", "path": {"shape": "circle", "center": [1.5, 1.5, 0.4], "normal": [0, 0, 0], "radius": 0.1, "period": 5.0}}), "target.path.normal"),
        (json!({"kind": "cartesian", "path": {"shape": "lines", "points": [[1, 1, 0.4], [1.2, 1, 0.4]], "times": [0, 0]}}), "target.path.times[1]"),
        (json!({"kind": "cartesian", "path": {"shape": "circle", "center": [3.5, 3.5, 0.4], "normal": [0, 0, 1], "radius": 0.1, "period": 5.0}}), "target.path` = t = 0.0000 s: the general IK cannot follow the path there: task residual"),
        (json!({"kind": "cartesian", "path": {"shape": "spiral"}}), "unknown variant `spiral`"),
        (json!({"kind": "joint-spline", "waypoints": [{"t": 0, "q": [0, 1]}]}), "target.waypoints[0].q"),
        (json!({"kind": "joint-spline", "waypoints": [{"t": 0, "q": [0,0,0,0,0,0,0,0,0,0], "qq": 1}]}), "target.waypoints[0]"),
        (json!({"kind": "teleport"}), "unknown variant `teleport`"),
        (json!({"kind": "cartesian", "path": {"shape": "circle", "center": [1.5, 1.5, 0.4], "normal": [0, 0, 1], "radius": 0.1, "period": 5.0}, "ik": {"solver": "jt"}}), "field `target.ik.solver`: unknown variant `jt`, expected `dls`"),
        (json!({"kind": "cartesian", "path": {"shape": "circle", "center": [1.5, 1.5, 0.4], "normal": [0, 0, 1], "radiuss": 0.1, "period": 5.0}}), "field `target.path.radiuss` = 0.1: unknown field `radiuss`"),
        (json!({"circle": {"center": [1.5, 1.5, 0.4], "radius": "big", "period": 5.0, "phase": 0.0, "direction": "counter-clockwise"}, "ik": {}}), "field `target.circle.radius`: invalid type: string \"big\", expected f64"),
        (json!({"kind": "cartesian", "path": {"shape": "circle", "center": [1.5, 1.5, 0.4], "normal": [0, 0, 1], "radius": 0.1, "period": 5.0}, "ik": {"keep_contacts": ["knee"]}}), "target.ik.keep_contacts[0]` = knee"),
    ];
    for (target, want) in cases {
        let mut v = paper_json();
        v["target"] = target;
        v["duration"] = json!(0.2);
        let e = scene_from(&v, None).unwrap_err().to_string();
        assert!(e.contains(want), "{e}\nwanted {want}");
    }
}

/// Sanity of the test arms: the circle path type is reachable on the 7-DoF arm with all
/// joints, tracked by `track` with its spline within 1e-9 m of the path between knots.
#[test]
fn track_a_tilted_circle_on_the_seven_dof_arm() {
    let model = seven_dof();
    let q0 = [0.0, 0.3, 0.0, -1.8, 0.0, 2.0, 0.7];
    let hand = body_point(&model, "hand", Vector3::zeros()).unwrap();
    let start = hand_at(&model, &q0);
    let path = CartesianPath::Circle(CirclePath::new(start - Vector3::new(0.0, 0.1, 0.0), Vector3::new(1.0, 0.0, 1.0), Some(Vector3::y()), 0.1, 2.0, 0.0, 1.0).unwrap());
    assert!((path.position(0.0) - start).norm() < 1e-15);
    let ik = GeneralIk { hand, orientation: None, contacts: vec![], active: vec![true; 7], posture: q0.to_vec() };
    let (q, stats) = track(&ik, &model, &path, &q0, 2.0, 0.002).unwrap();
    eprintln!("7-DoF tilted circle: {stats:?}");
    assert!(stats.between_knots <= 1e-9 && stats.at_knots <= 1e-12, "{stats:?}");
    let (mut qq, mut qd, mut qdd) = ([0.0; 7], [0.0; 7], [0.0; 7]);
    q.eval(0.0, &mut qq, &mut qd, &mut qdd);
    // q_d(0) is the posture's nearest solution: the start point is q0's hand, so q_d(0) = q0
    assert!(qq.iter().zip(&q0).all(|(a, b)| (a - b).abs() < 1e-6), "{qq:?}");
    let _ = Target::Cartesian { path, q, stats };
}

/// The example scenes in sim/scenes/targets load (the Cartesian ones with their spline within
/// 1e-9 m of the path between knots) and run 0.2 s of their two-elbow case without failure,
/// the elbows staying on the table to 1e-6 m (the runs are unstabilised, as the paper's).
#[test]
fn example_target_scenes_load_and_run() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/targets");
    for name in ["tilted-circle", "square-lines", "joint-spline"] {
        let s = Scene::load(&dir.join(format!("{name}.json"))).unwrap_or_else(|e| panic!("{e}"));
        if let Some(st) = s.target().track_stats() {
            assert!(st.between_knots <= 1e-9, "{name}: {st:?}");
        }
        assert!(!s.target().describe(s.model()).is_empty());
        let s = s.vary(|spec| spec.duration = 0.2).unwrap();
        let run = s.run("two-elbow").unwrap().clone();
        let mut worst = 0.0f64;
        sim::run::simulate(&s, &run, |out| {
            worst = out.constraint_position.iter().fold(worst, |w, c| w.max(c.abs()));
            Ok(())
        })
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(worst < 1e-6, "{name}: elbows off the table by {worst} m");
    }
}

/// An unknown key is named once in the field path (`contacts[1].plane.normale`, not
/// `…normale.normale`), inside the target as elsewhere.
#[test]
fn unknown_keys_are_named_once() {
    let mut v = paper_json();
    v["contacts"][1]["plane"]["normale"] = json!([0, 0, 1]);
    let e = scene_from(&v, None).unwrap_err().to_string();
    assert!(e.contains("field `contacts[1].plane.normale` = [0,0,1]: unknown field `normale`"), "{e}");
    let mut v = paper_json();
    v["target"]["circle"]["radiuss"] = json!(0.1);
    let e = scene_from(&v, None).unwrap_err().to_string();
    assert!(e.contains("field `target.circle.radiuss` = 0.1: unknown field `radiuss`"), "{e}");
}

/// The 7-DoF arm follows a line segment holding the hand frame's start orientation (the
/// `orientation` task): along the path the orientation error is ≤ 1e-9 rad and the position
/// error ≤ 1e-9 m at off-knot times, and every angle stays inside the ±2.8 rad limits.
#[test]
fn track_with_a_held_orientation() {
    let model = seven_dof();
    let q0 = [0.0, 0.3, 0.0, -1.8, 0.0, 2.0, 0.7];
    let hand = body_point(&model, "hand", Vector3::zeros()).unwrap();
    let mut data = Data::new(&model);
    forward_kinematics(&model, &mut data, &q0);
    let r_hold = data.x_world_body[6].rotation;
    let start = hand_at(&model, &q0);
    let path = CartesianPath::lines(&[start.into(), (start + Vector3::new(-0.1, 0.15, 0.05)).into()], &[0.0, 1.0]).unwrap();
    let ik = GeneralIk { hand, orientation: Some((UnitQuaternion::identity(), r_hold)), contacts: vec![], active: vec![true; 7], posture: q0.to_vec() };
    let (q, stats) = track(&ik, &model, &path, &q0, 1.0, 0.002).unwrap();
    eprintln!("7-DoF line with held orientation: {stats:?}");
    let (mut qq, mut qd, mut qdd) = ([0.0; 7], [0.0; 7], [0.0; 7]);
    for k in 0..=50 {
        let t = (k as f64 * 0.02 + 0.0011).min(1.0);
        q.eval(t, &mut qq, &mut qd, &mut qdd);
        forward_kinematics(&model, &mut data, &qq);
        assert!(data.x_world_body[6].rotation.angle_to(&r_hold) <= 1e-9, "t = {t}");
        assert!((hand.position(&data) - path.position(t)).norm() <= 1e-9, "t = {t}");
        assert!(qq.iter().all(|x| x.abs() <= 2.8 + 1e-12));
    }
}

/// A `joint-csv` run replays from its recording alone: the CSV's text is in the `scene`
/// record, and the replayed run writes the same bytes.
#[test]
fn a_joint_csv_run_replays_from_its_recording_alone() {
    let mut v = paper_json();
    v["target"] = json!({"kind": "joint-csv", "file": "traj.csv"});
    v["duration"] = json!(0.5);
    let csv = "t,joint10,joint1\n0,0.7853981633974483,0.0\n0.25,0.8,0.02\n0.5,0.81,0.03\n";
    let scene = scene_from(&v, Some(csv)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.mcap"), dir.path().join("b.mcap"));
    let run = scene.run("no-elbow").unwrap();
    sim::run::run_to_file(&scene, run, &a, |_| {}).unwrap();
    let (replayed, name) = sim::replay::scene_from_recording(&a).unwrap();
    assert_eq!(name, "no-elbow");
    sim::run::run_to_file(&replayed, replayed.run(&name).unwrap(), &b, |_| {}).unwrap();
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap(), "the replay wrote other bytes");
}

/// An arm with prismatic joints in the hand's chain (a lift along z and a telescope along the
/// forearm, between revolute joints): the general IK's Jacobian column of a prismatic joint is
/// its axis (the hand moves along it without turning), so random reachable targets are reached
/// to 1e-9 m, within the joints' limits.
#[test]
fn general_ik_reaches_targets_through_prismatic_joints() {
    let inertial = r#"<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>"#;
    let xml = format!(
        r#"<robot name="lift"><link name="base"/>
        <link name="l1">{inertial}</link><link name="l2">{inertial}</link><link name="l3">{inertial}</link><link name="l4">{inertial}</link><link name="hand"/>
        <joint name="yaw" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="10" velocity="1"/></joint>
        <joint name="lift" type="prismatic"><parent link="l1"/><child link="l2"/><origin xyz="0 0 0.2"/><axis xyz="0 0 1"/><limit lower="0" upper="0.5" effort="100" velocity="1"/></joint>
        <joint name="shoulder" type="revolute"><parent link="l2"/><child link="l3"/><origin xyz="0.05 0 0"/><axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="10" velocity="1"/></joint>
        <joint name="telescope" type="prismatic"><parent link="l3"/><child link="l4"/><origin xyz="0.3 0 0"/><axis xyz="1 0 0"/><limit lower="0" upper="0.4" effort="100" velocity="1"/></joint>
        <joint name="tool" type="fixed"><parent link="l4"/><child link="hand"/><origin xyz="0.1 0 0"/></joint>
        </robot>"#
    );
    let model = Model::from_urdf(&xml, "lift.urdf", Vector3::new(0.0, 0.0, -9.81)).unwrap();
    let hand = body_point(&model, "hand", Vector3::zeros()).unwrap();
    let mut rng = Lcg(11);
    for case in 0..20 {
        let q_goal = [4.0 * rng.unit() - 2.0, 0.1 + 0.3 * rng.unit(), 1.6 * rng.unit() - 0.8, 0.05 + 0.3 * rng.unit()];
        let r = hand_at(&model, &q_goal);
        let ik = GeneralIk { hand, orientation: None, contacts: vec![], active: vec![true; 4], posture: vec![0.0, 0.25, 0.0, 0.2] };
        let mut q = vec![q_goal[0] + 0.3, q_goal[1] - 0.05, q_goal[2] + 0.3, q_goal[3] - 0.04];
        let mut s = ik.scratch(&model);
        let st = ik.solve(&model, &mut s, &r, &mut q).unwrap_or_else(|e| panic!("case {case}: {e:?}"));
        let miss = (hand_at(&model, &q) - r).norm();
        assert!(miss <= 1e-9, "case {case}: missed by {miss} m ({st:?})");
        assert!((0.0..=0.5).contains(&q[1]) && (0.0..=0.4).contains(&q[3]), "limits: {q:?}");
    }
}
