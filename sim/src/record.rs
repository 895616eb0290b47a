//! Turns the outputs of a run into a recording, through the `schemas` crate (the only code that
//! knows topics and encodings). What a recording holds follows shared VIEWERS.md:
//! `/robot_description` (URDF, once), `/tf` (world → root and every URDF joint, each sample),
//! `/joint_states` (q, q̇, τ of eq 12), `/motors`, `/constraints`, `/hand`, `/energy`,
//! `/hand_points`; and metadata with everything needed to reproduce the run (scene, URDF,
//! tool version, integrator), nothing that differs between two identical runs.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use nalgebra::UnitQuaternion;
use schemas::{
    frame_transform, hand_points, to_log_time, topics, ConstraintState, EnergyState, FrameTransforms, HandState,
    JointState, MotorState, RecordingWriter, RosString, Vec3,
};

use crate::error::RunError;
use crate::scene::{IntegratorSettings, Run, Scene};
use crate::system::Outputs;

/// The world frame's id in `/tf`.
pub const WORLD_FRAME: &str = "world";
/// Name and version of this tool, stored in every recording.
pub const TOOL: &str = concat!("elbow-sim ", env!("CARGO_PKG_VERSION"));

/// Metadata record names.
pub mod records {
    pub const RUN: &str = "run";
    pub const SCENE: &str = "scene";
    pub const URDF: &str = "urdf";
    pub const RESULT: &str = "result";
}

/// The integrator and its settings as metadata text.
pub fn integrator_description(s: &IntegratorSettings) -> BTreeMap<String, String> {
    let mut m = BTreeMap::new();
    match *s {
        IntegratorSettings::Rk4 { step } => {
            m.insert("integrator".into(), "rk4".into());
            m.insert("integrator.step".into(), format!("{step:e}"));
        }
        IntegratorSettings::Dopri45 { rtol, atol, h_max, max_steps } => {
            m.insert("integrator".into(), "dopri45".into());
            m.insert("integrator.rtol".into(), format!("{rtol:e}"));
            m.insert("integrator.atol".into(), format!("{atol:e}"));
            m.insert("integrator.h_max".into(), format!("{h_max:e}"));
            m.insert("integrator.max_steps".into(), max_steps.to_string());
        }
        IntegratorSettings::Rosenbrock { rtol, atol, h_max, max_steps, jacobian_reuse } => {
            m.insert("integrator".into(), "rosenbrock (ROS34PW2, structured Jacobian)".into());
            m.insert("integrator.rtol".into(), format!("{rtol:e}"));
            m.insert("integrator.atol".into(), format!("{atol:e}"));
            m.insert("integrator.h_max".into(), format!("{h_max:e}"));
            m.insert("integrator.max_steps".into(), max_steps.to_string());
            m.insert("integrator.jacobian_reuse".into(), jacobian_reuse.to_string());
        }
        IntegratorSettings::Imex { rtol, atol, h_max, max_steps } => {
            m.insert("integrator".into(), "imex (ARK4(3)6L[2]SA, armature circuits implicit)".into());
            m.insert("integrator.rtol".into(), format!("{rtol:e}"));
            m.insert("integrator.atol".into(), format!("{atol:e}"));
            m.insert("integrator.h_max".into(), format!("{h_max:e}"));
            m.insert("integrator.max_steps".into(), max_steps.to_string());
        }
    }
    m
}

fn v3(v: &nalgebra::Vector3<f64>) -> Vec3 {
    Vec3 { x: v.x, y: v.y, z: v.z }
}

fn set(dst: &mut Vec<f64>, src: &[f64]) {
    dst.clear();
    dst.extend_from_slice(src);
}

/// Writes one run. Create, `record` every sample, then `finish` (or `fail`).
pub struct Recorder<'a> {
    scene: &'a Scene,
    writer: RecordingWriter,
    path: PathBuf,
    motors: MotorState,
    constraints: ConstraintState,
    energy: EnergyState,
    joint_state: JointState,
}

impl<'a> Recorder<'a> {
    /// Open `path` (written under a temporary name until `finish`) and write the metadata and
    /// the robot description.
    pub fn create(path: &Path, scene: &'a Scene, run: &Run) -> Result<Self, RunError> {
        let err = |source| RunError::Recording { path: path.to_path_buf(), source };
        let mut writer = RecordingWriter::create(path).map_err(err)?;
        let joint_names = scene.model.joint_names();
        let contact_names: Vec<&str> = run.contacts.iter().map(|&k| scene.contacts[k].name.as_str()).collect();

        let mut rec = BTreeMap::new();
        rec.insert("tool".to_string(), TOOL.to_string());
        writer.write_metadata(schemas::RECORDING_METADATA, &rec).map_err(err)?;

        let mut m = integrator_description(&scene.integrator);
        m.insert("scene".into(), scene.spec.name.clone());
        m.insert("run".into(), run.name.clone());
        m.insert("contacts".into(), serde_json::to_string(&contact_names).unwrap_or_default());
        m.insert("joint_names".into(), serde_json::to_string(&joint_names).unwrap_or_default());
        m.insert("duration".into(), format!("{:e}", scene.duration));
        m.insert("output_rate".into(), format!("{:e}", scene.output_rate));
        m.insert("mass_matrix".into(), serde_json::to_string(&scene.mass_matrix).unwrap_or_default().trim_matches('"').into());
        m.insert("constraint_solver".into(), serde_json::to_string(&scene.solver).unwrap_or_default().trim_matches('"').into());
        m.insert("stabilization".into(), serde_json::to_string(&scene.stabilization).unwrap_or_default());
        // the model that ran: only the terms the scene has are assembled
        m.insert(
            "model.electrical".into(),
            if scene.drives.quasi_static { "quasi-static current (L = 0)" } else { "L di/dt (one state per motor)" }.into(),
        );
        m.insert("model.contacts".into(), run.contacts.len().to_string());
        m.insert("model.friction".into(), if scene.drives.has_friction { "on" } else { "off" }.into());
        m.insert("model.gravity".into(), if scene.model.gravity == nalgebra::Vector3::zeros() { "off" } else { "on" }.into());
        m.insert("hand_frame".into(), WORLD_FRAME.into());
        m.insert("tool".into(), TOOL.into());
        writer.write_metadata(records::RUN, &m).map_err(err)?;

        let mut s = BTreeMap::new();
        s.insert("json".into(), serde_json::to_string_pretty(&scene.spec).unwrap_or_default());
        s.insert("source".into(), Path::new(&scene.source).file_name().map_or(scene.source.clone(), |f| f.to_string_lossy().into_owned()));
        writer.write_metadata(records::SCENE, &s).map_err(err)?;
        let mut u = BTreeMap::new();
        u.insert("file".into(), scene.spec.urdf.clone());
        u.insert("xml".into(), scene.urdf_xml.clone());
        writer.write_metadata(records::URDF, &u).map_err(err)?;

        writer
            .write(topics::ROBOT_DESCRIPTION, 0, &RosString { data: scene.urdf_xml.clone() })
            .map_err(err)?;
        Ok(Self {
            scene,
            writer,
            path: path.to_path_buf(),
            joint_state: JointState { name: joint_names, ..Default::default() },
            motors: MotorState::default(),
            constraints: ConstraintState::default(),
            energy: EnergyState::default(),
        })
    }

    /// Write every channel for one sample.
    pub fn record(&mut self, o: &Outputs) -> Result<(), RunError> {
        let t_ns = to_log_time(o.t);
        let model = &self.scene.model;
        let path = self.path.clone();
        let err = |source| RunError::Recording { path: path.clone(), source };

        // joint states (effort = the motor torque delivered to the link, eq 12)
        let js = &mut self.joint_state;
        js.stamp_ns = t_ns;
        set(&mut js.position, &o.q);
        set(&mut js.velocity, &o.qd);
        set(&mut js.effort, &o.tau_motor);
        self.writer.write(topics::JOINT_STATES, t_ns, &self.joint_state).map_err(&err)?;

        // transforms: world -> root, then every URDF joint (fixed ones too)
        let mut tf = FrameTransforms { transforms: Vec::with_capacity(model.urdf_joints.len() + 1) };
        tf.transforms.push(frame_transform(t_ns, WORLD_FRAME, &model.root_link, [0.0; 3], [0.0, 0.0, 0.0, 1.0]));
        for j in &model.urdf_joints {
            let x = match j.dof {
                Some(d) => j.origin * UnitQuaternion::from_axis_angle(&model.bodies[d].axis, o.q[d]),
                None => j.origin,
            };
            let t = x.translation.vector;
            let r = x.rotation.coords;
            tf.transforms.push(frame_transform(t_ns, &j.parent_link, &j.child_link, [t.x, t.y, t.z], [r.x, r.y, r.z, r.w]));
        }
        self.writer.write(topics::TF, t_ns, &tf).map_err(&err)?;

        let m = &mut self.motors;
        m.time = o.t;
        set(&mut m.current, &o.current);
        set(&mut m.voltage, &o.voltage);
        set(&mut m.back_emf, &o.back_emf);
        set(&mut m.electric_power, &o.electric_power);
        set(&mut m.torque, &o.tau_motor);
        self.writer.write(topics::MOTORS, t_ns, &self.motors).map_err(&err)?;

        let c = &mut self.constraints;
        c.time = o.t;
        set(&mut c.normal_force, &o.normal_force);
        set(&mut c.position, &o.constraint_position);
        set(&mut c.velocity, &o.constraint_velocity);
        self.writer.write(topics::CONSTRAINTS, t_ns, &self.constraints).map_err(&err)?;

        let e = o.hand - o.hand_desired;
        let hand = HandState { time: o.t, actual: v3(&o.hand), desired: v3(&o.hand_desired), error: v3(&e), error_norm: e.norm() };
        self.writer.write(topics::HAND, t_ns, &hand).map_err(&err)?;
        let pts = [[o.hand.x, o.hand.y, o.hand.z], [o.hand_desired.x, o.hand_desired.y, o.hand_desired.z]];
        self.writer.write(topics::HAND_POINTS, t_ns, &hand_points(t_ns, WORLD_FRAME, &pts)).map_err(&err)?;

        let en = &mut self.energy;
        en.time = o.t;
        set(&mut en.link_work, &o.link_work);
        set(&mut en.electric_energy, &o.electric_energy);
        en.link_work_total = o.link_work.iter().sum();
        en.electric_energy_total = o.electric_energy.iter().sum();
        en.kinetic = o.kinetic;
        en.potential = o.potential;
        en.magnetic = o.magnetic;
        en.resistive_loss = o.loss_resistance;
        en.friction_loss = o.loss_friction;
        en.gear_friction_loss = o.loss_gear_friction;
        en.balance_residual = o.balance_residual;
        self.writer.write(topics::ENERGY, t_ns, &self.energy).map_err(&err)?;
        Ok(())
    }

    /// Close the file with a result record, then rename it into place. `outcome` is `Ok` with
    /// the solver statistics, or the error that stopped the run (the file then holds every
    /// sample up to the failure and says when and why).
    pub fn finish(mut self, outcome: Result<&crate::integrate::Stats, &RunError>) -> Result<PathBuf, RunError> {
        let mut r = BTreeMap::new();
        match outcome {
            Ok(stats) => {
                r.insert("status".into(), "complete".into());
                r.insert("rhs_evals".into(), stats.rhs_evals.to_string());
                r.insert("steps".into(), stats.steps.to_string());
                r.insert("rejected".into(), stats.rejected.to_string());
            }
            Err(e) => {
                r.insert("status".into(), "failed".into());
                r.insert("error".into(), e.to_string());
                if let Some(t) = e.time() {
                    r.insert("error_time".into(), format!("{t:e}"));
                }
            }
        }
        let path = self.path.clone();
        let err = |source| RunError::Recording { path: path.clone(), source };
        self.writer.write_metadata(records::RESULT, &r).map_err(err)?;
        self.writer.finish().map_err(err)
    }
}
