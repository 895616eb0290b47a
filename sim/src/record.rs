//! Turns the outputs of a run into a recording, through the `schemas` crate (the only code that
//! knows topics and encodings). What a recording holds follows shared VIEWERS.md:
//! `/robot_description` (URDF, once), `/tf` (world → root and every URDF joint, each sample),
//! `/joint_states` (q, q̇, τ of eq 12), `/motors`, `/constraints`, `/hand`, `/energy`,
//! `/hand_points`; and metadata with everything needed to reproduce the run (scene, URDF,
//! tool version, integrator), nothing that differs between two identical runs.
//!
//! Every recording also has the scene entities for Foxglove's 3D panel (format version 3,
//! `schemas::markers`): `/scene` at t = 0 (the table: every distinct contact plane of the scene,
//! drawn fainter when this run has no contact on it, so that the no-elbow arm's sinking below
//! the table shows; the hand's target path, sampled on the output grid before the run; the
//! force arrows' scale bar, [`force_scale`]: one scale per scene, from the arm) and
//! `/contact_markers` every sample (the points of the contacts that touch coloured by mode,
//! their rings on the table, the contact force arrows from the table's surface with their
//! labels, the actual and desired hand; a contact that separates is deleted in that sample's
//! message and costs nothing while it stays separated: `schemas::markers::ContactMarkers`),
//! from [`Outputs::contact_point`], `normal_force` and `contacts`.
//!
//! Runs with a non-bilateral contact (issue 11: rigid unilateral contacts after Pfeiffer &
//! Glocker, *Multibody Dynamics with Unilateral Contacts*, 1996; compliant ones) also get
//! `/contacts` (mode, gap, forces, slip, cumulative contact losses per contact, every sample),
//! `/contact_events` (one message per event at the event time, written before the sample that
//! follows it), the metadata record `contacts` (models, parameters, planes, tangent bases, event
//! settings) and the contact totals in `energy_terms`; those with a frictional one (μ > 0) also
//! `/contact_friction` (slip speed, friction use |f_t|/(μ f_n), mode per contact, from the
//! `/contacts` sample: the slip/stick tab of their Foxglove layout plots it). Purely bilateral runs (the paper's) write
//! none of these: their recordings are byte for byte what they were.

use std::path::{Path, PathBuf};

use schemas::{
    frame_transform, hand_points, set_hand_points, timestamp, to_log_time, topics, ConstraintState, ContactEventMsg, ContactFriction, ContactInfo, ContactState,
    ContactsRecord, EnergyState, EnergyTermsRecord, FrameTransforms, HandState, LimitEventInfo, LimitsRecord,
    JointState, Mirror, ModelInfo, MotorState, MotorThermalState, RecordingInfo, RecordingWriter, RosString, RunInfo, RunResult,
    SceneRecord, Setup, Tap, Tapped, UrdfRecord, Vec3, WriterOptions,
};
use schemas::markers::{self, ContactMarkers, ContactSample, ForceScale, MarkerContact, MarkerMode, SceneDescription, TablePlane};
use schemas::{Quaternion, Vector3, HAND_ACTUAL_RGBA, HAND_DESIRED_RGBA};

use crate::dynamics::contact::{Contact, ContactEvent, ContactModel, ContactOutput, ContactSettings};
use crate::error::RunError;
use crate::joint_limits::LimitMonitor;
use crate::scene::{Run, Scene};
use crate::ode::Outputs;

/// The world frame's id in `/tf`.
pub const WORLD_FRAME: &str = "world";
/// Name and version of this tool, stored in every recording.
pub const TOOL: &str = concat!("elbow-sim ", env!("CARGO_PKG_VERSION"));

/// Compact JSON of a setting (its serde form).
fn json<T: serde::Serialize>(v: &T) -> String {
    serde_json::to_string(v).unwrap_or_default()
}

fn v3(v: &nalgebra::Vector3<f64>) -> Vec3 {
    Vec3 { x: v.x, y: v.y, z: v.z }
}

fn set(dst: &mut Vec<f64>, src: &[f64]) {
    dst.clear();
    dst.extend_from_slice(src);
}

/// `dst` = `f` of every contact output (no allocation once `dst` has grown to the run's size).
fn set_with<T>(dst: &mut Vec<T>, src: &[ContactOutput], f: impl Fn(&ContactOutput) -> T) {
    dst.clear();
    dst.extend(src.iter().map(f));
}

/// The contacts of `run`, in its order, with their models.
fn run_contacts(scene: &Scene, run: &Run) -> Vec<Contact> {
    scene.run_contact_models(run)
}

/// Most points of the target path on `/scene`: the output grid, every k-th sample when it has
/// more (a line strip of 1 000 points draws the paper's 0.1 m circle with chords of 0.3 mm).
pub const TARGET_PATH_MAX_POINTS: usize = 1000;

/// The hand's target path sampled on the output grid (every k-th sample, at most
/// [`TARGET_PATH_MAX_POINTS`] points, the last sample included), world frame, m, and the time
/// between two points, s: the same function the run's `/hand` desired position comes from.
pub fn target_path(scene: &Scene) -> (Vec<[f64; 3]>, f64) {
    let dt = 1.0 / scene.output_rate;
    let n = (scene.duration * scene.output_rate).round().max(0.0) as usize;
    let stride = (n + 1).div_ceil(TARGET_PATH_MAX_POINTS).max(1);
    let mut scratch = crate::control::target::TargetScratch::new(&scene.model);
    let mut ks: Vec<usize> = (0..=n).step_by(stride).collect();
    if ks.last() != Some(&n) {
        ks.push(n);
    }
    let points = ks
        .iter()
        .map(|&k| {
            let p = scene.target.hand_desired(k as f64 * dt, &scene.model, &scene.hand, &mut scratch);
            [p.x, p.y, p.z]
        })
        .collect();
    (points, dt * stride as f64)
}

/// The arm's reach from its base, m: the lengths of every URDF joint origin and of the hand
/// point's offset, summed (an upper bound).
pub fn reach(scene: &Scene) -> f64 {
    scene.model.urdf_joints.iter().map(|j| j.origin.translation.vector.norm()).sum::<f64>() + scene.hand.p_body.norm()
}

/// The scale of the force arrows of every run of `scene` ([`ForceScale::for_arm`]): from the
/// arm's mass (every body of the model), its [`reach`] and its number of links (URDF joints
/// with a nonzero origin, the segments the reach sums), not from any run.
pub fn force_scale(scene: &Scene) -> ForceScale {
    let mass: f64 = scene.model.bodies.iter().map(|b| b.inertia.mass).sum();
    let links = scene.model.urdf_joints.iter().filter(|j| j.origin.translation.vector.norm() > 0.0).count() + usize::from(scene.hand.p_body.norm() > 0.0);
    ForceScale::for_arm(mass, reach(scene), links)
}

/// The distinct contact planes of `scene` (every run's), each with the contacts of `run` on it.
pub fn table_planes(scene: &Scene, run: &Run) -> Vec<TablePlane> {
    let mut planes: Vec<TablePlane> = Vec::new();
    for (k, c) in scene.contact_models.iter().enumerate() {
        let n = c.plane.normal_world;
        let normal = [n.x, n.y, n.z];
        let idx = match planes.iter().position(|p| p.normal == normal && p.offset == c.plane.offset) {
            Some(i) => i,
            None => {
                planes.push(TablePlane { normal, offset: c.plane.offset, contacts: Vec::new() });
                planes.len() - 1
            }
        };
        if run.contacts.contains(&k) {
            planes[idx].contacts.push(c.name().to_string());
        }
    }
    planes
}

/// The Foxglove layout's input for the runs of `scene` (`schemas::layout`).
pub fn layout_input(scene: &Scene) -> schemas::layout::LayoutInput {
    let (path, _) = target_path(scene);
    let (focus, camera_distance_m) = schemas::layout::camera_for(&path);
    schemas::layout::LayoutInput {
        title: scene.spec.name.clone(),
        joint_names: scene.model.joint_names(),
        runs: scene
            .runs()
            .iter()
            .map(|r| schemas::layout::LayoutRun {
                run: r.name.clone(),
                contacts: run_contacts(scene, r).iter().map(|c| c.name().to_string()).collect(),
                has_contact_topic: scene.run_is_hybrid(r),
                frictional: friction_coefficients(&run_contacts(scene, r)).map(|mu| mu.iter().map(|&m| m > 0.0).collect()).unwrap_or_default(),
                // whether the run has events is known after it: `sim` sets it then
                has_contact_events: false,
            })
            .collect(),
        focus,
        camera_distance_m,
    }
}

/// Record `contacts`: every contact of the run (its model and parameters, plane, tangent basis)
/// and the event settings.
pub fn contacts_record(contacts: &[Contact], settings: &ContactSettings) -> ContactsRecord {
    let xyz = |v: &nalgebra::Vector3<f64>| [v.x, v.y, v.z];
    let contacts = contacts
        .iter()
        .map(|c| {
            let mut info = ContactInfo {
                name: c.name().to_string(),
                model: c.model.name().to_string(),
                restitution: None,
                friction: None,
                stiffness: None,
                damping: None,
                slip_velocity: None,
                normal: xyz(&c.plane.normal_world),
                offset: c.plane.offset,
                t1: xyz(&c.t1),
                t2: xyz(&c.t2),
                shape: None,
            };
            match c.model {
                ContactModel::Bilateral => {}
                ContactModel::Unilateral { restitution, friction } => {
                    info.restitution = Some(restitution);
                    info.friction = Some(friction);
                }
                ContactModel::Compliant { stiffness, damping, friction, slip_velocity } => {
                    info.stiffness = Some(stiffness);
                    info.damping = Some(damping);
                    info.friction = Some(friction);
                    info.slip_velocity = Some(slip_velocity);
                }
            }
            info
        })
        .collect();
    ContactsRecord {
        contacts,
        time_tolerance: settings.time_tol,
        gap_tolerance: settings.gap_tol,
        velocity_tolerance: settings.vel_tol,
        rest_velocity: settings.rest_velocity,
        max_events: settings.max_events,
        // stated only where it exceeds v_s (loose tolerances): every other record as before
        onset_slip_speed: (settings.onset_slip_speed > crate::dynamics::contact::forward::SLIP_DIRECTION_SPEED).then_some(settings.onset_slip_speed),
    }
}

/// Record `contacts` as a run writes it: [`contacts_record`] with each contact's shape on its
/// link ([`contact_shape`]).
pub fn contacts_record_with_shapes(model: &crate::dynamics::Model, contacts: &[Contact], settings: &ContactSettings) -> ContactsRecord {
    let mut record = contacts_record(contacts, settings);
    for (info, c) in record.contacts.iter_mut().zip(contacts) {
        info.shape = Some(contact_shape(model, c));
    }
    record
}

/// Where contact `c` is on the arm, in a `/tf` frame: its link (the URDF link of the contact's
/// body whose frame is the body's own, else the first link fixed to that body; the root link
/// for a point of the base), its point (the sphere's or rim's centre) and a rim's axis in that
/// link's frame, its kind and radius (`dynamics::contact::shape`).
pub fn contact_shape(model: &crate::dynamics::Model, c: &Contact) -> schemas::ContactShapeInfo {
    use crate::dynamics::contact::ContactShape;
    let p = &c.plane.point;
    let on_body = |f: &&crate::dynamics::model::Frame| f.body == p.body;
    let frame = model
        .frames
        .iter()
        .filter(on_body)
        .find(|f| f.x_body_frame == nalgebra::Isometry3::identity())
        .or_else(|| model.frames.iter().find(on_body));
    let (link, x_frame_body) = match frame {
        Some(f) => (f.name.clone(), f.x_body_frame.inverse()),
        None => (model.root_link.clone(), nalgebra::Isometry3::identity()),
    };
    let center = x_frame_body * nalgebra::Point3::from(p.p_body);
    let axis = match c.shape {
        ContactShape::Rim { axis, .. } => {
            let a = x_frame_body.rotation * axis;
            Some([a.x, a.y, a.z])
        }
        _ => None,
    };
    schemas::ContactShapeInfo { kind: c.shape.name().into(), radius: c.shape.radius(), link, center: [center.x, center.y, center.z], axis }
}

/// Each contact's Coulomb friction coefficient μ, in the order of `contacts` (0 for a bilateral
/// contact: no friction law), when a non-bilateral one has μ > 0 (the run gets
/// `/contact_friction`); `None` otherwise (nothing new is written).
fn friction_coefficients(contacts: &[Contact]) -> Option<Vec<f64>> {
    let mu: Vec<f64> = contacts
        .iter()
        .map(|c| match c.model {
            ContactModel::Bilateral => 0.0,
            ContactModel::Unilateral { friction, .. } | ContactModel::Compliant { friction, .. } => friction,
        })
        .collect();
    mu.iter().any(|&m| m > 0.0).then_some(mu)
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
    /// `/tf`, built once (frame names), its poses and stamps updated every sample.
    tf: FrameTransforms,
    /// `/hand_points`, built once (frame, fields), its points and stamp updated every sample.
    hand_cloud: schemas::PointCloud,
    /// The limits monitor, when the scene monitors limits: its verdict is written at the end
    /// (record `limits`, and counts in `result`), for failed runs too.
    monitor: Option<LimitMonitor>,
    /// The last sample's `E_conv`, `ΣV_s`, `E_s` (record `energy_terms`, scenes that have them).
    terms: [f64; 3],
    /// The run has a non-bilateral contact: `/contacts`, `/contact_events`, record `contacts`.
    hybrid: bool,
    /// `/contacts`, names set once, arrays reused every sample.
    contact_state: ContactState,
    /// `/contact_events`, reused for every event.
    contact_event: ContactEventMsg,
    /// The last sample's impact loss, friction work and damping loss summed over the contacts
    /// (record `energy_terms`, hybrid runs).
    contact_terms: [f64; 3],
    /// `/contact_markers`, built once, updated in place every sample.
    markers: ContactMarkers,
    /// Each contact's plane normal and tangents `(n, t1, t2)`, world frame, in the run's order.
    contact_frames: Vec<[nalgebra::Vector3<f64>; 3]>,
    /// `/supply`, reused every sample (`Some` when the scene has a `supply`).
    supply: Option<schemas::SupplyState>,
    /// The last sample's gear loss and supply energy, regenerated, dumped, loss (record
    /// `energy_terms`, scenes with `gear_friction` or `supply`).
    drive_terms: [f64; 5],
    /// `/contact_friction` and each contact's friction coefficient μ (0 for a frictionless or
    /// bilateral one), in the run's order: `Some` when a non-bilateral contact has μ > 0.
    friction: Option<(ContactFriction, Vec<f64>)>,
    /// The contact audit (hybrid runs): every `/contacts` sample checked against its model's
    /// laws; record `contact_audit` and the count in `result` at the end.
    audit: Option<schemas::ContactAuditor>,
    /// `/motor_temperatures`, when the scene has the thermal model (names set once).
    thermal: Option<MotorThermalState>,
    /// The last sample's heat stored and heat to the ambient (record `energy_terms`).
    heat: [f64; 2],
}

impl<'a> Recorder<'a> {
    /// Open `path` (written under a temporary name until `finish`) and write the metadata and
    /// the robot description.
    pub fn create(path: &Path, scene: &'a Scene, run: &Run) -> Result<Self, RunError> {
        Self::create_tapped(path, scene, run, None)
    }

    /// [`Recorder::create`], every record also fed to `tap` (see
    /// [`RecordingWriter::create_tapped`]); [`Recorder::finish`] returns what it saw.
    #[allow(clippy::result_large_err)] // RunError carries schemas::Error, as `create`
    pub fn create_tapped(path: &Path, scene: &'a Scene, run: &Run, tap: Option<Tap>) -> Result<Self, RunError> {
        Self::create_with(path, scene, run, WriterOptions::default(), tap)
    }

    /// [`Recorder::create_tapped`] with the writer's `options` (compression, chunks, thread:
    /// the bench `record` compares them).
    #[allow(clippy::result_large_err)] // RunError carries schemas::Error, as `create`
    pub fn create_with(path: &Path, scene: &'a Scene, run: &Run, options: WriterOptions, tap: Option<Tap>) -> Result<Self, RunError> {
        Self::create_described(path, scene, run, options, tap, None, &run_contacts(scene, run), &scene.contact_settings())
    }

    /// [`Recorder::create_tapped`], every record also handed to `mirror` as it is written (see
    /// [`RecordingWriter::create_mirrored`]: `sim --live`); the file does not depend on it.
    #[allow(clippy::result_large_err)] // RunError carries schemas::Error, as `create`
    pub fn create_mirrored(path: &Path, scene: &'a Scene, run: &Run, tap: Option<Tap>, mirror: Option<Box<dyn Mirror>>) -> Result<Self, RunError> {
        Self::create_described(path, scene, run, WriterOptions::default(), tap, mirror, &run_contacts(scene, run), &scene.contact_settings())
    }

    /// [`Recorder::create_with`] for the run's `contacts` (in its order, with their models) and
    /// event `settings`: a run with a non-bilateral contact also gets the record `contacts`.
    #[allow(clippy::result_large_err)] // RunError carries schemas::Error, as `create`
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn create_described(
        path: &Path,
        scene: &'a Scene,
        run: &Run,
        options: WriterOptions,
        tap: Option<Tap>,
        mirror: Option<Box<dyn Mirror>>,
        contacts: &[Contact],
        settings: &ContactSettings,
    ) -> Result<Self, RunError> {
        let err = |source| RunError::Recording { path: path.to_path_buf(), source };
        let mut writer = RecordingWriter::create_mirrored(path, options, tap, mirror).map_err(err)?;
        let joint_names = scene.model.joint_names();
        let contact_names: Vec<String> = contacts.iter().map(|c| c.name().to_string()).collect();
        let hybrid = contacts.iter().any(|c| c.model != ContactModel::Bilateral);
        writer.write_record(&RecordingInfo::new(TOOL)).map_err(err)?;
        let run_info = RunInfo {
            scene: scene.spec.name.clone(),
            run: run.name.clone(),
            contacts: contact_names.clone(),
            joint_names: joint_names.clone(),
            setup: Setup {
                integrator: scene.integrator.describe(),
                duration_s: scene.duration,
                output_rate_hz: scene.output_rate,
                mass_matrix: json(&scene.mass_matrix).trim_matches('"').into(),
                constraint_solver: json(&scene.solver).trim_matches('"').into(),
                stabilization: json(&scene.stabilization),
                // the model that ran: only the terms the scene has are assembled
                model: ModelInfo {
                    electrical: scene.drives.electrical.describe().into(),
                    contacts: run.contacts.len(),
                    friction: scene.drives.has_friction,
                    gravity: scene.model.gravity != nalgebra::Vector3::zeros(),
                },
                hand_frame: WORLD_FRAME.into(),
                tool: TOOL.into(),
            },
        };
        writer.write_record(&run_info).map_err(err)?;
        let source = Path::new(&scene.source).file_name().map_or(scene.source.clone(), |f| f.to_string_lossy().into_owned());
        let (json, target_csv) = (serde_json::to_string_pretty(&scene.spec).unwrap_or_default(), scene.target_csv.clone());
        writer.write_record(&SceneRecord { json, source, target_csv }).map_err(err)?;
        writer
            .write_record(&UrdfRecord {
                file: scene.spec.urdf.clone(),
                xml: scene.urdf_xml.clone(),
                meshes: crate::dynamics::urdf::mesh_summary(&scene.meshes),
                repaired_inertias: crate::dynamics::model::repair_summary(&scene.model.repaired_inertias),
            })
            .map_err(err)?;
        let audit = if hybrid {
            let record = contacts_record_with_shapes(&scene.model, contacts, settings);
            writer.write_record(&record).map_err(err)?;
            Some(schemas::ContactAuditor::new(&record))
        } else {
            None
        };

        writer
            .write(topics::ROBOT_DESCRIPTION, 0, &RosString { data: scene.urdf_xml.clone() })
            .map_err(err)?;
        // the table and the target path, once
        let planes = table_planes(scene, run);
        let (path_points, path_dt) = target_path(scene);
        // the contact shapes on their links (none for point contacts: the paper's `/scene` is
        // as it was)
        let shape_infos: Vec<schemas::ContactShapeInfo> = contacts.iter().map(|c| contact_shape(&scene.model, c)).collect();
        let shapes = markers::shape_glyphs(contacts.iter().zip(&shape_infos).map(|(c, s)| (c.name(), s)));
        let scene_msg = markers::scene_update(&SceneDescription {
            frame_id: WORLD_FRAME,
            planes: &planes,
            half_size_m: reach(scene).max(0.25),
            target_path: &path_points,
            target_dt_s: path_dt,
            force_scale: force_scale(scene),
            shapes: &shapes,
        });
        writer.write(topics::SCENE, 0, &scene_msg).map_err(err)?;
        // world -> root (none when the URDF's root link is itself named `world`, as UR5's and
        // Z1's: a frame is not its own parent), then every URDF joint (fixed ones too), in this
        // order every sample
        let mut tf = FrameTransforms { transforms: Vec::with_capacity(scene.model.urdf_joints.len() + 1) };
        if scene.model.root_link != WORLD_FRAME {
            tf.transforms.push(frame_transform(0, WORLD_FRAME, &scene.model.root_link, [0.0; 3], [0.0, 0.0, 0.0, 1.0]));
        }
        for j in &scene.model.urdf_joints {
            tf.transforms.push(frame_transform(0, &j.parent_link, &j.child_link, [0.0; 3], [0.0, 0.0, 0.0, 1.0]));
        }
        Ok(Self {
            scene,
            writer,
            tf,
            hand_cloud: hand_points(0, WORLD_FRAME, &[]),
            path: path.to_path_buf(),

            motors: MotorState { name: joint_names.clone(), ..Default::default() },
            constraints: ConstraintState { name: contact_names.clone(), ..Default::default() },
            energy: EnergyState { name: joint_names.clone(), ..Default::default() },
            joint_state: JointState { name: joint_names, ..Default::default() },
            monitor: LimitMonitor::for_scene(scene, 1.0 / scene.output_rate),
            terms: [0.0; 3],
            hybrid,
            markers: ContactMarkers::new(
                WORLD_FRAME,
                &contacts
                    .iter()
                    .map(|c| {
                        let n = c.plane.normal_world;
                        MarkerContact { name: c.name().to_string(), normal: [n.x, n.y, n.z], offset: c.plane.offset }
                    })
                    .collect::<Vec<_>>(),
                force_scale(scene),
            ),
            contact_state: ContactState { name: contact_names, ..Default::default() },
            contact_event: ContactEventMsg::default(),
            contact_terms: [0.0; 3],
            contact_frames: contacts.iter().map(|c| [c.plane.normal_world.into_inner(), c.t1, c.t2]).collect(),
            supply: scene.supply.is_some().then(schemas::SupplyState::default),
            drive_terms: [0.0; 5],
            audit,
            friction: friction_coefficients(contacts).map(|mu| (ContactFriction::default(), mu)),
            thermal: scene.thermal.as_ref().map(|_| MotorThermalState { name: scene.model.joint_names(), ..Default::default() }),
            heat: [0.0; 2],
        })
    }

    /// Write every channel for one sample.
    pub fn record(&mut self, o: &Outputs) -> Result<(), RunError> {
        if let Some(m) = self.monitor.as_mut() {
            m.observe(o);
        }
        self.terms = [o.loss_conversion, o.stop_energy, o.loss_stop];
        let t_ns = to_log_time(o.t);
        let model = &self.scene.model;

        // the contact events since the previous sample, at their own times (≤ t), before it
        self.record_events(&o.events)?;
        let path = &self.path;
        let err = |source| RunError::Recording { path: path.clone(), source };

        // joint states (effort = the motor torque delivered to the link, eq 12)
        let js = &mut self.joint_state;
        js.stamp_ns = t_ns;
        set(&mut js.position, &o.q);
        set(&mut js.velocity, &o.qd);
        set(&mut js.effort, &o.tau_motor);
        self.writer.write(topics::JOINT_STATES, t_ns, &self.joint_state).map_err(&err)?;

        // transforms: world -> root (identity), then every URDF joint (fixed ones too); the
        // frame names were set by `create` (no allocation per sample)
        let stamp = Some(timestamp(t_ns));
        let roots = self.tf.transforms.len() - model.urdf_joints.len();
        let (root, joints) = self.tf.transforms.split_at_mut(roots);
        root.iter_mut().for_each(|r| r.timestamp = stamp);
        for (j, tr) in model.urdf_joints.iter().zip(joints) {
            let x = match j.dof {
                Some(d) => model.bodies[d].after(&j.origin, o.q[d]),
                None => j.origin,
            };
            let t = x.translation.vector;
            let r = x.rotation.coords;
            tr.timestamp = stamp;
            tr.translation = Some(Vector3 { x: t.x, y: t.y, z: t.z });
            tr.rotation = Some(Quaternion { x: r.x, y: r.y, z: r.z, w: r.w });
        }
        self.writer.write(topics::TF, t_ns, &self.tf).map_err(&err)?;

        let m = &mut self.motors;
        m.time = o.t;
        set(&mut m.current, &o.current);
        set(&mut m.voltage, &o.voltage);
        set(&mut m.back_emf, &o.back_emf);
        set(&mut m.electric_power, &o.electric_power);
        set(&mut m.torque, &o.tau_motor);
        self.writer.write(topics::MOTORS, t_ns, &self.motors).map_err(&err)?;
        if let Some(th) = &mut self.thermal {
            th.time = o.t;
            set(&mut th.winding_temperature, &o.winding_temperature);
            set(&mut th.housing_temperature, &o.housing_temperature);
            set(&mut th.resistance, &o.resistance);
            set(&mut th.copper_loss, &o.copper_loss);
            self.heat = [o.heat_stored, o.heat_to_ambient];
            self.writer.write(topics::MOTOR_TEMPERATURES, t_ns, th).map_err(&err)?;
        }

        let c = &mut self.constraints;
        c.time = o.t;
        set(&mut c.normal_force, &o.normal_force);
        set(&mut c.position, &o.constraint_position);
        set(&mut c.velocity, &o.constraint_velocity);
        self.writer.write(topics::CONSTRAINTS, t_ns, &self.constraints).map_err(&err)?;

        let e = o.hand - o.hand_desired;
        let hand = HandState { time: o.t, actual: v3(&o.hand), desired: v3(&o.hand_desired), error: v3(&e), error_norm: e.norm() };
        self.writer.write(topics::HAND, t_ns, &hand).map_err(&err)?;
        let pts = [([o.hand.x, o.hand.y, o.hand.z], HAND_ACTUAL_RGBA), ([o.hand_desired.x, o.hand_desired.y, o.hand_desired.z], HAND_DESIRED_RGBA)];
        set_hand_points(&mut self.hand_cloud, t_ns, &pts);
        self.writer.write(topics::HAND_POINTS, t_ns, &self.hand_cloud).map_err(&err)?;

        // contact markers: the force of the table on the arm, f_n n + f_t1 t1 + f_t2 t2
        let hybrid = self.hybrid;
        let frames = &self.contact_frames;
        let samples = o.contact_point.iter().zip(frames).enumerate().map(|(k, (p, [n, t1, t2]))| {
            let f_n = o.normal_force.get(k).copied().unwrap_or(0.0);
            let (f_t, mode) = match o.contacts.get(k) {
                Some(c) if hybrid => (c.friction_force, MarkerMode::from_code(c.mode.code(), c.normal_force)),
                _ => ([0.0; 2], MarkerMode::bilateral(f_n)),
            };
            let f = n * f_n + t1 * f_t[0] + t2 * f_t[1];
            ContactSample { point: [p.x, p.y, p.z], force: [f.x, f.y, f.z], mode }
        });
        let msg = self.markers.update(t_ns, samples, [o.hand.x, o.hand.y, o.hand.z], [o.hand_desired.x, o.hand_desired.y, o.hand_desired.z]);
        self.writer.write(topics::CONTACT_MARKERS, t_ns, msg).map_err(&err)?;

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

        if self.hybrid && !o.contacts.is_empty() {
            let cs = &mut self.contact_state;
            cs.time = o.t;
            set_with(&mut cs.mode, &o.contacts, |c| c.mode.code());
            set_with(&mut cs.gap, &o.contacts, |c| c.gap);
            set_with(&mut cs.gap_rate, &o.contacts, |c| c.gap_rate);
            set_with(&mut cs.normal_force, &o.contacts, |c| c.normal_force);
            set_with(&mut cs.friction_force_t1, &o.contacts, |c| c.friction_force[0]);
            set_with(&mut cs.friction_force_t2, &o.contacts, |c| c.friction_force[1]);
            set_with(&mut cs.slip_velocity_t1, &o.contacts, |c| c.slip_velocity[0]);
            set_with(&mut cs.slip_velocity_t2, &o.contacts, |c| c.slip_velocity[1]);
            set_with(&mut cs.impact_loss, &o.contacts, |c| c.impact_loss);
            set_with(&mut cs.friction_work, &o.contacts, |c| c.friction_work);
            set_with(&mut cs.damping_loss, &o.contacts, |c| c.damping_loss);
            self.contact_terms = [cs.impact_loss.iter().sum(), cs.friction_work.iter().sum(), cs.damping_loss.iter().sum()];
            if let Some(audit) = self.audit.as_mut() {
                audit.sample(o.t, cs);
            }
            self.writer.write(topics::CONTACTS, t_ns, &self.contact_state).map_err(&err)?;
            if let Some((msg, mu)) = self.friction.as_mut() {
                msg.set(&self.contact_state, mu);
                self.writer.write(topics::CONTACT_FRICTION, t_ns, &*msg).map_err(&err)?;
            }
        }
        self.drive_terms[0] = o.loss_gear;
        if let (Some(st), Some(sup)) = (self.supply.as_mut(), o.supply) {
            *st = schemas::SupplyState {
                time: o.t,
                power: sup.power,
                bus_power: sup.bus_power,
                energy: sup.energy,
                regenerated: sup.regenerated,
                dumped: sup.dumped,
                loss: sup.loss,
            };
            self.drive_terms[1..].copy_from_slice(&[sup.energy, sup.regenerated, sup.dumped, sup.loss]);
            self.writer.write(topics::SUPPLY, t_ns, &*st).map_err(&err)?;
        }
        Ok(())
    }

    /// Contact events outside a sample: those logged after the last sample of a run that then
    /// failed (drain the system's log and call this before [`Recorder::finish`]), so the file
    /// says what happened up to the failure. Written only for runs with a non-bilateral contact.
    #[allow(clippy::result_large_err)] // RunError carries schemas::Error, as `create`
    pub fn record_events(&mut self, events: &[ContactEvent]) -> Result<(), RunError> {
        if self.hybrid {
            for ev in events {
                self.write_event(ev)?;
            }
        }
        Ok(())
    }

    /// One contact event on `/contact_events`, log time = the event time.
    #[allow(clippy::result_large_err)] // RunError carries schemas::Error, as `create`
    fn write_event(&mut self, ev: &ContactEvent) -> Result<(), RunError> {
        let path = &self.path;
        let e = &mut self.contact_event;
        e.time = ev.t;
        e.contact.clear();
        match self.contact_state.name.get(ev.contact) {
            Some(name) => e.contact.push_str(name),
            None => {
                let detail = format!("contact index {} of a run with {} contacts", ev.contact, self.contact_state.name.len());
                return Err(RunError::Recording {
                    path: path.clone(),
                    source: schemas::Error::BadMetadata { file: path.display().to_string(), record: "contacts".into(), key: "contact".into(), detail },
                });
            }
        }
        e.kind.clear();
        e.kind.push_str(ev.kind.name());
        e.impulse = ev.impulse;
        e.energy_lost = ev.energy_lost;
        e.gap_rate_before = ev.gap_rate_before;
        e.gap_rate_after = ev.gap_rate_after;
        let err = |source| RunError::Recording { path: path.clone(), source };
        self.writer.write(topics::CONTACT_EVENTS, to_log_time(ev.t), &self.contact_event).map_err(err)
    }

    /// Close the file with a result record, then rename it into place. `outcome` is `Ok` with
    /// the solver statistics, or the error that stopped the run (the file then holds every
    /// sample up to the failure and says when and why). With a tap, what it saw.
    pub fn finish(mut self, outcome: Result<&crate::integrate::Stats, &RunError>) -> Result<(PathBuf, Option<Tapped>), RunError> {
        let mut result = match outcome {
            Ok(stats) => RunResult::complete(stats.rhs_evals, stats.steps, stats.rejected),
            Err(e) => RunResult::failed(e.to_string(), e.time()),
        };
        let path = self.path.clone();
        let err = |source| RunError::Recording { path: path.clone(), source };
        // a scene that sets no limits of its own (no `joint_limits`, no drive limits) is still
        // watched against its URDF's limits, and says so only when one was crossed
        let configured = self.scene.spec.joint_limits.is_some() || self.scene.drives.has_limits || self.scene.thermal.is_some();
        let summary = self.monitor.as_ref().map(LimitMonitor::summary).filter(|s| configured || s.exceeded() + s.saturated() > 0);
        if let Some(sum) = summary {
            let (exceeded, saturations) = (sum.exceeded() as u64, sum.saturated() as u64);
            result.limits_exceeded = Some(exceeded);
            result.saturations = Some(saturations);
            let events = sum
                .events
                .iter()
                .map(|e| LimitEventInfo {
                    joint: e.joint.clone(),
                    kind: e.kind.name().into(),
                    limit: e.limit,
                    first_time: e.first_time,
                    time_beyond: e.time_beyond,
                    peak: e.peak,
                    intervals: e.intervals.clone(),
                    interval_count: e.interval_count,
                })
                .collect();
            let rec = LimitsRecord { monitored: sum.monitored, resolution: sum.resolution, exceeded, saturations, events };
            self.writer.write_record(&rec).map_err(err)?;
        }
        let (conv, stops, hybrid) = (self.scene.drives.has_conversion, self.scene.stops.is_some(), self.hybrid);
        let (gear, supply) = (self.scene.gear_friction.is_some(), self.scene.supply.is_some());
        let thermal = self.thermal.is_some();
        if conv || stops || hybrid || thermal || gear || supply {
            let [c, e, l] = self.terms;
            let [imp, fric, damp] = self.contact_terms;
            let rec = EnergyTermsRecord {
                emf_conversion: conv.then_some(c),
                stop_energy: stops.then_some(e),
                stop_loss: stops.then_some(l),
                impact_loss: hybrid.then_some(imp),
                friction_work: hybrid.then_some(fric),
                damping_loss: hybrid.then_some(damp),
                gear_loss: gear.then_some(self.drive_terms[0]),
                supply_energy: supply.then_some(self.drive_terms[1]),
                supply_regenerated: supply.then_some(self.drive_terms[2]),
                supply_dumped: supply.then_some(self.drive_terms[3]),
                supply_loss: supply.then_some(self.drive_terms[4]),
                heat_stored: thermal.then_some(self.heat[0]),
                heat_to_ambient: thermal.then_some(self.heat[1]),
            };
            self.writer.write_record(&rec).map_err(err)?;
        }
        if let Some(audit) = self.audit.take() {
            let rec = schemas::ContactAuditRecord::from(audit.finish());
            result.contact_law_breaches = Some(rec.breaches);
            self.writer.write_record(&rec).map_err(err)?;
        }
        self.writer.write_record(&result).map_err(err)?;
        self.writer.finish_tapped().map_err(err)
    }
}

#[cfg(test)]
mod tests;
