//! What the arm is asked to do: the hand's target path, the inverse kinematics that turns it
//! into joint targets, and the PD voltage law of the paper (eq 27).

pub mod controller;
pub mod ik;
pub mod pd;
pub mod trajectory;

pub use controller::{ControlInput, Controller, ControllerScratch, Law};
pub use ik::YawPlanarIk;
pub use pd::PdGains;
pub use trajectory::Circle;
