//! Test problems with exact solutions, for checking integrators (order, tolerance, dense output)
//! and their failure paths (a failing right-hand side, NaN, a finite-time singularity).
//!
//! Each well-posed problem implements [`ExactSolution`]: `t0()`, `y0()` and `exact(t)`, in the
//! spirit of diffsol's `test_models` (problem plus reference solution). The Kepler problem is the
//! one of Hairer, Lubich & Wanner, *Geometric Numerical Integration*, §I.2; the stiff problem is
//! Prothero & Robinson's (1974), as used in Hairer & Wanner, *Solving ODEs II*, §IV.15.
//!
//! For the implicit steppers the smooth problems also implement [`OdeJacobian`] (analytic
//! `∂f/∂y` and `∂f/∂t`), and the stiff ones [`super::SplitSystem`]; the stiff problems with
//! several components ([`StiffOscillator`], [`StiffKepler`]) are in `test_problems/stiff.rs`.
//!
//! These allocate nothing in `rhs`; `y0()` allocates (tests only).

use std::convert::Infallible;
use std::fmt;

use super::{OdeJacobian, OdeSystem};

mod stiff;
pub use self::stiff::{OscillatorSplit, StiffKepler, StiffOscillator};

/// A test problem whose exact solution is known in closed form.
pub trait ExactSolution: OdeSystem {
    /// Initial time.
    fn t0(&self) -> f64;
    /// Writes the exact solution `y(t)` (length `dim`) into `y`.
    fn exact(&self, t: f64, y: &mut [f64]);
    /// Initial state `y(t0)`.
    fn y0(&self) -> Vec<f64> {
        let mut y = vec![0.0; self.dim()];
        self.exact(self.t0(), &mut y);
        y
    }
}

/// `y' = -k y`, `y(0) = y0`; `y(t) = y0 exp(-k t)`.
#[derive(Clone, Copy, Debug)]
pub struct ExponentialDecay {
    /// Rate, 1/s.
    pub k: f64,
    /// Initial value.
    pub y0: f64,
}

impl Default for ExponentialDecay {
    fn default() -> Self {
        Self { k: 1.0, y0: 1.0 }
    }
}

impl OdeSystem for ExponentialDecay {
    type Error = Infallible;
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), Infallible> {
        dydt[0] = -self.k * y[0];
        Ok(())
    }
}

impl OdeJacobian for ExponentialDecay {
    fn jacobian(
        &mut self,
        _t: f64,
        _y: &[f64],
        _fy: &[f64],
        jac: &mut [f64],
    ) -> Result<(), Infallible> {
        jac[0] = -self.k;
        Ok(())
    }
    fn time_derivative(
        &mut self,
        _t: f64,
        _y: &[f64],
        _fy: &[f64],
        dfdt: &mut [f64],
    ) -> Result<bool, Infallible> {
        dfdt[0] = 0.0;
        Ok(true)
    }
}

impl ExactSolution for ExponentialDecay {
    fn t0(&self) -> f64 {
        0.0
    }
    fn exact(&self, t: f64, y: &mut [f64]) {
        y[0] = self.y0 * (-self.k * t).exp();
    }
}

/// Harmonic oscillator `x'' = -omega^2 x` as `y = [x, v]`, `x(0) = 1`, `v(0) = 0`;
/// `x = cos(omega t)`, `v = -omega sin(omega t)`.
#[derive(Clone, Copy, Debug)]
pub struct HarmonicOscillator {
    /// Angular frequency, rad/s.
    pub omega: f64,
}

impl Default for HarmonicOscillator {
    fn default() -> Self {
        Self { omega: 1.0 }
    }
}

impl OdeSystem for HarmonicOscillator {
    type Error = Infallible;
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), Infallible> {
        dydt[0] = y[1];
        dydt[1] = -self.omega * self.omega * y[0];
        Ok(())
    }
}

impl OdeJacobian for HarmonicOscillator {
    fn jacobian(
        &mut self,
        _t: f64,
        _y: &[f64],
        _fy: &[f64],
        jac: &mut [f64],
    ) -> Result<(), Infallible> {
        jac.copy_from_slice(&[0.0, 1.0, -self.omega * self.omega, 0.0]);
        Ok(())
    }
    fn time_derivative(
        &mut self,
        _t: f64,
        _y: &[f64],
        _fy: &[f64],
        dfdt: &mut [f64],
    ) -> Result<bool, Infallible> {
        dfdt.fill(0.0);
        Ok(true)
    }
}

impl ExactSolution for HarmonicOscillator {
    fn t0(&self) -> f64 {
        0.0
    }
    fn exact(&self, t: f64, y: &mut [f64]) {
        let (s, c) = (self.omega * t).sin_cos();
        y[0] = c;
        y[1] = -self.omega * s;
    }
}

/// Nonlinear scalar problem `y' = -2 t y^2`, `y(0) = 1`; `y(t) = 1 / (1 + t^2)`.
#[derive(Clone, Copy, Debug, Default)]
pub struct RationalDecay;

impl OdeSystem for RationalDecay {
    type Error = Infallible;
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), Infallible> {
        dydt[0] = -2.0 * t * y[0] * y[0];
        Ok(())
    }
}

impl OdeJacobian for RationalDecay {
    fn jacobian(
        &mut self,
        t: f64,
        y: &[f64],
        _fy: &[f64],
        jac: &mut [f64],
    ) -> Result<(), Infallible> {
        jac[0] = -4.0 * t * y[0];
        Ok(())
    }
    fn time_derivative(
        &mut self,
        _t: f64,
        y: &[f64],
        _fy: &[f64],
        dfdt: &mut [f64],
    ) -> Result<bool, Infallible> {
        dfdt[0] = -2.0 * y[0] * y[0];
        Ok(true)
    }
}

impl ExactSolution for RationalDecay {
    fn t0(&self) -> f64 {
        0.0
    }
    fn exact(&self, t: f64, y: &mut [f64]) {
        y[0] = 1.0 / (1.0 + t * t);
    }
}

/// Kepler two-body problem (gravitational parameter 1, semi-major axis 1, period 2π),
/// `y = [qx, qy, px, py]`, `q'' = -q / |q|^3`, starting at pericentre:
/// `q(0) = (1 - e, 0)`, `p(0) = (0, sqrt((1 + e) / (1 - e)))` (Hairer, Lubich & Wanner, GNI §I.2).
///
/// The exact solution solves Kepler's equation `E - e sin E = t` for the eccentric anomaly `E`;
/// then `q = (cos E - e, sqrt(1 - e^2) sin E)` and
/// `p = (-sin E, sqrt(1 - e^2) cos E) / (1 - e cos E)`.
#[derive(Clone, Copy, Debug)]
pub struct Kepler {
    /// Eccentricity, `0 <= e < 1`.
    pub e: f64,
}

impl Default for Kepler {
    fn default() -> Self {
        Self { e: 0.5 }
    }
}

impl Kepler {
    /// Eccentric anomaly for mean anomaly `m` (Newton on Kepler's equation).
    fn eccentric_anomaly(&self, m: f64) -> f64 {
        let tau = std::f64::consts::TAU;
        let turns = (m / tau).floor();
        let m_red = m - turns * tau;
        let mut ecc = if self.e > 0.8 {
            std::f64::consts::PI
        } else {
            m_red
        };
        for _ in 0..100 {
            let d = (ecc - self.e * ecc.sin() - m_red) / (1.0 - self.e * ecc.cos());
            ecc -= d;
            if d.abs() < 1e-15 {
                break;
            }
        }
        ecc + turns * tau
    }
}

impl OdeSystem for Kepler {
    type Error = Infallible;
    fn dim(&self) -> usize {
        4
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), Infallible> {
        let r2 = y[0] * y[0] + y[1] * y[1];
        let r3 = r2 * r2.sqrt();
        dydt[0] = y[2];
        dydt[1] = y[3];
        dydt[2] = -y[0] / r3;
        dydt[3] = -y[1] / r3;
        Ok(())
    }
}

impl OdeJacobian for Kepler {
    fn jacobian(
        &mut self,
        _t: f64,
        y: &[f64],
        _fy: &[f64],
        jac: &mut [f64],
    ) -> Result<(), Infallible> {
        kepler_jacobian(y, 4, jac);
        Ok(())
    }
    fn time_derivative(
        &mut self,
        _t: f64,
        _y: &[f64],
        _fy: &[f64],
        dfdt: &mut [f64],
    ) -> Result<bool, Infallible> {
        dfdt.fill(0.0);
        Ok(true)
    }
}

/// Writes the Kepler Jacobian (rows and columns 0..4 of `y = [qx, qy, px, py, ..]`) into the
/// row-major `n x n` matrix `jac`, zeroing everything else.
pub(crate) fn kepler_jacobian(y: &[f64], n: usize, jac: &mut [f64]) {
    let (qx, qy) = (y[0], y[1]);
    let r2 = qx * qx + qy * qy;
    let r = r2.sqrt();
    let (r3, r5) = (r2 * r, r2 * r2 * r);
    jac.fill(0.0);
    jac[2] = 1.0; // d qx' / d px
    jac[n + 3] = 1.0; // d qy' / d py
    jac[2 * n] = -1.0 / r3 + 3.0 * qx * qx / r5;
    jac[2 * n + 1] = 3.0 * qx * qy / r5;
    jac[3 * n] = 3.0 * qx * qy / r5;
    jac[3 * n + 1] = -1.0 / r3 + 3.0 * qy * qy / r5;
}

impl ExactSolution for Kepler {
    fn t0(&self) -> f64 {
        0.0
    }
    fn exact(&self, t: f64, y: &mut [f64]) {
        let ecc = self.eccentric_anomaly(t);
        let (s, c) = ecc.sin_cos();
        let b = (1.0 - self.e * self.e).sqrt();
        let denom = 1.0 - self.e * c;
        y[0] = c - self.e;
        y[1] = b * s;
        y[2] = -s / denom;
        y[3] = b * c / denom;
    }
}

/// Stiff linear problem of Prothero & Robinson (1974) (Hairer & Wanner, Solving ODEs II, §IV.15):
/// `y' = lambda (y - cos t) - sin t`, `y(0) = y0`; `y(t) = cos t + (y0 - 1) exp(lambda t)`.
///
/// With `lambda = -1e4` and `y0 = 1` the solution is the smooth `cos t`, yet an explicit
/// method must keep `h |lambda|` inside its stability region (about 3.3 for DOPRI5), so the step
/// count is set by stability, not by the tolerance.
#[derive(Clone, Copy, Debug)]
pub struct StiffLinear {
    /// Eigenvalue, 1/s (negative).
    pub lambda: f64,
    /// Initial value.
    pub y0: f64,
}

impl Default for StiffLinear {
    fn default() -> Self {
        Self {
            lambda: -1e4,
            y0: 1.0,
        }
    }
}

impl OdeSystem for StiffLinear {
    type Error = Infallible;
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), Infallible> {
        let (s, c) = t.sin_cos();
        dydt[0] = self.lambda * (y[0] - c) - s;
        Ok(())
    }
}

impl OdeJacobian for StiffLinear {
    fn jacobian(
        &mut self,
        _t: f64,
        _y: &[f64],
        _fy: &[f64],
        jac: &mut [f64],
    ) -> Result<(), Infallible> {
        jac[0] = self.lambda;
        Ok(())
    }
    fn time_derivative(
        &mut self,
        t: f64,
        _y: &[f64],
        _fy: &[f64],
        dfdt: &mut [f64],
    ) -> Result<bool, Infallible> {
        let (s, c) = t.sin_cos();
        dfdt[0] = self.lambda * s - c;
        Ok(true)
    }
}

/// Split for [`super::ArkImex`]: the whole equation implicit, `f_I = f`, `f_E = 0`. (With the
/// forcing `-sin t` in `f_E` instead, the explicit stages' low stage order gives an `O(h^2)`
/// local error on this stiff component that no error estimate sees well.)
impl super::SplitSystem for StiffLinear {
    fn rhs_split(
        &mut self,
        t: f64,
        y: &[f64],
        f_e: &mut [f64],
        f_i: &mut [f64],
    ) -> Result<(), Infallible> {
        let (s, c) = t.sin_cos();
        f_e[0] = 0.0;
        f_i[0] = self.lambda * (y[0] - c) - s;
        Ok(())
    }
    fn solve_implicit(
        &mut self,
        t: f64,
        gamma: f64,
        r: &[f64],
        z: &mut [f64],
    ) -> Result<(), Infallible> {
        // z - gamma (lambda (z - cos t) - sin t) = r
        let (s, c) = t.sin_cos();
        z[0] = (r[0] - gamma * (self.lambda * c + s)) / (1.0 - gamma * self.lambda);
        Ok(())
    }
}

impl ExactSolution for StiffLinear {
    fn t0(&self) -> f64 {
        0.0
    }
    fn exact(&self, t: f64, y: &mut [f64]) {
        y[0] = t.cos() + (self.y0 - 1.0) * (self.lambda * t).exp();
    }
}

/// `y' = y^2`, `y(0) = 1`; `y(t) = 1 / (1 - t)`, which blows up at `t = 1`.
#[derive(Clone, Copy, Debug, Default)]
pub struct RiccatiBlowup;

impl OdeSystem for RiccatiBlowup {
    type Error = Infallible;
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), Infallible> {
        dydt[0] = y[0] * y[0];
        Ok(())
    }
}

impl ExactSolution for RiccatiBlowup {
    fn t0(&self) -> f64 {
        0.0
    }
    /// Valid for `t < 1`.
    fn exact(&self, t: f64, y: &mut [f64]) {
        y[0] = 1.0 / (1.0 - t);
    }
}

/// The error returned by [`FailingRhs`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RhsFailure {
    /// Time of the failing evaluation.
    pub t: f64,
}

impl fmt::Display for RhsFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "test system failed on purpose at t = {}", self.t)
    }
}

impl std::error::Error for RhsFailure {}

/// `y' = -y` that returns `Err(RhsFailure { t })` for every evaluation at `t >= t_fail`
/// (pass-through of system errors).
#[derive(Clone, Copy, Debug)]
pub struct FailingRhs {
    /// First time at which `rhs` fails.
    pub t_fail: f64,
}

impl OdeSystem for FailingRhs {
    type Error = RhsFailure;
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), RhsFailure> {
        if t >= self.t_fail {
            return Err(RhsFailure { t });
        }
        dydt[0] = -y[0];
        Ok(())
    }
}

impl ExactSolution for FailingRhs {
    fn t0(&self) -> f64 {
        0.0
    }
    /// Valid for `t < t_fail`.
    fn exact(&self, t: f64, y: &mut [f64]) {
        y[0] = (-t).exp();
    }
}

/// Two uncoupled decays `y_i' = -y_i` whose derivative component `index` becomes NaN for
/// `t >= t_nan`, the way an unguarded singular solve inside a dynamics model does.
#[derive(Clone, Copy, Debug)]
pub struct NanAfter {
    /// First time at which `rhs` produces NaN.
    pub t_nan: f64,
    /// Component that turns NaN (`< 2`).
    pub index: usize,
}

impl OdeSystem for NanAfter {
    type Error = Infallible;
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), Infallible> {
        dydt[0] = -y[0];
        dydt[1] = -y[1];
        if t >= self.t_nan {
            dydt[self.index] = f64::NAN;
        }
        Ok(())
    }
}

impl ExactSolution for NanAfter {
    fn t0(&self) -> f64 {
        0.0
    }
    /// Valid for `t < t_nan`.
    fn exact(&self, t: f64, y: &mut [f64]) {
        y[0] = (-t).exp();
        y[1] = (-t).exp();
    }
}

#[cfg(test)]
mod tests;
