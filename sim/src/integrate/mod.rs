//! ODE integrators for first-order systems `y' = f(t, y)`.
//!
//! The split follows diffsol: the *problem* is an [`OdeSystem`] (what gets integrated, a pure
//! function of `(t, y)` apart from scratch), the *method* is a [`Stepper`] ([`Rk4`],
//! [`DormandPrince45`]), and the *state* (`t`, `y`, the stage derivatives and the dense-output
//! coefficients of the last step) lives inside the stepper, sized once in its constructor.
//! [`integrate_sampled`] drives a stepper over an interval and reports the solution on a fixed
//! output grid via dense output, so recorded times never depend on the solver's step sizes.
//!
//! Methods and their references (Hairer, Nørsett & Wanner, *Solving Ordinary Differential
//! Equations I*, 2nd ed., Springer 1993, "HNW I" below):
//! - [`Rk4`]: the classical 4th-order Runge–Kutta method (Kutta 1901, HNW I §II.1),
//!   fixed step, cubic Hermite dense output (HNW I §II.6).
//! - [`DormandPrince45`]: the embedded 5(4) pair of Dormand & Prince (1980), HNW I §II.5
//!   with the error estimation and step-size control of HNW I §II.4 and the 4th-order
//!   continuous extension of HNW I §II.6, following Hairer's `dopri5.f`.
//!
//! Conventions: integration runs forward in time only (`t_stop > t`); times in seconds if the
//! system's are; all slices have length `dim`. A dimension mismatch is a programmer error and
//! panics; everything that depends on the numbers (a failing right-hand side, a NaN, a step-size
//! collapse) is returned as an [`IntegrateError`].

use std::fmt;

mod dopri5;
mod rk4;
mod sampled;
pub mod test_problems;

pub use self::dopri5::{Dopri5Settings, DormandPrince45, SettingsError};
pub use self::rk4::Rk4;
pub use self::sampled::integrate_sampled;

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
}

/// Why an integration stopped.
#[derive(Debug)]
pub enum IntegrateError<E> {
    /// The system's own error (e.g. singular constraint system), passed through.
    Rhs(E),
    /// The step size needed to meet the tolerance fell below `h_min` or below what `t` can
    /// resolve (`0.1 h <= |t| eps`): a singularity or a very stiff problem at `t`.
    StepSizeTooSmall { t: f64, h: f64 },
    /// NaN/inf in state component `index`: in the state after a step (`t` is the step's end),
    /// or in a stage derivative (`t` is the time at which `rhs` produced it).
    NonFiniteState { t: f64, index: usize },
    /// More than `max_steps` step attempts (accepted + rejected) since `init`; `t` is where
    /// the stepper stands.
    TooManySteps { t: f64, max_steps: usize },
    /// The `sample` callback of [`integrate_sampled`] returned an error at output time `t`.
    /// (Added to the interface so a recorder failure is not mistaken for a dynamics failure.)
    Sample { t: f64, source: E },
    /// [`integrate_sampled`] was asked for an empty or non-finite output grid (`dt_out <= 0`,
    /// `t_end < t0`, a non-finite value, or more than 2^53 samples).
    InvalidOutputGrid { t0: f64, t_end: f64, dt_out: f64 },
}

impl<E: fmt::Display> fmt::Display for IntegrateError<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            IntegrateError::Rhs(e) => write!(f, "right-hand side evaluation failed: {e}"),
            IntegrateError::StepSizeTooSmall { t, h } => write!(
                f,
                "step size collapsed to h = {h:e} at t = {t} (singularity or stiffness?)"
            ),
            IntegrateError::NonFiniteState { t, index } => {
                write!(
                    f,
                    "non-finite value (NaN or inf) in state component {index} at t = {t}"
                )
            }
            IntegrateError::TooManySteps { t, max_steps } => {
                write!(
                    f,
                    "more than max_steps = {max_steps} step attempts, stopped at t = {t}"
                )
            }
            IntegrateError::Sample { t, source } => {
                write!(f, "output callback failed at t = {t}: {source}")
            }
            IntegrateError::InvalidOutputGrid { t0, t_end, dt_out } => write!(
                f,
                "invalid output grid: t0 = {t0}, t_end = {t_end}, dt_out = {dt_out} \
                 (need finite values, dt_out > 0, t_end >= t0)"
            ),
        }
    }
}

impl<E: std::error::Error + 'static> std::error::Error for IntegrateError<E> {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            IntegrateError::Rhs(e) | IntegrateError::Sample { source: e, .. } => Some(e),
            _ => None,
        }
    }
}

/// Work counters since the last [`Stepper::init`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stats {
    /// Calls to [`OdeSystem::rhs`], including failed ones and those of rejected steps.
    pub rhs_evals: u64,
    /// Accepted steps.
    pub steps: u64,
    /// Rejected step attempts (error test failed, or a non-finite stage).
    pub rejected: u64,
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
}

/// Index of the first NaN/inf in `v`, if any.
#[inline]
fn first_non_finite(v: &[f64]) -> Option<usize> {
    v.iter().position(|x| !x.is_finite())
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
