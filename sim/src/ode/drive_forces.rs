//! The drives' terms of the right-hand side in the modes of `drive_modes.rs` (which decides
//! the modes at events): the sliding gears' torques `(c − 1) K_m i − τ_f(q̇) s`
//! (`dynamics/gear_friction.rs`), the holding torques of the sticking joints, the gear
//! efficiency and friction slope the structured Jacobian needs, and the rates of the gear loss
//! and supply quadratures (`dynamics/supply.rs`). In fixed modes each of them is a smooth
//! function of (t, y).
//!
//! A sticking joint is held by the torque λ_j that makes `q̈_j = 0` with the other joints in
//! their modes: eq 21 is affine in the joint torques for fixed modes, so with `S` the sticking
//! joints, `q̈_S(τ + E_S λ) = q̈_S(τ) + G_SS λ` where column a of G is the change of q̈ for a
//! unit torque at joint S_a (one more solve per sticking joint, exact up to rounding), and
//! `G_SS λ = −q̈_S(τ)` is solved in `gear_hold.rs` ([`ArmSystem::lock_stuck`]; the lock of a
//! joint as a holding torque: Pfeiffer & Glocker, *Multibody Dynamics with Unilateral
//! Contacts*, Wiley 1996, ch. 5): uniquely when G_SS is regular, and where several sticking
//! joints of a closed chain share the load with the constraint forces (G_SS singular) the
//! analytic centre of the distributions that lie in every joint's band. The gear loss quadrature `E_g = ∫ Σ (K_m i_j − τ_gear,j) q̇_j
//! dt` and the supply's `E_supply`, `E_regen`, `E_dump`, `E_sloss` follow the contacts'
//! quadratures in the state; each integrand is smooth between events, so the adaptive methods
//! integrate them to their order. Allocates nothing.

use crate::dynamics::gear_friction::GearMode;
use crate::dynamics::motor::Electrical;
use crate::error::DynamicsError;

use super::arm::ArmSystem;
use super::gear_hold::hold_torques;

impl ArmSystem<'_> {
    /// `K_m i_j` with the currents of this evaluation (after `inputs`).
    pub(super) fn km_i(&self, y: &[f64], j: usize) -> f64 {
        let i = match self.layout.electrical {
            Electrical::Inductive => y[self.layout.current().start + j],
            Electrical::QuasiStatic => self.ws.current_qs[j],
        };
        self.scene.drives.km[j] * i
    }

    /// The gears' sliding torques into `fd.tau_joint` (after the stops' torques, which
    /// `inputs` wrote when the scene has stops) and `gear_torque`, at y with this evaluation's
    /// currents (0 for sticking joints: [`ArmSystem::lock_stuck`] finds theirs).
    pub(super) fn gear_inputs(&mut self, y: &[f64]) {
        let (Some(g), Some(m)) = (&self.scene.gear_friction, self.drive_modes.as_mut()) else { return };
        let l = self.layout;
        let stops = self.scene.stops.is_some();
        for j in 0..l.nv {
            let i = match l.electrical {
                Electrical::Inductive => y[l.current().start + j],
                Electrical::QuasiStatic => self.ws.current_qs[j],
            };
            let tau = g.sliding_torque(j, m.gear[j], self.scene.drives.km[j] * i, y[l.qd().start + j]);
            m.gear_torque[j] = tau;
            if stops {
                self.ws.fd.tau_joint[j] += tau;
            } else {
                self.ws.fd.tau_joint[j] = tau;
            }
        }
    }

    /// The holding torques of the sticking joints (module docs), after a solve at (t, y) in
    /// the current modes: `q̈_S = 0`, λ added to `fd.tau_joint` and kept in `gear_torque`.
    pub(super) fn lock_stuck(&mut self, t: f64, y: &[f64]) -> Result<(), DynamicsError> {
        let Some(m) = self.drive_modes.as_mut() else { return Ok(()) };
        m.stuck.clear();
        m.stuck.extend((0..self.layout.nv).filter(|&j| m.gear[j] == GearMode::Stick));
        let n = m.stuck.len();
        if n == 0 {
            return Ok(());
        }
        m.qdd0.copy_from_slice(self.ws.fd.qdd.as_slice());
        for a in 0..n {
            let j = self.drive_modes.as_ref().expect("drive modes").stuck[a];
            let saved = self.ws.fd.tau_joint[j];
            self.ws.fd.tau_joint[j] = saved + 1.0;
            self.solve_eq21(t, y)?;
            self.ws.fd.tau_joint[j] = saved;
            let m = self.drive_modes.as_mut().expect("drive modes");
            for b in 0..n {
                let r = m.stuck[b];
                m.g[b * n + a] = self.ws.fd.qdd[r] - m.qdd0[r];
            }
        }
        let gf = self.scene.gear_friction.as_ref();
        for b in 0..n {
            let j = self.drive_modes.as_ref().expect("drive modes").stuck[b];
            let (lo, hi) = gf.map_or((0.0, 0.0), |g| g.band(j, self.km_i(y, j)));
            let m = self.drive_modes.as_mut().expect("drive modes");
            m.lambda[b] = -m.qdd0[j];
            m.lo[b] = lo;
            m.hi[b] = hi;
        }
        // the absolute scale of G's pivots (gear_hold.rs): the largest free mobility bound
        // 1/(M + J_m)_aa of the sticking joints
        let m = self.drive_modes.as_mut().expect("drive modes");
        let free = m.stuck.iter().map(|&j| 1.0 / (self.ws.data.m[(j, j)] + self.ws.drives.jm[j])).filter(|v| v.is_finite() && *v > 0.0).fold(0.0, f64::max);
        if hold_torques(&mut m.hold, &m.g[..n * n], &mut m.lambda[..n], &m.lo[..n], &m.hi[..n], n, free).is_none() {
            return Err(DynamicsError::NonFinite { t, what: "the holding torque of a sticking gear (its joint has no inertia of its own)".into() });
        }
        for a in 0..n {
            let j = m.stuck[a];
            self.ws.fd.tau_joint[j] += m.lambda[a];
            m.gear_torque[j] = m.lambda[a];
        }
        self.solve_eq21(t, y)?;
        let m = self.drive_modes.as_ref().expect("drive modes");
        for &j in &m.stuck {
            self.ws.fd.qdd[j] = 0.0;
        }
        Ok(())
    }

    /// For the structured Jacobian (`jacobian.rs`): joint j's gear efficiency factor c on K_m
    /// and `s ∂τ_f/∂q̇` (the friction torque's slope, as a damping) while it slides; (1, 0)
    /// otherwise.
    pub(super) fn gear_jacobian_terms(&self, j: usize, qd: f64) -> (f64, f64) {
        let (Some(g), Some(m)) = (&self.scene.gear_friction, &self.drive_modes) else { return (1.0, 0.0) };
        match m.gear[j] {
            GearMode::Slide { dir, driving } => (g.factor(j, driving), g.sliding_friction_slope(j, qd) * f64::from(dir)),
            GearMode::Stick => (1.0, 0.0),
        }
    }

    /// The electric powers `p_j = i_j v_j` of this evaluation into the scratch.
    pub(super) fn powers_into_scratch(&mut self, y: &[f64]) {
        let l = self.layout;
        let Some(m) = self.drive_modes.as_mut() else { return };
        for j in 0..l.nv {
            let i = match l.electrical {
                Electrical::Inductive => y[l.current().start + j],
                Electrical::QuasiStatic => self.ws.current_qs[j],
            };
            m.power[j] = i * self.ws.voltage[j];
        }
    }

    /// The rates of the gear loss and the supply quadratures after an evaluation.
    pub(super) fn drive_loss_rates(&mut self, y: &[f64], dydt: &mut [f64]) {
        let l = self.layout;
        if let Some(k) = l.loss_gear() {
            let m = self.drive_modes.as_ref().expect("drive modes");
            let qd = &y[l.qd()];
            dydt[k] = -(0..l.nv).map(|j| if m.gear[j] == GearMode::Stick { 0.0 } else { m.gear_torque[j] * qd[j] }).sum::<f64>();
        }
        if let Some(k) = l.supply() {
            self.powers_into_scratch(y);
            let s = self.scene.supply.as_ref().expect("supply");
            let m = self.drive_modes.as_ref().expect("drive modes");
            let w = s.powers(&m.power, &m.pos, m.bus_pos);
            dydt[k] = w.supply;
            dydt[k + 1] = w.regenerated;
            dydt[k + 2] = w.dumped;
            dydt[k + 3] = w.loss;
        }
    }

    /// The supply's powers at the last evaluation (for the outputs).
    pub(super) fn supply_powers(&mut self, y: &[f64]) -> Option<crate::dynamics::supply::SupplyPowers> {
        self.scene.supply.as_ref()?;
        self.powers_into_scratch(y);
        let s = self.scene.supply.as_ref().expect("supply");
        let m = self.drive_modes.as_ref().expect("drive modes");
        Some(s.powers(&m.power, &m.pos, m.bus_pos))
    }
}
