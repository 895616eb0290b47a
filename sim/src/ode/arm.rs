//! [`ArmSystem`]: one run of a scene as an [`OdeSystem`] — the targets and PD voltages
//! (eqs 27–29), the motors' currents, eq 21, and the quadratures of the energy balance.

use crate::dynamics::constraints::PointOnPlane;
use crate::dynamics::contact::forward::{forward_dynamics_contacts, forward_dynamics_contacts_same_q};
use crate::dynamics::energy::{link_kinetic_energy, magnetic_energy, potential_energy, rotor_kinetic_energy};
use crate::dynamics::forward::{forward_dynamics, Plant, Stabilization};
use crate::dynamics::kinematics::forward_kinematics;
use crate::dynamics::motor::{Drives, Electrical};
use crate::error::{DynamicsError, RunError};
use crate::integrate::OdeSystem;
use crate::scene::{Run, Scene};

use super::layout::Layout;
use super::workspace::Workspace;

/// One run of a scene as an ODE. The scene is read-only; all scratch is in the workspace.
pub struct ArmSystem<'a> {
    pub(super) scene: &'a Scene,
    pub(super) contacts: Vec<PointOnPlane>,
    pub(super) layout: Layout,
    pub(super) ws: Workspace,
    /// T + V + ½ L i² at t = 0, J (for the balance residual).
    pub(super) stored0: f64,
    /// The contacts' models, modes and event log: `Some` when the run has a non-bilateral
    /// contact (event-driven), `None` for the paper's runs (today's path, untouched).
    pub(super) hybrid: Option<Box<super::hybrid::Hybrid>>,
    /// The gears' and the supply's modes (`drive_modes.rs`): `Some` when the scene has
    /// `gear_friction` or `supply`, `None` for the paper's runs.
    pub(super) drive_modes: Option<Box<super::drive_modes::DriveModes>>,
}

impl<'a> ArmSystem<'a> {
    pub fn new(scene: &'a Scene, run: &Run) -> Self {
        let nv = scene.model.nv;
        let contacts = scene.run_contacts(run);
        let is_hybrid = scene.run_is_hybrid(run);
        let layout = Layout {
            nv,
            electrical: scene.drives.electrical,
            conversion: scene.drives.has_conversion,
            stops: scene.stops.is_some(),
            contacts: if is_hybrid { contacts.len() } else { 0 },
            thermal: scene.thermal.is_some(),
            gear: scene.gear_friction.is_some(),
            supply: scene.supply.is_some(),
        };
        let mut ws = Workspace::new(&scene.model, &scene.drives, contacts.len(), layout.dim());
        ws.fd.joint_torque = scene.stops.is_some() || scene.gear_friction.is_some();
        ws.want_qdd = matches!(scene.controller.law, crate::control::Law::ComputedTorque { .. });
        let hybrid = is_hybrid.then(|| Box::new(super::hybrid::Hybrid::new(scene, run)));
        let drive_modes = (layout.gear || layout.supply).then(|| Box::new(super::drive_modes::DriveModes::new(nv)));
        let mut sys = Self { scene, contacts, layout, ws, stored0: 0.0, hybrid, drive_modes };
        sys.stored0 = sys.stored_energy(&scene.q0, &scene.qd0, &scene.current0);
        if sys.hybrid.is_some() {
            // the compliant contacts' ½ k δ² at t = 0 (kinematics at q0 from stored_energy)
            sys.stored0 += sys.contact_energy();
        }
        sys
    }

    /// How many right-hand sides of difference-Jacobian columns reused the q-only part of the
    /// sweep's first q̇ column (`OdeSystem::rhs_column`; 0 for a run without contacts' modes).
    pub fn same_q_evaluations(&self) -> u64 {
        self.ws.same_q_evals
    }

    /// Where each part of the state is.
    pub fn layout(&self) -> Layout {
        self.layout
    }

    /// The initial state vector.
    pub fn initial_state(&self) -> Vec<f64> {
        let l = self.layout;
        let mut y = vec![0.0; l.dim()];
        y[l.q()].copy_from_slice(&self.scene.q0);
        y[l.qd()].copy_from_slice(&self.scene.qd0);
        if l.ni() > 0 {
            y[l.current()].copy_from_slice(&self.scene.current0);
        }
        if let Some(th) = &self.scene.thermal {
            y[l.winding_temperature()].fill(th.initial);
            y[l.housing_temperature()].fill(th.initial);
        }
        y
    }

    /// The winding resistances R(T_w) at the temperatures of `y`, into the workspace's drives
    /// (thermal model on; otherwise they stay the scene's).
    pub(super) fn set_resistance(&mut self, y: &[f64]) {
        if let Some(th) = &self.scene.thermal {
            let t_w = &y[self.layout.winding_temperature()];
            for (j, (r, &t)) in self.ws.drives.r.iter_mut().zip(t_w).enumerate() {
                *r = th.resistance(j, t);
            }
        }
    }

    /// T + V + ½ Σ L i² (+ the stops' ½ k δ² when configured), J. Clobbers the kinematics
    /// scratch.
    pub(super) fn stored_energy(&mut self, q: &[f64], qd: &[f64], current: &[f64]) -> f64 {
        let s = self.scene;
        let data = &mut self.ws.data;
        crate::dynamics::rnea::bias_forces(&s.model, data, q, qd);
        let t = link_kinetic_energy(&s.model, data) + rotor_kinetic_energy(&s.drives, qd);
        forward_kinematics(&s.model, data, q);
        let e = t + potential_energy(&s.model, data) + magnetic_energy(&s.drives, current);
        match &s.stops {
            Some(st) => e + st.energy(q),
            None => e,
        }
    }

    /// The targets (the paper's: eqs 28–29), the controller's voltages (eq 27 for the paper) and the
    /// drive's limits at (t, q, q̇; i for a law with a current loop), into the workspace. With
    /// quasi-static motors and drive limits, also their currents (`current_qs`).
    pub(super) fn voltage_at(&mut self, t: f64, q: &[f64], qd: &[f64], current: Option<&[f64]>) -> Result<(), DynamicsError> {
        let s = self.scene;
        let ws = &mut self.ws;
        // the targets depend on t alone: a difference Jacobian's columns and the stage at
        // c = 0 share theirs (the paper's IK: atan2, acos, sin, cos per evaluation)
        if ws.target_t.to_bits() != t.to_bits() {
            let qdd_des = if ws.want_qdd { Some(&mut ws.qdd_des[..]) } else { None };
            ws.target_t = f64::NAN;
            s.target.eval(t, &s.model, &s.hand, &mut ws.target, &mut ws.q_des, &mut ws.qd_des, qdd_des)
                .map_err(|why| DynamicsError::Unreachable { t, why })?;
            ws.target_t = t;
        }
        let input = crate::control::ControlInput { q, qd, current, q_des: &ws.q_des, qd_des: &ws.qd_des, qdd_des: &ws.qdd_des };
        s.controller.voltage(&s.model, &s.drives, &mut ws.data, &mut ws.ctrl, &input, &mut ws.voltage);
        // the drive's current window at the winding's resistance now (R(T_w) with the thermal
        // model; the controller keeps its nominal model: it measures no temperature)
        let d = &ws.drives;
        if d.has_limits {
            ws.voltage_cmd.copy_from_slice(&ws.voltage);
            for j in 0..q.len() {
                match d.electrical {
                    Electrical::Inductive => ws.voltage[j] = d.limited_voltage(j, ws.voltage_cmd[j], qd[j]),
                    Electrical::QuasiStatic => {
                        (ws.voltage[j], ws.current_qs[j]) = d.limited_quasi_static(j, ws.voltage_cmd[j], qd[j]);
                    }
                }
            }
        }
        Ok(())
    }

    /// The motor currents at `y`: the current states, or for quasi-static motors the currents
    /// the last [`ArmSystem::evaluate`] computed.
    pub(super) fn currents<'y>(&'y self, y: &'y [f64]) -> &'y [f64] {
        currents_in(&self.layout, y, &self.ws.current_qs)
    }

    /// Targets, voltages, the stops' torques and the quasi-static currents at (t, y), into the
    /// workspace: the inputs of eq 21.
    pub(super) fn inputs(&mut self, t: f64, y: &[f64]) -> Result<(), DynamicsError> {
        let l = self.layout;
        let (q, qd) = (&y[l.q()], &y[l.qd()]);
        let s = self.scene;
        let current = (l.electrical == Electrical::Inductive).then(|| &y[l.current()]);
        self.set_resistance(y);
        self.voltage_at(t, q, qd, current)?;
        if let Some(st) = &s.stops {
            for j in 0..l.nv {
                self.ws.fd.tau_joint[j] = st.torque(j, q[j], qd[j]);
            }
        }
        if l.electrical == Electrical::QuasiStatic && !s.drives.has_limits {
            for j in 0..l.nv {
                self.ws.current_qs[j] = self.ws.drives.quasi_static_current(j, self.ws.voltage[j], qd[j]);
            }
        }
        self.gear_inputs(y);
        Ok(())
    }

    /// Targets, voltages and currents at (t, y), then eq 21: everything the right-hand side,
    /// the outputs and the Jacobian read, into the workspace. A hybrid run solves eq 21 with
    /// its contacts' active rows in the current modes (`dynamics/contact/forward.rs`).
    pub(super) fn evaluate(&mut self, t: f64, y: &[f64]) -> Result<(), DynamicsError> {
        self.ws.sweep_ready = false;
        self.inputs(t, y)?;
        self.solve_eq21(t, y)?;
        if self.drive_modes.is_some() {
            self.lock_stuck(t, y)?;
        }
        Ok(())
    }

    /// [`ArmSystem::evaluate`] of a hybrid run at a state whose q is the one of the q-only
    /// part in the workspace (`sweep_q`, checked by the caller): the inputs in full, eq 21 with
    /// that part reused (`forward_dynamics_contacts_same_q`), bit for bit a full evaluation.
    pub(super) fn evaluate_same_q(&mut self, t: f64, y: &[f64]) -> Result<(), DynamicsError> {
        self.inputs(t, y)?;
        let l = self.layout;
        let s = self.scene;
        let plant = plant(s, &self.ws.drives, &self.contacts);
        let current = currents_in(&l, y, &self.ws.current_qs);
        let h = self.hybrid.as_mut().expect("hybrid");
        forward_dynamics_contacts_same_q(&plant, &h.contacts, &h.state, &mut self.ws.data, &mut self.ws.fd, &mut h.cd, t, &y[l.qd()], current, &self.ws.voltage)?;
        if self.drive_modes.is_some() {
            self.lock_stuck(t, y)?;
        }
        Ok(())
    }

    /// Eq 21 at (t, y) with the inputs in the workspace (the contacts' active rows in a hybrid
    /// run).
    pub(super) fn solve_eq21(&mut self, t: f64, y: &[f64]) -> Result<(), DynamicsError> {
        let l = self.layout;
        let (q, qd) = (&y[l.q()], &y[l.qd()]);
        let s = self.scene;
        let plant = plant(s, &self.ws.drives, &self.contacts);
        let current = currents_in(&l, y, &self.ws.current_qs);
        match &mut self.hybrid {
            None => forward_dynamics(&plant, &mut self.ws.data, &mut self.ws.fd, t, q, qd, current, &self.ws.voltage),
            Some(h) => forward_dynamics_contacts(&plant, &h.contacts, &h.state, &mut self.ws.data, &mut self.ws.fd, &mut h.cd, t, q, qd, current, &self.ws.voltage),
        }
    }
}

impl OdeSystem for ArmSystem<'_> {
    type Error = RunError;

    fn dim(&self) -> usize {
        self.layout.dim()
    }

    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), RunError> {
        self.evaluate(t, y)?;
        self.rates(y, dydt);
        Ok(())
    }

    /// A hybrid run's q̇ and current columns after the first q̇ column reuse the q-only part
    /// of that column's evaluation ([`ArmSystem::evaluate_same_q`]): the sweep moves one
    /// component at a time from the same base, so their q is the base's (checked bit for bit).
    /// The other columns, and every column of a run without contacts' modes, are full
    /// evaluations.
    fn rhs_column(&mut self, t: f64, y: &[f64], col: usize, dydt: &mut [f64]) -> Result<(), RunError> {
        let l = self.layout;
        let (q, qd) = (l.q(), l.qd());
        let moves_qd_or_i = col >= qd.start && col < l.work().start;
        if self.hybrid.is_some() && moves_qd_or_i && col > qd.start && self.ws.sweep_ready && self.ws.sweep_q[..] == y[q.clone()] {
            self.evaluate_same_q(t, y)?;
            self.ws.same_q_evals += 1;
        } else {
            self.evaluate(t, y)?;
            if self.hybrid.is_some() && col == qd.start {
                self.ws.sweep_q.copy_from_slice(&y[q]);
                self.ws.sweep_ready = true;
            }
        }
        self.rates(y, dydt);
        Ok(())
    }

    /// Leaves out of the step-size control the three quadratures of every unilateral contact
    /// that is separated ([`Layout::contact_quadratures`]: impact loss, friction work, damping
    /// loss). Their rates are exactly 0 until the next event (no force, no friction, and impact
    /// losses jump only at events, `hybrid.rs`), and a separation ends only at an event, whose
    /// restart reads this again; so their error estimates are 0, and in the norm they only
    /// raised its divisor: the more candidate contacts a scene lists, the looser the effective
    /// tolerance (whole-table's 80 components, 21 of them the idle candidates' zeros, against
    /// two-elbow-unilateral's 59: 5756 steps / 120 rejected against 5799 / 122 where the
    /// trajectories are the same; issue 24; now the same steps, `contacts_idle.rs`). A touching
    /// contact's quadratures stay measured (a compliant contact's force, and so its mode, does
    /// not change at events: always measured), as do the motors' energy quadratures: they are
    /// results the runs report, and the archived bilateral runs were made with them in the norm
    /// (`recordings/`).
    fn error_measured(&self, measured: &mut [bool]) {
        let Some(h) = &self.hybrid else { return };
        for (k, (c, mode)) in h.contacts.iter().zip(&h.state.mode).enumerate() {
            if super::resolution::quadratures_idle(c, *mode) {
                for i in self.layout.contact_quadratures(k) {
                    measured[i] = false;
                }
            }
        }
    }

    fn project(&mut self, t: f64, y: &mut [f64]) -> Result<bool, RunError> {
        if self.scene.stabilization == Stabilization::Projection {
            if self.hybrid.is_some() {
                return Ok(self.project_onto_active_rows(t, y)?);
            }
            Ok(self.project_onto_constraints(t, y)?)
        } else {
            Ok(false)
        }
    }
}

impl ArmSystem<'_> {
    /// The derivative `dydt` from the evaluation in the workspace at `y` (eq 21's q̈ and
    /// di/dt, the quadratures' rates).
    fn rates(&mut self, y: &[f64], dydt: &mut [f64]) {
        let l = self.layout;
        let d = &self.ws.drives;
        let qd = &y[l.qd()];
        let cur = self.currents(y);
        let (fd, voltage) = (&self.ws.fd, &self.ws.voltage);
        dydt[l.q()].copy_from_slice(qd);
        dydt[l.qd()].copy_from_slice(fd.qdd.as_slice());
        if l.ni() > 0 {
            dydt[l.current()].copy_from_slice(fd.di.as_slice());
        }
        let (mut p_r, mut p_d, mut p_dm) = (0.0, 0.0, 0.0);
        for j in 0..l.nv {
            dydt[l.work().start + j] = fd.tau_motor[j] * qd[j];
            dydt[l.electric().start + j] = cur[j] * voltage[j];
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
        if let Some(k) = l.loss_conversion() {
            dydt[k] = (0..l.nv).map(|j| (d.ke[j] - d.km[j]) * cur[j] * qd[j]).sum();
        }
        if let (Some(k), Some(st)) = (l.loss_stop(), &self.scene.stops) {
            dydt[k] = st.loss_rate(&y[l.q()], qd);
        }
        if let (Some(th), Some(k)) = (&self.scene.thermal, l.heat_to_ambient()) {
            // the two-node network of each motor, heated by its copper loss R(T_w) i²
            let (t_w, t_h) = (&y[l.winding_temperature()], &y[l.housing_temperature()]);
            let mut q_a = 0.0;
            for j in 0..l.nv {
                let (a, b) = th.rates(j, d.r[j] * cur[j] * cur[j], t_w[j], t_h[j]);
                dydt[l.winding_temperature().start + j] = a;
                dydt[l.housing_temperature().start + j] = b;
                q_a += th.heat_to_ambient(j, t_h[j]);
            }
            dydt[k] = q_a;
        }
        if self.hybrid.is_some() {
            self.contact_loss_rates(dydt);
        }
        if self.drive_modes.is_some() {
            self.drive_loss_rates(y, dydt);
        }
    }
}

/// [`ArmSystem::currents`] from the fields it reads, for callers that hold other fields of the
/// system mutably: the current states of `y`, or for quasi-static motors `current_qs`.
pub(super) fn currents_in<'y>(layout: &Layout, y: &'y [f64], current_qs: &'y [f64]) -> &'y [f64] {
    match layout.electrical {
        Electrical::Inductive => &y[layout.current()],
        Electrical::QuasiStatic => current_qs,
    }
}

/// The plant eq 21 reads: the scene's model and solver settings with `drives` (the workspace's,
/// with this evaluation's winding resistances, or the scene's) and the bilateral contacts.
pub(super) fn plant<'p>(scene: &'p Scene, drives: &'p Drives, contacts: &'p [PointOnPlane]) -> Plant<'p> {
    Plant { model: &scene.model, drives, contacts, mass_matrix: scene.mass_matrix, solver: scene.solver, stabilization: scene.stabilization }
}
