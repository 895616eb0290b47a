//! The exact `∂f/∂t` of the arm's right-hand side, for the classical Rosenbrock methods
//! (`integrate/rodas.rs`, [`crate::integrate::OdeJacobian::exact_time_derivative`]), which need
//! it exact (HNW II §IV.7, (7.4)): instead of a difference in t, one right-hand side a step
//! (issue 24, point 1).
//!
//! At fixed y, f depends on t only through the controller's voltage v(t, q, q̇), which reads
//! the target's `q_d(t)`, `q̇_d(t)`: eq 11 `di/dt = (v − R i − K_e k q̇)/L` and the electric
//! energy's rate `i v`; eq 21's q̈ reads the currents, not v, for inductive motors, and nothing
//! else in f reads t (the contacts' planes and the stops are fixed). So `∂(di_j/dt)/∂t =
//! (∂v_j/∂t)/L_j`, `∂(i_j v_j)/∂t = i_j ∂v_j/∂t`, every other component 0, with, for eq 27's
//! `v = k_p (q_d − q) + k_d (q̇_d − q̇)` (`control/pd.rs`), `∂v_j/∂t = k_p q̇_d,j + k_d q̈_d,j`,
//! and for `pd-gravity` (`control/controller.rs`) also its feed-forward's
//! `K_e k q̈_d,j` (+ `R/K_m (D + D_m) q̈_d,j` with `friction`); a passive joint's v is 0.
//! `q̈_d` is the target's own (the closed-form IK's, `control/target.rs`, or the spline's).
//!
//! None (the stepper differences in t) with quasi-static motors (v enters q̈ through
//! `i = (v − K_e k q̇)/R`), computed torque (v reads `q̈_d`, whose derivative the targets do not
//! give), drive limits (the window clips v), gear friction and a supply (`drive_modes.rs`), or a
//! target whose `q̈_d` fails at t (the paper's at a singular J₃: the difference never asks for it).
//! Checked against central differences in t at random states (`sim/tests/current_columns.rs`;
//! with pd-gravity's feed-forward, with and without friction, and K_e ≠ K_m:
//! `sim/tests/current_columns_cases.rs`).

use crate::control::Law;
use crate::dynamics::motor::Electrical;
use crate::error::RunError;

use super::arm::ArmSystem;

impl ArmSystem<'_> {
    /// `∂f/∂t (t, y)` into `dfdt` (module docs), or `Ok(false)` without writing.
    #[allow(clippy::result_large_err)] // RunError, as every evaluation of the arm
    pub(super) fn exact_time_derivative_at(&mut self, t: f64, y: &[f64], dfdt: &mut [f64]) -> Result<bool, RunError> {
        let s = self.scene;
        let l = self.layout;
        let friction = match s.controller.law {
            Law::Pd => None,
            Law::PdGravity { friction } => Some(friction),
            Law::ComputedTorque { .. } => return Ok(false),
        };
        if l.electrical != Electrical::Inductive || s.drives.has_limits || self.drive_modes.is_some() {
            return Ok(false);
        }
        let ws = &mut self.ws;
        let js = &mut ws.jac;
        // a target whose q̈_d is not to be had here (the paper's at a singular J₃) leaves ∂f/∂t
        // to the difference, which never asks for q̈_d: the exact one adds no way for a run to fail
        if s.target.eval(t, &s.model, &s.hand, &mut ws.target, &mut js.q_d, &mut js.qd_d, Some(&mut js.qdd_d[..])).is_err() {
            return Ok(false);
        }
        let (g, d) = (&s.controller.gains, &s.drives);
        dfdt.fill(0.0);
        let cur = &y[l.current()];
        for j in 0..l.nv {
            if d.passive[j] {
                continue;
            }
            let mut dv = g.kp[j] * js.qd_d[j] + g.kd[j] * js.qdd_d[j];
            if let Some(friction) = friction {
                dv += d.ke[j] * js.qdd_d[j];
                if friction {
                    dv += d.r[j] / d.km[j] * (d.d[j] + d.dm[j]) * js.qdd_d[j];
                }
            }
            dfdt[l.current().start + j] = dv / ws.drives.l[j];
            dfdt[l.electric().start + j] = cur[j] * dv;
        }
        Ok(true)
    }
}
