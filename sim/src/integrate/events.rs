//! Event-driven (hybrid) integration: a smooth phase integrated by any [`Stepper`], events
//! located as roots of event functions on the stepper's dense output, the system's discrete
//! mode switched (and its state possibly jumped) at each event, then the stepper restarted.
//!
//! The driver ([`integrate_hybrid`]) follows the event-driven scheme of Pfeiffer & Glocker,
//! *Multibody Dynamics with Unilateral Contacts* (Wiley 1996, ch. 6) and Acary & Brogliato,
//! *Numerical Methods for Nonsmooth Dynamical Systems* (Springer 2008, ch. 8 "event-driven
//! schemes"): integrate a smooth phase with an ordinary (adaptive) method, detect a sign change
//! of an event function between the ends of an accepted step, locate its root on the step's
//! dense output (HNW I §II.6), switch the mode at the root, restart the method there.
//! Root location is the Illinois (modified regula falsi) iteration of SUNDIALS CVODE's
//! rootfinding (Hindmarsh et al., ACM TOMS 31 (2005) 363–396, §2.4 and `cvRootfind`), on all
//! functions at once, so the earliest root across the functions is found:
//!
//! - an accepted step `[t_lo, t_hi]` has a *sign change* of function `i` when, with the
//!   function's direction `d_i` ([`HybridSystem::event_direction`]), `g_i(t_lo) > 0 ≥
//!   g_i(t_hi)` (`d_i = −1`), `g_i(t_lo) < 0 ≤ g_i(t_hi)` (`d_i = +1`) or either (`d_i = 0`).
//!   A function of direction −1 (+1) that is `≤ 0` (`≥ 0`) at a (re)start — on its firing side
//!   already, e.g. a contact force exactly 0 in the undetermined case `f_n = 0, g̈ = 0`, or a
//!   slip speed below its threshold — is, when the system asks for it
//!   ([`HybridSystem::event_tolerance`]), *watched from its start value* `g₀` until it has left
//!   its firing side: the driver tests `g − g₀` instead of `g`. A root of `g − g₀` is located
//!   like any other (a slip that starts from rest and comes back to rest); a function that moves
//!   from `g₀` straight to its firing side, by more than the system's
//!   [`HybridSystem::event_tolerance`], within a step that starts at `g₀` fires at that step's
//!   start (for the first step: at the restart itself). So a contact closed with `f_n = 0` whose
//!   force then turns negative opens at once instead of pulling unseen, while a function that
//!   only jitters at its start value fires nothing. Unless it went the other way first: the
//!   dense output is probed at `t_lo + h 2^−k` (k = 1, 2, … down to `time_tol`), and a
//!   function found off its firing side there left and came back inside the step (a gear that
//!   starts sliding from rest, turns and stops within one step), so its return is located like
//!   any other root instead of firing at the start, where the handler would restart it into
//!   the same mode without end (`locate::departed_inside`). And unless another function
//!   changes sign inside the same step: its root is located first, and the start firing stands
//!   only if the watched function had moved past its tolerance by that root (an elbow still at
//!   its start gap, inside its dead band, when the other elbow lands cannot have touched down
//!   before it; `Bracket::hold_start_firing`). Other functions exactly 0 at a
//!   start are disarmed for that step;
//! - the bracket `[t_lo, t_hi]` is narrowed by the Illinois secant on the function with the
//!   largest `|g(t_hi)| / |g(t_hi) − g(t_lo)|` (all functions are evaluated at each trial point;
//!   a sign change of any function in `[t_lo, t_mid]` keeps that half), to a width
//!   `≤ time_tol` (default 1e-12 s, or 4 ulp of `t` if larger);
//! - the event time `t*` is the bracket's upper end (every fired function has changed sign
//!   there); all functions with a sign change over the final bracket fire together;
//! - output samples `t_k < t*` come from the pre-event dense output, `y* = y(t*)` from the same;
//!   [`HybridSystem::handle_events`] switches the modes and may jump `y*`; the state is then
//!   projected ([`OdeSystem::project`], with the new modes), the stepper restarted at
//!   `(t*, y*)` with [`Stepper::init`], or, if the system allows it
//!   ([`HybridSystem::restart_keeps_step_size`]), [`Stepper::restart`] and then, once the
//!   functions at the restart are known, [`Stepper::first_step_after_restart`] (an adaptive
//!   stepper may keep its step size; [`RestartStart`] says whether a function is disarmed
//!   for the first step) (its statistics accumulated over the restarts either way), and
//!   samples `t_k ≥ t*` come from after the event.
//!
//! Guards: more than [`EventSettings::max_events`] events in a run is
//! [`IntegrateError::TooManyEvents`]; more than [`EventSettings::max_events_at_one_time`]
//! events in a row, each within `10 time_tol` of the previous one, is
//! [`IntegrateError::Chattering`] (a handler that does not settle the mode; Zeno accumulation
//! of impacts is the system's to stop, by a rest rule).
//!
//! Fixed-step [`super::Rk4`]: the same procedure on its cubic Hermite interpolant, so event
//! times are accurate to that interpolant (O(h⁴)), not to `time_tol`; and a function that
//! changes sign twice within one step (up to the step size) is not seen. The adaptive methods
//! have the same blind spot within one of their steps; their `h_max` bounds it.
//!
//! Cost: each trial point of the root finding evaluates all event functions once (for the arm,
//! force-type functions need a right-hand side); the functions are also evaluated at the end
//! of every accepted step and again at its (projected) start, so the next step compares like
//! with like. Allocation: the buffers are sized once per call; nothing per step; an event
//! allocates only for an error message.

mod locate;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod toys;

use self::locate::{crosses, departed_inside, locate_root, Bracket, Side};
use super::sampled::{OutputGrid, Pace};
use super::{Deadline, IntegrateError, OdeSystem, RestartStart, Stats, Stepper, Watch};

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

    /// Whether the stepper may carry its step size over an event ([`Stepper::restart`] and
    /// [`Stepper::first_step_after_restart`] instead of [`Stepper::init`], whose first step
    /// is Hairer's starting step). The default `false`: on the arm with gear friction and the
    /// supply, carrying RODAS5P's last step over the gears' events broke its error ∝ rtol
    /// (rtol^0.82 and rtol^1.20, `convergence.rs`, `gear_band.rs`; issue 24).
    fn restart_keeps_step_size(&self) -> bool {
        false
    }

    /// Whether function `i`, when it is on its firing side at a (re)start, is watched from its
    /// start value (the module doc), and if so how far past that value, towards its firing
    /// side, it must move for the driver to take the event at a step's start (in the function's
    /// own units). For a system whose events always change what the fired function means (a
    /// contact's force becomes its gap), a function on its firing side after a restart is a
    /// state the modes do not allow, and must be watched. The default `None`: not watched (a
    /// function that stays past its root after an event that did not change it is no new
    /// event), and one exactly 0 is disarmed until it has left 0.
    fn event_tolerance(&self, i: usize) -> Option<f64> {
        let _ = i;
        None
    }

    /// How far off its firing side a watched function that fired at a step's start must be
    /// found at a probe inside the step for the driver to take it as having left and come back
    /// (`locate::departed_inside`), in the function's units. The default: its
    /// [`HybridSystem::event_tolerance`] (a force of `−c t³` computed as `+1e-20` at a tiny
    /// probe is no departure). A system whose function is computed to far better than its dead
    /// band (a contact's gap: rounding ~1e-15 m against a dead band of 1e-9 m) gives that
    /// smaller bound, so an excursion above the rounding but inside the dead band (a contact
    /// that lifts off by 1e-11 m and lands again within the step) is located, not fired at the
    /// step's start, where the handler finds it leaving again and the same step is retaken.
    fn event_departure(&self, i: usize) -> Option<f64> {
        self.event_tolerance(i)
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

/// [`super::integrate_sampled_within`] for a [`HybridSystem`]: the same fixed output grid,
/// projection and deadline, plus event location and restarts (the module doc says how).
/// `sample(t, y, sys)` gets the system too, so a caller can read its modes (and drain what it
/// logged) at each output time; samples at `t_k < t_event` come from before the event,
/// `t_k ≥ t_event` from after it.
///
/// - [`HybridSystem::init_modes`] is called at `(t0, y0)` before anything else; the first
///   sample is `y0` bit for bit unless it moved `y0`.
/// - [`HybridSystem::after_step`] is called after every accepted step that has no event (after
///   the projection, before the next step: so not after the step that ends the run), when the
///   system has event functions.
/// - With `sys.n_events() == 0` the samples, the steps and the statistics are those of
///   `integrate_sampled_within` bit for bit.
/// - `settings.time_tol` that is not finite and positive means "as fine as `t` resolves"
///   (4 ulp of `t`).
///
/// Returns the [`Stats`] summed over all restarts.
///
/// # Errors
/// Those of `integrate_sampled_within`; the system's errors from `events`, `init_modes`,
/// `handle_events` as [`IntegrateError::Rhs`]; [`IntegrateError::TooManyEvents`] and
/// [`IntegrateError::Chattering`] at the event time.
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
    mut sample: impl FnMut(f64, &[f64], &mut S) -> Result<(), S::Error>,
) -> Result<Stats, IntegrateError<S::Error>> {
    let grid = OutputGrid::new(t0, t_end, dt_out)?;
    let n_out = grid.n_out;
    let n_ev = sys.n_events();
    let rhs = IntegrateError::Rhs;
    // the long loops inside a step (the stepper's Jacobian, the event location) look at the
    // deadline too
    let watch = Watch::new(deadline);
    stepper.set_watch(watch);

    // the modes at t0, then the first sample
    let mut y_star = y0.to_vec();
    sys.init_modes(t0, &mut y_star).map_err(rhs)?;
    stepper.init(sys, t0, &y_star)?;
    sample(t0, stepper.y(), sys).map_err(|source| IntegrateError::Sample { t: t0, source })?;

    let mut buf = vec![0.0; y0.len()];
    let mut br = Bracket::new(n_ev);
    if n_ev > 0 {
        br.refresh_directions(sys);
        sys.events(t0, stepper.y(), &mut br.g_lo).map_err(rhs)?;
        br.set_bases(sys);
    }
    let mut k = 1;
    let mut pace = Pace::new(deadline, t0, t_end);
    let mut done = Stats::default(); // statistics of the segments before the last restart
    let mut restarted = false; // no step since the last event's restart
    let mut stepped = false; // a step since the last (re)start
    let mut n_events = 0u64;
    let mut in_row = 0u32;
    let mut t_last_event = f64::NEG_INFINITY;
    loop {
        // report every grid point inside the last accepted step [t_prev, t] (or at the restart)
        while k <= n_out {
            let t_k = grid.time(k);
            if t_k > stepper.t() {
                break;
            }
            if t_k == stepper.t() {
                sample(t_k, stepper.y(), sys)
            } else {
                stepper.interpolate(t_k, &mut buf);
                sample(t_k, &buf, sys)
            }
            .map_err(|source| IntegrateError::Sample { t: t_k, source })?;
            k += 1;
        }
        if stepper.t() >= t_end {
            break;
        }
        // projection after an accepted step, as integrate_sampled_within does (after sampling)
        if !restarted && (k > 1 || stepper.t() > t0) {
            buf.copy_from_slice(stepper.y());
            if sys.project(stepper.t(), &mut buf).map_err(rhs)? {
                stepper.set_state(sys, &buf)?;
            }
        }
        if stepped && n_ev > 0 {
            // the step had no event: the system may refresh what its functions refer to, and
            // the next step's start values are taken at the (projected) state
            sys.after_step(stepper.t(), stepper.y());
            sys.events(stepper.t(), stepper.y(), &mut br.g_lo).map_err(rhs)?;
            br.release_and_shift_lo();
        }
        let t_before = stepper.t();
        let t_after = stepper.step(sys, t_end)?;
        if t_after.is_nan() || t_after <= t_before {
            // a stepper that stops advancing before t_end would loop forever
            return Err(IntegrateError::StepSizeTooSmall { t: t_before, h: t_after - t_before });
        }
        pace.after_step(t_after)?;
        restarted = false;
        stepped = true;
        if n_ev == 0 {
            continue;
        }
        sys.events(t_after, stepper.y(), &mut br.g_hi).map_err(rhs)?;
        br.shift(Side::Hi);
        let tol = time_tolerance(settings.time_tol, t_after);
        let mut at_start = br.left_at_start();
        let (mut t_lo, mut t_hi) = (t_before, t_after);
        if at_start {
            // or a departure and a return inside the step: a root to locate
            if let Some(bracket) = departed_inside(stepper, sys, &mut br, t_before, t_after, tol, watch, &mut buf)? {
                (t_lo, t_hi) = bracket;
                at_start = false;
            }
        }
        if !at_start && !(0..n_ev).any(|i| crosses(br.dir[i], br.g_lo[i], br.g_hi[i])) {
            continue;
        }

        // an event in [t_lo, t_hi]: its time, then the samples before it
        let t_star = if at_start && !br.hold_start_firing() {
            t_before
        } else {
            // a root to locate; after a held start firing (another function's root in the same
            // step), the start firing stands only if it had moved past its dead band by that root
            let t_root = locate_root(stepper, sys, &mut br, t_lo, t_hi, tol, watch, &mut buf)?;
            if at_start && br.start_firing_before_root() {
                t_before
            } else {
                t_root
            }
        };
        while k <= n_out && grid.time(k) < t_star {
            let t_k = grid.time(k);
            stepper.interpolate(t_k, &mut buf);
            sample(t_k, &buf, sys).map_err(|source| IntegrateError::Sample { t: t_k, source })?;
            k += 1;
        }
        n_events += 1;
        if n_events > settings.max_events {
            return Err(IntegrateError::TooManyEvents { t: t_star, max_events: settings.max_events });
        }
        let window = 10.0 * tol;
        in_row = if t_star - t_last_event <= window { in_row + 1 } else { 1 };
        t_last_event = t_star;
        if in_row > settings.max_events_at_one_time {
            let fired: Vec<usize> = (0..n_ev).filter(|&i| br.fired[i]).collect();
            return Err(IntegrateError::Chattering { t: t_star, count: in_row, window, events: format!("event functions {fired:?}") });
        }

        // switch the modes (and jump the state) at t*, project, restart there
        stepper.interpolate(t_star, &mut y_star);
        sys.handle_events(t_star, &mut y_star, &br.fired).map_err(rhs)?;
        pace.after_event(t_star)?;
        sys.project(t_star, &mut y_star).map_err(rhs)?;
        done = add_stats(done, stepper.stats());
        if sys.restart_keeps_step_size() {
            stepper.restart(sys, t_star, &y_star)?;
        } else {
            stepper.init(sys, t_star, &y_star)?;
        }
        br.refresh_directions(sys);
        sys.events(t_star, stepper.y(), &mut br.g_lo).map_err(rhs)?;
        br.set_bases(sys);
        let start = if br.any_disarmed() { RestartStart::Disarmed } else { RestartStart::Armed };
        stepper.first_step_after_restart(sys, start)?;
        restarted = true;
        stepped = false;
    }
    Ok(add_stats(done, stepper.stats()))
}

/// Width an event time is located to at `t`: `time_tol`, or 4 ulp of `t` if larger (or if
/// `time_tol` is not a positive number).
fn time_tolerance(time_tol: f64, t: f64) -> f64 {
    let a = t.abs();
    let ulp = if a.is_finite() { f64::from_bits(a.to_bits() + 1) - a } else { 0.0 };
    let floor = 4.0 * ulp.max(f64::MIN_POSITIVE);
    if time_tol.is_finite() && time_tol > floor {
        time_tol
    } else {
        floor
    }
}

/// `a + b`, counter by counter.
fn add_stats(a: Stats, b: Stats) -> Stats {
    Stats {
        rhs_evals: a.rhs_evals + b.rhs_evals,
        steps: a.steps + b.steps,
        rejected: a.rejected + b.rejected,
        jacobian_evals: a.jacobian_evals + b.jacobian_evals,
        lu_decompositions: a.lu_decompositions + b.lu_decompositions,
        implicit_solves: a.implicit_solves + b.implicit_solves,
    }
}
