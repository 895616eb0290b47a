use super::super::SplitSystem;
use super::*;

/// Central difference of the exact solution against `rhs`: catches typos in either.
/// Tolerance: 1e-6 relative to max(1, |f|) with h = 1e-5 (truncation ~h^2 |y'''|).
fn check_exact_matches_rhs<P: ExactSolution>(mut p: P, times: &[f64]) {
    let n = p.dim();
    let (mut yp, mut ym, mut y, mut f) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let h = 1e-5;
    for &t in times {
        p.exact(t + h, &mut yp);
        p.exact(t - h, &mut ym);
        p.exact(t, &mut y);
        if p.rhs(t, &y, &mut f).is_err() {
            panic!("rhs failed at t = {t}");
        }
        for i in 0..n {
            let fd = (yp[i] - ym[i]) / (2.0 * h);
            assert!(
                (fd - f[i]).abs() <= 1e-6 * f[i].abs().max(1.0),
                "component {i} at t = {t}: finite difference {fd} vs rhs {}",
                f[i]
            );
        }
    }
}

#[test]
fn exact_solutions_satisfy_their_odes() {
    let times = [0.1, 0.7, 1.3, 2.9, 5.0];
    check_exact_matches_rhs(ExponentialDecay { k: 0.7, y0: 2.0 }, &times);
    check_exact_matches_rhs(HarmonicOscillator { omega: 2.0 }, &times);
    check_exact_matches_rhs(RationalDecay, &times);
    check_exact_matches_rhs(Kepler { e: 0.5 }, &times);
    check_exact_matches_rhs(Kepler { e: 0.9 }, &times);
    check_exact_matches_rhs(
        StiffLinear {
            lambda: -1e4,
            y0: 1.0,
        },
        &times,
    );
    check_exact_matches_rhs(RiccatiBlowup, &[0.1, 0.5, 0.9]);
    // after the fast transient (e^(-450 t) < 1e-19 at t >= 0.1): y''' is O(1), as above
    check_exact_matches_rhs(StiffOscillator::default(), &times);
    check_exact_matches_rhs(
        StiffOscillator {
            gain: 1e3,
            ..Default::default()
        },
        &times,
    );
    check_exact_matches_rhs(StiffKepler::default(), &times);
    check_exact_matches_rhs(FailingRhs { t_fail: 10.0 }, &times);
    check_exact_matches_rhs(
        NanAfter {
            t_nan: 10.0,
            index: 1,
        },
        &times,
    );
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

/// At a few points: the split parts add up to `rhs` (to 1e-15 relative), `solve_implicit`
/// solves `z - gamma f_I(t, z) = r` (residual <= 1e-14 times the size of the terms that
/// cancel, `1 + |r| + gamma sum_j |J_ij z_j| + gamma |f|`; the oscillator's coefficients reach
/// 7.6e7), the analytic `∂f/∂t` matches a central difference in `t` (1e-6 relative to
/// max(1, |f_t|)).
fn check_split_and_time_derivative<P: SplitSystem + OdeJacobian + ExactSolution>(mut p: P) {
    let n = p.dim();
    let (mut y, mut f, mut fe, mut fi) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let (mut z, mut fz_e, mut fz_i, mut ft) =
        (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
    for &t in &[0.05, 0.7, 2.3] {
        p.exact(t, &mut y);
        // a point off the solution, so the stiff terms do not vanish
        for (i, v) in y.iter_mut().enumerate() {
            *v += 0.01 * (i as f64 + 1.0);
        }
        let _ = p.rhs(t, &y, &mut f);
        let _ = p.rhs_split(t, &y, &mut fe, &mut fi);
        for i in 0..n {
            assert!(
                (fe[i] + fi[i] - f[i]).abs() <= 1e-15 * f[i].abs().max(1.0),
                "split sum {i}"
            );
        }
        let mut jac = vec![0.0; n * n];
        for gamma in [1e-6, 1e-3, 0.1] {
            let _ = p.solve_implicit(t, gamma, &y, &mut z);
            let _ = p.rhs_split(t, &z, &mut fz_e, &mut fz_i);
            let _ = p.jacobian(t, &z, &f, &mut jac);
            for i in 0..n {
                let res = z[i] - gamma * fz_i[i] - y[i];
                // size of the terms that cancel: |r| + gamma sum_j |J_ij z_j| + gamma |f_i|
                let scale = y[i].abs()
                    + gamma * (0..n).map(|j| (jac[i * n + j] * z[j]).abs()).sum::<f64>()
                    + gamma * f[i].abs()
                    + 1.0;
                assert!(
                    res.abs() <= 1e-14 * scale,
                    "t {t} gamma {gamma} [{i}]: {res} (scale {scale:e})"
                );
            }
        }
        assert!(matches!(p.time_derivative(t, &y, &f, &mut ft), Ok(true)));
        let dt = 1e-5;
        let _ = p.rhs(t + dt, &y, &mut fp);
        let _ = p.rhs(t - dt, &y, &mut fm);
        for i in 0..n {
            let fd = (fp[i] - fm[i]) / (2.0 * dt);
            assert!(
                (fd - ft[i]).abs() <= 1e-6 * ft[i].abs().max(1.0),
                "f_t[{i}]: {fd} vs {}",
                ft[i]
            );
        }
    }
}

#[test]
fn splits_solves_and_time_derivatives_are_consistent() {
    check_split_and_time_derivative(StiffLinear::default());
    for split in [
        OscillatorSplit::Current,
        OscillatorSplit::VelocityCurrent,
        OscillatorSplit::Full,
    ] {
        for gain in [1.0, 1e3] {
            check_split_and_time_derivative(StiffOscillator {
                split,
                gain,
                ..Default::default()
            });
        }
    }
    check_split_and_time_derivative(StiffKepler::default());
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
