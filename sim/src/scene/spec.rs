//! The scene file as written by people: serde types that reject unknown keys. Every number of
//! the experiment is here, none is a constant in code. Validation into a runnable
//! [`super::Scene`] happens once, in `super::build`.

use serde::{Deserialize, Serialize};

use crate::dynamics::forward::{ConstraintSolver, MassMatrixMethod, Stabilization};

/// A per-joint setting: one number for every joint, or an array with one per joint (dof order).
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum PerJoint {
    All(f64),
    Each(Vec<f64>),
}

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

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// Short name, used in output file names.
    pub name: String,
    #[serde(default)]
    pub description: String,
    /// URDF file, relative to the scene file.
    pub urdf: String,
    /// Gravitational acceleration in the world frame, m/s^2.
    pub gravity: [f64; 3],
    /// Simulated time of each run, s.
    pub duration: f64,
    /// Rate of the recorded samples, Hz (independent of the integrator's steps).
    pub output_rate: f64,
    /// Viscous friction D of each joint, N m s/rad.
    pub joint_damping: PerJoint,
    pub motor: MotorSpec,
    pub controller: ControllerSpec,
    /// Joints without a motor (URDF joint names): no current, voltage or rotor.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub passive: Vec<String>,
    /// Monitor the URDF's joint limits (and enforce the position limits by soft stops when
    /// asked); absent: limits are not looked at (the paper's behaviour).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub joint_limits: Option<JointLimitsSpec>,
    /// The hand point whose path is tracked.
    pub hand: PointSpec,
    pub target: TargetSpec,
    pub initial: InitialSpec,
    /// Named contacts; each run picks some of them.
    #[serde(default)]
    pub contacts: Vec<ContactSpec>,
    #[serde(default)]
    pub dynamics: DynamicsSpec,
    pub integrator: IntegratorSpec,
    /// The runs of this scene (e.g. the paper's three elbow configurations).
    pub runs: Vec<RunSpec>,
    /// How the URDF is loaded: locked joints, inertia repair, mesh packages (absent: as is).
    #[serde(default, skip_serializing_if = "RobotSpec::is_default")]
    pub robot: RobotSpec,
}

/// How the URDF is loaded (`"robot": {...}`); every key optional.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotSpec {
    /// Joints made fixed at a value (rad, or m for a prismatic joint): their child is welded
    /// to the parent at that value (a gripper, a joint the task does not use). A `<mimic>`
    /// joint whose leader is locked is locked with it at `multiplier · value + offset`.
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub locked: std::collections::BTreeMap<String, f64>,
    /// Replace an implausible inertia of a moving link (not positive semi-definite, or
    /// violating the triangle inequality) by the nearest plausible one; the repaired links
    /// are listed in the scene's model (`Model::repaired_inertias`).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub repair_inertia: bool,
    /// ROS package name → directory (relative to the scene file) for `package://` mesh URIs.
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub package_paths: std::collections::BTreeMap<String, String>,
}

impl RobotSpec {
    pub fn is_default(&self) -> bool {
        *self == RobotSpec::default()
    }
}

/// DC motor and gear of each joint (the paper's eqs 1–12); each entry per joint or for all.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotorSpec {
    /// K, N m/A (= V s/rad).
    pub torque_constant: PerJoint,
    /// R, ohm.
    pub resistance: PerJoint,
    /// L, H.
    pub inductance: PerJoint,
    /// I_m, kg m^2.
    pub rotor_inertia: PerJoint,
    /// k, motor turns per joint turn.
    pub gear_ratio: PerJoint,
    /// d_m, N m s/rad (motor side).
    pub gear_damping: PerJoint,
    /// K_e, V s/rad (motor side); absent: equal to `torque_constant`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub back_emf_constant: Option<PerJoint>,
    /// Supply voltage limit, V: the amplifier saturates at ±limit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub voltage_limit: Option<PerJoint>,
    /// The driver's current limit, A.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub current_limit: Option<PerJoint>,
}

/// The controller's law (`sim/src/control/controller.rs` gives each equation).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LawSpec {
    Pd,
    PdGravity,
    ComputedTorque,
}

/// What the monitor does at a joint's position limit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
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
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointLimitsSpec {
    #[serde(default)]
    pub position: PositionLimitMode,
    /// The stops' stiffness, N m/rad (`stop` only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness: Option<f64>,
    /// The stops' damping, N m s/rad (`stop` only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping: Option<f64>,
}

/// The controller: the paper's PD on the motor voltage (eq 27) when `law` is absent or `pd`;
/// `pd-gravity` (with `friction`) or `computed-torque` (with `current_gain`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControllerSpec {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub law: Option<LawSpec>,
    /// k_p: V/rad (`pd`, `pd-gravity`), 1/s^2 (`computed-torque`).
    pub kp: PerJoint,
    /// k_d: V s/rad (`pd`, `pd-gravity`), 1/s (`computed-torque`).
    pub kd: PerJoint,
    /// `pd-gravity`: also feed forward the viscous friction (D + D_m) q'_d.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<bool>,
    /// `computed-torque`: the inner current loop's gain k_i, V/A (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub current_gain: Option<PerJoint>,
}

/// A point fixed on the robot: the origin of a joint, or a point in a link's frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointSpec {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub joint: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub link: Option<String>,
    /// Offset in the link's (or the joint's child link's) frame, m.
    #[serde(default)]
    pub offset: [f64; 3],
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TargetSpec {
    pub circle: CircleSpec,
    pub ik: IkSpec,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Direction {
    CounterClockwise,
    Clockwise,
}

/// A horizontal circle run once per `period`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CircleSpec {
    /// m, world frame.
    pub center: [f64; 3],
    /// m.
    pub radius: f64,
    /// s per turn.
    pub period: f64,
    /// Angle at t = 0 from +x towards +y, rad.
    pub phase: f64,
    /// Seen from above (+z).
    pub direction: Direction,
    /// Optional jump of the target: `offset` (m) is added from `time` (s) on.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step: Option<StepSpec>,
}

/// A step in the target.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StepSpec {
    /// s.
    pub time: f64,
    /// m, world frame.
    pub offset: [f64; 3],
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Branch {
    Positive,
    Negative,
}

/// Closed-form IK (eqs 28–29): a yaw joint and two planar joints; every other joint holds its
/// initial angle.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IkSpec {
    pub yaw_joint: String,
    pub planar_joints: [String; 2],
    /// Sign of the second planar joint's angle relative to the first link.
    pub branch: Branch,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialSpec {
    /// rad.
    pub q: PerJoint,
    /// rad/s.
    #[serde(default = "PerJoint::zero")]
    pub qd: PerJoint,
    /// A.
    #[serde(default = "PerJoint::zero")]
    pub current: PerJoint,
}

/// A frictionless, bilateral point-on-plane contact (the paper's C = z = 0).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    pub name: String,
    pub point: PointSpec,
    pub plane: PlaneSpec,
}

/// The plane `normal · x = offset`, world frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlaneSpec {
    pub normal: [f64; 3],
    /// m.
    pub offset: f64,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DynamicsSpec {
    #[serde(default)]
    pub mass_matrix: MassMatrixMethod,
    #[serde(default)]
    pub constraint_solver: ConstraintSolver,
    /// Constraint stabilisation (default none, as in the paper).
    #[serde(default)]
    pub stabilization: Stabilization,
}

/// The integrator and its settings, tagged by `method`; each method accepts only its own
/// settings (an unknown or misplaced one is rejected with its name). Defaults are filled in one
/// place, [`crate::integrator::Integrator::from_spec`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
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
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FixedStepSpec {
    /// s.
    pub step: f64,
}

/// The step control of an adaptive method (`dopri45`, `imex`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AdaptiveSpec {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance (in each state component's unit).
    pub atol: f64,
    /// Largest step, s (default: the output interval).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub h_max: Option<f64>,
    /// Most step attempts per run before giving up (default 10^8).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_steps: Option<u64>,
}

/// `rosenbrock`'s, `rodas5p`'s and `rodas4`'s settings: the step control of [`AdaptiveSpec`] and the Jacobian's reuse.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RosenbrockSpec {
    pub rtol: f64,
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
}

impl IntegratorSpec {
    /// `method` at `rtol` (atol = rtol / 100), steps of at most `h_max` when given.
    pub fn adaptive(method: &str, rtol: f64, h_max: Option<f64>) -> Option<Self> {
        let a = AdaptiveSpec { rtol, atol: rtol * 1e-2, h_max, max_steps: None };
        Some(match method {
            "dopri45" => IntegratorSpec::Dopri45(a),
            "imex" => IntegratorSpec::Imex(a),
            "rosenbrock" => IntegratorSpec::Rosenbrock(RosenbrockSpec { rtol, atol: a.atol, h_max, max_steps: None, jacobian_reuse: None }),
            "rodas5p" => IntegratorSpec::Rodas5p(RosenbrockSpec { rtol, atol: a.atol, h_max, max_steps: None, jacobian_reuse: None }),
            "rodas4" => IntegratorSpec::Rodas4(RosenbrockSpec { rtol, atol: a.atol, h_max, max_steps: None, jacobian_reuse: None }),
            _ => return None,
        })
    }

    /// `rk4` with the fixed `step`, s.
    pub fn rk4(step: f64) -> Self {
        IntegratorSpec::Rk4(FixedStepSpec { step })
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunSpec {
    pub name: String,
    /// Names of the contacts active in this run.
    pub contacts: Vec<String>,
}
