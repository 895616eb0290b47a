//! The exact current columns `∂f/∂i` of the arm's right-hand side, for the classical Rosenbrock
//! methods (`integrate/rodas.rs`, [`crate::integrate::OdeJacobian::exact_columns`]), which need
//! the exact Jacobian (HNW II §IV.7): instead of `nv` difference columns (issue 24, point 1).
//!
//! The currents enter f only through the motor torque `K_m i` in the generalised force b of
//! eq 21 (`dynamics/forward.rs`), the armature equation `L di/dt = v − R i − K_e k q̇` (eq 11;
//! the voltage of `pd`, `pd-gravity` and computed torque without a current loop does not read
//! i, `Controller::reads_current`) and the quadratures. For fixed q, q̇ and contact modes q̈ is
//! affine in b (`dynamics/contact/solve.rs`, after Pfeiffer & Glocker 1996, §5, and
//! Featherstone, RBDA §8.1): `q̈ = u + X λ`, `A λ = −w − W u`, `u = M_J⁻¹ b`, `X = M_J⁻¹ Ŵᵀ`,
//! `A = W X`, where the active rows W, their force columns Ŵ (a sliding contact's along the
//! friction direction, a function of q̇) and their biases w depend on q, q̇ and the modes
//! only. So, with `U = M_J⁻¹ K_m` (K_m diagonal):
//!
//! - `∂q̈/∂i = Q = U + X Λ`, `Λ = ∂λ/∂i = −A⁻¹ W U`; for a run without contact modes (the
//!   bilateral constraints of eq 21) `Q = M_c⁻¹ K_m` with the constrained inverse inertia of
//!   `jacobian.rs`;
//! - `∂q̇/∂i = 0`, `∂(di/dt)/∂i = −diag(R/L)`;
//! - the quadratures: the motor work `τ_j q̇_j` with eq 12's `τ_j = K_m,j i_j − J_m,j q̈_j −
//!   D_m,j q̇_j` gives `(K_m,j δ_jc − J_m,j Q_jc) q̇_j`; the electric energy `i_j v_j` gives
//!   `v_j δ_jc`; the copper loss `Σ R i²` gives `2 R_c i_c`; the conversion loss
//!   `Σ (K_e − K_m) k i q̇` gives `(K_e − K_m)_c q̇_c`; a contact's friction work `−f_t · v_t`
//!   gives `−(∂f_t/∂i) · v_t` with `∂f_t` from Λ (a sliding contact's `−μ s ∂λ_n`, a sticking
//!   one's `∂λ_t`); the viscous losses, the stops' loss, the impact losses and the compliant
//!   contacts' damping loss do not depend on i (0).
//!
//! Where this is not f's exact derivative the system gives no column and the stepper
//! differences them as before: thermal model (R(T_w)), gear friction or a supply
//! (`drive_modes.rs`: efficiency switches and locks), a law with a current loop, and the
//! states where a contact force is not the solve's λ or A is near singular: a contact in a
//! stick → slip onset (its friction's anchor is the direction of the sticking force, a
//! function of b; `dynamics/contact/forward.rs`, `onset_anchors`), a statically indeterminate
//! contact's force chosen by the largest margin (`indeterminate.rs`, `dependent.rs`), and an A
//! whose LU pivots span more than 1e10 (`solve.rs` regularises from 1e12 on). Checked against
//! central differences at random states of the paper arm in every contact mode and without
//! contacts (`sim/tests/current_columns.rs`), and with pd-gravity, K_e ≠ K_m, Baumgarte
//! stabilisation and a compliant contact (written), in an onset, at an indeterminate contact,
//! with gears, a supply, the thermal model and a current loop (declined, the differenced
//! columns checked; `sim/tests/current_columns_cases.rs`). RODAS counts the evaluation made
//! here as one right-hand side (`OdeJacobian::exact_columns_rhs_evals`).

use crate::dynamics::contact::solve::{lu_resolve, lu_solve_in_place, solve_mj, RowForce};
use crate::dynamics::contact::{ContactMode, ContactModel};
use crate::dynamics::motor::Electrical;
use crate::error::RunError;

use super::arm::ArmSystem;

/// LU pivots smaller than this times the largest count as singular (module docs).
const PIVOT_RATIO: f64 = 1e-10;

impl ArmSystem<'_> {
    /// Whether the scene's right-hand side has exact current columns at all (module docs).
    pub(super) fn has_exact_current_columns(&self) -> bool {
        let s = self.scene;
        self.layout.electrical == Electrical::Inductive && self.layout.ni() > 0 && s.thermal.is_none() && self.drive_modes.is_none() && !s.controller.reads_current()
    }

    /// The current columns of `∂f/∂y (t, y)` (all rows) into `jac` (row-major `dim x dim`),
    /// `Ok(false)` without writing where they are not exact (module docs). Evaluates f at
    /// `(t, y)` (reusing the q-only part of a difference sweep at the same q).
    #[allow(clippy::result_large_err)] // RunError, as every evaluation of the arm
    pub(super) fn exact_current_columns(&mut self, t: f64, y: &[f64], jac: &mut [f64]) -> Result<bool, RunError> {
        if !self.has_exact_current_columns() {
            return Ok(false);
        }
        let l = self.layout;
        let nv = l.nv;
        if self.hybrid.is_some() && self.ws.sweep_ready && self.ws.sweep_q[..] == y[l.q()] {
            self.evaluate_same_q(t, y)?;
            self.ws.same_q_evals += 1;
        } else {
            self.evaluate(t, y)?;
        }
        if self.hybrid.is_some() {
            if !self.hybrid_current_block() {
                return Ok(false);
            }
        } else {
            if !self.constrained_inverse_inertia(t)? {
                return Ok(false);
            }
            let js = &mut self.ws.jac;
            for c in 0..nv {
                for r in 0..nv {
                    js.cur.q[c * nv + r] = js.minv[(r, c)] * self.ws.drives.km[c];
                }
            }
        }
        self.write_current_columns(y, jac);
        Ok(true)
    }

    /// Q and Λ of a run with contact modes, from the evaluation in the workspace, into
    /// `ws.jac.cur`; false at the states the module docs list.
    fn hybrid_current_block(&mut self) -> bool {
        let nv = self.layout.nv;
        let Some(h) = &self.hybrid else { return false };
        let (cd, state) = (&h.cd, &h.state);
        for (k, c) in h.contacts.iter().enumerate() {
            if state.onset[k].is_some() && state.mode[k] == ContactMode::Sliding && c.unilateral_friction() > 0.0 {
                return false;
            }
        }
        let (rows, active) = (&cd.rows, &cd.active[..]);
        let m = active.len();
        // the recorded forces must be λ's image (forces_of in contact/forward.rs), else a
        // margin rule chose them
        let lam = &cd.scratch.lambda;
        for (k, c) in h.contacts.iter().enumerate() {
            if matches!(c.model, ContactModel::Compliant { .. }) {
                continue;
            }
            let (mut f_n, mut f_t) = (0.0, [0.0; 2]);
            for (i, ar) in active.iter().enumerate().filter(|(_, a)| a.row / 3 == k) {
                match (ar.row % 3, ar.force) {
                    (0, RowForce::Same) => f_n = lam[i],
                    (0, RowForce::Sliding { mu, s }) => {
                        f_n = lam[i];
                        f_t = [-mu * lam[i] * s[0], -mu * lam[i] * s[1]];
                    }
                    (a, _) => f_t[a - 1] = lam[i],
                }
            }
            if f_n.to_bits() != cd.f_n[k].to_bits() || f_t[0].to_bits() != cd.f_t[k][0].to_bits() || f_t[1].to_bits() != cd.f_t[k][1].to_bits() {
                return false;
            }
        }
        let (l_fac, inv) = (self.ws.fd.m_j.as_slice(), &self.ws.fd.l_inv_diag[..]);
        let km = &self.ws.drives.km;
        let s = &mut self.ws.jac.cur;
        // U = M_J⁻¹ K_m, column by column (into q, completed below)
        for c in 0..nv {
            let u = &mut s.q[c * nv..(c + 1) * nv];
            u.fill(0.0);
            u[c] = km[c];
            solve_mj(l_fac, inv, nv, u);
        }
        if m == 0 {
            return true;
        }
        // X = M_J⁻¹ Ŵᵀ, A = W X, and the right-hand sides −W U
        for (k, ar) in active.iter().enumerate() {
            let x = &mut s.x[k * nv..(k + 1) * nv];
            x.copy_from_slice(rows.row(ar.row));
            if let RowForce::Sliding { mu, s: dir } = ar.force {
                let c = ar.row / 3;
                for ((xj, t1), t2) in x.iter_mut().zip(rows.row(3 * c + 1)).zip(rows.row(3 * c + 2)) {
                    *xj -= mu * (dir[0] * t1 + dir[1] * t2);
                }
            }
            solve_mj(l_fac, inv, nv, x);
        }
        for (i, ai) in active.iter().enumerate() {
            for k in 0..m {
                s.a[i * m + k] = rows.dot(ai.row, &s.x[k * nv..(k + 1) * nv]);
            }
            for c in 0..nv {
                s.lam[c * m + i] = -rows.dot(ai.row, &s.q[c * nv..(c + 1) * nv]);
            }
        }
        // Λ = A⁻¹ (−W U): the force solve's LU with partial pivoting (`contact/solve.rs`),
        // factored with the first right-hand side and reused for the other nv − 1
        let (a, lam, piv) = (&mut s.a[..m * m], &mut s.lam[..m * nv], &mut s.piv[..m]);
        if lu_solve_in_place(a, m, piv, &mut lam[..m], 0.0).is_err() {
            return false;
        }
        let (piv_min, piv_max) = (0..m).map(|k| a[k * m + k].abs()).fold((f64::INFINITY, 0.0f64), |(lo, hi), p| (lo.min(p), hi.max(p)));
        if piv_min <= PIVOT_RATIO * piv_max {
            return false;
        }
        for c in 1..nv {
            lu_resolve(a, m, piv, &mut lam[c * m..(c + 1) * m]);
        }
        // Q = U + X Λ
        for c in 0..nv {
            for k in 0..m {
                let f = lam[c * m + k];
                let (q, x) = (&mut s.q[c * nv..(c + 1) * nv], &s.x[k * nv..(k + 1) * nv]);
                for (qr, xr) in q.iter_mut().zip(x) {
                    *qr += xr * f;
                }
            }
        }
        true
    }

    /// The current columns from Q (and Λ for the contacts' friction work) in `ws.jac.cur`, at
    /// the evaluation in the workspace (module docs).
    fn write_current_columns(&self, y: &[f64], jac: &mut [f64]) {
        let l = self.layout;
        let (nv, n) = (l.nv, l.dim());
        let d = &self.ws.drives;
        let (qd, cur) = (&y[l.qd()], &y[l.current()]);
        let s = &self.ws.jac.cur;
        for c in 0..nv {
            let col = l.current().start + c;
            for r in 0..n {
                jac[r * n + col] = 0.0;
            }
            let q = &s.q[c * nv..(c + 1) * nv];
            for r in 0..nv {
                jac[(l.qd().start + r) * n + col] = q[r];
                let dtau = (if r == c { d.km[c] } else { 0.0 }) - d.jm[r] * q[r];
                jac[(l.work().start + r) * n + col] = dtau * qd[r];
            }
            jac[(l.current().start + c) * n + col] = -d.r[c] / d.l[c];
            jac[(l.electric().start + c) * n + col] = self.ws.voltage[c];
            jac[l.loss_r() * n + col] = 2.0 * d.r[c] * cur[c];
            if let Some(k) = l.loss_conversion() {
                jac[k * n + col] = (d.ke[c] - d.km[c]) * qd[c];
            }
        }
        let Some(h) = &self.hybrid else { return };
        let (rows, active) = (&h.cd.rows, &h.cd.active);
        let m = active.len();
        for (i, ar) in active.iter().enumerate() {
            let k = ar.row / 3;
            if matches!(h.contacts[k].model, ContactModel::Compliant { .. }) {
                continue;
            }
            let v = rows.slip(k);
            // the friction force's change per ampere along this row's λ, dotted with v_t
            let per_lambda = match (ar.row % 3, ar.force) {
                (0, RowForce::Same) => 0.0,
                (0, RowForce::Sliding { mu, s }) => -mu * (s[0] * v[0] + s[1] * v[1]),
                (a, _) => v[a - 1],
            };
            if per_lambda == 0.0 {
                continue;
            }
            let row = l.friction_work(k);
            for c in 0..nv {
                jac[row * n + l.current().start + c] -= per_lambda * s.lam[c * m + i];
            }
        }
    }
}

/// Scratch of the exact current columns, sized once for nv joints and nc contacts (3 nc rows).
pub(super) struct CurrentColumnsScratch {
    /// `U = M_J⁻¹ K_m`, then `Q = ∂q̈/∂i` (column-major nv x nv).
    pub(super) q: Vec<f64>,
    /// `X = M_J⁻¹ Ŵᵀ` (column-major nv x 3 nc).
    pub(super) x: Vec<f64>,
    /// A and its LU (row-major, up to 3 nc x 3 nc).
    pub(super) a: Vec<f64>,
    /// `−W U`, then `Λ = ∂λ/∂i` (column-major m x nv, m the active rows).
    pub(super) lam: Vec<f64>,
    /// A's row interchanges.
    pub(super) piv: Vec<usize>,
}

impl CurrentColumnsScratch {
    pub(super) fn new(nv: usize, nc: usize) -> Self {
        let m = 3 * nc;
        Self { q: vec![0.0; nv * nv], x: vec![0.0; nv * m], a: vec![0.0; m * m], lam: vec![0.0; m * nv], piv: vec![0; m] }
    }
}
