//! Point contacts between a body point and a world plane, with a model chosen per contact
//! ([`ContactModel`]): the paper's bilateral constraint, rigid unilateral contact with
//! Coulomb friction and Newton restitution (event-driven), or a compliant spring-damper.
//!
//! Shared types of the contact modules (issue 11). Frames: the plane's unit normal `n` and its
//! tangent basis `(t1, t2)` ([`tangent_basis`]) are world-frame; every tangential quantity is
//! given in that basis, `[along t1, along t2]`.
//!
//! Sign conventions: gap `g = n · p − d` (m, > 0 separated); gap rate `ġ` (m/s); normal force
//! `f_n` (N, > 0 pushes the point away from the plane); friction force `f_t` (N, on the
//! point); slip velocity `v_t` (m/s, of the point relative to the plane).

use nalgebra::{Unit, Vector3};

use super::constraints::PointOnPlane;
pub use shape::{ContactShape, Touch};

/// How one contact behaves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ContactModel {
    /// The paper's: the point is held on the plane (`g = 0` always), frictionless; `f_n` takes
    /// either sign (a table that can pull).
    Bilateral,
    /// Rigid, event-driven: `g ≥ 0`, `f_n ≥ 0`, `f_n g = 0`; Newton restitution
    /// `restitution ∈ [0, 1]` at impacts; isotropic Coulomb friction `friction = μ ≥ 0`.
    Unilateral { restitution: f64, friction: f64 },
    /// A spring-damper normal force `f_n = max(0, k δ + c δ̇)` for penetration `δ = −g > 0`
    /// (`stiffness` k in N/m, `damping` c in N s/m), with regularised Coulomb friction
    /// `f_t = −μ f_n v_t / sqrt(|v_t|² + v_s²)` (`friction` μ, `slip_velocity` v_s in m/s).
    Compliant { stiffness: f64, damping: f64, friction: f64, slip_velocity: f64 },
}

impl ContactModel {
    /// Its name in scenes and recordings: `bilateral`, `unilateral`, `compliant`.
    pub fn name(&self) -> &'static str {
        match self {
            ContactModel::Bilateral => "bilateral",
            ContactModel::Unilateral { .. } => "unilateral",
            ContactModel::Compliant { .. } => "compliant",
        }
    }
}

/// The state of one contact at an instant, as recorded (`mode` codes in the recording).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ContactMode {
    /// Not touching (`g > 0`, or a compliant contact with zero force): code 0.
    #[default]
    Separated,
    /// Touching with no slip (`v_t = 0`, `|f_t| ≤ μ f_n`): code 1.
    Sticking,
    /// Touching and slipping (`f_t = −μ f_n v_t/|v_t|`); also a frictionless contact in
    /// touch: code 2.
    Sliding,
    /// A bilateral contact (always held): code 3.
    Bilateral,
}

impl ContactMode {
    /// The code recorded in `/contacts`' `mode` array.
    pub fn code(self) -> u32 {
        match self {
            ContactMode::Separated => 0,
            ContactMode::Sticking => 1,
            ContactMode::Sliding => 2,
            ContactMode::Bilateral => 3,
        }
    }

    /// Its name: `separated`, `sticking`, `sliding`, `bilateral`.
    pub fn name(self) -> &'static str {
        match self {
            ContactMode::Separated => "separated",
            ContactMode::Sticking => "sticking",
            ContactMode::Sliding => "sliding",
            ContactMode::Bilateral => "bilateral",
        }
    }
}

/// One contact of a run: the point and its plane, the model, and the plane's tangent basis.
#[derive(Clone, Debug, PartialEq)]
pub struct Contact {
    pub plane: PointOnPlane,
    pub model: ContactModel,
    /// World-frame unit tangents, `t2 = n × t1` ([`tangent_basis`]).
    pub t1: Vector3<f64>,
    pub t2: Vector3<f64>,
    /// What touches the plane: the point itself, or a sphere centred on it (`shape.rs`).
    pub shape: ContactShape,
}

impl Contact {
    /// Coulomb's friction coefficient μ of a unilateral (rigid) contact, the μ of its modes;
    /// 0 for the other models (a bilateral contact is frictionless; a compliant contact's
    /// regularised friction is part of its own force law, not of the mode problem).
    pub fn unilateral_friction(&self) -> f64 {
        match self.model {
            ContactModel::Unilateral { friction, .. } => friction,
            _ => 0.0,
        }
    }

    pub fn new(plane: PointOnPlane, model: ContactModel) -> Self {
        let (t1, t2) = tangent_basis(&plane.normal_world);
        Contact { plane, model, t1, t2, shape: ContactShape::Point }
    }

    /// This contact with `shape` touching the plane instead of its point.
    pub fn with_shape(self, shape: ContactShape) -> Self {
        Contact { shape, ..self }
    }

    pub fn name(&self) -> &str {
        &self.plane.name
    }
}

/// The tangent basis of a plane with unit normal `n`: `t1` is world x projected onto the plane
/// and normalised (world y when `|x · n| > 0.9`), `t2 = n × t1`. For the table `n = z` this is
/// `(x, y)`.
pub fn tangent_basis(n: &Unit<Vector3<f64>>) -> (Vector3<f64>, Vector3<f64>) {
    let n = n.into_inner();
    let e = if n.x.abs() > 0.9 { Vector3::y() } else { Vector3::x() };
    let t1 = (e - n * n.dot(&e)).normalize();
    let t2 = n.cross(&t1);
    (t1, t2)
}

/// What happened at a contact event (the `/contact_events` channel).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactEventKind {
    /// `f_n` fell to zero: the contact opens.
    LiftOff,
    /// The gap closed with (numerically) zero approach speed: the contact closes without an
    /// impact.
    TouchDown,
    /// The gap closed with approach speed: an impulse (Newton's restitution).
    Impact,
    /// A bouncing sequence ended: the approach speed fell below the rest threshold, the
    /// impact was made plastic and the contact closed (the Zeno rule).
    Rest,
    /// Friction could no longer hold: sticking to sliding.
    StickToSlip,
    /// The slip velocity reached zero and friction can hold: sliding to sticking.
    SlipToStick,
}

impl ContactEventKind {
    /// Its name in recordings: `lift-off`, `touch-down`, `impact`, `rest`, `stick-to-slip`,
    /// `slip-to-stick`.
    pub fn name(self) -> &'static str {
        match self {
            ContactEventKind::LiftOff => "lift-off",
            ContactEventKind::TouchDown => "touch-down",
            ContactEventKind::Impact => "impact",
            ContactEventKind::Rest => "rest",
            ContactEventKind::StickToSlip => "stick-to-slip",
            ContactEventKind::SlipToStick => "slip-to-stick",
        }
    }
}

/// One contact event, as recorded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactEvent {
    /// Event time, s (located on the dense output).
    pub t: f64,
    /// Index of the contact in the run's contact list.
    pub contact: usize,
    pub kind: ContactEventKind,
    /// Normal impulse of an impact, N s (0 for the other kinds).
    pub impulse: f64,
    /// Kinetic energy lost in an impact (with the rotors'), J (0 for the other kinds).
    pub energy_lost: f64,
    /// Gap rate just before and just after the event, m/s.
    pub gap_rate_before: f64,
    pub gap_rate_after: f64,
}

/// A contact's recorded quantities at one output time (`ode::Outputs::contacts`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactOutput {
    pub mode: ContactMode,
    /// Gap g, m, and its rate ġ, m/s.
    pub gap: f64,
    pub gap_rate: f64,
    /// Normal force f_n, N.
    pub normal_force: f64,
    /// Friction force on the point, `[t1, t2]`, N.
    pub friction_force: [f64; 2],
    /// Slip velocity of the point, `[t1, t2]`, m/s.
    pub slip_velocity: [f64; 2],
    /// Cumulative since t = 0, J: kinetic energy lost in this contact's impacts, work
    /// dissipated by its friction (`∫ −f_t · v_t dt ≥ 0`), and a compliant contact's damping
    /// loss (`∫ (f_n − k δ) δ̇ dt`).
    pub impact_loss: f64,
    pub friction_work: f64,
    pub damping_loss: f64,
}

/// Tolerances and limits of the event-driven contact handling (the scene's `events`, with the
/// closing tolerances fixed here).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactSettings {
    /// Width of the bracket an event time is located to, s (default 1e-12).
    pub time_tol: f64,
    /// A contact is closed when `|g| ≤ gap_tol` (m) and `|ġ| ≤ vel_tol` (m/s); 1e-9 each.
    pub gap_tol: f64,
    pub vel_tol: f64,
    /// Impacts with approach speed below this are plastic (the Zeno rule), m/s (default 1e-4).
    pub rest_velocity: f64,
    /// Most contact events in a run (default 100 000).
    pub max_events: u64,
    /// Most events in a row at one instant (within `10 time_tol` of each other) before the
    /// run stops as chattering (default [`DEFAULT_MAX_EVENTS_AT_ONE_TIME`]).
    pub max_events_at_one_time: u32,
    /// The largest speed below which a stick → slip onset's friction direction is regularised,
    /// m/s ([`forward::onset_speed_bound`] of the run's tolerances; default
    /// [`forward::SLIP_DIRECTION_SPEED`]): written in the record `contacts`, where the audit
    /// reads it.
    pub onset_slip_speed: f64,
}

/// The default of the scene's `events.max_events_at_one_time`.
pub const DEFAULT_MAX_EVENTS_AT_ONE_TIME: u32 = 32;

/// The bound on the scene's `events.max_events_at_one_time`: past a few thousand events at
/// one instant nothing settles, and each event may cost a mode enumeration.
pub const MAX_EVENTS_AT_ONE_TIME_LIMIT: u32 = 10_000;

impl Default for ContactSettings {
    fn default() -> Self {
        ContactSettings {
            time_tol: 1e-12,
            gap_tol: 1e-9,
            vel_tol: 1e-9,
            rest_velocity: 1e-4,
            max_events: 100_000,
            max_events_at_one_time: DEFAULT_MAX_EVENTS_AT_ONE_TIME,
            onset_slip_speed: forward::SLIP_DIRECTION_SPEED,
        }
    }
}

/// Most unilateral contacts closed at one time: the mode problem enumerates 3^n combinations.
pub const MAX_CLOSED_CONTACTS: usize = 8;

pub mod dependent;
pub mod forward;
pub mod impact;
pub mod indeterminate;
pub mod modes;
pub mod pair_normal;
pub mod pair_slip;
pub mod rows;
pub mod shape;
pub mod solve;
#[cfg(test)]
mod tests;
