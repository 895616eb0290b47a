//! [`Outputs`]: everything recorded at one output time, computed from (t, y) by the same
//! evaluation as the right-hand side.

use nalgebra::Vector3;

use crate::dynamics::energy::{magnetic_energy, potential_energy, rotor_kinetic_energy};
use crate::dynamics::kinematics::{forward_kinematics, forward_velocities};
use crate::error::DynamicsError;

use super::arm::ArmSystem;

/// Everything recorded at one output time, computed from (t, y).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Outputs {
    pub t: f64,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    pub current: Vec<f64>,
    pub voltage: Vec<f64>,
    pub back_emf: Vec<f64>,
    pub electric_power: Vec<f64>,
    pub tau_motor: Vec<f64>,
    pub normal_force: Vec<f64>,
    pub constraint_position: Vec<f64>,
    pub constraint_velocity: Vec<f64>,
    pub hand: Vector3<f64>,
    pub hand_desired: Vector3<f64>,
    pub link_work: Vec<f64>,
    pub electric_energy: Vec<f64>,
    pub kinetic: f64,
    pub potential: f64,
    pub magnetic: f64,
    pub loss_resistance: f64,
    /// `∫ Σ (D + D_m) q̇² dt`, J.
    pub loss_friction: f64,
    /// Its gear part `∫ Σ D_m q̇² dt`, J.
    pub loss_gear_friction: f64,
    /// `Σ E_j − (ΔT + ΔV + ΔE_L + E_R + E_D + E_Dm)`, J.
    pub balance_residual: f64,
}

fn set(dst: &mut Vec<f64>, src: &[f64]) {
    dst.clear();
    dst.extend_from_slice(src);
}

impl ArmSystem<'_> {
    /// Everything recorded at (t, y), written into `out` (whose vectors are reused).
    pub fn outputs(&mut self, t: f64, y: &[f64], out: &mut Outputs) -> Result<(), DynamicsError> {
        self.evaluate(t, y)?;
        let l = self.layout;
        let s = self.scene;
        let d = &s.drives;
        let (q, qd) = (&y[l.q()], &y[l.qd()]);
        let cur = self.currents(y);
        let (fd, voltage) = (&self.ws.fd, &self.ws.voltage);
        out.t = t;
        set(&mut out.q, q);
        set(&mut out.qd, qd);
        set(&mut out.qdd, fd.qdd.as_slice());
        set(&mut out.current, cur);
        set(&mut out.voltage, voltage);
        out.back_emf.clear();
        out.back_emf.extend((0..l.nv).map(|j| d.back_emf(j, qd[j])));
        out.electric_power.clear();
        out.electric_power.extend((0..l.nv).map(|j| cur[j] * voltage[j]));
        set(&mut out.tau_motor, fd.tau_motor.as_slice());
        set(&mut out.normal_force, fd.f_n.as_slice());
        set(&mut out.link_work, &y[l.work()]);
        set(&mut out.electric_energy, &y[l.electric()]);
        out.loss_resistance = y[l.loss_r()];
        out.loss_friction = y[l.loss_d()] + y[l.loss_dm()];
        out.loss_gear_friction = y[l.loss_dm()];
        out.magnetic = magnetic_energy(d, cur);
        // ½ q̇ᵀ M q̇ from the mass matrix of this evaluation (valid for CRBA and Walker–Orin)
        let data = &mut self.ws.data;
        let m_qd: f64 = (0..l.nv).map(|r| qd[r] * (0..l.nv).map(|c| data.m[(r, c)] * qd[c]).sum::<f64>()).sum();
        out.kinetic = 0.5 * m_qd + rotor_kinetic_energy(d, qd);
        // kinematics at this state (the dynamics left body velocities of RNEA in `data`)
        forward_kinematics(&s.model, data, q);
        forward_velocities(&s.model, data, qd);
        out.potential = potential_energy(&s.model, data);
        out.hand = s.hand.position(data);
        out.hand_desired = s.circle.position(t);
        out.constraint_position.clear();
        out.constraint_position.extend(self.contacts.iter().map(|c| c.position(data)));
        out.constraint_velocity.clear();
        out.constraint_velocity.extend(self.contacts.iter().map(|c| c.velocity(data)));
        let electric: f64 = out.electric_energy.iter().sum();
        out.balance_residual = electric
            - (out.kinetic + out.potential + out.magnetic - self.stored0 + out.loss_resistance + out.loss_friction);
        Ok(())
    }
}
