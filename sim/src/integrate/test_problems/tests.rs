//! Checks of the test problems themselves: exact solutions against their ODEs, the splits,
//! implicit solves, analytic Jacobians and time derivatives against differences; Kepler's
//! orbit, the failure systems, the oscillator's spectrum.

use super::super::testutil::Problem;
use super::super::{OdeJacobian, SplitSystem};
use super::*;

/// Every problem the way the steppers see it ([`Problem`]), with times inside its domain.
fn problems() -> Vec<(Problem, &'static [f64])> {
    let times: &[f64] = &[0.1, 0.7, 1.3, 2.9, 5.0];
    let mut v = vec![
        (Problem::Decay(ExponentialDecay { k: 0.7, y0: 2.0 }), times),
        (
            Problem::Oscillator(HarmonicOscillator { omega: 2.0 }),
            times,
        ),
        (Problem::Rational(RationalDecay), times),
        (Problem::Kepler(Kepler { e: 0.5 }), times),
        (Problem::Kepler(Kepler { e: 0.9 }), times),
        (
            Problem::Pr(StiffLinear {
                lambda: -1e4,
                y0: 1.0,
            }),
            times,
        ),
        (Problem::Blowup(RiccatiBlowup), &[0.1, 0.5, 0.9]),
        (Problem::StiffKepler(StiffKepler::default()), times),
        (Problem::Failing(FailingRhs { t_fail: 10.0 }), times),
        (
            Problem::Nan(NanAfter {
                t_nan: 10.0,
                index: 1,
            }),
            times,
        ),
    ];
    for split in [
        OscillatorSplit::Current,
        OscillatorSplit::VelocityCurrent,
        OscillatorSplit::Full,
    ] {
        for gain in [1.0, 1e3] {
            v.push((
                Problem::Motor(StiffOscillator {
                    split,
                    gain,
                    ..Default::default()
                }),
                times,
            ));
        }
    }
    v
}

/// Column `j` of `df/dy` by central differences, `(f(t, y + d e_j) - f(t, y - d e_j)) / 2d`
/// with `d = 1e-6 max(1, |y_j|)`, into `col`.
fn central_column(p: &mut Problem, t: f64, y: &[f64], j: usize, col: &mut [f64]) {
    let n = y.len();
    let d = 1e-6 * y[j].abs().max(1.0);
    let (mut yp, mut fp, mut fm) = (y.to_vec(), vec![0.0; n], vec![0.0; n]);
    yp[j] = y[j] + d;
    p.rhs(t, &yp, &mut fp).expect("rhs");
    yp[j] = y[j] - d;
    p.rhs(t, &yp, &mut fm).expect("rhs");
    for i in 0..n {
        col[i] = (fp[i] - fm[i]) / (2.0 * d);
    }
}

// For every problem:
// - the exact solution satisfies the ODE: central difference (h = 1e-5, truncation ~h^2 |y'''|)
//   against rhs within 1e-6 relative to max(1, |f|) (the motor oscillator after its fast
//   transient, e^(-450 t) < 1e-19 at t >= 0.1);
// - at points off the solution (y + 0.01 (i + 1) at t = 0.05, 0.7, 2.3, so the stiff terms
//   do not vanish): the split parts add up to rhs (1e-15 relative); solve_implicit solves
//   z - gamma f_I(t, z) = r (residual <= 1e-14 times the size of the terms that cancel,
//   1 + |r| + gamma sum_j |J_ij z_j| + gamma |f|; the oscillator's coefficients reach 7.6e7);
//   and where the problem has them (analytic) f_t matches a central difference in t (1e-6
//   relative to max(1, |f_t|)) and J central differences in y (1e-8 relative to
//   1 + max_j |J_ij|; measured <= 7e-11).
#[test]
fn problems_are_consistent() {
    for (mut p, times) in problems() {
        let n = p.dim();
        let v = |len| vec![0.0; len];
        let (mut yp, mut ym, mut y, mut f) = (v(n), v(n), v(n), v(n));
        for &t in times {
            let h = 1e-5;
            p.exact(t + h, &mut yp);
            p.exact(t - h, &mut ym);
            p.exact(t, &mut y);
            p.rhs(t, &y, &mut f).expect("rhs");
            for i in 0..n {
                let fd = (yp[i] - ym[i]) / (2.0 * h);
                let ok = (fd - f[i]).abs() <= 1e-6 * f[i].abs().max(1.0);
                assert!(ok, "{p:?} [{i}] at t = {t}: {fd} vs {}", f[i]);
            }
        }
        let (mut fe, mut fi, mut z, mut fz_e, mut fz_i) = (v(n), v(n), v(n), v(n), v(n));
        let (mut ft, mut fp, mut fm, mut jac, mut col) = (v(n), v(n), v(n), v(n * n), v(n));
        for t in [0.05, 0.7, 2.3] {
            p.exact(t, &mut y);
            for (i, v) in y.iter_mut().enumerate() {
                *v += 0.01 * (i as f64 + 1.0);
            }
            p.rhs(t, &y, &mut f).expect("rhs");
            p.rhs_split(t, &y, &mut fe, &mut fi).expect("rhs_split");
            for i in 0..n {
                let ok = (fe[i] + fi[i] - f[i]).abs() <= 1e-15 * f[i].abs().max(1.0);
                assert!(ok, "{p:?} split sum {i}");
            }
            for gamma in [1e-6, 1e-3, 0.1] {
                p.solve_implicit(t, gamma, &y, &mut z).expect("solve");
                p.rhs_split(t, &z, &mut fz_e, &mut fz_i).expect("rhs_split");
                p.jacobian(t, &z, &f, &mut jac).expect("jacobian");
                for i in 0..n {
                    let res = z[i] - gamma * fz_i[i] - y[i];
                    let scale = y[i].abs()
                        + gamma * (0..n).map(|j| (jac[i * n + j] * z[j]).abs()).sum::<f64>()
                        + gamma * f[i].abs()
                        + 1.0;
                    let ok = res.abs() <= 1e-14 * scale;
                    assert!(
                        ok,
                        "{p:?} t {t} gamma {gamma} [{i}]: {res} (scale {scale:e})"
                    );
                }
            }
            if !p.time_derivative(t, &y, &f, &mut ft).expect("f_t") {
                continue; // finite-difference Jacobian and f_t
            }
            let dt = 1e-5;
            p.rhs(t + dt, &y, &mut fp).expect("rhs");
            p.rhs(t - dt, &y, &mut fm).expect("rhs");
            for i in 0..n {
                let fd = (fp[i] - fm[i]) / (2.0 * dt);
                let ok = (fd - ft[i]).abs() <= 1e-6 * ft[i].abs().max(1.0);
                assert!(ok, "{p:?} f_t[{i}]: {fd} vs {}", ft[i]);
            }
            p.jacobian(t, &y, &f, &mut jac).expect("jacobian");
            for j in 0..n {
                central_column(&mut p, t, &y, j, &mut col);
                for i in 0..n {
                    let row = &jac[i * n..(i + 1) * n];
                    let e = (col[i] - row[j]).abs()
                        / (1.0 + row.iter().fold(0.0f64, |m, v| m.max(v.abs())));
                    assert!(
                        e <= 1e-8,
                        "{p:?} t {t} J[{i}][{j}]: {} vs {} ({e:e})",
                        col[i],
                        row[j]
                    );
                }
            }
        }
    }
}

#[test]
fn kepler_starts_at_pericentre_and_is_periodic() {
    let p = Kepler { e: 0.6 };
    let y0 = p.y0();
    assert!((y0[0] - 0.4).abs() < 1e-15 && y0[1].abs() < 1e-15 && y0[2].abs() < 1e-15);
    assert!((y0[3] - (1.6f64 / 0.4).sqrt()).abs() < 1e-14);
    let mut y = [0.0; 4];
    p.exact(3.0 * std::f64::consts::TAU, &mut y);
    for i in 0..4 {
        assert!(
            (y[i] - y0[i]).abs() < 1e-12,
            "component {i}: {} vs {}",
            y[i],
            y0[i]
        );
    }
}

#[test]
fn failure_systems_fail_where_documented() {
    let mut f = [0.0];
    assert!(FailingRhs { t_fail: 0.5 }.rhs(0.49, &[1.0], &mut f).is_ok());
    assert_eq!(
        FailingRhs { t_fail: 0.5 }.rhs(0.5, &[1.0], &mut f),
        Err(RhsFailure { t: 0.5 })
    );
    let mut f2 = [0.0; 2];
    let _ = NanAfter {
        t_nan: 0.5,
        index: 1,
    }
    .rhs(0.49, &[1.0, 1.0], &mut f2);
    assert!(f2.iter().all(|v| v.is_finite()));
    let _ = NanAfter {
        t_nan: 0.5,
        index: 1,
    }
    .rhs(0.5, &[1.0, 1.0], &mut f2);
    assert!(f2[0].is_finite() && f2[1].is_nan());
}

// The oscillator's eigenvalues are the documented ones: the characteristic polynomial
// s^3 + rho s^2 + c s + p vanishes at -sigma + i beta and -mu (relative to the size of its
// terms, <= 1e-14), and the exact solution starts at phi(0) + dy0.
#[test]
fn stiff_oscillator_has_the_stated_spectrum_and_start() {
    let o = StiffOscillator::default();
    let (p, c, rho) = o.coefficients();
    // complex arithmetic by hand: s = -sigma + i beta
    let (a, b) = (-o.sigma, o.beta);
    let (s2r, s2i) = (a * a - b * b, 2.0 * a * b);
    let (s3r, s3i) = (s2r * a - s2i * b, s2r * b + s2i * a);
    let re = s3r + rho * s2r + c * a + p;
    let im = s3i + rho * s2i + c * b;
    let scale = s3r.abs() + s3i.abs();
    assert!(re.abs().max(im.abs()) <= 1e-14 * scale, "{re} {im}");
    let m = -o.mu;
    let r = m * m * m + rho * m * m + c * m + p;
    assert!(r.abs() <= 1e-14 * p, "{r}");
    let y0 = o.y0();
    let w = o.omega;
    assert!((y0[0] - o.dy0[0]).abs() < 1e-15);
    assert!((y0[1] - (w + o.dy0[1])).abs() < 1e-12);
    assert!((y0[2] - o.dy0[2]).abs() < 1e-12);
}
