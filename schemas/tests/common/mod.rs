//! Shared fixture: a recording with every message type, awkward f64 values included.
#![allow(dead_code)] // each test binary uses a different part

use std::collections::BTreeMap;
use std::path::Path;

use schemas::{
    frame_transform, hand_points, to_log_time, topics, ConstraintState, EnergyState, HAND_ACTUAL_RGBA, HAND_DESIRED_RGBA,
    FrameTransforms, HandState, JointState, MotorState, RecordingWriter, RosString, Value, Vec3,
};

pub const URDF: &str = r#"<robot name="two_link">
  <link name="base_link"/>
  <link name="upper_arm"/>
  <link name="forearm"/>
  <joint name="shoulder" type="revolute"><parent link="base_link"/><child link="upper_arm"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="10" velocity="5"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper_arm"/><child link="forearm"/>
    <origin xyz="0.5 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="10" velocity="5"/></joint>
</robot>"#;

/// Awkward values: signed zero, subnormal, huge, NaN, irrational fractions.
pub fn val(k: usize, i: usize) -> f64 {
    match (k + i) % 7 {
        0 => -0.0,
        1 => 5e-324,
        2 => f64::MAX,
        3 => f64::NAN,
        4 => -(k as f64) / 3.0,
        5 => std::f64::consts::PI * (i as f64 + 1.0),
        _ => 1e-300 * k as f64,
    }
}

pub fn vals(k: usize, n: usize, salt: usize) -> Vec<f64> {
    (0..n).map(|i| val(k, i + salt)).collect()
}

pub struct Content {
    pub motors: Vec<MotorState>,
    pub constraints: Vec<ConstraintState>,
    pub hands: Vec<HandState>,
    pub energies: Vec<EnergyState>,
    pub joints: Vec<JointState>,
    pub times: Vec<u64>,
}

pub fn content(n: usize) -> Content {
    let times: Vec<u64> = (0..n).map(|k| to_log_time(k as f64 * 0.01)).collect();
    let v3 = |k, s| Vec3 {
        x: val(k, s),
        y: val(k, s + 1),
        z: val(k, s + 2),
    };
    Content {
        motors: (0..n)
            .map(|k| MotorState {
                time: k as f64 * 0.01,
                current: vals(k, 2, 0),
                voltage: vals(k, 2, 1),
                back_emf: vals(k, 2, 2),
                electric_power: vals(k, 2, 3),
                torque: vals(k, 2, 4),
                name: vec!["shoulder".into(), "elbow".into()],
            })
            .collect(),
        constraints: (0..n)
            .map(|k| ConstraintState {
                time: k as f64 * 0.01,
                normal_force: vals(k, 3, 0),
                position: vals(k, 3, 1),
                velocity: if k == 0 { vec![] } else { vals(k, 3, 2) },
                name: vec!["c0".into(), "c1".into(), "c2".into()],
            })
            .collect(),
        hands: (0..n)
            .map(|k| HandState {
                time: k as f64 * 0.01,
                actual: v3(k, 0),
                desired: v3(k, 3),
                error: v3(k, 6),
                error_norm: val(k, 9),
            })
            .collect(),
        energies: (0..n)
            .map(|k| EnergyState {
                time: k as f64 * 0.01,
                link_work: vals(k, 2, 0),
                electric_energy: vals(k, 2, 1),
                link_work_total: val(k, 2),
                electric_energy_total: val(k, 3),
                kinetic: val(k, 4),
                potential: val(k, 5),
                magnetic: val(k, 6),
                resistive_loss: val(k, 7),
                friction_loss: val(k, 8),
                balance_residual: val(k, 9),
                gear_friction_loss: val(k, 10),
                name: vec!["shoulder".into(), "elbow".into()],
            })
            .collect(),
        joints: (0..n)
            .map(|k| JointState {
                stamp_ns: times[k] + 3_000_000_000 * k as u64,
                frame_id: if k % 2 == 0 {
                    String::new()
                } else {
                    "base_link".into()
                },
                name: vec!["shoulder".into(), "elbow".into()],
                position: vals(k, 2, 0),
                velocity: vals(k, 2, 1),
                effort: if k == 1 { vec![] } else { vals(k, 2, 2) },
            })
            .collect(),
        times,
    }
}

pub fn tf(t: u64, k: usize) -> FrameTransforms {
    FrameTransforms {
        transforms: vec![
            frame_transform(
                t,
                "world",
                "base_link",
                [0.0, 0.0, 0.0],
                [0.0, 0.0, 0.0, 1.0],
            ),
            frame_transform(
                t,
                "base_link",
                "upper_arm",
                [0.0, 0.0, 0.1],
                [0.0, 0.0, val(k, 0), 1.0],
            ),
            frame_transform(
                t,
                "upper_arm",
                "forearm",
                [0.5, 0.0, 0.0],
                [0.0, 0.0, -0.5, 0.75],
            ),
        ],
    }
}

pub fn write_all(path: &Path, c: &Content) -> std::path::PathBuf {
    write_all_with(path, c, RecordingWriter::create(path).unwrap())
}

/// [`write_all`] through the writer `w` (created for `path` with any options or tap).
pub fn write_all_with(_path: &Path, c: &Content, mut w: RecordingWriter) -> std::path::PathBuf {
    let mut rec = BTreeMap::new();
    rec.insert("scene".to_string(), "two_link".to_string());
    rec.insert("integrator".to_string(), "rk4".to_string());
    w.write_metadata_raw("recording", &rec).unwrap();
    let mut extra = BTreeMap::new();
    extra.insert("dt".to_string(), "0.001".to_string());
    w.write_metadata_raw("solver", &extra).unwrap();
    w.write(
        topics::ROBOT_DESCRIPTION,
        0,
        &RosString { data: URDF.into() },
    )
    .unwrap();
    for (k, &t) in c.times.iter().enumerate() {
        w.write(topics::TF, t, &tf(t, k)).unwrap();
        w.write(topics::JOINT_STATES, t, &c.joints[k]).unwrap();
        w.write(topics::MOTORS, t, &c.motors[k]).unwrap();
        w.write(topics::CONSTRAINTS, t, &c.constraints[k]).unwrap();
        w.write(topics::HAND, t, &c.hands[k]).unwrap();
        w.write(topics::ENERGY, t, &c.energies[k]).unwrap();
        w.write(
            topics::HAND_POINTS,
            t,
            &hand_points(t, "world", &[([1.0, 2.0, 3.0], HAND_ACTUAL_RGBA), ([val(k, 0), -0.0, 9.5], HAND_DESIRED_RGBA)]),
        )
        .unwrap();
    }
    w.finish().unwrap()
}

pub fn f(v: &Value, path: &str) -> u64 {
    v.get(path)
        .and_then(Value::as_f64)
        .unwrap_or_else(|| panic!("no f64 at {path}: {v:?}"))
        .to_bits()
}

pub fn fv(v: &Value, path: &str) -> Vec<u64> {
    let x = v
        .get(path)
        .and_then(Value::as_f64_vec)
        .unwrap_or_else(|| panic!("no list at {path}: {v:?}"));
    x.into_iter().map(f64::to_bits).collect()
}

pub fn bits(x: &[f64]) -> Vec<u64> {
    x.iter().map(|v| v.to_bits()).collect()
}
