//! Stiff test problems with several components, exact solutions, analytic Jacobians and
//! IMEX splits.
//!
//! - [`StiffOscillator`]: a motor-driven joint in the shape of the robot's linearised
//!   electromechanics — position `q`, velocity `v`, current `i` with `q' = v`, `v' = a i`
//!   (`a` = torque constant / inertia) and a PD voltage law tracking a slow (0.2 Hz) reference,
//!   `a i' = -p (q - q_r) - c (v - v_r) - rho (a i - a i_r) + a i_r'`. The coefficients are
//!   chosen so that the eigenvalues are exactly `-sigma ± i beta` (default `-450 ± 1900i` 1/s,
//!   the lightly damped electrical mode) and `-mu` (the position loop). With `e = y - phi`,
//!   `phi = (q_r, v_r, i_r)` (`q_r = sin(omega t)`, `v_r = q_r'`, `a i_r = v_r'`), `(e_q, e_v,
//!   a e_i)` obeys `e' = A e` for the companion matrix `A`, so the solution is `phi` plus a
//!   transient in closed form (a Prothero–Robinson construction, HNW II §IV.15, for a system).
//!   Default `a = 1e3`: the current is then slaved to the velocity error with
//!   `c / (rho a) ≈ 4.2` A per rad/s, a servo-like `(K_d + K_m) / R`.
//! - [`StiffKepler`]: the Kepler problem (non-stiff, nonlinear, explicit) coupled to a stiff
//!   Prothero–Robinson component `w' = -k (w - cos t) - sin t` (implicit), which feeds back
//!   nonlinearly into the Kepler part; exact solution Kepler's and `w = cos t`. For the IMEX
//!   order test.

use std::convert::Infallible;

use super::super::{OdeJacobian, OdeSystem, SplitSystem};
use super::{kepler_jacobian, ExactSolution, Kepler};

/// Which part of [`StiffOscillator`] an IMEX method treats implicitly.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OscillatorSplit {
    /// Only the current equation `i' = ...` (`f_I = [0, 0, i']`), the robot's natural split:
    /// diagonal in the currents. The velocity–current loop `v' = i` stays explicit.
    Current,
    /// The current equation and the torque term `v' = i` (`f_I = [0, i, i']`).
    VelocityCurrent,
    /// Everything (`f_E = 0`): the ESDIRK part alone.
    Full,
}

/// The motor-joint oscillator described in the module docs; `y = [q, v, i]`.
#[derive(Clone, Copy, Debug)]
pub struct StiffOscillator {
    /// Decay rate of the electrical mode, 1/s (> 0).
    pub sigma: f64,
    /// Frequency of the electrical mode, rad/s (> 0).
    pub beta: f64,
    /// Decay rate of the position loop, 1/s (> 0, != sigma).
    pub mu: f64,
    /// Angular frequency of the reference `q_r = sin(omega t)`, rad/s.
    pub omega: f64,
    /// Torque gain `a` in `v' = a i` (> 0): the unit of the current. The current is slaved
    /// to the velocity error with gain `c / (rho a)` (about 4160 / a), so with one tolerance for
    /// all components a small `a` makes the current the component that limits the step.
    pub gain: f64,
    /// Initial deviation `y(0) - phi(0)` (starts the transient).
    pub dy0: [f64; 3],
    /// IMEX split.
    pub split: OscillatorSplit,
}

impl Default for StiffOscillator {
    fn default() -> Self {
        Self {
            sigma: 450.0,
            beta: 1900.0,
            mu: 20.0,
            omega: std::f64::consts::TAU * 0.2,
            gain: 1e3,
            dy0: [1e-3, 0.0, 1e-3],
            split: OscillatorSplit::Current,
        }
    }
}

impl StiffOscillator {
    /// `(p, c, rho)`: `s^3 + rho s^2 + c s + p = ((s + sigma)^2 + beta^2) (s + mu)`.
    pub fn coefficients(&self) -> (f64, f64, f64) {
        let w2 = self.sigma * self.sigma + self.beta * self.beta;
        (
            w2 * self.mu,
            w2 + 2.0 * self.sigma * self.mu,
            2.0 * self.sigma + self.mu,
        )
    }

    /// Reference `phi(t)` and its first two derivatives, each `[q_r, v_r, a i_r]` (the third
    /// component is an acceleration).
    fn reference(&self, t: f64) -> [[f64; 3]; 3] {
        let w = self.omega;
        let (s, c) = (w * t).sin_cos();
        [
            [s, w * c, -w * w * s],
            [w * c, -w * w * s, -w * w * w * c],
            [-w * w * s, -w * w * w * c, w * w * w * w * s],
        ]
    }

    /// `(-p (z0 - q_r) - c (z1 - v_r) + rho a i_r + a i_r') / a`: the current equation
    /// without `-rho i`.
    fn g(&self, ph: &[[f64; 3]; 3], z0: f64, z1: f64) -> f64 {
        let (p, c, rho) = self.coefficients();
        (-p * (z0 - ph[0][0]) - c * (z1 - ph[0][1]) + rho * ph[0][2] + ph[1][2]) / self.gain
    }

    /// Transient coefficients `(C1, C2, C3)` of `e_q = C1 e^(-mu t) + e^(-sigma t) (C2 cos +
    /// C3 sin)(beta t)`, from `e(0) = (dy0_0, dy0_1, a dy0_2)`, `e = (e_q, e_q', e_q'')`
    /// (Cramer's rule).
    fn transient(&self) -> [f64; 3] {
        let (s, b, m) = (self.sigma, self.beta, self.mu);
        let a = [
            [1.0, 1.0, 0.0],
            [-m, -s, b],
            [m * m, s * s - b * b, -2.0 * s * b],
        ];
        let det3 = |a: &[[f64; 3]; 3]| {
            a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
                - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
                + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
        };
        let d = det3(&a);
        let mut out = [0.0; 3];
        for (k, o) in out.iter_mut().enumerate() {
            let mut ak = a;
            let e0 = [self.dy0[0], self.dy0[1], self.gain * self.dy0[2]];
            for (row, v) in ak.iter_mut().zip(e0) {
                row[k] = v;
            }
            *o = det3(&ak) / d;
        }
        out
    }
}

impl OdeSystem for StiffOscillator {
    type Error = Infallible;
    fn dim(&self) -> usize {
        3
    }
    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), Infallible> {
        let ph = self.reference(t);
        let (_, _, rho) = self.coefficients();
        dydt[0] = y[1];
        dydt[1] = self.gain * y[2];
        dydt[2] = self.g(&ph, y[0], y[1]) - rho * y[2];
        Ok(())
    }
}

impl OdeJacobian for StiffOscillator {
    fn jacobian(
        &mut self,
        _t: f64,
        _y: &[f64],
        _fy: &[f64],
        jac: &mut [f64],
    ) -> Result<(), Infallible> {
        let (p, c, rho) = self.coefficients();
        let a = self.gain;
        jac.copy_from_slice(&[0.0, 1.0, 0.0, 0.0, 0.0, a, -p / a, -c / a, -rho]);
        Ok(())
    }
    fn time_derivative(
        &mut self,
        t: f64,
        _y: &[f64],
        _fy: &[f64],
        dfdt: &mut [f64],
    ) -> Result<bool, Infallible> {
        let (p, c, rho) = self.coefficients();
        let ph = self.reference(t);
        // d/dt of (-p (q - q_r) - c (v - v_r) + rho a i_r + a i_r') / a - rho i
        dfdt[0] = 0.0;
        dfdt[1] = 0.0;
        dfdt[2] = (p * ph[1][0] + c * ph[1][1] + rho * ph[1][2] + ph[2][2]) / self.gain;
        Ok(true)
    }
}

impl SplitSystem for StiffOscillator {
    fn rhs_split(
        &mut self,
        t: f64,
        y: &[f64],
        f_e: &mut [f64],
        f_i: &mut [f64],
    ) -> Result<(), Infallible> {
        let ph = self.reference(t);
        let (_, _, rho) = self.coefficients();
        let di = self.g(&ph, y[0], y[1]) - rho * y[2];
        match self.split {
            OscillatorSplit::Current => {
                f_e.copy_from_slice(&[y[1], self.gain * y[2], 0.0]);
                f_i.copy_from_slice(&[0.0, 0.0, di]);
            }
            OscillatorSplit::VelocityCurrent => {
                f_e.copy_from_slice(&[y[1], 0.0, 0.0]);
                f_i.copy_from_slice(&[0.0, self.gain * y[2], di]);
            }
            OscillatorSplit::Full => {
                f_e.fill(0.0);
                f_i.copy_from_slice(&[y[1], self.gain * y[2], di]);
            }
        }
        Ok(())
    }

    /// Closed form by substitution (`f_I` is linear): with `g(z0, z1)` the current equation
    /// without `-rho i`,
    /// - `Current`: `z0 = r0`, `z1 = r1`, `z2 (1 + gamma rho) = r2 + gamma g(z0, z1)`;
    /// - `VelocityCurrent`: `z0 = r0`, `z2 (1 + gamma rho + gamma^2 c) = r2 + gamma g(r0, r1)`,
    ///   `z1 = r1 + gamma a z2`;
    /// - `Full`: `z2 (1 + gamma rho + gamma^2 c + gamma^3 p) = r2 + gamma g(r0 + gamma r1, r1)`,
    ///   `z1 = r1 + gamma a z2`, `z0 = r0 + gamma z1`.
    fn solve_implicit(
        &mut self,
        t: f64,
        gamma: f64,
        r: &[f64],
        z: &mut [f64],
    ) -> Result<(), Infallible> {
        let ph = self.reference(t);
        let (p, c, rho) = self.coefficients();
        match self.split {
            OscillatorSplit::Current => {
                z[0] = r[0];
                z[1] = r[1];
                z[2] = (r[2] + gamma * self.g(&ph, r[0], r[1])) / (1.0 + gamma * rho);
            }
            OscillatorSplit::VelocityCurrent => {
                z[0] = r[0];
                z[2] = (r[2] + gamma * self.g(&ph, r[0], r[1]))
                    / (1.0 + gamma * rho + gamma * gamma * c);
                z[1] = r[1] + gamma * self.gain * z[2];
            }
            OscillatorSplit::Full => {
                let g2 = gamma * gamma;
                z[2] = (r[2] + gamma * self.g(&ph, r[0] + gamma * r[1], r[1]))
                    / (1.0 + gamma * rho + g2 * c + g2 * gamma * p);
                z[1] = r[1] + gamma * self.gain * z[2];
                z[0] = r[0] + gamma * z[1];
            }
        }
        Ok(())
    }
}

impl ExactSolution for StiffOscillator {
    fn t0(&self) -> f64 {
        0.0
    }
    fn exact(&self, t: f64, y: &mut [f64]) {
        let [c1, c2, c3] = self.transient();
        let (s, b, m) = (self.sigma, self.beta, self.mu);
        let em = (-m * t).exp();
        let es = (-s * t).exp();
        let (sn, cs) = (b * t).sin_cos();
        let gc = [
            cs,
            -s * cs - b * sn,
            (s * s - b * b) * cs + 2.0 * s * b * sn,
        ];
        let gs = [
            sn,
            -s * sn + b * cs,
            (s * s - b * b) * sn - 2.0 * s * b * cs,
        ];
        let mp = [1.0, -m, m * m];
        let ph = self.reference(t);
        for k in 0..3 {
            y[k] = ph[0][k] + c1 * mp[k] * em + es * (c2 * gc[k] + c3 * gs[k]);
        }
        y[2] /= self.gain;
    }
}

/// Kepler problem (`e` as in [`Kepler`]) plus a stiff Prothero–Robinson component `w`:
/// `y = [qx, qy, px, py, w]`, `w' = -k (w - cos t) - sin t`, and the back-coupling
/// `px' = -qx / r^3 + (w - cos t) qy`, which vanishes on the exact solution `w = cos t`.
///
/// Split: `f_I = [0, 0, 0, 0, w']` (the whole stiff equation), the Kepler part explicit.
#[derive(Clone, Copy, Debug)]
pub struct StiffKepler {
    /// Eccentricity, `0 <= e < 1`.
    pub e: f64,
    /// Relaxation rate of `w`, 1/s (> 0; stiff when large).
    pub k: f64,
}

impl Default for StiffKepler {
    fn default() -> Self {
        Self { e: 0.3, k: 1e4 }
    }
}

impl OdeSystem for StiffKepler {
    type Error = Infallible;
    fn dim(&self) -> usize {
        5
    }
    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), Infallible> {
        let (mut fe, mut fi) = ([0.0; 5], [0.0; 5]);
        self.rhs_split(t, y, &mut fe, &mut fi)?;
        for i in 0..5 {
            dydt[i] = fe[i] + fi[i];
        }
        Ok(())
    }
}

impl SplitSystem for StiffKepler {
    fn rhs_split(
        &mut self,
        t: f64,
        y: &[f64],
        f_e: &mut [f64],
        f_i: &mut [f64],
    ) -> Result<(), Infallible> {
        let r2 = y[0] * y[0] + y[1] * y[1];
        let r3 = r2 * r2.sqrt();
        let (s, c) = t.sin_cos();
        f_e[0] = y[2];
        f_e[1] = y[3];
        f_e[2] = -y[0] / r3 + (y[4] - c) * y[1];
        f_e[3] = -y[1] / r3;
        f_e[4] = 0.0;
        f_i[..4].fill(0.0);
        f_i[4] = -self.k * (y[4] - c) - s;
        Ok(())
    }
    /// `z_j = r_j` (j < 4), `z4 (1 + gamma k) = r4 + gamma (k cos t - sin t)`.
    fn solve_implicit(
        &mut self,
        t: f64,
        gamma: f64,
        r: &[f64],
        z: &mut [f64],
    ) -> Result<(), Infallible> {
        let (s, c) = t.sin_cos();
        z[..4].copy_from_slice(&r[..4]);
        z[4] = (r[4] + gamma * (self.k * c - s)) / (1.0 + gamma * self.k);
        Ok(())
    }
}

impl OdeJacobian for StiffKepler {
    fn jacobian(
        &mut self,
        t: f64,
        y: &[f64],
        _fy: &[f64],
        jac: &mut [f64],
    ) -> Result<(), Infallible> {
        let n = 5;
        kepler_jacobian(y, n, jac);
        // back-coupling (w - cos t) qy in px'
        jac[2 * n + 1] += y[4] - t.cos();
        jac[2 * n + 4] = y[1];
        jac[4 * n + 4] = -self.k;
        Ok(())
    }
    fn time_derivative(
        &mut self,
        t: f64,
        y: &[f64],
        _fy: &[f64],
        dfdt: &mut [f64],
    ) -> Result<bool, Infallible> {
        let (s, c) = t.sin_cos();
        dfdt.fill(0.0);
        dfdt[2] = s * y[1];
        dfdt[4] = -self.k * s - c;
        Ok(true)
    }
}

impl ExactSolution for StiffKepler {
    fn t0(&self) -> f64 {
        0.0
    }
    fn exact(&self, t: f64, y: &mut [f64]) {
        Kepler { e: self.e }.exact(t, &mut y[..4]);
        y[4] = t.cos();
    }
}
