//! [`Data`]: every buffer the algorithms write, sized once from the [`Model`] so that the
//! step loop never allocates (the MuJoCo `mjData` / pinocchio `Data` split). Each field says
//! which function writes it.

use nalgebra::{DMatrix, DVector, Isometry3, Vector3};

use super::model::Model;
use super::spatial::{Force, Inertia, Motion, Xform};

#[derive(Clone, Debug)]
pub struct Data {
    /// Placement of body i in its parent (or the world) at the current q; written by
    /// `kinematics::forward_kinematics`, `rnea::rnea`, `crba::crba`.
    pub x_parent_body: Vec<Isometry3<f64>>,
    /// The same placements as matrices, for the recursions; written with `x_parent_body`.
    pub xm_parent_body: Vec<Xform>,
    /// Placement of body i in the world; written by `kinematics::forward_kinematics`.
    pub x_world_body: Vec<Isometry3<f64>>,
    /// Body spatial velocity in body coordinates (nv); written by `rnea::rnea`.
    pub v_body: Vec<Motion>,
    /// Body spatial acceleration in body coordinates, gravity included as a base acceleration (nv); `rnea::rnea`.
    pub a_body: Vec<Motion>,
    /// Force transmitted across joint i in body-i coordinates (nv); `rnea::rnea`.
    pub f_body: Vec<Force>,
    /// Joint torques of inverse dynamics (nv), N m; `rnea::rnea`.
    pub tau: DVector<f64>,
    /// Composite inertias (nv): in body coordinates after `crba::crba`; with world axes about
    /// joint i's origin after `crba::crba_world`.
    pub ic: Vec<Inertia>,
    /// Joint motion subspaces with world axes at each joint's own origin, `(z, 0)` or `(0, z)` (nv); `crba::crba_world`.
    pub s_world: Vec<Motion>,
    /// Joint-space inertia M(q) (nv x nv), both triangles filled; `crba::crba` or `walker_orin::mass_matrix`.
    pub m: DMatrix<f64>,
    /// World-frame angular velocity of body i, rad/s; `kinematics::forward_velocities`.
    pub w_world: Vec<Vector3<f64>>,
    /// World-frame velocity of body i's origin, m/s; `kinematics::forward_velocities`.
    pub v_world: Vec<Vector3<f64>>,
    /// World-frame angular acceleration of body i at qdd = 0 (the J̇q̇ part), rad/s^2.
    pub alpha_bias_world: Vec<Vector3<f64>>,
    /// World-frame acceleration of body i's origin at qdd = 0 (the J̇q̇ part), m/s^2.
    pub a_bias_world: Vec<Vector3<f64>>,
    /// Zero vector (nv), for calls with q̇ = 0 or q̈ = 0.
    pub zeros_nv: DVector<f64>,
    /// Unit vector scratch (nv), for the Walker–Orin columns.
    pub unit_nv: DVector<f64>,
    /// Saved inverse-dynamics result (nv), scratch for `walker_orin`.
    pub tau_saved: DVector<f64>,
}

impl Data {
    pub fn new(model: &Model) -> Self {
        let nv = model.nv;
        Self {
            x_parent_body: vec![Isometry3::identity(); nv],
            xm_parent_body: vec![Xform::identity(); nv],
            x_world_body: vec![Isometry3::identity(); nv],
            v_body: vec![Motion::ZERO; nv],
            a_body: vec![Motion::ZERO; nv],
            f_body: vec![Force::ZERO; nv],
            tau: DVector::zeros(nv),
            ic: vec![Inertia::zero(); nv],
            s_world: vec![Motion::ZERO; nv],
            m: DMatrix::zeros(nv, nv),
            w_world: vec![Vector3::zeros(); nv],
            v_world: vec![Vector3::zeros(); nv],
            alpha_bias_world: vec![Vector3::zeros(); nv],
            a_bias_world: vec![Vector3::zeros(); nv],
            zeros_nv: DVector::zeros(nv),
            unit_nv: DVector::zeros(nv),
            tau_saved: DVector::zeros(nv),
        }
    }
}
