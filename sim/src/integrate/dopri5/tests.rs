use super::super::test_problems::{
    ExactSolution, ExponentialDecay, FailingRhs, HarmonicOscillator, Kepler, NanAfter,
    RationalDecay, RhsFailure, RiccatiBlowup, StiffLinear,
};
use super::super::testutil::{run_exact, scaled_err, Run};
use super::*;

fn tol_settings(tol: f64) -> StepControl {
    StepControl::new(tol, tol)
}

fn run<P: ExactSolution>(p: P, settings: StepControl, t_end: f64) -> Run {
    let st = DormandPrince45::new(p.dim(), settings);
    run_exact(p, st, t_end)
}

const TOLS: [f64; 3] = [1e-6, 1e-8, 1e-10];

/// Every well-posed test problem with its end time and error constant `C` (global error
/// <= C tol), for the tolerance tests.
///
/// The constants are measured, with margin (worst ratio err/tol over tol = 1e-6..1e-10, end
/// point or dense output): decay 0.15, oscillator 4.5, rational 2.4, Kepler e=0.5 222,
/// Kepler e=0.9 16800. Kepler's are large for a physical reason, not a numerical one: the
/// period depends on the energy, so every local error in the energy becomes a phase error
/// that grows along the orbit (about 10x per revolution at e = 0, much more at e = 0.9,
/// where the pericentre passage is fast). Tolerance proportionality still holds: the ratio
/// err/tol stays roughly constant as tol shrinks.
fn for_each_problem(mut f: impl FnMut(&str, f64, &dyn Fn(StepControl) -> Run)) {
    let tau = std::f64::consts::TAU;
    f("decay", 10.0, &|s| {
        run(ExponentialDecay { k: 1.0, y0: 1.0 }, s, 5.0)
    });
    f("oscillator", 10.0, &|s| {
        run(HarmonicOscillator { omega: 2.0 }, s, 10.0)
    });
    f("rational", 10.0, &|s| run(RationalDecay, s, 5.0));
    f("kepler e=0.5", 500.0, &|s| run(Kepler { e: 0.5 }, s, tau));
    f("kepler e=0.9", 5e4, &|s| run(Kepler { e: 0.9 }, s, tau));
}

// Global error at t_end and dense-output error at 7 interior points of every step stay
// below C * tol for rtol = atol = tol in {1e-6, 1e-8, 1e-10} (C per problem, see
// `for_each_problem`), and decrease with tol.
#[test]
fn dopri5_global_and_dense_error_within_c_tol() {
    for_each_problem(|name, c, solve| {
        let mut prev = f64::INFINITY;
        for tol in TOLS {
            let r = solve(tol_settings(tol));
            eprintln!(
                "{name:14} tol {tol:.0e}: end err {:.2e} ({:.2} tol), dense err {:.2e} ({:.2} tol), {:?}",
                r.err_end,
                r.err_end / tol,
                r.err_dense,
                r.err_dense / tol,
                r.stats
            );
            assert!(
                r.err_end <= c * tol,
                "{name} tol {tol}: end error {:e}",
                r.err_end
            );
            assert!(
                r.err_dense <= c * tol,
                "{name} tol {tol}: dense error {:e}",
                r.err_dense
            );
            let worst = r.err_end.max(r.err_dense);
            assert!(worst < prev, "{name}: error did not decrease at tol {tol}");
            prev = worst;
        }
    });
}

// With the controller out of the loop (h_init = h_max = h, tolerances so loose every step
// passes), the global error of the 5th-order solution falls 32x per halving of h:
// observed order in [4.8, 5.2] (measured: oscillator 4.97, decay 5.09, Kepler e=0.3 5.0 at
// 160 -> 320 steps per period; at 40 -> 80 Kepler is not yet asymptotic). Guards the
// tableau itself.
#[test]
fn dopri5_fixed_step_order_five() {
    fn fixed<P: ExactSolution>(p: P, h: f64, t_end: f64) -> f64 {
        let s = StepControl {
            rtol: 1e3,
            atol: 1e3,
            h_init: Some(h),
            h_max: h,
            ..StepControl::new(1e-6, 1e-9)
        };
        let r = run(p, s, t_end);
        assert_eq!(r.stats.rejected, 0);
        r.err_end
    }
    let tau = std::f64::consts::TAU;
    let osc = |n: f64| fixed(HarmonicOscillator { omega: 1.0 }, tau / n, tau);
    let dec = |n: f64| fixed(ExponentialDecay::default(), 3.0 / n, 3.0);
    let kep = |n: f64| fixed(Kepler { e: 0.3 }, tau / n, tau);
    for (name, order) in [
        ("oscillator", (osc(40.0) / osc(80.0)).log2()),
        ("decay", (dec(40.0) / dec(80.0)).log2()),
        ("kepler", (kep(160.0) / kep(320.0)).log2()),
    ] {
        eprintln!("{name}: fixed-step observed order {order:.3}");
        assert!((4.8..=5.2).contains(&order), "{name}: order {order}");
    }
}

// Steps grow like tol^(-1/5): slope of log(steps) vs -log(tol) between 1e-6 and 1e-10 in
// [0.15, 0.25] (measured 0.169..0.199).
#[test]
fn dopri5_steps_grow_like_tol_pow_minus_one_fifth() {
    for_each_problem(|name, _, solve| {
        let s_lo = solve(tol_settings(1e-6)).stats.steps as f64;
        let s_hi = solve(tol_settings(1e-10)).stats.steps as f64;
        let slope = (s_hi / s_lo).ln() / 1e4f64.ln();
        eprintln!("{name:14} steps {s_lo} -> {s_hi}, slope {slope:.3}");
        assert!((0.15..=0.25).contains(&slope), "{name}: slope {slope}");
    });
}

// The continuous extension is of order 4: its local error at interior points of one step
// from the exact value is O(h^5). Observed order over h -> h/2 in [4.6, 5.4].
#[test]
fn dopri5_dense_output_local_order_five() {
    fn local_dense_err(h: f64) -> f64 {
        let mut p = Kepler { e: 0.3 };
        let t0 = 0.3;
        let mut y0 = [0.0; 4];
        p.exact(t0, &mut y0);
        // loose tolerance so the step of size h is accepted as is
        let s = StepControl {
            rtol: 1e3,
            atol: 1e3,
            h_init: Some(h),
            ..StepControl::new(1e-6, 1e-9)
        };
        let mut st = DormandPrince45::new(4, s);
        st.init(&mut p, t0, &y0).expect("init");
        let t1 = st.step(&mut p, 100.0).expect("step");
        assert_eq!(t1, t0 + h);
        let (mut yi, mut ex) = ([0.0; 4], [0.0; 4]);
        let mut e: f64 = 0.0;
        for th in [0.25, 0.5, 0.75] {
            st.interpolate(t0 + th * h, &mut yi);
            p.exact(t0 + th * h, &mut ex);
            e = e.max(scaled_err(&yi, &ex));
        }
        e
    }
    for h in [0.2, 0.1] {
        let order = (local_dense_err(h) / local_dense_err(0.5 * h)).log2();
        eprintln!("h = {h}: local dense-output order {order:.3}");
        assert!((4.6..=5.4).contains(&order), "h = {h}: order {order}");
    }
}

#[test]
fn dopri5_dense_output_endpoints_are_exact() {
    let mut p = Kepler { e: 0.5 };
    let y0 = p.y0();
    let mut st = DormandPrince45::new(4, tol_settings(1e-8));
    st.init(&mut p, 0.0, &y0).expect("init");
    let mut out = [0.0; 4];
    st.interpolate(0.0, &mut out);
    assert_eq!(out.as_slice(), y0.as_slice());
    for _ in 0..5 {
        let y_before: Vec<f64> = st.y().to_vec();
        st.step(&mut p, 10.0).expect("step");
        st.interpolate(st.t_prev(), &mut out);
        assert_eq!(out.as_slice(), y_before.as_slice());
        st.interpolate(st.t(), &mut out);
        assert_eq!(out.as_slice(), st.y());
    }
}

// rhs evaluations: 1 (init) + 1 (starting-step guess) + 6 per attempt (FSAL), exactly.
#[test]
fn dopri5_stats_count_rhs_evals() {
    let tau = std::f64::consts::TAU;
    // a too-large first step forces rejections; with h_init given there is no guess
    let mut p = Kepler { e: 0.9 };
    let y0 = p.y0();
    let s = StepControl {
        h_init: Some(1.0),
        ..tol_settings(1e-8)
    };
    let mut st = DormandPrince45::new(4, s);
    st.init(&mut p, 0.0, &y0).expect("init");
    assert_eq!(
        st.stats(),
        Stats {
            rhs_evals: 1,
            steps: 0,
            rejected: 0,
            ..Stats::default()
        }
    );
    while st.t() < tau {
        st.step(&mut p, tau).expect("step");
    }
    let s = st.stats();
    assert!(s.rejected >= 1, "{s:?}");
    assert_eq!(s.rhs_evals, 1 + 6 * (s.steps + s.rejected), "{s:?}");

    let r = run(Kepler { e: 0.9 }, tol_settings(1e-8), tau);
    let s = r.stats;
    assert_eq!(s.rhs_evals, 2 + 6 * (s.steps + s.rejected), "{s:?}");
}

// Explicit methods on y' = lambda (y - cos t) - sin t, lambda = -1e4: the step count is set
// by the stability boundary (|h lambda| <~ 3.3), nearly independent of the tolerance.
#[test]
fn dopri5_stiff_problem_is_stability_limited() {
    let t_end = 1.0;
    let stiff = |tol| {
        run(
            StiffLinear {
                lambda: -1e4,
                y0: 1.0,
            },
            tol_settings(tol),
            t_end,
        )
    };
    let (loose, tight) = (stiff(1e-4), stiff(1e-8));
    let mild = run(
        StiffLinear {
            lambda: -1.0,
            y0: 1.0,
        },
        tol_settings(1e-4),
        t_end,
    );
    eprintln!(
        "stiff 1e-4 {:?}, 1e-8 {:?}; mild {:?}",
        loose.stats, tight.stats, mild.stats
    );
    let bound = 1e4 * t_end / 3.31; // steps needed at the stability boundary
    for r in [&loose, &tight] {
        let s = r.stats.steps as f64;
        assert!(s >= bound && s <= 1.5 * bound, "steps {s}, bound {bound}");
        assert!(r.err_end <= 1e-3, "err {}", r.err_end);
    }
    assert!(mild.stats.steps < 30, "{:?}", mild.stats);
}

// y' = y^2, y(0) = 1 blows up at t = 1: the step size collapses just before it.
#[test]
fn dopri5_step_size_too_small_at_singularity() {
    let mut p = RiccatiBlowup;
    let mut st = DormandPrince45::new(1, tol_settings(1e-8));
    st.init(&mut p, 0.0, &[1.0]).expect("init");
    let err = loop {
        if let Err(e) = st.step(&mut p, 2.0) {
            break e;
        }
    };
    eprintln!("{err} after {:?}", st.stats());
    match err {
        IntegrateError::StepSizeTooSmall { t, h } => {
            // the numerical solution's own pole sits within O(tol) of t = 1 (measured
            // t - 1 = 1.1e-9 at tol 1e-8), where y ~ 1e13 is still finite
            assert!((t - 1.0).abs() < 1e-6, "t = {t}");
            assert!(h < 1e-12, "h = {h}");
        }
        other => panic!("expected StepSizeTooSmall, got {other:?}"),
    }
    // the same with a user h_min stops earlier
    let mut st = DormandPrince45::new(
        1,
        StepControl {
            h_min: 1e-6,
            ..tol_settings(1e-8)
        },
    );
    st.init(&mut p, 0.0, &[1.0]).expect("init");
    let err = loop {
        if let Err(e) = st.step(&mut p, 2.0) {
            break e;
        }
    };
    match err {
        IntegrateError::StepSizeTooSmall { t, h } => {
            assert!(h < 1e-6 && (t - 1.0).abs() < 1e-3, "t = {t}, h = {h}");
        }
        other => panic!("expected StepSizeTooSmall, got {other:?}"),
    }
}

// A derivative that turns NaN at t_nan is localised to t_nan (the step size collapses
// onto it), reported as NonFiniteState with the component index.
#[test]
fn dopri5_nan_reports_onset_time_and_index() {
    let t_nan = 0.5;
    let mut p = NanAfter { t_nan, index: 1 };
    let mut st = DormandPrince45::new(2, tol_settings(1e-8));
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
    // everything accepted so far is finite and before the onset
    assert!(st.t() < t_nan);
    assert!(st.y().iter().all(|v| v.is_finite()));
}

#[test]
fn dopri5_rhs_error_passes_through() {
    let mut p = FailingRhs { t_fail: 0.5 };
    let mut st = DormandPrince45::new(1, tol_settings(1e-8));
    st.init(&mut p, 0.0, &[1.0]).expect("init");
    let err = loop {
        if let Err(e) = st.step(&mut p, 2.0) {
            break e;
        }
    };
    let t_ok = st.t();
    match err {
        IntegrateError::Rhs(RhsFailure { t }) => assert!(t >= 0.5 && t_ok < 0.5, "t = {t}"),
        other => panic!("expected Rhs error, got {other:?}"),
    }
    // a failure at t0 comes out of init
    let mut p = FailingRhs { t_fail: 0.0 };
    let res = st.init(&mut p, 0.0, &[1.0]);
    assert!(matches!(res, Err(IntegrateError::Rhs(RhsFailure { t })) if t == 0.0));
}

#[test]
fn dopri5_too_many_steps() {
    let mut p = HarmonicOscillator::default();
    let mut st = DormandPrince45::new(
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
        IntegrateError::TooManySteps { t, max_steps } => {
            assert_eq!(max_steps, 10);
            assert_eq!(t, st.t());
            let s = st.stats();
            assert_eq!(s.steps + s.rejected, 10);
        }
        other => panic!("expected TooManySteps, got {other:?}"),
    }
}

#[test]
fn dopri5_respects_h_max_h_init_and_stop_times() {
    let mut p = ExponentialDecay::default();
    let s = StepControl {
        h_max: 0.01,
        ..tol_settings(1e-6)
    };
    let mut st = DormandPrince45::new(1, s);
    st.init(&mut p, 0.0, &[1.0]).expect("init");
    while st.t() < 1.0 {
        let t0 = st.t();
        let t1 = st.step(&mut p, 1.0).expect("step");
        assert!(t1 - t0 <= 0.01 * 1.01 + 1e-15, "step {}", t1 - t0);
    }
    assert!(st.stats().steps >= 100);

    // h_init is the first step when it passes the error test
    let s = StepControl {
        h_init: Some(1e-3),
        ..tol_settings(1e-6)
    };
    let mut st = DormandPrince45::new(1, s);
    st.init(&mut p, 0.0, &[1.0]).expect("init");
    assert_eq!(st.step(&mut p, 1.0).expect("step"), 1e-3);

    // many stop times: each is hit exactly and costs about one extra step (measured 21 for
    // 20 stops; bound 25)
    let free = run(HarmonicOscillator::default(), tol_settings(1e-8), 10.0)
        .stats
        .steps;
    let mut p = HarmonicOscillator::default();
    let mut st = DormandPrince45::new(2, tol_settings(1e-8));
    st.init(&mut p, 0.0, &[1.0, 0.0]).expect("init");
    for k in 1..=20 {
        let t_stop = f64::from(k) * 0.5;
        while st.t() < t_stop {
            st.step(&mut p, t_stop).expect("step");
        }
        assert_eq!(st.t(), t_stop);
    }
    let with_stops = st.stats().steps;
    eprintln!("steps free {free}, with 20 stops {with_stops}");
    assert!(
        with_stops <= free + 25,
        "free {free}, with stops {with_stops}"
    );
    // at t_stop a step is a no-op
    assert_eq!(st.step(&mut p, 10.0).expect("no-op"), 10.0);
    assert_eq!(st.stats().steps, with_stops);
}

#[test]
fn dopri5_settings_validation() {
    let ok = StepControl::new(1e-6, 1e-9);
    assert!(ok.validate().is_ok());
    let cases = [
        ("rtol", StepControl { rtol: -1.0, ..ok }),
        ("atol", StepControl { atol: 0.0, ..ok }),
        (
            "h_init",
            StepControl {
                h_init: Some(f64::NAN),
                ..ok
            },
        ),
        ("h_max", StepControl { h_max: 0.0, ..ok }),
        (
            "h_min",
            StepControl {
                h_min: 1.0,
                h_max: 0.5,
                ..ok
            },
        ),
        (
            "h_init",
            StepControl {
                h_init: Some(1e-9),
                h_min: 1e-6,
                ..ok
            },
        ),
        ("max_steps", StepControl { max_steps: 0, ..ok }),
    ];
    for (field, s) in cases {
        match DormandPrince45::try_new(1, s) {
            Err(e) => {
                assert_eq!(e.field, field);
                assert!(e.to_string().contains(field));
            }
            Ok(_) => panic!("{field}: accepted invalid settings"),
        }
    }
}
