//! The mode problem at t0 and at every event: which closed rigid contacts separate, stick or
//! slide, so that the contact forces and accelerations are consistent (the acceleration-level
//! complementarity of Pfeiffer & Glocker 1996, §5.2, and of Acary & Brogliato 2008, §5.4), by
//! EXACT ENUMERATION of the candidate modes of the closed contacts (3^n solves for n ≤
//! [`MAX_CLOSED_CONTACTS`]; at events only, so the allocations here are at events).
//!
//! Candidates per closed contact: separated; sticking (μ > 0 and `|v_t| ≤ vel_tol`); sliding
//! (along `v_t/|v_t|` when `|v_t| > vel_tol`; from rest along the direction s with `a_t ∥ s`,
//! found by the fixed-point iteration `s ← a_t/|a_t|` started from the impending direction
//! `−f_t/|f_t|` of the same combination with the contact sticking — one contact: a scan of its
//! angle; two, when the fixed point does not settle and its combination fails: once more with
//! Newton's root of both angles, `pair_slip.rs`; frictionless: the normal
//! row alone). Feasibility, with tolerances relative to the solution's scale
//! (`tol_f = 1e-8 (1 N + max |f|)`, `tol_a = 1e-8 (1 + max |q̈|)`): separated → `g̈ ≥ −tol_a`;
//! sticking → `f_n ≥ −tol_f`, `|f_t| ≤ μ f_n + tol_f`; sliding → `f_n ≥ −tol_f` and from rest
//! `a_t · s ≥ −max(tol_a, tol_f sᵀ G s)` (G the contact's tangential Delassus block: "at the
//! cone" is the same force tolerance for the stick and for the slide from rest, so at a
//! stick → slip onset, where both are at the cone, the two agree; with `tol_a` alone a slide
//! whose acceleration read −1.3e-7 m/s² — 2.6e-6 N of force, the rounding of the stick's
//! margin — was refused while the stick at margin −4e-14 N was taken, and the stick broke
//! again at the restart: one-elbow-unilateral at rtol 1e-5, 0.7161 s, 33 events). A slide from
//! rest is an onset (`ContactState::onset`): its friction follows the impending direction
//! while slower than `SLIP_DIRECTION_SPEED` (`forward::onset_anchors`). No feasible combination: Painlevé inconsistency (error). Feasible
//! combinations with different q̈ (beyond `1e-6 (1 + max |q̈|)`): indeterminate (error). Among
//! those with the same q̈ (f_n = 0 with g̈ = 0, or |f_t| = μ f_n), the rule: the one whose modes
//! agree with the `preferred` ones (the event's implication: lift-off → separated, touch-down →
//! closed, stick→slip → sliding, slip→stick → sticking; else the current mode) at the most
//! contacts, then the first in the order sticking, sliding, separated.

use super::forward::{solve_modes, ContactData, ContactState};
use super::{Contact, ContactMode, MAX_CLOSED_CONTACTS};
use crate::dynamics::forward::{ForwardData, Stabilization};
use crate::error::DynamicsError;
use crate::integrate::{Phase, Watch};


#[derive(Clone, Copy, Debug, PartialEq)]
enum Cand {
    Stick,
    /// Sliding; `moving` when |v_t| > vel_tol (direction v_t/|v_t|), else from rest.
    Slide { moving: bool },
    Sep,
}

struct Feasible {
    mode: Vec<ContactMode>,
    slip: Vec<[f64; 2]>,
    onset: Vec<Option<[f64; 2]>>,
    qdd: Vec<f64>,
    score: usize,
    /// At a boundary of its modes within the tolerances (a stick with its margin at 0, a
    /// slide from rest not accelerating, a separation not accelerating away, a closed contact
    /// with no force): the limit of the neighbouring combination, not a second solution.
    marginal: bool,
}

/// Choose the modes of the `closed` contacts (indices) after [`super::forward::prepare`] at the
/// state; the other contacts keep theirs. On return `state` holds the choice and `fd`, `cd` its
/// solution.
#[allow(clippy::too_many_arguments)]
pub fn choose_modes(
    contacts: &[Contact],
    state: &mut ContactState,
    closed: &[usize],
    preferred: &[ContactMode],
    vel_tol: f64,
    stabilization: Stabilization,
    fd: &mut ForwardData,
    cd: &mut ContactData,
    t: f64,
) -> Result<(), DynamicsError> {
    choose_modes_within(contacts, state, closed, preferred, vel_tol, stabilization, fd, cd, t, Watch::default())
}

/// [`choose_modes`] that reads `watch`'s clock before every combination after the first (each
/// costs one or more constrained solves, up to 3^8 of them): past the deadline,
/// [`DynamicsError::OutOfTime`] with how many were tried, `state` unchanged.
#[allow(clippy::too_many_arguments)]
pub fn choose_modes_within(
    contacts: &[Contact],
    state: &mut ContactState,
    closed: &[usize],
    preferred: &[ContactMode],
    vel_tol: f64,
    stabilization: Stabilization,
    fd: &mut ForwardData,
    cd: &mut ContactData,
    t: f64,
    watch: Watch,
) -> Result<(), DynamicsError> {
    let names = || closed.iter().map(|&k| contacts[k].name()).collect::<Vec<_>>().join(", ");
    if closed.len() > MAX_CLOSED_CONTACTS {
        return Err(DynamicsError::InconsistentContact {
            t,
            contact: names(),
            why: format!("more than {MAX_CLOSED_CONTACTS} simultaneous rigid contacts ({}): the exact mode enumeration is limited to 3^{MAX_CLOSED_CONTACTS}; use compliant contacts", closed.len()),
        });
    }
    let nv = cd.rows.nv;
    let cands: Vec<Vec<Cand>> = closed
        .iter()
        .map(|&k| {
            let v = cd.rows.slip(k);
            let moving = v[0].hypot(v[1]) > vel_tol;
            if contacts[k].unilateral_friction() == 0.0 || moving {
                vec![Cand::Slide { moving }, Cand::Sep]
            } else {
                vec![Cand::Stick, Cand::Slide { moving: false }, Cand::Sep]
            }
        })
        .collect();
    let mut idx = vec![0usize; closed.len()];
    let mut feasible: Vec<Feasible> = Vec::new();
    let mut trial = state.clone();
    let mut impending = state.slip.clone();
    let combinations: usize = cands.iter().map(Vec::len).product();
    let mut tried = 0usize;
    // coincident contacts move as one point: they take the same mode (`dependent.rs`)
    let twins = super::dependent::twins(contacts, &cd.rows, closed);
    loop {
        if super::dependent::twins_differ(&twins, &cands, &idx) {
            if !super::dependent::next_combination(&mut idx, &cands) {
                break;
            }
            continue;
        }
        if tried > 0 && watch.out_of_time() {
            return Err(DynamicsError::OutOfTime { t, during: Phase::ChoosingModes { tried, of: combinations } });
        }
        tried += 1;
        // the combination idx
        let mut from_rest = false;
        for (i, &k) in closed.iter().enumerate() {
            trial.onset[k] = None;
            trial.mode[k] = match cands[i][idx[i]] {
                Cand::Stick => ContactMode::Sticking,
                Cand::Slide { moving } => {
                    let v = cd.rows.slip(k);
                    if moving {
                        let s = v[0].hypot(v[1]);
                        trial.slip[k] = [v[0] / s, v[1] / s];
                    } else if contacts[k].unilateral_friction() > 0.0 {
                        from_rest = true;
                    }
                    ContactMode::Sliding
                }
                Cand::Sep => ContactMode::Separated,
            };
        }
        let mut ok = true;
        let mut pair_root: Option<[[f64; 2]; 2]> = None;
        if from_rest {
            // the impending slip directions: the same combination with those contacts sticking
            let mut stick = trial.clone();
            for (i, &k) in closed.iter().enumerate() {
                if cands[i][idx[i]] == (Cand::Slide { moving: false }) && contacts[k].unilateral_friction() > 0.0 {
                    stick.mode[k] = ContactMode::Sticking;
                }
            }
            ok = solve_modes(contacts, &stick, stabilization, fd, cd).is_ok();
            if ok {
                for (i, &k) in closed.iter().enumerate() {
                    if cands[i][idx[i]] == (Cand::Slide { moving: false }) && contacts[k].unilateral_friction() > 0.0 {
                        let f = cd.f_t[k];
                        let m = f[0].hypot(f[1]);
                        // no impending slip: sliding from rest is the sticking solution (not a separate candidate)
                        if !(m > 1e-12 * (1.0 + cd.f_n[k].abs())) {
                            ok = false;
                        } else {
                            trial.slip[k] = [-f[0] / m, -f[1] / m];
                            impending[k] = trial.slip[k];
                        }
                    }
                }
            }
        }
        let rest_sliders: Vec<usize> = closed
            .iter()
            .enumerate()
            .filter(|&(i, &k)| cands[i][idx[i]] == (Cand::Slide { moving: false }) && contacts[k].unilateral_friction() > 0.0 && twins[i].is_none())
            .map(|(_, &k)| k)
            .collect();
        if ok && rest_sliders.len() == 1 {
            // one contact starting to slide: the directions s(φ) = (cos φ, sin φ) with a_t ∥ s
            // and a_t · s > 0 are the roots of cross(a_t(φ), s(φ)); scanned at 5° and refined by
            // bisection to 1e-13 rad; the root nearest the impending direction is taken
            let k = rest_sliders[0];
            let s0 = trial.slip[k];
            let eval = |phi: f64, trial: &mut ContactState, fd: &mut ForwardData, cd: &mut ContactData| -> Option<(f64, f64)> {
                trial.slip[k] = [phi.cos(), phi.sin()];
                super::dependent::copy_to_twins(&twins, closed, &mut trial.slip);
                solve_modes(contacts, trial, stabilization, fd, cd).ok()?;
                let qdd = &fd.qdd.as_slice()[..nv];
                let a = [cd.rows.dot(3 * k + 1, qdd) + cd.rows.bias[3 * k + 1], cd.rows.dot(3 * k + 2, qdd) + cd.rows.bias[3 * k + 2]];
                let sv = trial.slip[k];
                Some((a[0] * sv[1] - a[1] * sv[0], a[0] * sv[0] + a[1] * sv[1]))
            };
            let n = 72;
            let mut best: Option<(f64, f64)> = None;
            let step = std::f64::consts::TAU / n as f64;
            let mut prev = eval(0.0, &mut trial, fd, cd);
            for i in 1..=n {
                let phi = i as f64 * step;
                let cur = eval(phi, &mut trial, fd, cd);
                if let (Some((c0, _)), Some((c1, _))) = (prev, cur) {
                    let root = if c0 == 0.0 {
                        Some(phi - step)
                    } else if c0 * c1 < 0.0 {
                        let (mut lo, mut hi) = (phi - step, phi);
                        while hi - lo > 1e-13 {
                            let mid = 0.5 * (lo + hi);
                            match eval(mid, &mut trial, fd, cd) {
                                Some((cm, _)) if cm * c0 > 0.0 => lo = mid,
                                Some(_) => hi = mid,
                                None => break,
                            }
                        }
                        Some(0.5 * (lo + hi))
                    } else {
                        None
                    };
                    if let Some(root) = root {
                        if let Some((_, dot)) = eval(root, &mut trial, fd, cd) {
                            if dot >= 0.0 {
                                let closeness = root.cos() * s0[0] + root.sin() * s0[1];
                                if best.is_none_or(|(_, c)| closeness > c) {
                                    best = Some((root, closeness));
                                }
                            }
                        }
                    }
                }
                prev = cur;
            }
            match best {
                Some((phi, _)) => trial.slip[k] = [phi.cos(), phi.sin()],
                None => trial.slip[k] = s0,
            }
            super::dependent::copy_to_twins(&twins, closed, &mut trial.slip);
        } else if ok && from_rest {
            // the consistent slip direction from rest: a_t ∥ s (so v_t grows along s and the
            // direction v_t/|v_t| is smooth); fixed-point iteration s ← a_t/|a_t| from the
            // impending direction, to 1e-12 (at most 50 solves); when it does not settle and
            // two contacts start together, Newton's iteration on both angles from the impending
            // directions (`pair_slip.rs`: at their common onset |a_t| is rounding noise)
            let mut settled = false;
            for _ in 0..50 {
                if solve_modes(contacts, &trial, stabilization, fd, cd).is_err() {
                    ok = false;
                    break;
                }
                let qdd = &fd.qdd.as_slice()[..nv];
                let mut change = 0.0f64;
                for (i, &k) in closed.iter().enumerate() {
                    if cands[i][idx[i]] == (Cand::Slide { moving: false }) && contacts[k].unilateral_friction() > 0.0 {
                        let a = [cd.rows.dot(3 * k + 1, qdd) + cd.rows.bias[3 * k + 1], cd.rows.dot(3 * k + 2, qdd) + cd.rows.bias[3 * k + 2]];
                        let m = a[0].hypot(a[1]);
                        if m > 0.0 {
                            let s_new = [a[0] / m, a[1] / m];
                            change = change.max((s_new[0] - trial.slip[k][0]).hypot(s_new[1] - trial.slip[k][1]));
                            // only a direction the slip can take (a_t · s > 0): otherwise keep s and let the check decide
                            if s_new[0] * trial.slip[k][0] + s_new[1] * trial.slip[k][1] > 0.0 {
                                trial.slip[k] = s_new;
                            }
                        }
                    }
                }
                if change <= 1e-12 {
                    settled = true;
                    break;
                }
            }
            if ok && !settled && rest_sliders.len() == 2 && twins.iter().all(Option::is_none) {
                let mut pair = trial.clone();
                for &k in &rest_sliders {
                    pair.slip[k] = impending[k];
                }
                if super::pair_slip::newton(contacts, &mut pair, [rest_sliders[0], rest_sliders[1]], stabilization, fd, cd) {
                    pair_root = Some([pair.slip[rest_sliders[0]], pair.slip[rest_sliders[1]]]);
                }
            }
        }
        // the combination with the fixed point's directions; if it fails and Newton's root of the
        // pair differs, once more with the root (`pair_slip.rs`)
        let feasible_before = feasible.len();
        for attempt in 0..2 {
            if attempt == 1 {
                match pair_root {
                    Some(root) if feasible.len() == feasible_before && (root[0] != trial.slip[rest_sliders[0]] || root[1] != trial.slip[rest_sliders[1]]) => {
                        trial.slip[rest_sliders[0]] = root[0];
                        trial.slip[rest_sliders[1]] = root[1];
                    }
                    _ => break,
                }
            }
            if ok && from_rest {
                // the slides from rest are onsets: their friction's direction follows the sticking
                // force's impending direction while slower than SLIP_DIRECTION_SPEED
                // (`forward::onset_anchors`), turned by the rotation from it to the direction chosen
                for &k in &rest_sliders {
                    let (i, s) = (impending[k], trial.slip[k]);
                    trial.onset[k] = Some([s[0] * i[0] + s[1] * i[1], s[1] * i[0] - s[0] * i[1]]);
                }
                super::dependent::copy_to_twins(&twins, closed, &mut trial.onset);
            }
            if ok && solve_modes(contacts, &trial, stabilization, fd, cd).is_ok() {
                let qdd = &fd.qdd.as_slice()[..nv];
                let qmax = qdd.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                let fmax = closed.iter().fold(0.0f64, |m, &k| m.max(cd.f_n[k].abs()).max(cd.f_t[k][0].hypot(cd.f_t[k][1])));
                let (tol_f, tol_a) = (1e-8 * (1.0 + fmax), 1e-8 * (1.0 + qmax));
                // a slide from rest is at the cone when its slip acceleration along s is within what
                // a force of tol_f along s gives (the stick's tolerance, in the same units):
                // `a_t · s ≥ −tol_f sᵀ G s`, G the contact's tangential Delassus block
                let slip_tol = |k: usize, s: [f64; 2]| tol_a.max(tol_f * tangential_delassus(fd, cd, k, s));
                let breaking = |k: usize| state.mode[k] == ContactMode::Sticking && preferred[k] == ContactMode::Sliding;
                let mut feasible_here = true;
                let mut marginal = false;
                for (i, &k) in closed.iter().enumerate() {
                    let accel = |axis: usize| cd.rows.dot(3 * k + axis, qdd) + cd.rows.bias[3 * k + axis];
                    marginal |= match cands[i][idx[i]] {
                        Cand::Sep => accel(0) <= tol_a,
                        Cand::Stick => cd.margin[k] <= tol_f || cd.f_n[k] <= tol_f,
                        Cand::Slide { moving } => {
                            cd.f_n[k] <= tol_f || (!moving && contacts[k].unilateral_friction() > 0.0 && accel(1) * trial.slip[k][0] + accel(2) * trial.slip[k][1] <= slip_tol(k, trial.slip[k]))
                        }
                    };
                }
                for (i, &k) in closed.iter().enumerate() {
                    let (f_n, f_t) = (cd.f_n[k], cd.f_t[k]);
                    let accel = |axis: usize| cd.rows.dot(3 * k + axis, qdd) + cd.rows.bias[3 * k + axis];
                    feasible_here &= match cands[i][idx[i]] {
                        Cand::Sep => accel(0) >= -tol_a,
                        // at a stick → slip event (a sticking contact preferred sliding: its margin
                        // crossed 0 falling) a stick at the cone does not go on
                        Cand::Stick => f_n >= -tol_f && f_t[0].hypot(f_t[1]) <= contacts[k].unilateral_friction() * f_n + tol_f && !(breaking(k) && cd.margin[k] <= tol_f),
                        Cand::Slide { moving } => {
                            f_n >= -tol_f && (moving || contacts[k].unilateral_friction() == 0.0 || accel(1) * trial.slip[k][0] + accel(2) * trial.slip[k][1] >= -slip_tol(k, trial.slip[k]))
                        }
                    };
                }
                // the slides from rest at the cone (a_t·s within its tolerance of 0: the onset,
                // where the slide and the stick are the same solution): they go on only if their slip
                // acceleration grows with the stick's excess, p(s) > 0 ([`onset_grows`])
                // (per twin group: judged once, on the group's first contact carrying the group's
                // force, [`as_one`]; a twin's own p(s) is 0 while its twin takes the load)
                let at_cone: Vec<usize> = closed
                    .iter()
                    .enumerate()
                    .filter(|&(i, &k)| {
                        let accel = |axis: usize| cd.rows.dot(3 * k + axis, qdd) + cd.rows.bias[3 * k + axis];
                        twins[i].is_none() && cands[i][idx[i]] == (Cand::Slide { moving: false }) && contacts[k].unilateral_friction() > 0.0 && accel(1) * trial.slip[k][0] + accel(2) * trial.slip[k][1] <= slip_tol(k, trial.slip[k])
                    })
                    .map(|(i, _)| i)
                    .collect();
                if feasible_here {
                    let score = closed.iter().filter(|&&k| trial.mode[k] == preferred[k]).count();
                    let found = Feasible { mode: trial.mode.clone(), slip: trial.slip.clone(), onset: trial.onset.clone(), qdd: qdd.to_vec(), score, marginal };
                    if at_cone.iter().all(|&i| onset_grows(contacts, &as_one(&trial, &twins, closed, i), closed[i], stabilization, fd, cd)) {
                        feasible.push(found);
                    }
                }
            }
        }
        // next combination
        let mut i = 0;
        loop {
            if i == closed.len() {
                break;
            }
            idx[i] += 1;
            if idx[i] < cands[i].len() {
                break;
            }
            idx[i] = 0;
            i += 1;
        }
        if i == closed.len() {
            break;
        }
    }
    let mus = closed.iter().map(|&k| format!("{} (mu = {})", contacts[k].name(), contacts[k].unilateral_friction())).collect::<Vec<_>>().join(", ");
    let Some(best) = feasible.iter().enumerate().max_by_key(|(i, f)| (f.score, usize::MAX - i)).map(|(_, f)| f) else {
        // say why at each frictional contact (the rigid problem's terms at this state)
        // (a twin group once, as one contact carrying the group's force: [`as_one`])
        let whys: Vec<String> = closed
            .iter()
            .enumerate()
            .filter(|&(i, &k)| contacts[k].unilateral_friction() > 0.0 && twins[i].is_none())
            .filter_map(|(i, &k)| {
                let v = cd.rows.slip(k);
                let speed = v[0].hypot(v[1]);
                let moving = (speed > vel_tol).then(|| [v[0] / speed, v[1] / speed]);
                one_contact(contacts, &as_one(state, &twins, closed, i), k, stabilization, fd, cd).map(|o| painleve_why(contacts[k].name(), &o, moving))
            })
            .collect();
        let mut whys = whys;
        whys.splice(0..0, super::pair_normal::painleve_pairs(contacts, state, closed, vel_tol, stabilization, fd, cd));
        let whys = if whys.is_empty() { String::new() } else { format!(": {}", whys.join("; ")) };
        return Err(DynamicsError::InconsistentContact {
            t,
            contact: names(),
            why: format!("no consistent contact forces: Painleve inconsistency ({mus}){whys}; no combination of the closed contacts' modes passed (the enumeration, with its slip directions from rest): use a smaller friction or a compliant contact"),
        });
    };
    let qmax = best.qdd.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    for f in feasible.iter().filter(|f| !f.marginal && !best.marginal) {
        let d = f.qdd.iter().zip(&best.qdd).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        if d > 1e-6 * (1.0 + qmax) {
            return Err(DynamicsError::InconsistentContact {
                t,
                contact: names(),
                why: format!("indeterminate: several solutions of the contact problem accelerate the arm differently (by {d:.3e} rad/s^2; {mus}); Painleve indeterminacy, try a smaller friction"),
            });
        }
    }
    for &k in closed {
        state.mode[k] = best.mode[k];
        state.slip[k] = best.slip[k];
        state.onset[k] = best.onset[k];
    }
    solve_modes(contacts, state, stabilization, fd, cd).map_err(|_| DynamicsError::SingularConstraints { t, constraints: names() })
}

/// `sᵀ G s` for contact `k`'s tangential rows, `G = J_t M_J⁻¹ J_tᵀ` (the tangential Delassus
/// block, m s⁻² N⁻¹; Pfeiffer & Glocker 1996, §5.2): the slip acceleration along `s` a unit
/// force along `s` gives. After [`super::forward::prepare`] (`fd.m_j` holds the factor).
fn tangential_delassus(fd: &ForwardData, cd: &ContactData, k: usize, s: [f64; 2]) -> f64 {
    let nv = cd.rows.nv;
    let (t1, t2) = (cd.rows.row(3 * k + 1), cd.rows.row(3 * k + 2));
    let w: Vec<f64> = (0..nv).map(|j| s[0] * t1[j] + s[1] * t2[j]).collect();
    let mut x = w.clone();
    super::solve::solve_mj(fd.m_j.as_slice(), &fd.l_inv_diag, nv, &mut x);
    w.iter().zip(&x).map(|(a, b)| a * b).sum()
}

/// What the rigid problem of one frictional contact `k` reads at a state (after
/// [`super::forward::prepare`]), with the other contacts in the modes of `state`: its
/// effective Delassus block `G` (3 × 3, rows normal, t1, t2, m s⁻² N⁻¹; `J_k M_J⁻¹ J_kᵀ`
/// less what the other contacts' active rows take, found column by column as the change of
/// contact k's acceleration under a unit force on each of its rows, the equations being
/// linear), its acceleration `a0` with no force of its own, and the sticking force `f*` (with
/// the others as they are). From these (Pfeiffer & Glocker 1996, §5.2; Brogliato, *Nonsmooth
/// Mechanics*, 2016, §5.5; Génot & Brogliato 1999): a slide along `s` (friction `−μ f_n s`)
/// has `f_n = −a0_n / p(s)` with `p(s) = G_nn − μ G_nt·s`, and when it starts from the stick at
/// the cone, `a_t·s = δ (g_t g_n − g_c²) / p(s)` (δ = |f*_t| − μ f*_n, `g_c = G_nt·s`,
/// `g_t = sᵀ G_tt s`): with `p(s) ≤ 0` a slide along `s` is not a solution (Painlevé).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OneContact {
    pub g: [[f64; 3]; 3],
    pub a0: [f64; 3],
    pub f_n: f64,
    pub f_t: [f64; 2],
    pub mu: f64,
}

impl OneContact {
    /// The slide's normal coefficient `p(s) = G_nn − μ G_nt·s` (m s⁻² N⁻¹).
    pub fn p(&self, s: [f64; 2]) -> f64 {
        self.g[0][0] - self.mu * (self.g[0][1] * s[0] + self.g[0][2] * s[1])
    }
    /// The impending slip direction `−f*_t/|f*_t|` (None when the stick has no tangential force).
    pub fn impending(&self) -> Option<[f64; 2]> {
        let m = self.f_t[0].hypot(self.f_t[1]);
        (m > 0.0).then(|| [-self.f_t[0] / m, -self.f_t[1] / m])
    }
    /// The stick margin `μ f*_n − |f*_t|` (N).
    pub fn margin(&self) -> f64 {
        self.mu * self.f_n - self.f_t[0].hypot(self.f_t[1])
    }
}

/// [`OneContact`] of contact `k` (unilateral with friction) with the others in `state`'s
/// modes; None when a solve is singular. Allocates (events and diagnostics only).
pub fn one_contact(contacts: &[Contact], state: &ContactState, k: usize, stabilization: Stabilization, fd: &mut ForwardData, cd: &mut ContactData) -> Option<OneContact> {
    let nv = cd.rows.nv;
    let mut st = state.clone();
    st.onset[k] = None;
    st.mode[k] = ContactMode::Separated;
    let b0 = fd.b.clone();
    let accel = |fd: &ForwardData, cd: &ContactData| -> [f64; 3] {
        let qdd = &fd.qdd.as_slice()[..nv];
        std::array::from_fn(|a| cd.rows.dot(3 * k + a, qdd) + cd.rows.bias[3 * k + a])
    };
    let mut out = None;
    if solve_modes(contacts, &st, stabilization, fd, cd).is_ok() {
        let a0 = accel(fd, cd);
        let mut cols = [[0.0; 3]; 3];
        let mut ok = true;
        for (a, col) in cols.iter_mut().enumerate() {
            fd.b.copy_from(&b0);
            for (bj, rj) in fd.b.iter_mut().zip(cd.rows.row(3 * k + a)) {
                *bj += rj;
            }
            ok &= solve_modes(contacts, &st, stabilization, fd, cd).is_ok();
            let a1 = accel(fd, cd);
            *col = std::array::from_fn(|r| a1[r] - a0[r]);
        }
        let g: [[f64; 3]; 3] = std::array::from_fn(|r| std::array::from_fn(|c| cols[c][r]));
        fd.b.copy_from(&b0);
        st.mode[k] = ContactMode::Sticking;
        if ok && solve_modes(contacts, &st, stabilization, fd, cd).is_ok() {
            out = Some(OneContact { g, a0, f_n: cd.f_n[k], f_t: cd.f_t[k], mu: contacts[k].unilateral_friction() });
        }
    }
    fd.b.copy_from(&b0);
    out
}

/// Why the rigid problem has no solution at contact `k` (the message's part for it): the stick
/// outside the cone, the separation pressing into the table, and the slide along the impending
/// direction with `p(s) ≤ 0`, with the numbers and the friction below which the slide would be
/// consistent (`μ < G_nn / (G_nt·s)`).
fn painleve_why(name: &str, o: &OneContact, moving: Option<[f64; 2]>) -> String {
    let Some(s) = moving.or(o.impending()) else {
        return format!("{name}: the stick has no tangential force (f_n = {:.6e} N)", o.f_n);
    };
    let along = if moving.is_some() { "its slip direction" } else { "the impending direction" };
    let stick = match (moving, o.margin() < 0.0) {
        (Some(_), _) => String::new(),
        (None, true) => format!("sticking needs |f_t| = {:.6e} N > mu f_n = {:.6e} N (margin {:.3e} N); ", o.f_t[0].hypot(o.f_t[1]), o.mu * o.f_n, o.margin()),
        (None, false) => format!("sticking alone would hold (margin {:.3e} N, f_n = {:.6e} N); ", o.margin(), o.f_n),
    };
    let gc = o.g[0][1] * s[0] + o.g[0][2] * s[1];
    let terms = format!("G_nn - mu G_nt.s = {:.6e} m/(s^2 N) (G_nn = {:.6e}, G_nt.s = {:.6e})", o.p(s), o.g[0][0], gc);
    let slide = if o.p(s) <= 0.0 {
        let limit = if gc > 0.0 { format!("friction below G_nn/(G_nt.s) = {:.4} makes the slide consistent", o.g[0][0] / gc) } else { String::new() };
        format!("sliding along {along} s = ({:.4}, {:.4}) has {terms}, so its normal force -a_n/(G_nn - mu G_nt.s) has the sign of a_n and its slip cannot grow: no slide either (Painleve's paradox; Genot & Brogliato 1999); {limit}", s[0], s[1])
    } else {
        format!("sliding along {along} s = ({:.4}, {:.4}) alone would be consistent ({terms} > 0): the other contacts' modes make the combination inconsistent", s[0], s[1])
    };
    format!("{name} (mu = {}): {stick}separated it would accelerate {} (a_n = {:.6e} m/s^2); {slide}", o.mu, if o.a0[0] < 0.0 { "into the table" } else { "away" }, o.a0[0])
}

/// Whether a slide from rest of contact `k` at the cone (the stick → slip onset, where the
/// slide's slip acceleration `a_t·s` is 0 and the stick's margin is 0) is a solution after the
/// instant: with the other contacts in `trial`'s modes, `a_t·s = δ (g_t g_n − g_c²) / p(s)`
/// (δ = |f*_t| − μ f*_n, the stick's excess, > 0 once the stick is broken; [`OneContact`]), and
/// `g_t g_n − g_c² > 0` (G is positive definite), so the slip grows along `s` iff
/// `p(s) = G_nn − μ G_nt·s > 0` (Pfeiffer & Glocker 1996, §5.2, the acceleration-level problem
/// whose degenerate case this is; Génot & Brogliato 1999, the slide's normal coefficient in
/// Painlevé's paradox; Brogliato 2016, §5.5). With `p(s) ≤ 0` the slide decelerates as soon as
/// it starts, the slip → stick event fires ~1e-7 s later with the stick broken, and the modes
/// chattered (issue 23 item 6: elbow7 at μ ≈ 1.3, `contacts_chatter`); refused, the stick's
/// excess goes to the other candidates: separation when the contact's free normal acceleration
/// `a0_n = −p(s) f*_n` is positive (the friction was pressing it on), else no solution
/// (Painlevé's inconsistency, reported with these terms).
fn onset_grows(contacts: &[Contact], trial: &ContactState, k: usize, stabilization: Stabilization, fd: &mut ForwardData, cd: &mut ContactData) -> bool {
    one_contact(contacts, trial, k, stabilization, fd, cd).is_none_or(|o| o.p(trial.slip[k]) > 0.0)
}

/// `state` with the twins of `closed[i]` (the later contacts of its twin group, `dependent::twins`)
/// separated: the group as one contact, `closed[i]`, carrying the group's force. Twins have the
/// same rows `W` (normal, t1, t2), the same μ and, sliding, the same slip direction s, so their
/// forces enter the dynamics only as `Wᵀ (Σ f_n,j, Σ f_t,j)`, and a slide's as
/// `(W_n − μ sᵀ W_t)ᵀ Σ f_n,j`: only the sum is determined, and the sum of forces on one ray of
/// one cone is on that ray (Coulomb's cone is convex and positively homogeneous; Glocker,
/// *Set-Valued Force Laws*, 2001, §7: the force law of the group is the law of one contact in
/// the summed force, and so is its maximal dissipation, `−Σ f_t,j · v_t = −(Σ f_t,j) · v_t`).
/// The group's Delassus matrix is `G_group = 1 1ᵀ ⊗ G_1` (every block the one contact's `G_1`),
/// so a split `f_j` of the group's force gives the point the acceleration `a0 + G_1 Σ f_j`: the
/// rigid problem of the group (Pfeiffer & Glocker 1996, §5.2), restricted to the group's one
/// normal and one slip direction, is that of one contact, and its slide's normal coefficient is
/// `G_nn − μ G_nt·s` of `closed[i]` with its twins absent. With a twin left sliding beside it instead, a unit push on
/// `closed[i]`'s normal row is taken back by the twin's identical row, its `G_nn` and `G_nt·s`
/// are 0 and `p(s) = 0` says nothing about the group (the refused slides of both
/// `contacts_pair` runs, "Painlevé inconsistency" with every term 0). For events only (allocates).
fn as_one(state: &ContactState, twins: &[Option<usize>], closed: &[usize], i: usize) -> ContactState {
    let mut st = state.clone();
    for (j, t) in twins.iter().enumerate() {
        if *t == Some(i) {
            st.mode[closed[j]] = ContactMode::Separated;
            st.onset[closed[j]] = None;
        }
    }
    st
}
