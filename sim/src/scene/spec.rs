//! The scene file as written by people: serde types that reject unknown keys. Every number of
//! the experiment is here, none is a constant in code. Validation into a runnable
//! [`super::Scene`] happens once, in `super::build`.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::dynamics::forward::{ConstraintSolver, MassMatrixMethod, Stabilization};

pub use super::spec_contacts::{EventsSpec, LawKeys, ShapeSpec, TablePointSpec, TableSpec};
use super::spec_contacts::ContactModelName;
pub use super::spec_gear_supply::{BusSpec, GearFrictionSpec, PerJointFlag, SupplySpec};

/// A per-joint setting: one number for every joint, or an array with one per joint (dof order).
/// Its JSON Schema is written by hand (`schema.rs`), as its `Deserialize` is.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum PerJoint {
    All(f64),
    Each(Vec<f64>),
}

// its schema: `schema.rs` (number or array of numbers), written by hand as this is
impl<'de> Deserialize<'de> for PerJoint {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = PerJoint;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number, or an array of numbers with one per joint")
            }
            fn visit_f64<E>(self, v: f64) -> Result<PerJoint, E> {
                Ok(PerJoint::All(v))
            }
            fn visit_i64<E>(self, v: i64) -> Result<PerJoint, E> {
                Ok(PerJoint::All(v as f64))
            }
            fn visit_u64<E>(self, v: u64) -> Result<PerJoint, E> {
                Ok(PerJoint::All(v as f64))
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<PerJoint, A::Error> {
                let mut v = Vec::new();
                while let Some(x) = seq.next_element::<f64>()? {
                    v.push(x);
                }
                Ok(PerJoint::Each(v))
            }
        }
        d.deserialize_any(V)
    }
}

impl PerJoint {
    pub fn zero() -> Self {
        PerJoint::All(0.0)
    }
}

/// `initial.q`: angles (one for all joints or one per joint), or `"from-target"` (q_d(0)).
#[derive(Clone, Debug, PartialEq)]
pub enum InitialQ {
    Values(PerJoint),
    FromTarget,
}

impl Serialize for InitialQ {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            InitialQ::Values(p) => p.serialize(s),
            InitialQ::FromTarget => s.serialize_str("from-target"),
        }
    }
}

// its schema: `schema.rs` (a per-joint value or "from-target"), written by hand as this is
impl<'de> Deserialize<'de> for InitialQ {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = InitialQ;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number, an array of numbers with one per joint, or \"from-target\"")
            }
            fn visit_f64<E>(self, v: f64) -> Result<InitialQ, E> {
                Ok(InitialQ::Values(PerJoint::All(v)))
            }
            fn visit_i64<E>(self, v: i64) -> Result<InitialQ, E> {
                Ok(InitialQ::Values(PerJoint::All(v as f64)))
            }
            fn visit_u64<E>(self, v: u64) -> Result<InitialQ, E> {
                Ok(InitialQ::Values(PerJoint::All(v as f64)))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<InitialQ, E> {
                if v == "from-target" {
                    Ok(InitialQ::FromTarget)
                } else {
                    Err(E::invalid_value(serde::de::Unexpected::Str(v), &self))
                }
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<InitialQ, A::Error> {
                let mut v = Vec::new();
                while let Some(x) = seq.next_element::<f64>()? {
                    v.push(x);
                }
                Ok(InitialQ::Values(PerJoint::Each(v)))
            }
        }
        d.deserialize_any(V)
    }
}

/// A scene file: the arm (a URDF), its drives and controller, the task, the contacts, the
/// integrator and the runs (README, "Scenes"). Units are SI, angles in radians; a per-joint
/// value is one number for all joints or an array in joint (dof) order.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// Short name, used in output file names (`<name>-<run>.mcap`): letters, digits, `-`, `_`, `.`.
    pub name: String,
    /// What the scene is, one sentence for `sim list` (default: empty).
    #[serde(default)]
    pub description: String,
    /// URDF file of the arm, relative to the scene file.
    pub urdf: String,
    /// Gravitational acceleration in the world frame, m/s^2 (e.g. [0, 0, -9.81]).
    pub gravity: [f64; 3],
    /// Simulated time of each run, s.
    pub duration: f64,
    /// Rate of the recorded samples, Hz (independent of the integrator's steps).
    pub output_rate: f64,
    /// Viscous friction D of each joint, N m s/rad (per joint).
    pub joint_damping: PerJoint,
    /// The DC motor and gear of each joint (the paper's eqs 1–12).
    pub motor: MotorSpec,
    /// The controller: its law (default: the paper's PD on the motor voltage, eq 27) and gains.
    pub controller: ControllerSpec,
    /// Joints without a motor (URDF joint names): no current, voltage or rotor (default: none).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub passive: Vec<String>,
    /// What is done at the URDF's joint limits: flagged, or soft stops at the position limits
    /// (absent: the limits are watched and flagged, as with `"position": "flag"`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub joint_limits: Option<JointLimitsSpec>,
    /// The hand point whose path is tracked: a joint's origin, or a point of a link.
    pub hand: PointSpec,
    /// A payload held at the hand: mass, centre of mass and inertia in the hand link's frame,
    /// merged into the hand's body (default: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hand_load: Option<super::hand_load::HandLoadSpec>,
    /// What the arm is asked to do: the paper's circle and IK, or a target tagged by `kind`.
    pub target: TargetSpec,
    /// The state at t = 0: joint angles, speeds and motor currents.
    pub initial: InitialSpec,
    /// Named point-on-plane contacts; each run picks some of them (default: none).
    #[serde(default)]
    pub contacts: Vec<ContactSpec>,
    /// How M(q) is computed, the constrained system solved and the constraints stabilised
    /// (default: CRBA, Schur complement, no stabilisation).
    #[serde(default)]
    pub dynamics: DynamicsSpec,
    /// The integrator, tagged by `method`, and its settings.
    pub integrator: IntegratorSpec,
    /// The runs of this scene (e.g. the paper's three elbow configurations); at least one.
    pub runs: Vec<RunSpec>,
    /// How the URDF is loaded: locked joints, inertia repair, mesh packages (absent: as is).
    #[serde(default, skip_serializing_if = "RobotSpec::is_default")]
    pub robot: RobotSpec,
    /// A table plane under named points, each a (unilateral by default) contact of every run
    /// (default: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub table: Option<TableSpec>,
    /// Settings of the event-driven integration of runs with a non-bilateral contact (default:
    /// each setting's own).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub events: Option<EventsSpec>,
    /// Coulomb friction and direction-dependent efficiency of the gears (default: none, the
    /// paper's ideal gear with viscous damping only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gear_friction: Option<GearFrictionSpec>,
    /// The electric supply: regeneration per drive and a shared DC bus (default: none, ideal
    /// regenerating supplies: the supply energy is E).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub supply: Option<SupplySpec>,
    /// Datasheet drives: a catalogue motor (and gearhead) by name, or its datasheet values, per
    /// joint; each replaces the `motor` values of its joints (default: none).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub drives: Vec<super::spec_drive::DatasheetDriveSpec>,
    /// The motors' winding temperature: a two-node thermal model (winding, housing) with R(T)
    /// in the electrical equation; needs datasheet drives with thermal data (default: off).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thermal: Option<super::spec_drive::ThermalSpec>,
}

/// How the URDF is loaded (`"robot": {...}`); every key optional.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RobotSpec {
    /// Joints made fixed at a value, rad (m for a prismatic joint), by URDF joint name: the
    /// child is welded to the parent there (default: none). A `<mimic>` joint whose leader is
    /// locked is locked with it at `multiplier · value + offset`.
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub locked: std::collections::BTreeMap<String, f64>,
    /// Replace an implausible inertia of a moving link (not positive semi-definite, or
    /// violating the triangle inequality) by the nearest plausible one, and record the repair
    /// (default: false, an error).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub repair_inertia: bool,
    /// ROS package name → directory (relative to the scene file) for `package://` mesh URIs
    /// (default: none).
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub package_paths: std::collections::BTreeMap<String, String>,
}

impl RobotSpec {
    pub fn is_default(&self) -> bool {
        *self == RobotSpec::default()
    }
}

/// The physical bounds of the motor and drive values (validation refuses values outside them,
/// naming the file, the field and the value). Below a floor or above a ceiling a value is no
/// motor any more, and the run's numbers stop meaning anything: a current limit of 5e-324 A
/// lets the motors deliver nothing, so the energy balance's relative residual divides by ~0
/// (inf); a voltage limit of 1e-300 V or an inductance of 1e300 H gave a relative residual of
/// 4e302 with status "complete" (issue 29). The bounds are wide around real motors: armature
/// resistances of small DC motors are 0.1-100 ohm, inductances 1e-5-1e-2 H (maxon and Faulhaber
/// catalogues; the paper's motor: 1.1 ohm, 1.7 mH, eq 1-12 and Table 1).
pub mod motor_bounds {
    /// Armature resistance: `RESISTANCE_MIN <= R <= RESISTANCE_MAX`, ohm. R = 0 is a
    /// superconductor (no quasi-static current `i = (v - K q')/R`); above 1 kohm a motor passes
    /// no useful current at any supply voltage.
    pub const RESISTANCE_MIN: f64 = 1e-6;
    pub const RESISTANCE_MAX: f64 = 1e3;
    /// Armature inductance: 0 (quasi-static currents) or `INDUCTANCE_MIN <= L <= INDUCTANCE_MAX`,
    /// H. Below 1e-12 H the electrical time constant L/R is under 1 ps, far below any step
    /// (use 0); above 1 H the time constant of a 1-ohm winding is over 1 s, a solenoid, not a
    /// motor.
    pub const INDUCTANCE_MIN: f64 = 1e-12;
    pub const INDUCTANCE_MAX: f64 = 1.0;
    /// Supply voltage limit: `VOLTAGE_LIMIT_MIN <= limit <= VOLTAGE_LIMIT_MAX`, V. Below 1 mV
    /// no drive delivers any torque (the motors do nothing and every energy ratio is 0/0).
    pub const VOLTAGE_LIMIT_MIN: f64 = 1e-3;
    pub const VOLTAGE_LIMIT_MAX: f64 = 1e6;
    /// The driver's current limit: `CURRENT_LIMIT_MIN <= limit <= CURRENT_LIMIT_MAX`, A. Below
    /// 1 uA a motor delivers no torque (leave the limit out for an unlimited driver).
    pub const CURRENT_LIMIT_MIN: f64 = 1e-6;
    pub const CURRENT_LIMIT_MAX: f64 = 1e6;
}

/// DC motor and gear of each joint (the paper's eqs 1–12); each entry per joint or for all.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MotorSpec {
    /// Torque constant K, N m/A (= V s/rad), per joint.
    pub torque_constant: PerJoint,
    /// Armature resistance R, ohm, per joint: 1e-6 <= R <= 1e3 ohm (a physical range; outside
    /// it the quasi-static current and the losses lose meaning).
    pub resistance: PerJoint,
    /// Armature inductance L, H, per joint (0 on every joint: quasi-static currents); otherwise
    /// 1e-12 <= L <= 1 H (below: use 0; above: no motor's time constant).
    pub inductance: PerJoint,
    /// Rotor inertia I_m, kg m^2, per joint.
    pub rotor_inertia: PerJoint,
    /// Gear ratio k, motor turns per joint turn (rad/m for a prismatic joint), per joint.
    pub gear_ratio: PerJoint,
    /// Gear damping d_m, N m s/rad (motor side), per joint.
    pub gear_damping: PerJoint,
    /// Back-EMF constant K_e, V s/rad (motor side), per joint (default: `torque_constant`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub back_emf_constant: Option<PerJoint>,
    /// Supply voltage limit, V, per joint: the amplifier saturates at ±limit (default: none);
    /// 1e-3 <= limit <= 1e6 V (below 1 mV the motors deliver nothing and the energy ratios are
    /// 0/0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub voltage_limit: Option<PerJoint>,
    /// The driver's current limit, A, per joint (default: none); 1e-6 <= limit <= 1e6 A (below
    /// 1 uA the motors deliver no torque and the energy ratios are 0/0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub current_limit: Option<PerJoint>,
}

/// The controller's law (`sim/src/control/controller.rs` gives each equation).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum LawSpec {
    /// The paper's PD on the motor voltage, v = k_p e + k_d ė (eq 27).
    Pd,
    /// PD plus gravity (and, with `friction`, viscous friction) feed-forward.
    PdGravity,
    /// Computed torque with an inner current loop (`current_gain`).
    ComputedTorque,
}

/// What the monitor does at a joint's position limit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum PositionLimitMode {
    /// Flag the crossing (first time, time beyond, peak); nothing pushes back.
    #[default]
    Flag,
    /// A soft stop: a spring-damper beyond the limit (`stiffness`, `damping`), and flagged.
    Stop,
}

/// `"joint_limits"`: the URDF `<limit>`s are monitored at every output sample (position,
/// velocity, effort), and the position limits optionally enforced by soft stops.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct JointLimitsSpec {
    /// What is done at a position limit: `flag` it, or a soft `stop` (default: flag).
    #[serde(default)]
    pub position: PositionLimitMode,
    /// The stops' stiffness, N m/rad (`stop` only; required there).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness: Option<f64>,
    /// The stops' damping, N m s/rad (`stop` only; default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping: Option<f64>,
}

/// The controller: the paper's PD on the motor voltage (eq 27) when `law` is absent or `pd`;
/// `pd-gravity` (with `friction`) or `computed-torque` (with `current_gain`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ControllerSpec {
    /// The control law (default: `pd`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub law: Option<LawSpec>,
    /// Proportional gain k_p, per joint: V/rad (`pd`, `pd-gravity`), 1/s^2 (`computed-torque`).
    pub kp: PerJoint,
    /// Derivative gain k_d, per joint: V s/rad (`pd`, `pd-gravity`), 1/s (`computed-torque`).
    pub kd: PerJoint,
    /// `pd-gravity` only: also feed forward the viscous friction (D + D_m) q'_d (default: false).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<bool>,
    /// `computed-torque` only: the inner current loop's gain k_i, V/A, per joint (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub current_gain: Option<PerJoint>,
}

/// A point fixed on the robot: the origin of a joint, or a point in a link's frame (one of
/// `joint` and `link`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PointSpec {
    /// A URDF joint: the point is its origin (plus `offset`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub joint: Option<String>,
    /// A URDF link: the point is `offset` in its frame.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub link: Option<String>,
    /// Offset in the link's (or the joint's child link's) frame, m (default: [0, 0, 0]).
    #[serde(default)]
    pub offset: [f64; 3],
}

/// The scene's target: the paper's form `{"circle": ..., "ik": ...}` (no `kind`), or a form
/// tagged by `kind` ([`KindedTarget`]). Read through a JSON value so that the paper's form keeps
/// its exact syntax and each tagged form rejects unknown keys; written back the same way.
#[derive(Clone, Debug, PartialEq)]
pub enum TargetSpec {
    Paper(PaperTargetSpec),
    Kinded(KindedTarget),
}

impl Serialize for TargetSpec {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            TargetSpec::Paper(p) => p.serialize(s),
            TargetSpec::Kinded(k) => k.serialize(s),
        }
    }
}

// its schema: `schema.rs` (the paper's form or a `kind`-tagged one), written by hand as this is
impl<'de> Deserialize<'de> for TargetSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = serde_json::Value::deserialize(d)?;
        if v.as_object().is_some_and(|o| o.contains_key("kind")) {
            read_inner(v).map(TargetSpec::Kinded)
        } else {
            read_inner(v).map(TargetSpec::Paper)
        }
    }
}

/// Read a value that was taken whole (a JSON value), keeping the path of an error inside it:
/// the message becomes "at `path.inside`: why", which `Scene::from_json` appends to the
/// field's path (serde's own tagged enums buffer their content and lose that path).
fn read_inner<T: serde::de::DeserializeOwned, E: serde::de::Error>(v: serde_json::Value) -> Result<T, E> {
    serde_path_to_error::deserialize(v).map_err(|e| {
        let path = e.path().to_string();
        let path = if path == "." { String::new() } else { path };
        let msg = e.inner().to_string();
        let (path, msg) = match msg.strip_prefix("at `").and_then(|r| r.split_once("`: ")) {
            Some((inside, rest)) if path.is_empty() => (inside.to_string(), rest.to_string()),
            Some((inside, rest)) => (format!("{path}.{inside}"), rest.to_string()),
            None => (path, msg),
        };
        if path.is_empty() {
            E::custom(msg)
        } else {
            E::custom(format!("at `{path}`: {msg}"))
        }
    })
}

/// Take the string tag `tag` out of the object `v`; it must name one of `variants`.
fn take_tag<E: serde::de::Error>(v: &mut serde_json::Value, tag: &'static str, variants: &'static [&'static str]) -> Result<String, E> {
    let Some(obj) = v.as_object_mut() else {
        return Err(E::custom(format!("expected an object with `{tag}`")));
    };
    match obj.remove(tag) {
        Some(serde_json::Value::String(s)) if variants.contains(&s.as_str()) => Ok(s),
        Some(serde_json::Value::String(s)) => Err(E::unknown_variant(&s, variants)),
        Some(other) => Err(E::custom(format!("at `{tag}`: expected one of {variants:?}, found {other}"))),
        None => Err(E::missing_field(tag)),
    }
}

impl<'de> Deserialize<'de> for KindedTarget {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let mut v = serde_json::Value::deserialize(d)?;
        match take_tag::<D::Error>(&mut v, "kind", &["joint-spline", "joint-csv", "cartesian"])?.as_str() {
            "joint-spline" => read_inner(v).map(KindedTarget::JointSpline),
            "joint-csv" => read_inner(v).map(KindedTarget::JointCsv),
            _ => read_inner(v).map(KindedTarget::Cartesian),
        }
    }
}

impl<'de> Deserialize<'de> for PathSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let mut v = serde_json::Value::deserialize(d)?;
        match take_tag::<D::Error>(&mut v, "shape", &["circle", "lines", "waypoints"])?.as_str() {
            "circle" => read_inner(v).map(PathSpec::Circle),
            "lines" => read_inner(v).map(PathSpec::Lines),
            _ => read_inner(v).map(PathSpec::Waypoints),
        }
    }
}

/// The paper's target: a horizontal circle and the closed-form IK.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PaperTargetSpec {
    /// The horizontal circle the hand follows.
    pub circle: CircleSpec,
    /// The closed-form IK's joints and branch.
    pub ik: IkSpec,
}

/// The targets selected by `kind`.
// (read by hand, so that errors keep their path inside)
#[derive(Clone, Debug, PartialEq, Serialize, JsonSchema)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum KindedTarget {
    /// Joint-space waypoints joined by a named spline.
    JointSpline(JointSplineSpec),
    /// Joint-space samples from a CSV file (`t,<joint names>`), joined by the cubic spline.
    JointCsv(JointCsvSpec),
    /// A hand path, tracked by the general IK.
    Cartesian(CartesianSpec),
}

/// `cubic`: the clamped C² cubic spline at rest at both ends; `quintic`: minimum-jerk
/// segments at rest at every waypoint.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum Interpolation {
    #[default]
    Cubic,
    Quintic,
}

impl Interpolation {
    fn is_cubic(&self) -> bool {
        *self == Interpolation::Cubic
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct JointSplineSpec {
    /// The spline joining the waypoints: `cubic` or `quintic` (default: cubic).
    #[serde(default, skip_serializing_if = "Interpolation::is_cubic")]
    pub interpolation: Interpolation,
    /// The waypoints, in time order.
    pub waypoints: Vec<JointWaypointSpec>,
}

/// Joint angles (rad, one per joint in dof order) at time `t` (s).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct JointWaypointSpec {
    /// Time of the waypoint, s.
    pub t: f64,
    /// Joint angles, rad (m for a prismatic joint), one per joint in dof order.
    pub q: Vec<f64>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct JointCsvSpec {
    /// CSV file (header `t,<joint names>`; t in s, angles in rad), relative to the scene file.
    pub file: String,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CartesianSpec {
    /// The hand path, world frame, tagged by `shape`.
    pub path: PathSpec,
    /// A constant orientation of the hand frame, held along the path (default: position only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orientation: Option<OrientationSpec>,
    /// The general IK's settings (default: each setting's own).
    #[serde(default)]
    pub ik: GeneralIkSpec,
}

/// A hand path, world frame, selected by `shape`.
// (read by hand, as [`KindedTarget`])
#[derive(Clone, Debug, PartialEq, Serialize, JsonSchema)]
#[serde(tag = "shape", rename_all = "kebab-case")]
pub enum PathSpec {
    /// A circle in any plane.
    Circle(CirclePathSpec),
    /// Straight segments, each with a minimum-jerk time profile (at rest at each point).
    Lines(PointsSpec),
    /// A C² cubic spline through the points.
    Waypoints(PointsSpec),
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CirclePathSpec {
    /// Centre of the circle, m, world frame.
    pub center: [f64; 3],
    /// The circle plane's normal (normalised when read).
    pub normal: [f64; 3],
    /// Radius, m.
    pub radius: f64,
    /// Time of one turn, s.
    pub period: f64,
    /// Angle at t = 0 from the zero axis, rad (default 0).
    #[serde(default)]
    pub phase: f64,
    /// Sense of rotation about the normal, right-hand rule (default: counter-clockwise).
    #[serde(default = "ccw")]
    pub direction: Direction,
    /// The direction of angle 0, projected onto the plane (default: world x, or world y when
    /// the normal is along x).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub zero_axis: Option<[f64; 3]>,
}

fn ccw() -> Direction {
    Direction::CounterClockwise
}

/// Points (m) reached at times (s).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PointsSpec {
    /// The points [x, y, z], m, world frame.
    pub points: Vec<[f64; 3]>,
    /// The time each point is reached, s, one per point, increasing.
    pub times: Vec<f64>,
}

/// URDF convention: roll about x, pitch about y, yaw about z, fixed axes (R = Rz Ry Rx), rad.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct OrientationSpec {
    /// Roll, pitch, yaw, rad (R = Rz(yaw) Ry(pitch) Rx(roll)).
    pub rpy: [f64; 3],
}

/// The general IK's solver.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum IkSolver {
    /// Damped least squares / Levenberg–Marquardt with a null-space posture task.
    #[default]
    Dls,
}

/// The general IK's settings.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GeneralIkSpec {
    /// The solver (default: `dls`).
    #[serde(default)]
    pub solver: IkSolver,
    /// Joints the IK moves, URDF names (default: all); the others hold their posture angle.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub joints: Option<Vec<String>>,
    /// Null-space posture, rad, one per joint (default: initial.q).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub posture: Option<Vec<f64>>,
    /// Scene contacts whose point must stay on its plane along the path (default: none).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub keep_contacts: Vec<String>,
    /// Grid step of the solved trajectory, s (default 0.002).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grid_step: Option<f64>,
}

/// A sense of rotation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum Direction {
    CounterClockwise,
    Clockwise,
}

/// A horizontal circle run once per `period`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CircleSpec {
    /// Centre of the circle, m, world frame.
    pub center: [f64; 3],
    /// Radius, m.
    pub radius: f64,
    /// Time of one turn, s.
    pub period: f64,
    /// Angle at t = 0 from +x towards +y, rad.
    pub phase: f64,
    /// Sense of rotation, seen from above (+z).
    pub direction: Direction,
    /// A jump of the target: `offset` (m) is added from `time` (s) on (default: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step: Option<StepSpec>,
}

/// A step in the target.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StepSpec {
    /// Time of the jump, s.
    pub time: f64,
    /// Added to the target from then on, m, world frame.
    pub offset: [f64; 3],
}

/// Which of the closed-form IK's two solutions.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum Branch {
    Positive,
    Negative,
}

/// Closed-form IK (eqs 28–29): a yaw joint and two planar joints; every other joint holds its
/// initial angle.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct IkSpec {
    /// The yaw joint (URDF name): a revolute joint about the vertical.
    pub yaw_joint: String,
    /// The two planar joints (URDF names), parallel axes, in one plane with the hand.
    pub planar_joints: [String; 2],
    /// Sign of the second planar joint's angle relative to the first link.
    pub branch: Branch,
}

/// The state at t = 0.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct InitialSpec {
    /// Joint angles, rad, per joint; or `"from-target"`: q_d(0), the target at t = 0.
    pub q: InitialQ,
    /// Joint speeds, rad/s, per joint (default 0).
    #[serde(default = "PerJoint::zero")]
    pub qd: PerJoint,
    /// Motor currents, A, per joint (default 0).
    #[serde(default = "PerJoint::zero")]
    pub current: PerJoint,
}

/// A point-on-plane contact. Without `model` it is the paper's frictionless, bilateral
/// constraint C = z = 0 (every existing scene keeps its meaning); `model` chooses
/// `"bilateral"`, `"unilateral"` (rigid, event-driven: `restitution`, `friction`) or
/// `"compliant"` (`stiffness`, `damping`, `friction`, `slip_velocity`). Keys that do not belong
/// to the chosen model are rejected.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// The contact's name, used by `runs[].contacts` and in the recordings.
    pub name: String,
    /// The point of the arm that touches the plane.
    pub point: PointSpec,
    /// The plane, world frame.
    pub plane: PlaneSpec,
    /// The contact model: `bilateral`, `unilateral` or `compliant` (default: bilateral).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(with = "Option<ContactModelName>")]
    pub model: Option<String>,
    /// Newton's coefficient of restitution e in [0, 1] (unilateral; default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub restitution: Option<f64>,
    /// Coulomb friction coefficient mu >= 0 (unilateral, compliant; default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<f64>,
    /// Normal stiffness k, N/m (compliant; required).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness: Option<f64>,
    /// Normal damping c, N s/m (compliant; default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping: Option<f64>,
    /// Regularisation speed v_s of the compliant friction, m/s (default 1e-3).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slip_velocity: Option<f64>,
    /// What touches the plane at the point: a `sphere` of a radius centred on it (unilateral
    /// and compliant contacts; default: the point itself).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<ShapeSpec>,
}

/// The plane `normal · x = offset`, world frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PlaneSpec {
    /// The plane's normal n, world frame (normalised when read).
    pub normal: [f64; 3],
    /// The plane's offset d along n, m: n · x = d.
    pub offset: f64,
}

/// How the dynamics are computed.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DynamicsSpec {
    /// How M(q) is computed: `crba` or `walker-orin` (default: crba).
    #[serde(default)]
    pub mass_matrix: MassMatrixMethod,
    /// How the constrained system is solved: `schur` or `kkt` (default: schur).
    #[serde(default)]
    pub constraint_solver: ConstraintSolver,
    /// Constraint stabilisation, tagged by `method` (default: none, as in the paper).
    #[serde(default)]
    pub stabilization: Stabilization,
}

/// The integrator and its settings, tagged by `method`; each method accepts only its own
/// settings (an unknown or misplaced one is rejected with its name).
// Defaults are filled in one place, [`crate::integrator::Integrator::from_spec`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "method", rename_all = "kebab-case")]
pub enum IntegratorSpec {
    /// Classical Runge–Kutta with the fixed `step`, s.
    Rk4(FixedStepSpec),
    /// Dormand–Prince 5(4), adaptive, with dense output.
    Dopri45(AdaptiveSpec),
    /// Rosenbrock-W ROS34PW2 (order 3, L-stable), adaptive, with the structured motor-arm
    /// Jacobian (`sim/src/ode/jacobian.rs`).
    Rosenbrock(RosenbrockSpec),
    /// IMEX additive Runge–Kutta ARK4(3)6L[2]SA: the armature circuits implicit (closed form),
    /// the mechanics explicit.
    Imex(AdaptiveSpec),
    /// Rosenbrock RODAS5P (Steinebach 2023; order 5(4), L-stable, dense output of order 4),
    /// adaptive, with the exact Jacobian of the q, q̇, i block by finite differences.
    Rodas5p(RosenbrockSpec),
    /// Rosenbrock RODAS4 (Hairer & Wanner; order 4(3), L-stable, dense output of order 3),
    /// otherwise as `rodas5p`.
    Rodas4(RosenbrockSpec),
}

/// `rk4`'s settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FixedStepSpec {
    /// The fixed step, s.
    pub step: f64,
}

/// The step control of an adaptive method (`dopri45`, `imex`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AdaptiveSpec {
    /// Relative tolerance (dimensionless).
    pub rtol: f64,
    /// Absolute tolerance, in each state component's unit.
    pub atol: f64,
    /// Largest step, s (default: the output interval).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub h_max: Option<f64>,
    /// Most step attempts per run before giving up (default 10^8).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_steps: Option<u64>,
}

/// `rosenbrock`'s, `rodas5p`'s and `rodas4`'s settings: the step control of [`AdaptiveSpec`] and the Jacobian's reuse.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RosenbrockSpec {
    /// Relative tolerance (dimensionless).
    pub rtol: f64,
    /// Absolute tolerance, in each state component's unit.
    pub atol: f64,
    /// Largest step, s (default: the output interval).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub h_max: Option<f64>,
    /// Most step attempts per run before giving up (default 10^8).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_steps: Option<u64>,
    /// Accepted steps between Jacobian refreshes (default 1: every step).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub jacobian_reuse: Option<u64>,
    /// How the step after an accepted one is chosen (default `elementary`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step_size_control: Option<StepSizeControlSpec>,
}

/// The step-size controller after an accepted step (rejected steps always shrink by the
/// elementary rule).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum StepSizeControlSpec {
    /// The step the last error predicts, `h (0.9 / err)^(1/(q+1))` (Hairer & Wanner, HNW I
    /// (4.13); Hairer's `rodas.f`).
    Elementary,
    /// Gustafsson's predictive controller (HNW II §IV.8 (8.21); `radau5.f`): the smaller of the
    /// elementary step and one extrapolated from the last two accepted steps' sizes and errors;
    /// fewer rejected steps where the error grows faster than the elementary rule assumes.
    Predictive,
}

impl IntegratorSpec {
    /// `method` at `rtol` (atol = rtol / 100), steps of at most `h_max` when given.
    pub fn adaptive(method: &str, rtol: f64, h_max: Option<f64>) -> Option<Self> {
        let a = AdaptiveSpec { rtol, atol: rtol * 1e-2, h_max, max_steps: None };
        Some(match method {
            "dopri45" => IntegratorSpec::Dopri45(a),
            "imex" => IntegratorSpec::Imex(a),
            "rosenbrock" => IntegratorSpec::Rosenbrock(RosenbrockSpec { rtol, atol: a.atol, h_max, max_steps: None, jacobian_reuse: None, step_size_control: None }),
            "rodas5p" => IntegratorSpec::Rodas5p(RosenbrockSpec { rtol, atol: a.atol, h_max, max_steps: None, jacobian_reuse: None, step_size_control: None }),
            "rodas4" => IntegratorSpec::Rodas4(RosenbrockSpec { rtol, atol: a.atol, h_max, max_steps: None, jacobian_reuse: None, step_size_control: None }),
            _ => return None,
        })
    }

    /// `rk4` with the fixed `step`, s.
    pub fn rk4(step: f64) -> Self {
        IntegratorSpec::Rk4(FixedStepSpec { step })
    }
}

/// One run of the scene: which contacts are active.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RunSpec {
    /// The run's name, used in output file names: letters, digits, `-`, `_`, `.`.
    pub name: String,
    /// Names of the contacts active in this run (the table's points are in every run).
    pub contacts: Vec<String>,
}
