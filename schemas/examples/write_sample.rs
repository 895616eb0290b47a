//! Writes a sample recording with every channel for a 2-joint planar arm, for checking with
//! `../shared/tools/check_mcap.py` (beside the repository; Foxglove and Rerun compatibility).
//!
//! `cargo run -p schemas --example write_sample -- /tmp/sample.mcap`
//!
//! The kinematics are exact for the URDF below (rotations about z); the "physics" numbers are
//! made up but shaped like the real ones. `/tf` carries `world -> base_link` and one transform
//! per URDF joint, the fixed `hand_mount` included, as VIEWERS.md requires for Rerun.

use std::collections::BTreeMap;
use std::path::PathBuf;

use schemas::{
    frame_transform, hand_points, to_log_time, topics, ConstraintState, EnergyState, HAND_ACTUAL_RGBA, HAND_DESIRED_RGBA,
    FrameTransforms, HandState, JointState, MotorState, RecordingWriter, RosString, Vec3,
};

const L1: f64 = 0.5;
const L2: f64 = 0.4;
const BASE_Z: f64 = 0.05;

const URDF: &str = r#"<?xml version="1.0"?>
<robot name="sample_arm">
  <link name="base_link">
    <visual><geometry><cylinder radius="0.06" length="0.1"/></geometry></visual>
  </link>
  <link name="upper_arm">
    <visual><origin xyz="0.25 0 0"/><geometry><box size="0.5 0.05 0.05"/></geometry></visual>
  </link>
  <link name="forearm">
    <visual><origin xyz="0.2 0 0"/><geometry><box size="0.4 0.04 0.04"/></geometry></visual>
  </link>
  <link name="hand">
    <visual><geometry><sphere radius="0.03"/></geometry></visual>
  </link>
  <joint name="shoulder" type="revolute">
    <parent link="base_link"/><child link="upper_arm"/>
    <origin xyz="0 0 0.05"/><axis xyz="0 0 1"/>
    <limit lower="-3.14" upper="3.14" effort="20" velocity="5"/>
  </joint>
  <joint name="elbow" type="revolute">
    <parent link="upper_arm"/><child link="forearm"/>
    <origin xyz="0.5 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3.14" upper="3.14" effort="20" velocity="5"/>
  </joint>
  <joint name="hand_mount" type="fixed">
    <parent link="forearm"/><child link="hand"/>
    <origin xyz="0.4 0 0"/>
  </joint>
</robot>
"#;

/// Unit quaternion `[x, y, z, w]` of a rotation by `angle` about z.
fn rot_z(angle: f64) -> [f64; 4] {
    [0.0, 0.0, (angle / 2.0).sin(), (angle / 2.0).cos()]
}

/// Hand position in the world for joint angles `q`.
fn hand(q: [f64; 2]) -> Vec3 {
    Vec3 {
        x: L1 * q[0].cos() + L2 * (q[0] + q[1]).cos(),
        y: L1 * q[0].sin() + L2 * (q[0] + q[1]).sin(),
        z: BASE_Z,
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| "sample.mcap".into());
    let mut w = RecordingWriter::create(&path)?;

    let mut rec = BTreeMap::new();
    rec.insert(
        "generator".to_string(),
        "schemas/examples/write_sample.rs".to_string(),
    );
    rec.insert("joints".to_string(), "shoulder,elbow".to_string());
    rec.insert("output_rate_hz".to_string(), "100".to_string());
    w.write_metadata_raw("recording", &rec)?;
    w.write(
        topics::ROBOT_DESCRIPTION,
        0,
        &RosString {
            data: URDF.to_string(),
        },
    )?;

    let (dt, steps) = (0.01, 300);
    let mut energy = EnergyState {
        link_work: vec![0.0; 2],
        electric_energy: vec![0.0; 2],
        ..EnergyState::default()
    };
    for k in 0..=steps {
        let t = k as f64 * dt;
        let ns = to_log_time(t);
        let q_des = [0.6 * t.sin(), 0.9 * (0.7 * t).sin()];
        let q = [0.6 * (t - 0.05).sin(), 0.9 * (0.7 * (t - 0.05)).sin()];
        let qd = [0.6 * (t - 0.05).cos(), 0.63 * (0.7 * (t - 0.05)).cos()];
        let torque = [
            2.0 * (q_des[0] - q[0]) - 0.1 * qd[0],
            2.0 * (q_des[1] - q[1]) - 0.1 * qd[1],
        ];

        // transforms: world -> base_link, then every URDF joint
        let tf = FrameTransforms {
            transforms: vec![
                frame_transform(ns, "world", "base_link", [0.0; 3], [0.0, 0.0, 0.0, 1.0]),
                frame_transform(
                    ns,
                    "base_link",
                    "upper_arm",
                    [0.0, 0.0, BASE_Z],
                    rot_z(q[0]),
                ),
                frame_transform(ns, "upper_arm", "forearm", [L1, 0.0, 0.0], rot_z(q[1])),
                frame_transform(ns, "forearm", "hand", [L2, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]),
            ],
        };
        w.write(topics::TF, ns, &tf)?;
        let js = JointState {
            stamp_ns: ns,
            frame_id: String::new(),
            name: vec!["shoulder".into(), "elbow".into()],
            position: q.to_vec(),
            velocity: qd.to_vec(),
            effort: torque.to_vec(),
        };
        w.write(topics::JOINT_STATES, ns, &js)?;

        // a DC motor per joint: k = 0.05 N m/A, R = 1 ohm, gear 50
        let current: Vec<f64> = torque.iter().map(|tau| tau / (0.05 * 50.0)).collect();
        let back_emf: Vec<f64> = qd.iter().map(|w| 0.05 * 50.0 * w).collect();
        let voltage: Vec<f64> = current
            .iter()
            .zip(&back_emf)
            .map(|(i, e)| i * 1.0 + e)
            .collect();
        let power: Vec<f64> = current.iter().zip(&voltage).map(|(i, v)| i * v).collect();
        let motors = MotorState {
            time: t,
            current: current.clone(),
            voltage,
            back_emf,
            electric_power: power.clone(),
            torque: torque.to_vec(),
            ..Default::default()
        };
        w.write(topics::MOTORS, ns, &motors)?;

        let gap = 0.02 + 0.01 * (2.0 * t).cos();
        let constraints = ConstraintState {
            time: t,
            normal_force: vec![if gap < 0.015 {
                40.0 * (0.015 - gap)
            } else {
                0.0
            }],
            position: vec![gap],
            velocity: vec![-0.02 * (2.0 * t).sin()],
            ..Default::default()
        };
        w.write(topics::CONSTRAINTS, ns, &constraints)?;

        let (actual, desired) = (hand(q), hand(q_des));
        let error = Vec3 {
            x: actual.x - desired.x,
            y: actual.y - desired.y,
            z: actual.z - desired.z,
        };
        let error_norm = (error.x * error.x + error.y * error.y + error.z * error.z).sqrt();
        w.write(
            topics::HAND,
            ns,
            &HandState {
                time: t,
                actual,
                desired,
                error,
                error_norm,
            },
        )?;
        let points = [
            ([actual.x, actual.y, actual.z], HAND_ACTUAL_RGBA),
            ([desired.x, desired.y, desired.z], HAND_DESIRED_RGBA),
        ];
        w.write(topics::HAND_POINTS, ns, &hand_points(ns, "world", &points))?;

        // energies: rectangle-rule integrals, enough for a sample
        if k > 0 {
            for j in 0..2 {
                energy.link_work[j] += torque[j] * qd[j] * dt;
                energy.electric_energy[j] += power[j] * dt;
                energy.resistive_loss += current[j] * current[j] * dt;
            }
        }
        energy.time = t;
        energy.link_work_total = energy.link_work.iter().sum();
        energy.electric_energy_total = energy.electric_energy.iter().sum();
        energy.kinetic = 0.5 * (qd[0] * qd[0] + qd[1] * qd[1]) * 0.02;
        energy.balance_residual =
            energy.electric_energy_total - energy.link_work_total - energy.resistive_loss;
        w.write(topics::ENERGY, ns, &energy)?;
    }
    let path = w.finish()?;
    println!("wrote {}", path.display());
    Ok(())
}
