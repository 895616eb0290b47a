//! The one workspace of an [`super::ArmSystem`], sized once (no allocation while integrating):
//! the dynamics scratch ([`Data`], [`ForwardData`]), the controller's targets and voltages, the
//! quasi-static currents, and the scratch of the Jacobian and of the projection. Fields are
//! private to the `ode` module; each says which part writes it and which reads it.

use nalgebra::{DMatrix, DVector};

use crate::control::{ControllerScratch, TargetScratch};
use crate::dynamics::forward::ForwardData;
use crate::dynamics::motor::Drives;
use crate::dynamics::{Data, Model};

pub(super) struct Workspace {
    /// Kinematics and dynamics scratch; written by every evaluation.
    pub(super) data: Data,
    /// Eq 21's scratch and outputs (q̈, f_n, di/dt, τ); written by `ArmSystem::evaluate`.
    pub(super) fd: ForwardData,
    /// Targets q_d, q̇_d (nv); written by `ArmSystem::voltage_at`.
    pub(super) q_des: Vec<f64>,
    pub(super) qd_des: Vec<f64>,
    /// Target q̈_d (nv), rad/s^2, for the controllers that feed it forward; written by
    /// `ArmSystem::voltage_at` when `want_qdd`.
    pub(super) qdd_des: Vec<f64>,
    /// The time of the targets in `q_des`, `qd_des` (and `qdd_des`), NaN when none: they
    /// depend on t alone, so `ArmSystem::voltage_at` computes them once per t.
    pub(super) target_t: f64,
    /// Whether the controller reads q̈_d (computed torque; the paper's PD does not, and the
    /// paper target then skips computing it). Set once in `ArmSystem::new`.
    pub(super) want_qdd: bool,
    /// The target's own scratch (`Target::eval`, `Target::hand_desired`).
    pub(super) target: TargetScratch,
    /// Motor voltages (nv), V, as the motors see them (after the drive's limits); written by
    /// `ArmSystem::voltage_at`.
    pub(super) voltage: Vec<f64>,
    /// The controller's command before the drive's limits (nv), V; written by
    /// `ArmSystem::voltage_at` when the drives have limits.
    pub(super) voltage_cmd: Vec<f64>,
    /// The controller's scratch.
    pub(super) ctrl: ControllerScratch,
    /// Currents of quasi-static motors (computed, not integrated), A; `ArmSystem::evaluate`.
    pub(super) current_qs: Vec<f64>,
    /// The structured Jacobian's own matrices (`jacobian.rs`), computed there from `fd.jac`
    /// (J_c) and `data.m` (M), whatever constraint solver ran.
    pub(super) jac: JacobianScratch,
    /// The projection's matrices (`projection.rs`).
    pub(super) projection: ProjectionScratch,
    /// The scene's drives with the winding resistances of this evaluation: R(T_w) with the
    /// thermal model (`ArmSystem::set_resistance`), else the scene's own. What the physics
    /// reads (eq 11, the copper loss, the drive's current window); the controller keeps the
    /// scene's nominal drives.
    pub(super) drives: Drives,
    /// The q (nv) whose q-only part of a hybrid evaluation (placements, `M_J`'s factor, the
    /// contact rows and gaps) the workspace holds for the q̇ and current columns of a
    /// difference-Jacobian sweep, when `sweep_ready`: set by `ArmSystem::rhs_column` after its
    /// full evaluation of the first q̇ column, cleared by every `ArmSystem::evaluate`.
    pub(super) sweep_q: Vec<f64>,
    pub(super) sweep_ready: bool,
    /// Evaluations that reused that part (`ArmSystem::same_q_evaluations`).
    pub(super) same_q_evals: u64,
}

impl Workspace {
    pub(super) fn new(model: &Model, drives: &Drives, nc: usize, dim: usize) -> Self {
        let nv = model.nv;
        Self {
            data: Data::new(model),
            fd: ForwardData::new(nv, nc),
            q_des: vec![0.0; nv],
            qd_des: vec![0.0; nv],
            qdd_des: vec![0.0; nv],
            target_t: f64::NAN,
            want_qdd: false,
            target: TargetScratch::new(model),
            voltage: vec![0.0; nv],
            voltage_cmd: vec![0.0; nv],
            ctrl: ControllerScratch::new(nv),
            current_qs: vec![0.0; nv],
            jac: JacobianScratch::new(nv, nc, dim),
            projection: ProjectionScratch::new(nv, nc),
            drives: drives.clone(),
            sweep_q: vec![0.0; nv],
            sweep_ready: false,
            same_q_evals: 0,
        }
    }
}

/// Scratch of the structured Jacobian.
pub(super) struct JacobianScratch {
    /// `M_J = M + J_m`, then its Cholesky factor (nv x nv).
    pub(super) m_j: DMatrix<f64>,
    /// `M_c⁻¹`, the constrained inverse inertia (nv x nv).
    pub(super) minv: DMatrix<f64>,
    /// `Y = M_J⁻¹ J_cᵀ` (nv x nc).
    pub(super) y: DMatrix<f64>,
    /// `A = J_c Y` (nc x nc), and its factor.
    pub(super) a: DMatrix<f64>,
    pub(super) a_factor: DMatrix<f64>,
    /// `A⁻¹ Yᵀ` (nc x nv).
    pub(super) ayt: DMatrix<f64>,
    /// f(t, y) of the evaluation the Jacobian is taken at (dim).
    pub(super) f: Vec<f64>,
    /// The controller's diagonal linearisation per joint (k_p', k_d', k_i').
    pub(super) lin: Vec<(f64, f64, f64)>,
    /// The exact current columns' matrices (`current_columns.rs`).
    pub(super) cur: super::current_columns::CurrentColumnsScratch,
    /// The target's q_d, q̇_d, q̈_d for the exact `∂f/∂t` (`time_derivative.rs`), nv each.
    pub(super) q_d: Vec<f64>,
    pub(super) qd_d: Vec<f64>,
    pub(super) qdd_d: Vec<f64>,
}

impl JacobianScratch {
    fn new(nv: usize, nc: usize, dim: usize) -> Self {
        Self {
            m_j: DMatrix::zeros(nv, nv),
            minv: DMatrix::zeros(nv, nv),
            y: DMatrix::zeros(nv, nc),
            a: DMatrix::zeros(nc, nc),
            a_factor: DMatrix::zeros(nc, nc),
            ayt: DMatrix::zeros(nc, nv),
            f: vec![0.0; dim],
            lin: vec![(0.0, 0.0, 0.0); nv],
            cur: super::current_columns::CurrentColumnsScratch::new(nv, nc),
            q_d: vec![0.0; nv],
            qd_d: vec![0.0; nv],
            qdd_d: vec![0.0; nv],
        }
    }
}

/// Scratch of the projection onto the constraints.
pub(super) struct ProjectionScratch {
    /// `J_c` (nc x nv) and `J̇_c q̇` (nc).
    pub(super) jac: DMatrix<f64>,
    pub(super) jdqd: DVector<f64>,
    /// `J_c J_cᵀ` (nc x nc) and its factor.
    pub(super) jjt: DMatrix<f64>,
    pub(super) work: DMatrix<f64>,
    /// The right-hand side, then the solution (nc).
    pub(super) rhs: DVector<f64>,
}

impl ProjectionScratch {
    fn new(nv: usize, nc: usize) -> Self {
        Self { jac: DMatrix::zeros(nc, nv), jdqd: DVector::zeros(nc), jjt: DMatrix::zeros(nc, nc), work: DMatrix::zeros(nc, nc), rhs: DVector::zeros(nc) }
    }
}
