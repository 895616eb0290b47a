//! What the arm is asked to do: the [`Target`] chosen by the scene (the paper's circle with its
//! closed-form IK, joint-space splines, hand paths tracked by a general IK), and the PD voltage
//! law of the paper (eq 27).

pub mod controller;
pub mod general_ik;
pub mod ik;
pub mod path;
pub mod pd;
pub mod spline;
pub mod target;
pub mod trajectory;

pub use controller::{ControlInput, Controller, ControllerScratch, Law};
pub use ik::YawPlanarIk;
pub use pd::PdGains;
pub use trajectory::Circle;
pub use target::{Target, TargetScratch};
