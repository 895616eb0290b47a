//! The integrator's resolution of a contact's gap rate and slip: the speeds below which an
//! accepted step cannot tell them from zero, from the step control's error norm
//! (`sqrt(1/n Σ (e_i/w_i)²) ≤ 1` over the `n` measured components, `w_i = atol + rtol |y_i|`;
//! Hairer, Nørsett & Wanner, *Solving ODEs I*, (4.11)) by Cauchy–Schwarz on the contact's rows.
//! They decide the events `hybrid.rs` and `contact_events.rs` locate at loose tolerances: a
//! rebound's depth, a slip's stop speed, an onset's blend speed.

use crate::dynamics::contact::forward::{ONSET_RESOLUTION_FACTOR, SLIP_DIRECTION_SPEED};
use crate::dynamics::contact::{Contact, ContactMode, ContactModel};

use super::hybrid::Hybrid;
use super::layout::QUADRATURES_PER_CONTACT;

/// The gap rate of contact `k` below which the integrator does not resolve it (m/s): the
/// normal analogue of [`slip_resolution`], `sqrt(n) |J_n (atol + rtol |q̇|)|` over the joint
/// speeds (an accepted step has `sqrt(1/n Σ (e_i/w_i)²) ≤ 1`, HNW I (4.11); Cauchy–Schwarz);
/// 0 for a fixed-step method. It ends an accumulation of impacts (issue 23 item 6, the see-saw
/// of two landings: each plastic landing lifted the other contact off at `G₄₇/G₄₄` of its
/// speed, a Zeno sequence whose speeds fell to the integrator's noise and then chattered):
/// a contact a plastic impact leaves separating slower than this is held closed with ġ = 0
/// ([`ArmSystem::impact`]), and the acceleration-level mode problem decides its lift-off by g̈.
/// This is the event-driven schemes' handling of an accumulation point (Acary & Brogliato 2008,
/// §7.2: near an accumulation point the impacts are stopped and the contact closed when the
/// velocity falls below a threshold; Brogliato, *Nonsmooth Mechanics*, 2016, §1.3 and §5.3 on
/// Zeno sequences of impacts, whose limit is the persistent contact), with the threshold the
/// step control's own resolution instead of a fixed speed. At the paper's rtol 1e-8,
/// atol 1e-10 it is ~1e-8 m/s.
pub(super) fn gap_resolution(tolerances: Option<(f64, f64)>, rows: &crate::dynamics::contact::rows::ContactRows, k: usize, qd: &[f64], n: usize) -> f64 {
    let Some((rtol, atol)) = tolerances else { return 0.0 };
    (n as f64 * weighted_row_sq(rows, 3 * k, qd, rtol, atol)).sqrt()
}

/// The slip speed of contact `k` below which the integrator does not resolve the slip (m/s):
/// the largest error in `v_t = J_t q̇` an accepted step may carry. A step is accepted with
/// `sqrt(1/n Σ_i (e_i/w_i)²) ≤ 1` over the `n` components the norm measures ([`measured_len`]), `w_i = atol + rtol |y_i|`
/// (the step control's weights, HNW I (4.11)), so by Cauchy–Schwarz the error of a tangential
/// row's `J_t · q̇` is at most `sqrt(n) (Σ_i (J_t,i w_i)²)^½` over the joint speeds (the rows
/// of the last solve, `rows`); the two rows' bounds combined as a vector. 0 for a fixed-step
/// method. At rtol 1e-8, atol 1e-10 (the paper's runs) it is ~1e-8 m/s, below
/// [`SLIP_DIRECTION_SPEED`]; at rtol 1e-3, atol 1e-5 (whole-table at 0.2448 s) ~1e-4 m/s,
/// where an onset's first step carried a slip of 2.3e-5 m/s 35° off the direction the slip
/// takes at rtol 1e-6 (within 0.03° of its anchor up to 8e-6 m/s).
pub(super) fn slip_resolution(tolerances: Option<(f64, f64)>, rows: &crate::dynamics::contact::rows::ContactRows, k: usize, qd: &[f64], n: usize) -> f64 {
    let Some((rtol, atol)) = tolerances else { return 0.0 };
    (n as f64 * (weighted_row_sq(rows, 3 * k + 1, qd, rtol, atol) + weighted_row_sq(rows, 3 * k + 2, qd, rtol, atol))).sqrt()
}

/// Whether the step control leaves contact `c`'s quadratures out of its error norm in `mode`
/// (`OdeSystem::error_measured`, `ode/arm.rs`): a separated unilateral contact's three
/// quadratures are constant until its next event (SUNDIALS CVODES's `errconQ`).
pub(super) fn quadratures_idle(c: &Contact, mode: ContactMode) -> bool {
    matches!(c.model, ContactModel::Unilateral { .. }) && mode == ContactMode::Separated
}

/// The number of components the step control's error norm measures over a state of `n`
/// (`n` less the idle contacts' quadratures, [`quadratures_idle`]): the `n` of the bound
/// [`slip_resolution`] and [`gap_resolution`] take (`sqrt(1/n Σ (e_i/w_i)²) ≤ 1` over the
/// measured components). With `n` the whole state, whole-table's seven idle candidates raised
/// the bound by √(80/59) against two-elbow-unilateral's and the same motion took other steps
/// at loose tolerances (dopri45, rtol 1e-4: 4 125 steps against 10 923 over 5 s).
pub(super) fn measured_len(h: &Hybrid, n: usize) -> usize {
    let idle = h.contacts.iter().zip(&h.state.mode).filter(|(c, m)| quadratures_idle(c, **m)).count();
    n - QUADRATURES_PER_CONTACT * idle
}

/// The speed below which a stick → slip onset's friction blends towards its anchor
/// (`forward::onset_direction`'s `v_on`), m/s, fixed at the onset's start:
/// `max(v_s, min(K · slip_resolution, bound))`, K = [`ONSET_RESOLUTION_FACTOR`], `bound` the
/// run's declared largest (`ContactSettings::onset_slip_speed`, `forward::onset_speed_bound`).
pub(super) fn onset_speed(tolerances: Option<(f64, f64)>, rows: &crate::dynamics::contact::rows::ContactRows, k: usize, qd: &[f64], n: usize, bound: f64) -> f64 {
    SLIP_DIRECTION_SPEED.max((ONSET_RESOLUTION_FACTOR * slip_resolution(tolerances, rows, k, qd, n)).min(bound))
}

/// `Σ_i (J_r,i w_i)²` of contact row `r` over the joint speeds, `w_i = atol + rtol |q̇_i|` (the
/// step control's weights): the squared bound [`slip_resolution`] and [`gap_resolution`] scale.
fn weighted_row_sq(rows: &crate::dynamics::contact::rows::ContactRows, r: usize, qd: &[f64], rtol: f64, atol: f64) -> f64 {
    rows.row(r).iter().zip(qd).map(|(j, v)| (j * (atol + rtol * v.abs())).powi(2)).sum::<f64>()
}
