use super::super::test_problems::{
    ExactSolution, ExponentialDecay, FailingRhs, HarmonicOscillator, Kepler, NanAfter,
    RationalDecay, RhsFailure, StiffKepler, StiffLinear, StiffOscillator,
};
use super::super::testutil::{run_exact, scaled_err, Run};
use super::super::{integrate_sampled, DormandPrince45, FdJacobian, OdeSystem};
use super::tableau::{ALPHA, B, B_HAT, GAMMA_IJ};
use super::*;
use std::convert::Infallible;

fn tol_settings(tol: f64) -> StepControl {
    StepControl::new(tol, tol)
}

/// Fixed step `h`: tolerances so loose that every step passes, `h_init = h_max = h`.
fn fixed_settings(h: f64) -> StepControl {
    StepControl {
        rtol: 1e3,
        atol: 1e3,
        h_init: Some(h),
        h_max: h,
        ..StepControl::new(1e-6, 1e-9)
    }
}

fn run<P: ExactSolution + OdeJacobian>(p: P, settings: StepControl, t_end: f64) -> Run {
    let st = Rosenbrock::new(p.dim(), settings);
    run_exact(p, st, t_end)
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

/// Global scaled error at t_end with fixed step h (no rejections).
fn fixed<P: ExactSolution + OdeJacobian>(p: P, h: f64, t_end: f64) -> f64 {
    let r = run(p, fixed_settings(h), t_end);
    assert_eq!(r.stats.rejected, 0);
    r.err_end
}

// With the controller out of the loop, the global error falls 8x per halving of h: observed
// order in [2.8, 3.2] — with the exact Jacobian and f_t, and with a wrong one (0.5 J + 0.3,
// + 0.7 I, f_t = 0: the W property). Non-autonomous nonlinear (rational, f_t != 0) and
// Kepler e = 0.3.
#[test]
fn ros34pw2_fixed_step_order_three_exact_and_wrong_jacobian() {
    let tau = std::f64::consts::TAU;
    for (name, e1, e2) in [
        (
            "rational exact J",
            fixed(RationalDecay, 0.05, 3.0),
            fixed(RationalDecay, 0.025, 3.0),
        ),
        (
            "rational wrong J",
            fixed(WrongJacobian(RationalDecay), 0.05, 3.0),
            fixed(WrongJacobian(RationalDecay), 0.025, 3.0),
        ),
        (
            "kepler exact J",
            fixed(Kepler { e: 0.3 }, tau / 800.0, tau),
            fixed(Kepler { e: 0.3 }, tau / 1600.0, tau),
        ),
        (
            "kepler wrong J",
            fixed(WrongJacobian(Kepler { e: 0.3 }), tau / 800.0, tau),
            fixed(WrongJacobian(Kepler { e: 0.3 }), tau / 1600.0, tau),
        ),
    ] {
        let order = (e1 / e2).log2();
        eprintln!("{name}: err {e1:.3e} -> {e2:.3e}, observed order {order:.3}");
        assert!((2.8..=3.2).contains(&order), "{name}: order {order}");
    }
}

/// Well-posed problems with end time and error constant C (global error <= C tol, end point
/// and dense output, rtol = atol = tol in 1e-5..1e-9). Measured worst err/tol: PR 2.3 (dense;
/// end point 0.03), PR with transient 2.3, motor oscillator 6.4 (dense; end 0.6), stiff
/// Kepler 213, decay 0.5, harmonic 10.3, rational 0.7, Kepler e=0.5 108; C has a margin of 2-4x.
/// Kepler's are large for the physical reason given in the DOPRI5 tests (energy errors become
/// phase errors), the harmonic oscillator's because 10 s is 3 periods of undamped error growth.
fn for_each_problem(mut f: impl FnMut(&str, f64, &dyn Fn(StepControl) -> Run)) {
    let tau = std::f64::consts::TAU;
    f("PR -1e4", 7.0, &|s| {
        run(
            StiffLinear {
                lambda: -1e4,
                y0: 1.0,
            },
            s,
            3.0,
        )
    });
    f("PR -1e4 y0=2", 7.0, &|s| {
        run(
            StiffLinear {
                lambda: -1e4,
                y0: 2.0,
            },
            s,
            3.0,
        )
    });
    f("motor oscillator", 20.0, &|s| {
        run(StiffOscillator::default(), s, 5.0)
    });
    f("stiff kepler", 500.0, &|s| {
        run(StiffKepler::default(), s, tau)
    });
    f("decay", 2.0, &|s| {
        run(ExponentialDecay { k: 1.0, y0: 1.0 }, s, 5.0)
    });
    f("harmonic", 30.0, &|s| {
        run(HarmonicOscillator { omega: 2.0 }, s, 10.0)
    });
    f("rational", 2.0, &|s| run(RationalDecay, s, 5.0));
    f("kepler e=0.5", 300.0, &|s| run(Kepler { e: 0.5 }, s, tau));
}

// Global error at t_end and dense-output error at 7 interior points of every step stay below
// C tol for tol in {1e-5, 1e-7, 1e-9}, on the stiff problems (state C of the brief: stiff,
// exact solution known) and non-stiff ones, and decrease with tol.
#[test]
fn rosenbrock_global_and_dense_error_within_c_tol() {
    for_each_problem(|name, c, solve| {
        let mut prev = f64::INFINITY;
        for tol in [1e-5, 1e-7, 1e-9] {
            let r = solve(tol_settings(tol));
            eprintln!(
                "{name:19} tol {tol:.0e}: end err {:.2e} ({:.3} tol), dense err {:.2e} ({:.2} tol), steps {}, rejected {}, rhs {}",
                r.err_end,
                r.err_end / tol,
                r.err_dense,
                r.err_dense / tol,
                r.stats.steps,
                r.stats.rejected,
                r.stats.rhs_evals
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

/// Steps of DOPRI5 on the same problem and tolerance (for contrast).
fn dopri5_steps<P: ExactSolution>(mut p: P, tol: f64, t_end: f64) -> (Stats, f64) {
    let y0 = p.y0();
    let n = p.dim();
    let s = StepControl::new(tol, tol);
    let mut st = DormandPrince45::new(n, s);
    let t0 = p.t0();
    st.init(&mut p, t0, &y0).expect("init");
    while st.t() < t_end {
        st.step(&mut p, t_end).expect("step");
    }
    let mut ex = vec![0.0; n];
    p.exact(t_end, &mut ex);
    (st.stats(), scaled_err(st.y(), &ex))
}

// Prothero-Robinson y' = lambda (y - cos t) - sin t on [0, 1] at tol 1e-6: ROS34PW2's step
// count is small and nearly independent of lambda (measured 11, 14, 14 steps for lambda =
// -1e2, -1e4, -1e6; bound <= 40 and max/min <= 1.5), while DOPRI5 is stability-limited
// (|h lambda| <= 3.3: measured 3030 steps, 18188 rhs at -1e4; bound >= 1e4 / 3.31).
#[test]
fn rosenbrock_step_count_independent_of_stiffness_unlike_dopri5() {
    let tol = 1e-6;
    let mut counts = Vec::new();
    for lambda in [-1e2, -1e4, -1e6] {
        let r = run(StiffLinear { lambda, y0: 1.0 }, tol_settings(tol), 1.0);
        eprintln!(
            "lambda {lambda:.0e}: Rosenbrock {} steps, {} rejected, {} rhs, {} jacobians, err {:.2e}",
            r.stats.steps, r.stats.rejected, r.stats.rhs_evals, r.stats.jacobian_evals, r.err_end
        );
        assert!(r.err_end <= 7.0 * tol);
        counts.push(r.stats.steps as f64);
    }
    let (d, d_err) = dopri5_steps(
        StiffLinear {
            lambda: -1e4,
            y0: 1.0,
        },
        tol,
        1.0,
    );
    eprintln!(
        "lambda -1e4: DOPRI5 {} steps, {} rhs, err {d_err:.2e}",
        d.steps, d.rhs_evals
    );
    let (lo, hi) = counts
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &c| (a.min(c), b.max(c)));
    assert!(hi <= 40.0 && hi / lo <= 1.5, "{counts:?}");
    assert!(d.steps as f64 >= 1e4 / 3.31, "DOPRI5 {d:?}");
}

// The brief's comparison on the motor oscillator (eigenvalues -450 +- 1900i, -20; 0.2 Hz
// reference; 5 s) at tol 1e-6 and 1e-9: steps and rhs evaluations of DOPRI5 and ROS34PW2
// (analytic Jacobian; and finite-difference Jacobian refreshed every 1 and every 5 steps,
// counting the Jacobian's own rhs evaluations). Printed for the report; asserts only that
// ROS34PW2 needs fewer steps than DOPRI5 and meets 20 tol (see `for_each_problem`). Also
// printed: the same with the current in units where it is slaved to the velocity error with
// gain 4160 (gain a = 1): one tolerance for all components then makes the current limit the
// step (measured ROS34PW2 3936 vs DOPRI5 13083 steps at 1e-6).
#[test]
fn rosenbrock_vs_dopri5_on_motor_oscillator() {
    for tol in [1e-6, 1e-9] {
        let a1 = StiffOscillator {
            gain: 1.0,
            ..Default::default()
        };
        let (d, _) = dopri5_steps(a1, tol, 5.0);
        let r = run(a1, tol_settings(tol), 5.0);
        eprintln!(
            "tol {tol:.0e}, gain 1: DOPRI5 {} steps, {} rhs; ROS34PW2 {} steps, {} rhs, err {:.2} tol",
            d.steps, d.rhs_evals, r.stats.steps, r.stats.rhs_evals, r.err_end / tol
        );
        assert!(r.stats.steps < d.steps && r.err_end <= 20.0 * tol);
    }
    for tol in [1e-6, 1e-9] {
        let (d, d_err) = dopri5_steps(StiffOscillator::default(), tol, 5.0);
        let r = run(StiffOscillator::default(), tol_settings(tol), 5.0);
        eprintln!(
            "tol {tol:.0e}: DOPRI5 {} steps ({} rejected), {} rhs, err {:.2} tol",
            d.steps,
            d.rejected,
            d.rhs_evals,
            d_err / tol
        );
        eprintln!(
            "tol {tol:.0e}: ROS34PW2 analytic J: {} steps ({} rejected), {} rhs, {} J, {} LU, err {:.2} tol",
            r.stats.steps, r.stats.rejected, r.stats.rhs_evals, r.stats.jacobian_evals,
            r.stats.lu_decompositions, r.err_end / tol
        );
        for reuse in [1, 5] {
            let mut p = FdJacobian::new(StiffOscillator::default());
            let y0 = p.inner().y0();
            let mut st = Rosenbrock::new(3, tol_settings(tol)).with_jacobian_reuse(reuse);
            st.init(&mut p, 0.0, &y0).expect("init");
            while st.t() < 5.0 {
                st.step(&mut p, 5.0).expect("step");
            }
            let mut ex = [0.0; 3];
            p.inner().exact(5.0, &mut ex);
            let e = scaled_err(st.y(), &ex);
            let s = st.stats();
            eprintln!(
                "tol {tol:.0e}: ROS34PW2 FD J reuse {reuse}: {} steps ({} rejected), {} rhs + {} in J = {}, {} J, {} LU, err {:.2} tol",
                s.steps, s.rejected, s.rhs_evals, p.fd_evals(), s.rhs_evals + p.fd_evals(),
                s.jacobian_evals, s.lu_decompositions, e / tol
            );
            assert!(e <= 20.0 * tol, "reuse {reuse}: err {e}");
        }
        assert!(r.stats.steps < d.steps, "{:?} vs {d:?}", r.stats);
        assert!(r.err_end <= 20.0 * tol);
    }
}

// Jacobian reuse (finite differences, the robot's case): refreshing every 5 or 20 steps cuts
// jacobian_evals and the rhs evaluations spent on Jacobians, keeps the tolerance (error within
// the same 20 tol as a fresh J every step) and costs few extra steps (bound: 1.5x the steps
// with a fresh J). Stiff Kepler (tol 1e-7) and the motor oscillator (tol 1e-7).
#[test]
fn rosenbrock_jacobian_reuse_cuts_jacobian_evals_and_keeps_tolerance() {
    fn go<P: ExactSolution + Clone>(p: P, t_end: f64, name: &str, c: f64) {
        let tol = 1e-7;
        let n = p.dim();
        let y0 = p.y0();
        let mut base: Option<Stats> = None;
        for reuse in [1, 5, 20] {
            let mut sys = FdJacobian::new(p.clone());
            let mut st = Rosenbrock::new(n, tol_settings(tol)).with_jacobian_reuse(reuse);
            st.init(&mut sys, 0.0, &y0).expect("init");
            while st.t() < t_end {
                st.step(&mut sys, t_end).expect("step");
            }
            let mut ex = vec![0.0; n];
            p.exact(t_end, &mut ex);
            let e = scaled_err(st.y(), &ex);
            let s = st.stats();
            eprintln!(
                "{name} reuse {reuse:2}: steps {}, rejected {}, jacobians {}, LU {}, rhs {} + {} in J, err {:.2} tol",
                s.steps, s.rejected, s.jacobian_evals, s.lu_decompositions, s.rhs_evals, sys.fd_evals(), e / tol
            );
            assert!(e <= c * tol, "{name} reuse {reuse}: err {e:e}");
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

mod contract;
