//! The scene's `"robot"` object: absent = today's scene (and absent again when serialized),
//! its errors name the scene field, meshes resolved against `package_paths`.

use serde_json::json;
use sim::dynamics::crba::crba;
use sim::dynamics::Data;
use sim::scene::{Scene, PAPER_SCENE_JSON, PAPER_URDF};

fn with_robot(robot: serde_json::Value) -> String {
    let mut v: serde_json::Value = serde_json::from_str(PAPER_SCENE_JSON).unwrap();
    v["robot"] = robot;
    v.to_string()
}

fn paper_urdf(name: &str) -> Result<String, String> {
    (name == "paper_arm.urdf").then(|| PAPER_URDF.to_string()).ok_or_else(|| format!("no {name}"))
}

/// No `robot` key: not serialized; `"robot": {"repair_inertia": true}` on the paper arm
/// (whose inertias are plausible) repairs nothing and gives the same M(q) bit for bit.
#[test]
fn absent_robot_is_not_serialized_and_repair_changes_nothing_on_the_paper_arm() {
    let paper = Scene::paper().unwrap();
    let text = serde_json::to_string(paper.spec()).unwrap();
    assert!(!text.contains("\"robot\""), "{text}");
    assert!(paper.model().repaired_inertias.is_empty() && paper.model().locked.is_empty() && paper.meshes().is_empty());
    assert_eq!(paper.urdf_xml(), PAPER_URDF);

    let repaired = Scene::from_json(&with_robot(json!({"repair_inertia": true})), "t.json", paper_urdf).unwrap();
    assert!(serde_json::to_string(repaired.spec()).unwrap().contains("\"robot\":{\"repair_inertia\":true}"));
    assert!(repaired.model().repaired_inertias.is_empty());
    let q = paper.q0().to_vec();
    let m1 = crba(paper.model(), &mut Data::new(paper.model()), &q).clone();
    let m2 = crba(repaired.model(), &mut Data::new(repaired.model()), &q).clone();
    assert_eq!(m1, m2);
}

/// Errors of the options name the scene field and the value.
#[test]
fn robot_errors_name_the_scene_field() {
    let e = Scene::from_json(&with_robot(json!({"locked": {"elbow": 0.5}})), "t.json", paper_urdf).unwrap_err().to_string();
    assert!(e.starts_with("t.json: field `robot.locked.elbow` = 0.5: the URDF has no joint of that name"), "{e}");
    let e = Scene::from_json(&with_robot(json!({"locked": {"joint2": 9.0}})), "t.json", paper_urdf).unwrap_err().to_string();
    assert!(e.starts_with("t.json: field `robot.locked.joint2` = 9: outside the joint's <limit>"), "{e}");
    let e = Scene::from_json(&with_robot(json!({"lock": {}})), "t.json", paper_urdf).unwrap_err().to_string();
    assert!(e.contains("robot.lock") && e.contains("unknown field"), "{e}");
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("paper_arm.urdf"), PAPER_URDF).unwrap();
    let scene = dir.path().join("s.json");
    std::fs::write(&scene, with_robot(json!({"package_paths": {"arm": "nowhere"}}))).unwrap();
    let e = Scene::load(&scene).unwrap_err().to_string();
    assert!(e.contains("field `robot.package_paths.arm` = nowhere: no directory"), "{e}");
}

/// A `package://` mesh is rewritten as an absolute `file://` URI in the URDF text the
/// recording stores, the rest of the text unchanged; without `package_paths` the scene says
/// the mesh is not embedded and keeps the text as read.
#[test]
fn package_meshes_are_resolved_in_the_stored_urdf() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("pkgs/arm/meshes")).unwrap();
    std::fs::write(dir.path().join("pkgs/arm/meshes/l2.stl"), b"solid l2\nendsolid l2\n").unwrap();
    let mesh = r#"<visual><geometry><mesh filename="package://arm/meshes/l2.stl"/></geometry></visual>"#;
    let urdf = PAPER_URDF.replacen("<link name=\"link2\">", &format!("<link name=\"link2\">{mesh}"), 1);
    assert_ne!(urdf, PAPER_URDF);
    std::fs::write(dir.path().join("paper_arm.urdf"), &urdf).unwrap();
    let scene = dir.path().join("s.json");
    std::fs::write(&scene, with_robot(json!({"package_paths": {"arm": "pkgs/arm"}}))).unwrap();
    let s = Scene::load(&scene).unwrap();
    let abs = std::path::absolute(dir.path().join("pkgs/arm/meshes/l2.stl")).unwrap();
    let uri = format!("file://{}", abs.display());
    assert_eq!(s.meshes().len(), 1);
    assert!(s.meshes()[0].exists, "{:?}", s.meshes()[0]);
    assert_eq!(s.meshes()[0].uri.as_deref(), Some(uri.as_str()));
    assert_eq!(s.urdf_xml(), urdf.replace("package://arm/meshes/l2.stl", &uri));
    // varied scenes keep the resolved text
    let v = s.vary(|spec| spec.duration = 1.0).unwrap();
    assert_eq!(v.urdf_xml(), s.urdf_xml());

    std::fs::write(&scene, PAPER_SCENE_JSON).unwrap();
    let s = Scene::load(&scene).unwrap();
    assert_eq!(s.urdf_xml(), urdf);
    assert!(s.meshes()[0].uri.is_none() && s.meshes()[0].note.contains("not embedded"), "{:?}", s.meshes());
}

/// A joint that moves only massless links (the paper arm with link10's `<inertial>` removed)
/// runs when its motor has a rotor (M + J_m is regular), and is refused, naming the joint,
/// when the rotor inertia is zero (M + J_m would be singular at every q).
#[test]
fn a_joint_moving_only_massless_links_needs_a_rotor() {
    let inertial10 = r#"<inertial><origin xyz="0 0 0.15" rpy="0 0 0"/><mass value="0.1"/><inertia ixx="0.0007525" ixy="0" ixz="0" iyy="0.0007525" iyz="0" izz="5e-06"/></inertial>"#;
    let (head, tail) = PAPER_URDF.split_at(PAPER_URDF.find(r#"<link name="link10">"#).unwrap());
    assert!(tail.contains(inertial10));
    let urdf = format!("{head}{}", tail.replacen(inertial10, "", 1));
    let read = |name: &str| (name == "paper_arm.urdf").then(|| urdf.clone()).ok_or_else(|| format!("no {name}"));
    let with_rotor = Scene::from_json(PAPER_SCENE_JSON, "t.json", read).unwrap();
    assert_eq!(with_rotor.model().massless_dofs(), vec![9]);
    let mut v: serde_json::Value = serde_json::from_str(PAPER_SCENE_JSON).unwrap();
    v["motor"]["rotor_inertia"] = json!(0.0);
    let e = Scene::from_json(&v.to_string(), "t.json", read).unwrap_err().to_string();
    assert!(e.contains("joint `joint10` moves only massless links") && e.contains("rotor inertia"), "{e}");
}
