//! A small recording in the layout `analyze` reads, written with `schemas::RecordingWriter`.
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use schemas::{
    to_log_time, topics, ConstraintState, EnergyState, HandState, MotorState, RecordingWriter, Vec3,
};

/// What to write.
pub struct Spec {
    pub samples: usize,
    /// `None`: the writer's default chunk size.
    pub chunk_size: Option<u64>,
    pub run_metadata: bool,
    pub result_metadata: bool,
    /// Write a `HandState` on `/motors` (a schema without `current`).
    pub wrong_motor_schema: bool,
}

impl Default for Spec {
    fn default() -> Self {
        Spec {
            samples: 400,
            chunk_size: Some(4096),
            run_metadata: true,
            result_metadata: true,
            wrong_motor_schema: false,
        }
    }
}

/// Two joints, one contact, 1 kHz; values are smooth functions of t.
pub fn write(path: &Path, spec: &Spec) -> PathBuf {
    let mut w = match spec.chunk_size {
        Some(n) => RecordingWriter::create_with_chunk_size(path, n),
        None => RecordingWriter::create(path),
    }
    .unwrap();
    if spec.run_metadata {
        let mut run = BTreeMap::new();
        run.insert("scene".to_string(), "test".to_string());
        run.insert("run".to_string(), "one-elbow".to_string());
        run.insert("contacts".to_string(), r#"["elbow4"]"#.to_string());
        run.insert(
            "joint_names".to_string(),
            r#"["joint1","joint2"]"#.to_string(),
        );
        w.write_metadata("run", &run).unwrap();
    }
    for k in 0..spec.samples {
        let t = k as f64 * 1e-3;
        let ns = to_log_time(t);
        let e = Vec3 {
            x: 1e-3 * t.sin(),
            y: -1e-3 * t,
            z: 2e-3 * t.cos(),
        };
        let norm = (e.x * e.x + e.y * e.y + e.z * e.z).sqrt();
        w.write(
            topics::HAND,
            ns,
            &HandState {
                time: t,
                error: e,
                error_norm: norm,
                ..Default::default()
            },
        )
        .unwrap();
        if spec.wrong_motor_schema {
            w.write(
                topics::MOTORS,
                ns,
                &HandState {
                    time: t,
                    ..Default::default()
                },
            )
            .unwrap();
        } else {
            let m = MotorState {
                time: t,
                current: vec![(3.0 * t).sin(), -t],
                voltage: vec![1.0, 2.0],
                ..Default::default()
            };
            w.write(topics::MOTORS, ns, &m).unwrap();
        }
        let c = ConstraintState {
            time: t,
            normal_force: vec![1.0 - 4.0 * t],
            position: vec![1e-15 * t],
            velocity: vec![0.0],
        };
        w.write(topics::CONSTRAINTS, ns, &c).unwrap();
        let energy = EnergyState {
            time: t,
            link_work: vec![t, 2.0 * t],
            electric_energy: vec![3.0 * t, 4.0 * t],
            link_work_total: 3.0 * t,
            electric_energy_total: 7.0 * t,
            kinetic: t * t,
            friction_loss: 0.5 * t,
            gear_friction_loss: 0.2 * t,
            balance_residual: 1e-13 * t,
            ..Default::default()
        };
        w.write(topics::ENERGY, ns, &energy).unwrap();
    }
    if spec.result_metadata {
        let mut result = BTreeMap::new();
        result.insert("status".to_string(), "complete".to_string());
        w.write_metadata("result", &result).unwrap();
    }
    w.finish().unwrap()
}
