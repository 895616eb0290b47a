//! Event-driven (hybrid) integration: a smooth phase integrated by any [`Stepper`], events
//! located as roots of event functions on the stepper's dense output, the system's discrete
//! mode switched (and its state possibly jumped) at each event, then the stepper restarted.
//!
//! INTERFACE ONLY in this base commit (issue 11); the driver is implemented on its branch.

use super::{Deadline, IntegrateError, OdeSystem, Stats, Stepper};

/// A system whose right-hand side depends on a discrete mode that changes at events.
///
/// The driver never looks inside the mode: it evaluates the event functions, locates their
/// roots, and calls [`HybridSystem::handle_events`] at the earliest.
pub trait HybridSystem: OdeSystem {
    /// Number of event functions (fixed for a run; a function that means nothing in the
    /// current mode returns a constant positive value, e.g. 1.0).
    fn n_events(&self) -> usize;

    /// Direction of event function `i` in the current mode: `-1` fires only when it goes from
    /// `> 0` to `≤ 0`, `+1` only from `< 0` to `≥ 0`, `0` either way.
    fn event_direction(&self, i: usize) -> i8;

    /// Event functions at (t, y) in the current mode, into `out` (length `n_events()`).
    fn events(&mut self, t: f64, y: &[f64], out: &mut [f64]) -> Result<(), Self::Error>;

    /// Choose the modes at the start (t0, y0): called once before the first step. May move
    /// `y` (e.g. an impact at t0); returns whether it did.
    fn init_modes(&mut self, t: f64, y: &mut [f64]) -> Result<bool, Self::Error>;

    /// Events `fired[i]` occurred at `t` (the located root; `y` the state there, from the
    /// dense output): switch modes, and jump `y` if the event says so (an impact). Returns
    /// whether `y` changed. Errors are the system's (e.g. an inconsistent contact
    /// configuration).
    fn handle_events(&mut self, t: f64, y: &mut [f64], fired: &[bool]) -> Result<bool, Self::Error>;

    /// After every accepted step that ends at `(t, y)` with no event: lets the system refresh
    /// what its event functions refer to (e.g. the slip direction of a sliding contact). The
    /// default does nothing.
    fn after_step(&mut self, t: f64, y: &[f64]) {
        let _ = (t, y);
    }
}

/// Settings of the event driver.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EventSettings {
    /// Width of the bracket an event time is located to, s (default 1e-12, widened to
    /// 4 ulp of t when t is large).
    pub time_tol: f64,
    /// Most events in a run (default 1_000_000): beyond, [`IntegrateError::TooManyEvents`].
    pub max_events: u64,
    /// Most events in a row within `10 time_tol` of each other (default 32): beyond,
    /// [`IntegrateError::Chattering`].
    pub max_events_at_one_time: u32,
}

impl Default for EventSettings {
    fn default() -> Self {
        EventSettings { time_tol: 1e-12, max_events: 1_000_000, max_events_at_one_time: 32 }
    }
}

/// [`super::integrate_sampled_within`] for a [`HybridSystem`]: the same fixed output grid and
/// projection, plus event location and restarts. `sample(t, y, sys)` gets the system too, so
/// a caller can read its modes (and drain what it logged) at each output time; samples at
/// `t_k < t_event` come from before the event, `t_k ≥ t_event` from after it.
#[allow(clippy::too_many_arguments)]
pub fn integrate_hybrid<S: HybridSystem, St: Stepper<S> + ?Sized>(
    stepper: &mut St,
    sys: &mut S,
    t0: f64,
    y0: &[f64],
    t_end: f64,
    dt_out: f64,
    deadline: Option<Deadline>,
    settings: EventSettings,
    sample: impl FnMut(f64, &[f64], &mut S) -> Result<(), S::Error>,
) -> Result<Stats, IntegrateError<S::Error>> {
    let _ = (stepper, sys, t0, y0, t_end, dt_out, deadline, settings, sample);
    unimplemented!("issue 11: the event driver lands on its branch")
}
