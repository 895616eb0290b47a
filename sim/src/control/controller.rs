//! The joint controllers a scene chooses (`"controller": {"law": ...}`), each a voltage law for
//! the DC motors of `dynamics/motor.rs`, with gains per joint. Errors `e = q_d − q`,
//! `ė = q̇_d − q̇`; K_m = K_t k, K_e k, R, J_m, D_m and the joints' D are the drive constants
//! reflected to the link side (eqs 9–12 of the paper). Passive joints get no voltage.
//!
//! - `pd` (the paper's eq 27, the default when `law` is absent): `v = k_p e + k_d ė`, k_p in
//!   V/rad, k_d in V s/rad. The same arithmetic as [`PdGains::voltage`].
//! - `pd-gravity`: PD plus a model feed-forward, the voltage that makes the motor deliver the
//!   gravity torque G(q) at the measured q (Takegaki & Arimoto, "A new feedback method for
//!   dynamic control of manipulators", *J. Dyn. Syst. Meas. Control* 103, 1981; Spong,
//!   Hutchinson & Vidyasagar, *Robot Modeling and Control*, §8.4, "PD control with gravity
//!   compensation") and that cancels the back EMF of the desired motion:
//!   `v = k_p e + k_d ė + (R / K_m) (G(q) + [D + D_m] q̇_d) + K_e k q̇_d`, the bracket only with
//!   `"friction": true`. G(q) is RNEA at (q, q̇ = 0, q̈ = 0). At rest at q = q_d the current is
//!   `G / K_m` exactly (quasi-static motors, or inductive ones in steady state), so a static pose
//!   is held with zero error — the PD alone settles at `e = R G / (K_m k_p)`.
//! - `computed-torque` with an inner current loop (Spong, Hutchinson & Vidyasagar, §8.3, inverse
//!   dynamics control; the motor and its current loop: Siciliano, Sciavicco, Villani & Oriolo,
//!   *Robotics*, §8.5): the outer loop asks for the joint acceleration
//!   `a = q̈_d + k_p e + k_d ė` (k_p in 1/s², k_d in 1/s; critically damped at k_d = 2 √k_p), the
//!   model turns it into the torque the motor must deliver, `τ* = (M(q) + J_m) a + h(q, q̇) +
//!   G(q) + (D + D_m) q̇` (RNEA at (q, q̇, a) plus the drive terms of eq 12), i.e. the current
//!   `i* = τ* / K_m`, and the inner loop sets `v = R i* + K_e k q̇ + k_i (i* − i)` (k_i in V/A,
//!   ohm), or `v = R i* + K_e k q̇` for quasi-static motors (then i = i* exactly). With an exact
//!   model, no contact force, no saturation and quasi-static motors the error obeys
//!   `ë + k_d ė + k_p e = 0`; with inductive motors the lag `L di/dt` is not fed forward (the
//!   current loop k_i shortens it: the current error decays at the rate (R + k_i)/L). Passive
//!   joints are not driven, so with one the arm is underactuated and tracking is not promised.
//!
//! The controller works in the workspace's scratch ([`ControllerScratch`]): no allocation per
//! evaluation.

use nalgebra::DVector;

use crate::dynamics::motor::Drives;
use crate::dynamics::rnea::rnea;
use crate::dynamics::{Data, Model};

use super::pd::PdGains;

/// Which law, with its law-specific settings (the gains are in [`Controller`]).
#[derive(Clone, Debug, PartialEq)]
pub enum Law {
    /// Eq 27.
    Pd,
    /// PD + gravity (and with `friction`, viscous friction) feed-forward.
    PdGravity { friction: bool },
    /// Computed torque; `current_gain` k_i per joint, V/A.
    ComputedTorque { current_gain: DVector<f64> },
}

impl Law {
    /// The law's name as written in a scene.
    pub fn name(&self) -> &'static str {
        match self {
            Law::Pd => "pd",
            Law::PdGravity { .. } => "pd-gravity",
            Law::ComputedTorque { .. } => "computed-torque",
        }
    }
}

/// A validated controller: its law and its gains per joint (units per law: module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Controller {
    pub law: Law,
    pub gains: PdGains,
}

/// The controller's scratch (nv each), sized once.
#[derive(Clone, Debug)]
pub struct ControllerScratch {
    zeros: Vec<f64>,
    accel: Vec<f64>,
}

impl ControllerScratch {
    pub fn new(nv: usize) -> Self {
        Self { zeros: vec![0.0; nv], accel: vec![0.0; nv] }
    }
}

/// What one evaluation of the law reads.
pub struct ControlInput<'a> {
    pub q: &'a [f64],
    pub qd: &'a [f64],
    /// The motor currents (inductive motors), for the inner current loop; `None` for quasi-static.
    pub current: Option<&'a [f64]>,
    pub q_des: &'a [f64],
    pub qd_des: &'a [f64],
    pub qdd_des: &'a [f64],
}

impl Controller {
    /// The paper's PD law (eq 27) with these gains.
    pub fn pd(gains: PdGains) -> Self {
        Self { law: Law::Pd, gains }
    }

    /// Whether the law reads the motor currents (then the voltage depends on i).
    pub fn reads_current(&self) -> bool {
        matches!(&self.law, Law::ComputedTorque { current_gain } if current_gain.iter().any(|&k| k != 0.0))
    }

    /// The commanded voltages (nv), V, into `voltage`. `data` is clobbered (RNEA).
    pub fn voltage(
        &self,
        model: &Model,
        drives: &Drives,
        data: &mut Data,
        scratch: &mut ControllerScratch,
        x: &ControlInput,
        voltage: &mut [f64],
    ) {
        let g = &self.gains;
        match &self.law {
            Law::Pd => g.voltage(x.q, x.qd, x.q_des, x.qd_des, voltage),
            Law::PdGravity { friction } => {
                g.voltage(x.q, x.qd, x.q_des, x.qd_des, voltage);
                let grav = rnea(model, data, x.q, &scratch.zeros, &scratch.zeros, &model.gravity);
                for j in 0..voltage.len() {
                    if drives.passive[j] {
                        continue;
                    }
                    let mut tau = grav[j];
                    if *friction {
                        tau += (drives.d[j] + drives.dm[j]) * x.qd_des[j];
                    }
                    voltage[j] += drives.r[j] / drives.km[j] * tau + drives.ke[j] * x.qd_des[j];
                }
            }
            Law::ComputedTorque { current_gain } => {
                for j in 0..voltage.len() {
                    scratch.accel[j] = x.qdd_des[j] + g.kp[j] * (x.q_des[j] - x.q[j]) + g.kd[j] * (x.qd_des[j] - x.qd[j]);
                }
                let tau = rnea(model, data, x.q, x.qd, &scratch.accel, &model.gravity);
                for j in 0..voltage.len() {
                    if drives.passive[j] {
                        continue;
                    }
                    let tau_star = tau[j] + drives.jm[j] * scratch.accel[j] + (drives.d[j] + drives.dm[j]) * x.qd[j];
                    let i_star = tau_star / drives.km[j];
                    let mut v = drives.r[j] * i_star + drives.ke[j] * x.qd[j];
                    if let Some(i) = x.current {
                        v += current_gain[j] * (i_star - i[j]);
                    }
                    voltage[j] = v;
                }
            }
        }
        for j in 0..voltage.len() {
            if drives.passive[j] {
                voltage[j] = 0.0;
            }
        }
    }

    /// Diagonal linearisation of the law for the stiff methods' structured Jacobian
    /// (`ode/jacobian.rs`): `(k_p', k_d', k_i')` with `∂v_j/∂q_j ≈ −k_p'`, `∂v_j/∂q̇_j ≈ −k_d'`,
    /// `∂v_j/∂i_j = −k_i'`, V/rad, V s/rad, V/A. `m_jj` is the diagonal of M + J_m. For `pd`
    /// and `pd-gravity` the PD gains (the feed-forward's slope in q is left out); for computed
    /// torque `c M_jj k_p`, `c M_jj k_d − c (D + D_m) − K_e k` and k_i, `c = (R + k_i) / K_m`
    /// (k_i = 0 for quasi-static motors, `inductive` false). An approximation, as the module
    /// docs of `ode/jacobian.rs` allow (saturation is left out).
    pub fn linearized(&self, drives: &Drives, j: usize, m_jj: f64, inductive: bool) -> (f64, f64, f64) {
        let g = &self.gains;
        if drives.passive[j] {
            return (0.0, 0.0, 0.0);
        }
        match &self.law {
            Law::Pd | Law::PdGravity { .. } => (g.kp[j], g.kd[j], 0.0),
            Law::ComputedTorque { current_gain } => {
                let ki = if inductive { current_gain[j] } else { 0.0 };
                let c = (drives.r[j] + ki) / drives.km[j];
                (c * m_jj * g.kp[j], c * m_jj * g.kd[j] - c * (drives.d[j] + drives.dm[j]) - drives.ke[j], ki)
            }
        }
    }
}
