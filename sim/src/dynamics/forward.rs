//! Constrained forward dynamics of the motor–arm system, the paper's eq 21:
//!
//! ```text
//! [ M + J_m   −J_c^T  0 ] [ q̈  ]   [ K_m i − h − G − (D + D_m) q̇ ]
//! [ J_c        0      0 ] [ f_n ] = [ −J̇_c q̇                     ]
//! [ 0          0      L ] [ i̇  ]   [ v − R i − K_m q̇            ]
//! ```
//!
//! Two equivalent solutions are offered ([`ConstraintSolver`]):
//! - `Schur` (default): Cholesky of `M_J = M + J_m = L Lᵀ`, then the Schur complement
//!   `A = J_c M_J^{-1} J_c^T` (nc x nc, Cholesky), `f_n = A^{-1}(−J̇_c q̇ − J_c M_J^{-1} b)`,
//!   `q̈ = M_J^{-1}(b + J_c^T f_n)` (Featherstone, RBDA §8.1, eq 8.9–8.10). With `Z = L⁻¹ J_cᵀ`
//!   and `u = L⁻¹ b`: `A = Zᵀ Z` (symmetric by construction), `J_c M_J⁻¹ b = Zᵀ u` and
//!   `q̈ = L⁻ᵀ (u + Z f_n)`: one forward substitution with 1 + nc columns and one back
//!   substitution (eqs 8.9–8.10 with `M_J⁻¹ = L⁻ᵀ L⁻¹` substituted; the solves of
//!   `dynamics/cholesky.rs`).
//! - `Kkt`: LU of the whole (nv + nc) block system, as the paper does.
//!
//! With soft joint stops (`sim/src/joint_limits.rs`), their torques `τ_s` (filled by the caller
//! into [`ForwardData::tau_joint`]) are added to b; without, b is as above. The electrical rows
//! are diagonal and solved directly (with the back-EMF constant K_e k of `motor.rs`). The mass matrix comes from the
//! composite-rigid-body algorithm or from the paper's Walker–Orin method ([`MassMatrixMethod`]).

use nalgebra::{Cholesky, DMatrix, DVector, LU};

use super::cholesky;
use super::constraints::{constraint_rows, PointOnPlane};
use super::crba::crba_world;
use super::data::Data;
use super::kinematics::{forward_kinematics, forward_velocities};
use super::model::Model;
use super::motor::Drives;
use super::rnea::bias_forces_placed;
use super::spd::solve_regularized;
use super::walker_orin;
use crate::error::DynamicsError;

/// How the joint-space inertia is computed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum MassMatrixMethod {
    /// Composite-rigid-body algorithm (RBDA §6.2).
    #[default]
    Crba,
    /// n calls of RNEA, the paper's eqs 22–26 (Walker and Orin 1982, method 1).
    WalkerOrin,
}

/// Constraint stabilisation: the acceleration-level constraint of eq 15 lets C and Ċ drift.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case", tag = "method", deny_unknown_fields)]
pub enum Stabilization {
    /// Eq 15 as in the paper: `J_c q̈ = −J̇_c q̇`.
    #[default]
    None,
    /// Baumgarte (1972): `J_c q̈ = −J̇_c q̇ − 2 α Ċ − β² C`, α and β in 1/s.
    Baumgarte {
        /// Velocity gain α, 1/s.
        alpha: f64,
        /// Position gain β, 1/s.
        beta: f64,
    },
    /// After every accepted step, project q onto C = 0 and q̇ onto Ċ = 0 (mass-weighted
    /// Gauss–Newton; Hairer, Lubich & Wanner, *Geometric Numerical Integration*, §IV.4).
    Projection,
}

/// How the constrained system is solved.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum ConstraintSolver {
    /// Cholesky of M_J and of the nc x nc Schur complement.
    #[default]
    Schur,
    /// LU of the full (nv + nc) block system of eq 21.
    Kkt,
}

/// Scratch and outputs of [`forward_dynamics`], sized once for (nv, nc).
#[derive(Clone, Debug)]
pub struct ForwardData {
    /// `M + J_m`, then its Cholesky factor L in the lower triangle (nv x nv; `Schur` only).
    pub m_j: DMatrix<f64>,
    /// Generalised force `b = K_m i − h − G − (D + D_m) q̇` (nv), N m.
    pub b: DVector<f64>,
    /// Joint accelerations (nv), rad/s^2.
    pub qdd: DVector<f64>,
    /// Constraint Jacobian `J_c` (nc x nv).
    pub jac: DMatrix<f64>,
    /// `J̇_c q̇` (nc), m/s^2.
    pub jdqd: DVector<f64>,
    /// Constraint positions `C` (nc), m, and velocities `Ċ` (nc), m/s.
    pub c: DVector<f64>,
    pub cd: DVector<f64>,
    /// `[u | Z] = L⁻¹ [b | J_cᵀ]` (nv x (1 + nc)), L the Cholesky factor of `M_J` (`Schur` only).
    pub y: DMatrix<f64>,
    /// `1 / L_jj` (nv), the factor's reciprocal diagonal (`Schur` only).
    pub l_inv_diag: Vec<f64>,
    /// Schur complement `J_c M_J^{-1} J_c^T` (nc x nc).
    pub a: DMatrix<f64>,
    /// Its Cholesky factor (nc x nc).
    pub a_factor: DMatrix<f64>,
    /// Whether the last solve had to regularise a singular Schur complement (redundant contacts).
    pub regularized: bool,
    /// Normal forces `f_n` (nc), N.
    pub f_n: DVector<f64>,
    /// Block matrix of eq 21 without the electrical rows ((nv + nc)^2), for `Kkt`.
    pub kkt: DMatrix<f64>,
    pub kkt_rhs: DVector<f64>,
    /// Current rates (nv), A/s.
    pub di: DVector<f64>,
    /// Torque delivered to each link by its motor, eq 12 (nv), N m.
    pub tau_motor: DVector<f64>,
    /// Further joint torques (nv), N m, added to b when `joint_torque` is set (the soft joint
    /// stops, `sim/src/joint_limits.rs`); the caller fills them before each solve.
    pub tau_joint: DVector<f64>,
    /// Whether `tau_joint` enters b (else it is not read: no arithmetic is added).
    pub joint_torque: bool,
}

impl ForwardData {
    pub fn new(nv: usize, nc: usize) -> Self {
        Self {
            m_j: DMatrix::zeros(nv, nv),
            b: DVector::zeros(nv),
            qdd: DVector::zeros(nv),
            jac: DMatrix::zeros(nc, nv),
            jdqd: DVector::zeros(nc),
            c: DVector::zeros(nc),
            cd: DVector::zeros(nc),
            y: DMatrix::zeros(nv, 1 + nc),
            l_inv_diag: vec![0.0; nv],
            a: DMatrix::zeros(nc, nc),
            a_factor: DMatrix::zeros(nc, nc),
            regularized: false,
            f_n: DVector::zeros(nc),
            kkt: DMatrix::zeros(nv + nc, nv + nc),
            kkt_rhs: DVector::zeros(nv + nc),
            di: DVector::zeros(nv),
            tau_motor: DVector::zeros(nv),
            tau_joint: DVector::zeros(nv),
            joint_torque: false,
        }
    }
}

/// The pieces of a system that [`forward_dynamics`] reads.
#[derive(Clone, Copy, Debug)]
pub struct Plant<'a> {
    pub model: &'a Model,
    pub drives: &'a Drives,
    pub contacts: &'a [PointOnPlane],
    pub mass_matrix: MassMatrixMethod,
    pub solver: ConstraintSolver,
    pub stabilization: Stabilization,
}

/// The placements at `q` (RNEA, CRBA and the contacts share them), the bias forces h + G, the
/// generalised force `b = K_m i − h − G − (D + D_m) q̇ [+ τ_joint]` into `fd.b`, and
/// `M_J = M + J_m` into `fd.m_j` (not yet factored): the part of eq 21 that does not depend on
/// the constraints, shared by the bilateral solve below and the contacts' active-row solve
/// (`dynamics/contact/forward.rs`).
pub(crate) fn generalized_force_and_inertia(plant: &Plant, data: &mut Data, fd: &mut ForwardData, q: &[f64], qd: &[f64], current: &[f64]) {
    let (model, drives) = (plant.model, plant.drives);
    let nv = model.nv;
    forward_kinematics(model, data, q);
    generalized_force_placed(plant, data, fd, qd, current);
    match plant.mass_matrix {
        // in world coordinates, from the world placements just computed (crba.rs)
        MassMatrixMethod::Crba => crba_world(model, data),
        MassMatrixMethod::WalkerOrin => walker_orin::mass_matrix(model, data, q),
    };
    fd.m_j.copy_from(&data.m);
    for j in 0..nv {
        fd.m_j[(j, j)] += drives.jm[j];
    }
}

/// The generalised force `b` of [`generalized_force_and_inertia`] into `fd.b` (and the bias
/// forces into `data.tau`), from the placements already in `data` (at the same q): the part
/// that depends on q̇ and the currents, for an evaluation that moves only those
/// (`dynamics/contact/forward.rs`, `forward_dynamics_contacts_same_q`).
pub(crate) fn generalized_force_placed(plant: &Plant, data: &mut Data, fd: &mut ForwardData, qd: &[f64], current: &[f64]) {
    let (model, drives) = (plant.model, plant.drives);
    let nv = model.nv;
    bias_forces_placed(model, data, qd);
    for j in 0..nv {
        fd.b[j] = drives.km[j] * current[j] - data.tau[j];
    }
    if drives.has_friction {
        for j in 0..nv {
            fd.b[j] -= (drives.d[j] + drives.dm[j]) * qd[j];
        }
    }
    if fd.joint_torque {
        for j in 0..nv {
            fd.b[j] += fd.tau_joint[j];
        }
    }
}

/// Solve eq 21 at time `t` (used only in error messages) for the state `q` (rad), `qd`
/// (rad/s), `current` (A) and the motor voltages `voltage` (V), all of length nv.
/// Outputs in `fd`: `qdd`, `f_n`, `di`, `tau_motor`; `data` holds the placements at `q` and,
/// with contacts, the world velocities and bias accelerations at (`q`, `qd`) (the outputs read them).
pub fn forward_dynamics(
    plant: &Plant,
    data: &mut Data,
    fd: &mut ForwardData,
    t: f64,
    q: &[f64],
    qd: &[f64],
    current: &[f64],
    voltage: &[f64],
) -> Result<(), DynamicsError> {
    let (model, drives) = (plant.model, plant.drives);
    let nv = model.nv;
    let nc = plant.contacts.len();
    generalized_force_and_inertia(plant, data, fd, q, qd, current);
    // constraint rows
    if nc > 0 {
        forward_velocities(model, data, qd);
        constraint_rows(model, data, plant.contacts, &mut fd.jac, &mut fd.jdqd, &mut fd.c, &mut fd.cd);
        // Baumgarte: the right-hand side −J̇q̇ becomes −J̇q̇ − 2αĊ − β²C
        if let Stabilization::Baumgarte { alpha, beta } = plant.stabilization {
            for k in 0..nc {
                fd.jdqd[k] += 2.0 * alpha * fd.cd[k] + beta * beta * fd.c[k];
            }
        }
    }
    match plant.solver {
        ConstraintSolver::Schur => solve_schur(plant, fd, t)?,
        ConstraintSolver::Kkt => solve_kkt(plant, fd, t)?,
    }
    // electrical rows and the motor torque of eq 12
    for j in 0..nv {
        fd.di[j] = drives.current_rate(j, voltage[j], current[j], qd[j]);
        fd.tau_motor[j] = drives.link_torque(j, current[j], qd[j], fd.qdd[j]);
    }
    if let Some(j) = fd.qdd.iter().position(|x| !x.is_finite()) {
        return Err(DynamicsError::NonFinite { t, what: format!("the acceleration of {}", model.bodies[j].joint) });
    }
    Ok(())
}

fn contact_names(plant: &Plant) -> String {
    plant.contacts.iter().map(|c| c.name.as_str()).collect::<Vec<_>>().join(", ")
}

fn solve_schur(plant: &Plant, fd: &mut ForwardData, t: f64) -> Result<(), DynamicsError> {
    let nv = plant.model.nv;
    let nc = plant.contacts.len();
    // M_J = L Lᵀ in place (cholesky.rs)
    if !cholesky::factor_in_place(fd.m_j.as_mut_slice(), nv, &mut fd.l_inv_diag) {
        return Err(DynamicsError::SingularMassMatrix { t });
    }
    let (l, inv) = (fd.m_j.as_slice(), &fd.l_inv_diag[..]);
    // [u | Z] = L⁻¹ [b | J_cᵀ]: A = J_c M_J⁻¹ J_cᵀ = Zᵀ Z and J_c M_J⁻¹ b = Zᵀ u
    fd.y.column_mut(0).copy_from(&fd.b);
    for k in 0..nc {
        for j in 0..nv {
            fd.y[(j, 1 + k)] = fd.jac[(k, j)];
        }
    }
    cholesky::solve_lower(l, inv, nv, fd.y.as_mut_slice());
    let (u, z) = fd.y.as_slice().split_at(nv);
    fd.qdd.as_mut_slice().copy_from_slice(u);
    if nc > 0 {
        for a in 0..nc {
            let z_a = &z[a * nv..(a + 1) * nv];
            for b in 0..=a {
                let z_b = &z[b * nv..(b + 1) * nv];
                let dot: f64 = z_a.iter().zip(z_b).map(|(x, y)| x * y).sum();
                fd.a[(a, b)] = dot;
                fd.a[(b, a)] = dot;
            }
            // f_n = A⁻¹ (−J̇q̇ − J q̈_free)
            let ju: f64 = z_a.iter().zip(u).map(|(x, y)| x * y).sum();
            fd.f_n[a] = -fd.jdqd[a] - ju;
        }
        // a redundant set (the same point twice, a rank-deficient J_c) has a singular A:
        // regularised so that q̈ stays unique up to O(ε) (spd.rs)
        let solved = match solve_regularized(&fd.a, &mut fd.a_factor, &mut fd.f_n) {
            Some(regularized) => {
                fd.regularized = regularized;
                true
            }
            None => false,
        };
        if !solved || fd.f_n.iter().any(|x| !x.is_finite()) {
            return Err(DynamicsError::SingularConstraints { t, constraints: contact_names(plant) });
        }
        // L⁻¹ (b + J_cᵀ f_n) = u + Z f_n
        let qdd = fd.qdd.as_mut_slice();
        for (k, z_k) in z.chunks_exact(nv).enumerate() {
            let f = fd.f_n[k];
            for (x, z) in qdd.iter_mut().zip(z_k) {
                *x += z * f;
            }
        }
    }
    // q̈ = L⁻ᵀ L⁻¹ (b + J_cᵀ f_n) = M_J⁻¹ (b + J_cᵀ f_n)
    cholesky::solve_upper_transposed(fd.m_j.as_slice(), &fd.l_inv_diag, nv, fd.qdd.as_mut_slice());
    Ok(())
}

/// `Y = M_J⁻¹ J_cᵀ` (nv x nc) and the Schur complement `A = J_c Y` (nc x nc) of the constraint
/// rows, from the Cholesky factor of `M_J`, into `y` and `a` (RBDA §8.1, eq 8.9).
pub fn schur_complement(chol_m_j: &Cholesky<f64, nalgebra::Dyn>, jac: &DMatrix<f64>, y: &mut DMatrix<f64>, a: &mut DMatrix<f64>) {
    y.tr_copy_from(jac);
    chol_m_j.solve_mut(y);
    a.gemm(1.0, jac, y, 0.0);
}

fn solve_kkt(plant: &Plant, fd: &mut ForwardData, t: f64) -> Result<(), DynamicsError> {
    let nv = plant.model.nv;
    let nc = plant.contacts.len();
    let n = nv + nc;
    fd.kkt.as_mut_slice().fill(0.0);
    fd.kkt.view_mut((0, 0), (nv, nv)).copy_from(&fd.m_j);
    for k in 0..nc {
        for j in 0..nv {
            fd.kkt[(j, nv + k)] = -fd.jac[(k, j)];
            fd.kkt[(nv + k, j)] = fd.jac[(k, j)];
        }
    }
    fd.kkt_rhs.rows_mut(0, nv).copy_from(&fd.b);
    for k in 0..nc {
        fd.kkt_rhs[nv + k] = -fd.jdqd[k];
    }
    // LU with partial pivoting (its permutation is the one allocation of this baseline path)
    let kkt = std::mem::replace(&mut fd.kkt, DMatrix::zeros(0, 0));
    let lu = LU::new(kkt);
    let ok = lu.solve_mut(&mut fd.kkt_rhs);
    let u_diag_min = lu.u().diagonal().iter().fold(f64::INFINITY, |m, x| m.min(x.abs()));
    fd.kkt = lu.l_unpack();
    fd.kkt.resize_mut(n, n, 0.0);
    if !ok || !(u_diag_min > 1e-12) {
        return Err(if nc > 0 {
            DynamicsError::SingularConstraints { t, constraints: contact_names(plant) }
        } else {
            DynamicsError::SingularMassMatrix { t }
        });
    }
    fd.qdd.copy_from(&fd.kkt_rhs.rows(0, nv));
    for k in 0..nc {
        fd.f_n[k] = fd.kkt_rhs[nv + k];
    }
    Ok(())
}
