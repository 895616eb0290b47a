//! The exact current columns of the arm's Jacobian (`ode/current_columns.rs`), which RODAS
//! uses instead of difference columns (issue 24, point 1), against central differences of full
//! right-hand sides, and so is the exact `∂f/∂t` (`ode/time_derivative.rs`): at random states of the paper's unilateral runs in every contact mode
//! (separated, sticking, sliding) and of the paper's bilateral runs (constrained and free).
//! f is affine in the currents for fixed q, q̇ and modes (quadratic in the copper loss), so
//! the central difference has no truncation error and its rounding error is ~`noise |f| / δ`
//! (noise ~2e-14 relative, `ode/jacobian.rs`; δ = 1e-3 A): the bound below, 1e-9 of the
//! largest entry of the row's block (q̈, di/dt, each quadrature), leaves a margin over the
//! largest error measured (printed).

#![allow(clippy::result_large_err)]

use sim::dynamics::contact::ContactMode;
use sim::integrate::{fd_jacobian_columns, HybridSystem as _, OdeJacobian as _, OdeSystem};
use sim::ode::ArmSystem;
use sim::scene::Scene;

use crate::rng_support::Lcg;

/// The columns of the currents by central differences of `rhs`, δ = 1e-3 A.
pub(crate) fn central_current_columns(sys: &mut ArmSystem, t: f64, y: &[f64]) -> Vec<f64> {
    let n = y.len();
    let l = sys.layout();
    let mut jac = vec![0.0; n * n];
    let (mut yp, mut fp, mut fm) = (y.to_vec(), vec![0.0; n], vec![0.0; n]);
    for c in l.current() {
        let delta = 1e-3;
        yp[c] = y[c] + delta;
        let d_plus = yp[c] - y[c];
        sys.rhs(t, &yp, &mut fp).unwrap();
        yp[c] = y[c] - delta;
        let d_minus = y[c] - yp[c];
        sys.rhs(t, &yp, &mut fm).unwrap();
        yp[c] = y[c];
        for i in 0..n {
            jac[i * n + c] = (fp[i] - fm[i]) / (d_plus + d_minus);
        }
    }
    jac
}

/// The blocks of rows whose entries share a scale: q̇, q̈, di/dt, then each quadrature alone.
pub(crate) fn row_block(sys: &ArmSystem, r: usize) -> std::ops::Range<usize> {
    let l = sys.layout();
    for b in [l.q(), l.qd(), l.current()] {
        if b.contains(&r) {
            return b;
        }
    }
    r..r + 1
}

/// Checks the exact columns against the central ones at `(t, y)`; returns the largest error
/// relative to the row block's largest entry, or `None` where the system gave no exact
/// columns.
pub(crate) fn check(sys: &mut ArmSystem, t: f64, y: &[f64], what: &str) -> Option<f64> {
    let n = y.len();
    let l = sys.layout();
    let mut f = vec![0.0; n];
    sys.rhs(t, y, &mut f).unwrap();
    let k = sys.exact_columns_start();
    assert_eq!(k, l.current().start, "{what}: the exact columns are the currents'");
    // as RODAS calls it: the difference sweep over the q and q̇ columns, then the exact ones
    let mut jac = vec![f64::NAN; n * n];
    let (mut sy, mut sf) = (vec![0.0; n], vec![0.0; n]);
    fd_jacobian_columns(sys, t, y, &f, &mut jac, k, 1e-2, &mut sy, &mut sf).unwrap();
    if !sys.exact_columns(t, y, &f, &mut jac).unwrap() {
        return None;
    }
    let central = central_current_columns(sys, t, y);
    let mut worst = 0.0f64;
    for r in 0..n {
        let block = row_block(sys, r);
        let scale = block.clone().flat_map(|i| l.current().map(move |c| (i, c))).map(|(i, c)| central[i * n + c].abs()).fold(0.0, f64::max);
        for c in l.current() {
            let (a, b) = (jac[r * n + c], central[r * n + c]);
            assert!(a.is_finite(), "{what}: d f[{r}] / d y[{c}] = {a}");
            let err = (a - b).abs() / scale.max(1e-300);
            if scale == 0.0 {
                assert_eq!(a, 0.0, "{what}: d f[{r}] / d y[{c}] = {a:e}, central 0");
                continue;
            }
            assert!(err <= 1e-9, "{what} (modes {:?}): d f[{r}] / d y[{c}]: exact {a:e}, central {b:e}, error {err:.1e} of the block's {scale:.2e}", sys.contact_modes());
            worst = worst.max(err);
        }
    }
    Some(worst)
}

/// Checks the exact `∂f/∂t` against central differences in t (δ = 1e-5 s: truncation
/// `δ² |f'''| / 6` and rounding `eps |f| / δ` both below 1e-10 of the block's largest entry
/// here); returns the largest error relative to the row block's largest entry.
pub(crate) fn check_time_derivative(sys: &mut ArmSystem, t: f64, y: &[f64], what: &str) -> f64 {
    let n = y.len();
    let mut f = vec![0.0; n];
    sys.rhs(t, y, &mut f).unwrap();
    let mut exact = vec![f64::NAN; n];
    assert!(sys.exact_time_derivative(t, y, &f, &mut exact).unwrap(), "{what}: no exact f_t");
    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
    let delta = 1e-5;
    sys.rhs(t + delta, y, &mut fp).unwrap();
    sys.rhs(t - delta, y, &mut fm).unwrap();
    let central: Vec<f64> = (0..n).map(|i| (fp[i] - fm[i]) / ((t + delta) - (t - delta))).collect();
    let mut worst = 0.0f64;
    for r in 0..n {
        let scale = row_block(sys, r).map(|i| central[i].abs()).fold(0.0, f64::max);
        if scale == 0.0 {
            assert_eq!(exact[r], 0.0, "{what}: d f[{r}] / dt = {:e}, central 0", exact[r]);
            continue;
        }
        let err = (exact[r] - central[r]).abs() / scale;
        assert!(err <= 1e-7, "{what}: d f[{r}] / dt: exact {:e}, central {:e}, error {err:.1e} of the block's {scale:.2e}", exact[r], central[r]);
        worst = worst.max(err);
    }
    worst
}

/// The exact current columns equal the central differences to 1e-9 of each row block's
/// largest entry at 24 states per run of the paper's unilateral runs (every other one with the
/// joint speeds moved at random, so that contacts slide and leave) and 8 per bilateral run;
/// they are given (not left to differences) at all but a few states, and those states reach
/// every contact mode. The exact `∂f/∂t` equals the central differences in t to 1e-7 of each
/// row block's largest entry at the same states.
#[test]
fn the_exact_current_columns_are_the_central_differences_in_every_mode() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/");
    let unilateral = Scene::load(std::path::Path::new(&format!("{dir}paper_unilateral.json"))).unwrap();
    let bilateral = Scene::load(std::path::Path::new(&format!("{dir}paper.json"))).unwrap();
    let mut rng = Lcg(2024);
    let (mut seen, mut exact, mut skipped, mut inconsistent, mut worst, mut worst_t) = ([false; 3], 0, 0, 0, 0.0f64, 0.0f64);
    for (scene, per_run, what) in [(&unilateral, 24, "paper-unilateral"), (&bilateral, 8, "paper")] {
        let short = scene.vary(|s| s.duration = 0.3).unwrap();
        for run in scene.runs() {
            let mut samples = Vec::new();
            sim::run::simulate(&short, short.run(&run.name).unwrap(), |o| {
                if samples.len() < per_run && o.t >= 0.3 / per_run as f64 * (samples.len() + 1) as f64 - 1e-9 {
                    samples.push((o.t, o.q.clone(), o.qd.clone(), o.current.clone()));
                }
                Ok(())
            })
            .unwrap();
            assert_eq!(samples.len(), per_run);
            for (k, (t, q, qd, current)) in samples.into_iter().enumerate() {
                let mut sys = ArmSystem::new(scene, run);
                let l = sys.layout();
                let mut y = sys.initial_state();
                y[l.q()].copy_from_slice(&q);
                y[l.qd()].copy_from_slice(&qd);
                y[l.current()].copy_from_slice(&current);
                if k % 2 == 1 {
                    for j in 0..l.nv {
                        y[l.qd().start + j] += 0.3 * rng.next();
                        y[l.current().start + j] += 2.0 * rng.next();
                    }
                }
                if sys.is_hybrid() && sys.init_modes(t, &mut y).is_err() {
                    // no consistent contact forces at this draw (Painlevé); another draw
                    inconsistent += 1;
                    continue;
                }
                let label = format!("{what} {} state {k} (t = {t})", run.name);
                worst_t = worst_t.max(check_time_derivative(&mut sys, t, &y, &label));
                match check(&mut sys, t, &y, &label) {
                    Some(e) => {
                        exact += 1;
                        worst = worst.max(e);
                        for m in sys.contact_modes() {
                            match m {
                                ContactMode::Separated => seen[0] = true,
                                ContactMode::Sticking => seen[1] = true,
                                ContactMode::Sliding => seen[2] = true,
                                ContactMode::Bilateral => {}
                            }
                        }
                    }
                    None => skipped += 1,
                }
            }
        }
    }
    eprintln!("{exact} states with exact current columns (largest error {worst:.1e} of the row block), {skipped} left to differences, {inconsistent} draws without consistent forces; exact f_t: largest error {worst_t:.1e}");
    assert!(exact >= 80 && skipped <= 4, "{exact} exact, {skipped} left to differences");
    assert_eq!(seen, [true; 3], "modes reached with exact columns (separated, sticking, sliding)");
}
