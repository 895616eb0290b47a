//! The paper's controller, eq 27: PD on the motor voltage, `v = k_p (q_d − q) + k_d (q̇_d − q̇)`,
//! with diagonal gains and no voltage limit. Gains are in V/rad and V s/rad.

use nalgebra::DVector;

#[derive(Clone, Debug, PartialEq)]
pub struct PdGains {
    /// k_p per joint, V/rad.
    pub kp: DVector<f64>,
    /// k_d per joint, V s/rad.
    pub kd: DVector<f64>,
}

impl PdGains {
    /// Eq 27 for every joint, written into `voltage` (nv), V.
    #[inline]
    pub fn voltage(&self, q: &[f64], qd: &[f64], q_des: &[f64], qd_des: &[f64], voltage: &mut [f64]) {
        for j in 0..voltage.len() {
            voltage[j] = self.kp[j] * (q_des[j] - q[j]) + self.kd[j] * (qd_des[j] - qd[j]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eq_27_per_joint() {
        let g = PdGains { kp: DVector::from_vec(vec![500.0, 10.0]), kd: DVector::from_vec(vec![20.0, 1.0]) };
        let mut v = [0.0; 2];
        g.voltage(&[0.1, -1.0], &[0.5, 0.0], &[0.2, 1.0], &[0.0, 2.0], &mut v);
        assert!((v[0] - (500.0 * 0.1 + 20.0 * -0.5)).abs() < 1e-12);
        assert!((v[1] - (10.0 * 2.0 + 1.0 * 2.0)).abs() < 1e-12);
    }
}
