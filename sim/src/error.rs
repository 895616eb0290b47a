//! Error types of the `sim` library. Every variant carries what a user needs to act on it:
//! the file, the field and the value for bad input; the simulated time for numerical failure.

use std::path::PathBuf;

/// A robot description that cannot be turned into a [`crate::dynamics::Model`].
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ModelError {
    #[error("{file}: the URDF could not be parsed: {message}")]
    Parse { file: String, message: String },
    #[error("{file}: joint `{joint}` is of type `{kind}`, which is not modelled (revolute, continuous and fixed are)")]
    UnsupportedJoint { file: String, joint: String, kind: String },
    #[error("{file}: joint `{joint}` refers to link `{link}`, which the URDF does not define")]
    MissingLink { file: String, joint: String, link: String },
    #[error("{file}: link `{link}` is the child of both `{first}` and `{second}`: kinematic loops are not modelled")]
    Loop { file: String, link: String, first: String, second: String },
    #[error("{file}: the links must form one tree with one root; found roots {roots:?}")]
    Roots { file: String, roots: Vec<String> },
    #[error("{file}: {item} `{name}`: {field} = {value}: {why}")]
    BadValue { file: String, item: &'static str, name: String, field: &'static str, value: String, why: &'static str },
    #[error("{file}: the URDF has no movable joint")]
    NoJoints { file: String },
}

/// A scene file that cannot be turned into a validated [`crate::scene::Scene`].
#[derive(Debug, thiserror::Error)]
#[error("{file}: field `{field}`{value}: {why}", value = if .value.is_empty() { String::new() } else { format!(" = {}", .value) })]
pub struct SceneError {
    pub file: String,
    pub field: String,
    pub value: String,
    pub why: String,
}

impl SceneError {
    pub fn new(file: &str, field: impl Into<String>, value: impl std::fmt::Display, why: impl Into<String>) -> Self {
        Self { file: file.to_string(), field: field.into(), value: value.to_string(), why: why.into() }
    }
}

/// A failure while the equations of motion are evaluated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum DynamicsError {
    #[error("t = {t:.9} s: the joint-space inertia M + J_m is not positive definite (a massless or degenerate chain?)")]
    SingularMassMatrix { t: f64 },
    #[error("t = {t:.9} s: the constraint system J (M + J_m)^-1 J^T is singular (redundant or degenerate constraints: {constraints})")]
    SingularConstraints { t: f64, constraints: String },
    #[error("t = {t:.9} s: the target left the reachable workspace of the inverse kinematics ({why})")]
    Unreachable { t: f64, why: String },
    #[error("t = {t:.9} s: a non-finite value appeared in {what}")]
    NonFinite { t: f64, what: String },
}

/// A failure of a whole run.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RunError {
    #[error("{0}")]
    Dynamics(#[from] DynamicsError),
    #[error("the integrator stopped: step size collapsed to h = {h:e} s at t = {t:.9} s")]
    StepSizeTooSmall { t: f64, h: f64 },
    #[error("the implicit integrator stopped: its iteration matrix I - h gamma J is singular at t = {t:.9} s (h = {h:e} s)")]
    SingularIterationMatrix { t: f64, h: f64 },
    #[error("the integrator stopped: state component {index} ({name}) became non-finite at t = {t:.9} s")]
    NonFiniteState { t: f64, index: usize, name: String },
    #[error("the integrator stopped: more than {max_steps} steps before t = {t:.9} s")]
    TooManySteps { t: f64, max_steps: usize },
    /// The recording could not be written (I/O error, full disk, another writer of the same
    /// path): `source` names the path and the OS reason.
    #[error("writing the recording: {source}")]
    Recording { path: PathBuf, source: schemas::Error },
}

impl DynamicsError {
    /// The simulated time of the failure, s.
    pub fn time(&self) -> f64 {
        match *self {
            DynamicsError::SingularMassMatrix { t }
            | DynamicsError::SingularConstraints { t, .. }
            | DynamicsError::Unreachable { t, .. }
            | DynamicsError::NonFinite { t, .. } => t,
        }
    }
}

impl RunError {
    /// The simulated time of the failure, s, when it happened during integration.
    pub fn time(&self) -> Option<f64> {
        match self {
            RunError::Dynamics(e) => Some(e.time()),
            RunError::StepSizeTooSmall { t, .. }
            | RunError::SingularIterationMatrix { t, .. }
            | RunError::NonFiniteState { t, .. }
            | RunError::TooManySteps { t, .. } => Some(*t),
            RunError::Recording { .. } => None,
        }
    }

    /// Whether the run failed because its recording could not be written (an I/O error, exit
    /// status 2 in the tools) rather than numerically (exit status 1).
    pub fn is_io(&self) -> bool {
        matches!(self, RunError::Recording { .. })
    }
}
