//! Rigid-body dynamics of motor-driven arms: the read-only [`Model`], the scratch [`Data`],
//! and one algorithm per file.

pub mod cholesky;
pub mod constraints;
pub mod contact;
pub mod crba;
pub mod data;
pub mod energy;
pub mod forward;
pub mod gear_friction;
pub mod kinematics;
pub mod model;
pub mod motor;
pub mod psd_null;
pub mod rnea;
pub mod samples;
pub mod spatial;
pub mod spd;
pub mod supply;
pub mod thermal;
pub mod urdf;
pub mod walker_orin;

pub use data::Data;
pub use model::Model;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod urdf_tests;
