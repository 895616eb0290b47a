//! Finite-difference Jacobians for systems without an analytic one.
//!
//! Forward differences, one column per evaluation of `f` ([`super::OdeSystem::rhs_column`],
//! which lets a system reuse the work of the components a column does not move; HNW II §IV.8, "Jacobian by finite
//! differences"; as in Hairer's `radau5.f`/`rodas.f`), with the increment
//! `delta_j = sqrt(eps) max(|y_j|, 1e-5)`, signed like `y_j` (positive for `y_j = 0`), and
//! divided by the increment actually represented (`(y_j + delta_j) - y_j`). The truncation
//! error is `O(delta_j |f''|)` and the rounding error `O(eps |f| / delta_j)`, so columns of
//! components that sit near 0 are the least accurate. A Rosenbrock-W method
//! ([`super::Rosenbrock`]) keeps its order with such an approximation.

use super::{OdeJacobian, OdeSystem, Watch};

/// The forward-difference increment of a column, `delta_j = sqrt(noise) max(|y_j|, floor)`:
/// the size that balances the truncation error `delta |f''| / 2` against the rounding error
/// `noise |f| / delta` when `f` is computed with relative noise `noise` (≥ eps) and the
/// components have natural size `floor` (Gill, Murray & Wright, *Practical Optimization*,
/// Academic Press 1981, §8.6.2, "finite-difference intervals"; Moré & Wild, "Estimating
/// derivatives of noisy simulations", ACM TOMS 38 (2012) 19). A right-hand side that sums many
/// rounded terms (an arm's RNEA, CRBA and Cholesky) is noisier than eps, and differencing it
/// with `sqrt(eps)` gives a Jacobian whose rounding error, `sqrt(noise / eps)` times larger
/// than planned, costs a classical Rosenbrock method its order ([`OdeJacobian::difference_increment`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DifferenceIncrement {
    /// Relative rounding noise of `f` (values below eps count as eps).
    pub noise: f64,
    /// The size below which a component counts as 0 (its natural scale).
    pub floor: f64,
}

/// Forward-difference Jacobian `jac[i * n + j] ≈ ∂f_i/∂y_j` of `sys` at `(t, y)`, column by
/// column (`n = y.len()` evaluations of `rhs`), given `fy = f(t, y)`. `scratch_y`, `scratch_f`
/// (length `n`) are overwritten. Allocates nothing.
///
/// # Errors
/// The first error of `sys.rhs` (the remaining columns are not computed).
///
/// # Panics
/// If the slice lengths do not match `n` (`jac`: `n * n`).
pub fn fd_jacobian<S: OdeSystem>(
    sys: &mut S,
    t: f64,
    y: &[f64],
    fy: &[f64],
    jac: &mut [f64],
    scratch_y: &mut [f64],
    scratch_f: &mut [f64],
) -> Result<(), S::Error> {
    fd_jacobian_columns(sys, t, y, fy, jac, y.len(), 1e-5, scratch_y, scratch_f)
}

/// [`fd_jacobian`] for the first `cols` columns only (`cols` evaluations of `rhs`), with the
/// increment `sqrt(eps) max(|y_j|, floor)` (`fd_jacobian`: `floor = 1e-5`); the other columns
/// of `jac` are left untouched. For systems whose trailing components do not feed back
/// ([`OdeJacobian::coupled_dim`]): their columns are zero. [`fd_jacobian_columns_within`]
/// also watches a deadline. The floor is the size below which a
/// component counts as zero: at `y_j = 0` the increment is `sqrt(eps) floor`, and the
/// rounding error of the column is `eps |f| / (sqrt(eps) floor)`, so a floor far below the
/// component's natural scale (an angle at 0 rad with a floor of 1e-5 rad) buys a rounding
/// error of `1e3 sqrt(eps) |f|`-ish.
///
/// # Errors
/// The first error of `sys.rhs` (the remaining columns are not computed).
///
/// # Panics
/// If the slice lengths do not match `n` (`jac`: `n * n`) or `cols > n`.
#[allow(clippy::too_many_arguments)]
pub fn fd_jacobian_columns<S: OdeSystem>(
    sys: &mut S,
    t: f64,
    y: &[f64],
    fy: &[f64],
    jac: &mut [f64],
    cols: usize,
    floor: f64,
    scratch_y: &mut [f64],
    scratch_f: &mut [f64],
) -> Result<(), S::Error> {
    fd_jacobian_columns_within(sys, t, y, fy, jac, cols, DifferenceIncrement { noise: f64::EPSILON, floor }, scratch_y, scratch_f, Watch::default()).map(|_| ())
}

/// [`fd_jacobian_columns`] with the increment `sqrt(inc.noise) max(|y_j|, inc.floor)`
/// ([`DifferenceIncrement`]; `fd_jacobian_columns` is `noise = eps`) that reads `watch`'s clock
/// before every column after the first
/// (each costs one evaluation of `rhs`, far more than the clock): `Ok(None)` when every column
/// is done, `Ok(Some(j))` when the deadline passed before column `j` (0-based; the columns
/// from `j` on are not computed). Allocates nothing.
///
/// # Errors
/// The first error of `sys.rhs` (the remaining columns are not computed).
///
/// # Panics
/// As [`fd_jacobian_columns`].
#[allow(clippy::too_many_arguments)]
pub fn fd_jacobian_columns_within<S: OdeSystem>(
    sys: &mut S,
    t: f64,
    y: &[f64],
    fy: &[f64],
    jac: &mut [f64],
    cols: usize,
    inc: DifferenceIncrement,
    scratch_y: &mut [f64],
    scratch_f: &mut [f64],
    watch: Watch,
) -> Result<Option<usize>, S::Error> {
    fd_jacobian_column_range_within(sys, t, y, fy, jac, 0..cols, inc, scratch_y, scratch_f, watch)
}

/// [`fd_jacobian_columns_within`] over the columns `cols` only (a sweep continued after
/// columns the system wrote exactly, [`super::OdeJacobian::exact_columns`]); the deadline is
/// read before every column after the first of the range.
///
/// # Errors
/// The first error of `sys.rhs` (the remaining columns are not computed).
///
/// # Panics
/// As [`fd_jacobian_columns`] (`cols.end > n`).
#[allow(clippy::too_many_arguments)]
pub fn fd_jacobian_column_range_within<S: OdeSystem>(
    sys: &mut S,
    t: f64,
    y: &[f64],
    fy: &[f64],
    jac: &mut [f64],
    cols: std::ops::Range<usize>,
    inc: DifferenceIncrement,
    scratch_y: &mut [f64],
    scratch_f: &mut [f64],
    watch: Watch,
) -> Result<Option<usize>, S::Error> {
    let n = y.len();
    assert!(
        fy.len() == n && scratch_y.len() == n && scratch_f.len() == n && jac.len() == n * n && cols.end <= n,
        "fd_jacobian: slice lengths vs dim {n}, columns {cols:?}"
    );
    let rel = inc.noise.max(f64::EPSILON).sqrt();
    scratch_y.copy_from_slice(y);
    let first = cols.start;
    for j in cols {
        if j > first && watch.out_of_time() {
            return Ok(Some(j));
        }
        let yj = y[j];
        let delta = rel * yj.abs().max(inc.floor);
        scratch_y[j] = if yj < 0.0 { yj - delta } else { yj + delta };
        let d = scratch_y[j] - yj; // the increment actually represented
        let res = sys.rhs_column(t, scratch_y, j, scratch_f);
        scratch_y[j] = yj;
        res?;
        for i in 0..n {
            jac[i * n + j] = (scratch_f[i] - fy[i]) / d;
        }
    }
    Ok(None)
}

/// Wraps an [`OdeSystem`] to make it an [`OdeJacobian`] by forward differences
/// ([`fd_jacobian`]; `dim` evaluations of `rhs` per Jacobian, counted in
/// [`FdJacobian::fd_evals`], not in the stepper's `Stats::rhs_evals`). `∂f/∂t` is left to
/// the stepper's own difference. Scratch is allocated in [`FdJacobian::new`] only.
#[derive(Clone, Debug)]
pub struct FdJacobian<S> {
    sys: S,
    scratch_y: Vec<f64>,
    scratch_f: Vec<f64>,
    fd_evals: u64,
}

impl<S: OdeSystem> FdJacobian<S> {
    /// Wraps `sys` (allocates two vectors of length `sys.dim()`).
    pub fn new(sys: S) -> Self {
        let n = sys.dim();
        Self {
            sys,
            scratch_y: vec![0.0; n],
            scratch_f: vec![0.0; n],
            fd_evals: 0,
        }
    }

    /// The wrapped system.
    pub fn inner(&self) -> &S {
        &self.sys
    }

    /// The wrapped system, mutably.
    pub fn inner_mut(&mut self) -> &mut S {
        &mut self.sys
    }

    /// Unwraps the system.
    pub fn into_inner(self) -> S {
        self.sys
    }

    /// Evaluations of `rhs` made for Jacobians since construction (including failed ones).
    pub fn fd_evals(&self) -> u64 {
        self.fd_evals
    }
}

impl<S: OdeSystem> OdeSystem for FdJacobian<S> {
    type Error = S::Error;
    fn dim(&self) -> usize {
        self.sys.dim()
    }
    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), S::Error> {
        self.sys.rhs(t, y, dydt)
    }
    fn rhs_column(&mut self, t: f64, y: &[f64], col: usize, dydt: &mut [f64]) -> Result<(), S::Error> {
        self.sys.rhs_column(t, y, col, dydt)
    }
    fn error_measured(&self, measured: &mut [bool]) {
        self.sys.error_measured(measured)
    }
}

impl<S: OdeSystem> OdeJacobian for FdJacobian<S> {
    fn jacobian(&mut self, t: f64, y: &[f64], fy: &[f64], jac: &mut [f64]) -> Result<(), S::Error> {
        let n = y.len();
        let res = fd_jacobian(
            &mut self.sys,
            t,
            y,
            fy,
            jac,
            &mut self.scratch_y,
            &mut self.scratch_f,
        );
        // every column evaluated before a failure, plus the failing one
        self.fd_evals += n as u64;
        res
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_problems::{Kepler, RationalDecay, StiffOscillator};
    use super::*;

    /// max |fd - exact| / max(1, |exact|) over all entries.
    fn fd_vs_exact<P: OdeJacobian + Clone>(p: &P, t: f64, y: &[f64]) -> f64 {
        let n = y.len();
        let mut sys = p.clone();
        let mut f = vec![0.0; n];
        let (mut je, mut jf) = (vec![0.0; n * n], vec![0.0; n * n]);
        let (mut sy, mut sf) = (vec![0.0; n], vec![0.0; n]);
        sys.rhs(t, y, &mut f).ok();
        sys.jacobian(t, y, &f, &mut je).ok();
        let mut fd = FdJacobian::new(sys.clone());
        fd.jacobian(t, y, &f, &mut jf).ok();
        assert_eq!(fd.fd_evals(), n as u64);
        // the free function gives the same bits
        let mut jf2 = vec![0.0; n * n];
        fd_jacobian(&mut sys, t, y, &f, &mut jf2, &mut sy, &mut sf).ok();
        assert_eq!(jf, jf2);
        je.iter()
            .zip(&jf)
            .map(|(a, b)| (a - b).abs() / a.abs().max(1.0))
            .fold(0.0, f64::max)
    }

    // Forward differences agree with the analytic Jacobians to O(sqrt(eps)) relative: bound
    // 1e-6 (measured 1.0e-7 Kepler, 1.4e-8 rational). The rounding error eps |f| / delta_j
    // grows where |y_j| is small against |f|: the oscillator's current is ~1e-3 (increment
    // 2e-11) while |f| ~ 1e4, measured 3.5e-6, bound 1e-5 (and 6.5e-4 at v = 0, increment
    // 1.5e-13, which is why the state here avoids 0).
    #[test]
    fn fd_jacobian_matches_analytic() {
        let e1 = fd_vs_exact(&Kepler { e: 0.5 }, 0.0, &[0.4, 0.3, -0.2, 1.1]);
        let e2 = fd_vs_exact(&RationalDecay, 0.7, &[0.8]);
        let osc = StiffOscillator::default();
        let e3 = fd_vs_exact(&osc, 0.3, &[0.2, 0.3, -1.5e-3]);
        eprintln!(
            "fd jacobian rel errors: kepler {e1:.1e}, rational {e2:.1e}, oscillator {e3:.1e}"
        );
        assert!(e1 < 1e-6 && e2 < 1e-6 && e3 < 1e-5, "{e1} {e2} {e3}");
    }
}
