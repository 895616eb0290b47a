//! Synthetic recordings with known signals, for tests of readers (feature `synth`): one builder
//! that every test of `analyze` and of the tools uses, written through [`RecordingWriter`] and
//! the typed records, so a test says what it wants (a run, its signals, what is missing) and
//! never spells the format.
//!
//! ```no_run
//! # use schemas::synth::{currents, Synth};
//! let mut s = Synth::new("two-elbow", &["elbow4", "elbow7"], 3); // 1 s at 100 Hz
//! s.motors = Some(currents(|t| vec![t, 2.0 * t, 3.0 * t]));
//! s.energy = None; // no /energy topic
//! let path = s.write_in(std::path::Path::new("/tmp"));
//! ```

use std::path::{Path, PathBuf};

use crate::meta::{ContactsRecord, EnergyTermsRecord, RecordingInfo, RunInfo, RunNames, RunResult, Setup};
use crate::{
    hand_points, to_log_time, topics, HAND_ACTUAL_RGBA, HAND_DESIRED_RGBA, ConstraintState, ContactEventMsg, ContactState, EnergyState, HandState, JointState, MotorState,
    RecordingWriter, Vec3,
};

mod contacts;
pub use contacts::{unilateral, UnilateralTruth};

/// A message as a function of time (its `time` field is set by the writer).
pub type Signal<T> = Box<dyn Fn(f64) -> T>;

/// What to write: metadata records and, per topic, a signal (`None`: the topic is left out).
pub struct Synth {
    /// Samples at `t_k = k dt`, `k = 0..=n`, s.
    pub dt: f64,
    pub n: usize,
    /// Record `recording` with this tool (the writer adds the format version anyway).
    pub tool: Option<String>,
    /// Record `run`: the names (`None`: no `run` record).
    pub names: Option<RunNames>,
    /// With the names, how the run was computed (the full [`RunInfo`] of `sim`).
    pub setup: Option<Setup>,
    /// Record `result` (`None`: no `result` record, as a run cut short).
    pub result: Option<RunResult>,
    /// Close a chunk above this many uncompressed bytes (`None`: the writer's default).
    pub chunk_size: Option<u64>,
    pub hand: Option<Signal<HandState>>,
    pub motors: Option<Signal<MotorState>>,
    pub constraints: Option<Signal<ConstraintState>>,
    pub energy: Option<Signal<EnergyState>>,
    pub joint_states: Option<Signal<JointState>>,
    /// `/hand_points` from the hand's actual and desired positions.
    pub hand_points: bool,
    /// Log times are `t_k × time_scale` (1: `sim`'s; another producer's clock otherwise).
    pub time_scale: f64,
    /// A sample left out of every topic (a gap), by index.
    pub drop_sample: Option<usize>,
    /// `/contacts` (runs with a non-bilateral contact; `None`: no such topic).
    pub contacts: Option<Signal<ContactState>>,
    /// `/contact_events`, each written at its `time` before the first sample at or after it
    /// (as `sim` writes them); the topic is registered when `contacts` is given.
    pub contact_events: Vec<ContactEventMsg>,
    /// Record `contacts`.
    pub contacts_record: Option<ContactsRecord>,
    /// Record `energy_terms`.
    pub energy_terms: Option<EnergyTermsRecord>,
}

impl Synth {
    /// Run `run` of scene `synthetic` with `contacts` and `n_joints` joints (`joint1…`), 1 s at
    /// dt = 0.01 s, complete: zero hand error; currents `(j+1) sin(2π t)`; every contact force
    /// 1 N with no drift; `W_j = (j+1) t`, `E_j = 2 (j+1) t` ([`linear_energy`]).
    pub fn new(run: &str, contacts: &[&str], n_joints: usize) -> Self {
        let nc = contacts.len();
        Self {
            dt: 0.01,
            n: 100,
            tool: None,
            names: Some(RunNames {
                scene: "synthetic".into(),
                run: run.into(),
                contacts: contacts.iter().map(|c| c.to_string()).collect(),
                joint_names: Some((1..=n_joints).map(|k| format!("joint{k}")).collect()),
            }),
            setup: None,
            result: Some(RunResult::complete(0, 0, 0)),
            chunk_size: None,
            hand: Some(hand_error(|_| [0.0; 3])),
            motors: Some(currents(move |t| {
                let s = (2.0 * std::f64::consts::PI * t).sin();
                (0..n_joints).map(|j| (j + 1) as f64 * s).collect()
            })),
            constraints: Some(contact_forces(move |_| vec![[1.0, 0.0, 0.0]; nc])),
            energy: Some(Box::new(move |t| linear_energy(t, n_joints, 1.0, 2.0))),
            joint_states: None,
            hand_points: false,
            time_scale: 1.0,
            drop_sample: None,
            contacts: None,
            contact_events: Vec::new(),
            contacts_record: None,
            energy_terms: None,
        }
    }

    /// With the `run` record's [`Setup`] as `sim` writes it: output rate `1/dt`, duration `n dt`.
    pub fn with_setup(mut self) -> Self {
        self.setup = Some(Setup {
            integrator: crate::IntegratorInfo { method: "rk4".into(), step: Some(self.dt), rtol: None, atol: None, h_max: None, max_steps: None, jacobian_reuse: None },
            duration_s: self.n as f64 * self.dt,
            output_rate_hz: 1.0 / self.dt,
            mass_matrix: "crba".into(),
            constraint_solver: "schur".into(),
            stabilization: r#"{"method":"none"}"#.into(),
            model: crate::ModelInfo { electrical: "L di/dt (one state per motor)".into(), contacts: self.names.as_ref().map_or(0, |n| n.contacts.len()), friction: false, gravity: true },
            hand_frame: "world".into(),
            tool: "synth".into(),
        });
        self
    }

    /// Writes `dir/<run>.mcap` (`synthetic.mcap` without a run record); returns its path.
    pub fn write_in(&self, dir: &Path) -> PathBuf {
        let name = self.names.as_ref().map_or("synthetic", |n| n.run.as_str());
        self.write(&dir.join(format!("{name}.mcap")))
    }

    /// Writes the recording at `path`; returns it. Panics on an I/O error (a test helper).
    pub fn write(&self, path: &Path) -> PathBuf {
        let w = match self.chunk_size {
            Some(n) => RecordingWriter::create_with_chunk_size(path, n),
            None => RecordingWriter::create(path),
        }
        .expect("creating the synthetic recording");
        self.write_with(w).0
    }

    /// [`Synth::write`] through `w` (any options, a tap); returns the path and what the tap saw.
    pub fn write_with(&self, mut w: RecordingWriter) -> (PathBuf, Option<crate::Tapped>) {
        if let Some(tool) = &self.tool {
            w.write_record(&RecordingInfo::new(tool)).expect("recording record");
        }
        match (&self.names, &self.setup) {
            (Some(n), Some(setup)) => {
                let joint_names = n.joint_names.clone().unwrap_or_default();
                let info = RunInfo { scene: n.scene.clone(), run: n.run.clone(), contacts: n.contacts.clone(), joint_names, setup: setup.clone() };
                w.write_record(&info).expect("run record");
            }
            (Some(n), None) => w.write_record(n).expect("run record"),
            (None, _) => {}
        }
        if let Some(r) = &self.contacts_record {
            w.write_record(r).expect("contacts record");
        }
        let mut events = self.contact_events.iter().peekable();
        for k in 0..=self.n {
            if self.drop_sample == Some(k) {
                continue;
            }
            let t = k as f64 * self.dt;
            let ns = to_log_time(t * self.time_scale);
            if let Some(f) = &self.hand {
                let h = HandState { time: t, ..f(t) };
                w.write(topics::HAND, ns, &h).expect("hand");
                if self.hand_points {
                    let p = |v: &Vec3| [v.x, v.y, v.z];
                    w.write(topics::HAND_POINTS, ns, &hand_points(ns, "world", &[(p(&h.actual), HAND_ACTUAL_RGBA), (p(&h.desired), HAND_DESIRED_RGBA)])).expect("hand points");
                }
            }
            if let Some(f) = &self.motors {
                w.write(topics::MOTORS, ns, &MotorState { time: t, ..f(t) }).expect("motors");
            }
            if let Some(f) = &self.constraints {
                w.write(topics::CONSTRAINTS, ns, &ConstraintState { time: t, ..f(t) }).expect("constraints");
            }
            if let Some(f) = &self.energy {
                w.write(topics::ENERGY, ns, &EnergyState { time: t, ..f(t) }).expect("energy");
            }
            if let Some(f) = &self.joint_states {
                w.write(topics::JOINT_STATES, ns, &JointState { stamp_ns: ns, ..f(t) }).expect("joint states");
            }
            if let Some(f) = &self.contacts {
                while let Some(e) = events.next_if(|e| e.time <= t) {
                    w.write(topics::CONTACT_EVENTS, to_log_time(e.time * self.time_scale), e).expect("contact event");
                }
                w.write(topics::CONTACTS, ns, &ContactState { time: t, ..f(t) }).expect("contacts");
            }
        }
        if let Some(r) = &self.energy_terms {
            w.write_record(r).expect("energy_terms record");
        }
        if let Some(r) = &self.result {
            w.write_record(r).expect("result record");
        }
        w.finish_tapped().expect("finishing the synthetic recording")
    }
}

/// `/hand` from the error `r - r_d` (actual = error, desired = 0; the norm computed).
pub fn hand_error(f: impl Fn(f64) -> [f64; 3] + 'static) -> Signal<HandState> {
    Box::new(move |t| {
        let [x, y, z] = f(t);
        HandState { actual: Vec3 { x, y, z }, error: Vec3 { x, y, z }, error_norm: (x * x + y * y + z * z).sqrt(), ..Default::default() }
    })
}

/// `/motors` with these currents (every other array zero, as long).
pub fn currents(f: impl Fn(f64) -> Vec<f64> + 'static) -> Signal<MotorState> {
    Box::new(move |t| {
        let current = f(t);
        let zero = vec![0.0; current.len()];
        MotorState { voltage: zero.clone(), back_emf: zero.clone(), electric_power: zero.clone(), torque: zero, current, ..Default::default() }
    })
}

/// `/constraints` from `[f_n, C, C']` per contact.
pub fn contact_forces(f: impl Fn(f64) -> Vec<[f64; 3]> + 'static) -> Signal<ConstraintState> {
    Box::new(move |t| {
        let c = f(t);
        let col = |i: usize| c.iter().map(|v| v[i]).collect();
        ConstraintState { normal_force: col(0), position: col(1), velocity: col(2), ..Default::default() }
    })
}

/// `/energy` with these per-link `W_j` and `E_j` and their totals; everything else zero.
pub fn energy(link_work: Vec<f64>, electric_energy: Vec<f64>) -> EnergyState {
    EnergyState {
        link_work_total: link_work.iter().sum(),
        electric_energy_total: electric_energy.iter().sum(),
        link_work,
        electric_energy,
        ..Default::default()
    }
}

/// `W_j = w (j+1) t`, `E_j = e (j+1) t` ([`energy`]).
pub fn linear_energy(t: f64, n_joints: usize, w: f64, e: f64) -> EnergyState {
    energy((0..n_joints).map(|j| w * (j + 1) as f64 * t).collect(), (0..n_joints).map(|j| e * (j + 1) as f64 * t).collect())
}

/// `full` cut to what `part` holds: every topic to `part`'s message count, and without the
/// metadata records `part` lacks, for tests comparing a recovered recording with the same
/// messages read whole.
pub fn prefix_like(full: &crate::Recording, part: &crate::Recording) -> crate::Recording {
    let mut out = full.clone();
    for (topic, list) in &mut out.messages {
        list.truncate(part.messages.get(topic).map_or(0, Vec::len));
    }
    out.metadata.retain(|name, _| part.metadata.contains_key(name));
    out
}
