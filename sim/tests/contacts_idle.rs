//! Candidate contacts that never touch cost nothing (issue 24, items 1 and 2): the paper arm
//! over a table under the whole arm (`whole-table`: 9 candidate contacts, of which the two
//! elbows touch) is integrated with exactly the steps of the same arm with the two elbows alone
//! (`two-elbow-unilateral`), in `sim/scenes/paper_unilateral.json`.
//!
//! What makes it exact: a separated contact adds no force (its rows are not in the contact
//! problem) and its three quadratures (impact loss, friction work, damping loss) stay constant
//! until the next event; they feed nothing back, and the step-size control leaves a separated
//! contact's quadratures out of its error norm (`OdeSystem::error_measured`, `ode/arm.rs`;
//! SUNDIALS CVODES leaves quadratures out of its error test by default, `errconQ`). Measured in the norm, the seven idle contacts'
//! 21 zeros only raised the RMS's divisor (whole-table's 80 components against two-elbow's
//! 59), loosening whole-table's effective tolerance by √(80/59) = 1.16: over these 0.3 s, 865 steps /
//! 67 rejected against 893 / 74 (and 5756 / 120 against 5799 / 122 over the 5-s runs).

use std::path::Path;

use crate::contacts_support::*;
use sim::scene::Scene;

/// Over the first 0.3 s (the touch-downs, both elbows' impacts and elbow7's stick → slip
/// onset at 0.2446 s, the part where the step sizes vary most): the same steps, rejections and
/// right-hand sides, and the same hand at every sample (0 m apart; allowed 1e-15 m, rounding,
/// though none is expected since every operation on the state is the same).
#[test]
fn idle_candidate_contacts_do_not_change_the_steps() {
    let s = Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/paper_unilateral.json")).expect("the paper scene loads");
    let s = s.vary(|spec| spec.duration = 0.3).expect("the varied scene is valid");
    let two = collect(&s, "two-elbow-unilateral");
    let whole = collect(&s, "whole-table");
    let (a, b) = (&two.report.stats, &whole.report.stats);
    eprintln!("two-elbow-unilateral {} steps / {} rejected / {} rhs; whole-table {} / {} / {}", a.steps, a.rejected, a.rhs_evals, b.steps, b.rejected, b.rhs_evals);
    assert_eq!((b.steps, b.rejected, b.rhs_evals), (a.steps, a.rejected, a.rhs_evals), "whole-table's steps / rejected / right-hand sides against two-elbow-unilateral's");
    assert_eq!(two.samples.len(), whole.samples.len(), "same output grid");
    for (x, y) in two.samples.iter().zip(&whole.samples) {
        let d = (x.hand - y.hand).norm();
        assert!(d <= 1e-15, "hand {d:e} m apart at t = {} s", x.t);
    }
    // the idle candidates never touched
    let touched: std::collections::BTreeSet<usize> = whole.events.iter().map(|e| e.contact).collect();
    assert_eq!(touched.len(), 2, "events of contacts {touched:?}: only the two elbows touch");
}

/// The same at the loose tolerances, where the integrator's resolution of a slip and of a gap
/// rate (`ode/hybrid.rs::slip_resolution`, `gap_resolution`: `sqrt(n)` times the weighted
/// rows) decides an onset's blend speed, a slip's stop speed and a rebound's depth: there `n`
/// is the count of components the error norm measures (`measured_len`), not the state's
/// length, so the idle candidates' quadratures move no decision. With the state's length
/// whole-table's bound was √(80/59) two-elbow's and the runs parted (0.3 s: dopri45 rtol 1e-3
/// 340 steps against 377, rosenbrock 1e-5 2 240 against 2 124, imex 1e-4 1 088 against 1 035).
#[test]
fn idle_candidate_contacts_do_not_change_the_steps_at_loose_tolerances() {
    use sim::scene::spec::IntegratorSpec;
    let s = Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/paper_unilateral.json")).expect("the paper scene loads");
    for (method, rtol) in [("dopri45", 1e-3), ("dopri45", 1e-4), ("rosenbrock", 1e-5), ("imex", 1e-4)] {
        let s = s
            .vary(|spec| {
                spec.duration = 0.3;
                spec.integrator = IntegratorSpec::adaptive(method, rtol, None).expect("a known method");
            })
            .expect("the varied scene is valid");
        let two = collect(&s, "two-elbow-unilateral");
        let whole = collect(&s, "whole-table");
        let (a, b) = (&two.report.stats, &whole.report.stats);
        assert_eq!((b.steps, b.rejected, b.rhs_evals), (a.steps, a.rejected, a.rhs_evals), "{method} rtol {rtol:e}: whole-table's steps / rejected / right-hand sides against two-elbow-unilateral's");
        for (x, y) in two.samples.iter().zip(&whole.samples) {
            let d = (x.hand - y.hand).norm();
            assert!(d <= 1e-15, "{method} rtol {rtol:e}: hand {d:e} m apart at t = {} s", x.t);
        }
    }
}
