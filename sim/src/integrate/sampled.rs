//! Driving a stepper over an interval and reporting the solution on a fixed output grid.
//!
//! Output times are `t_k = t0 + k (t_end − t0) / N` when the span is a whole number N of
//! output intervals (correctly rounded: 0.009 s, not 9 × 0.001 s), else `t_k = t0 + k dt_out`;
//! by multiplication, with no accumulated round-off,
//! independent of the solver's steps: points inside a step come from the stepper's dense output
//! (diffsol's `interpolate`; HNW I §II.6), so an adaptive solver takes exactly the same steps
//! whatever the output rate, and a recording never depends on step sizes. After every accepted
//! step the system may project the state ([`OdeSystem::project`]).

use std::time::{Duration, Instant};

use super::{IntegrateError, OdeSystem, Stats, Stepper};

/// Relative slack for treating `(t_end - t0) / dt_out` as an integer.
const GRID_REL_TOL: f64 = 1e-9;

/// Drive a stepper from `t0` to `t_end` and call `sample(t_k, y(t_k))` at every output grid
/// point `t_k = t0 + k dt_out` (`k = 0..=N`, computed by multiplication; the last point is
/// exactly `t_end` when `(t_end - t0) / dt_out` is an integer within 1e-9 relative),
/// independent of the solver's steps (via `interpolate`). The callback's error type is the
/// system error type; `sample` may return `Err` to stop.
///
/// - `y0` has length `sys.dim()`; the first sample is `(t0, y0)` with `y0` bit for bit.
/// - When `(t_end - t0) / dt_out` is not an integer, the grid stops at the last `t_k < t_end`
///   and integration still continues to `t_end`: on return `stepper.t() == t_end` and
///   `stepper.y()` is `y(t_end)`, whether or not `t_end` was sampled.
/// - The stepper is always asked to stop at `t_end` only, never at output times.
///
/// Returns the stepper's [`Stats`] for the whole run. Allocates one output buffer of length
/// `dim` per call, nothing per step.
///
/// # Errors
/// The stepper's errors unchanged (samples before the failure have been delivered); a failing
/// `sample` gives [`IntegrateError::Sample`] with the output time; a non-finite
/// `t0`/`t_end`/`dt_out`, `dt_out <= 0`, `t_end < t0` or more than 2^53 samples gives
/// [`IntegrateError::InvalidOutputGrid`] before anything is evaluated.
pub fn integrate_sampled<S: OdeSystem, St: Stepper<S> + ?Sized>(
    stepper: &mut St,
    sys: &mut S,
    t0: f64,
    y0: &[f64],
    t_end: f64,
    dt_out: f64,
    sample: impl FnMut(f64, &[f64]) -> Result<(), S::Error>,
) -> Result<Stats, IntegrateError<S::Error>> {
    integrate_sampled_within(stepper, sys, t0, y0, t_end, dt_out, None, sample)
}

/// Accepted steps between two looks at the clock in [`integrate_sampled_within`].
const CLOCK_EVERY: u64 = 16;

/// After this much wall time [`integrate_sampled_within`] judges the pace: a run whose
/// simulated time so far projects more than twice its budget stops then
/// ([`IntegrateError::TooSlow`]) instead of at its deadline. A sane run is either done by then
/// (the paper's runs take about a second) or keeps its pace well inside the budget.
pub const PACE_AFTER: Duration = Duration::from_secs(5);

/// When [`integrate_sampled_within`] must stop: at `at`, or as soon as, after
/// `judge_pace_after` of wall time, the pace so far projects more than twice the time to `at`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Deadline {
    pub at: Instant,
    pub judge_pace_after: Duration,
}

impl Deadline {
    /// At `at`, the pace judged after [`PACE_AFTER`].
    pub fn new(at: Instant) -> Self {
        Deadline { at, judge_pace_after: PACE_AFTER }
    }
}

/// A wall-clock deadline as the long loops inside one step see it (a difference Jacobian's
/// columns, an LU factorisation's, the trial points of an event location, a system's mode
/// enumeration): [`Watch::out_of_time`] reads the clock (no allocation, some tens of ns), so a
/// loop whose every pass costs a right-hand side looks at every pass, and a cheaper one every
/// few. The default watches nothing.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Watch {
    at: Option<Instant>,
}

impl Watch {
    /// Watches `deadline` (`None`: nothing).
    pub fn new(deadline: Option<Deadline>) -> Self {
        Watch { at: deadline.map(|d| d.at) }
    }

    /// Watches the instant `at`.
    pub fn until(at: Instant) -> Self {
        Watch { at: Some(at) }
    }

    /// Whether the deadline has passed.
    #[inline]
    pub fn out_of_time(&self) -> bool {
        self.at.is_some_and(|at| Instant::now() >= at)
    }
}

/// Where in a step a run was when its wall-time budget ran out ([`IntegrateError::OutOfTime`]),
/// for the message: between steps, or inside one of the long loops a step may run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Phase {
    /// Between steps or events (the driver's clock).
    #[default]
    Stepping,
    /// Building the Jacobian by differences: `column` (1-based) of `columns`, each one
    /// evaluation of the right-hand side.
    Jacobian { column: usize, columns: usize },
    /// Factoring the iteration matrix: `column` (1-based) of `columns`.
    Factoring { column: usize, columns: usize },
    /// Locating an event on a step's dense output: after `trials` trial points.
    LocatingEvent { trials: usize },
    /// Choosing the contact modes: after `tried` of the `of` combinations.
    ChoosingModes { tried: usize, of: usize },
}

impl std::fmt::Display for Phase {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Phase::Stepping => write!(f, "between steps"),
            Phase::Jacobian { column, columns } => write!(f, "while building the Jacobian (column {column} of {columns})"),
            Phase::Factoring { column, columns } => {
                write!(f, "while factoring the iteration matrix (column {column} of {columns})")
            }
            Phase::LocatingEvent { trials } => write!(f, "while locating an event (after {trials} trial points)"),
            Phase::ChoosingModes { tried, of } => {
                write!(f, "while choosing the contact modes ({tried} of {of} combinations tried)")
            }
        }
    }
}

/// [`integrate_sampled`] with a wall-clock `deadline`: after it passes, the run stops with
/// [`IntegrateError::OutOfTime`] at the stepper's time (the clock is read every
/// [`CLOCK_EVERY`] accepted steps; a step ends before it is read, so a run may overrun by
/// those steps). After [`Deadline::judge_pace_after`], a run whose pace so far,
/// `elapsed × (t_end − t0) / (t − t0)`, projects more than twice the budget stops at once
/// ([`IntegrateError::TooSlow`]). `None`: no deadline.
#[allow(clippy::too_many_arguments)]
pub fn integrate_sampled_within<S: OdeSystem, St: Stepper<S> + ?Sized>(
    stepper: &mut St,
    sys: &mut S,
    t0: f64,
    y0: &[f64],
    t_end: f64,
    dt_out: f64,
    deadline: Option<Deadline>,
    mut sample: impl FnMut(f64, &[f64]) -> Result<(), S::Error>,
) -> Result<Stats, IntegrateError<S::Error>> {
    let grid = OutputGrid::new(t0, t_end, dt_out)?;
    let n_out = grid.n_out;
    // the stepper's own long loops (a difference Jacobian) look at the deadline too
    stepper.set_watch(Watch::new(deadline));

    // first sample: the initial state exactly
    stepper.init(sys, t0, y0)?;
    sample(t0, stepper.y()).map_err(|source| IntegrateError::Sample { t: t0, source })?;

    let mut buf = vec![0.0; y0.len()];
    let mut k = 1;
    let mut pace = Pace::new(deadline, t0, t_end);
    loop {
        // report every grid point inside the last accepted step [t_prev, t]
        while k <= n_out {
            let t_k = grid.time(k);
            if t_k > stepper.t() {
                break;
            }
            if t_k == stepper.t() {
                sample(t_k, stepper.y())
            } else {
                stepper.interpolate(t_k, &mut buf);
                sample(t_k, &buf)
            }
            .map_err(|source| IntegrateError::Sample { t: t_k, source })?;
            k += 1;
        }
        if stepper.t() >= t_end {
            break;
        }
        // let the system move the state back onto its invariant manifold (after sampling the
        // step, so the samples are the method's own dense output)
        if k > 1 || stepper.t() > t0 {
            buf.copy_from_slice(stepper.y());
            if sys
                .project(stepper.t(), &mut buf)
                .map_err(IntegrateError::Rhs)?
            {
                stepper.set_state(sys, &buf)?;
            }
        }
        let t_before = stepper.t();
        let t_after = stepper.step(sys, t_end)?;
        if t_after.is_nan() || t_after <= t_before {
            // a stepper that stops advancing before t_end would loop forever
            return Err(IntegrateError::StepSizeTooSmall {
                t: t_before,
                h: t_after - t_before,
            });
        }
        pace.after_step(t_after)?;
    }
    Ok(stepper.stats())
}

/// The output grid of [`integrate_sampled_within`] (and of the event driver): `n_out`
/// intervals, the last one ending exactly on `t_end` when the span is a whole number of
/// output intervals (within [`GRID_REL_TOL`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct OutputGrid {
    t0: f64,
    t_end: f64,
    dt_out: f64,
    /// Index of the last output time (`k = 0..=n_out`).
    pub(super) n_out: u64,
    lands_on_end: bool,
}

impl OutputGrid {
    /// The grid, or [`IntegrateError::InvalidOutputGrid`] for a non-finite value, `dt_out <= 0`,
    /// `t_end < t0` or more than 2^53 samples.
    pub(super) fn new<E>(t0: f64, t_end: f64, dt_out: f64) -> Result<Self, IntegrateError<E>> {
        let invalid = || IntegrateError::InvalidOutputGrid { t0, t_end, dt_out };
        if !(t0.is_finite() && t_end.is_finite() && dt_out.is_finite() && dt_out > 0.0 && t_end >= t0) {
            return Err(invalid());
        }
        let ratio = (t_end - t0) / dt_out;
        if ratio > 9.007_199_254_740_992e15 {
            return Err(invalid());
        }
        let nearest = ratio.round();
        let lands_on_end = (ratio - nearest).abs() <= GRID_REL_TOL * nearest.max(1.0);
        let n_out = if lands_on_end { nearest } else { ratio.floor() } as u64;
        Ok(OutputGrid { t0, t_end, dt_out, n_out, lands_on_end })
    }

    /// Output time `k` (by multiplication, no accumulated round-off).
    pub(super) fn time(&self, k: u64) -> f64 {
        let OutputGrid { t0, t_end, dt_out, n_out, lands_on_end } = *self;
        if k == n_out && lands_on_end {
            t_end
        } else if lands_on_end {
            // k (t_end - t0) / N, correctly rounded: 0.009, not 9 * 0.001 = 0.009000000000000001
            t0 + (k as f64 * (t_end - t0)) / n_out as f64
        } else {
            t0 + k as f64 * dt_out
        }
    }
}

/// The pace rule of [`Deadline`]: a run that has spent `spent` of wall time on the share `done`
/// of its simulated span, with `limit` of wall time in all, is too slow when `spent` is at
/// least `judge_after` and the linear projection `spent / done` exceeds twice `limit`:
/// `Some(projection, s)`, else `None`. The projection is from the run's start, so a run whose
/// start is far slower than the rest (the rodas5p rtol-1e-12 reference of `sim precision` on
/// the unilateral scene spends ~11 % of its work on the first 0.03 % of its 0.3 s) is judged
/// by its start: a caller that knows the run will finish (`precision::reference`) passes
/// `judge_after = limit`, which leaves only the deadline.
pub fn too_slow(spent: Duration, done: f64, judge_after: Duration, limit: Duration) -> Option<f64> {
    if spent < judge_after || done <= 0.0 {
        return None;
    }
    let projected_s = spent.as_secs_f64() / done;
    (projected_s > 2.0 * limit.as_secs_f64()).then_some(projected_s)
}

/// The wall-clock watch of a run ([`Deadline`]): counts accepted steps and reads the clock
/// every [`CLOCK_EVERY`] of them.
pub(super) struct Pace {
    deadline: Option<Deadline>,
    t0: f64,
    t_end: f64,
    steps: u64,
    started: Instant,
}

impl Pace {
    pub(super) fn new(deadline: Option<Deadline>, t0: f64, t_end: f64) -> Self {
        Pace { deadline, t0, t_end, steps: 0, started: Instant::now() }
    }

    /// After an accepted step ending at `t_after`: [`IntegrateError::OutOfTime`] past the
    /// deadline, [`IntegrateError::TooSlow`] when the pace so far cannot make it.
    pub(super) fn after_step<E>(&mut self, t_after: f64) -> Result<(), IntegrateError<E>> {
        self.steps += 1;
        if let Some(deadline) = self.deadline {
            if self.steps.is_multiple_of(CLOCK_EVERY) {
                let now = Instant::now();
                if now >= deadline.at {
                    return Err(IntegrateError::OutOfTime { t: t_after, during: Phase::Stepping });
                }
                let spent = now.duration_since(self.started);
                let done = (t_after - self.t0) / (self.t_end - self.t0);
                if let Some(projected_s) = too_slow(spent, done, deadline.judge_pace_after, deadline.at.duration_since(self.started)) {
                    return Err(IntegrateError::TooSlow { t: t_after, projected_s });
                }
            }
        }
        Ok(())
    }

    /// After an event handled at `t`: [`IntegrateError::OutOfTime`] past the deadline. Read at
    /// every event, since handling one (a system's mode problem) may cost far more than a step.
    pub(super) fn after_event<E>(&self, t: f64) -> Result<(), IntegrateError<E>> {
        match self.deadline {
            Some(deadline) if Instant::now() >= deadline.at => Err(IntegrateError::OutOfTime { t, during: Phase::Stepping }),
            _ => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    /// The pace rule's decisions on (simulated time, wall time) sequences, the run's span 0.3 s
    /// and its limit 600 s: the rtol-1e-12 reference's profile (measured on the unilateral scene,
    /// `sim run`, test profile, unloaded: 0.1 ms of 0.3 s after 0.9 s of wall time, 1 ms after
    /// 1.3 s, 10 ms after 2.0 s, 0.3 s after 8.4 s) slowed 10× by load is stopped at its first
    /// judgment with the default `PACE_AFTER` (what `sim precision` did on a loaded machine), and
    /// never with `judge_after = limit` (`precision::reference`'s budget), where only the
    /// deadline stops it; a run crawling at a constant pace that projects 3× its limit is stopped
    /// at the first look past `judge_after` and not before; a run at a constant pace within the
    /// limit never.
    #[test]
    fn pace_rule_decides_on_the_projection_from_the_start() {
        let (span, limit) = (0.3, Duration::from_secs(600));
        let profile = [(0.0001, 0.9), (0.001, 1.3), (0.01, 2.0), (0.3, 8.4)];
        // wall time at simulated time t by linear interpolation of the profile, slowed `load`×
        let wall = |t: f64, load: f64| {
            let mut prev = (0.0, 0.0);
            for &(ts, ws) in &profile {
                if t <= ts {
                    return load * (prev.1 + (ws - prev.1) * (t - prev.0) / (ts - prev.0));
                }
                prev = (ts, ws);
            }
            load * prev.1
        };
        let judge = |t: f64, w: f64, after: Duration| too_slow(Duration::from_secs_f64(w), t / span, after, limit);
        let ts: Vec<f64> = (1..=3000).map(|i| span * f64::from(i) / 3000.0).chain([2e-5, 5e-5, 1e-4, 3e-4]).collect();
        // loaded 10×: the default rule stops the reference (the first judgment at 5 s projects
        // 10 × 0.9 s / (1e-4/0.3) ≈ 27 000 s > 1 200 s)
        let stopped: Vec<f64> = ts.iter().filter(|&&t| judge(t, wall(t, 10.0), PACE_AFTER).is_some()).copied().collect();
        assert!(!stopped.is_empty() && stopped.iter().all(|&t| t < 0.1), "{stopped:?}");
        let first = stopped.iter().copied().fold(f64::INFINITY, f64::min);
        assert!(wall(first, 10.0) >= 5.0, "judged before PACE_AFTER");
        // the same loaded run with judge_after = limit: never stopped by the pace (84 s ≤ 600 s)
        assert!(ts.iter().all(|&t| judge(t, wall(t, 10.0), limit).is_none()));
        // unloaded, the default rule lets it run (8.4 s)
        assert!(ts.iter().all(|&t| judge(t, wall(t, 1.0), PACE_AFTER).is_none()));
        // a crawl at a constant pace projecting 1 800 s (3× the limit): stopped from 5 s on
        let crawl = |t: f64| 1800.0 * t / span;
        for &t in &ts {
            let w = crawl(t);
            let verdict = judge(t, w, PACE_AFTER);
            assert_eq!(verdict.is_some(), w >= 5.0, "t {t}, wall {w}");
            if let Some(p) = verdict {
                assert!((p - 1800.0).abs() <= 1e-9 * 1800.0, "projection {p}");
            }
        }
        // a constant pace within the limit (projecting 1 100 s < 2 × 600 s): never
        assert!(ts.iter().all(|&t| judge(t, 1100.0 * t / span, PACE_AFTER).is_none()));
        // nothing simulated yet: no projection
        assert_eq!(too_slow(Duration::from_secs(100), 0.0, PACE_AFTER, limit), None);
    }

    use super::super::test_problems::{
        ExactSolution, FailingRhs, HarmonicOscillator, Kepler, RhsFailure,
    };
    use super::super::{DormandPrince45, Rk4, StepControl};
    use super::*;

    /// Collects all samples of one run.
    fn collect<P: ExactSolution, St: Stepper<P>>(
        st: &mut St,
        p: &mut P,
        t_end: f64,
        dt_out: f64,
    ) -> (Vec<(f64, Vec<f64>)>, Stats) {
        let y0 = p.y0();
        let mut out = Vec::new();
        let stats = integrate_sampled(st, p, p.t0(), &y0, t_end, dt_out, |t, y| {
            out.push((t, y.to_vec()));
            Ok(())
        })
        .expect("integrate_sampled");
        (out, stats)
    }

    fn max_err<P: ExactSolution>(p: &P, samples: &[(f64, Vec<f64>)]) -> f64 {
        let mut ex = vec![0.0; p.dim()];
        let mut e: f64 = 0.0;
        for (t, y) in samples {
            p.exact(*t, &mut ex);
            for (a, b) in y.iter().zip(&ex) {
                e = e.max((a - b).abs());
            }
        }
        e
    }

    #[test]
    fn sampled_times_are_exactly_on_the_grid() {
        for (t0, t_end, dt_out, n) in [
            (0.0, 1.0, 0.1, 10u64),
            (0.3, 2.3, 0.01, 200),
            (1.0, 1.0 + 7.0 * 0.013, 0.013, 7),
            (0.0, 0.0, 0.1, 0),
        ] {
            for which in ["rk4", "dopri5"] {
                let mut p = HarmonicOscillator::default();
                let y0 = [0.25, -0.5];
                let mut times = Vec::new();
                let mut first = None;
                let mut sample = |t: f64, y: &[f64]| {
                    if first.is_none() {
                        first = Some(y.to_vec());
                    }
                    times.push(t);
                    Ok(())
                };
                let res = if which == "rk4" {
                    integrate_sampled(
                        &mut Rk4::new(2, 0.037),
                        &mut p,
                        t0,
                        &y0,
                        t_end,
                        dt_out,
                        &mut sample,
                    )
                } else {
                    let mut st = DormandPrince45::new(2, StepControl::new(1e-6, 1e-9));
                    integrate_sampled(&mut st, &mut p, t0, &y0, t_end, dt_out, &mut sample)
                };
                res.expect("run");
                assert_eq!(times.len() as u64, n + 1, "{which} {t0} {t_end} {dt_out}");
                assert_eq!(first.as_deref(), Some(y0.as_slice()));
                for (k, &t) in times.iter().enumerate() {
                    let expected = if k as u64 == n {
                        t_end
                    } else {
                        t0 + (k as f64 * (t_end - t0)) / n as f64
                    };
                    assert_eq!(t, expected, "{which}: sample {k}");
                }
                assert_eq!(times.last().copied(), Some(t_end));
            }
        }
    }

    #[test]
    fn sampled_non_integer_span_stops_grid_but_integrates_to_t_end() {
        let mut p = HarmonicOscillator::default();
        let mut st = Rk4::new(2, 0.01);
        let (samples, _) = collect(&mut st, &mut p, 1.05, 0.1);
        assert_eq!(samples.len(), 11); // 0.0, 0.1, ..., 1.0
        assert_eq!(samples.last().map(|s| s.0), Some(10.0 * 0.1));
        assert_eq!(st.t(), 1.05);
    }

    // RK4 with steps 10x the output interval and 10x smaller: both follow the exact solution
    // to RK4 accuracy (h = 0.1: ~1e-5 incl. Hermite; h = 0.001: ~1e-12). Bounds: 1e-4, 1e-10.
    #[test]
    fn sampled_rk4_steps_larger_and_smaller_than_dt_out() {
        let mut p = Kepler { e: 0.3 };
        let (coarse, s1) = collect(&mut Rk4::new(4, 0.1), &mut p, 3.0, 0.01);
        let (fine, s2) = collect(&mut Rk4::new(4, 0.001), &mut p, 3.0, 0.1);
        assert_eq!((coarse.len(), fine.len()), (301, 31));
        assert_eq!((s1.steps, s2.steps), (30, 3000));
        let (e1, e2) = (max_err(&p, &coarse), max_err(&p, &fine));
        eprintln!("rk4 coarse steps: max err {e1:.2e}; fine steps: {e2:.2e}");
        assert!(e1 < 1e-4, "{e1}");
        assert!(e2 < 1e-10, "{e2}");
    }

    // That an adaptive stepper's steps do not depend on the output grid, for every method:
    // the contract (`contract/behaviour.rs`).

    #[test]
    fn sampled_callback_error_stops_the_run() {
        let mut p = FailingRhs { t_fail: 100.0 };
        let mut st = Rk4::new(1, 0.05);
        let mut count = 0;
        let res = integrate_sampled(&mut st, &mut p, 0.0, &[1.0], 10.0, 0.1, |t, _| {
            count += 1;
            if t >= 0.5 {
                Err(RhsFailure { t })
            } else {
                Ok(())
            }
        });
        match res {
            Err(IntegrateError::Sample { t, source }) => {
                assert_eq!(t, 5.0 * 0.1);
                assert_eq!(source, RhsFailure { t });
            }
            other => panic!("expected Sample error, got {other:?}"),
        }
        assert_eq!(count, 6);
        assert!(st.t() < 1.0, "kept integrating after the callback failed");
    }

    #[test]
    fn sampled_rhs_error_passes_through() {
        let mut p = FailingRhs { t_fail: 0.42 };
        let mut st = DormandPrince45::new(1, StepControl::new(1e-6, 1e-9));
        let mut last = 0.0;
        let res = integrate_sampled(&mut st, &mut p, 0.0, &[1.0], 1.0, 0.1, |t, _| {
            last = t;
            Ok(())
        });
        assert!(
            matches!(res, Err(IntegrateError::Rhs(RhsFailure { t })) if t >= 0.42),
            "{res:?}"
        );
        assert!(last < 0.42);
    }

    /// A deadline in the past stops the run after the first clock reading, with the time
    /// reached; without one the same run completes.
    #[test]
    fn sampled_deadline_stops_the_run() {
        let mut p = HarmonicOscillator::default();
        let mut st = Rk4::new(2, 1e-3);
        let mut samples = 0;
        let res = integrate_sampled_within(&mut st, &mut p, 0.0, &[1.0, 0.0], 1.0, 0.1, Some(Deadline::new(Instant::now())), |_, _| {
            samples += 1;
            Ok(())
        });
        match res {
            Err(IntegrateError::OutOfTime { t, during }) => assert_eq!((t, during), (st.t(), Phase::Stepping)),
            other => panic!("expected OutOfTime, got {other:?}"),
        }
        assert_eq!(st.stats().steps, CLOCK_EVERY);
        assert_eq!(samples, 1);
        let mut st = Rk4::new(2, 1e-3);
        let later = Instant::now() + std::time::Duration::from_secs(3600);
        let stats = integrate_sampled_within(&mut st, &mut p, 0.0, &[1.0, 0.0], 1.0, 0.1, Some(Deadline::new(later)), |_, _| Ok(())).unwrap();
        assert_eq!(stats.steps, 1000);
    }

    #[test]
    fn sampled_rejects_invalid_grids() {
        let nan = f64::NAN;
        for (t0, t_end, dt) in [
            (0.0, 1.0, 0.0),
            (0.0, 1.0, -0.1),
            (1.0, 0.0, 0.1),
            (0.0, nan, 0.1),
            (0.0, 1e10, 1e-10),
        ] {
            let mut p = HarmonicOscillator::default();
            let mut st = Rk4::new(2, 0.1);
            let mut called = false;
            let res = integrate_sampled(&mut st, &mut p, t0, &[1.0, 0.0], t_end, dt, |_, _| {
                called = true;
                Ok(())
            });
            assert!(
                matches!(res, Err(IntegrateError::InvalidOutputGrid { .. })),
                "{t0} {t_end} {dt}"
            );
            assert!(!called);
        }
    }
}
