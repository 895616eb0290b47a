//! What the stiff integrators need from the arm's ODE ([`ArmSystem`]):
//!
//! - [`OdeJacobian`]: a cheap structured approximation of ∂f/∂y that keeps exactly the stiff
//!   couplings — the PD voltage law into the armature circuit, the circuit's own `−R/L`, the
//!   back-EMF, and the motor torque through the constrained inverse inertia
//!   `M_c⁻¹ = M_J⁻¹ − M_J⁻¹ J_cᵀ (J_c M_J⁻¹ J_cᵀ)⁻¹ J_c M_J⁻¹` (frozen at the current q;
//!   Featherstone, RBDA §8.1): `∂q̇/∂q̇ = I`; `∂q̈/∂i = M_c⁻¹ K_m`; `∂q̈/∂q̇ = −M_c⁻¹ (D + D_m)`;
//!   `∂i̇/∂q = −k_p/L`, `∂i̇/∂q̇ = −(k_d + K_m)/L`, `∂i̇/∂i = −R/L`. With quasi-static motors
//!   (L = 0) the current is eliminated: `∂q̈/∂q = −M_c⁻¹ K_m k_p/R`,
//!   `∂q̈/∂q̇ = −M_c⁻¹ (K_m (k_d + K_m)/R + D + D_m)`. Coriolis, gravity stiffness and the
//!   quadrature rows are left out: a Rosenbrock-W method keeps its order with any bounded
//!   approximation (Hairer & Wanner, *Solving ODEs II*, §IV.7), and these terms are not stiff.
//!   With a back-EMF constant K_e ≠ K_t the back-EMF entries use K_e k; k_p, k_d (and an inner
//!   current loop's k_i, in `∂i̇/∂i = −(R + k_i)/L`) are the controller's diagonal
//!   linearisation (`Controller::linearized`: the PD gains for `pd` and `pd-gravity`, the
//!   model-scaled gains for computed torque); the drive's saturation, the feed-forward's slope
//!   and the soft stops' stiffness are left out (bounded, so the W-method keeps its order; the
//!   stops' k can make steps shorter while a joint is beyond its limit).
//!   With `gear_friction` a sliding gear's efficiency factor c multiplies K_m in `∂q̈/∂i` (and
//!   the quasi-static rows) and its Stribeck slope `s ∂τ_f/∂q̇` adds to the damping; a sticking
//!   joint's lock (`drive_modes.rs`) is left out (bounded, as the stops).
//!   `M_c⁻¹` is computed here from M and J_c of the evaluation, whatever constraint solver the
//!   scene uses (the Schur and the KKT solve leave different scratch behind). With the motors'
//!   thermal model (`dynamics/thermal.rs`) its rows are exact: `∂Ṫ_w/∂T_w = (±R' i²) / C_w −
//!   1 / (R_th1 C_w)`, `∂Ṫ_w/∂T_h = 1 / (R_th1 C_w)`, `∂Ṫ_h/∂T_w = 1 / (R_th1 C_h)`,
//!   `∂Ṫ_h/∂T_h = −(1/R_th1 + 1/R_th2) / C_h`, and the copper loss's `∂Ṫ_w/∂i = 2 R i / C_w`,
//!   `∂i̇/∂T_w = −R' i / L` (inductive) or through `i = (v − K_e k q̇)/R(T_w)` (L = 0).
//! - For the classical Rosenbrock methods (`Rodas`), which need the exact Jacobian:
//!   [`OdeJacobian::coupled_dim`] = the q, q̇, i block (the quadratures never feed back, so
//!   their columns are zero); the current columns exact (`current_columns.rs`,
//!   [`OdeJacobian::exact_columns`]) where the scene and the state allow, and the stepper
//!   differences the right-hand side over the q and q̇ columns (and the current ones where
//!   they are not exact), with the increment the arm's units and rounding noise call for
//!   ([`OdeJacobian::difference_increment`]).
//! - [`SplitSystem`]: the armature circuit `L di/dt = v − R i − K_e k q̇` (K_e k = K_m unless
//!   the scene gives `back_emf_constant`) is linear in i with a diagonal matrix, so its implicit
//!   stage equation `z − γ f_I(z) = r` has the closed form
//!   `z_i = (r_i + γ (v − K_e k q̇)/L) / (1 + γ R/L)` (v and q̇ from the explicit components of r),
//!   for an IMEX Runge–Kutta method (Ascher, Ruuth & Spiteri 1997; Kennedy & Carpenter 2003).

use nalgebra::{Cholesky, DMatrix};

use crate::dynamics::forward::schur_complement;
use crate::dynamics::motor::Electrical;
use crate::dynamics::spd::solve_regularized;
use crate::error::{DynamicsError, RunError};
use crate::integrate::{OdeJacobian, OdeSystem, SplitSystem};

use super::arm::ArmSystem;

impl ArmSystem<'_> {
    /// `M_c⁻¹` at the state of the last evaluation (M in `data.m`, J_c in `fd.jac`), into the
    /// Jacobian scratch. False when the constraints' A could not be solved and the unconstrained
    /// `M_J⁻¹` was left there: an approximation the W-methods allow, not an exact column.
    pub(super) fn constrained_inverse_inertia(&mut self, t: f64) -> Result<bool, RunError> {
        let nv = self.layout.nv;
        // a hybrid run's rows depend on its modes and are not in fd.jac: the unconstrained
        // M_J⁻¹ there (a bounded approximation, which the W-methods allow; the classical
        // Rosenbrock methods difference f instead)
        let nc = if self.hybrid.is_some() { 0 } else { self.contacts.len() };
        let d = &self.ws.drives;
        let (data, fd, js) = (&self.ws.data, &self.ws.fd, &mut self.ws.jac);
        js.m_j.copy_from(&data.m);
        for j in 0..nv {
            js.m_j[(j, j)] += d.jm[j];
        }
        // factor in place: the storage moves into the factor and back, no allocation
        let m = std::mem::replace(&mut js.m_j, DMatrix::zeros(0, 0));
        let Some(chol) = Cholesky::new(m) else {
            js.m_j = DMatrix::zeros(nv, nv);
            return Err(DynamicsError::SingularMassMatrix { t }.into());
        };
        js.minv.fill_with_identity();
        chol.solve_mut(&mut js.minv);
        let mut constrained = true;
        if nc > 0 {
            // Y = M_J⁻¹ J_cᵀ, A = J_c Y, then M_c⁻¹ = M_J⁻¹ − Y A⁻¹ Yᵀ (A regularised like the
            // force solve, dynamics/spd.rs)
            schur_complement(&chol, &fd.jac, &mut js.y, &mut js.a);
            js.ayt.tr_copy_from(&js.y);
            constrained = solve_regularized(&js.a, &mut js.a_factor, &mut js.ayt).is_some();
            if constrained {
                js.minv.gemm(-1.0, &js.y, &js.ayt, 1.0);
            }
        }
        js.m_j = chol.unpack_dirty();
        Ok(constrained)
    }
}

impl OdeJacobian for ArmSystem<'_> {
    /// The structured Jacobian above is an approximation (no Coriolis, no gravity stiffness):
    /// the classical Rosenbrock methods difference `f` over the coupled columns instead.
    fn exact_jacobian(&mut self, _t: f64, _y: &[f64], _fy: &[f64], _jac: &mut [f64]) -> Result<bool, RunError> {
        Ok(false)
    }

    /// q, q̇ and the currents; the quadratures W, E, E_R, E_D, E_Dm never enter the
    /// right-hand side.
    fn coupled_dim(&self) -> usize {
        self.layout.work().start
    }

    /// The increment RODAS differences `f` with: `3.2e-7 max(|y_j|, 1)`. The components are in
    /// SI units of natural size 1 (rad, rad/s, A; m for a prismatic joint; °C, larger), not
    /// `atol / rtol` (1e-2 at the usual tolerances: an angle or a speed at 0 got an increment
    /// of 1.5e-10); and q̈, summed from the RNEA, the CRBA, a Cholesky solve and the
    /// constraint and gear solves, carries a rounding noise up to ~2e-14 of the largest |q̈|
    /// (measured on the paper arm with every drive feature, the 6th differences of f along
    /// each coupled component, Moré & Wild 2012), so `noise = 1e-13` leaves a margin of 5.
    /// With `sqrt(eps) · max(|y_j|, 1e-2)` the difference Jacobian's rounding error, up to 1e-4
    /// of a row, cost RODAS4 its order with gear friction on (error ∝ rtol^0.55 over
    /// 1e-6 … 1e-9, `drive_features.rs`) and RODAS5P on the paper arm with gears (rtol^0.76).
    /// Not in a run with contact modes (`None`: the stepper's `sqrt(eps) max(|y_j|, atol /
    /// rtol)`): a sliding contact's friction direction blends over tangential speeds below
    /// 1e-6 m/s (`dynamics/contact/forward.rs`), a feature of f far below the SI scale that an
    /// increment of 3.2e-7 rad/s would straddle.
    fn difference_increment(&self) -> Option<crate::integrate::DifferenceIncrement> {
        self.hybrid.is_none().then_some(crate::integrate::DifferenceIncrement { noise: 1e-13, floor: 1.0 })
    }

    /// The current columns, exact where `current_columns.rs` says; the q and q̇ columns by
    /// differences.
    fn exact_columns_start(&self) -> usize {
        if self.has_exact_current_columns() {
            self.layout.current().start
        } else {
            self.coupled_dim()
        }
    }

    fn exact_columns(&mut self, t: f64, y: &[f64], _fy: &[f64], jac: &mut [f64]) -> Result<bool, RunError> {
        self.exact_current_columns(t, y, jac)
    }

    /// One: the evaluation of f at `(t, y)` that `current_columns.rs` makes (a hybrid run's
    /// same-q re-solve, as a difference column after the sweep's first q̇ one, which counts
    /// one too), made whether the columns are written or declined.
    fn exact_columns_rhs_evals(&self) -> u64 {
        1
    }

    /// `time_derivative.rs`.
    fn exact_time_derivative(&mut self, t: f64, y: &[f64], _fy: &[f64], dfdt: &mut [f64]) -> Result<bool, RunError> {
        self.exact_time_derivative_at(t, y, dfdt)
    }

    fn jacobian(&mut self, t: f64, y: &[f64], _fy: &[f64], jac: &mut [f64]) -> Result<(), RunError> {
        // the dynamics at (t, y): M and J_c are left in the workspace
        let mut f = std::mem::take(&mut self.ws.jac.f);
        let r = self.rhs(t, y, &mut f);
        self.ws.jac.f = f;
        r?;
        // M_J⁻¹ where A is not solved: the approximation the W-methods allow (module docs)
        self.constrained_inverse_inertia(t)?;
        let l = self.layout;
        let (nv, dim) = (l.nv, l.dim());
        let scene = self.scene;
        let d = &self.ws.drives;
        let inductive = l.electrical == Electrical::Inductive;
        // the law's diagonal linearisation (k_p', k_d', k_i'): the PD gains for the paper
        let lin = &mut self.ws.jac.lin;
        for j in 0..nv {
            lin[j] = scene.controller.linearized(d, j, self.ws.data.m[(j, j)] + d.jm[j], inductive);
        }
        let lin = &self.ws.jac.lin;
        jac.fill(0.0);
        let mut set = |row: usize, col: usize, v: f64| jac[row * dim + col] = v;
        for j in 0..nv {
            set(l.q().start + j, l.qd().start + j, 1.0);
        }
        let minv = &self.ws.jac.minv;
        for r in 0..nv {
            for c in 0..nv {
                let m = minv[(r, c)];
                // a sliding gear's efficiency factor on K_m and its Stribeck slope (1 and 0
                // without `gear_friction`; `drive_modes.rs`)
                let (eff, slope) = self.gear_jacobian_terms(c, y[l.qd().start + c]);
                let km = eff * d.km[c];
                match l.electrical {
                    Electrical::Inductive => {
                        set(l.qd().start + r, l.current().start + c, m * km);
                        set(l.qd().start + r, l.qd().start + c, -m * (d.d[c] + d.dm[c] + slope));
                    }
                    Electrical::QuasiStatic => {
                        let (kp, kd, _) = lin[c];
                        set(l.qd().start + r, l.q().start + c, -m * km * kp / d.r[c]);
                        set(l.qd().start + r, l.qd().start + c, -m * (km * (kd + d.ke[c]) / d.r[c] + d.d[c] + d.dm[c] + slope));
                    }
                }
            }
        }
        if l.electrical == Electrical::Inductive {
            for j in 0..nv {
                let row = l.current().start + j;
                let (kp, kd, ki) = lin[j];
                set(row, l.q().start + j, -kp / d.l[j]);
                set(row, l.qd().start + j, -(kd + d.ke[j]) / d.l[j]);
                if ki == 0.0 {
                    set(row, l.current().start + j, -d.r[j] / d.l[j]);
                } else {
                    set(row, l.current().start + j, -(d.r[j] + ki) / d.l[j]);
                }
            }
        }
        if let Some(th) = &scene.thermal {
            // the two-node networks and R(T_w) (`dynamics/thermal.rs`), exactly: the copper
            // loss P = R(T_w) i² into the winding, R(T_w) into eq 11 (inductive) or into the
            // algebraic current i = (v − K_e k q̇) / R(T_w) (quasi-static)
            let cur = super::arm::currents_in(&l, y, &self.ws.current_qs);
            for j in 0..nv {
                let Some(p) = &th.params[j] else { continue };
                let (tw, thj) = (l.winding_temperature().start + j, l.housing_temperature().start + j);
                let (cw, ch, r1, r2) = (p.c_winding(), p.c_housing(), p.r_winding_housing, p.r_housing_ambient);
                let (r, dr, i) = (d.r[j], th.resistance_slope(j), cur[j]);
                set(tw, thj, 1.0 / (r1 * cw));
                set(thj, tw, 1.0 / (r1 * ch));
                set(thj, thj, -(1.0 / r1 + 1.0 / r2) / ch);
                match l.electrical {
                    Electrical::Inductive => {
                        set(tw, tw, dr * i * i / cw - 1.0 / (r1 * cw));
                        set(tw, l.current().start + j, 2.0 * r * i / cw);
                        set(l.current().start + j, tw, -dr * i / d.l[j]);
                    }
                    Electrical::QuasiStatic => {
                        // ∂P/∂T_w = −R' i², ∂P/∂q = −2 i k_p, ∂P/∂q̇ = −2 i (k_d + K_e k)
                        let (kp, kd, _) = lin[j];
                        set(tw, tw, -dr * i * i / cw - 1.0 / (r1 * cw));
                        set(tw, l.q().start + j, -2.0 * i * kp / cw);
                        set(tw, l.qd().start + j, -2.0 * i * (kd + d.ke[j]) / cw);
                        // ∂q̈/∂T_w = M_c⁻¹ K_m ∂i/∂T_w, ∂i/∂T_w = −i R' / R
                        for r_ in 0..nv {
                            set(l.qd().start + r_, tw, -minv[(r_, j)] * d.km[j] * i * dr / r);
                        }
                    }
                }
            }
        }
        Ok(())
    }
}

impl SplitSystem for ArmSystem<'_> {
    fn rhs_split(&mut self, t: f64, y: &[f64], f_e: &mut [f64], f_i: &mut [f64]) -> Result<(), RunError> {
        self.rhs(t, y, f_e)?;
        f_i.fill(0.0);
        for k in self.layout.current() {
            f_i[k] = f_e[k];
            f_e[k] = 0.0;
        }
        Ok(())
    }

    fn solve_implicit(&mut self, t: f64, gamma: f64, r: &[f64], z: &mut [f64]) -> Result<(), RunError> {
        z.copy_from_slice(r);
        let l = self.layout;
        if l.electrical == Electrical::QuasiStatic {
            return Ok(());
        }
        // v(t, q, q̇) from the explicit components, then the closed form per motor
        // (a law with a current loop is rejected with imex when the scene is built)
        self.set_resistance(r);
        self.voltage_at(t, &r[l.q()], &r[l.qd()], Some(&r[l.current()]))?;
        let (d, voltage) = (&self.ws.drives, &self.ws.voltage);
        for j in 0..l.nv {
            let k = l.current().start + j;
            let qd = r[l.qd().start + j];
            z[k] = (r[k] + gamma * (voltage[j] - d.ke[j] * qd) / d.l[j]) / (1.0 + gamma * d.r[j] / d.l[j]);
        }
        Ok(())
    }
}
