//! Loading URDFs as users find them: prismatic joints against the closed form of a block on a
//! slider, locked and mimic joints, inertia checks and repair, errors naming the line and the
//! element, mesh references.

use std::collections::BTreeMap;

use nalgebra::{DVector, Vector3};

use super::crba::crba;
use super::data::Data;
use super::energy::potential_energy;
use super::kinematics::{body_point, forward_kinematics, forward_velocities};
use super::model::{repair_principal_moments, JointKind, Model, UrdfOptions};
use super::rnea::{bias_forces, rnea};
use super::urdf::{mesh_summary, resolve_meshes};

const BOX: &str = r#"<inertial><mass value="2"/><inertia ixx="0.01" iyy="0.02" izz="0.025" ixy="0" ixz="0" iyz="0"/></inertial>"#;

/// A block of mass 2 kg on a slider inclined by `theta` (axis in the x-z plane).
fn slider(theta: f64) -> String {
    format!(
        r#"<robot name="slider">
  <link name="world"/>
  <link name="block">{BOX}</link>
  <joint name="slide" type="prismatic"><parent link="world"/><child link="block"/>
    <origin xyz="0.1 0.2 0.3" rpy="0 0 0"/><axis xyz="{} 0 {}"/>
    <limit lower="-0.5" upper="0.5" effort="100" velocity="1"/></joint>
</robot>"#,
        theta.cos(),
        theta.sin()
    )
}

/// m q̈ = f − m g sin θ: M = m, the bias is m g sin θ, and RNEA returns m q̈ + m g sin θ, to
/// 1e-14 relative, for a horizontal and two inclined sliders; the block moves along its axis.
#[test]
fn block_on_a_slider_matches_the_closed_form() {
    let g = 9.81;
    for theta in [0.0, 0.3, -1.1] {
        let model = Model::from_urdf(&slider(theta), "slider.urdf", Vector3::new(0.0, 0.0, -g)).unwrap();
        assert_eq!(model.nv, 1);
        assert_eq!(model.bodies[0].kind, JointKind::Prismatic);
        assert_eq!(model.bodies[0].limits.position, Some((-0.5, 0.5)));
        let mut data = Data::new(&model);
        let m = 2.0;
        for (q, qd, qdd) in [(0.0, 0.0, 0.0), (0.3, -0.7, 1.9), (-0.2, 2.0, -4.0)] {
            let mm = crba(&model, &mut data, &[q])[(0, 0)];
            assert!((mm - m).abs() < 1e-14 * m, "theta {theta}: M = {mm}");
            let h = bias_forces(&model, &mut data, &[q], &[qd])[0];
            let want_h = m * g * theta.sin();
            assert!((h - want_h).abs() < 1e-13 * (1.0 + want_h.abs()), "theta {theta}: h = {h}, want {want_h}");
            let tau = rnea(&model, &mut data, &[q], &[qd], &[qdd], &model.gravity)[0];
            let want = m * qdd + want_h;
            assert!((tau - want).abs() < 1e-13 * (1.0 + want.abs()), "theta {theta}: tau = {tau}, want {want}");
            // the block's origin is the joint origin moved by q along the axis
            forward_kinematics(&model, &mut data, &[q]);
            forward_velocities(&model, &mut data, &[qd]);
            let p = data.x_world_body[0].translation.vector;
            let want_p = Vector3::new(0.1 + q * theta.cos(), 0.2, 0.3 + q * theta.sin());
            assert!((p - want_p).norm() < 1e-15, "theta {theta}: {p} vs {want_p}");
            let v = data.v_world[0];
            assert!((v - Vector3::new(qd * theta.cos(), 0.0, qd * theta.sin())).norm() < 1e-15);
            // potential m g z
            let pe = potential_energy(&model, &data);
            assert!((pe - m * g * want_p.z).abs() < 1e-12, "{pe}");
        }
    }
}

/// A prismatic joint on a rotating arm: the centrifugal force m ω² r on the slider (the
/// Coriolis term 2 m ω ṙ on the arm) from RNEA, gravity off, against the closed form of a
/// bead on a rod turning about z: τ_r = m (r̈ − r ω²), τ_θ = (I_z + m r²) ω̇ + 2 m r ṙ ω.
#[test]
fn bead_on_a_rotating_rod_matches_the_closed_form() {
    let xml = r#"<robot name="rod">
  <link name="base"/>
  <link name="rod"/>
  <link name="bead"><inertial><mass value="0.5"/><inertia ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="turn" type="continuous"><parent link="base"/><child link="rod"/><axis xyz="0 0 1"/></joint>
  <joint name="slide" type="prismatic"><parent link="rod"/><child link="bead"/><axis xyz="1 0 0"/></joint>
</robot>"#;
    let model = Model::from_urdf(xml, "rod.urdf", Vector3::zeros()).unwrap();
    let mut data = Data::new(&model);
    let m = 0.5;
    let (r, rd, w, wd, rdd) = (0.4, 0.3, 2.0, 0.7, -1.2);
    let tau = rnea(&model, &mut data, &[0.2, r], &[w, rd], &[wd, rdd], &Vector3::zeros()).clone();
    let want = [m * r * r * wd + 2.0 * m * r * rd * w, m * (rdd - r * w * w)];
    for k in 0..2 {
        assert!((tau[k] - want[k]).abs() < 1e-14, "dof {k}: {} vs {}", tau[k], want[k]);
    }
}

const ARM: &str = r#"<robot name="arm">
  <link name="world"/>
  <link name="base"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="5" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="upper"><inertial><origin xyz="0 0 0.2"/><mass value="1.5"/><inertia ixx="0.02" iyy="0.02" izz="0.003" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="palm"><inertial><mass value="0.4"/><inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="finger_l"><inertial><mass value="0.05"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><mesh filename="package://arm_description/meshes/finger.stl"/></geometry><material name="m"><texture filename="t.png"/></material></visual></link>
  <link name="finger_r"><inertial><mass value="0.05"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><mesh filename="meshes/finger_r.stl" scale="1 1 1"/></geometry></collision></link>
  <joint name="to_world" type="fixed"><parent link="world"/><child link="base"/></joint>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/><origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="30" velocity="2"/></joint>
  <joint name="wrist" type="revolute"><parent link="upper"/><child link="palm"/><origin xyz="0 0 0.4"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="10" velocity="2"/></joint>
  <joint name="finger_l_joint" type="prismatic"><parent link="palm"/><child link="finger_l"/><origin xyz="0 0.01 0.05"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.04" effort="20" velocity="0.2"/></joint>
  <joint name="finger_r_joint" type="prismatic"><parent link="palm"/><child link="finger_r"/><origin xyz="0 -0.01 0.05"/><axis xyz="0 -1 0"/>
    <limit lower="0" upper="0.04" effort="20" velocity="0.2"/><mimic joint="finger_l_joint" multiplier="1" offset="0"/></joint>
  <transmission name="t"><type>transmission_interface/SimpleTransmission</type></transmission>
  <gazebo reference="palm"><material>Gazebo/Grey</material></gazebo>
</robot>"#;

fn locked(pairs: &[(&str, f64)]) -> UrdfOptions {
    UrdfOptions { locked: pairs.iter().map(|(k, v)| (k.to_string(), *v)).collect::<BTreeMap<_, _>>(), ..Default::default() }
}

fn err(xml: &str, options: &UrdfOptions) -> String {
    Model::from_urdf_with(xml, "arm.urdf", Vector3::new(0.0, 0.0, -9.81), options).unwrap_err().to_string()
}

/// The base link welded to the world has an inertia that breaks the triangle inequality
/// (1 + 1 < 5): it never moves, so it is not checked. The mimic finger whose leader moves is
/// refused at the `<mimic>` line with what to do; locking the leader locks both fingers at the
/// mimic's value, and the locked model equals, in M(q) and gravity, the model whose fingers
/// were written as fixed joints at those offsets (to 1e-15).
#[test]
fn locked_and_mimic_joints() {
    let e = err(ARM, &UrdfOptions::default());
    assert!(e.starts_with("arm.urdf:18: <joint name=\"finger_r_joint\"><mimic joint=\"finger_l_joint\">: "), "{e}");
    assert!(e.contains("\"robot\": {\"locked\": {\"finger_l_joint\": VALUE}}"), "{e}");

    let g = Vector3::new(0.0, 0.0, -9.81);
    let model = Model::from_urdf_with(ARM, "arm.urdf", g, &locked(&[("finger_l_joint", 0.03)])).unwrap();
    assert_eq!(model.joint_names(), ["shoulder", "wrist"]);
    assert_eq!(model.locked, [("finger_l_joint".to_string(), 0.03), ("finger_r_joint".to_string(), 0.03)]);
    assert_eq!(model.mimics.len(), 1);
    assert_eq!((model.mimics[0].leader.as_str(), model.mimics[0].locked_at), ("finger_l_joint", 0.03));
    // the same arm with the fingers fixed where the lock puts them
    let fixed = ARM
        .replace(r#"<joint name="finger_l_joint" type="prismatic">"#, r#"<joint name="finger_l_joint" type="fixed">"#)
        .replace(r#"<joint name="finger_r_joint" type="prismatic">"#, r#"<joint name="finger_r_joint" type="fixed">"#)
        .replace(r#"<origin xyz="0 0.01 0.05"/>"#, r#"<origin xyz="0 0.04 0.05"/>"#)
        .replace(r#"<origin xyz="0 -0.01 0.05"/>"#, r#"<origin xyz="0 -0.04 0.05"/>"#);
    let reference = Model::from_urdf(&fixed, "fixed.urdf", g).unwrap();
    let (mut d1, mut d2) = (Data::new(&model), Data::new(&reference));
    for q in [[0.3, -0.4], [1.2, 2.0]] {
        let m1 = crba(&model, &mut d1, &q).clone();
        let m2 = crba(&reference, &mut d2, &q).clone();
        assert!((&m1 - &m2).amax() < 1e-15, "{m1} vs {m2}");
        let g1 = bias_forces(&model, &mut d1, &q, &[0.0, 0.0]).clone();
        let g2 = bias_forces(&reference, &mut d2, &q, &[0.0, 0.0]).clone();
        assert!((&g1 - &g2).amax() < 1e-14, "{g1} vs {g2}");
    }
    // the finger tip frame is where the locked value puts it
    let p = body_point(&model, "finger_l", Vector3::zeros()).unwrap();
    forward_kinematics(&model, &mut d1, &[0.0, 0.0]);
    assert!((p.position(&d1) - Vector3::new(0.0, 0.04, 0.55)).norm() < 1e-15);

    // locking the follower alone is the user's choice; both unlocked moves the fingers
    let free = Model::from_urdf_with(ARM, "arm.urdf", g, &locked(&[("finger_r_joint", 0.0)])).unwrap();
    assert_eq!(free.joint_names(), ["shoulder", "wrist", "finger_l_joint"]);
    assert_eq!(free.bodies[2].kind, JointKind::Prismatic);

    // options that do not fit
    let e = err(ARM, &locked(&[("elbow", 0.0)]));
    assert!(e.contains("robot.locked.elbow = 0: the URDF has no joint of that name") && e.contains("shoulder"), "{e}");
    let e = err(ARM, &locked(&[("finger_l_joint", 0.1)]));
    assert!(e.contains("robot.locked.finger_l_joint = 0.1: outside the joint's <limit> [0, 0.04]"), "{e}");
    let e = err(ARM, &locked(&[("to_world", 0.1)]));
    assert!(e.contains("robot.locked.to_world") && e.contains("fixed already"), "{e}");
}

/// Inertia checks: a moving link's implausible inertia is refused with the line and what to
/// do; with repair it is replaced by the nearest plausible principal moments and reported.
#[test]
fn inertia_checks_and_repair() {
    let bad = ARM.replace(
        r#"<mass value="1.5"/><inertia ixx="0.02" iyy="0.02" izz="0.003""#,
        r#"<mass value="1.5"/><inertia ixx="0.001" iyy="0.001" izz="0.005""#,
    );
    let opts = locked(&[("finger_l_joint", 0.0)]);
    let e = err(&bad, &opts);
    assert!(e.starts_with("arm.urdf:4: <link name=\"upper\"><inertial>: <inertia ixx=0.001"), "{e}");
    assert!(e.contains("triangle inequality") && e.contains("\"robot\": {\"repair_inertia\": true}"), "{e}");
    let neg = ARM.replace(r#"ixx="0.02" iyy="0.02" izz="0.003""#, r#"ixx="-0.02" iyy="0.02" izz="0.003""#);
    assert!(err(&neg, &opts).contains("not positive semi-definite"));

    let opts = UrdfOptions { repair_inertia: true, ..opts };
    let model = Model::from_urdf_with(&bad, "arm.urdf", Vector3::zeros(), &opts).unwrap();
    assert_eq!(model.repaired_inertias.len(), 1);
    let r = &model.repaired_inertias[0];
    assert_eq!(r.link, "upper");
    // (0.001, 0.001, 0.005): c − a − b = 0.003 moved by a third to each: (0.002, 0.002, 0.004)
    for (got, want) in r.after.iter().zip([0.002, 0.002, 0.004]) {
        assert!((got - want).abs() < 1e-15, "{:?}", r.after);
    }
    // M_00 about the shoulder axis (y): the repaired moment plus m d^2 of each link (the
    // distance in x-z: the fingers sit at z = 0.45 m)
    let mut data = Data::new(&model);
    let m = crba(&model, &mut data, &[0.0, 0.0]);
    let want = 0.002 + 1.5 * 0.2f64.powi(2) + (0.001 + 0.4 * 0.4f64.powi(2)) + 2.0 * (1e-5 + 0.05 * 0.45f64.powi(2));
    assert!((m[(0, 0)] - want).abs() < 1e-14, "{} vs {want}", m[(0, 0)]);
    // the projection: non-negative, triangle inequality, nearest on the plane c = a + b
    assert_eq!(repair_principal_moments([-1.0, 2.0, 3.0]), [0.0, 2.0, 3.0].map(|x| x + 1.0 / 3.0 * if x == 3.0 { -1.0 } else { 1.0 }));
    assert_eq!(repair_principal_moments([1.0, 2.0, 3.0]), [1.0, 2.0, 3.0]);
}

/// Every error names the file, the line and the element, and says what to do; elements that
/// do not matter (texture, transmission, gazebo) are skipped.
#[test]
fn errors_name_the_line_and_the_element() {
    let opts = locked(&[("finger_l_joint", 0.0)]);
    let cases: Vec<(String, &str)> = vec![
        (ARM.replace(r#"<mass value="1.5"/>"#, r#"<mass/>"#), "arm.urdf:4: <link name=\"upper\"><inertial><mass>: the attribute `value` (kg) is missing"),
        (ARM.replace(r#"<mass value="1.5"/>"#, r#"<mass value="1,5"/>"#), "arm.urdf:4: <link name=\"upper\"><inertial><mass>: value=\"1,5\" is not a number"),
        (ARM.replace(r#"type="revolute"><parent link="base"/>"#, r#"type="hinge"><parent link="base"/>"#), "arm.urdf:11: <joint name=\"shoulder\">: unknown joint type `hinge`"),
        (ARM.replace(r#"<child link="palm"/>"#, r#"<child link="hand"/>"#), "arm.urdf:13: <joint name=\"wrist\">: <child link=\"hand\">: the URDF defines no link `hand`"),
        (ARM.replace(r#"<joint name="wrist""#, r#"<joint name="shoulder""#), "arm.urdf:13: <joint name=\"shoulder\">: defined twice (first on line 11)"),
        (ARM.replace(r#"<link name="palm">"#, r#"<link name="upper">"#), "arm.urdf:5: <link name=\"upper\">: defined twice (first on line 4)"),
        (ARM.replace(r#"<axis xyz="0 0 1"/>"#, r#"<axis xyz="0 0"/>"#), "arm.urdf:13: <joint name=\"wrist\"><axis>: xyz=\"0 0\" must be three numbers"),
        (ARM.replace(r#"type="fixed"><parent link="world"/>"#, r#"type="floating"><parent link="world"/>"#), "arm.urdf:10: <joint name=\"to_world\">: type=\"floating\": only fixed-base arms"),
        (ARM.replace(r#"<mass value="0.4"/>"#, r#"<mass value="${m}"/>"#), "xacro"),
        (ARM.replace("</link>\n  <link name=\"palm\">", "\n  <link name=\"palm\">"), "arm.urdf:"),
        (ARM.replace("<robot name=\"arm\">", "<robot name=\"arm\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\"><xacro:include filename=\"x\"/>"), "arm.urdf:1: this is a xacro file"),
    ];
    for (xml, want) in cases {
        let e = err(&xml, &opts);
        assert!(e.contains(want), "want {want:?} in {e}");
    }
    // a locked floating joint is welded at its origin
    let floating = ARM.replace(r#"type="fixed"><parent link="world"/>"#, r#"type="floating"><parent link="world"/>"#);
    let mut o = locked(&[("finger_l_joint", 0.0), ("to_world", 0.0)]);
    assert_eq!(Model::from_urdf_with(&floating, "arm.urdf", Vector3::zeros(), &o).unwrap().nv, 2);
    o.locked.insert("to_world".into(), 1.0);
    assert!(err(&floating, &o).contains("robot.locked.to_world = 1: a floating joint is locked at its origin: give 0"));
    // a revolute tool frame with no inertial loads, and is reported as moving only massless
    // links (the scene refuses it unless its motor has a rotor: M(q)'s row is zero); locked,
    // it is no dof at all
    let tool = ARM.replace("</robot>", r#"<link name="tool"/><joint name="tool_spin" type="continuous"><parent link="palm"/><child link="tool"/></joint></robot>"#);
    let m = Model::from_urdf_with(&tool, "arm.urdf", Vector3::zeros(), &opts).unwrap();
    assert_eq!(m.massless_dofs(), vec![m.dof_of_joint("tool_spin").unwrap()]);
    let mut o = opts.clone();
    o.locked.insert("tool_spin".into(), 0.0);
    assert_eq!(Model::from_urdf_with(&tool, "arm.urdf", Vector3::zeros(), &o).unwrap().nv, 2);
    let e = Model::from_urdf(ARM, "arm.xacro", Vector3::zeros()).unwrap_err().to_string();
    assert!(e.contains("run `xacro FILE > robot.urdf` first"), "{e}");
}

/// `package://` resolved against the given package directory, a relative path against the
/// URDF's directory; everything else in the text byte for byte as it was; unknown packages
/// reported as not embedded.
#[test]
fn mesh_references_are_resolved() {
    let dir = tempfile::tempdir().unwrap();
    let pkg = dir.path().join("arm_description");
    std::fs::create_dir_all(pkg.join("meshes")).unwrap();
    std::fs::write(pkg.join("meshes/finger.stl"), b"solid x\nendsolid x\n").unwrap();
    let mut packages = BTreeMap::new();
    packages.insert("arm_description".to_string(), pkg.clone());
    let (text, infos) = resolve_meshes(ARM, "arm.urdf", &packages, Some(dir.path())).unwrap();
    assert_eq!(infos.len(), 2);
    let want_l = format!("file://{}", pkg.join("meshes/finger.stl").display());
    assert_eq!(infos[0].uri.as_deref(), Some(want_l.as_str()));
    assert!(infos[0].exists && infos[0].note.is_empty(), "{:?}", infos[0]);
    assert_eq!((infos[1].link.as_str(), infos[1].line, infos[1].exists), ("finger_r", 9, false));
    assert!(text.contains(&format!("<mesh filename=\"{want_l}\"/>")));
    assert_eq!(text.replace(&want_l, "package://arm_description/meshes/finger.stl").replace(&format!("file://{}/", dir.path().display()), ""), ARM);
    // the summary's remedy fits what is missing: here a file under the given paths
    let summary = mesh_summary(&infos).unwrap();
    assert!(summary.starts_with("meshes not embedded: 1 of 2 ") && summary.contains("the files named are not there") && !summary.contains("give robot.package_paths"), "{summary}");
    // no package path: not embedded, the text unchanged
    let (text, infos) = resolve_meshes(ARM, "arm.urdf", &BTreeMap::new(), None).unwrap();
    assert_eq!(text, ARM);
    assert!(infos.iter().all(|m| m.uri.is_none() && !m.exists));
    assert!(infos[0].note.contains("not embedded"), "{}", infos[0].note);
    let summary = mesh_summary(&infos).unwrap();
    assert!(summary.starts_with("meshes not embedded: 2 of 2 ") && summary.contains("(give robot.package_paths in the scene)"), "{summary}");
}

/// The identities of a mixed revolute/prismatic model hold at a locked configuration too:
/// M q̈ + h = RNEA for the arm with both fingers moving.
#[test]
fn arm_with_prismatic_fingers_satisfies_the_identities() {
    let model = Model::from_urdf_with(ARM, "arm.urdf", Vector3::new(0.0, 0.0, -9.81), &locked(&[("finger_r_joint", 0.01)])).unwrap();
    let mut data = Data::new(&model);
    let (q, qd, qdd) = ([0.3, -1.0, 0.02], [0.5, 1.5, -0.1], [2.0, -1.0, 0.7]);
    let tau = rnea(&model, &mut data, &q, &qd, &qdd, &model.gravity).clone();
    let h = bias_forces(&model, &mut data, &q, &qd).clone();
    let m = crba(&model, &mut data, &q).clone();
    let lhs = &m * DVector::from_column_slice(&qdd) + h;
    assert!((&lhs - &tau).amax() < 1e-12 * tau.amax(), "{lhs} vs {tau}");
    assert!(m.clone().symmetric_eigenvalues().min() > 0.0);
}
