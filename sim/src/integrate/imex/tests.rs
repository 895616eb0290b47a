//! ArkImex-specific tests: the tableau's order conditions and stability, and the choice of the
//! split on the motor oscillator. The stepper contract (orders, tolerance, dense output,
//! counts, errors, settings, stiff problems) is `contract.rs`.

use super::super::test_problems::{OscillatorSplit, StiffOscillator};
use super::super::testutil::run_exact;
use super::super::DormandPrince45;
use super::*;

/// `sum_i w_i (A c^k)_i`-style sums: `phi(b, v) = sum_i b_i v_i`, `mv(A, v) = A v`.
fn dot(b: &[f64; 6], v: &[f64; 6]) -> f64 {
    b.iter().zip(v).map(|(x, y)| x * y).sum()
}
fn mv(a: &[[f64; 6]; 6], v: &[f64; 6]) -> [f64; 6] {
    std::array::from_fn(|i| dot(&a[i], v))
}
fn pow(c: &[f64; 6], k: i32) -> [f64; 6] {
    std::array::from_fn(|i| c[i].powi(k))
}
fn mul(u: &[f64; 6], v: &[f64; 6]) -> [f64; 6] {
    std::array::from_fn(|i| u[i] * v[i])
}

/// The additive order conditions up to order `p <= 4` for weights `b` (Kennedy & Carpenter 2003,
/// §3; with equal row sums `c` of both parts the colourings of the bushy trees coincide),
/// returned as (name, value - target) pairs. `theta` scales the targets for a continuous
/// extension (`theta^order / gamma(tree)`).
fn conditions(b: &[f64; 6], p: usize, theta: f64) -> Vec<(String, f64)> {
    let one = [1.0; 6];
    let parts = [("E", &AE), ("I", &AI)];
    let mut out = vec![("b.1".to_string(), dot(b, &one) - theta)];
    if p >= 2 {
        out.push(("b.c".into(), dot(b, &C) - theta.powi(2) / 2.0));
    }
    if p >= 3 {
        out.push(("b.c2".into(), dot(b, &pow(&C, 2)) - theta.powi(3) / 3.0));
        for (x, a) in parts {
            out.push((format!("b.A{x}c"), dot(b, &mv(a, &C)) - theta.powi(3) / 6.0));
        }
    }
    if p >= 4 {
        out.push(("b.c3".into(), dot(b, &pow(&C, 3)) - theta.powi(4) / 4.0));
        for (x, a) in parts {
            out.push((
                format!("b.(c*A{x}c)"),
                dot(b, &mul(&C, &mv(a, &C))) - theta.powi(4) / 8.0,
            ));
            out.push((
                format!("b.A{x}c2"),
                dot(b, &mv(a, &pow(&C, 2))) - theta.powi(4) / 12.0,
            ));
            for (y, a2) in parts {
                out.push((
                    format!("b.A{x}A{y}c"),
                    dot(b, &mv(a, &mv(a2, &C))) - theta.powi(4) / 24.0,
                ));
            }
        }
    }
    out
}

// The tableau as printed satisfies: row sums of both parts = c; every additive order
// condition to order 4 for b (incl. the coupling trees A_E A_I c etc.) and to order 3 for
// b_hat (which misses order 4); the dense weights b*(theta) satisfy the order-3 conditions at
// theta = 0.3, 0.7 and give b at theta = 1; the ESDIRK part is stiffly accurate and
// L-stable: |R(iy)| <= 1 on the imaginary axis and R(-1e8) ~ 0. Tolerance 1e-12 (the
// rational coefficients have up to 14 digits; measured residuals <= 3e-16... see output).
#[test]
fn ark436_satisfies_its_order_conditions() {
    for i in 0..6 {
        let (se, si): (f64, f64) = (AE[i].iter().sum(), AI[i].iter().sum());
        assert!(
            (se - C[i]).abs() < 1e-12 && (si - C[i]).abs() < 1e-12,
            "row sums {i}: {se} {si}"
        );
    }
    let mut worst: f64 = 0.0;
    for (name, r) in conditions(&B, 4, 1.0) {
        worst = worst.max(r.abs());
        assert!(r.abs() < 1e-12, "b: {name} residual {r:e}");
    }
    for (name, r) in conditions(&B_HAT, 3, 1.0) {
        worst = worst.max(r.abs());
        assert!(r.abs() < 1e-12, "b_hat: {name} residual {r:e}");
    }
    let missed = conditions(&B_HAT, 4, 1.0)
        .iter()
        .fold(0.0f64, |m, (_, r)| m.max(r.abs()));
    assert!(
        missed > 1e-6,
        "embedded solution is of order 3 only: {missed}"
    );
    for th in [0.3, 0.7, 1.0] {
        let bd: [f64; 6] = std::array::from_fn(|i| {
            B_DENSE[i][0] * th + B_DENSE[i][1] * th * th + B_DENSE[i][2] * th.powi(3)
        });
        for (name, r) in conditions(&bd, 3, th) {
            worst = worst.max(r.abs());
            assert!(r.abs() < 1e-12, "dense theta {th}: {name} residual {r:e}");
        }
        if th == 1.0 {
            for i in 0..6 {
                assert!(
                    (bd[i] - B[i]).abs() < 1e-12,
                    "b*_{i}(1) = {} vs {}",
                    bd[i],
                    B[i]
                );
            }
        }
    }
    eprintln!("largest order-condition residual {worst:.1e}");
    // stability function of the ESDIRK part, R(z) = 1 + z b^T (I - z A_I)^-1 1 (complex z)
    let r = |zr: f64, zi: f64| {
        // forward substitution on (I - z A) x = 1 in complex arithmetic
        let mut x = [(0.0, 0.0); 6];
        for i in 0..6 {
            let (mut sr, mut si) = (1.0, 0.0);
            for j in 0..i {
                let (ar, ai) = (zr * AI[i][j], zi * AI[i][j]);
                sr += ar * x[j].0 - ai * x[j].1;
                si += ar * x[j].1 + ai * x[j].0;
            }
            let (dr, di) = (1.0 - zr * AI[i][i], -zi * AI[i][i]);
            let den = dr * dr + di * di;
            x[i] = ((sr * dr + si * di) / den, (si * dr - sr * di) / den);
        }
        let (mut br, mut bi) = (0.0, 0.0);
        for i in 0..6 {
            br += B[i] * x[i].0;
            bi += B[i] * x[i].1;
        }
        let (rr, ri) = (1.0 + zr * br - zi * bi, zr * bi + zi * br);
        (rr * rr + ri * ri).sqrt()
    };
    for k in 0..200 {
        let y = 10f64.powf(-2.0 + 8.0 * f64::from(k) / 199.0);
        assert!(r(0.0, y) <= 1.0 + 1e-12, "|R({y}i)| = {}", r(0.0, y));
    }
    assert!(r(-1e8, 0.0) < 1e-6, "R(-1e8) = {}", r(-1e8, 0.0));
    for i in 0..6 {
        assert_eq!(AI[5][i], B[i]);
    }
}

// The brief's comparison on the motor oscillator (eigenvalues -450 +- 1900i, -20; 5 s) at tol
// 1e-6 and 1e-9, for the three splits (numbers in the output). Only the current equation
// implicit (the robot's diagonal split) leaves the velocity-current loop explicit: the step
// stays at the explicit stability limit (more steps than DOPRI5 at 1e-9, 965 rejections at
// 1e-6). With the torque term v' = a i also implicit, q' = v is still explicit and the
// position loop (gain p) still limits the step. Only with everything implicit are the steps
// accuracy-limited. Asserts: current-only >= 1000 steps; all-implicit <= 1/3 of DOPRI5's
// steps; errors within 50 tol (current-only; measured 19 end, 26 dense) or 80 tol (the others,
// measured <= 1.8 end, 40 dense; see the contract's `tolerance_cases`).
#[test]
fn ark436_splits_on_motor_oscillator() {
    for tol in [1e-6, 1e-9] {
        let p = StiffOscillator::default();
        let d = run_exact(
            p,
            &mut DormandPrince45::new(3, StepControl::new(tol, tol)),
            5.0,
        )
        .stats;
        eprintln!(
            "tol {tol:.0e}: DOPRI5 {} steps ({} rejected), {} rhs",
            d.steps, d.rejected, d.rhs_evals
        );
        for split in [
            OscillatorSplit::Current,
            OscillatorSplit::VelocityCurrent,
            OscillatorSplit::Full,
        ] {
            let mut st = ArkImex::new(3, StepControl::new(tol, tol));
            let r = run_exact(StiffOscillator { split, ..p }, &mut st, 5.0);
            let s = r.stats;
            eprintln!(
                "tol {tol:.0e}: ARK {split:?}: {} steps ({} rejected), {} rhs, {} solves, err end {:.2} tol, dense {:.2} tol",
                s.steps, s.rejected, s.rhs_evals, s.implicit_solves, r.err_end / tol, r.err_dense / tol
            );
            let c = if split == OscillatorSplit::Current {
                50.0
            } else {
                80.0
            };
            assert!(r.err_end <= c * tol && r.err_dense <= c * tol, "{split:?}");
            if split == OscillatorSplit::Current {
                assert!(s.steps >= 1000, "{split:?}: {s:?}");
            } else if split == OscillatorSplit::Full {
                assert!(3 * s.steps <= d.steps, "{split:?}: {s:?} vs DOPRI5 {d:?}");
            }
        }
    }
}
