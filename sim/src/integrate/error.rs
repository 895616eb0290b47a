//! Why an integration stopped ([`IntegrateError`]; split from `integrate/mod.rs` for its size).

use std::fmt;

use super::Phase;

/// Why an integration stopped.
#[derive(Debug)]
pub enum IntegrateError<E> {
    /// The system's own error (e.g. singular constraint system), passed through.
    Rhs(E),
    /// The step size needed to meet the tolerance fell below `h_min` or below what `t` can
    /// resolve (`0.1 h <= |t| eps`): a singularity or a very stiff problem at `t`.
    StepSizeTooSmall { t: f64, h: f64 },
    /// NaN/inf in state component `index`: in the state after a step (`t` is the step's end),
    /// or in a stage derivative (`t` is the time at which `rhs` produced it), or in row `index`
    /// of the Jacobian or of `∂f/∂t` ([`Rosenbrock`](super::Rosenbrock); `t` is where they were evaluated).
    NonFiniteState { t: f64, index: usize },
    /// More than `max_steps` step attempts (accepted + rejected) since `init`; `t` is where
    /// the stepper stands.
    TooManySteps { t: f64, max_steps: u64 },
    /// The `sample` callback of [`integrate_sampled`](super::integrate_sampled) returned an error at output time `t`.
    /// (Added to the interface so a recorder failure is not mistaken for a dynamics failure.)
    Sample { t: f64, source: E },
    /// [`integrate_sampled`](super::integrate_sampled) was asked for an empty or non-finite output grid (`dt_out <= 0`,
    /// `t_end < t0`, a non-finite value, or more than 2^53 samples).
    InvalidOutputGrid { t0: f64, t_end: f64, dt_out: f64 },
    /// [`DormandPrince45`](super::DormandPrince45) found the problem stiff (HNW I §II.10, `dopri5.f`'s test: `h λ`
    /// beyond the stability boundary on 15 checks in a row) while more than
    /// [`STIFF_STEPS_LEFT`](super::STIFF_STEPS_LEFT) steps of the current size `h` remained before `t_stop`: an
    /// explicit method would crawl at its stability limit. `t` is the end of the last accepted
    /// step, `h_lambda` the last estimate of `h λ`.
    Stiff { t: f64, h: f64, h_lambda: f64 },
    /// [`integrate_sampled_within`](super::integrate_sampled_within)'s wall-clock deadline passed; `t` is where the stepper
    /// stands (the state there is valid), `during` what it was doing (between steps, or inside
    /// one of a step's long loops: a difference Jacobian, a factorisation, an event location).
    OutOfTime { t: f64, during: Phase },
    /// At the pace of its first [`Deadline::judge_pace_after`](super::Deadline::judge_pace_after) of wall time, the run would need
    /// `projected_s` of wall time, more than twice its budget: stopped at `t` rather than at the
    /// deadline.
    TooSlow { t: f64, projected_s: f64 },
    /// The iteration matrix `I - gamma h J` of [`Rosenbrock`](super::Rosenbrock) was (numerically) singular in the
    /// step from `t`, still at the last step size tried, `h` (the step is halved up to 5 times
    /// in a row, and not below `h_min`, before giving up).
    SingularMatrix { t: f64, h: f64 },
    /// [`integrate_hybrid`](super::integrate_hybrid): more than [`EventSettings::max_events`](super::EventSettings::max_events) events in the run.
    TooManyEvents { t: f64, max_events: u64 },
    /// [`integrate_hybrid`](super::integrate_hybrid): more than [`EventSettings::max_events_at_one_time`](super::EventSettings::max_events_at_one_time) events in a
    /// row within `window` s of each other, at `t`; `events` names the last functions fired.
    Chattering { t: f64, count: u32, window: f64, events: String },
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
            IntegrateError::Stiff { t, h, h_lambda } => write!(
                f,
                "the problem is stiff at t = {t}: h lambda = {h_lambda:.2} is at the explicit \
                 method's stability limit (h = {h:e}); use an implicit method"
            ),
            IntegrateError::OutOfTime { t, during } => {
                write!(f, "the wall-clock deadline passed at t = {t} {during}")
            }
            IntegrateError::TooSlow { t, projected_s } => {
                write!(f, "at t = {t} the pace so far projects {projected_s:.0} s of wall time, more than twice the budget")
            }
            IntegrateError::TooManyEvents { t, max_events } => {
                write!(f, "more than {max_events} events, stopped at t = {t}")
            }
            IntegrateError::Chattering { t, count, window, events } => {
                write!(f, "{count} events in a row within {window:e} s at t = {t} ({events})")
            }
            IntegrateError::SingularMatrix { t, h } => write!(
                f,
                "singular iteration matrix I - gamma h J in the step from t = {t} \
                 (last step size tried h = {h:e})"
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
