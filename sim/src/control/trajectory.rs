//! The hand's target: a horizontal circle run at constant speed (the paper's §4),
//! `r_d(t) = c + ρ (cos φ(t), sin φ(t), 0)`, `φ(t) = φ_0 ± 2π t / T` (+ counter-clockwise seen
//! from above, i.e. about +z), with its exact time derivative; optionally plus a step
//! `Δr H(t − t_s)` (the derivative of the step, a Dirac, is left out of ṙ_d).

use nalgebra::Vector3;

#[derive(Clone, Debug, PartialEq)]
pub struct Circle {
    /// Centre, world frame, m.
    pub center: Vector3<f64>,
    /// Radius, m.
    pub radius: f64,
    /// Time of one turn, s.
    pub period: f64,
    /// Phase at t = 0, rad, measured from +x towards +y.
    pub phase: f64,
    /// +1 counter-clockwise seen from above, −1 clockwise.
    pub direction: f64,
    /// A jump of the target: (time, offset), s and m.
    pub step: Option<(f64, Vector3<f64>)>,
}

impl Circle {
    fn angle(&self, t: f64) -> f64 {
        self.phase + self.direction * 2.0 * std::f64::consts::PI * t / self.period
    }

    /// `r_d(t)`, world frame, m.
    pub fn position(&self, t: f64) -> Vector3<f64> {
        let a = self.angle(t);
        let jump = match self.step {
            Some((ts, dr)) if t >= ts => dr,
            _ => Vector3::zeros(),
        };
        self.center + Vector3::new(a.cos(), a.sin(), 0.0) * self.radius + jump
    }

    /// `ṙ_d(t)`, world frame, m/s.
    pub fn velocity(&self, t: f64) -> Vector3<f64> {
        let a = self.angle(t);
        let w = self.direction * 2.0 * std::f64::consts::PI / self.period;
        Vector3::new(-a.sin(), a.cos(), 0.0) * (self.radius * w)
    }

    /// `r̈_d(t)`, world frame, m/s² (the step's derivatives left out, as in ṙ_d).
    pub fn acceleration(&self, t: f64) -> Vector3<f64> {
        let a = self.angle(t);
        let w = self.direction * 2.0 * std::f64::consts::PI / self.period;
        Vector3::new(a.cos(), a.sin(), 0.0) * (-self.radius * w * w)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper scene's circle starts at c + ρ(1/√2, 1/√2, 0) and its velocity is the exact
    /// derivative (central difference, h = 1e-6, tol 1e-8).
    #[test]
    fn start_point_and_derivative() {
        let c = Circle {
            center: Vector3::new(1.5, 1.5, 0.4), radius: 0.1, period: 5.0,
            phase: std::f64::consts::FRAC_PI_4, direction: 1.0, step: None,
        };
        let s = 0.1 / 2f64.sqrt();
        assert!((c.position(0.0) - Vector3::new(1.5 + s, 1.5 + s, 0.4)).norm() < 1e-15);
        for t in [0.0, 0.7, 2.5, 4.9] {
            let h = 1e-6;
            let fd = (c.position(t + h) - c.position(t - h)) / (2.0 * h);
            assert!((fd - c.velocity(t)).norm() < 1e-8);
        }
        // one full turn in one period, counter-clockwise: the z component of r x v is positive
        assert!((c.position(5.0) - c.position(0.0)).norm() < 1e-14);
        let r = c.position(1.0) - c.center;
        assert!(r.cross(&c.velocity(1.0)).z > 0.0);
    }
}
