//! Scenes: a JSON file ([`spec::SceneSpec`], unknown keys rejected) validated once into a
//! runnable [`Scene`] (ripgrep's low-args → high-args split). Every error names the file, the
//! field and the value. The paper's scene is built in ([`Scene::paper`]).

pub mod builtin;
pub mod catalogue;
mod contacts;
mod ctx;
pub mod drive;
pub mod hand_load;
mod robot;
pub mod schema;
pub mod schema_key;
pub mod spec;
mod spec_contacts;
mod spec_gear_supply;
pub mod spec_drive;
mod target;

use std::path::Path;

use nalgebra::DVector;

use crate::control::{Circle, Controller, Law, PdGains, Target, YawPlanarIk};
use crate::joint_limits::JointStops;
use crate::dynamics::constraints::PointOnPlane;
use crate::dynamics::contact::{Contact, ContactModel, ContactSettings};
use crate::dynamics::forward::{ConstraintSolver, MassMatrixMethod, Stabilization};
use crate::dynamics::kinematics::{forward_kinematics, forward_velocities, BodyPoint};
use crate::dynamics::motor::{DriveSpec, Drives, Electrical, MotorParams};
use crate::dynamics::urdf::MeshInfo;
use crate::dynamics::{Data, Model};
use crate::error::{short, SceneError};
use crate::limits::{read_text, MAX_INPUT_BYTES, MAX_SAMPLES};
use ctx::{names, non_negative, positive, within, Ctx};
use spec::motor_bounds::*;
use robot::load_robot;
pub use spec::SceneSpec;
use spec::{KindedTarget, LawSpec, PositionLimitMode, TargetSpec};
pub use target::{parse_joint_csv, MAX_BETWEEN_KNOTS};

use crate::integrator::Integrator;

/// The built-in paper scene and its URDF.
pub const PAPER_SCENE_JSON: &str = include_str!("../../scenes/paper.json");
pub const PAPER_URDF: &str = include_str!("../../scenes/paper_arm.urdf");

/// One run of a scene: which contacts are active.
#[derive(Clone, Debug, PartialEq)]
pub struct Run {
    pub name: String,
    /// Indices into `Scene::contacts`.
    pub contacts: Vec<usize>,
}

/// A validated scene, ready to run, and immutable: a variation goes through its spec and is
/// validated again ([`Scene::vary`]), so the scene a recording stores is always the one that ran.
/// Read it through the accessors below.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The spec as read (with defaults filled in): recorded so that a run can be replayed.
    pub(crate) spec: SceneSpec,
    /// Where the scene came from (a path, or "built-in paper scene").
    pub(crate) source: String,
    /// URDF text, as read.
    pub(crate) urdf_xml: String,
    pub(crate) model: Model,
    pub(crate) drives: Drives,
    pub(crate) gains: PdGains,
    /// The controller (its law and gains; `gains` are its k_p, k_d).
    pub(crate) controller: Controller,
    /// Soft stops at the URDF position limits, when the scene asks.
    pub(crate) stops: Option<JointStops>,
    /// The URDF joint limits are monitored: always (with `joint_limits` absent, a record is
    /// written only when one is crossed: `record.rs`).
    pub(crate) monitor_joints: bool,
    pub(crate) hand: BodyPoint,
    /// What the arm is asked to do (`target`).
    pub(crate) target: Target,
    /// The text of the target's CSV file (`joint-csv`), kept for [`Scene::vary`].
    pub(crate) target_csv: Option<String>,
    pub(crate) q0: Vec<f64>,
    pub(crate) qd0: Vec<f64>,
    pub(crate) current0: Vec<f64>,
    pub(crate) contacts: Vec<PointOnPlane>,
    /// The same contacts with their models and tangent bases (same order as `contacts`).
    pub(crate) contact_models: Vec<Contact>,
    /// Tolerances and limits of the event-driven contact handling (`events`).
    pub(crate) contact_settings: ContactSettings,
    pub(crate) runs: Vec<Run>,
    pub(crate) mass_matrix: MassMatrixMethod,
    pub(crate) solver: ConstraintSolver,
    pub(crate) stabilization: Stabilization,
    pub(crate) integrator: Integrator,
    pub(crate) duration: f64,
    pub(crate) output_rate: f64,
    /// The scene file's directory (`None` for text with no file), for `robot.package_paths`.
    pub(crate) dir: Option<std::path::PathBuf>,
    /// The URDF's `<mesh>` references and what became of them (`urdf_xml` holds the resolved
    /// URIs).
    pub(crate) meshes: Vec<MeshInfo>,
    /// Coulomb friction and efficiency of the gears (`gear_friction`), when the scene has them.
    pub(crate) gear_friction: Option<crate::dynamics::gear_friction::GearFriction>,
    /// The supply behind the drives (`supply`), when the scene has one.
    pub(crate) supply: Option<crate::dynamics::supply::Supply>,
    /// The motors' thermal model, when the scene turns it on (`thermal`).
    pub(crate) thermal: Option<crate::dynamics::thermal::Thermal>,
    /// Per joint: what its datasheet drive is (`drives`), or `None` (the `motor` values).
    pub(crate) datasheets: Vec<Option<drive::DatasheetDrive>>,
}

/// Read access (the fields are private to the crate: a scene never changes after validation).
impl Scene {
    /// The spec as read (with defaults filled in): recorded so that a run can be replayed.
    pub fn spec(&self) -> &SceneSpec {
        &self.spec
    }
    /// Where the scene came from (a path, or "built-in paper scene").
    pub fn source(&self) -> &str {
        &self.source
    }
    /// The URDF text, as read.
    pub fn urdf_xml(&self) -> &str {
        &self.urdf_xml
    }
    /// The robot: the read-only dynamics model built from the URDF.
    pub fn model(&self) -> &Model {
        &self.model
    }
    /// The motors and gears, reflected to the link side.
    pub fn drives(&self) -> &Drives {
        &self.drives
    }
    /// The controller's k_p and k_d (the PD voltage law of eq 27 for the paper).
    pub fn gains(&self) -> &PdGains {
        &self.gains
    }
    /// The controller: law and gains.
    pub fn controller(&self) -> &Controller {
        &self.controller
    }
    /// The gears' Coulomb friction and efficiency, if configured.
    pub fn gear_friction(&self) -> Option<&crate::dynamics::gear_friction::GearFriction> {
        self.gear_friction.as_ref()
    }
    /// The supply behind the drives, if configured.
    pub fn supply(&self) -> Option<&crate::dynamics::supply::Supply> {
        self.supply.as_ref()
    }
    /// The soft joint stops, if configured.
    pub fn stops(&self) -> Option<&JointStops> {
        self.stops.as_ref()
    }
    /// Whether the URDF joint limits are monitored.
    pub fn monitors_joint_limits(&self) -> bool {
        self.monitor_joints
    }
    /// The tracked hand point.
    pub fn hand(&self) -> &BodyPoint {
        &self.hand
    }
    /// The target (joint or hand path, and how q_d follows from it).
    pub fn target(&self) -> &Target {
        &self.target
    }
    /// The paper's circle, when the target is the paper's.
    pub fn circle(&self) -> Option<&Circle> {
        self.target.circle()
    }
    /// The paper's closed-form inverse kinematics, when the target is the paper's.
    pub fn ik(&self) -> Option<&YawPlanarIk> {
        self.target.paper_ik()
    }
    /// Initial joint angles, rad.
    pub fn q0(&self) -> &[f64] {
        &self.q0
    }
    /// Initial joint speeds, rad/s.
    pub fn qd0(&self) -> &[f64] {
        &self.qd0
    }
    /// Initial currents, A (zero for quasi-static motors).
    pub fn current0(&self) -> &[f64] {
        &self.current0
    }
    /// Every named contact; a run picks some.
    pub fn contacts(&self) -> &[PointOnPlane] {
        &self.contacts
    }
    /// Every contact with its model (same order as [`Scene::contacts`]).
    pub fn contact_models(&self) -> &[Contact] {
        &self.contact_models
    }
    /// The event-driven contact handling's tolerances and limits (`events`), with the onset's
    /// regularisation bound of the scene's integrator
    /// (`contact::forward::onset_speed_bound`).
    pub fn contact_settings(&self) -> ContactSettings {
        let onset_slip_speed = crate::dynamics::contact::forward::onset_speed_bound(&self.integrator);
        ContactSettings { onset_slip_speed, ..self.contact_settings }
    }
    /// The runs, in the scene's order.
    pub fn runs(&self) -> &[Run] {
        &self.runs
    }
    /// How M(q) is computed.
    pub fn mass_matrix(&self) -> MassMatrixMethod {
        self.mass_matrix
    }
    /// How the constrained system is solved.
    pub fn solver(&self) -> ConstraintSolver {
        self.solver
    }
    /// Constraint stabilisation.
    pub fn stabilization(&self) -> Stabilization {
        self.stabilization
    }
    /// The motors' thermal model, when on.
    pub fn thermal(&self) -> Option<&crate::dynamics::thermal::Thermal> {
        self.thermal.as_ref()
    }
    /// Per joint: its datasheet drive, or `None` (the `motor` values).
    pub fn datasheets(&self) -> &[Option<drive::DatasheetDrive>] {
        &self.datasheets
    }
    /// The validated integrator.
    pub fn integrator(&self) -> Integrator {
        self.integrator
    }
    /// Simulated time of each run, s.
    pub fn duration(&self) -> f64 {
        self.duration
    }
    /// Rate of the recorded samples, Hz.
    pub fn output_rate(&self) -> f64 {
        self.output_rate
    }
    /// The URDF's `<mesh>` references: resolved to `file://` URIs in [`Scene::urdf_xml`] or
    /// not (then the recording's viewers will not find them: say so in its metadata).
    pub fn meshes(&self) -> &[MeshInfo] {
        &self.meshes
    }
}

/// Tolerance on the initial constraint violation |C(q0)|, m, and |Ċ|, m/s.
pub const INITIAL_CONSTRAINT_TOL: f64 = 1e-9;

impl Scene {
    /// The paper's scene (SCENE.md), built into the binary.
    pub fn paper() -> Result<Scene, SceneError> {
        Self::from_json(PAPER_SCENE_JSON, "built-in paper scene", |name| {
            if name == "paper_arm.urdf" {
                Ok(PAPER_URDF.to_string())
            } else {
                Err(format!("the built-in scene has no file `{name}`"))
            }
        })
    }

    /// Read a scene file; its `urdf` is resolved relative to the file's directory.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let file = path.display().to_string();
        let text = read_text(path, MAX_INPUT_BYTES).map_err(|e| SceneError::new(&file, "(file)", "", e.to_string()))?;
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Self::from_json_in(&text, &file, Some(&dir), |name| read_urdf_file(&dir, name))
    }

    /// Parse and validate scene JSON. `read_urdf` returns the text of the named URDF.
    pub fn from_json(
        text: &str,
        source: &str,
        read_urdf: impl Fn(&str) -> Result<String, String>,
    ) -> Result<Scene, SceneError> {
        Self::from_json_in(text, source, None, read_urdf)
    }

    /// [`Scene::from_json`] for a scene file in directory `dir`, against which
    /// `robot.package_paths` and the URDF's relative mesh paths are resolved.
    pub fn from_json_in(
        text: &str,
        source: &str,
        dir: Option<&Path>,
        read_urdf: impl Fn(&str) -> Result<String, String>,
    ) -> Result<Scene, SceneError> {
        let spec = read_spec(text, source)?;
        let urdf_xml = read_urdf(&spec.urdf).map_err(|why| SceneError::new(source, "urdf", &spec.urdf, why))?;
        // a joint CSV is read like the URDF: next to the scene, bounded in size
        let csv = match &spec.target {
            TargetSpec::Kinded(KindedTarget::JointCsv(cs)) => {
                Some(read_urdf(&cs.file).map_err(|why| SceneError::new(source, "target.file", &cs.file, why))?)
            }
            _ => None,
        };
        build(spec, source, urdf_xml, dir, csv)
    }

    /// A variation of this scene: `edit` changes a copy of its spec, which is validated again
    /// (the URDF text is kept), so that a scene is never changed after validation and a
    /// recording's stored scene is always what ran. Errors name the field and the value.
    pub fn vary(&self, edit: impl FnOnce(&mut SceneSpec)) -> Result<Scene, SceneError> {
        let mut spec = self.spec.clone();
        edit(&mut spec);
        build(spec, &self.source, self.urdf_xml.clone(), self.dir.as_deref(), self.target_csv.clone())
    }

    /// The run called `name`.
    pub fn run(&self, name: &str) -> Option<&Run> {
        self.runs.iter().find(|r| r.name == name)
    }

    /// The contacts active in `run` with their models, in its order.
    pub fn run_contact_models(&self, run: &Run) -> Vec<Contact> {
        run.contacts.iter().map(|&k| self.contact_models[k].clone()).collect()
    }

    /// Whether `run` has a non-bilateral contact (then it is integrated event by event).
    pub fn run_is_hybrid(&self, run: &Run) -> bool {
        run.contacts.iter().any(|&k| self.contact_models[k].model != ContactModel::Bilateral)
    }

    /// The contacts active in `run`, in its order.
    pub fn run_contacts(&self, run: &Run) -> Vec<PointOnPlane> {
        run.contacts.iter().map(|&k| self.contacts[k].clone()).collect()
    }
}

/// Parse scene JSON into its spec, without validating it (what a scene file says, as
/// [`Scene::from_json`] reads it: unknown keys refused, a top-level `"$schema"` dropped); errors
/// name `source`, the field and the value.
pub fn read_spec(text: &str, source: &str) -> Result<SceneSpec, SceneError> {
    let de = &mut serde_json::Deserializer::from_str(text);
    // a top-level "$schema" (for editors) is dropped here, before the spec exists
    serde_path_to_error::deserialize(schema_key::SkipSchemaKey(de)).map_err(|e| {
        // a syntax error's path ends in `?` (the position serde had not reached)
        let path = e.path().to_string();
        let path = path.trim_end_matches('?').trim_end_matches('.');
        let why = e.inner().to_string();
        // a value read whole (the target) says where inside it: "at `path.inside`: why"
        let (path, why) = match why.strip_prefix("at `").and_then(|r| r.split_once("`: ")) {
            Some((inside, rest)) => (format!("{path}.{inside}"), rest.to_string()),
            None => (path.to_string(), why),
        };
        let path = path.as_str();
        // a tagged value (the integrator) is read whole: name the unknown key inside it
        if let Some(key) = why.strip_prefix("unknown field `").and_then(|r| r.split('`').next()) {
            // serde_path_to_error's path already ends in the unknown key; a tagged value's does not
            let field = if path.is_empty() {
                key.to_string()
            } else if path == key || path.ends_with(&format!(".{key}")) {
                path.to_string()
            } else {
                format!("{path}.{key}")
            };
            let value = serde_json::from_str::<serde_json::Value>(text)
                .ok()
                .and_then(|doc| doc.pointer(&format!("/{}", field.replace('.', "/").replace('[', "/").replace(']', ""))).map(|v| v.to_string()))
                .unwrap_or_default();
            return SceneError::new(source, field, value, why);
        }
        let field = if path.is_empty() { "(document)" } else { path };
        SceneError::new(source, field, json_literal_at(text, e.inner()), why)
    })
}

/// The text of the URDF `name` next to a scene in `dir` (a regular file of at most
/// [`MAX_INPUT_BYTES`]), or why not, naming the path.
pub fn read_urdf_file(dir: &Path, name: &str) -> Result<String, String> {
    let p = dir.join(name);
    read_text(&p, MAX_INPUT_BYTES).map_err(|e| format!("cannot read {}: {e}", p.display()))
}

/// The number literal a "number out of range" error points at (e.g. `1e999`), else "".
fn json_literal_at(text: &str, e: &serde_json::Error) -> String {
    if !e.to_string().starts_with("number out of range") {
        return String::new();
    }
    let line = text.lines().nth(e.line().saturating_sub(1)).unwrap_or("");
    let end = e.column().min(line.len());
    let head = line.get(..end).unwrap_or("");
    let start = head.rfind(|ch: char| !(ch.is_ascii_alphanumeric() || "+-.".contains(ch))).map_or(0, |i| i + head[i..].chars().next().map_or(1, char::len_utf8));
    head[start..].to_string()
}

fn build(spec: SceneSpec, file: &str, urdf_xml: String, dir: Option<&Path>, target_csv: Option<String>) -> Result<Scene, SceneError> {
    let c = Ctx { file };
    if spec.name.is_empty() || !spec.name.chars().all(|ch| ch.is_ascii_alphanumeric() || "-_.".contains(ch)) {
        return Err(c.err("name", format!("{:?}", spec.name), "must be non-empty and use only letters, digits, '-', '_' and '.' (it names output files)"));
    }
    let gravity = c.vec3("gravity", spec.gravity)?;
    let (model, urdf_xml, meshes) = load_robot(&c, &spec, urdf_xml, gravity, dir)?;
    let model = hand_load::with_hand_load(&c, spec.hand_load.as_ref(), &spec.hand, model)?;
    let nv = model.nv;
    let duration = c.number("duration", spec.duration, positive, "must be > 0 s")?;
    let output_rate = c.number("output_rate", spec.output_rate, positive, "must be > 0 Hz")?;
    // the output grid has floor(duration / (1 / output_rate)) + 1 samples (`integrate_sampled`,
    // which rounds a span within 1e-9 of whole intervals): at least 2, at most MAX_SAMPLES
    let intervals = duration / (1.0 / output_rate);
    if intervals < 1.0 - 1e-9 {
        return Err(c.err(
            "output_rate",
            short(output_rate),
            format!("gives a single sample (t = 0) in duration = {} s; a run needs at least 2: use output_rate >= 1 / duration = {} Hz", short(duration), short(1.0 / duration)),
        ));
    }
    if intervals + 1.0 > MAX_SAMPLES {
        // blame the factor that is out of scale (a rate in Hz larger than the duration in s)
        let (field, value) = if output_rate > duration { ("output_rate", output_rate) } else { ("duration", duration) };
        let (d, r) = (short(duration), short(output_rate));
        return Err(c.err(
            field,
            short(value),
            format!("duration = {d} s at output_rate = {r} Hz gives {:.3e} samples, more than the limit of 10^8 per run; shorten duration or lower output_rate", intervals + 1.0),
        ));
    }

    // motors and joints
    let m = &spec.motor;
    let k = c.per_joint("motor.torque_constant", &m.torque_constant, nv, positive, "must be > 0 N m/A")?;
    let r = c.per_joint("motor.resistance", &m.resistance, nv, within(RESISTANCE_MIN, RESISTANCE_MAX), "must be > 0 ohm and within the physical range 1e-6 ..= 1e3 ohm")?;
    let l = c.per_joint(
        "motor.inductance",
        &m.inductance,
        nv,
        |x| x == 0.0 || within(INDUCTANCE_MIN, INDUCTANCE_MAX)(x),
        "must be >= 0 H: 0 (quasi-static current) or within the physical range 1e-12 ..= 1 H",
    )?;
    if l.iter().any(|&x| x == 0.0) && l.iter().any(|&x| x > 0.0) {
        return Err(c.err("motor.inductance", format!("{l:?}"), "must be 0 on every joint (quasi-static motors) or > 0 on every joint"));
    }
    let im = c.per_joint("motor.rotor_inertia", &m.rotor_inertia, nv, non_negative, "must be >= 0 kg m^2")?;
    let gear = c.per_joint("motor.gear_ratio", &m.gear_ratio, nv, positive, "must be > 0")?;
    let dmg = c.per_joint("motor.gear_damping", &m.gear_damping, nv, non_negative, "must be >= 0 N m s/rad")?;
    let damping = c.per_joint("joint_damping", &spec.joint_damping, nv, non_negative, "must be >= 0 N m s/rad")?;
    let mut motors: Vec<MotorParams> = (0..nv)
        .map(|j| MotorParams {
            torque_constant: k[j], resistance: r[j], inductance: l[j], rotor_inertia: im[j], gear_ratio: gear[j],
            gear_damping: dmg[j],
        })
        .collect();
    let mut specs = vec![DriveSpec::ideal(); nv];
    let datasheets = drive::apply_drives(&c, &spec, &model, &mut motors, &mut specs)?;
    if motors.iter().any(|m| m.inductance == 0.0) && motors.iter().any(|m| m.inductance > 0.0) {
        return Err(c.err("drives", "(datasheet inductances)", "the datasheet drives have an inductance, so `motor.inductance` must be > 0 on the other joints too (quasi-static motors are all or none)"));
    }
    let mut drives = Drives::new(&motors, &damping);
    if let Some(p) = &m.back_emf_constant {
        let ke = c.per_joint("motor.back_emf_constant", p, nv, positive, "must be > 0 V s/rad")?;
        for (s, x) in specs.iter_mut().zip(ke) {
            s.back_emf_constant = Some(x);
        }
    }
    if let Some(p) = &m.voltage_limit {
        let v = c.per_joint("motor.voltage_limit", p, nv, within(VOLTAGE_LIMIT_MIN, VOLTAGE_LIMIT_MAX), "must be > 0 V and within the physical range 1e-3 ..= 1e6 V (below 1 mV the motors deliver nothing; leave the limit out for none)")?;
        for (s, x) in specs.iter_mut().zip(v) {
            s.voltage_limit = Some(x);
        }
    }
    if let Some(p) = &m.current_limit {
        let v = c.per_joint("motor.current_limit", p, nv, within(CURRENT_LIMIT_MIN, CURRENT_LIMIT_MAX), "must be > 0 A and within the physical range 1e-6 ..= 1e6 A (below 1 uA the motors deliver nothing; leave the limit out for none)")?;
        for (s, x) in specs.iter_mut().zip(v) {
            s.current_limit = Some(x);
        }
    }
    for (k, name) in spec.passive.iter().enumerate() {
        let j = c.dof(&format!("passive[{k}]"), &model, name)?;
        if specs[j].passive {
            return Err(c.err(format!("passive[{k}]"), name, "is listed twice"));
        }
        specs[j].passive = true;
    }
    if specs.iter().any(|s| *s != DriveSpec::ideal()) {
        drives = drives.with_real_drives(&motors, &specs);
    }
    let thermal = drive::build_thermal(&c, &spec, &model, &specs, &motors.iter().map(|m| m.resistance).collect::<Vec<_>>())?;
    // a joint that moves only massless links has a zero row in M(q): M + J_m is singular at
    // every q unless its motor adds a rotor inertia
    for j in model.massless_dofs() {
        if drives.jm[j] == 0.0 {
            let joint = &model.bodies[j].joint;
            return Err(c.err(
                "urdf",
                &spec.urdf,
                format!("joint `{joint}` moves only massless links (no <inertial> on `{}` or after it) and has no rotor inertia (passive, or motor.rotor_inertia = 0), so M + J_m would be singular: give the links their <inertial>, give the motor a rotor inertia, or lock the joint (\"robot\": {{\"locked\": {{\"{joint}\": 0.0}}}})", model.bodies[j].link),
            ));
        }
    }
    let cs = &spec.controller;
    let law = cs.law.unwrap_or(LawSpec::Pd);
    let (kp_unit, kd_unit) = if law == LawSpec::ComputedTorque { ("1/s^2", "1/s") } else { ("V/rad", "V s/rad") };
    let gains = PdGains {
        kp: DVector::from_vec(c.per_joint("controller.kp", &cs.kp, nv, non_negative, &format!("must be >= 0 {kp_unit}"))?),
        kd: DVector::from_vec(c.per_joint("controller.kd", &cs.kd, nv, non_negative, &format!("must be >= 0 {kd_unit}"))?),
    };
    if cs.friction.is_some() && law != LawSpec::PdGravity {
        return Err(c.err("controller.friction", format!("{:?}", cs.friction), "only the law \"pd-gravity\" has a friction feed-forward"));
    }
    if cs.current_gain.is_some() && law != LawSpec::ComputedTorque {
        return Err(c.err("controller.current_gain", "(given)", "only the law \"computed-torque\" has an inner current loop"));
    }
    let controller = Controller {
        law: match law {
            LawSpec::Pd => Law::Pd,
            LawSpec::PdGravity => Law::PdGravity { friction: cs.friction.unwrap_or(false) },
            LawSpec::ComputedTorque => Law::ComputedTorque {
                current_gain: DVector::from_vec(match &cs.current_gain {
                    Some(p) => c.per_joint("controller.current_gain", p, nv, non_negative, "must be >= 0 V/A")?,
                    None => vec![0.0; nv],
                }),
            },
        },
        gains: gains.clone(),
    };

    // joint limits: monitored, and the position limits enforced by soft stops when asked
    // (without `joint_limits` the URDF's limits are still watched, as with "flag")
    let (monitor_joints, stops) = match &spec.joint_limits {
        None => (true, None),
        Some(jl) => {
            let stops = match jl.position {
                PositionLimitMode::Flag => {
                    for (f, x) in [("joint_limits.stiffness", jl.stiffness), ("joint_limits.damping", jl.damping)] {
                        if let Some(x) = x {
                            return Err(c.err(f, x, "only with \"position\": \"stop\" (soft stops)"));
                        }
                    }
                    None
                }
                PositionLimitMode::Stop => {
                    let Some(k) = jl.stiffness else {
                        return Err(c.err("joint_limits.stiffness", "(absent)", "soft stops need a stiffness, N m/rad (> 0)"));
                    };
                    let k = c.number("joint_limits.stiffness", k, positive, "must be > 0 N m/rad")?;
                    let d = c.number("joint_limits.damping", jl.damping.unwrap_or(0.0), non_negative, "must be >= 0 N m s/rad")?;
                    if model.bodies.iter().all(|b| b.limits.position.is_none()) {
                        return Err(c.err("joint_limits.position", "stop", "the URDF gives no position limit to any joint (<limit lower upper>)"));
                    }
                    Some(JointStops::new(&model, k, d))
                }
            };
            (true, stops)
        }
    };

    // initial state (initial.q may be "from-target": q0 = q_d(0))
    let qd0 = c.per_joint("initial.qd", &spec.initial.qd, nv, |_| true, "")?;
    let current0 = c.per_joint("initial.current", &spec.initial.current, nv, |_| true, "")?;
    if let Some(j) = (0..nv).find(|&j| drives.passive[j] && current0[j] != 0.0) {
        return Err(c.err(format!("initial.current[{j}]"), current0[j], "a passive joint has no motor: its current is 0"));
    }
    if drives.electrical == Electrical::QuasiStatic && current0.iter().any(|&i| i != 0.0) {
        return Err(c.err("initial.current", format!("{current0:?}"), "quasi-static motors (L = 0) have no current state: leave it 0"));
    }

    // hand and target (`target.rs`)
    let hand = c.point("hand", &model, &spec.hand)?;
    let (target, q0) = target::build_target(&c, &spec, &model, &hand, duration, target_csv.as_deref())?;

    // contacts: well-formed, and satisfied by the initial state
    let mut data = Data::new(&model);
    forward_kinematics(&model, &mut data, &q0);
    forward_velocities(&model, &mut data, &qd0);
    let (contacts, contact_models, table_contacts, contact_settings) = contacts::build_contacts(&c, &spec, &model, &data, &urdf_xml)?;
    let mut runs = Vec::with_capacity(spec.runs.len());
    if spec.runs.is_empty() {
        return Err(c.err("runs", "[]", "needs at least one run"));
    }
    for (i, rs) in spec.runs.iter().enumerate() {
        if rs.name.is_empty() || !rs.name.chars().all(|ch| ch.is_ascii_alphanumeric() || "-_.".contains(ch)) {
            return Err(c.err(format!("runs[{i}].name"), format!("{:?}", rs.name), "must be non-empty and use only letters, digits, '-', '_' and '.'"));
        }
        if runs.iter().any(|r: &Run| r.name == rs.name) {
            return Err(c.err(format!("runs[{i}].name"), &rs.name, "is used twice"));
        }
        let mut idx = Vec::new();
        for (k, name) in rs.contacts.iter().enumerate() {
            let Some(ci) = contacts.iter().position(|p| &p.name == name) else {
                return Err(c.err(format!("runs[{i}].contacts[{k}]"), name, format!("no contact of that name (contacts: {})", names(contacts.iter().map(|p| &p.name)))));
            };
            if idx.contains(&ci) {
                return Err(c.err(format!("runs[{i}].contacts[{k}]"), name, "is listed twice"));
            }
            idx.push(ci);
        }
        // the table's contacts belong to every run
        for &k in &table_contacts {
            if !idx.contains(&k) {
                idx.push(k);
            }
        }
        runs.push(Run { name: rs.name.clone(), contacts: idx });
    }

    let stabilization = spec.dynamics.stabilization;
    if let Stabilization::Baumgarte { alpha, beta } = stabilization {
        c.number("dynamics.stabilization.alpha", alpha, non_negative, "must be >= 0 1/s")?;
        c.number("dynamics.stabilization.beta", beta, non_negative, "must be >= 0 1/s")?;
    }

    let integrator = Integrator::from_spec(&spec.integrator, file, duration, 1.0 / output_rate)?;
    let gear_friction = spec_gear_supply::gear_friction(&c, spec.gear_friction.as_ref(), nv, &drives.passive)?;
    spec_gear_supply::refuse_fixed_step(&c, gear_friction.as_ref(), integrator.method(), |j| model.bodies[j].joint.clone())?;
    let supply = spec_gear_supply::supply(&c, spec.supply.as_ref(), nv)?;
    if integrator.method() == "imex" && drives.electrical == Electrical::Inductive && controller.reads_current() {
        return Err(c.err(
            "controller.current_gain",
            "(non-zero)",
            "the imex method solves the armature circuits implicitly with a voltage independent of the current; an inner current loop makes it depend on i: use another integrator or current_gain 0",
        ));
    }
    Ok(Scene {
        source: file.to_string(),
        urdf_xml,
        model,
        drives,
        gains,
        controller,
        stops,
        monitor_joints,
        hand,
        target,
        target_csv,
        q0,
        qd0,
        current0,
        contacts,
        contact_models,
        contact_settings,
        runs,
        mass_matrix: spec.dynamics.mass_matrix,
        solver: spec.dynamics.constraint_solver,
        stabilization,
        integrator,
        duration,
        output_rate,
        dir: dir.map(Path::to_path_buf),
        meshes,
        gear_friction,
        supply,
        spec,
        thermal,
        datasheets,
    })
}

#[cfg(test)]
mod tests;
