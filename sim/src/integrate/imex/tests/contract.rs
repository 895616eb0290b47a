//! The stepper contract for `ArkImex`: evaluation counts, dense output, failures (NaN, system
//! errors, too many steps), stop times, settings, `integrate_sampled`.

use super::super::super::testutil::local_dense_err;
use super::*;

// Counts: 1 (init) + 5 rhs_split and 7 solves (5 stages, 2 for the filtered estimate) per
// attempt, + 1 rhs_split per attempt that passes the error test (accepted, or rejected by the
// interpolation check), + 1 for the starting step when h_init is None.
#[test]
fn ark436_stats_count_evaluations_exactly() {
    let tau = std::f64::consts::TAU;
    let p = StiffKepler { e: 0.9, k: 1e4 };
    let y0 = p.y0();
    for h_init in [Some(1.0), None] {
        let mut q = p;
        let mut st = ArkImex::new(
            5,
            StepControl {
                h_init,
                ..tol_settings(1e-8)
            },
        );
        st.init(&mut q, 0.0, &y0).expect("init");
        assert_eq!(
            st.stats(),
            Stats {
                rhs_evals: 1,
                ..Stats::default()
            }
        );
        while st.t() < tau {
            st.step(&mut q, tau).expect("step");
        }
        let s = st.stats();
        eprintln!("h_init {h_init:?}: {s:?}");
        let attempts = s.steps + s.rejected;
        let guess = u64::from(h_init.is_none());
        let base = 1 + guess + 5 * attempts;
        assert!(
            s.rhs_evals >= base + s.steps && s.rhs_evals <= base + attempts,
            "{s:?}"
        );
        assert_eq!(s.implicit_solves, 7 * attempts, "{s:?}");
        assert_eq!((s.jacobian_evals, s.lu_decompositions), (0, 0));
        if h_init.is_some() {
            assert!(s.rejected >= 1, "{s:?}");
        }
    }
}

// Hermite dense output: local error from the exact state over one step O(h^4), observed order
// in [3.6, 4.4] at theta = 1/4, 1/2, 3/4 (stiff Kepler with k = 10); ends exact.
#[test]
fn ark436_dense_output_local_order_four_and_exact_ends() {
    fn local(h: f64) -> f64 {
        let st = ArkImex::new(5, fixed_settings(h));
        local_dense_err(StiffKepler { e: 0.3, k: 10.0 }, st, 0.3, h)
    }
    for h in [0.1, 0.05] {
        let order = (local(h) / local(0.5 * h)).log2();
        eprintln!("h = {h}: local dense-output order {order:.3}");
        assert!((3.6..=4.4).contains(&order), "h = {h}: order {order}");
    }
}

/// `NanAfter` split as all-explicit (f_I = 0; the solve is z = r).
#[derive(Clone, Copy, Debug)]
struct SplitNan(NanAfter);

impl OdeSystem for SplitNan {
    type Error = Infallible;
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), Infallible> {
        self.0.rhs(t, y, dydt)
    }
}

impl SplitSystem for SplitNan {
    fn rhs_split(
        &mut self,
        t: f64,
        y: &[f64],
        f_e: &mut [f64],
        f_i: &mut [f64],
    ) -> Result<(), Infallible> {
        f_i.fill(0.0);
        self.0.rhs(t, y, f_e)
    }
    fn solve_implicit(
        &mut self,
        _t: f64,
        _gamma: f64,
        r: &[f64],
        z: &mut [f64],
    ) -> Result<(), Infallible> {
        z.copy_from_slice(r);
        Ok(())
    }
}

/// `y' = -y` (implicit) whose solve fails from `t_fail` on.
struct FailingSolve {
    t_fail: f64,
}

impl OdeSystem for FailingSolve {
    type Error = RhsFailure;
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), RhsFailure> {
        dydt[0] = -y[0];
        Ok(())
    }
}

impl SplitSystem for FailingSolve {
    fn rhs_split(
        &mut self,
        _t: f64,
        y: &[f64],
        f_e: &mut [f64],
        f_i: &mut [f64],
    ) -> Result<(), RhsFailure> {
        f_e[0] = 0.0;
        f_i[0] = -y[0];
        Ok(())
    }
    fn solve_implicit(
        &mut self,
        t: f64,
        gamma: f64,
        r: &[f64],
        z: &mut [f64],
    ) -> Result<(), RhsFailure> {
        if t >= self.t_fail {
            return Err(RhsFailure { t });
        }
        z[0] = r[0] / (1.0 + gamma);
        Ok(())
    }
}

#[test]
fn ark436_nan_and_system_errors_are_reported() {
    let t_nan = 0.5;
    let mut p = SplitNan(NanAfter { t_nan, index: 1 });
    let mut st = ArkImex::new(2, tol_settings(1e-8));
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
    assert!(st.t() < t_nan);

    let mut p = FailingSolve { t_fail: 0.5 };
    let mut st = ArkImex::new(1, tol_settings(1e-8));
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
    let res = st.init(&mut p, 0.0, &[f64::INFINITY]);
    assert!(matches!(res, Err(IntegrateError::NonFiniteState { t, index: 0 }) if t == 0.0));
}

#[test]
fn ark436_too_many_steps_stop_times_and_settings() {
    let mut p = StiffKepler::default();
    let y0 = p.y0();
    let mut st = ArkImex::new(
        5,
        StepControl {
            max_steps: 10,
            ..tol_settings(1e-10)
        },
    );
    st.init(&mut p, 0.0, &y0).expect("init");
    let err = loop {
        if let Err(e) = st.step(&mut p, 100.0) {
            break e;
        }
    };
    assert!(
        matches!(err, IntegrateError::TooManySteps { max_steps: 10, .. }),
        "{err:?}"
    );
    assert_eq!(st.stats().steps + st.stats().rejected, 10);

    let mut st = ArkImex::new(5, tol_settings(1e-8));
    st.init(&mut p, 0.0, &y0).expect("init");
    for k in 1..=10 {
        let t_stop = f64::from(k) * 0.3;
        while st.t() < t_stop {
            assert!(st.step(&mut p, t_stop).expect("step") <= t_stop);
        }
        assert_eq!(st.t(), t_stop);
    }
    assert_eq!(st.step(&mut p, 3.0).expect("no-op"), 3.0);

    assert!(StepControl::new(1e-6, 1e-9).validate().is_ok());
    let ok = StepControl::new(1e-6, 1e-9);
    for (field, s) in [
        ("atol", StepControl { atol: 0.0, ..ok }),
        ("max_steps", StepControl { max_steps: 0, ..ok }),
    ] {
        match ArkImex::try_new(1, s) {
            Err(e) => assert_eq!((e.settings, e.field), ("StepControl", field)),
            Ok(_) => panic!("{field}: accepted invalid settings"),
        }
    }
}

// integrate_sampled drives ArkImex unchanged: identical stats and bit-identical final state
// for dt_out from 1 s to 1 ms; samples within the 20 tol bound of the tolerance test.
#[test]
fn ark436_with_integrate_sampled_is_independent_of_dt_out() {
    let tol = 1e-7;
    let mut reference: Option<(Stats, Vec<f64>)> = None;
    for dt_out in [1.0, 0.1, 1e-3] {
        let mut p = StiffOscillator {
            split: OscillatorSplit::VelocityCurrent,
            ..Default::default()
        };
        let exact = p;
        let y0 = p.y0();
        let mut st = ArkImex::new(3, tol_settings(tol));
        let (mut worst, mut ex) = (0.0f64, [0.0; 3]);
        let stats = integrate_sampled(&mut st, &mut p, 0.0, &y0, 5.0, dt_out, |t, y| {
            exact.exact(t, &mut ex);
            worst = worst.max(scaled_err(y, &ex));
            Ok(())
        })
        .expect("integrate_sampled");
        eprintln!("dt_out {dt_out}: {stats:?}, max err {:.2} tol", worst / tol);
        assert!(worst <= 80.0 * tol, "dt_out {dt_out}: {worst:e}");
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
