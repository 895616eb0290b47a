//! DC motors through a gear train, the paper's eqs 1–12 (after 神崎, *基礎メカトロニクス*, 1994):
//! armature circuit `L di/dt = v − R i − K_m q̇` (eq 11) and the torque delivered to the link
//! `τ = K_m i − J_m q̈ − D_m q̇` (eq 12), with, for a motor of torque/back-EMF constant K, rotor
//! inertia I_m, gear ratio k and gear viscous friction d_m: `K_m = K k`, `J_m = I_m k^2`,
//! `D_m = d_m k^2` (eqs 9–10). Angles and speeds are those of the link side of the gear.
//!
//! With L = 0 on every joint the current is algebraic (quasi-static): `i = (v − K_m q̇) / R`,
//! and the motor is a torque source with back-EMF damping; no electrical state is integrated.
//!
//! Real drives ([`DriveSpec`], all optional; absent = the paper's ideal drive, same arithmetic):
//! - a back-EMF constant K_e distinct from the torque constant K_t (datasheets give both, in
//!   V s/rad and N m/A; equal in SI for an ideal machine). Eq 11 uses `K_e k q̇`, eq 12 uses
//!   `K_t k i`. The electric power `i v = R i² + d(½ L i²)/dt + K_e k i q̇` then differs from the
//!   mechanical power `K_t k i q̇` by `(K_e − K_t) k i q̇`, which the energy balance carries as
//!   its own quadrature `E_conv = ∫ Σ (K_e − K_t) k i q̇ dt` (present only when some K_e ≠ K_t);
//! - a supply voltage limit V: the amplifier saturates, `v = clamp(v*, −V, V)`; the saturated
//!   voltage is what the motor sees, what eq 11 integrates and what is recorded (so the
//!   amplifier's own losses are outside the balance: it is an ideal switch-mode stage);
//! - a current limit I of the driver, applied by limiting the voltage to the window
//!   `−R I + K_e k q̇ ≤ v ≤ R I + K_e k q̇`, before the voltage limit (the supply wins when the
//!   two disagree, and the run then flags the current). With L = 0 this is `|i| ≤ I` exactly
//!   (the current is clamped and the voltage recomputed from it); with L > 0 it makes `i = ±I`
//!   a barrier: at `i = I`, `L di/dt = v − R I − K_e k q̇ ≤ 0` (and symmetrically), so `|i| ≤ I`
//!   up to the integration error (Mohan, Undeland & Robbins, *Power Electronics*, 3rd ed.,
//!   §13-5: a current-limited drive is a voltage source whose command is clipped);
//! - passive joints: no motor at all (K_m = K_e k = J_m = D_m = 0, zero voltage, zero current);
//! - the motor's thermal data (a datasheet drive): with the scene's thermal model on, R follows
//!   the winding temperature (`dynamics/thermal.rs`); the ODE then reads its drives with R(T_w)
//!   from its workspace (`ode/workspace.rs`), the controller the nominal ones.
//!
//! Prismatic joints use the same model with link-side units: the gear ratio (lead screw or
//! rack) is in rad/m, K_m = K_t k in N/A, J_m = I_m k² in kg, D_m in N s/m, and the back EMF
//! `K_e k q̇` in V with q̇ in m/s.
//!
//! Gear efficiency and Coulomb friction are not in this file: they make the right-hand side
//! non-smooth (a constant efficiency η < 1 scales the torque in one power direction and its
//! inverse in the other; Coulomb friction changes sign with q̇ and holds a joint at rest), so
//! they are a law with discrete modes, `dynamics/gear_friction.rs`, whose switches are events
//! of the hybrid driver (`ode/drive_modes.rs`), with their loss as its own term of the balance.
//! The viscous gear loss `D_m q̇²` of eq 12 stays here. What the supply delivers for the power
//! `i v` the motors draw (regeneration, a shared DC bus) is `dynamics/supply.rs`.

use nalgebra::DVector;

/// One motor and its gear, as written in a scene (SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MotorParams {
    /// K: torque constant = back-EMF constant, N m/A = V s/rad.
    pub torque_constant: f64,
    /// R: armature resistance, ohm.
    pub resistance: f64,
    /// L: armature inductance, H.
    pub inductance: f64,
    /// I_m: rotor inertia, kg m^2.
    pub rotor_inertia: f64,
    /// k: gear ratio (motor turns per link turn).
    pub gear_ratio: f64,
    /// d_m: viscous friction of the gear, motor side, N m s/rad.
    pub gear_damping: f64,
}

impl MotorParams {
    /// `K_m = K k` (eq 10), N m/A.
    pub fn km(&self) -> f64 {
        self.torque_constant * self.gear_ratio
    }
    /// `J_m = I_m k^2` (eq 10), kg m^2.
    pub fn jm(&self) -> f64 {
        self.rotor_inertia * self.gear_ratio * self.gear_ratio
    }
    /// `D_m = d_m k^2` (eq 10), N m s/rad.
    pub fn dm(&self) -> f64 {
        self.gear_damping * self.gear_ratio * self.gear_ratio
    }
}

/// The motors' electrical model: what the state holds and how the current is found. A scene's
/// motors are all of one kind (validated).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Electrical {
    /// `L di/dt = v − R i − K_m q̇` (eq 11): one current state per motor.
    Inductive,
    /// L = 0: `i = (v − K_m q̇) / R`, algebraic; no electrical state.
    QuasiStatic,
}

impl Electrical {
    /// Electrical states of `nv` motors: `nv` or 0.
    pub fn states(self, nv: usize) -> usize {
        match self {
            Electrical::Inductive => nv,
            Electrical::QuasiStatic => 0,
        }
    }

    /// As recorded (`model.electrical`) and shown.
    pub fn describe(self) -> &'static str {
        match self {
            Electrical::Inductive => "L di/dt (one state per motor)",
            Electrical::QuasiStatic => "quasi-static current (L = 0)",
        }
    }
}

/// The real-drive additions of one joint (see the module docs); [`DriveSpec::ideal`] is the
/// paper's drive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DriveSpec {
    /// K_e, motor side, V s/rad; `None`: equal to the torque constant.
    pub back_emf_constant: Option<f64>,
    /// Supply voltage limit V, V.
    pub voltage_limit: Option<f64>,
    /// Driver current limit I, A.
    pub current_limit: Option<f64>,
    /// No motor on this joint.
    pub passive: bool,
    /// The motor's thermal data (a datasheet drive; used when the scene turns the thermal
    /// model on, `dynamics/thermal.rs`).
    pub thermal: Option<crate::dynamics::thermal::ThermalParams>,
}

impl DriveSpec {
    /// The paper's drive: K_e = K_t, no limits, a motor.
    pub const fn ideal() -> Self {
        Self { back_emf_constant: None, voltage_limit: None, current_limit: None, passive: false, thermal: None }
    }
}

/// The drive train of every joint, reflected to the link side, as vectors (nv) for the RHS.
#[derive(Clone, Debug, PartialEq)]
pub struct Drives {
    /// K_m = K_t k, N m/A.
    pub km: DVector<f64>,
    /// K_e k, the back-EMF constant seen at the link, V s/rad (= K_m unless the scene gives K_e).
    pub ke: DVector<f64>,
    /// Supply voltage limit per joint, V (+∞: none).
    pub voltage_limit: Vec<f64>,
    /// Driver current limit per joint, A (+∞: none).
    pub current_limit: Vec<f64>,
    /// Joints without a motor.
    pub passive: Vec<bool>,
    /// Some voltage or current limit is finite (else the limiting is skipped).
    pub has_limits: bool,
    /// Some K_e ≠ K_t (the energy balance then has its conversion term).
    pub has_conversion: bool,
    /// R, ohm.
    pub r: DVector<f64>,
    /// L, H.
    pub l: DVector<f64>,
    /// J_m, kg m^2.
    pub jm: DVector<f64>,
    /// D_m, N m s/rad.
    pub dm: DVector<f64>,
    /// D: the joint's own viscous friction, N m s/rad.
    pub d: DVector<f64>,
    /// Inductive, or quasi-static (L = 0 on every joint: the current follows the voltage).
    pub electrical: Electrical,
    /// Some D + D_m is non-zero (else the friction terms are skipped).
    pub has_friction: bool,
}

impl Drives {
    pub fn new(motors: &[MotorParams], joint_damping: &[f64]) -> Self {
        assert_eq!(motors.len(), joint_damping.len(), "one motor per joint");
        let n = motors.len();
        Self {
            km: DVector::from_iterator(motors.len(), motors.iter().map(MotorParams::km)),
            ke: DVector::from_iterator(motors.len(), motors.iter().map(MotorParams::km)),
            voltage_limit: vec![f64::INFINITY; n],
            current_limit: vec![f64::INFINITY; n],
            passive: vec![false; n],
            has_limits: false,
            has_conversion: false,
            r: DVector::from_iterator(motors.len(), motors.iter().map(|m| m.resistance)),
            l: DVector::from_iterator(motors.len(), motors.iter().map(|m| m.inductance)),
            jm: DVector::from_iterator(motors.len(), motors.iter().map(MotorParams::jm)),
            dm: DVector::from_iterator(motors.len(), motors.iter().map(MotorParams::dm)),
            d: DVector::from_column_slice(joint_damping),
            electrical: if motors.iter().all(|m| m.inductance == 0.0) { Electrical::QuasiStatic } else { Electrical::Inductive },
            has_friction: motors.iter().zip(joint_damping).any(|(m, d)| m.dm() + d != 0.0),
        }
    }

    /// [`Drives::new`] with the real-drive additions of each joint (one per joint): K_e,
    /// the limits, passive joints (whose K_m, K_e, J_m and D_m become 0). `motors` must be those
    /// given to `new`.
    pub fn with_real_drives(mut self, motors: &[MotorParams], specs: &[DriveSpec]) -> Self {
        assert_eq!(specs.len(), self.nv(), "one drive per joint");
        for (j, (s, m)) in specs.iter().zip(motors).enumerate() {
            if let Some(ke) = s.back_emf_constant {
                self.ke[j] = ke * m.gear_ratio;
            }
            self.voltage_limit[j] = s.voltage_limit.unwrap_or(f64::INFINITY);
            self.current_limit[j] = s.current_limit.unwrap_or(f64::INFINITY);
            if s.passive {
                self.passive[j] = true;
                self.km[j] = 0.0;
                self.ke[j] = 0.0;
                self.jm[j] = 0.0;
                self.dm[j] = 0.0;
            }
        }
        self.has_limits = self.voltage_limit.iter().chain(&self.current_limit).any(|x| x.is_finite());
        self.has_conversion = (0..self.nv()).any(|j| self.ke[j] != self.km[j]);
        self.has_friction = (0..self.nv()).any(|j| self.dm[j] + self.d[j] != 0.0);
        self
    }

    /// The quasi-static current of joint j (L = 0), `(v − K_e k q̇) / R`, A.
    #[inline]
    pub fn quasi_static_current(&self, j: usize, v: f64, qd: f64) -> f64 {
        (v - self.ke[j] * qd) / self.r[j]
    }

    /// The amplifier's output for the command `v_cmd` at joint speed `qd`: the current window
    /// `|v − K_e k q̇| ≤ R I`, then the supply `|v| ≤ V` (module docs). Only called when
    /// [`Drives::has_limits`].
    #[inline]
    pub fn limited_voltage(&self, j: usize, v_cmd: f64, qd: f64) -> f64 {
        let mut v = v_cmd;
        let i_max = self.current_limit[j];
        if i_max.is_finite() {
            let emf = self.ke[j] * qd;
            // max/min, not clamp: an integrator's trial stage far from the solution (a winding
            // temperature so low that R(T) < 0, a speed of 1e8 rad/s) must give a number the
            // error control rejects, not a panic on a window whose ends cross
            let w = self.r[j] * i_max;
            v = v.max(emf - w).min(emf + w);
        }
        let v_max = self.voltage_limit[j];
        v.clamp(-v_max, v_max)
    }

    /// Quasi-static motors (L = 0) with limits: the voltage and the current for the command
    /// `v_cmd`, with `|i| ≤ I` exactly when the supply allows it (the current is clamped and
    /// the voltage follows from it), then `|v| ≤ V` exactly.
    #[inline]
    pub fn limited_quasi_static(&self, j: usize, v_cmd: f64, qd: f64) -> (f64, f64) {
        let emf = self.ke[j] * qd;
        let i_max = self.current_limit[j];
        let (mut v, mut i) = (v_cmd, (v_cmd - emf) / self.r[j]);
        if i_max.is_finite() && i.abs() > i_max {
            i = i.clamp(-i_max, i_max);
            v = self.r[j] * i + emf;
        }
        let v_max = self.voltage_limit[j];
        if v.abs() > v_max {
            v = v.clamp(-v_max, v_max);
            i = (v - emf) / self.r[j];
        }
        (v, i)
    }

    pub fn nv(&self) -> usize {
        self.km.len()
    }

    /// Eq 11 solved for the current rate of joint j, A/s (0 for quasi-static motors, which
    /// have no current state).
    #[inline]
    pub fn current_rate(&self, j: usize, v: f64, i: f64, qd: f64) -> f64 {
        match self.electrical {
            Electrical::Inductive => (v - self.r[j] * i - self.ke[j] * qd) / self.l[j],
            Electrical::QuasiStatic => 0.0,
        }
    }

    /// Eq 12: torque delivered to link j, N m.
    #[inline]
    pub fn link_torque(&self, j: usize, i: f64, qd: f64, qdd: f64) -> f64 {
        self.km[j] * i - self.jm[j] * qdd - self.dm[j] * qd
    }

    /// Back-EMF `K_e k q̇` of joint j, V.
    #[inline]
    pub fn back_emf(&self, j: usize, qd: f64) -> f64 {
        self.ke[j] * qd
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's numbers: K_m = 0.609, J_m = 0.001476, D_m = 0.09 (SCENE.md), to 1e-15.
    #[test]
    fn reflected_constants_of_the_paper_motor() {
        let m = MotorParams {
            torque_constant: 0.203, resistance: 1.1, inductance: 0.0017, rotor_inertia: 0.000164,
            gear_ratio: 3.0, gear_damping: 0.01,
        };
        assert!((m.km() - 0.609).abs() < 1e-15);
        assert!((m.jm() - 0.001476).abs() < 1e-15);
        assert!((m.dm() - 0.09).abs() < 1e-15);
    }

    fn limited() -> (MotorParams, Drives) {
        let m = MotorParams {
            torque_constant: 0.2, resistance: 2.0, inductance: 0.01, rotor_inertia: 1e-4,
            gear_ratio: 3.0, gear_damping: 0.0,
        };
        let spec = DriveSpec { back_emf_constant: Some(0.25), voltage_limit: Some(24.0), current_limit: Some(5.0), ..DriveSpec::ideal() };
        (m, Drives::new(&[m], &[0.0]).with_real_drives(&[m], &[spec]))
    }

    /// The current window `|v − K_e k q̇| ≤ R I`, then the supply: at the window's edge the
    /// inductive current cannot grow past I (di/dt = 0 at i = I), and |v| ≤ V always.
    #[test]
    fn the_driver_clips_to_the_current_window_then_the_supply() {
        let (_, d) = limited();
        assert_eq!((d.km[0], d.ke[0]), (0.2 * 3.0, 0.25 * 3.0));
        assert!(d.has_limits && d.has_conversion);
        for &(v_cmd, qd) in &[(100.0, 0.0), (-100.0, 2.0), (100.0, 20.0), (3.0, 1.0), (-30.0, -40.0)] {
            let v = d.limited_voltage(0, v_cmd, qd);
            assert!(v.abs() <= 24.0, "{v}");
            let emf = 0.75 * qd;
            // inside the window the command passes when the supply allows it
            if (v_cmd - emf).abs() <= 10.0 && v_cmd.abs() <= 24.0 {
                assert_eq!(v, v_cmd);
            }
            // eq 11 at i = ±I: the current does not grow beyond the limit
            assert!(d.current_rate(0, v, 5.0, qd) <= 1e-12 || v == -24.0 || v == 24.0, "{v_cmd} {qd}");
            assert!(d.current_rate(0, v, -5.0, qd) >= -1e-12 || v == -24.0 || v == 24.0, "{v_cmd} {qd}");
            // quasi-static: |i| ≤ I exactly when the supply does not cut first
            let (vq, i) = d.limited_quasi_static(0, v_cmd, qd);
            assert!(vq.abs() <= 24.0);
            assert!((i - (vq - emf) / 2.0).abs() <= 1e-15 * (1.0 + i.abs()), "i = {i} is not (v - K_e k q') / R");
            if (v_cmd - emf).abs() > 10.0 && (emf - 10.0).abs() <= 24.0 && (emf + 10.0).abs() <= 24.0 {
                assert_eq!(i.abs(), 5.0, "{v_cmd} {qd}");
            }
        }
    }

    /// A passive joint has no motor: nothing reflected, no torque from any current.
    #[test]
    fn a_passive_joint_has_no_motor() {
        let (m, _) = limited();
        let d = Drives::new(&[m, m], &[0.0, 0.0]).with_real_drives(&[m, m], &[DriveSpec::ideal(), DriveSpec { passive: true, ..DriveSpec::ideal() }]);
        assert_eq!((d.km[1], d.ke[1], d.jm[1], d.dm[1]), (0.0, 0.0, 0.0, 0.0));
        assert_eq!(d.link_torque(1, 3.0, 1.0, 1.0), 0.0);
        assert!(d.km[0] > 0.0 && !d.has_limits && !d.has_conversion);
    }

    /// A stalled motor (q̇ = 0) settles at i = v / R: the current ODE's fixed point, exactly.
    #[test]
    fn stalled_motor_settles_at_v_over_r() {
        let m = MotorParams {
            torque_constant: 0.2, resistance: 2.0, inductance: 0.01, rotor_inertia: 1e-4,
            gear_ratio: 1.0, gear_damping: 0.0,
        };
        let d = Drives::new(&[m], &[0.0]);
        assert_eq!(d.current_rate(0, 12.0, 6.0, 0.0), 0.0);
        // and it is approached at the electrical rate R/L: i(t) = v/R (1 - exp(-R t / L))
        let (mut i, h) = (0.0, 1e-6);
        for _ in 0..5000 {
            // implicit Euler of a linear ODE, to stay independent of the integrators
            i = (i + h * 12.0 / 0.01) / (1.0 + h * 2.0 / 0.01);
        }
        let exact = 6.0 * (1.0 - (-2.0 * 5000.0 * h / 0.01f64).exp());
        assert!((i - exact).abs() < 1e-3 * 6.0, "i = {i}, exact {exact}");
    }
}
