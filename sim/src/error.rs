//! Error types of the `sim` library. Every variant carries what a user needs to act on it:
//! the file, the field and the value for bad input; the simulated time for numerical failure.

use std::path::PathBuf;

/// A robot description that cannot be turned into a [`crate::dynamics::Model`].
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ModelError {
    /// The text is not well-formed XML (or not a URDF at all).
    #[error("{file}:{line}: the URDF could not be parsed: {message}")]
    Parse { file: String, line: usize, message: String },
    /// One element is wrong: `element` is written as in the file (`<joint name="j1">`), `why`
    /// says what is wrong and what to do.
    #[error("{file}:{line}: {element}: {why}")]
    At { file: String, line: usize, element: String, why: String },
    #[error("{file}:{line}: {hint}", hint = crate::dynamics::urdf::XACRO_HINT)]
    Xacro { file: String, line: usize },
    /// A loading option of the scene (`robot.locked.<joint>`, ...) that does not fit the URDF:
    /// `field` is the scene field.
    #[error("{file}: {field} = {value}: {why}")]
    Option { file: String, field: String, value: String, why: String },
    #[error("{file}: the links must form one tree with one root; found roots {roots:?}")]
    Roots { file: String, roots: Vec<String> },
    #[error("{file}: the URDF has no movable joint (every joint is fixed or locked)")]
    NoJoints { file: String },
    #[error("{file}: elements nested more than {limit} deep (a URDF is about 6 deep); refused before parsing")]
    TooDeep { file: String, limit: usize },
    #[error("{file}: {count} {items}, more than the limit of {limit} (sim::limits::MAX_URDF_JOINTS)")]
    TooMany { file: String, items: &'static str, count: usize, limit: usize },
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

/// `x` as written by people, for a value in a message: plain in [1e-4, 1e9) (`0.001`), else
/// with an exponent (`1e-12`, `1e300`, not 300 digits).
pub(crate) fn short(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e9).contains(&x.abs()) {
        x.to_string()
    } else {
        format!("{x:e}")
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
    /// A rigid unilateral contact configuration with no consistent solution, or with several
    /// that accelerate the arm differently (Painlevé's paradox: friction too high for the
    /// geometry); `contact` names the contact(s).
    #[error("t = {t:.9} s: contact {contact}: {why}")]
    InconsistentContact { t: f64, contact: String, why: String },
    /// The run's wall-time budget ran out inside an evaluation (`during`: the contact mode
    /// enumeration); the run turns it into [`RunError::OutOfTime`] with its limit and method.
    #[error("t = {t:.9} s: the wall-time budget ran out {during}")]
    OutOfTime { t: f64, during: crate::integrate::Phase },
}

/// A failure of a whole run.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RunError {
    #[error("{0}")]
    Dynamics(#[from] DynamicsError),
    #[error("the integrator stopped at t = {t:.9} s: the step size collapsed to h = {h:e} s and can no longer advance t; the solution is not smooth there (a contact force, the inverse kinematics at its reach) or too stiff for the method: check the scene at that time, or use rosenbrock")]
    StepSizeTooSmall { t: f64, h: f64 },
    #[error("the integrator stopped at t = {t:.9} s: the problem is stiff for an explicit method (h lambda = {h_lambda:.2} at the stability limit, h = {h:.3e} s, more than 10^6 steps to go): use rosenbrock or imex")]
    Stiff { t: f64, h: f64, h_lambda: f64 },
    /// `during`: where in a step the budget ran out (between steps, or inside one of a step's
    /// long loops: the Jacobian by differences, the factorisation, an event location, the
    /// contact mode enumeration).
    #[error("the run stopped at t = {t:.9} s: it used its wall-time limit of {limit_s} s with {method}, {during}; {hint}, or the run is long: to allow more, give --max-wall-time SECONDS", hint = out_of_time_hint(method, during))]
    OutOfTime { t: f64, limit_s: f64, method: &'static str, during: crate::integrate::Phase },
    #[error("the run stopped at t = {t:.9} s: at its pace so far it would need about {projected_s:.0} s of wall time with {method}, more than twice its limit of {limit_s} s; {hint}, or the run is long: to allow more, give --max-wall-time SECONDS", hint = slow_run_hint(method))]
    TooSlow { t: f64, projected_s: f64, limit_s: f64, method: &'static str },
    #[error("the implicit integrator stopped: its iteration matrix I - h gamma J is singular at t = {t:.9} s (h = {h:e} s)")]
    SingularIterationMatrix { t: f64, h: f64 },
    #[error("the integrator stopped: state component {index} ({name}) became non-finite at t = {t:.9} s")]
    NonFiniteState { t: f64, index: usize, name: String },
    #[error("the integrator stopped at t = {t:.9} s: more than {max_steps} steps (integrator.max_steps) with {method}; {hint}; raise integrator.max_steps if the run needs more", hint = slow_run_hint(method))]
    TooManySteps { t: f64, max_steps: usize, method: &'static str },
    #[error("the run stopped at t = {t:.9} s: more than {max_events} contact events; a contact chatters, or the run is long (events.max_events)")]
    TooManyEvents { t: f64, max_events: u64 },
    /// More than `limit` (the scene's `events.max_events_at_one_time`) events in a row within
    /// `window` s of each other.
    #[error("the run stopped at t = {t:.9} s: {count} contact events in a row at the same instant (within {window:e} s), more than events.max_events_at_one_time = {limit}: the contact modes chatter; {events}. Remedies: raise events.max_events_at_one_time in the scene if the events do settle (a cascade through many contacts); make the contacts compliant (model \"compliant\", no instantaneous mode switches); lower the contacts' friction (a high coefficient can make the rigid contact problem inconsistent, Painleve's paradox); or check the initial state and the target near that time")]
    Chattering { t: f64, count: u32, window: f64, limit: u32, events: String },
    /// The gears' stick/slide modes (`gear_friction`, issue 26) found no consistent
    /// combination: either the joints' joint decision at an event found none among every
    /// combination of the joints at rest (`count` combinations tried, `window` 0), or the gears'
    /// events chattered at one instant ([`RunError::Chattering`] where every event is a gear's:
    /// `count` events within `window` s, more than `limit`).
    #[error("the run stopped at t = {t:.9} s: the gears of {joints} have no consistent stick/slide modes there ({count} {what}): the motions of these joints are coupled (a closed chain through the table, or their shared mass matrix) and every combination of their stick and slide modes contradicts itself, or they switch without end. {remedy}", what = gears_what(.window, .limit), remedy = gears_remedy(*.breakaway))]
    /// `breakaway`: some of these gears have a Coulomb or static torque (else they are
    /// efficiency-only, and the remedy differs).
    GearsChatter { t: f64, count: u32, window: f64, limit: u32, joints: String, breakaway: bool },
    /// The recording could not be written (I/O error, full disk, another writer of the same
    /// path): `source` names the path and the OS reason.
    #[error("writing the recording: {source}")]
    Recording { path: PathBuf, source: schemas::Error },
}

/// [`RunError::GearsChatter`]'s count, said: combinations tried (a joint decision, `window` 0)
/// or switches at one instant.
fn gears_what(window: &f64, limit: &u32) -> String {
    if *window == 0.0 {
        "combinations of stick, slide + and slide - tried".to_string()
    } else {
        format!("switches in a row within {window:e} s, events.max_events_at_one_time = {limit}")
    }
}

/// The remedy of [`RunError::GearsChatter`]: with a Coulomb or static torque on some of the
/// gears, fewer or weaker such torques; efficiency-only gears hold only in proportion to their
/// motor torque, nothing at zero current, so a breakaway torque is what widens their bands
/// there (a remedy about Coulomb friction would name a torque they do not have).
fn gears_remedy(breakaway: bool) -> &'static str {
    if breakaway {
        "Remedies: leave the Coulomb/static friction off all but one of these joints (gear_friction values per joint: coulomb and breakaway 0; their efficiencies can stay), lower their breakaway torques, or run the elbow-free run"
    } else {
        "These gears have no Coulomb or static friction (efficiency only): a sticking one holds at most (1/back_efficiency - efficiency) |K_m i| beyond its motor's torque, nothing at zero current, so their modes turn on how the currents leave 0. Remedies: give them a small breakaway torque (gear_friction.breakaway > 0), which lets each hold that much at zero current; set their efficiencies to 1 (no gear law on them); or run the elbow-free run"
    }
}

/// What makes a run with `method` slow where its budget ran out (`during`), and what to do.
fn out_of_time_hint(method: &str, during: &crate::integrate::Phase) -> &'static str {
    use crate::integrate::Phase;
    match during {
        Phase::Jacobian { .. } | Phase::Factoring { .. } => "the Jacobian by differences costs one right-hand side per state of the q, q̇, i block (3 per joint) and its factorisation grows as their cube: for a long chain use rosenbrock (a structured Jacobian) or imex",
        Phase::ChoosingModes { .. } => "the rigid contact mode problem tries up to 3^n combinations of the n closed contacts, each a constrained solve: use compliant contacts, or fewer simultaneous contacts",
        Phase::LocatingEvent { .. } | Phase::Stepping => slow_run_hint(method),
    }
}

/// What makes a run with `method` (a scene's `integrator.method`) take tiny steps, and what
/// to do about it.
fn slow_run_hint(method: &str) -> &'static str {
    match method {
        "rk4" | "dopri45" => "its steps are very small (a problem too stiff for an explicit method: use rosenbrock or imex; a fast target; tight tolerances)",
        "imex" => "its steps are very small (stiff mechanics, e.g. extreme damping, which imex treats explicitly: use rosenbrock; a fast target; tight tolerances)",
        _ => "its steps are very small (a fast target, tight tolerances, or a solution that is not smooth: check the scene)",
    }
}

impl DynamicsError {
    /// The simulated time of the failure, s.
    pub fn time(&self) -> f64 {
        match *self {
            DynamicsError::SingularMassMatrix { t }
            | DynamicsError::SingularConstraints { t, .. }
            | DynamicsError::Unreachable { t, .. }
            | DynamicsError::NonFinite { t, .. }
            | DynamicsError::InconsistentContact { t, .. }
            | DynamicsError::OutOfTime { t, .. } => t,
        }
    }
}

impl RunError {
    /// The simulated time of the failure, s, when it happened during integration.
    pub fn time(&self) -> Option<f64> {
        match self {
            RunError::Dynamics(e) => Some(e.time()),
            RunError::StepSizeTooSmall { t, .. }
            | RunError::Stiff { t, .. }
            | RunError::OutOfTime { t, .. }
            | RunError::TooSlow { t, .. }
            | RunError::SingularIterationMatrix { t, .. }
            | RunError::NonFiniteState { t, .. }
            | RunError::TooManySteps { t, .. }
            | RunError::TooManyEvents { t, .. }
            | RunError::Chattering { t, .. }
            | RunError::GearsChatter { t, .. } => Some(*t),
            RunError::Recording { .. } => None,
        }
    }

    /// Whether the run failed because its recording could not be written (an I/O error, exit
    /// status 2 in the tools) rather than numerically (exit status 1).
    pub fn is_io(&self) -> bool {
        matches!(self, RunError::Recording { .. })
    }
}
