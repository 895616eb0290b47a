//! `sim`: motor-driven robot arms that rest their elbows on a surface.
//!
//! Conventions used everywhere in this crate:
//! - SI units, angles in radians; time in seconds (recordings convert to ns once, in `schemas`).
//! - World frame: z up, gravity along −z by default; the table is a plane given by the scene.
//! - Degrees of freedom are 0-based and ordered parent-before-child (the order of the URDF
//!   for a serial chain); `q`, `qd`, `qdd`, currents and voltages share that order.
//! - A placement `x_a_b` maps frame-b coordinates into frame a; frames are written into names.
//!
//! Layout: `dynamics` (read-only `Model`, scratch `Data`, one algorithm per file), `control`
//! (PD voltage law, target trajectory, inverse kinematics), `integrate` (ODE methods with dense
//! output, robot-agnostic), `scene` (JSON spec → validated `Scene`), `system` (the ODE of a
//! scene: state layout and right-hand side), `run` (one run sampled on a fixed grid and
//! recorded through `schemas`), `limits` (the bounds on every input and run).

pub mod dynamics;
pub mod error;
pub mod limits;
pub mod joint_limits;
pub mod control;
pub mod scene;
pub mod integrate;
pub mod integrator;
pub mod run;
pub mod record;
pub mod precision;
pub mod ode;
pub mod replay;
pub mod sweep;
pub mod study;
