//! The stepper contract for `Rosenbrock`: dense output, evaluation counts, failures (singular
//! matrix, NaN, system errors, too many steps), stop times, settings, `integrate_sampled`.

use super::super::super::testutil::local_dense_err as local_dense_err_of;
use super::*;

// The Hermite dense output's local error from the exact state over one step is O(h^4):
// observed order over h -> h/2 in [3.6, 4.4] at interior points (Kepler, e = 0.3), and the
// end points are returned exactly.
#[test]
fn rosenbrock_dense_output_local_order_four_and_exact_ends() {
    fn local_dense_err(h: f64) -> f64 {
        let s = StepControl {
            h_init: Some(h),
            ..fixed_settings(h)
        };
        local_dense_err_of(Kepler { e: 0.3 }, Rosenbrock::new(4, s), 0.3, h)
    }
    for h in [0.05, 0.025] {
        let order = (local_dense_err(h) / local_dense_err(0.5 * h)).log2();
        eprintln!("h = {h}: local dense-output order {order:.3}");
        assert!((3.6..=4.4).contains(&order), "h = {h}: order {order}");
    }
    // before the first step: the state itself
    let mut p = Kepler { e: 0.3 };
    let y0 = p.y0();
    let mut st = Rosenbrock::new(4, tol_settings(1e-6));
    st.init(&mut p, 0.0, &y0).expect("init");
    let mut out = [0.0; 4];
    st.interpolate(0.0, &mut out);
    assert_eq!(out.as_slice(), y0.as_slice());
}

// Exact evaluation counts. Analytic J and f_t: 1 (init) + 3 per attempt + 1 per accepted
// step (f at the new point = next first stage); with reuse 1 one Jacobian per accepted step
// (a rejection keeps the fresh one) and one LU per attempt. With h_init = None: +1 (starting
// step). Through FdJacobian (no analytic f_t): +1 per accepted step (the forward difference
// in t, evaluated at every step start) and dim rhs per Jacobian inside it.
#[test]
fn rosenbrock_stats_count_evaluations_exactly() {
    let tau = std::f64::consts::TAU;
    let mut p = Kepler { e: 0.9 };
    let y0 = p.y0();
    let s = StepControl {
        h_init: Some(1.0),
        ..tol_settings(1e-7)
    };
    let mut st = Rosenbrock::new(4, s);
    st.init(&mut p, 0.0, &y0).expect("init");
    assert_eq!(
        st.stats(),
        Stats {
            rhs_evals: 1,
            ..Stats::default()
        }
    );
    while st.t() < tau {
        st.step(&mut p, tau).expect("step");
    }
    let s = st.stats();
    eprintln!("{s:?}");
    assert!(s.rejected >= 1, "{s:?}");
    assert_eq!(
        s.rhs_evals,
        1 + 3 * (s.steps + s.rejected) + s.steps,
        "{s:?}"
    );
    assert_eq!(s.jacobian_evals, s.steps, "{s:?}");
    assert_eq!(s.lu_decompositions, s.steps + s.rejected, "{s:?}");
    assert_eq!(s.implicit_solves, 0);

    let mut p = FdJacobian::new(Kepler { e: 0.9 });
    let mut st = Rosenbrock::new(4, tol_settings(1e-7)).with_jacobian_reuse(3);
    st.init(&mut p, 0.0, &y0).expect("init");
    while st.t() < tau {
        st.step(&mut p, tau).expect("step");
    }
    let s = st.stats();
    eprintln!("{s:?}, fd evals {}", p.fd_evals());
    assert_eq!(
        s.rhs_evals,
        2 + 3 * (s.steps + s.rejected) + 2 * s.steps,
        "{s:?}"
    );
    assert_eq!(p.fd_evals(), 4 * s.jacobian_evals);
    assert!(s.jacobian_evals <= s.steps / 3 + s.rejected + 1, "{s:?}");
}

/// `y' = -y` whose Jacobian is -1 before `t_sing` and `1 / (gamma h_sing)` from `t_sing` on,
/// so that `I/(h gamma) - J` is exactly singular for `h = h_sing`.
#[derive(Clone, Copy, Debug)]
struct SingularAt {
    t_sing: f64,
    h_sing: f64,
}

impl OdeSystem for SingularAt {
    type Error = Infallible;
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), Infallible> {
        dydt[0] = -y[0];
        Ok(())
    }
}

impl OdeJacobian for SingularAt {
    fn jacobian(
        &mut self,
        t: f64,
        _y: &[f64],
        _fy: &[f64],
        jac: &mut [f64],
    ) -> Result<(), Infallible> {
        jac[0] = if t >= self.t_sing {
            1.0 / (self.h_sing * GAMMA)
        } else {
            -1.0
        };
        Ok(())
    }
}

impl ExactSolution for SingularAt {
    fn t0(&self) -> f64 {
        0.0
    }
    fn exact(&self, t: f64, y: &mut [f64]) {
        y[0] = (-t).exp();
    }
}

// With the step pinned (h_min = h_max = 0.1) the singular matrix in the step from t = 0.5 is
// reported as SingularMatrix { t = 0.5, h = 0.1 }, with the state kept at t = 0.5. With a free
// step size the stepper halves h past the singularity and finishes within 10 tol.
#[test]
fn rosenbrock_singular_matrix_reported_with_its_time() {
    let h = 0.1;
    let mut p = SingularAt {
        t_sing: 0.45,
        h_sing: h,
    };
    let s = StepControl {
        h_min: h,
        ..fixed_settings(h)
    };
    let mut st = Rosenbrock::new(1, s);
    st.init(&mut p, 0.0, &[1.0]).expect("init");
    let err = loop {
        if let Err(e) = st.step(&mut p, 1.0) {
            break e;
        }
    };
    eprintln!("{err}");
    match err {
        IntegrateError::SingularMatrix { t, h: h_err } => {
            assert!(
                (t - 0.5).abs() < 1e-12 && h_err == h,
                "t = {t}, h = {h_err}"
            );
            assert_eq!(st.t(), t);
        }
        other => panic!("expected SingularMatrix, got {other:?}"),
    }
    assert!(err.to_string().contains("t = 0.5"));

    let tol = 1e-6;
    let s = StepControl {
        h_init: Some(h),
        h_max: h,
        ..tol_settings(tol)
    };
    let r = run(
        SingularAt {
            t_sing: 0.45,
            h_sing: h,
        },
        s,
        1.0,
    );
    eprintln!("free step size: {:?}, err {:.2e}", r.stats, r.err_end);
    assert!(
        r.stats.rejected >= 1 && r.err_end <= 10.0 * tol,
        "{:?} {}",
        r.stats,
        r.err_end
    );
}

// A derivative that turns NaN at t_nan (FdJacobian, so the time derivative is also a
// difference, whose forward probe crosses t_nan first) is localised to t_nan and reported as
// NonFiniteState with its component.
#[test]
fn rosenbrock_nan_reports_onset_time_and_index() {
    let t_nan = 0.5;
    let mut p = FdJacobian::new(NanAfter { t_nan, index: 1 });
    let mut st = Rosenbrock::new(2, tol_settings(1e-8));
    st.init(&mut p, 0.0, &[1.0, 1.0]).expect("init");
    let err = loop {
        if let Err(e) = st.step(&mut p, 2.0) {
            break e;
        }
    };
    eprintln!("{err} after {:?}", st.stats());
    match err {
        IntegrateError::NonFiniteState { t, index } => {
            assert_eq!(index, 1);
            assert!(t >= t_nan && t - t_nan < 1e-12, "t = {t}");
        }
        other => panic!("expected NonFiniteState, got {other:?}"),
    }
    assert!(st.t() < t_nan && st.y().iter().all(|v| v.is_finite()));
}

/// `y' = -y` whose Jacobian fails (`RhsFailure`) or is NaN in row 0.
struct BadJacobian {
    nan: bool,
}

impl OdeSystem for BadJacobian {
    type Error = RhsFailure;
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), RhsFailure> {
        dydt[0] = -y[0];
        Ok(())
    }
}

impl OdeJacobian for BadJacobian {
    fn jacobian(
        &mut self,
        t: f64,
        _y: &[f64],
        _fy: &[f64],
        jac: &mut [f64],
    ) -> Result<(), RhsFailure> {
        if self.nan {
            jac[0] = f64::NAN;
            Ok(())
        } else {
            Err(RhsFailure { t })
        }
    }
}

#[test]
fn rosenbrock_system_errors_pass_through() {
    // rhs failure
    let mut p = FdJacobian::new(FailingRhs { t_fail: 0.5 });
    let mut st = Rosenbrock::new(1, tol_settings(1e-8));
    st.init(&mut p, 0.0, &[1.0]).expect("init");
    let err = loop {
        if let Err(e) = st.step(&mut p, 2.0) {
            break e;
        }
    };
    match err {
        IntegrateError::Rhs(RhsFailure { t }) => assert!(t >= 0.5 && st.t() < 0.5, "t = {t}"),
        other => panic!("expected Rhs error, got {other:?}"),
    }
    // Jacobian failure and a NaN Jacobian, at the step's start
    let mut p = BadJacobian { nan: false };
    let mut st = Rosenbrock::new(1, tol_settings(1e-8));
    st.init(&mut p, 0.25, &[1.0]).expect("init");
    let res = st.step(&mut p, 1.0);
    assert!(
        matches!(res, Err(IntegrateError::Rhs(RhsFailure { t })) if t == 0.25),
        "{res:?}"
    );
    let mut p = BadJacobian { nan: true };
    st.init(&mut p, 0.25, &[1.0]).expect("init");
    let res = st.step(&mut p, 1.0);
    assert!(
        matches!(res, Err(IntegrateError::NonFiniteState { t, index: 0 }) if t == 0.25),
        "{res:?}"
    );
    assert_eq!(st.t(), 0.25);
    // non-finite initial state
    let res = st.init(&mut p, 0.0, &[f64::NAN]);
    assert!(matches!(res, Err(IntegrateError::NonFiniteState { t, index: 0 }) if t == 0.0));
}

#[test]
fn rosenbrock_too_many_steps_and_stop_times() {
    let mut p = HarmonicOscillator::default();
    let mut st = Rosenbrock::new(
        2,
        StepControl {
            max_steps: 10,
            ..tol_settings(1e-10)
        },
    );
    st.init(&mut p, 0.0, &[1.0, 0.0]).expect("init");
    let err = loop {
        if let Err(e) = st.step(&mut p, 100.0) {
            break e;
        }
    };
    match err {
        IntegrateError::TooManySteps { t, max_steps: 10 } => {
            assert_eq!(t, st.t());
            assert_eq!(st.stats().steps + st.stats().rejected, 10);
        }
        other => panic!("expected TooManySteps, got {other:?}"),
    }
    // stop times are hit exactly; at t_stop a step is a no-op
    let mut st = Rosenbrock::new(2, tol_settings(1e-8));
    st.init(&mut p, 0.0, &[1.0, 0.0]).expect("init");
    for k in 1..=10 {
        let t_stop = f64::from(k) * 0.3;
        while st.t() < t_stop {
            assert!(st.step(&mut p, t_stop).expect("step") <= t_stop);
        }
        assert_eq!(st.t(), t_stop);
    }
    let n = st.stats().steps;
    assert_eq!(st.step(&mut p, 3.0).expect("no-op"), 3.0);
    assert_eq!(st.stats().steps, n);
}

#[test]
fn rosenbrock_settings_validation() {
    let ok = StepControl::new(1e-6, 1e-9);
    let e = Rosenbrock::new(1, ok)
        .try_with_jacobian_reuse(0)
        .expect_err("reuse 0");
    assert_eq!((e.settings, e.field), ("Rosenbrock", "jacobian_reuse"));
    assert!(e.to_string().contains("Rosenbrock.jacobian_reuse"), "{e}");
    for (field, s) in [
        ("rtol", StepControl { rtol: -1.0, ..ok }),
        (
            "h_min",
            StepControl {
                h_min: 1.0,
                h_max: 0.5,
                ..ok
            },
        ),
    ] {
        match Rosenbrock::try_new(1, s) {
            Err(e) => {
                assert_eq!((e.settings, e.field), ("StepControl", field));
                assert!(
                    e.to_string().contains(&format!("StepControl.{field}")),
                    "{e}"
                );
            }
            Ok(_) => panic!("{field}: accepted invalid settings"),
        }
    }
}

// integrate_sampled drives the stepper unchanged: the steps do not depend on the output rate
// (identical stats and bit-identical final state for dt_out from 1 s to 1 ms), and the samples
// stay within the dense-output bound of `for_each_problem` (20 tol) on the motor oscillator
// with a finite-difference Jacobian reused over 5 steps.
#[test]
fn rosenbrock_with_integrate_sampled_is_independent_of_dt_out() {
    let tol = 1e-7;
    let mut reference: Option<(Stats, Vec<f64>)> = None;
    for dt_out in [1.0, 0.1, 1e-3] {
        let mut p = FdJacobian::new(StiffOscillator::default());
        let exact = *p.inner();
        let y0 = exact.y0();
        let mut st = Rosenbrock::new(3, tol_settings(tol)).with_jacobian_reuse(5);
        let (mut worst, mut count, mut ex) = (0.0f64, 0usize, [0.0; 3]);
        let stats = integrate_sampled(&mut st, &mut p, 0.0, &y0, 5.0, dt_out, |t, y| {
            exact.exact(t, &mut ex);
            worst = worst.max(scaled_err(y, &ex));
            count += 1;
            Ok(())
        })
        .expect("integrate_sampled");
        eprintln!(
            "dt_out {dt_out}: {count} samples, {stats:?}, max err {:.2} tol",
            worst / tol
        );
        assert!(worst <= 20.0 * tol, "dt_out {dt_out}: {worst:e}");
        let y_end = st.y().to_vec();
        match &reference {
            None => reference = Some((stats, y_end)),
            Some((s0, y0)) => {
                assert_eq!(&stats, s0);
                assert_eq!(&y_end, y0);
            }
        }
    }
}
