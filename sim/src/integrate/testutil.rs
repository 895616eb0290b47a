//! Helpers shared by the steppers' tests: the tolerance-scaled error and a run against an
//! exact solution that also measures the dense output.

use super::test_problems::ExactSolution;
use super::{Stats, Stepper};

/// max_i |y_i - exact_i| / (1 + |exact_i|): the error scaled the way rtol = atol = tol asks
/// for roughly `tol` per step.
pub(super) fn scaled_err(y: &[f64], exact: &[f64]) -> f64 {
    y.iter()
        .zip(exact)
        .map(|(a, b)| (a - b).abs() / (1.0 + b.abs()))
        .fold(0.0, f64::max)
}

pub(super) struct Run {
    /// scaled error at t_end
    pub err_end: f64,
    /// max scaled error of dense output at 7 interior points of every step
    pub err_dense: f64,
    pub stats: Stats,
}

/// Integrates `p` with `st` from its t0 to `t_end`, stepping to `t_end` (never past it) and
/// checking the dense output at 7 interior points of every step.
pub(super) fn run_exact<P: ExactSolution, St: Stepper<P>>(mut p: P, mut st: St, t_end: f64) -> Run {
    let n = p.dim();
    let y0 = p.y0();
    let (mut ex, mut yi) = (vec![0.0; n], vec![0.0; n]);
    let t0 = p.t0();
    st.init(&mut p, t0, &y0).expect("init");
    let mut err_dense: f64 = 0.0;
    while st.t() < t_end {
        let t_old = st.t();
        let t_new = st.step(&mut p, t_end).expect("step");
        assert!(t_new <= t_end, "stepped past t_stop: {t_new} > {t_end}");
        for j in 1..8 {
            let tq = t_old + f64::from(j) / 8.0 * (t_new - t_old);
            st.interpolate(tq, &mut yi);
            p.exact(tq, &mut ex);
            err_dense = err_dense.max(scaled_err(&yi, &ex));
        }
    }
    assert_eq!(st.t(), t_end);
    p.exact(t_end, &mut ex);
    Run {
        err_end: scaled_err(st.y(), &ex),
        err_dense,
        stats: st.stats(),
    }
}

/// One step `h` of `st` from the exact state of `p` at `t0` (the step must end at `t0 + h`):
/// checks that the dense output returns both ends exactly and returns its max scaled error at
/// theta = 1/4, 1/2, 3/4.
pub(super) fn local_dense_err<P: ExactSolution, St: Stepper<P>>(
    mut p: P,
    mut st: St,
    t0: f64,
    h: f64,
) -> f64 {
    let n = p.dim();
    let mut y0 = vec![0.0; n];
    p.exact(t0, &mut y0);
    st.init(&mut p, t0, &y0).expect("init");
    assert_eq!(st.step(&mut p, 100.0).expect("step"), t0 + h);
    let (mut yi, mut ex) = (vec![0.0; n], vec![0.0; n]);
    st.interpolate(t0, &mut yi);
    assert_eq!(yi, y0);
    st.interpolate(t0 + h, &mut yi);
    assert_eq!(yi.as_slice(), st.y());
    let mut e: f64 = 0.0;
    for th in [0.25, 0.5, 0.75] {
        st.interpolate(t0 + th * h, &mut yi);
        p.exact(t0 + th * h, &mut ex);
        e = e.max(scaled_err(&yi, &ex));
    }
    e
}
