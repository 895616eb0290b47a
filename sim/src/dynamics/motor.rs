//! DC motors through a gear train, the paper's eqs 1–12 (after 神崎, *基礎メカトロニクス*, 1994):
//! armature circuit `L di/dt = v − R i − K_m q̇` (eq 11) and the torque delivered to the link
//! `τ = K_m i − J_m q̈ − D_m q̇` (eq 12), with, for a motor of torque/back-EMF constant K, rotor
//! inertia I_m, gear ratio k and gear viscous friction d_m: `K_m = K k`, `J_m = I_m k^2`,
//! `D_m = d_m k^2` (eqs 9–10). Angles and speeds are those of the link side of the gear.
//!
//! With L = 0 on every joint the current is algebraic (quasi-static): `i = (v − K_m q̇) / R`,
//! and the motor is a torque source with back-EMF damping; no electrical state is integrated.

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

/// The drive train of every joint, reflected to the link side, as vectors (nv) for the RHS.
#[derive(Clone, Debug, PartialEq)]
pub struct Drives {
    /// K_m, N m/A.
    pub km: DVector<f64>,
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
        Self {
            km: DVector::from_iterator(motors.len(), motors.iter().map(MotorParams::km)),
            r: DVector::from_iterator(motors.len(), motors.iter().map(|m| m.resistance)),
            l: DVector::from_iterator(motors.len(), motors.iter().map(|m| m.inductance)),
            jm: DVector::from_iterator(motors.len(), motors.iter().map(MotorParams::jm)),
            dm: DVector::from_iterator(motors.len(), motors.iter().map(MotorParams::dm)),
            d: DVector::from_column_slice(joint_damping),
            electrical: if motors.iter().all(|m| m.inductance == 0.0) { Electrical::QuasiStatic } else { Electrical::Inductive },
            has_friction: motors.iter().zip(joint_damping).any(|(m, d)| m.dm() + d != 0.0),
        }
    }

    /// The quasi-static current of joint j (L = 0), `(v − K_m q̇) / R`, A.
    #[inline]
    pub fn quasi_static_current(&self, j: usize, v: f64, qd: f64) -> f64 {
        (v - self.km[j] * qd) / self.r[j]
    }

    pub fn nv(&self) -> usize {
        self.km.len()
    }

    /// Eq 11 solved for the current rate of joint j, A/s (0 for quasi-static motors, which
    /// have no current state).
    #[inline]
    pub fn current_rate(&self, j: usize, v: f64, i: f64, qd: f64) -> f64 {
        match self.electrical {
            Electrical::Inductive => (v - self.r[j] * i - self.km[j] * qd) / self.l[j],
            Electrical::QuasiStatic => 0.0,
        }
    }

    /// Eq 12: torque delivered to link j, N m.
    #[inline]
    pub fn link_torque(&self, j: usize, i: f64, qd: f64, qdd: f64) -> f64 {
        self.km[j] * i - self.jm[j] * qdd - self.dm[j] * qd
    }

    /// Back-EMF `K_m q̇` of joint j, V.
    #[inline]
    pub fn back_emf(&self, j: usize, qd: f64) -> f64 {
        self.km[j] * qd
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
