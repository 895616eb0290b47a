//! Published URDFs of common arms (sim/tests/urdf_corpus/README.md names each source): each
//! one either loads, and then M(q) is symmetric positive definite and the dynamics identities
//! hold at random states, or fails with an error that names the line, the element and what
//! to do. Which of the two is asserted per file.

use std::collections::BTreeMap;

use nalgebra::{DVector, Vector3};
use sim::dynamics::crba::{crba, crba_world};
use sim::dynamics::kinematics::forward_kinematics;
use sim::dynamics::model::{JointKind, Model, UrdfOptions};
use sim::dynamics::rnea::{bias_forces, rnea};
use sim::dynamics::samples::SplitMix64;
use sim::dynamics::{walker_orin, Data};

fn read(name: &str) -> String {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/urdf_corpus").join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn load(name: &str, locked: &[(&str, f64)]) -> Result<Model, String> {
    let options = UrdfOptions { locked: locked.iter().map(|(k, v)| (k.to_string(), *v)).collect::<BTreeMap<_, _>>(), ..Default::default() };
    Model::from_urdf_with(&read(name), name, Vector3::new(0.0, 0.0, -9.81), &options).map_err(|e| e.to_string())
}

/// M(q) symmetric positive definite; CRBA M q̈ + RNEA(q, q̇, 0) = RNEA(q, q̇, q̈) to 1e-10
/// relative; Walker–Orin = CRBA to 1e-12 relative; the world-aligned CRBA = the body-frame one
/// to 1e-14 of √(M_ii M_jj) per entry and their q̈ = M⁻¹ b to 1e-13 relative; at 5 random
/// states within the joint limits.
fn check_dynamics(model: &Model) {
    let mut rng = SplitMix64(0xC0FFEE ^ model.nv as u64);
    let mut data = Data::new(model);
    for _ in 0..5 {
        let q: Vec<f64> = model
            .bodies
            .iter()
            .map(|b| match b.limits.position {
                Some((lo, hi)) => rng.range(lo, hi),
                None => rng.range(-3.0, 3.0),
            })
            .collect();
        let qd = rng.vector(model.nv, -1.0, 1.0);
        let qdd = rng.vector(model.nv, -2.0, 2.0);
        let m = crba(model, &mut data, &q).clone();
        assert_eq!(m, m.transpose(), "{}", model.name);
        let min = m.clone().symmetric_eigenvalues().min();
        assert!(min > 0.0, "{}: smallest eigenvalue of M {min:e}", model.name);
        let tau = rnea(model, &mut data, &q, &qd, &qdd, &model.gravity).clone();
        let h = bias_forces(model, &mut data, &q, &qd).clone();
        let lhs = &m * DVector::from_column_slice(&qdd) + h;
        let err = (&lhs - &tau).amax() / tau.amax().max(1.0);
        assert!(err < 1e-10, "{}: |M qdd + h - RNEA| = {err:e}", model.name);
        let m_wo = walker_orin::mass_matrix(model, &mut data, &q).clone();
        let err = (&m - &m_wo).amax() / m.amax().max(1.0);
        assert!(err < 1e-12, "{}: |M_crba - M_wo| = {err:e}", model.name);
        // the world-aligned CRBA the right-hand side uses (forward.rs) against the body-frame
        // one, entry by entry on each entry's scale, and q̈ = M⁻¹ b from each (issue 24 item 4)
        forward_kinematics(model, &mut data, &q);
        let m_world = crba_world(model, &mut data).clone();
        let n = model.nv;
        for i in 0..n {
            for j in 0..n {
                let e = (m[(i, j)] - m_world[(i, j)]).abs() / (m[(i, i)] * m[(j, j)]).sqrt();
                assert!(e < 1e-14, "{}: M[{i},{j}] world-aligned vs body frame {e:e}", model.name);
            }
        }
        let b = DVector::from_column_slice(&rng.vector(n, -1.0, 1.0));
        let qdd_body = m.clone().cholesky().expect("M is positive definite").solve(&b);
        let qdd_world = m_world.cholesky().expect("M is positive definite").solve(&b);
        let err = (&qdd_world - &qdd_body).norm() / qdd_body.norm();
        assert!(err < 1e-13, "{}: q̈ world-aligned vs body frame {err:e}", model.name);
    }
}

fn names(model: &Model) -> Vec<String> {
    model.joint_names()
}

/// UR5 (example-robot-data, generated from ur_description's xacro): 6 revolute joints, the
/// links welded to the world skipped, loads as is; the UR5 with a gripper link too.
#[test]
fn ur5_loads() {
    for file in ["erd_ur5_robot.urdf", "erd_ur5_gripper.urdf"] {
        let m = load(file, &[]).unwrap();
        assert_eq!(names(&m), ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"], "{file}");
        check_dynamics(&m);
    }
}

/// Franka Panda with its hand: the second finger mimics the first, which moves: refused at
/// the `<mimic>` line with what to do. Locking the first finger locks both (the mimic's
/// multiplier 1, offset 0): 7 revolute joints remain, anti-parallel axes and all.
#[test]
fn panda_with_gripper_needs_its_fingers_locked() {
    let e = load("erd_panda.urdf", &[]).unwrap_err();
    assert!(e.starts_with("erd_panda.urdf:348: <joint name=\"panda_finger_joint2\"><mimic joint=\"panda_finger_joint1\">: "), "{e}");
    assert!(e.contains("\"robot\": {\"locked\": {\"panda_finger_joint1\": VALUE}}"), "{e}");
    let m = load("erd_panda.urdf", &[("panda_finger_joint1", 0.02)]).unwrap();
    assert_eq!(m.nv, 7);
    assert_eq!(m.locked, [("panda_finger_joint1".to_string(), 0.02), ("panda_finger_joint2".to_string(), 0.02)]);
    assert_eq!(m.mimics.len(), 1);
    assert_eq!(m.total_mass() > 15.0, true, "{}", m.total_mass());
    check_dynamics(&m);
    // the fingers free (the follower locked by the user): the first finger is a prismatic dof
    let m = load("erd_panda.urdf", &[("panda_finger_joint2", 0.0)]).unwrap();
    assert_eq!(m.nv, 8);
    assert_eq!(m.bodies[7].kind, JointKind::Prismatic);
    assert_eq!(m.bodies[7].limits.position, Some((0.0, 0.04)));
    check_dynamics(&m);
}

/// xArm7 (excerpt: README): a `<ros2_control>` block whose `<joint>` elements are not URDF
/// joints, `<transmission>`s, `package://` meshes: 7 revolute joints.
#[test]
fn xarm7_loads() {
    let m = load("erd_xarm7_excerpt.urdf", &[]).unwrap();
    assert_eq!(m.nv, 7);
    assert_eq!(m.bodies[0].limits.damping, 10.0);
    check_dynamics(&m);
}

/// Kinova Jaco 2 (j2s6s200): continuous and revolute joints with a two-finger hand.
#[test]
fn kinova_loads() {
    let m = load("erd_kinova.urdf", &[]).unwrap();
    assert!(m.nv >= 6, "{:?}", names(&m));
    assert_eq!(names(&m)[..6], ["j2s6s200_joint_1", "j2s6s200_joint_2", "j2s6s200_joint_3", "j2s6s200_joint_4", "j2s6s200_joint_5", "j2s6s200_joint_6"]);
    check_dynamics(&m);
}

/// Unitree Z1 with its gripper joint: 7 revolute joints; locking the gripper leaves 6.
#[test]
fn z1_loads() {
    let m = load("erd_z1.urdf", &[]).unwrap();
    assert_eq!(m.nv, 7);
    check_dynamics(&m);
    let m = load("erd_z1.urdf", &[("jointGripper", 0.0)]).unwrap();
    assert_eq!(m.nv, 6);
    check_dynamics(&m);
}

/// SO-100 and SO-101 (TheRobotStudio): relative mesh paths, transmissions; 6 revolute joints
/// (the jaw included).
#[test]
fn so_arms_load() {
    for file in ["so100.urdf", "so101_new_calib.urdf"] {
        let m = load(file, &[]).unwrap();
        assert_eq!(m.nv, 6, "{file}: {:?}", names(&m));
        check_dynamics(&m);
    }
}

/// Every corpus file cut, spliced and garbled at random (400 variants each): never a panic,
/// and every error starts with `FILE:` (the file, then a line, or the file-level reason).
#[test]
fn mangled_corpus_files_never_panic() {
    let files = ["erd_ur5_robot.urdf", "erd_panda.urdf", "erd_kinova.urdf", "erd_z1.urdf", "erd_xarm7_excerpt.urdf", "so100.urdf", "so101_new_calib.urdf"];
    let mut rng = SplitMix64(0x5EED);
    let (mut ok, mut refused) = (0, 0);
    for file in files {
        let text = read(file);
        let b = text.as_bytes();
        for _ in 0..400 {
            let i = (rng.next_u64() % b.len() as u64) as usize;
            let j = (i + (rng.next_u64() % 200) as usize).min(b.len());
            let mut v: Vec<u8> = match rng.next_u64() % 4 {
                0 => [&b[..i], &b[j..]].concat(),                  // a cut
                1 => [&b[..j], &b[i..j], &b[j..]].concat(),        // a repeat
                2 => [&b[..i], b"\"<>&=/".as_slice(), &b[i..]].concat(), // syntax inserted
                _ => [&b[..i], b" nan".as_slice(), &b[j..]].concat(),    // a value garbled
            };
            v.truncate(b.len() + 300);
            let mangled = String::from_utf8_lossy(&v).into_owned();
            let res = std::panic::catch_unwind(|| Model::from_urdf(&mangled, file, Vector3::new(0.0, 0.0, -9.81)).map_err(|e| e.to_string()));
            match res {
                Ok(Ok(_)) => ok += 1,
                Ok(Err(e)) => {
                    refused += 1;
                    assert!(e.starts_with(&format!("{file}:")), "{e}");
                    if std::env::var_os("SHOW_MANGLED").is_some() && refused % 97 == 0 {
                        eprintln!("{e}");
                    }
                }
                Err(_) => panic!("{file}: a mangled variant panicked:\n{mangled}"),
            }
        }
    }
    eprintln!("mangled corpus: {ok} loaded, {refused} refused");
    assert!(ok > 0 && refused > 0);
}
