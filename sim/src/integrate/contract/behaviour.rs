//! The stepper contract, behaviour: stop times, `StepControl` limits, `init` and `set_state`,
//! `integrate_sampled`, statistics, errors and settings, over every method of [`METHODS`].

use super::super::test_problems::{ExactSolution, FailingRhs, NanAfter, RhsFailure, RiccatiBlowup};
use super::super::testutil::{run_exact, run_to_failure, scaled_err, Checks, Problem};
use super::super::{integrate_sampled, IntegrateError, Stats, StepControl};
use super::*;

/// Steps `st` to `t_stop`, checking that no step passes it, that it is landed on exactly, and
/// that the dense output returns both ends of every step exactly.
fn step_to(st: &mut Dyn, p: &mut Problem, t_stop: f64, checks: &mut Checks, name: &str) {
    let mut out = vec![0.0; p.dim()];
    while st.t() < t_stop {
        let (t0, y0) = (st.t(), st.y().to_vec());
        let t = st.step(p, t_stop).expect("step");
        checks.check(t <= t_stop, || {
            format!("{name}: stepped to {t} past t_stop {t_stop}")
        });
        st.interpolate(t0, &mut out);
        checks.check(out == y0, || {
            format!("{name}: dense output at t_prev = {t0} is not y")
        });
        st.interpolate(t, &mut out);
        checks.check(out == st.y(), || {
            format!("{name}: dense output at t = {t} is not y")
        });
    }
    checks.check(st.t() == t_stop, || {
        format!("{name}: ended at {} instead of {t_stop}", st.t())
    });
}

// 20 stop times (oscillator, tol 1e-8, Rk4 h = 0.1): each landed exactly and never passed,
// the dense output exact at both ends of every step;
// at, before or at a NaN stop time a step is a no-op returning t (stats unchanged); the stops
// cost an adaptive method about one extra step each (measured 21 for 20 stops with
// DormandPrince45; bound: free run + 25), a fixed-step one none (they lie on its grid).
#[test]
fn stop_times_are_landed_exactly_and_never_passed() {
    let mut checks = Checks::default();
    for m in &METHODS {
        let mut p = oscillator(1.0);
        let free = run_exact(p, &mut *m.tol_or_step(2, 1e-8, 0.1), 10.0)
            .stats
            .steps;
        let mut st = m.tol_or_step(2, 1e-8, 0.1);
        st.init(&mut p, 0.0, &[1.0, 0.0]).expect("init");
        for k in 1..=20 {
            step_to(&mut st, &mut p, f64::from(k) * 0.5, &mut checks, m.name);
        }
        let stats = st.stats();
        for t_stop in [10.0, 9.0, f64::NAN] {
            let t = st.step(&mut p, t_stop).expect("no-op");
            checks.check(t == 10.0 && st.stats() == stats, || {
                format!("{}: step({t_stop}) moved", m.name)
            });
        }
        let extra = if m.adaptive() { 25 } else { 0 };
        eprintln!(
            "{:16} steps free {free}, with 20 stops {}",
            m.name, stats.steps
        );
        checks.check(stats.steps <= free + extra, || {
            format!("{}: {} steps with stops vs {free}", m.name, stats.steps)
        });
    }
}

// h_max = 0.01 bounds every step (up to the 1% stretch onto a stop time): >= 100 steps on
// [0, 1]; h_init is the first step when it passes the error test.
#[test]
fn step_control_limits_are_honoured() {
    let mut checks = Checks::default();
    for m in METHODS.iter().filter(|m| m.adaptive()) {
        let mut p = decay();
        let c = StepControl {
            h_max: 0.01,
            ..StepControl::new(1e-6, 1e-6)
        };
        let mut st = m.with(1, c).expect("adaptive").expect("valid");
        st.init(&mut p, 0.0, &[1.0]).expect("init");
        while st.t() < 1.0 {
            let t0 = st.t();
            let h = st.step(&mut p, 1.0).expect("step") - t0;
            checks.check(h <= 0.01 * 1.01 + 1e-15, || {
                format!("{}: step {h} > h_max", m.name)
            });
        }
        checks.check(st.stats().steps >= 100, || {
            format!("{}: {:?}", m.name, st.stats())
        });
        let c = StepControl {
            h_init: Some(1e-3),
            ..StepControl::new(1e-6, 1e-6)
        };
        let mut st = m.with(1, c).expect("adaptive").expect("valid");
        st.init(&mut p, 0.0, &[1.0]).expect("init");
        let t = st.step(&mut p, 1.0).expect("step");
        checks.check(t == 1e-3, || {
            format!("{}: first step to {t} with h_init 1e-3", m.name)
        });
    }
}

// init: rejects a non-finite y0 or f(t0, y0) with NonFiniteState at t0 and the component,
// passes a system error at t0 through, and restarts a used stepper: t0, y0 (also as dense
// output), statistics reset to the one evaluation of f(t0, y0).
#[test]
fn init_restarts_and_rejects_non_finite_states() {
    let mut checks = Checks::default();
    for m in &METHODS {
        let mut st = m.tol_or_step(2, 1e-6, 0.1);
        let mut p = oscillator(1.0);
        let res = st.init(&mut p, 0.5, &[1.0, f64::INFINITY]);
        checks.check(
            matches!(
                res,
                Err(IntegrateError::NonFiniteState { t: 0.5, index: 1 })
            ),
            || format!("{}: y0 inf: {res:?}", m.name),
        );
        let mut nan = Problem::Nan(NanAfter {
            t_nan: 0.0,
            index: 1,
        });
        let res = st.init(&mut nan, 0.25, &[1.0, 1.0]);
        checks.check(
            matches!(
                res,
                Err(IntegrateError::NonFiniteState { t: 0.25, index: 1 })
            ),
            || format!("{}: f0 NaN: {res:?}", m.name),
        );
        let mut fail = Problem::Failing(FailingRhs { t_fail: 0.0 });
        let mut st1 = m.tol_or_step(1, 1e-6, 0.1);
        let res = st1.init(&mut fail, 0.0, &[1.0]);
        checks.check(
            matches!(res, Err(IntegrateError::Rhs(RhsFailure { t: 0.0 }))),
            || format!("{}: failing f0: {res:?}", m.name),
        );

        st.init(&mut p, 0.0, &[1.0, 0.0]).expect("init");
        st.step(&mut p, 1.0).expect("step");
        st.step(&mut p, 1.0).expect("step");
        st.init(&mut p, 0.25, &[0.5, 0.5]).expect("re-init");
        let mut out = [0.0; 2];
        st.interpolate(0.3, &mut out);
        let fresh = Stats {
            rhs_evals: 1,
            ..Stats::default()
        };
        checks.check(
            st.t() == 0.25 && st.y() == [0.5, 0.5] && out == [0.5, 0.5] && st.stats() == fresh,
            || {
                format!(
                    "{}: re-init: t {}, y {:?}, dense {out:?}, {:?}",
                    m.name,
                    st.t(),
                    st.y(),
                    st.stats()
                )
            },
        );
    }
}

// set_state replaces y(t) and re-evaluates f there (one evaluation; t, steps and step size
// carry on): with the same y it changes nothing (bit-identical steps, one more rhs_evals per
// call); with y halved on the linear decay the run continues on the halved exact solution
// (error within 10 tol, which a stale f would miss by O(h)); a NaN y is NonFiniteState at t.
#[test]
fn set_state_replaces_the_state() {
    let mut checks = Checks::default();
    for m in &METHODS {
        let tol = 1e-8;
        let stops = [0.5, 1.0, 1.5, 2.0];
        let run = |factor: Option<f64>| {
            let mut p = decay();
            let mut st = m.tol_or_step(1, tol, 0.01);
            st.init(&mut p, 0.0, &[1.0]).expect("init");
            for ts in stops {
                while st.t() < ts {
                    st.step(&mut p, ts).expect("step");
                }
                if let Some(f) = factor {
                    let (t, before) = (st.t(), st.stats());
                    let y = [f * st.y()[0]];
                    st.set_state(&mut p, &y).expect("set_state");
                    assert!(
                        st.t() == t && st.y() == y && st.stats().rhs_evals == before.rhs_evals + 1
                    );
                }
            }
            (st.y()[0], st.stats(), st)
        };
        let (y_plain, s_plain, _) = run(None);
        let (y_same, s_same, _) = run(Some(1.0));
        checks.check(
            y_same == y_plain
                && s_same.steps == s_plain.steps
                && s_same.rhs_evals == s_plain.rhs_evals + 4,
            || {
                format!(
                    "{}: set_state(y) changed the run: {s_same:?} vs {s_plain:?}",
                    m.name
                )
            },
        );
        let (y_half, _, mut st) = run(Some(0.5));
        let exact = (-2.0f64).exp() / 16.0;
        let e = scaled_err(&[y_half], &[exact]);
        eprintln!("{:16} set_state halving: err {:.2} tol", m.name, e / tol);
        checks.check(e <= 10.0 * tol, || {
            format!("{}: after set_state err {e:e}", m.name)
        });
        let res = st.set_state(&mut decay(), &[f64::NAN]);
        checks.check(
            matches!(
                res,
                Err(IntegrateError::NonFiniteState { t: 2.0, index: 0 })
            ),
            || format!("{}: NaN: {res:?}", m.name),
        );
    }
}

// integrate_sampled drives the stepper unchanged: identical stats and bit-identical final
// state (also the last sample) for dt_out from one period to period / 20000, the adaptive
// steps on Kepler much coarser than the finest grid (fewer than a tenth of its samples);
// samples within the tolerance test's bound C tol (Kepler e = 0.5 at tol 1e-8; the motor
// oscillator at tol 1e-7 for the implicit methods; Rk4 with h = period / 2000 within 1e-8
// scaled, measured 0.47e-8).
#[test]
fn integrate_sampled_is_independent_of_the_output_grid() {
    let mut checks = Checks::default();
    let cases = tolerance_cases();
    for (k, m) in METHODS.iter().enumerate() {
        let mut runs = vec![(kepler(0.5), TAU, 1e-8, cases[3].4[k].unwrap_or(1.0))];
        if m.stability.is_none() {
            runs.push((motor(), 5.0, 1e-7, cases[7].4[k].unwrap_or(0.0)));
        }
        for (p, t_end, tol, c) in runs {
            let mut reference: Option<(Stats, Vec<f64>)> = None;
            for div in [1.0, 7.0, 1000.0, 20000.0] {
                let mut st = m.tol_or_step(p.dim(), tol, TAU / 2000.0);
                let (mut q, mut ex, mut worst, mut last) =
                    (p, vec![0.0; p.dim()], 0.0f64, Vec::new());
                let y0 = p.y0();
                let stats =
                    integrate_sampled(&mut *st, &mut q, 0.0, &y0, t_end, t_end / div, |t, y| {
                        p.exact(t, &mut ex);
                        worst = worst.max(scaled_err(y, &ex));
                        last = y.to_vec();
                        Ok(())
                    })
                    .expect("integrate_sampled");
                eprintln!(
                    "{:16} dt_out T/{div}: {stats:?}, max err {:.2} tol",
                    m.name,
                    worst / tol
                );
                checks.check(worst <= c * tol, || {
                    format!("{} T/{div}: sample error {worst:e}", m.name)
                });
                checks.check(last == st.y(), || {
                    format!("{} T/{div}: last sample is not y(t_end)", m.name)
                });
                match &reference {
                    None => reference = Some((stats, st.y().to_vec())),
                    Some((s0, y0)) => checks.check(stats == *s0 && st.y() == y0.as_slice(), || {
                        format!("{} T/{div}: {stats:?} vs {s0:?}", m.name)
                    }),
                }
            }
            if m.adaptive() && t_end == TAU {
                let steps = reference.map_or(0, |r| r.0.steps);
                checks.check(steps < 2000, || format!("{}: {steps} steps", m.name));
            }
        }
    }
}

// Exact counts (see `Method::counts`) on Kepler e = 0.9 and stiff Kepler (e = 0.9, k = 1e4;
// implicit methods) to one period, with h_init = 1 (a too-large first step: rejections for
// the adaptive methods) and with Hairer's starting step; after init only the evaluation of
// f(t0, y0); no rejection for a fixed step.
#[test]
fn statistics_count_every_evaluation() {
    let mut checks = Checks::default();
    for m in &METHODS {
        let mut problems = vec![kepler(0.9)];
        if m.stability.is_none() {
            problems.push(stiff_kepler(0.9, 1e4));
        }
        for mut p in problems {
            for h_init in [Some(1.0), None] {
                let c = StepControl {
                    h_init,
                    ..StepControl::new(1e-8, 1e-8)
                };
                let mut st = m
                    .with(p.dim(), c)
                    .map_or_else(|| m.fixed(p.dim(), 0.01), |s| s.expect("valid"));
                let y0 = p.y0();
                st.init(&mut p, 0.0, &y0).expect("init");
                checks.check(
                    st.stats()
                        == Stats {
                            rhs_evals: 1,
                            ..Stats::default()
                        },
                    || format!("{}: after init {:?}", m.name, st.stats()),
                );
                while st.t() < TAU {
                    st.step(&mut p, TAU).expect("step");
                }
                let s = st.stats();
                let want = (m.counts)(&s, h_init.is_none() && m.adaptive());
                let got = Counts {
                    rhs: (s.rhs_evals, s.rhs_evals),
                    jacobian_evals: s.jacobian_evals,
                    lu_decompositions: s.lu_decompositions,
                    implicit_solves: s.implicit_solves,
                };
                eprintln!("{:16} {p:?} h_init {h_init:?}: {s:?}", m.name);
                checks.check(
                    want.rhs.0 <= s.rhs_evals
                        && s.rhs_evals <= want.rhs.1
                        && Counts {
                            rhs: want.rhs,
                            ..got
                        } == want,
                    || {
                        format!(
                            "{} {p:?} h_init {h_init:?}: {s:?}, expected {want:?}",
                            m.name
                        )
                    },
                );
                let rejections_ok = if !m.adaptive() {
                    s.rejected == 0
                } else {
                    h_init.is_none() || s.rejected >= 1
                };
                checks.check(rejections_ok, || {
                    format!("{} h_init {h_init:?}: {s:?}", m.name)
                });
            }
        }
    }
}

// Errors, tol 1e-8 (Rk4: h = 0.1 and 0.05): a failing rhs (from t = 0.5; for ArkImex also its
// implicit solve) passes through as Rhs at its time, with the last accepted state kept
// (t < 0.5, within 1e-6 scaled of the exact y); a derivative turning NaN at 0.5 is NonFiniteState
// with its component, localised by an adaptive method to within 1e-12 after the onset (the
// step size collapses onto it), by a fixed step to the first stage time at or after it.
#[test]
fn system_errors_and_nan_are_reported_with_time_and_index() {
    let mut checks = Checks::default();
    for m in &METHODS {
        let mut p = Problem::Failing(FailingRhs { t_fail: 0.5 });
        let mut st = m.tol_or_step(1, 1e-8, 0.1);
        st.init(&mut p, 0.0, &[1.0]).expect("init");
        let err = run_to_failure(&mut *st, &mut p, 2.0);
        let e = scaled_err(st.y(), &[(-st.t()).exp()]);
        let ok = matches!(err, IntegrateError::Rhs(RhsFailure { t }) if t >= 0.5)
            && st.t() < 0.5
            && e <= 1e-6;
        checks.check(ok, || {
            format!("{}: {err:?} at t = {}, state err {e:e}", m.name, st.t())
        });

        let mut p = Problem::Nan(NanAfter {
            t_nan: 0.5,
            index: 1,
        });
        let mut st = m.tol_or_step(2, 1e-8, 0.1);
        st.init(&mut p, 0.0, &[1.0, 1.0]).expect("init");
        let err = run_to_failure(&mut *st, &mut p, 2.0);
        let late = if m.adaptive() { 1e-12 } else { 0.1 };
        let ok = matches!(err, IntegrateError::NonFiniteState { t, index: 1 } if t >= 0.5 && t - 0.5 <= late);
        eprintln!("{:16} {err} after {:?}", m.name, st.stats());
        checks.check(
            ok && st.t() < 0.5 && st.y().iter().all(|v| v.is_finite()),
            || format!("{}: {err:?} at {}", m.name, st.t()),
        );
    }
}

// y' = y^2, y(0) = 1 blows up at t = 1. Adaptive: the step size collapses, StepSizeTooSmall
// within 1e-6 of t = 1 with h < 1e-12 (the numerical solution's own pole sits within O(tol)
// of it; tol 1e-8), or, with h_min = 1e-6, with h < 1e-6 within 1e-3 of t = 1. Fixed step
// (h = 0.05): the state overflows after the pole, NonFiniteState in (1, 2).
#[test]
fn singularity_collapses_the_step_size() {
    let mut checks = Checks::default();
    for m in &METHODS {
        let mut p = Problem::Blowup(RiccatiBlowup);
        let mut st = m.tol_or_step(1, 1e-8, 0.05);
        st.init(&mut p, 0.0, &[1.0]).expect("init");
        let err = run_to_failure(&mut *st, &mut p, 10.0);
        eprintln!("{:16} {err} after {:?}", m.name, st.stats());
        if !m.adaptive() {
            let ok =
                matches!(err, IntegrateError::NonFiniteState { t, index: 0 } if t > 1.0 && t < 2.0);
            checks.check(ok, || format!("{}: {err:?}", m.name));
            continue;
        }
        let ok = matches!(err, IntegrateError::StepSizeTooSmall { t, h } if (t - 1.0).abs() < 1e-6 && h < 1e-12);
        checks.check(ok, || format!("{}: {err:?}", m.name));
        let c = StepControl {
            h_min: 1e-6,
            ..StepControl::new(1e-8, 1e-8)
        };
        let mut st = m.with(1, c).expect("adaptive").expect("valid");
        st.init(&mut p, 0.0, &[1.0]).expect("init");
        let err = run_to_failure(&mut *st, &mut p, 10.0);
        let ok = matches!(err, IntegrateError::StepSizeTooSmall { t, h } if (t - 1.0).abs() < 1e-3 && h < 1e-6);
        checks.check(ok, || format!("{} h_min 1e-6: {err:?}", m.name));
    }
}

// max_steps = 10 (tol 1e-10, oscillator to t = 100): TooManySteps after exactly 10 attempts,
// at the stepper's current time.
#[test]
fn max_steps_gives_too_many_steps() {
    let mut checks = Checks::default();
    for m in METHODS.iter().filter(|m| m.adaptive()) {
        let mut p = oscillator(1.0);
        let c = StepControl {
            max_steps: 10,
            ..StepControl::new(1e-10, 1e-10)
        };
        let mut st = m.with(2, c).expect("adaptive").expect("valid");
        st.init(&mut p, 0.0, &[1.0, 0.0]).expect("init");
        let err = run_to_failure(&mut *st, &mut p, 100.0);
        let s = st.stats();
        let ok = matches!(err, IntegrateError::TooManySteps { t, max_steps: 10 } if t == st.t());
        checks.check(ok && s.steps + s.rejected == 10, || {
            format!("{}: {err:?}, {s:?}", m.name)
        });
    }
}

// Every out-of-range StepControl field is rejected by try_new, naming the field and its value
// (in the message too); StepControl::new with positive tolerances is valid.
#[test]
fn invalid_settings_are_rejected_with_field_and_value() {
    let ok = StepControl::new(1e-6, 1e-9);
    let cases = [
        ("rtol", -1.0, StepControl { rtol: -1.0, ..ok }),
        (
            "rtol",
            f64::INFINITY,
            StepControl {
                rtol: f64::INFINITY,
                ..ok
            },
        ),
        ("atol", 0.0, StepControl { atol: 0.0, ..ok }),
        (
            "h_init",
            f64::NAN,
            StepControl {
                h_init: Some(f64::NAN),
                ..ok
            },
        ),
        (
            "h_init",
            1e-9,
            StepControl {
                h_init: Some(1e-9),
                h_min: 1e-6,
                ..ok
            },
        ),
        ("h_max", 0.0, StepControl { h_max: 0.0, ..ok }),
        (
            "h_max",
            f64::NAN,
            StepControl {
                h_max: f64::NAN,
                ..ok
            },
        ),
        (
            "h_min",
            1.0,
            StepControl {
                h_min: 1.0,
                h_max: 0.5,
                ..ok
            },
        ),
        ("h_min", -1.0, StepControl { h_min: -1.0, ..ok }),
        ("max_steps", 0.0, StepControl { max_steps: 0, ..ok }),
    ];
    let mut checks = Checks::default();
    for m in METHODS.iter().filter(|m| m.adaptive()) {
        checks.check(m.with(1, ok).is_some_and(|r| r.is_ok()), || {
            format!("{}: rejected {ok:?}", m.name)
        });
        for (field, value, c) in cases {
            match m.with(1, c).expect("adaptive") {
                Err(e) => {
                    let same = e.value == value || (e.value.is_nan() && value.is_nan());
                    let msg = e.to_string();
                    checks.check(
                        e.settings == "StepControl" && e.field == field && same,
                        || format!("{}: {e:?}", m.name),
                    );
                    checks.check(
                        msg.contains(&format!("StepControl.{field} = {value}")),
                        || format!("{}: {msg}", m.name),
                    );
                }
                Ok(_) => checks.check(false, || format!("{}: accepted {field} = {value}", m.name)),
            }
        }
    }
}
