//! Synthetic recordings with known answers, written with [`schemas::RecordingWriter`] (tests
//! only; shared by the library's and the binary's unit tests, so it uses `schemas` alone).
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use schemas::{
    to_log_time, topics, ConstraintState, EnergyState, HandState, MotorState, RecordingWriter, Vec3,
};

type Signal<T> = Box<dyn Fn(f64) -> T>;

/// A recording on the grid `t_k = k dt`, `k = 0..=n`, every signal a function of t.
pub struct Synth {
    pub dt: f64,
    pub n: usize,
    /// Metadata record `run` (scene, run, contacts, joint_names as JSON arrays).
    pub run_meta: BTreeMap<String, String>,
    /// Metadata record `result` (status complete by default).
    pub result_meta: BTreeMap<String, String>,
    /// Topics not to write.
    pub skip: Vec<&'static str>,
    /// Hand error `r - r_d`, m (the norm is computed from it).
    pub hand_error: Signal<[f64; 3]>,
    /// One current per joint, A.
    pub current: Signal<Vec<f64>>,
    /// `(f_n, C, C')` per contact.
    pub constraint: Signal<Vec<[f64; 3]>>,
    /// The whole `/energy` message but `time`.
    pub energy: Signal<EnergyState>,
}

/// `prefix1..=prefixN`.
pub fn names(prefix: &str, n: usize) -> Vec<String> {
    (1..=n).map(|k| format!("{prefix}{k}")).collect()
}

impl Synth {
    /// 1 s at dt = 0.01 s; zero hand error; currents `(j+1) sin(2π t)`; contact forces 1 N;
    /// `W_j = (j+1) t`, `E_j = 2 (j+1) t`, no other energy.
    pub fn new(run: &str, contacts: &[&str], n_joints: usize) -> Self {
        let json = |v: &[String]| serde_json::to_string(v).unwrap();
        let contacts: Vec<String> = contacts.iter().map(|c| c.to_string()).collect();
        let mut run_meta = BTreeMap::new();
        run_meta.insert("scene".into(), "synthetic".into());
        run_meta.insert("run".into(), run.into());
        run_meta.insert("contacts".into(), json(&contacts));
        run_meta.insert("joint_names".into(), json(&names("joint", n_joints)));
        let mut result_meta = BTreeMap::new();
        result_meta.insert("status".into(), "complete".into());
        let nc = contacts.len();
        Self {
            dt: 0.01,
            n: 100,
            run_meta,
            result_meta,
            skip: Vec::new(),
            hand_error: Box::new(|_| [0.0; 3]),
            current: Box::new(move |t| {
                let s = (2.0 * std::f64::consts::PI * t).sin();
                (0..n_joints).map(|j| (j + 1) as f64 * s).collect()
            }),
            constraint: Box::new(move |_| vec![[1.0, 0.0, 0.0]; nc]),
            energy: Box::new(move |t| linear_energy(t, n_joints, 1.0, 2.0)),
        }
    }

    /// Writes `dir/<run>.mcap` and returns its path.
    pub fn write(&self, dir: &Path) -> PathBuf {
        let path = dir.join(format!("{}.mcap", self.run_meta.get("run").unwrap()));
        let mut w = RecordingWriter::create(&path).unwrap();
        w.write_metadata("run", &self.run_meta).unwrap();
        w.write_metadata("result", &self.result_meta).unwrap();
        for k in 0..=self.n {
            let t = k as f64 * self.dt;
            let ns = to_log_time(t);
            if !self.skip.contains(&topics::HAND) {
                let [x, y, z] = (self.hand_error)(t);
                let error = Vec3 { x, y, z };
                let hand = HandState {
                    time: t,
                    error,
                    error_norm: (x * x + y * y + z * z).sqrt(),
                    ..Default::default()
                };
                w.write(topics::HAND, ns, &hand).unwrap();
            }
            if !self.skip.contains(&topics::MOTORS) {
                let current = (self.current)(t);
                let m = MotorState {
                    time: t,
                    current,
                    ..Default::default()
                };
                w.write(topics::MOTORS, ns, &m).unwrap();
            }
            if !self.skip.contains(&topics::CONSTRAINTS) {
                let c = (self.constraint)(t);
                let col = |i: usize| c.iter().map(|v| v[i]).collect();
                let msg = ConstraintState {
                    time: t,
                    normal_force: col(0),
                    position: col(1),
                    velocity: col(2),
                };
                w.write(topics::CONSTRAINTS, ns, &msg).unwrap();
            }
            if !self.skip.contains(&topics::ENERGY) {
                let e = EnergyState {
                    time: t,
                    ..(self.energy)(t)
                };
                w.write(topics::ENERGY, ns, &e).unwrap();
            }
        }
        w.finish().unwrap()
    }
}

/// `W_j = w (j+1) t`, `E_j = e (j+1) t` and their totals; everything else zero.
pub fn linear_energy(t: f64, n_joints: usize, w: f64, e: f64) -> EnergyState {
    let link_work: Vec<f64> = (0..n_joints).map(|j| w * (j + 1) as f64 * t).collect();
    let electric_energy: Vec<f64> = (0..n_joints).map(|j| e * (j + 1) as f64 * t).collect();
    EnergyState {
        link_work_total: link_work.iter().sum(),
        electric_energy_total: electric_energy.iter().sum(),
        link_work,
        electric_energy,
        ..Default::default()
    }
}
