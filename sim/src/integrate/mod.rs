//! ODE integrators for first-order systems `y' = f(t, y)`.
//!
//! The split follows diffsol: the *problem* is an [`OdeSystem`] (what gets integrated, a pure
//! function of `(t, y)` apart from scratch), the *method* is a [`Stepper`] ([`Rk4`],
//! [`DormandPrince45`], [`Rosenbrock`], [`ArkImex`]), and the *state* (`t`, `y`, the stage
//! derivatives and the dense-output coefficients of the last step) lives inside the stepper,
//! sized once in its constructor.
//! [`integrate_sampled`] drives a stepper over an interval and reports the solution on a fixed
//! output grid via dense output, so recorded times never depend on the solver's step sizes.
//!
//! The adaptive methods take one [`StepControl`] (tolerances and step limits, the same for
//! all three; [`StepControl::new`] sets no limit beyond the tolerances: user-facing defaults
//! belong to the caller). Each method's controller constants (safety factor, bounds on the
//! step-size ratio) are fixed to those of Hairer's reference codes (`dopri5.f`, `ros4.f`).
//!
//! Methods and their references (Hairer, Nørsett & Wanner, *Solving Ordinary Differential
//! Equations I*, 2nd ed., Springer 1993, "HNW I" below):
//! - [`Rk4`]: the classical 4th-order Runge–Kutta method (Kutta 1901, HNW I §II.1),
//!   fixed step, cubic Hermite dense output (HNW I §II.6).
//! - [`DormandPrince45`]: the embedded 5(4) pair of Dormand & Prince (1980), HNW I §II.5
//!   with the error estimation and step-size control of HNW I §II.4 and the 4th-order
//!   continuous extension of HNW I §II.6, following Hairer's `dopri5.f`.
//!
//! For stiff systems (Hairer & Wanner, *Solving Ordinary Differential Equations II*, 2nd ed.,
//! Springer 1996, "HNW II"), where an explicit method's step is bounded by stability rather
//! than accuracy:
//! - [`Rosenbrock`]: the Rosenbrock-W method ROS34PW2 of Rang & Angermann, BIT 45 (2005)
//!   761–787 (4 stages, order 3(2), L-stable, stiffly accurate, order kept with an approximate
//!   Jacobian), for an [`OdeJacobian`]: an analytic Jacobian, or [`FdJacobian`] around any
//!   [`OdeSystem`] (forward differences, [`fd_jacobian`]). Linear algebra: a dense in-place LU
//!   with partial pivoting (`lu.rs`).
//! - [`Rodas`]: the classical Rosenbrock methods RODAS5P (Steinebach, BIT 63 (2023) 27; order
//!   5(4), the default) and RODAS4 (HNW II §VI.4, `rodas.f`; order 4(3)), L-stable, stiffly
//!   accurate, with dense output of order 4 (3); they need the exact Jacobian
//!   ([`OdeJacobian::exact_jacobian`], else finite differences) and factor only the block of the
//!   state that feeds back ([`OdeJacobian::coupled_dim`]).
//! - [`ArkImex`]: the additive Runge–Kutta pair `ARK4(3)6L[2]SA` of Kennedy & Carpenter, Appl.
//!   Numer. Math. 44 (2003) 139–181 (explicit part + L-stable ESDIRK part, order 4(3)), for a
//!   [`SplitSystem`] that solves its own implicit stage equations.
//!
//! Conventions: integration runs forward in time only (`t_stop > t`); times in seconds if the
//! system's are; all slices have length `dim`. A dimension mismatch is a programmer error and
//! panics; everything that depends on the numbers (a failing right-hand side, a NaN, a step-size
//! collapse) is returned as an [`IntegrateError`].



/// The [`Stepper`] accessors, forwarded to the stepper type's inherent methods of the same names.
macro_rules! forward_stepper_accessors {
    ($ty:ident) => {
        fn t(&self) -> f64 {
            $ty::t(self)
        }

        fn y(&self) -> &[f64] {
            $ty::y(self)
        }

        fn interpolate(&self, t_query: f64, out: &mut [f64]) {
            $ty::interpolate(self, t_query, out)
        }

        fn stats(&self) -> Stats {
            $ty::stats(self)
        }
    };
}

/// The inherent accessors of an adaptive stepper with fields `core` ([`adaptive::Core`]) and
/// `y`.
macro_rules! adaptive_accessors {
    () => {
        /// The tolerances and limits this stepper was built with.
        pub fn control(&self) -> &StepControl {
            &self.core.control
        }

        /// Start of the last accepted step (equals `t()` before the first step).
        pub fn t_prev(&self) -> f64 {
            self.core.t_prev
        }

        /// Current time (same as [`Stepper::t`], without naming the system type).
        pub fn t(&self) -> f64 {
            self.core.t
        }

        /// Current state (same as [`Stepper::y`]).
        pub fn y(&self) -> &[f64] {
            &self.y
        }

        /// Work counters since `init` (same as [`Stepper::stats`]).
        pub fn stats(&self) -> Stats {
            self.core.stats
        }

        /// Step size the next attempt will use (before the `h_max` and `t_stop` limits);
        /// `None` before the first step.
        pub fn h_next(&self) -> Option<f64> {
            self.core.h_next
        }
    };
}

mod adaptive;
#[cfg(test)]
mod contract;
mod control;
mod error;
mod dopri5;
mod events;
mod imex;
mod jacobian;
mod lu;
mod rk4;
mod rodas;
mod rosenbrock;
mod sampled;
pub mod test_problems;
#[cfg(test)]
mod testutil;

pub use self::control::{SettingsError, StepControl, StepSizeControl};
pub use self::error::IntegrateError;
pub use self::dopri5::{DormandPrince45, STIFF_STEPS_LEFT};
pub use self::events::{integrate_hybrid, EventSettings, HybridSystem};
pub use self::imex::ArkImex;
pub use self::jacobian::{fd_jacobian, fd_jacobian_column_range_within, fd_jacobian_columns, fd_jacobian_columns_within, DifferenceIncrement, FdJacobian};
pub use self::rk4::Rk4;
pub use self::rodas::{Rodas, RodasMethod};
pub use self::rosenbrock::Rosenbrock;
pub use self::sampled::{integrate_sampled, integrate_sampled_within, too_slow, Deadline, Phase, Watch, PACE_AFTER};

/// What gets integrated: y' = f(t, y). Must be a pure function of (t, y) apart from scratch.
///
/// Steppers evaluate `rhs` at stage points that are later discarded (rejected steps, stages
/// inside a step), so any memory that must persist belongs in `y`, not in `self`.
pub trait OdeSystem {
    /// The system's own failure (e.g. a singular constraint system); passed through unchanged
    /// as [`IntegrateError::Rhs`].
    type Error: std::error::Error + Send + Sync + 'static;
    /// Length of the state vector `y`.
    fn dim(&self) -> usize;
    /// Writes `f(t, y)` into `dydt` (both of length `dim`).
    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), Self::Error>;
    /// `f(t, y)` for column `col` of a difference Jacobian ([`fd_jacobian_columns`]): `y` is
    /// the sweep's base point with component `col` moved. The columns of one sweep come in
    /// increasing order from `col = 0`, each call right after the previous one (nothing else
    /// evaluates the system in between), so a system may reuse what it computed in the sweep
    /// for the components not moved since (the arm: everything that depends on q only, for the
    /// q̇ and current columns). It must write what `rhs` would write. The default is `rhs`.
    fn rhs_column(&mut self, t: f64, y: &[f64], col: usize, dydt: &mut [f64]) -> Result<(), Self::Error> {
        let _ = col;
        self.rhs(t, y, dydt)
    }
    /// Which components the adaptive steppers' error norm measures: `measured` (length `dim`)
    /// comes all true, and a system sets false what the norm must leave out. The norm is the
    /// RMS over the rest (`adaptive.rs`); the components left out are still integrated, by the
    /// steps the others choose. Read by every `init`, so at the start of a run and after every
    /// event ([`integrate_hybrid`] restarts the stepper): a hybrid system may choose by its
    /// modes, which change only at events. Meant for quadratures that feed nothing back into
    /// `f` and whose error need not steer the step size, as SUNDIALS CVODES leaves its
    /// quadrature variables out of the local error test unless asked (`CVodeSetQuadErrCon`,
    /// `errconQ`, default false; Hindmarsh et al., *SUNDIALS*, ACM TOMS 31 (2005) 363; the CVODES
    /// guide, "Quadrature integration"). The default measures every component.
    fn error_measured(&self, measured: &mut [bool]) {
        let _ = measured;
    }
    /// Called by [`integrate_sampled`] after every accepted step: may move `y` back onto an
    /// invariant manifold (e.g. constraints C = 0, Ċ = 0) and returns whether it changed it.
    /// The default leaves `y` alone.
    fn project(&mut self, t: f64, y: &mut [f64]) -> Result<bool, Self::Error> {
        let _ = (t, y);
        Ok(false)
    }
}

/// A system that can give (an approximation of) `∂f/∂y`, for [`Rosenbrock`].
///
/// Rosenbrock-W methods keep their order with any bounded approximation (HNW II §IV.7,
/// "W-methods"), so a lagged, simplified or finite-difference Jacobian is fine for accuracy;
/// the closer it is to the true one on the stiff modes, the better the stability.
pub trait OdeJacobian: OdeSystem {
    /// Writes `∂f/∂y (t, y)` into `jac`, row-major `dim x dim` (`jac[i * dim + j] = ∂f_i/∂y_j`).
    /// `fy = f(t, y)` is supplied (for finite differences).
    fn jacobian(
        &mut self,
        t: f64,
        y: &[f64],
        fy: &[f64],
        jac: &mut [f64],
    ) -> Result<(), Self::Error>;

    /// Writes `∂f/∂t (t, y)` into `dfdt` and returns `Ok(true)`; the default returns `Ok(false)`
    /// without writing, and the stepper then uses a forward difference in `t` (one evaluation
    /// of `rhs` per step; [`Rosenbrock`] refreshes `f_t` every step even when it reuses `J`).
    /// Like the Jacobian, an approximation is allowed.
    fn time_derivative(
        &mut self,
        t: f64,
        y: &[f64],
        fy: &[f64],
        dfdt: &mut [f64],
    ) -> Result<bool, Self::Error> {
        let _ = (t, y, fy, dfdt);
        Ok(false)
    }

    /// For the classical Rosenbrock methods ([`Rodas`]), whose order needs the exact `∂f/∂t`:
    /// writes it into `dfdt` and returns `Ok(true)`, or returns `Ok(false)` without writing,
    /// and the stepper takes [`OdeJacobian::time_derivative`] (else a difference in `t`, one
    /// evaluation of `rhs` per step). The default returns `Ok(false)`.
    fn exact_time_derivative(
        &mut self,
        t: f64,
        y: &[f64],
        fy: &[f64],
        dfdt: &mut [f64],
    ) -> Result<bool, Self::Error> {
        let _ = (t, y, fy, dfdt);
        Ok(false)
    }

    /// For the classical Rosenbrock methods ([`Rodas`]), whose order needs the exact `∂f/∂y`:
    /// writes it like [`OdeJacobian::jacobian`] and returns `Ok(true)`, or returns `Ok(false)`
    /// without writing, and the stepper differences `f` over the coupled columns
    /// (`0..coupled_dim()`). The default is [`OdeJacobian::jacobian`], right for systems
    /// whose `jacobian` is exact; a system whose `jacobian` is a deliberate approximation
    /// (fine for a W-method) must override this.
    fn exact_jacobian(
        &mut self,
        t: f64,
        y: &[f64],
        fy: &[f64],
        jac: &mut [f64],
    ) -> Result<bool, Self::Error> {
        self.jacobian(t, y, fy, jac)?;
        Ok(true)
    }

    /// The number `nc` of leading state components that feed back: `f` must not depend on
    /// the components `nc..dim` (quadratures such as energies), so their Jacobian columns are
    /// zero and [`Rodas`] factors only the leading `nc x nc` block. The default, `dim()`,
    /// assumes nothing.
    fn coupled_dim(&self) -> usize {
        self.dim()
    }

    /// For [`Rodas`] when [`OdeJacobian::exact_jacobian`] gives no Jacobian: the first column
    /// `k ≤ coupled_dim()` of the trailing columns `k..coupled_dim()` that
    /// [`OdeJacobian::exact_columns`] may write exactly; the stepper differences `f` over
    /// `0..k` first. The default, `coupled_dim()`: no such column.
    fn exact_columns_start(&self) -> usize {
        self.coupled_dim()
    }

    /// Writes the columns `k..coupled_dim()` (`k = exact_columns_start()`, every row) of the
    /// exact `∂f/∂y (t, y)` into `jac` and returns `Ok(true)`, or returns `Ok(false)` without
    /// writing where it cannot at this state, and the stepper differences those columns too.
    /// [`Rodas`] calls it right after its difference sweep over `0..k` at the same `(t, y)`
    /// (so a system may reuse what the sweep left, as in [`OdeSystem::rhs_column`]), and a
    /// sweep over `k..coupled_dim()` may follow it. The default returns `Ok(false)`.
    fn exact_columns(
        &mut self,
        t: f64,
        y: &[f64],
        fy: &[f64],
        jac: &mut [f64],
    ) -> Result<bool, Self::Error> {
        let _ = (t, y, fy, jac);
        Ok(false)
    }

    /// How many right-hand sides one call of [`OdeJacobian::exact_columns`] counts as in
    /// [`Stats::rhs_evals`], whether it writes the columns or declines: the evaluations of `f`
    /// it makes itself (the arm's one same-q re-solve of its mode problem). The default, 0:
    /// columns from a closed form that evaluates no `f`.
    fn exact_columns_rhs_evals(&self) -> u64 {
        0
    }

    /// How [`Rodas`] differences `f` when [`OdeJacobian::exact_jacobian`] gives no Jacobian:
    /// the relative noise of `f` and the components' natural size ([`DifferenceIncrement`]).
    /// The default, `None`: `f` rounded to eps, and the stepper's own floor (`atol / rtol`
    /// within `[1e-5, 1]`, which knows nothing of the components' units).
    fn difference_increment(&self) -> Option<DifferenceIncrement> {
        None
    }
}

/// A system split as `f = f_E + f_I` into a non-stiff part `f_E`, treated explicitly, and a
/// stiff part `f_I`, treated implicitly, whose stage equations the system solves itself
/// (for [`ArkImex`]).
pub trait SplitSystem: OdeSystem {
    /// `f = f_E + f_I`; writes both parts (`f_E + f_I` must equal [`OdeSystem::rhs`]).
    fn rhs_split(
        &mut self,
        t: f64,
        y: &[f64],
        f_e: &mut [f64],
        f_i: &mut [f64],
    ) -> Result<(), Self::Error>;

    /// Solves `z - gamma f_I(t, z) = r` for `z` (`gamma = h a_ii > 0`). `z` holds no useful
    /// initial guess. An exact (e.g. closed-form, for `f_I` linear in `z`) solution keeps the
    /// method's order; the stepper recovers `f_I(t, z)` as `(z - r) / gamma`. Also called
    /// twice per step with `r` = the new state and the new state plus the error estimate, to
    /// filter that estimate (see [`ArkImex`]).
    fn solve_implicit(
        &mut self,
        t: f64,
        gamma: f64,
        r: &[f64],
        z: &mut [f64],
    ) -> Result<(), Self::Error>;
}

/// Work counters since the last [`Stepper::init`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stats {
    /// Calls to [`OdeSystem::rhs`] (and [`OdeSystem::rhs_column`]), including failed ones and
    /// those of rejected steps, plus [`OdeJacobian::exact_columns_rhs_evals`] per call of
    /// [`OdeJacobian::exact_columns`] ([`Rodas`]: the system's own evaluations for its exact
    /// columns).
    pub rhs_evals: u64,
    /// Accepted steps.
    pub steps: u64,
    /// Rejected step attempts (error test failed — for [`ArkImex`] also its interpolation
    /// check —, or a non-finite stage, or a singular iteration matrix).
    pub rejected: u64,
    /// Jacobian evaluations: calls to [`OdeJacobian::jacobian`] ([`Rosenbrock`]) or
    /// [`OdeJacobian::exact_jacobian`] ([`Rodas`]); 0 for the explicit methods. Evaluations of
    /// `rhs` made inside the system's own Jacobian (e.g. by [`FdJacobian`]) are not in
    /// `rhs_evals`; those of [`Rodas`]'s own finite differences (when the system has no exact
    /// Jacobian) are.
    pub jacobian_evals: u64,
    /// LU factorisations of the iteration matrix ([`Rosenbrock`], [`Rodas`]; 0 for the others).
    pub lu_decompositions: u64,
    /// Calls to [`SplitSystem::solve_implicit`] ([`ArkImex`]; 0 for the others).
    pub implicit_solves: u64,
}

/// What an event left behind at a restart ([`Stepper::first_step_after_restart`]), read by
/// [`integrate_hybrid`] from the event functions at the restart.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RestartStart {
    /// Every event function is away from 0, or on its firing side and watched from its start
    /// value (`events.rs`): the driver sees any root of the first step, whatever its length
    /// (a stick ↔ slip change, a lift-off).
    Armed,
    /// Some event function that is not watched starts at 0 or on its firing side, so it is
    /// disarmed for the first step (a ball left on the table by a bounce): a root of it within
    /// that step goes unseen, so the step must stay short.
    Disarmed,
}

/// A one-step method that owns its state between steps.
pub trait Stepper<S: OdeSystem> {
    /// Set initial condition; may evaluate f once. Resets [`Stats`].
    ///
    /// Errors: [`IntegrateError::Rhs`] from that evaluation, [`IntegrateError::NonFiniteState`]
    /// (at `t0`) for a NaN/inf in `y0` or `f(t0, y0)`. Panics if `y0.len() != sys.dim()` or the
    /// stepper was built for another dimension.
    fn init(&mut self, sys: &mut S, t0: f64, y0: &[f64]) -> Result<(), IntegrateError<S::Error>>;
    /// Take one accepted step, never past `t_stop` (land exactly on `t_stop` when reached).
    /// Returns the new time.
    ///
    /// With `t_stop <= t()` this is a no-op returning `t()`. On error the stepper keeps its last
    /// accepted state (`t()`, `y()`, dense output), so the caller can report or inspect it.
    /// Panics if called before a successful `init`.
    fn step(&mut self, sys: &mut S, t_stop: f64) -> Result<f64, IntegrateError<S::Error>>;
    /// Restart at `(t0, y0)` after an event ([`integrate_hybrid`]): like [`Stepper::init`]
    /// (statistics reset), except that a stepper may carry over what the steps before the event
    /// learned about the step size (e.g. [`Rodas`] tries the last accepted step's size first).
    /// What the event left behind (whether an event function is disarmed for the first step,
    /// [`RestartStart`]) the driver reads from the functions at `(t0, y0)` after this call and
    /// passes to [`Stepper::first_step_after_restart`]. Called only for a system that allows
    /// it ([`HybridSystem::restart_keeps_step_size`]). The default is `init`.
    fn restart(&mut self, sys: &mut S, t0: f64, y0: &[f64]) -> Result<(), IntegrateError<S::Error>> {
        self.init(sys, t0, y0)
    }
    /// After [`Stepper::restart`] and before the first step: what the event left behind at the
    /// restart ([`RestartStart`]), for a stepper that chooses its first step by it. The default
    /// does nothing.
    fn first_step_after_restart(&mut self, sys: &mut S, start: RestartStart) -> Result<(), IntegrateError<S::Error>> {
        let _ = (sys, start);
        Ok(())
    }
    /// Current time.
    fn t(&self) -> f64;
    /// Current state (length `dim`).
    fn y(&self) -> &[f64];
    /// Dense output inside the last accepted step `[t_prev, t]`; writes `y(t_query)` into `out`
    /// (length `dim`). At `t_query == t` (end) it returns `y()` exactly, at `t_prev` exactly the
    /// previous state. Before the first step it returns `y()`.
    fn interpolate(&self, t_query: f64, out: &mut [f64]);
    /// Work counters since `init`.
    fn stats(&self) -> Stats;
    /// Replace the current state `y(t)` (after a projection onto an invariant manifold, say)
    /// and re-evaluate what the method keeps about it (one `rhs` call); the step size, the
    /// controller and the statistics carry on. Dense output of the last step is not updated.
    fn set_state(&mut self, sys: &mut S, y: &[f64]) -> Result<(), IntegrateError<S::Error>>;
    /// The deadline the stepper's own long loops look at (a difference Jacobian's columns, a
    /// factorisation's), ending the step with [`IntegrateError::OutOfTime`] and where it was;
    /// set by the drivers from their [`Deadline`]. The default ignores it (a method whose
    /// step is a few right-hand sides: the driver's clock between steps is enough).
    fn set_watch(&mut self, watch: Watch) {
        let _ = watch;
    }
}

/// Index of the first NaN/inf in `v`, if any.
#[inline]
fn first_non_finite(v: &[f64]) -> Option<usize> {
    v.iter().position(|x| !x.is_finite())
}

/// Evaluates `sys.rhs(t, y)` into `out`, counting it; returns the first non-finite component.
fn eval<S: OdeSystem>(
    stats: &mut Stats,
    sys: &mut S,
    t: f64,
    y: &[f64],
    out: &mut [f64],
) -> Result<Option<usize>, IntegrateError<S::Error>> {
    stats.rhs_evals += 1;
    sys.rhs(t, y, out).map_err(IntegrateError::Rhs)?;
    Ok(first_non_finite(out))
}

/// [`eval`], with a non-finite value an [`IntegrateError::NonFiniteState`] at `t`.
fn eval_finite<S: OdeSystem>(
    stats: &mut Stats,
    sys: &mut S,
    t: f64,
    y: &[f64],
    out: &mut [f64],
) -> Result<(), IntegrateError<S::Error>> {
    match eval(stats, sys, t, y, out)? {
        Some(index) => Err(IntegrateError::NonFiniteState { t, index }),
        None => Ok(()),
    }
}

/// Dense output on the last step `[t_prev, t]` of size `h` (`h = 0` before the first step):
/// `y` at `t` (and before the first step), `y_prev` at `t_prev`, else `interior(theta, out)`
/// with `theta = (t_query - t_prev) / h`. Panics (naming the stepper `name`) if
/// `out.len() != y.len()`.
#[allow(clippy::too_many_arguments)]
fn dense_output(
    name: &str,
    t_query: f64,
    out: &mut [f64],
    t_prev: f64,
    t: f64,
    h: f64,
    y_prev: &[f64],
    y: &[f64],
    interior: impl FnOnce(f64, &mut [f64]),
) {
    assert_eq!(out.len(), y.len(), "{name}::interpolate: out length vs dim");
    if t_query == t || h == 0.0 {
        out.copy_from_slice(y);
        return;
    }
    if t_query == t_prev {
        out.copy_from_slice(y_prev);
        return;
    }
    interior((t_query - t_prev) / h, out);
}

/// The cubic Hermite interpolant (HNW I §II.6) at `theta` through `(y_prev, f_prev)` at the
/// start and `(y, f(i))` at the end of a step of size `h`, into `out`.
fn hermite(
    theta: f64,
    h: f64,
    y_prev: &[f64],
    f_prev: &[f64],
    y: &[f64],
    f: impl Fn(usize) -> f64,
    out: &mut [f64],
) {
    let th = theta;
    let th2 = th * th;
    let th3 = th2 * th;
    let h00 = 2.0 * th3 - 3.0 * th2 + 1.0;
    let h10 = th3 - 2.0 * th2 + th;
    let h01 = -2.0 * th3 + 3.0 * th2;
    let h11 = th3 - th2;
    for (i, o) in out.iter_mut().enumerate() {
        *o = h00 * y_prev[i] + h01 * y[i] + h * (h10 * f_prev[i] + h11 * f(i));
    }
}

#[cfg(test)]
mod tests {
    use super::test_problems::RhsFailure;
    use super::*;
    use std::error::Error as _;

    #[test]
    fn error_display_carries_context() {
        let e: IntegrateError<RhsFailure> = IntegrateError::StepSizeTooSmall { t: 0.5, h: 1e-17 };
        let s = e.to_string();
        assert!(s.contains("t = 0.5") && s.contains("1e-17"), "{s}");
        let e: IntegrateError<RhsFailure> = IntegrateError::NonFiniteState { t: 2.0, index: 3 };
        let s = e.to_string();
        assert!(s.contains("component 3") && s.contains("t = 2"), "{s}");
        let e: IntegrateError<RhsFailure> = IntegrateError::TooManySteps {
            t: 1.5,
            max_steps: 10,
        };
        assert!(e.to_string().contains("max_steps = 10"));
        assert!(e.source().is_none());
        let e: IntegrateError<RhsFailure> = IntegrateError::SingularMatrix { t: 0.75, h: 0.125 };
        let s = e.to_string();
        assert!(
            s.contains("t = 0.75") && s.contains("1.25e-1") && s.contains("singular"),
            "{s}"
        );
    }

    #[test]
    fn error_source_is_the_system_error() {
        let e = IntegrateError::Rhs(RhsFailure { t: 0.25 });
        let src = e.source().map(|s| s.to_string()).unwrap_or_default();
        assert_eq!(src, RhsFailure { t: 0.25 }.to_string());
        assert!(e.to_string().contains(&src));
    }

    #[test]
    fn integrate_error_is_send_sync_error() {
        fn check<T: std::error::Error + Send + Sync + 'static>() {}
        check::<IntegrateError<RhsFailure>>();
    }
}
