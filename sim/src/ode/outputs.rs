//! [`Outputs`]: everything recorded at one output time, computed from (t, y), at one of two
//! [`OutputLevel`]s so that a consumer pays per sample only for what it reads.
//!
//! What each quantity needs (n = nv joints):
//!
//! | quantity | needs |
//! |---|---|
//! | t, q, q̇, W_j, E_j, E_R, E_D + E_Dm, i (inductive motors) | the state y alone |
//! | back EMF `K_e k q̇` (= `K_m q̇` unless the scene gives K_e) | the state |
//! | hand position, constraint positions C, contact points, potential energy V | forward kinematics at q (placements) |
//! | constraint velocities Ċ | forward kinematics and velocities at (q, q̇) |
//! | desired hand position | the target's hand path at t (for a joint target: FK of q_d(t)) |
//! | voltages, electric power `i v`, i (quasi-static motors), ½ L i² then | the IK targets and the PD law (eqs 27–29) |
//! | q̈, f_n, τ_motor (eq 12, has `J_m q̈`), T (`½ q̇ᵀ M q̇`), balance residual | the full right-hand side (eq 21's solve) |
//!
//! [`OutputLevel::Full`] (the recording, every test of the physics) evaluates one right-hand
//! side per sample and reads the kinematics that evaluation left in the workspace (no second
//! forward-kinematics pass). [`OutputLevel::Kinematic`] (`sim precision`, which measures hand
//! error, energy-quadrature error and drift) evaluates forward kinematics (and velocities, with
//! contacts) only: about a tenth of a right-hand side per sample.

use nalgebra::Vector3;

use crate::dynamics::energy::{magnetic_energy, potential_energy, rotor_kinetic_energy};
use crate::dynamics::kinematics::{forward_kinematics, forward_velocities};
use crate::dynamics::motor::Electrical;
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
    /// World position of each contact of the run where it touches (or would touch) its plane,
    /// in its order, m (forward kinematics at q; for the viewers' contact markers): the
    /// contact's point, or a sphere's or rim's lowest point (`Contact::touch_point`).
    pub contact_point: Vec<Vector3<f64>>,
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
    /// `Σ E_j − (ΔT + ΔV + ΔE_L + E_R + E_D + E_Dm [+ E_conv + ΔV_s + E_s])`, J (the bracket's
    /// terms when the scene has them).
    pub balance_residual: f64,
    /// The controller's command before the drive's limits, V (empty unless the drives have
    /// voltage or current limits; full level only).
    pub voltage_command: Vec<f64>,
    /// `E_conv = ∫ Σ (K_e − K_t) k i q̇ dt`, J (0 unless some K_e ≠ K_t).
    pub loss_conversion: f64,
    /// The soft stops' stored energy `Σ ½ k δ²`, J (0 without stops).
    pub stop_energy: f64,
    /// The soft stops' damping loss `∫ Σ c q̇² [beyond] dt`, J (0 without stops).
    pub loss_stop: f64,
    /// Per contact of the run, in its order: mode, gap, forces, slip and the cumulative contact
    /// losses. Empty when every contact of the run is bilateral (the paper's runs: their
    /// recordings carry `/constraints` only).
    pub contacts: Vec<crate::dynamics::contact::ContactOutput>,
    /// The contact events since the previous sample (at times ≤ t), in time order; the run
    /// moves them here from the system's log at each sample (always empty for bilateral runs).
    pub events: Vec<crate::dynamics::contact::ContactEvent>,
    /// `E_g = ∫ Σ (K_m i − τ_gear) q̇ dt`: the gears' Coulomb and efficiency loss, J (0 without
    /// `gear_friction`).
    pub loss_gear: f64,
    /// Per joint, the gear's torque beyond the ideal train `K_m i` (sliding friction and
    /// efficiency, or the holding torque while sticking), N m (empty without `gear_friction`;
    /// full level only).
    pub gear_torque: Vec<f64>,
    /// Per joint, whether its gear sticks (empty without `gear_friction`).
    pub gear_stuck: Vec<bool>,
    /// The supply's powers and energies (`None` without `supply`).
    pub supply: Option<SupplyOutput>,
    /// Per joint: the winding and housing temperatures, °C, and the winding resistance R(T_w),
    /// ohm (empty without the thermal model).
    pub winding_temperature: Vec<f64>,
    pub housing_temperature: Vec<f64>,
    pub resistance: Vec<f64>,
    /// Per joint: the copper loss R(T_w) i², W (empty without the thermal model, and at the
    /// kinematic level for quasi-static motors).
    pub copper_loss: Vec<f64>,
    /// The heat stored in the motors since t = 0, `Σ C_w (T_w − T_0) + C_h (T_h − T_0)`, J, and
    /// the heat given to the ambient `Q_a`, J (0 without the thermal model): with the thermal
    /// model, `E_R = heat_stored + heat_to_ambient` (`dynamics/thermal.rs`).
    pub heat_stored: f64,
    pub heat_to_ambient: f64,
}

/// The supply at one sample (`dynamics/supply.rs`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SupplyOutput {
    /// `P_s`, the power the supply delivers, W (NaN at the kinematic level).
    pub power: f64,
    /// `P_b`, the drives' DC power on the bus (or summed), W (NaN at the kinematic level).
    pub bus_power: f64,
    /// `E_supply = ∫ P_s dt`, J.
    pub energy: f64,
    /// `∫ max(−P_s, 0) dt`: taken back by the supply, J.
    pub regenerated: f64,
    /// Dumped in the brake resistors, J.
    pub dumped: f64,
    /// The supply's conversion loss, J.
    pub loss: f64,
    /// `E_supply − (Σ E_j + dumped + loss)`, J: an identity of the quadratures (≈ rounding).
    pub residual: f64,
}

fn set(dst: &mut Vec<f64>, src: &[f64]) {
    dst.clear();
    dst.extend_from_slice(src);
}

/// Which quantities of [`Outputs`] a consumer reads (the module docs give what each needs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum OutputLevel {
    /// Everything: one full right-hand side per sample.
    #[default]
    Full,
    /// The state's quantities (t, q, q̇, W, E, the losses, the currents of inductive motors and
    /// their ½ L i²), the back EMF, and what forward kinematics gives: the hand, the desired
    /// hand, C, Ċ and V. The quantities that need the controller or eq 21 are left empty (the
    /// vectors: q̈, voltage, electric power, τ_motor, f_n, and the currents of quasi-static
    /// motors) or NaN (T, the balance residual, and ½ L i² of quasi-static motors).
    Kinematic,
}

impl ArmSystem<'_> {
    /// The temperatures, resistances and heat totals of the thermal model at `y` (cleared
    /// without it); the copper losses are set by the caller, which knows the currents.
    fn thermal_outputs(&self, y: &[f64], out: &mut Outputs) {
        let l = self.layout;
        let Some(th) = &self.scene.thermal else {
            for v in [&mut out.winding_temperature, &mut out.housing_temperature, &mut out.resistance, &mut out.copper_loss] {
                v.clear();
            }
            (out.heat_stored, out.heat_to_ambient) = (0.0, 0.0);
            return;
        };
        let (t_w, t_h) = (&y[l.winding_temperature()], &y[l.housing_temperature()]);
        set(&mut out.winding_temperature, t_w);
        set(&mut out.housing_temperature, t_h);
        out.resistance.clear();
        out.resistance.extend((0..l.nv).map(|j| th.resistance(j, t_w[j])));
        out.copper_loss.clear();
        out.heat_stored = (0..l.nv).map(|j| th.stored_heat(j, t_w[j], t_h[j])).sum();
        out.heat_to_ambient = l.heat_to_ambient().map_or(0.0, |k| y[k]);
    }

    /// Everything recorded at (t, y), written into `out` (whose vectors are reused).
    pub fn outputs(&mut self, t: f64, y: &[f64], out: &mut Outputs) -> Result<(), DynamicsError> {
        self.outputs_at(OutputLevel::Full, t, y, out)
    }

    /// The quantities of `level` at (t, y), written into `out` (whose vectors are reused).
    pub fn outputs_at(&mut self, level: OutputLevel, t: f64, y: &[f64], out: &mut Outputs) -> Result<(), DynamicsError> {
        let l = self.layout;
        let s = self.scene;
        let d = &s.drives;
        let (q, qd) = (&y[l.q()], &y[l.qd()]);
        match level {
            // the evaluation leaves the placements at q, and with contacts the world
            // velocities at (q, q̇), in the workspace (`forward_dynamics`)
            OutputLevel::Full => self.evaluate(t, y)?,
            OutputLevel::Kinematic => {
                forward_kinematics(&s.model, &mut self.ws.data, q);
                if !self.contacts.is_empty() {
                    forward_velocities(&s.model, &mut self.ws.data, qd);
                }
            }
        }
        out.t = t;
        set(&mut out.q, q);
        set(&mut out.qd, qd);
        out.back_emf.clear();
        out.back_emf.extend((0..l.nv).map(|j| d.back_emf(j, qd[j])));
        set(&mut out.link_work, &y[l.work()]);
        set(&mut out.electric_energy, &y[l.electric()]);
        out.loss_resistance = y[l.loss_r()];
        out.loss_friction = y[l.loss_d()] + y[l.loss_dm()];
        out.loss_gear_friction = y[l.loss_dm()];
        out.loss_conversion = l.loss_conversion().map_or(0.0, |k| y[k]);
        out.loss_stop = l.loss_stop().map_or(0.0, |k| y[k]);
        out.stop_energy = s.stops.as_ref().map_or(0.0, |st| st.energy(q));
        out.loss_gear = l.loss_gear().map_or(0.0, |k| y[k]);
        out.gear_stuck.clear();
        out.gear_torque.clear();
        if let (Some(m), true) = (&self.drive_modes, l.gear) {
            out.gear_stuck.extend(m.gear.iter().map(|&g| g == crate::dynamics::gear_friction::GearMode::Stick));
        }
        out.supply = l.supply().map(|k| {
            let (energy, dumped, loss) = (y[k], y[k + 2], y[k + 3]);
            let electric: f64 = y[l.electric()].iter().sum();
            SupplyOutput { power: f64::NAN, bus_power: f64::NAN, energy, regenerated: y[k + 1], dumped, loss, residual: energy - (electric + dumped + loss) }
        });
        self.thermal_outputs(y, out);
        let data = &self.ws.data;
        out.potential = potential_energy(&s.model, data);
        out.hand = s.hand.position(data);
        out.hand_desired = s.target.hand_desired(t, &s.model, &s.hand, &mut self.ws.target);
        out.constraint_position.clear();
        out.constraint_position.extend(self.contacts.iter().map(|c| c.position(data)));
        out.constraint_velocity.clear();
        out.constraint_velocity.extend(self.contacts.iter().map(|c| c.velocity(data)));
        out.contact_point.clear();
        match &self.hybrid {
            Some(h) => out.contact_point.extend(h.contacts.iter().map(|c| c.touch_point(data))),
            None => out.contact_point.extend(self.contacts.iter().map(|c| c.point.position(data))),
        }
        if level == OutputLevel::Kinematic {
            for v in [&mut out.qdd, &mut out.voltage, &mut out.electric_power, &mut out.tau_motor, &mut out.normal_force, &mut out.voltage_command] {
                v.clear();
            }
            match l.electrical {
                Electrical::Inductive => {
                    set(&mut out.current, &y[l.current()]);
                    out.magnetic = magnetic_energy(d, &out.current);
                }
                Electrical::QuasiStatic => {
                    out.current.clear();
                    out.magnetic = f64::NAN;
                }
            }
            if !out.resistance.is_empty() && l.ni() > 0 {
                out.copper_loss.clear();
                out.copper_loss.extend((0..l.nv).map(|j| out.resistance[j] * out.current[j] * out.current[j]));
            }
            out.kinetic = f64::NAN;
            out.balance_residual = f64::NAN;
            self.contact_outputs(y, false, &mut out.contacts);
            return Ok(());
        }
        let cur = self.currents(y);
        let (fd, voltage) = (&self.ws.fd, &self.ws.voltage);
        set(&mut out.qdd, fd.qdd.as_slice());
        set(&mut out.current, cur);
        set(&mut out.voltage, voltage);
        if d.has_limits {
            set(&mut out.voltage_command, &self.ws.voltage_cmd);
        } else {
            out.voltage_command.clear();
        }
        out.electric_power.clear();
        out.electric_power.extend((0..l.nv).map(|j| cur[j] * voltage[j]));
        if !out.resistance.is_empty() {
            out.copper_loss.clear();
            out.copper_loss.extend((0..l.nv).map(|j| out.resistance[j] * cur[j] * cur[j]));
        }
        set(&mut out.tau_motor, fd.tau_motor.as_slice());
        match &self.hybrid {
            None => set(&mut out.normal_force, fd.f_n.as_slice()),
            Some(h) => set(&mut out.normal_force, &h.cd.f_n),
        }
        out.magnetic = magnetic_energy(d, cur);
        // ½ q̇ᵀ M q̇ from the mass matrix of this evaluation (valid for CRBA and Walker–Orin)
        let m_qd: f64 = (0..l.nv).map(|r| qd[r] * (0..l.nv).map(|c| data.m[(r, c)] * qd[c]).sum::<f64>()).sum();
        out.kinetic = 0.5 * m_qd + rotor_kinetic_energy(d, qd);
        let electric: f64 = out.electric_energy.iter().sum();
        out.balance_residual = if l.conversion || l.stops {
            electric
                - (out.kinetic + out.potential + out.magnetic + out.stop_energy - self.stored0
                    + out.loss_resistance
                    + out.loss_friction
                    + out.loss_conversion
                    + out.loss_stop)
        } else {
            electric - (out.kinetic + out.potential + out.magnetic - self.stored0 + out.loss_resistance + out.loss_friction)
        };
        if l.gear {
            out.balance_residual -= out.loss_gear;
            set(&mut out.gear_torque, &self.drive_modes.as_ref().expect("drive modes").gear_torque);
        }
        if let Some(w) = self.supply_powers(y) {
            let sup = out.supply.as_mut().expect("supply outputs");
            (sup.power, sup.bus_power) = (w.supply, w.bus);
        }
        if self.hybrid.is_some() {
            // the contacts' losses and the compliant contacts' stored ½ k δ² (ΔV_c: stored0 has V_c(0))
            out.balance_residual -= self.contact_losses(y) + self.contact_energy();
            self.contact_outputs(y, true, &mut out.contacts);
        } else {
            out.contacts.clear();
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::OdeSystem;
    use crate::scene::Scene;

    /// At the same (t, y) — a state off the initial one, with velocities and currents — the
    /// kinematic level gives bit for bit the full level's hand, desired hand, C, Ċ, V, state
    /// quantities, back EMF and (inductive motors) currents and ½ L i², on every run of the
    /// paper scene and of its quasi-static variant; what needs the solve is empty or NaN.
    #[test]
    fn kinematic_outputs_equal_the_full_ones_where_defined() {
        let paper = Scene::paper().expect("the built-in scene");
        let quasi_static = paper
            .vary(|s| {
                s.motor.inductance = crate::scene::spec::PerJoint::All(0.0);
                s.initial.current = crate::scene::spec::PerJoint::All(0.0);
            })
            .expect("a valid variation");
        for scene in [&paper, &quasi_static] {
            for run in scene.runs() {
                let mut sys = ArmSystem::new(scene, run);
                let l = sys.layout();
                let mut y = sys.initial_state();
                let mut rng = crate::dynamics::samples::SplitMix64(3);
                for (k, x) in y.iter_mut().enumerate().skip(l.nv) {
                    *x += rng.range(-0.5, 0.5) * if k < 2 * l.nv { 1.0 } else { 2.0 };
                }
                let t = 0.37;
                let (mut full, mut kin) = (Outputs::default(), Outputs::default());
                sys.outputs_at(OutputLevel::Full, t, &y, &mut full).expect("full outputs");
                // the kinematic level must not read what the full level left in the workspace
                let mut dydt = vec![0.0; sys.dim()];
                sys.rhs(t + 0.1, &sys.initial_state(), &mut dydt).expect("rhs");
                sys.outputs_at(OutputLevel::Kinematic, t, &y, &mut kin).expect("kinematic outputs");
                let name = &run.name;
                assert_eq!((kin.t, &kin.q, &kin.qd), (full.t, &full.q, &full.qd), "{name}");
                assert_eq!((kin.hand, kin.hand_desired, kin.potential), (full.hand, full.hand_desired, full.potential), "{name}");
                assert_eq!((&kin.constraint_position, &kin.constraint_velocity), (&full.constraint_position, &full.constraint_velocity), "{name}");
                assert_eq!(&kin.contact_point, &full.contact_point, "{name}");
                assert_eq!(full.contact_point.len(), run.contacts.len(), "{name}");
                assert_eq!((&kin.link_work, &kin.electric_energy, &kin.back_emf), (&full.link_work, &full.electric_energy, &full.back_emf), "{name}");
                assert_eq!(
                    (kin.loss_resistance, kin.loss_friction, kin.loss_gear_friction),
                    (full.loss_resistance, full.loss_friction, full.loss_gear_friction),
                    "{name}"
                );
                assert_eq!(full.constraint_position.len(), run.contacts.len(), "{name}");
                if l.ni() > 0 {
                    assert_eq!((&kin.current, kin.magnetic), (&full.current, full.magnetic), "{name}");
                } else {
                    assert!(kin.current.is_empty() && kin.magnetic.is_nan(), "{name}");
                }
                assert!(full.qdd.len() == l.nv && kin.qdd.is_empty() && kin.tau_motor.is_empty() && kin.voltage.is_empty(), "{name}");
                assert!(kin.normal_force.is_empty() && kin.electric_power.is_empty(), "{name}");
                assert!(kin.kinetic.is_nan() && kin.balance_residual.is_nan() && full.kinetic.is_finite(), "{name}");
            }
        }
    }
}
