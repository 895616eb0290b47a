//! Rosenbrock-specific tests: the tableau (W order conditions, transformed coefficients), the
//! W property (order with a wrong Jacobian), Jacobian reuse, finite-difference Jacobians, the
//! stiff error bound, a singular iteration matrix and failing Jacobians. The stepper contract
//! (orders, tolerance, dense output, counts with an analytic Jacobian, errors, settings) is
//! `contract.rs`.

use super::super::test_problems::{
    ExactSolution, Kepler, RationalDecay, RhsFailure, StiffKepler, StiffLinear, StiffOscillator,
};
use super::super::testutil::{run_exact, run_to_failure, scaled_err, Run};
use super::super::{integrate_sampled, DormandPrince45, FdJacobian, OdeSystem};
use super::tableau::{ALPHA, B, B_HAT, GAMMA_IJ};
use super::*;

/// Fixed step `h`: tolerances so loose that every step passes, `h_init = h_max = h`.
fn fixed_control(h: f64) -> StepControl {
    StepControl {
        h_init: Some(h),
        h_max: h,
        ..StepControl::new(1e3, 1e3)
    }
}

fn run<P: ExactSolution + OdeJacobian>(
    p: P,
    control: StepControl,
    reuse: usize,
    t_end: f64,
) -> Run {
    let mut st = Rosenbrock::new(p.dim(), control).with_jacobian_reuse(reuse);
    run_exact(p, &mut st, t_end)
}

/// Global scaled error at t_end with fixed step h (no rejections).
fn fixed<P: ExactSolution + OdeJacobian>(p: P, h: f64, t_end: f64) -> f64 {
    let r = run(p, fixed_control(h), 1, t_end);
    assert_eq!(r.stats.rejected, 0);
    r.err_end
}

// The W-method order conditions of order 3 (HNW II §IV.7; for any W, so the trees with J
// nodes are separate conditions), with g_i = sum_{j<=i} gamma_ij:
//   sum b = 1; sum b alpha = 1/2; sum b g = 0;
//   sum b alpha^2 = 1/3; sum b_i alpha_ij alpha_j = 1/6; sum b_i alpha_ij g_j = 0;
//   sum b_i gamma_ij alpha_j = 0; sum b_i gamma_ij g_j = 0;
// the embedded solution's of order 2; stiff accuracy b_i = alpha_4i + gamma_4i; and
// R(inf) = 1 - b^T (alpha + Gamma)^-1 1 = 0 (L-stability at infinity). All to 1e-14 (the
// coefficients are given to 17 digits).
#[test]
fn ros34pw2_satisfies_w_order_conditions() {
    let (al, g, b, bh) = (ALPHA, GAMMA_IJ, B, B_HAT);
    let a: [f64; 4] = std::array::from_fn(|i| al[i].iter().sum());
    let gs: [f64; 4] = std::array::from_fn(|i| g[i][..=i].iter().sum());
    let sum = |f: &dyn Fn(usize) -> f64| (0..4).map(f).sum::<f64>();
    let conds = [
        ("sum b", sum(&|i| b[i]), 1.0),
        ("sum b alpha", sum(&|i| b[i] * a[i]), 0.5),
        ("sum b g", sum(&|i| b[i] * gs[i]), 0.0),
        ("sum b alpha^2", sum(&|i| b[i] * a[i] * a[i]), 1.0 / 3.0),
        (
            "sum b alpha_ij alpha_j",
            sum(&|i| b[i] * sum(&|j| al[i][j] * a[j])),
            1.0 / 6.0,
        ),
        (
            "sum b alpha_ij g_j",
            sum(&|i| b[i] * sum(&|j| al[i][j] * gs[j])),
            0.0,
        ),
        (
            "sum b gamma_ij alpha_j",
            sum(&|i| b[i] * sum(&|j| g[i][j] * a[j])),
            0.0,
        ),
        (
            "sum b gamma_ij g_j",
            sum(&|i| b[i] * sum(&|j| g[i][j] * gs[j])),
            0.0,
        ),
        ("sum bh", sum(&|i| bh[i]), 1.0),
        ("sum bh alpha", sum(&|i| bh[i] * a[i]), 0.5),
        ("sum bh g", sum(&|i| bh[i] * gs[i]), 0.0),
    ];
    for (name, v, expect) in conds {
        assert!((v - expect).abs() < 1e-14, "{name}: {v} vs {expect}");
    }
    // the embedded solution is only of order 2: it misses sum bh alpha^2 = 1/3
    assert!((sum(&|i| bh[i] * a[i] * a[i]) - 1.0 / 3.0).abs() > 1e-3);
    for i in 0..4 {
        assert!(
            (b[i] - (al[3][i] + g[3][i])).abs() < 1e-15,
            "stiff accuracy {i}"
        );
    }
    // R(inf) = 1 - b^T x, (alpha + Gamma) x = 1 (lower triangular)
    let mut x = [0.0; 4];
    for i in 0..4 {
        let s: f64 = (0..i).map(|j| (al[i][j] + g[i][j]) * x[j]).sum();
        x[i] = (1.0 - s) / g[i][i];
    }
    let r_inf = 1.0 - sum(&|i| b[i] * x[i]);
    assert!(r_inf.abs() < 1e-14, "R(inf) = {r_inf}");
}

// The transformed coefficients reproduce the original method: m Gamma = b, e Gamma = b - b_hat,
// a Gamma = alpha, and C Gamma = diag(1/gamma) Gamma - I below the diagonal (to 1e-13).
#[test]
fn transformed_coefficients_reproduce_the_method() {
    let tab = Tableau::new();
    for i in 0..4 {
        let mg: f64 = (0..4).map(|k| tab.m[k] * GAMMA_IJ[k][i]).sum();
        assert!((mg - B[i]).abs() < 1e-14, "m Gamma [{i}]");
        let eg: f64 = (0..4).map(|k| tab.e[k] * GAMMA_IJ[k][i]).sum();
        assert!((eg - (B[i] - B_HAT[i])).abs() < 1e-14, "e Gamma [{i}]");
        for j in 0..i {
            let ag: f64 = (0..4).map(|k| tab.a[i][k] * GAMMA_IJ[k][j]).sum();
            assert!((ag - ALPHA[i][j]).abs() < 1e-14, "a Gamma [{i}][{j}]");
            // C = diag(1/gamma) - Gamma^-1  =>  C Gamma = diag(1/gamma) Gamma - I
            // (the diagonal of C is 1/gamma - 1/gamma = 0)
            let cg: f64 = (0..i).map(|k| tab.c[i][k] * GAMMA_IJ[k][j]).sum();
            let expect = GAMMA_IJ[i][j] / GAMMA;
            assert!(
                (cg - expect).abs() < 1e-13,
                "c Gamma [{i}][{j}]: {cg} vs {expect}"
            );
        }
    }
}

/// A deliberately wrong Jacobian: `0.5 J + 0.3` in every entry plus `0.7 I`, and `f_t = 0`.
#[derive(Clone, Copy, Debug)]
struct WrongJacobian<P>(P);

impl<P: OdeSystem> OdeSystem for WrongJacobian<P> {
    type Error = P::Error;
    fn dim(&self) -> usize {
        self.0.dim()
    }
    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), P::Error> {
        self.0.rhs(t, y, dydt)
    }
}

impl<P: OdeJacobian> OdeJacobian for WrongJacobian<P> {
    fn jacobian(&mut self, t: f64, y: &[f64], fy: &[f64], jac: &mut [f64]) -> Result<(), P::Error> {
        self.0.jacobian(t, y, fy, jac)?;
        let n = y.len();
        for (k, v) in jac.iter_mut().enumerate() {
            *v = 0.5 * *v + 0.3 + if k % (n + 1) == 0 { 0.7 } else { 0.0 };
        }
        Ok(())
    }
    fn time_derivative(
        &mut self,
        _t: f64,
        _y: &[f64],
        _fy: &[f64],
        dfdt: &mut [f64],
    ) -> Result<bool, P::Error> {
        dfdt.fill(0.0);
        Ok(true)
    }
}

impl<P: ExactSolution> ExactSolution for WrongJacobian<P> {
    fn t0(&self) -> f64 {
        self.0.t0()
    }
    fn exact(&self, t: f64, y: &mut [f64]) {
        self.0.exact(t, y)
    }
}

// The W property: with a wrong Jacobian (0.5 J + 0.3, + 0.7 I, f_t = 0) the fixed-step global
// error still falls 8x per halving of h: observed order in [2.8, 3.2] (non-autonomous
// nonlinear rational decay, f_t != 0; Kepler e = 0.3). With the exact Jacobian: the contract.
#[test]
fn ros34pw2_keeps_order_three_with_a_wrong_jacobian() {
    let tau = std::f64::consts::TAU;
    for (name, e1, e2) in [
        (
            "rational",
            fixed(WrongJacobian(RationalDecay), 0.05, 3.0),
            fixed(WrongJacobian(RationalDecay), 0.025, 3.0),
        ),
        (
            "kepler",
            fixed(WrongJacobian(Kepler { e: 0.3 }), tau / 800.0, tau),
            fixed(WrongJacobian(Kepler { e: 0.3 }), tau / 1600.0, tau),
        ),
    ] {
        let order = (e1 / e2).log2();
        eprintln!("{name} wrong J: err {e1:.3e} -> {e2:.3e}, observed order {order:.3}");
        assert!((2.8..=3.2).contains(&order), "{name}: order {order}");
    }
}

// Stiff regime, fixed step (h |lambda| >= 100): Prothero-Robinson, the method's design case
// ("P" in ROS34PW2). The global error at t = 3 is of singular-perturbation type,
// O(h^2 / |lambda|): uniformly tiny as |lambda| grows (no order reduction to O(h) or O(1)).
// Measured err |lambda| / h^2 = 4.5e-3 for lambda = -1e4 and -1e6; bound 1e-2, and observed
// order in h in [1.8, 2.2].
#[test]
fn ros34pw2_stiff_prothero_robinson_error_is_h2_over_lambda() {
    for lambda in [-1e4, -1e6] {
        let p = StiffLinear { lambda, y0: 1.0 };
        let hs = [0.04, 0.02, 0.01];
        let e: Vec<f64> = hs.iter().map(|&h| fixed(p, h, 3.0)).collect();
        let (o1, o2) = ((e[0] / e[1]).log2(), (e[1] / e[2]).log2());
        let k: Vec<f64> = hs
            .iter()
            .zip(&e)
            .map(|(h, e)| e * lambda.abs() / (h * h))
            .collect();
        eprintln!("PR {lambda:.0e}: err {e:?}, orders {o1:.3} {o2:.3}, err |lambda|/h^2 {k:?}");
        assert!(
            (1.8..=2.2).contains(&o1) && (1.8..=2.2).contains(&o2),
            "{o1} {o2}"
        );
        assert!(k.iter().all(|&k| k <= 1e-2), "{k:?}");
    }
}

// The motor oscillator (eigenvalues -450 +- 1900i, -20; 0.2 Hz reference; 5 s) at tol 1e-6
// and 1e-9: ROS34PW2 needs fewer steps than DOPRI5 and meets 20 tol with the analytic
// Jacobian and with a finite-difference one refreshed every 1 and every 5 steps (counts
// printed for the report; a finite-difference Jacobian costs 3 more rhs evaluations). Also
// with the current in units where it is slaved to the velocity error with gain 4160 (gain
// a = 1): one tolerance for all components then makes the current limit the step (measured
// ROS34PW2 3936 vs DOPRI5 13083 steps at 1e-6), still fewer than DOPRI5.
#[test]
fn rosenbrock_vs_dopri5_on_motor_oscillator() {
    for tol in [1e-6, 1e-9] {
        for gain in [1.0, 1e3] {
            let p = StiffOscillator {
                gain,
                ..Default::default()
            };
            let d = run_exact(
                p,
                &mut DormandPrince45::new(3, StepControl::new(tol, tol)),
                5.0,
            );
            for (reuse, fd) in [(1, false), (1, true), (5, true)] {
                let mut st =
                    Rosenbrock::new(3, StepControl::new(tol, tol)).with_jacobian_reuse(reuse);
                let r = if fd {
                    run_exact(FdJacobian::new(p), &mut st, 5.0)
                } else {
                    run_exact(p, &mut st, 5.0)
                };
                let (s, ds) = (r.stats, d.stats);
                eprintln!(
                    "tol {tol:.0e} gain {gain} reuse {reuse} fd {fd}: DOPRI5 {} steps, {} rhs; \
                     ROS34PW2 {} steps ({} rejected), {} rhs, {} J, {} LU, err {:.2} tol",
                    ds.steps,
                    ds.rhs_evals,
                    s.steps,
                    s.rejected,
                    s.rhs_evals,
                    s.jacobian_evals,
                    s.lu_decompositions,
                    r.err_end / tol
                );
                let ok = s.steps < ds.steps && r.err_end <= 20.0 * tol;
                assert!(ok, "{s:?} vs {ds:?}, err {:e}", r.err_end);
            }
        }
    }
}

// Jacobian reuse (finite differences, the robot's case): refreshing every 5 or 20 steps cuts
// jacobian_evals at least 3x, keeps the tolerance (samples of integrate_sampled at 100 Hz
// within the same C tol as a fresh J every step: 500 stiff Kepler, 20 motor oscillator) and
// costs few extra steps (bound: 1.5x the steps with a fresh J); tol 1e-7.
#[test]
fn rosenbrock_jacobian_reuse_cuts_jacobian_evals_and_keeps_tolerance() {
    fn go<P: ExactSolution + Clone>(p: P, t_end: f64, name: &str, c: f64) {
        let tol = 1e-7;
        let y0 = p.y0();
        let mut base: Option<Stats> = None;
        for reuse in [1, 5, 20] {
            let mut sys = FdJacobian::new(p.clone());
            let mut st =
                Rosenbrock::new(p.dim(), StepControl::new(tol, tol)).with_jacobian_reuse(reuse);
            let (mut ex, mut worst) = (vec![0.0; y0.len()], 0.0f64);
            let s = integrate_sampled(&mut st, &mut sys, 0.0, &y0, t_end, 0.01, |t, y| {
                p.exact(t, &mut ex);
                worst = worst.max(scaled_err(y, &ex));
                Ok(())
            })
            .expect("integrate_sampled");
            eprintln!(
                "{name} reuse {reuse:2}: steps {}, rejected {}, jacobians {}, LU {}, rhs {} + {} in J, max err {:.2} tol",
                s.steps, s.rejected, s.jacobian_evals, s.lu_decompositions, s.rhs_evals, sys.fd_evals(), worst / tol
            );
            assert!(worst <= c * tol, "{name} reuse {reuse}: err {worst:e}");
            match base {
                None => base = Some(s),
                Some(b) => {
                    assert!(
                        s.jacobian_evals * 3 <= b.jacobian_evals,
                        "{name} reuse {reuse}: {s:?} vs {b:?}"
                    );
                    assert!(
                        s.steps as f64 <= 1.5 * b.steps as f64,
                        "{name} reuse {reuse}: {s:?} vs {b:?}"
                    );
                }
            }
        }
    }
    go(
        StiffKepler::default(),
        std::f64::consts::TAU,
        "stiff kepler",
        500.0,
    );
    go(StiffOscillator::default(), 5.0, "motor oscillator", 20.0);
}

// Counts through FdJacobian (no analytic f_t), reuse 3, Kepler e = 0.9, starting step guessed:
// 2 + 3 per attempt + 2 per accepted step (f at the new point, and the forward difference in
// t at every step start); dim = 4 rhs per Jacobian inside it, at most one Jacobian per 3
// accepted steps plus one per rejection.
#[test]
fn rosenbrock_counts_with_finite_difference_jacobian_and_reuse() {
    let tau = std::f64::consts::TAU;
    let mut p = FdJacobian::new(Kepler { e: 0.9 });
    let y0 = p.inner().y0();
    let mut st = Rosenbrock::new(4, StepControl::new(1e-7, 1e-7)).with_jacobian_reuse(3);
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
    assert_eq!(st.jacobian_reuse(), 3);
}

/// `y' = -y` whose Jacobian is -1 before `t_sing` and `1 / (gamma h_sing)` from `t_sing` on,
/// so that `I/(h gamma) - J` is exactly singular for `h = h_sing`; or (`fail`) whose Jacobian
/// fails with `RhsFailure` from `t_sing` on, or (`nan`) is NaN from `t_sing` on.
#[derive(Clone, Copy, Debug)]
struct OddJacobian {
    t_sing: f64,
    h_sing: f64,
    fail: bool,
    nan: bool,
}

impl OdeSystem for OddJacobian {
    type Error = RhsFailure;
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), RhsFailure> {
        dydt[0] = -y[0];
        Ok(())
    }
}

impl OdeJacobian for OddJacobian {
    fn jacobian(
        &mut self,
        t: f64,
        _y: &[f64],
        _fy: &[f64],
        jac: &mut [f64],
    ) -> Result<(), RhsFailure> {
        jac[0] = if t < self.t_sing {
            -1.0
        } else if self.fail {
            return Err(RhsFailure { t });
        } else if self.nan {
            f64::NAN
        } else {
            1.0 / (self.h_sing * GAMMA)
        };
        Ok(())
    }
}

impl ExactSolution for OddJacobian {
    fn t0(&self) -> f64 {
        0.0
    }
    fn exact(&self, t: f64, y: &mut [f64]) {
        y[0] = (-t).exp();
    }
}

// With the step pinned (h_min = h_max = 0.1) the singular matrix in the step from t = 0.5 is
// reported as SingularMatrix { t = 0.5, h = 0.1 }, with the state kept at t = 0.5. With a free
// step size the stepper halves h past the singularity and finishes within 10 tol. A failing
// Jacobian passes through as Rhs, a NaN one is NonFiniteState (row 0), both at the step's
// start (t = 0.25), the state kept.
#[test]
fn rosenbrock_singular_matrix_and_failing_jacobians_are_reported() {
    let h = 0.1;
    let odd = OddJacobian {
        t_sing: 0.45,
        h_sing: h,
        fail: false,
        nan: false,
    };
    let mut p = odd;
    let mut st = Rosenbrock::new(
        1,
        StepControl {
            h_min: h,
            ..fixed_control(h)
        },
    );
    st.init(&mut p, 0.0, &[1.0]).expect("init");
    let err = run_to_failure(&mut st, &mut p, 1.0);
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
    let c = StepControl {
        h_init: Some(h),
        h_max: h,
        ..StepControl::new(tol, tol)
    };
    let r = run(odd, c, 1, 1.0);
    eprintln!("free step size: {:?}, err {:.2e}", r.stats, r.err_end);
    assert!(
        r.stats.rejected >= 1 && r.err_end <= 10.0 * tol,
        "{:?} {}",
        r.stats,
        r.err_end
    );

    for (fail, nan) in [(true, false), (false, true)] {
        let mut p = OddJacobian {
            t_sing: 0.0,
            fail,
            nan,
            ..odd
        };
        let mut st = Rosenbrock::new(1, StepControl::new(1e-8, 1e-8));
        st.init(&mut p, 0.25, &[1.0]).expect("init");
        let res = st.step(&mut p, 1.0);
        let ok = match res {
            Err(IntegrateError::Rhs(RhsFailure { t })) => fail && t == 0.25,
            Err(IntegrateError::NonFiniteState { t, index: 0 }) => nan && t == 0.25,
            _ => false,
        };
        assert!(ok && st.t() == 0.25, "fail {fail} nan {nan}: {res:?}");
    }
}

#[test]
fn rosenbrock_jacobian_reuse_zero_is_rejected() {
    let c = StepControl::new(1e-6, 1e-9);
    let e = Rosenbrock::new(1, c)
        .try_with_jacobian_reuse(0)
        .expect_err("reuse 0");
    assert_eq!(
        (e.settings, e.field, e.value),
        ("Rosenbrock", "jacobian_reuse", 0.0)
    );
    assert!(
        e.to_string().contains("Rosenbrock.jacobian_reuse = 0"),
        "{e}"
    );
    assert_eq!(Rosenbrock::new(1, c).jacobian_reuse(), 1);
}
