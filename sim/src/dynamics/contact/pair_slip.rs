//! Two contacts starting to slide from rest together: the slip directions `s_1`, `s_2` with each
//! contact's tangential acceleration along its own direction, `a_t,k ∥ s_k` (Pfeiffer & Glocker
//! 1996, §5.2, the acceleration-level problem of the sliding contacts; Glocker, *Set-Valued Force
//! Laws*, 2001, §7: a slide from rest takes the friction `−μ f_n s` along the direction its slip
//! will grow in). With `s_k = (cos θ_k, sin θ_k)` the conditions are the two residuals
//! `r_k(θ_1, θ_2) = a_t,k × s_k = 0`, a 2-D root find; the mode problem (`modes.rs`) first tries
//! the fixed-point iteration `s ← a_t/|a_t|` and, when that does not settle and the combination
//! with its directions is not feasible, this Newton iteration from the impending directions
//! (finite-difference Jacobian, steps of at most 0.1 rad), and judges the combination once more.
//!
//! Why (issue 23 item 6): at a stick → slip onset of two contacts at once (their sticks
//! statically indeterminate together, so the largest-margin force reaches both cones at the same
//! instant: seed 0xe08f20ace809c12a at 0.049179627 s, elbow4 and elbow7) the slides start at the
//! cone, where `|a_t| ≈ 1e-12 m/s²`: the fixed point's direction `a_t/|a_t|` is rounding noise
//! and wandered off the root at the impending directions (where the slides' slip accelerations are
//! `4e-12` and `6e-12 m/s²` along `s`, `f_n` 3.2059 and 2.2064 N, p(s) 4.08 and 3.98 m/(s² N)),
//! and the mode problem reported "no consistent contact forces". The residuals grow by O(1) m/s²
//! per radian away from the root, so Newton finds it to rounding.
//! Events only (no allocation in the step loop; the solves are the mode problem's).

use super::forward::{solve_modes, ContactData, ContactState};
use super::Contact;
use crate::dynamics::forward::{ForwardData, Stabilization};

/// The residuals `a_t,k × s_k` (m/s²) and `|a_t,k|` of contacts `ks` at `trial` with the slip
/// directions at the angles `th`; None when the solve is singular.
fn residuals(contacts: &[Contact], trial: &mut ContactState, ks: [usize; 2], th: [f64; 2], stabilization: Stabilization, fd: &mut ForwardData, cd: &mut ContactData) -> Option<([f64; 2], f64)> {
    for (&k, &t) in ks.iter().zip(&th) {
        trial.slip[k] = [t.cos(), t.sin()];
    }
    solve_modes(contacts, trial, stabilization, fd, cd).ok()?;
    let nv = cd.rows.nv;
    let qdd = &fd.qdd.as_slice()[..nv];
    let mut r = [0.0; 2];
    let mut amax = 0.0f64;
    for (rk, &k) in r.iter_mut().zip(&ks) {
        let a = [cd.rows.dot(3 * k + 1, qdd) + cd.rows.bias[3 * k + 1], cd.rows.dot(3 * k + 2, qdd) + cd.rows.bias[3 * k + 2]];
        let s = trial.slip[k];
        *rk = a[0] * s[1] - a[1] * s[0];
        amax = amax.max(a[0].hypot(a[1]));
    }
    Some((r, amax))
}

/// Newton's iteration for `a_t,k × s_k = 0` (k = the two contacts `ks`, sliding from rest in
/// `trial`) from `trial.slip` (the impending directions): on success `trial.slip` holds the
/// root (residuals ≤ 1e-10 (1 m/s² + max |a_t|)) and true; else `trial.slip` is restored and false.
pub fn newton(contacts: &[Contact], trial: &mut ContactState, ks: [usize; 2], stabilization: Stabilization, fd: &mut ForwardData, cd: &mut ContactData) -> bool {
    let start = [trial.slip[ks[0]], trial.slip[ks[1]]];
    let mut th = [start[0][1].atan2(start[0][0]), start[1][1].atan2(start[1][0])];
    let h = 1e-7;
    for _ in 0..30 {
        let Some((r, amax)) = residuals(contacts, trial, ks, th, stabilization, fd, cd) else { break };
        if r[0].abs().max(r[1].abs()) <= 1e-10 * (1.0 + amax) {
            return true;
        }
        let Some((r1, _)) = residuals(contacts, trial, ks, [th[0] + h, th[1]], stabilization, fd, cd) else { break };
        let Some((r2, _)) = residuals(contacts, trial, ks, [th[0], th[1] + h], stabilization, fd, cd) else { break };
        let j = [[(r1[0] - r[0]) / h, (r2[0] - r[0]) / h], [(r1[1] - r[1]) / h, (r2[1] - r[1]) / h]];
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        if det == 0.0 || det.is_nan() {
            break;
        }
        let d = [(j[1][1] * r[0] - j[0][1] * r[1]) / det, (j[0][0] * r[1] - j[1][0] * r[0]) / det];
        th = [th[0] - d[0].clamp(-0.1, 0.1), th[1] - d[1].clamp(-0.1, 0.1)];
    }
    trial.slip[ks[0]] = start[0];
    trial.slip[ks[1]] = start[1];
    false
}
