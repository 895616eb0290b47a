//! Pieces shared by the adaptive steppers: the tolerance-weighted error norm, Hairer's starting
//! step, the state kept between attempts and the step loop. The settings ([`StepControl`]) and
//! the elementary controller ([`Controller`]) are in `control.rs`.
//!
//! References (HNW I = Hairer, Nørsett & Wanner, *Solving Ordinary Differential Equations I*,
//! 2nd ed., 1993): error norm and controller HNW I §II.4 (4.11)–(4.13); starting step HNW I
//! §II.4 "Starting Step Size" (a)–(f); Gustafsson's predictive controller HNW II §IV.8 (8.21)
//! ([`Core::accepted_factor`], `control.rs`). [`super::DormandPrince45`], [`super::Rosenbrock`],
//! [`super::Rodas`] and [`super::ArkImex`] share these, the state they carry between attempts
//! ([`Core`]), the step loop ([`step`]) and the first step after an event's restart
//! ([`first_step_after_restart`]); [`super::DormandPrince45`] keeps its own (PI) controller.
//!
//! The first step after an event ([`super::Stepper::restart`], then
//! [`super::Stepper::first_step_after_restart`]): the state and statistics restart as in
//! `init`, but the first step is the last accepted step's size (at most `h_max`) when every
//! event function is armed at the restart ([`RestartStart::Armed`]), and the smaller of that
//! and Hairer's starting step (or `h_init`) when one is disarmed ([`RestartStart::Disarmed`]: a
//! function not tested in the first step, `events.rs`, so that step must be short enough not to
//! jump over its next root). Hairer's step alone ignores what the steps before the event learned
//! about the solution's scale (on the elbow runs often far too large, then rejected down by
//! factors of 5). Only for systems that allow it ([`super::HybridSystem::restart_keeps_step_size`]).

use super::control::{Controller, StepControl, StepSizeControl};
use super::{IntegrateError, OdeSystem, RestartStart, Stats, Stepper};

/// `sqrt(1/m sum (e_i / sc_i)^2)` over the `m` components `i` with `measured[i]`,
/// `sc_i = atol + rtol max(|y_i|, |y_new_i|)` (HNW I (4.11)); 0 for `m = 0`. NaN/inf
/// propagate. `measured` is the system's [`OdeSystem::error_measured`] (all true: every
/// component, summed over `0..n` in order, bit for bit the norm before the mask existed).
pub(super) fn error_norm(e: &[f64], y: &[f64], y_new: &[f64], atol: f64, rtol: f64, measured: &[bool]) -> f64 {
    let n = e.len();
    assert_eq!(measured.len(), n, "error_norm: mask length vs dim");
    let (mut sum, mut m) = (0.0, 0usize);
    for i in 0..n {
        if measured[i] {
            let sk = atol + rtol * y[i].abs().max(y_new[i].abs());
            sum += (e[i] / sk).powi(2);
            m += 1;
        }
    }
    if m == 0 {
        return 0.0;
    }
    (sum / m as f64).sqrt()
}

/// How the last rejected attempt failed, for the error returned when the step size collapses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Failure {
    /// Error test (or nothing yet).
    None,
    /// A non-finite stage value or derivative, produced at time `t` in component `index`.
    NonFinite { t: f64, index: usize },
    /// A singular iteration matrix in the step from `t` with step `h`.
    Singular { t: f64, h: f64 },
}

impl Failure {
    /// The error for a step size that fell below `h_min` or what `t` can resolve.
    pub fn collapse<E>(self, t: f64, h: f64) -> IntegrateError<E> {
        match self {
            Failure::None => IntegrateError::StepSizeTooSmall { t, h },
            Failure::NonFinite { t, index } => IntegrateError::NonFiniteState { t, index },
            Failure::Singular { t, h } => IntegrateError::SingularMatrix { t, h },
        }
    }
}

/// Outcome of one step attempt.
pub(super) enum Attempt {
    Accepted,
    Rejected,
}

/// What every adaptive stepper keeps between attempts besides its vectors.
#[derive(Clone, Debug)]
pub(super) struct Core {
    /// The user's tolerances and limits.
    pub control: StepControl,
    /// The method's controller constants.
    pub controller: Controller,
    /// Current time.
    pub t: f64,
    /// Start and size of the last accepted step (`h_last = 0` before the first step).
    pub t_prev: f64,
    pub h_last: f64,
    /// Next step size to try; `None` until the first `step` computes or takes `h_init`.
    pub h_next: Option<f64>,
    /// The last attempt was rejected (the next accepted step may not grow).
    pub rejected_last: bool,
    /// How the last rejected attempt failed.
    pub failure: Failure,
    pub stats: Stats,
    pub initialized: bool,
    /// Where the current call of [`step`] must stop (for a stepper's look ahead, e.g. how many
    /// steps remain).
    pub t_stop: f64,
    /// Singular iteration matrices in a row (the implicit methods; [`Core::reject_singular`]).
    pub singular_run: u32,
    /// The components the error norm measures (`dim` long), read from the system in every
    /// [`Core::init`] ([`OdeSystem::error_measured`]); allocated by the first.
    pub measured: Vec<bool>,
    /// The rule for the step after an accepted one ([`Core::accepted_factor`]).
    pub step_size_control: StepSizeControl,
    /// Size and scaled error (at least 1e-2, as `radau5.f`) of the last accepted step, for the
    /// predictive controller (`h_acc = 0` before the first since `init`).
    pub h_acc: f64,
    pub err_acc: f64,
    /// The last accepted step's size before a [`super::Stepper::restart`], until the first step
    /// after it is chosen ([`first_step_after_restart`]; 0: none).
    pub h_carry: f64,
}

impl Core {
    pub fn new(control: StepControl, controller: Controller) -> Self {
        Self {
            control,
            controller,
            t: 0.0,
            t_prev: 0.0,
            h_last: 0.0,
            h_next: None,
            rejected_last: false,
            failure: Failure::None,
            stats: Stats::default(),
            initialized: false,
            t_stop: 0.0,
            singular_run: 0,
            measured: Vec::new(),
            step_size_control: StepSizeControl::Elementary,
            h_acc: 0.0,
            err_acc: 1.0,
            h_carry: 0.0,
        }
    }

    /// [`error_norm`] with this stepper's tolerances and the system's measured components.
    pub fn error_norm(&self, e: &[f64], y: &[f64], y_new: &[f64]) -> f64 {
        error_norm(e, y, y_new, self.control.atol, self.control.rtol, &self.measured)
    }

    /// The start of every `init`: checks the dimensions (panics, naming the stepper `name`),
    /// reads which components the error norm measures (the system's choice at this state and
    /// mode: an event's restart reads it again), resets the statistics, rejects a non-finite
    /// `y0` and restarts the step control at `t0`. Allocates the mask on the first call only.
    pub fn init<S: OdeSystem>(
        &mut self,
        name: &str,
        dim: usize,
        sys: &S,
        t0: f64,
        y0: &[f64],
    ) -> Result<(), IntegrateError<S::Error>> {
        assert_eq!(sys.dim(), dim, "{name}::init: system dim vs stepper dim");
        self.measured.clear();
        self.measured.resize(dim, true);
        sys.error_measured(&mut self.measured);
        assert_eq!(y0.len(), dim, "{name}::init: y0 length vs dim");
        self.initialized = false;
        self.stats = Stats::default();
        if let Some(index) = super::first_non_finite(y0) {
            return Err(IntegrateError::NonFiniteState { t: t0, index });
        }
        self.t = t0;
        self.t_prev = t0;
        self.h_last = 0.0;
        self.h_next = None;
        self.rejected_last = false;
        self.failure = Failure::None;
        self.singular_run = 0;
        self.h_acc = 0.0;
        self.err_acc = 1.0;
        self.h_carry = 0.0;
        Ok(())
    }

    /// The last accepted step's size, to carry over a restart (0 before `init` or any step).
    pub fn h_to_carry(&self) -> f64 {
        if self.initialized {
            self.h_last
        } else {
            0.0
        }
    }

    /// The step-size factor `h_new / h` after the attempt of size `h` with scaled error `err`
    /// passed the error test (method of error order `1/expo - 1`): the elementary
    /// [`Controller::factor`]; with [`StepSizeControl::Predictive`] and an accepted step
    /// before it since the last `init` (a restart starts the history afresh), the smaller of
    /// that and [`Controller::predictive_factor`] (`radau5.f`). Records `h` and `err` as the
    /// last accepted step's: call it once per accepted step, before [`Core::accept`].
    pub fn accepted_factor(&mut self, err: f64, expo: f64, h: f64) -> f64 {
        let mut fac = self.controller.factor(err, expo);
        if self.step_size_control == StepSizeControl::Predictive && self.stats.steps > 0 && self.h_acc > 0.0 {
            fac = fac.min(self.controller.predictive_factor(err, expo, h, self.h_acc, self.err_acc));
        }
        self.h_acc = h;
        self.err_acc = err.max(1e-2);
        fac
    }

    /// Records a rejected attempt; the next one uses `h_next`.
    pub fn reject(&mut self, h_next: f64, failure: Failure) -> Attempt {
        self.h_next = Some(h_next);
        self.rejected_last = true;
        self.failure = failure;
        self.stats.rejected += 1;
        Attempt::Rejected
    }

    /// Records a rejection caused by a non-finite value produced at time `t_bad` in component
    /// `index` of an attempt with step `h`: the next attempt uses `fac_min h`.
    pub fn reject_non_finite(&mut self, h: f64, t_bad: f64, index: usize) -> Attempt {
        self.reject(
            h * self.controller.fac_min,
            Failure::NonFinite { t: t_bad, index },
        )
    }

    /// A singular iteration matrix in the attempt with step `h` from `t` (as `rodas.f`): halves
    /// the step (a rejection), up to 5 times in a row, then [`IntegrateError::SingularMatrix`].
    /// The implicit steppers set `singular_run = 0` once a matrix factors.
    pub fn reject_singular<E>(&mut self, h: f64) -> Result<Attempt, IntegrateError<E>> {
        let t = self.t;
        self.stats.rejected += 1;
        self.singular_run += 1;
        self.rejected_last = true;
        self.failure = Failure::Singular { t, h };
        if self.singular_run >= 5 {
            return Err(IntegrateError::SingularMatrix { t, h });
        }
        self.h_next = Some(0.5 * h);
        Ok(Attempt::Rejected)
    }

    /// The controller's proposal `h_new` after an accepted step `h`, limited: no growth right
    /// after a rejection, and a step shortened to land on `t_stop` (`h < h_proposed`) keeps the
    /// step the controller had planned.
    pub fn limit_growth(&self, h_new: f64, h: f64, h_proposed: f64) -> f64 {
        let mut h_new = h_new;
        if self.rejected_last {
            h_new = h_new.min(h);
        }
        if h < h_proposed {
            h_new = h_new.max(h_proposed);
        }
        h_new
    }

    /// Commits an accepted step `h` from `t` to `t_new`; the next one tries `h_new` (at most
    /// `h_max`).
    pub fn accept(&mut self, t_new: f64, h: f64, h_new: f64) {
        self.t_prev = self.t;
        self.t = t_new;
        self.h_last = h;
        self.h_next = Some(h_new.min(self.control.h_max));
        self.rejected_last = false;
        self.failure = Failure::None;
        self.stats.steps += 1;
    }
}

/// An adaptive one-step method, driven by [`step`].
pub(super) trait Adaptive<S: OdeSystem> {
    /// The stepper's type name, for panic messages.
    const NAME: &'static str;
    fn core(&mut self) -> &mut Core;
    /// The first step size when the settings give none (Hairer's algorithm, [`initial_step`]).
    fn starting_step(&mut self, sys: &mut S) -> Result<f64, IntegrateError<S::Error>>;
    /// One attempt from `(t, y)` with step `h` ending at `t_new`; commits on acceptance.
    /// `h_proposed` is the controller's step before it was shortened to land on `t_stop`.
    fn attempt(
        &mut self,
        sys: &mut S,
        h: f64,
        t_new: f64,
        h_proposed: f64,
    ) -> Result<Attempt, IntegrateError<S::Error>>;
}

/// [`super::Stepper::step`] of an adaptive stepper: attempts until one is accepted, landing on
/// `t_stop`, within `max_steps` attempts and above the smallest step.
pub(super) fn step<S: OdeSystem, A: Adaptive<S>>(
    st: &mut A,
    sys: &mut S,
    t_stop: f64,
) -> Result<f64, IntegrateError<S::Error>> {
    let core = st.core();
    assert!(
        core.initialized,
        "{}::step called before a successful init",
        A::NAME
    );
    // nothing to do at or past the stop time (forward integration only)
    if t_stop.is_nan() || t_stop <= core.t {
        return Ok(core.t);
    }
    let h_first = match (core.h_next, core.control.h_init) {
        (Some(h), _) | (None, Some(h)) => h,
        (None, None) => st.starting_step(sys)?,
    };
    st.core().h_next = Some(h_first);
    st.core().t_stop = t_stop;
    loop {
        let core = st.core();
        let max_steps = core.control.max_steps;
        if core.stats.steps + core.stats.rejected >= max_steps {
            return Err(IntegrateError::TooManySteps {
                t: core.t,
                max_steps,
            });
        }
        let h = core.h_next.unwrap_or(h_first).min(core.control.h_max);
        if step_collapsed(h, core.t, core.control.h_min) {
            return Err(core.failure.collapse(core.t, h));
        }
        let (h_try, t_new) = land(core.t, h, t_stop);
        if let Attempt::Accepted = st.attempt(sys, h_try, t_new, h)? {
            return Ok(st.core().t);
        }
    }
}

/// `init` at an event's restart, keeping the last accepted step's size in [`Core::h_carry`]
/// for [`first_step_after_restart`] (every adaptive stepper's `Stepper::restart`).
pub(super) fn restart<S: OdeSystem, A: Adaptive<S> + Stepper<S>>(st: &mut A, sys: &mut S, t0: f64, y0: &[f64]) -> Result<(), IntegrateError<S::Error>> {
    let h_last = st.core().h_to_carry();
    Stepper::init(st, sys, t0, y0)?;
    st.core().h_carry = h_last;
    Ok(())
}

/// [`super::Stepper::first_step_after_restart`] of an adaptive stepper whose `restart` kept
/// [`Core::h_carry`] (module docs): the last accepted step where every event function is
/// armed, the smaller of it and the fresh starting step (or `h_init`) where one is disarmed;
/// at most `h_max`. Nothing (`init`'s choice) before any accepted step or once stepped.
pub(super) fn first_step_after_restart<S: OdeSystem, A: Adaptive<S>>(
    st: &mut A,
    sys: &mut S,
    start: RestartStart,
) -> Result<(), IntegrateError<S::Error>> {
    let core = st.core();
    let h_last = std::mem::take(&mut core.h_carry);
    if h_last <= 0.0 || core.stats.steps > 0 {
        return Ok(());
    }
    let h = match start {
        RestartStart::Armed => h_last,
        RestartStart::Disarmed => {
            let fresh = match core.control.h_init {
                Some(h) => h,
                None => st.starting_step(sys)?,
            };
            h_last.min(fresh)
        }
    };
    let core = st.core();
    core.h_next = Some(h.min(core.control.h_max));
    Ok(())
}

/// `h` is too small: below `h_min`, or `0.1 h <= |t| eps` (`dopri5.f`), or not positive.
pub(super) fn step_collapsed(h: f64, t: f64, h_min: f64) -> bool {
    !(h >= h_min && 0.1 * h > t.abs() * f64::EPSILON && h > 0.0)
}

/// Hairer's starting step (HNW I §II.4, (a)–(f)) for a method of order `order`, in the RMS
/// norm above over the `measured` components ([`Core::measured`]); `f0 = f(t, y)`. Uses one evaluation of `rhs` (counted), with `y1`, `f1` as
/// scratch. A non-finite probe is ignored (the step then comes from `f0` alone).
#[allow(clippy::too_many_arguments)]
pub(super) fn initial_step<S: OdeSystem>(
    sys: &mut S,
    stats: &mut Stats,
    t: f64,
    y: &[f64],
    f0: &[f64],
    y1: &mut [f64],
    f1: &mut [f64],
    c: &StepControl,
    measured: &[bool],
    order: i32,
) -> Result<f64, IntegrateError<S::Error>> {
    let n = y.len();
    assert_eq!(measured.len(), n, "initial_step: mask length vs dim");
    let inv_n = 1.0 / measured.iter().filter(|&&m| m).count().max(1) as f64;
    let (mut d0, mut d1) = (0.0, 0.0);
    for i in (0..n).filter(|&i| measured[i]) {
        let sk = c.atol + c.rtol * y[i].abs();
        d0 += (y[i] / sk).powi(2);
        d1 += (f0[i] / sk).powi(2);
    }
    let (d0, d1) = ((d0 * inv_n).sqrt(), (d1 * inv_n).sqrt());
    let h0 = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6
    } else {
        0.01 * d0 / d1
    };
    let h0 = h0.min(c.h_max);
    for i in 0..n {
        y1[i] = y[i] + h0 * f0[i];
    }
    stats.rhs_evals += 1;
    sys.rhs(t + h0, y1, f1).map_err(IntegrateError::Rhs)?;
    let mut d2 = 0.0;
    for i in (0..n).filter(|&i| measured[i]) {
        let sk = c.atol + c.rtol * y[i].abs();
        d2 += ((f1[i] - f0[i]) / sk).powi(2);
    }
    let d2 = (d2 * inv_n).sqrt() / h0;
    let dmax = d1.max(d2);
    let h1 = if dmax <= 1e-15 {
        (h0 * 1e-3).max(1e-6)
    } else {
        (0.01 / dmax).powf(1.0 / f64::from(order + 1))
    };
    let h = (100.0 * h0).min(h1).min(c.h_max);
    Ok(if h.is_finite() && h > 0.0 { h } else { h0 })
}

/// Where the next attempt from `t` with the controller's step `h` ends: on `t_stop` when
/// `t + 1.01 h` reaches it (stretching by up to 1% rather than leaving a sliver), else `t + h`.
/// Returns `(h_try, t_new)`.
pub(super) fn land(t: f64, h: f64, t_stop: f64) -> (f64, f64) {
    if t + 1.01 * h >= t_stop {
        (t_stop - t, t_stop)
    } else {
        (h, t + h)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn error_norm_is_weighted_rms() {
        let e = [1e-6, -2e-6];
        let y = [0.0, 1.0];
        let y_new = [0.0, -3.0];
        // sc = [1e-6, 1e-6 + 3e-6]
        let expect = ((1.0f64 + 0.25) / 2.0).sqrt();
        assert!((error_norm(&e, &y, &y_new, 1e-6, 1e-6, &[true; 2]) - expect).abs() < 1e-15);
        assert_eq!(error_norm(&[], &[], &[], 1.0, 1.0, &[]), 0.0);
    }

    /// A component left out changes neither the sum nor the divisor: the norm of `[a, x, x, b]`
    /// measuring components 0 and 3 is the RMS of `[a, b]` whatever `x` is (0, as a separated
    /// contact's quadratures, or large), exactly; measuring all four it is the RMS over all
    /// four, as before the mask existed (bit for bit: same terms, same order), where the two
    /// zeros dilute it by sqrt(2/4).
    #[test]
    fn a_component_left_out_does_not_change_the_norm() {
        let (atol, rtol) = (1e-10, 1e-8);
        let y = [0.3, 2.0, 0.0, -1.5];
        let y_new = [0.31, 2.0, 0.0, -1.49];
        let two = error_norm(&[4e-10, -2e-10], &[0.3, -1.5], &[0.31, -1.49], atol, rtol, &[true; 2]);
        let ends = [true, false, false, true];
        for x in [0.0, 1e-9, 3.0, -1e6] {
            let e = [4e-10, x, x, -2e-10];
            assert_eq!(error_norm(&e, &y, &y_new, atol, rtol, &ends), two, "x = {x}");
        }
        let four = error_norm(&[4e-10, 0.0, 0.0, -2e-10], &y, &y_new, atol, rtol, &[true; 4]);
        assert!((four - two * 0.5f64.sqrt()).abs() <= 1e-15 * two, "{four} vs {two}");
        let mut sum = 0.0;
        for (i, e) in [4e-10, 0.0, 0.0, -2e-10].iter().enumerate() {
            let sk = atol + rtol * f64::abs(y[i]).max(y_new[i].abs());
            sum += (e / sk).powi(2);
        }
        assert_eq!(four, (sum / 4.0).sqrt());
        // nothing measured: 0, as the empty norm
        assert_eq!(error_norm(&[1.0, 2.0], &[0.0; 2], &[0.0; 2], atol, rtol, &[false; 2]), 0.0);
    }

    /// The system's mask reaches the stepper's norm and starting step through `Core::init`,
    /// read again by every `init` (an event's restart), without allocating after the first.
    #[test]
    fn core_init_reads_the_systems_mask_at_every_init() {
        struct Quad(bool);
        impl OdeSystem for Quad {
            type Error = std::convert::Infallible;
            fn dim(&self) -> usize {
                3
            }
            fn rhs(&mut self, _t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), Self::Error> {
                dydt.copy_from_slice(&[-y[0], y[0] * y[0], 1.0]);
                Ok(())
            }
            fn error_measured(&self, measured: &mut [bool]) {
                measured[1] = self.0;
            }
        }
        let controller = Controller { safety: 0.9, fac_min: 0.2, fac_max: 6.0 };
        let mut core = Core::new(StepControl::new(1e-6, 1e-9), controller);
        let (y, y_new) = ([1.0, 0.0, 0.0], [0.9, 0.1, 0.1]);
        core.init("Test", 3, &Quad(false), 0.0, &y).expect("init");
        assert_eq!(core.measured, [true, false, true]);
        assert_eq!(core.error_norm(&[1e-7, 5.0, 1e-7], &y, &y_new), core.error_norm(&[1e-7, 0.0, 1e-7], &y, &y_new));
        let ptr = core.measured.as_ptr();
        core.init("Test", 3, &Quad(true), 0.0, &y).expect("init");
        assert_eq!((core.measured.as_slice(), core.measured.as_ptr()), ([true; 3].as_slice(), ptr));
        assert!(core.error_norm(&[1e-7, 5.0, 1e-7], &y, &y_new) > 1e5);
    }
}
