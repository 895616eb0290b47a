//! The ODE of one run: the state layout, the right-hand side (eq 21 with the PD law of eq 27
//! and the IK targets of eqs 28–29), and the derived outputs recorded at each sample.
//!
//! State `y` (all that is integrated, nothing else), with n = nv:
//! `[ q (n) | q̇ (n) | i (n) | W (n) | E (n) | E_R | E_D | E_Dm ]` where the currents i are
//! present only when the motors have inductance (L = 0: quasi-static current, no electrical
//! state), and `W_j = ∫ τ_j q̇_j dt` (work of motor j on link j, τ of eq 12), `E_j = ∫ i_j v_j dt`
//! (electric energy into motor j), `E_R = ∫ Σ R i² dt`, `E_D = ∫ Σ D q̇² dt` (the joints' viscous
//! friction) and `E_Dm = ∫ Σ D_m q̇² dt` (the gears', eq 12's d_m term) (losses). The quadratures
//! ride along with the dynamics so that they are integrated to the same accuracy.
//!
//! Energy balance (SCENE.md; ideal constraints do no work):
//! `Σ E_j = ΔT + ΔV + Δ(½ Σ L i²) + E_R + E_D + E_Dm`, T including the rotors' `½ Σ J_m q̇²`.
//! Its residual measures the integration error (and constraint drift, which lets f_n work).

use nalgebra::Vector3;

use crate::dynamics::constraints::PointOnPlane;
use crate::dynamics::energy::{link_kinetic_energy, magnetic_energy, potential_energy, rotor_kinetic_energy};
use crate::dynamics::forward::{forward_dynamics, ForwardData, Plant};
use crate::dynamics::kinematics::{forward_kinematics, forward_velocities};
use crate::dynamics::Data;
use crate::error::{DynamicsError, RunError};
use crate::integrate::OdeSystem;
use crate::scene::{Run, Scene};

/// Index ranges of the state vector.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    pub nv: usize,
    /// Number of electrical states: nv, or 0 for quasi-static motors.
    pub ni: usize,
}

impl Layout {
    pub fn dim(&self) -> usize {
        4 * self.nv + self.ni + 3
    }
    pub fn q(&self) -> std::ops::Range<usize> {
        0..self.nv
    }
    pub fn qd(&self) -> std::ops::Range<usize> {
        self.nv..2 * self.nv
    }
    /// The currents; empty for quasi-static motors.
    pub fn current(&self) -> std::ops::Range<usize> {
        2 * self.nv..2 * self.nv + self.ni
    }
    pub fn work(&self) -> std::ops::Range<usize> {
        let s = 2 * self.nv + self.ni;
        s..s + self.nv
    }
    pub fn electric(&self) -> std::ops::Range<usize> {
        let s = 3 * self.nv + self.ni;
        s..s + self.nv
    }
    pub fn loss_r(&self) -> usize {
        4 * self.nv + self.ni
    }
    /// `∫ Σ D_j q̇_j² dt`: the joints' own viscous friction.
    pub fn loss_d(&self) -> usize {
        4 * self.nv + self.ni + 1
    }
    /// `∫ Σ D_m,j q̇_j² dt`: the gears' viscous friction, seen at the joint.
    pub fn loss_dm(&self) -> usize {
        4 * self.nv + self.ni + 2
    }
    /// A readable name of state component `k`, for error messages.
    pub fn name(&self, k: usize, joints: &[String]) -> String {
        let within = |r: std::ops::Range<usize>| r.contains(&k).then(|| joints[k - r.start].clone());
        if let Some(j) = within(self.q()) {
            format!("q of {j}")
        } else if let Some(j) = within(self.qd()) {
            format!("q' of {j}")
        } else if let Some(j) = within(self.current()) {
            format!("current of {j}")
        } else if let Some(j) = within(self.work()) {
            format!("link work of {j}")
        } else if let Some(j) = within(self.electric()) {
            format!("electric energy of {j}")
        } else if k == self.loss_r() {
            "resistive loss".into()
        } else if k == self.loss_d() {
            "joint friction loss".into()
        } else {
            "gear friction loss".into()
        }
    }
}

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

/// One run of a scene as an [`OdeSystem`]. Holds the scratch; the scene is read-only.
pub struct ArmSystem<'a> {
    pub scene: &'a Scene,
    pub contacts: Vec<PointOnPlane>,
    pub layout: Layout,
    pub data: Data,
    pub fd: ForwardData,
    q_des: Vec<f64>,
    qd_des: Vec<f64>,
    pub(crate) voltage: Vec<f64>,
    /// Currents of quasi-static motors (computed, not integrated), A.
    current_qs: Vec<f64>,
    /// Scratch of the structured Jacobian (`stiff.rs`).
    pub(crate) jac: crate::stiff::JacobianScratch,
    /// Scratch of the constraint projection (`projection.rs`).
    pub(crate) projection: crate::projection::ProjectionScratch,
    /// T + V + ½ L i² at t = 0, J (for the balance residual).
    stored0: f64,
}

impl<'a> ArmSystem<'a> {
    pub fn new(scene: &'a Scene, run: &Run) -> Self {
        let nv = scene.model.nv;
        let contacts = scene.run_contacts(run);
        let nc = contacts.len();
        let layout = Layout { nv, ni: if scene.drives.quasi_static { 0 } else { nv } };
        let mut sys = Self {
            scene,
            contacts,
            layout,
            data: Data::new(&scene.model),
            fd: ForwardData::new(nv, nc),
            q_des: vec![0.0; nv],
            qd_des: vec![0.0; nv],
            voltage: vec![0.0; nv],
            current_qs: vec![0.0; nv],
            jac: crate::stiff::JacobianScratch::new(nv, nc, layout.dim()),
            projection: crate::projection::ProjectionScratch::new(nv, nc),
            stored0: 0.0,
        };
        sys.stored0 = sys.stored_energy(&scene.q0, &scene.qd0, &scene.current0);
        sys
    }

    /// The initial state vector.
    pub fn initial_state(&self) -> Vec<f64> {
        let mut y = vec![0.0; self.layout.dim()];
        y[self.layout.q()].copy_from_slice(&self.scene.q0);
        y[self.layout.qd()].copy_from_slice(&self.scene.qd0);
        if self.layout.ni > 0 {
            y[self.layout.current()].copy_from_slice(&self.scene.current0);
        }
        y
    }

    /// T + V + ½ Σ L i², J. Clobbers `data`.
    fn stored_energy(&mut self, q: &[f64], qd: &[f64], current: &[f64]) -> f64 {
        let s = self.scene;
        crate::dynamics::rnea::bias_forces(&s.model, &mut self.data, q, qd);
        let t = link_kinetic_energy(&s.model, &self.data) + rotor_kinetic_energy(&s.drives, qd);
        forward_kinematics(&s.model, &mut self.data, q);
        t + potential_energy(&s.model, &self.data) + magnetic_energy(&s.drives, current)
    }

    /// The PD voltages (eq 27) at (t, q, q̇), into `self.voltage`.
    pub(crate) fn voltage_at(&mut self, t: f64, q: &[f64], qd: &[f64]) -> Result<(), DynamicsError> {
        let s = self.scene;
        s.ik
            .solve(&s.circle.position(t), &s.circle.velocity(t), &mut self.q_des, &mut self.qd_des)
            .map_err(|why| DynamicsError::Unreachable { t, why })?;
        s.gains.voltage(q, qd, &self.q_des, &self.qd_des, &mut self.voltage);
        Ok(())
    }

    /// Targets and voltages at (t, q, q̇), then eq 21. Fills `fd` and `voltage`.
    fn evaluate(&mut self, t: f64, y: &[f64]) -> Result<(), DynamicsError> {
        let l = self.layout;
        let (q, qd) = (&y[l.q()], &y[l.qd()]);
        let s = self.scene;
        self.voltage_at(t, q, qd)?;
        let cur = if l.ni == 0 {
            for j in 0..l.nv {
                self.current_qs[j] = s.drives.quasi_static_current(j, self.voltage[j], qd[j]);
            }
            &self.current_qs[..]
        } else {
            &y[l.current()]
        };
        let plant = Plant {
            model: &s.model,
            drives: &s.drives,
            contacts: &self.contacts,
            mass_matrix: s.mass_matrix,
            solver: s.solver,
            stabilization: s.stabilization,
        };
        forward_dynamics(&plant, &mut self.data, &mut self.fd, t, q, qd, cur, &self.voltage)
    }

    /// Everything recorded at (t, y), written into `out` (whose vectors are reused).
    pub fn outputs(&mut self, t: f64, y: &[f64], out: &mut Outputs) -> Result<(), DynamicsError> {
        self.evaluate(t, y)?;
        let l = self.layout;
        let s = self.scene;
        let d = &s.drives;
        let (q, qd) = (&y[l.q()], &y[l.qd()]);
        let cur = if l.ni == 0 { &self.current_qs[..] } else { &y[l.current()] };
        out.t = t;
        set(&mut out.q, q);
        set(&mut out.qd, qd);
        set(&mut out.qdd, self.fd.qdd.as_slice());
        set(&mut out.current, cur);
        set(&mut out.voltage, &self.voltage);
        out.back_emf.clear();
        out.back_emf.extend((0..l.nv).map(|j| d.back_emf(j, qd[j])));
        out.electric_power.clear();
        out.electric_power.extend((0..l.nv).map(|j| cur[j] * self.voltage[j]));
        set(&mut out.tau_motor, self.fd.tau_motor.as_slice());
        set(&mut out.normal_force, self.fd.f_n.as_slice());
        set(&mut out.link_work, &y[l.work()]);
        set(&mut out.electric_energy, &y[l.electric()]);
        out.loss_resistance = y[l.loss_r()];
        out.loss_friction = y[l.loss_d()] + y[l.loss_dm()];
        out.loss_gear_friction = y[l.loss_dm()];
        // kinematics at this state (the dynamics left body velocities of RNEA in `data`)
        // ½ q̇ᵀ M q̇ from the mass matrix of this evaluation (valid for CRBA and Walker–Orin)
        let m_qd: f64 = (0..l.nv).map(|r| qd[r] * (0..l.nv).map(|c| self.data.m[(r, c)] * qd[c]).sum::<f64>()).sum();
        out.kinetic = 0.5 * m_qd + rotor_kinetic_energy(d, qd);
        forward_kinematics(&s.model, &mut self.data, q);
        forward_velocities(&s.model, &mut self.data, qd);
        out.potential = potential_energy(&s.model, &self.data);
        out.magnetic = magnetic_energy(d, cur);
        out.hand = s.hand.position(&self.data);
        out.hand_desired = s.circle.position(t);
        out.constraint_position.clear();
        out.constraint_position.extend(self.contacts.iter().map(|c| c.position(&self.data)));
        out.constraint_velocity.clear();
        out.constraint_velocity.extend(self.contacts.iter().map(|c| c.velocity(&self.data)));
        let electric: f64 = out.electric_energy.iter().sum();
        out.balance_residual = electric
            - (out.kinetic + out.potential + out.magnetic - self.stored0 + out.loss_resistance + out.loss_friction);
        Ok(())
    }
}

fn set(dst: &mut Vec<f64>, src: &[f64]) {
    dst.clear();
    dst.extend_from_slice(src);
}

impl OdeSystem for ArmSystem<'_> {
    type Error = RunError;

    fn dim(&self) -> usize {
        self.layout.dim()
    }

    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), RunError> {
        self.evaluate(t, y)?;
        let l = self.layout;
        let d = &self.scene.drives;
        let qd = &y[l.qd()];
        let cur = if l.ni == 0 { &self.current_qs[..] } else { &y[l.current()] };
        dydt[l.q()].copy_from_slice(qd);
        dydt[l.qd()].copy_from_slice(self.fd.qdd.as_slice());
        if l.ni > 0 {
            dydt[l.current()].copy_from_slice(self.fd.di.as_slice());
        }
        let (mut p_r, mut p_d, mut p_dm) = (0.0, 0.0, 0.0);
        for j in 0..l.nv {
            dydt[l.work().start + j] = self.fd.tau_motor[j] * qd[j];
            dydt[l.electric().start + j] = cur[j] * self.voltage[j];
            p_r += d.r[j] * cur[j] * cur[j];
        }
        if d.has_friction {
            for j in 0..l.nv {
                p_d += d.d[j] * qd[j] * qd[j];
                p_dm += d.dm[j] * qd[j] * qd[j];
            }
        }
        dydt[l.loss_r()] = p_r;
        dydt[l.loss_d()] = p_d;
        dydt[l.loss_dm()] = p_dm;
        Ok(())
    }

    fn project(&mut self, t: f64, y: &mut [f64]) -> Result<bool, RunError> {
        if self.scene.stabilization == crate::dynamics::forward::Stabilization::Projection {
            Ok(ArmSystem::project(self, t, y)?)
        } else {
            Ok(false)
        }
    }
}
