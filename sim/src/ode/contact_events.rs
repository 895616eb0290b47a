//! The contacts' event functions and event handling of the hybrid arm (`hybrid.rs` has the
//! contact state, the impact, the mode problem's call and the bookkeeping; the table of the
//! event functions is in its module doc): the functions' values, directions and dead bands, the
//! modes at t0, and what an event does (impacts, stops, the modes chosen). Split from
//! `hybrid.rs` (file size); Pfeiffer & Glocker 1996, ch. 5–6; Acary & Brogliato 2008, ch. 7.
//! The slip's stop at the integrator's resolution of the slip ([`slip_stop_speed`]): Glocker,
//! *Set-Valued Force Laws*, 2001, §7 (the friction at rest is set-valued: what a slip's zero is can
//! only be told to the precision its velocity is known to); Acary & Brogliato 2008, §7.2 (an
//! event-driven scheme's thresholds set by what the integrator resolves).

use crate::dynamics::contact::forward::{has_rows, slip_direction, SLIP_DIRECTION_SPEED};
use crate::dynamics::contact::rows::contact_gaps_where;
use crate::dynamics::contact::{ContactEvent, ContactEventKind, ContactMode, ContactModel};
use crate::error::RunError;

use super::arm::ArmSystem;
use super::hybrid::{in_touch, REBOUND_START};
use super::resolution::{measured_len, slip_resolution};

/// The speed (m/s) at which a plain slip's stop is located (its ev1 is `v_t · s_ref` minus this):
/// the part of [`slip_resolution`] above [`SLIP_DIRECTION_SPEED`], 0 when the friction's blend
/// towards `s_ref` (`forward::friction_direction`, below `v_s`) already covers what a step
/// resolves. Above it the last `slip_resolution − v_s` of the slip is the integrator's error, whose
/// direction the friction follows: a decelerating 2-D slip there did not reach the zero of `v_t ·
/// s_ref` but crept at 1–2 `v_s` with the friction saturated (elbow7's stop at 0.1300525 s not
/// reached within 0.3 s by dopri45 at rtol 1e-4 and rosenbrock at 1e-3, 6.1 ms late by rosenbrock
/// at 1e-4; BENCHMARKS.md, "Issue 24 point 3" and "… point 3 again"). Located at the resolution,
/// the stop is the velocity projection `stop_slip` of a slip the integrator cannot tell from rest
/// (Pfeiffer & Glocker 1996, ch. 6; the gap's analogue is `resolution::gap_resolution`'s accumulation
/// rule, Acary & Brogliato 2008, §7.2): the stop's time moves by at most this speed / `|a_t|`, the
/// kinetic energy it removes (≤ ½ m (this speed)²) is booked as friction work. Continuous in the
/// state; 0 wherever the resolution is below `v_s`, as at the paper's rtol 1e-8 (~1e-8 m/s) and at
/// every rung of `sim precision` on the unilateral scene from rtol 1e-5 on: those runs do not move
/// at all (the rungs' right-hand sides and events to the digit, the printed paper energies).
///
/// For a method that takes the friction explicitly (dopri45, imex, rosenbrock: `bound`, the run's
/// declared `ContactSettings::onset_slip_speed` of `forward::onset_speed_bound`, above `v_s`) it
/// is at least `c · rtol · 1 m/s − v_s`, `c` = [`STABILITY_STOP_FACTOR`] (so from rtol 2e-6 up;
/// below the declared `bound` = 30 · rtol · 1 m/s): the friction's direction
/// `v_t/|v_t|` has the stiffness `λ ≈ μ f_n / (m_eff |v_t|)` (~2e6 /s at `v_s` on elbow7), and an
/// explicit step is stable only for `h λ` inside its stability region (Hairer & Wanner, *Solving
/// ODEs II*, §IV.2): below `v_stab = μ f_n h / (m_eff c_stab)` the step control holds `h` at that
/// limit and the slip cannot be followed to its zero. Imex at rtol 1e-5 crept there at 2–3 `v_s`
/// for 5.5 ms (elbow7's stop at 0.1300525 s located at 0.1355 s; 46 646 right-hand sides over
/// 0.3 s against 13 864 at 1e-6; the creep's speed scales with the step, ~0.25 · rtol · 1 m/s at
/// rtol 1e-4 and 1e-5, measured, not derived): the stop located above it is the velocity
/// projection of a slip the method cannot resolve, as above, and within the speed the run
/// declares to the audit as regularised (`AuditBounds::of`). 0 for rodas and rk4 and at rtol ≤
/// 3.3e-8 (`bound` = `v_s`): those runs do not move.
pub(super) fn slip_stop_speed(tolerances: Option<(f64, f64)>, rows: &crate::dynamics::contact::rows::ContactRows, k: usize, qd: &[f64], n: usize, bound: f64) -> f64 {
    let stability = match tolerances {
        Some((rtol, _)) if bound > SLIP_DIRECTION_SPEED => STABILITY_STOP_FACTOR * rtol * STABILITY_SPEED_SCALE - SLIP_DIRECTION_SPEED,
        _ => 0.0,
    };
    (slip_resolution(tolerances, rows, k, qd, n) - SLIP_DIRECTION_SPEED).max(stability).max(0.0)
}

/// `c` of the speed `c · rtol · 1 m/s` below which an explicit method's decelerating slip is
/// stopped ([`slip_stop_speed`]): twice imex's measured creep (~0.25 · rtol · 1 m/s at rtol 1e-4
/// and 1e-5, the stability limit `v_stab` of its steps there; tuned on the paper's unilateral
/// scene, not computed from `h`, `μ f_n` and `m_eff`).
const STABILITY_STOP_FACTOR: f64 = 0.5;
/// The speed scale of [`STABILITY_STOP_FACTOR`], m/s (as `forward::onset_speed_bound`'s).
const STABILITY_SPEED_SCALE: f64 = 1.0;

/// The slip→stick rule (issue 23, item 2). A sliding contact's ev1 is `v_t · s_ref` (m/s),
/// `s_ref` the slip direction at the start of the step, less [`slip_stop_speed`] (0 unless the
/// integrator's resolution of the slip exceeds `SLIP_DIRECTION_SPEED`; the bound below is then
/// at least twice it): its zero is located like
/// a lift-off or a touch-down (the sliding right-hand side continues the friction's direction
/// through the zero, `slip_direction`, so the integrator steps across it smoothly). In 1-D the
/// zero of `v_t · s_ref` is the zero of the slip; in 2-D it is where the slip velocity turns
/// perpendicular to `s_ref`, which is the stop when `|v_t|` there is at most this bound, and
/// otherwise a turn of the slip direction by 90° within one step (no stop: `s_ref` is refreshed
/// and the contact slides on). The bound is the larger of the contact settings' `vel_tol`
/// (`velocity_tolerance`, 1e-9 m/s) and [`SLIP_DIRECTION_SPEED`] (1e-6 m/s), below which the
/// friction's direction blends towards the stored one (`friction_direction`): there the slip's
/// part across `s_ref` is braked less, so a 2-D slip that ends inside that speed may turn across
/// `s_ref` instead of reaching zero along it, and without the second bound each such turn
/// restarted the slip at a smaller speed, 90° further, 33 times at one instant
/// (one-elbow-unilateral at rtol 1e-4, with the direction frozen below that speed). A slip that stops cleanly (1-D,
/// or 2-D coming to rest along a direction) reaches the zero with `|v_t|` ~1e-12 m/s (the root's
/// 1e-12 s bracket). What is left is removed by the velocity projection `stop_slip`.
///
/// During an onset (a slip from rest, `ContactState::onset`, until the end of the step where it
/// passes `SLIP_DIRECTION_SPEED`) ev1 is instead the stick's excess `|f*_t| − μ f*_n` at the
/// state (`ContactData::onset_excess`, N; dead band 1e-8 N as the stick's): by Coulomb's law a
/// slip from rest goes on while the stick is broken, and stops where the stick is feasible
/// again, which at `|v_t| ≤ SLIP_DIRECTION_SPEED` is the stop up to `SLIP_DIRECTION_SPEED/|a_t|`.
/// The onset's slip (1e-13 … 1e-10 m/s over its first microsecond) is far below what the
/// integrator controls, and `v_t · s_ref` there read its noise: a where-elbow candidate had its
/// slip swing to +3e-10 and −2e-10 m/s within 4e-7 s while its stick's excess grew, the stop
/// fired, the stick was refused, the slide from rest taken again, 33 times at one instant
/// (issue 23 item 6; `tests/contacts_chatter.rs`).
fn stops_here(v_t: [f64; 2], vel_tol: f64) -> bool {
    v_t[0].hypot(v_t[1]) <= vel_tol.max(SLIP_DIRECTION_SPEED)
}

/// How far above its start gap, m, a separated contact watched from its start value (at or
/// below it after a lift-off, or after a landing the mode problem separated again) must be
/// found inside a step to count as having left the table and come back (`integrate::events`,
/// `departed_inside`), instead of its touch-down firing at the step's start. The gap is
/// `n · p − d` with `|p|` a few metres, computed to a few ulp of that (~1e-15 m); this bound
/// is 1000 times that and 1/1000 of the closed-contact tolerance `gap_tol` (1e-9 m), which
/// stays the dead band for *firing*. Traced (issue 23 item 6 A,
/// `touchdown-refire-pair-tight.json`, rtol 1e-8, atol 1e-10): elbow7, landed at 0.0722681 s
/// and separated by the mode problem (ġ = 0, g̈ = +0.43 m/s²), rises ~1e-11 m and lands again
/// inside the restart's 8.3e-5-s step, which ends 3.5e-9 m below its start gap; with the dead
/// band as the departure bound its touch-down fired at the step's start, the handler found
/// elbow7 at ġ = 0 leaving again, and the same step was retaken 33 times.
pub const GAP_DEPARTURE: f64 = 1e-12;

/// The contacts' part of the [`HybridSystem`] (`drive_modes.rs` has the drives' part; the
/// trait's implementation there joins them: the contacts' functions come first).
impl ArmSystem<'_> {
    pub(super) fn contact_n_events(&self) -> usize {
        self.hybrid.as_ref().map_or(0, |h| 2 * h.contacts.len())
    }

    pub(super) fn contact_event_direction(&self, i: usize) -> i8 {
        let Some(h) = &self.hybrid else { return 0 };
        match h.contacts[i / 2].model {
            ContactModel::Compliant { .. } => 0,
            _ => -1,
        }
    }

    /// The dead band of a function that starts on its firing side (`integrate::events`): a gap
    /// must close by more than the closed-contact tolerance (`gap_tol`, m), a force turn
    /// negative (or leave the friction cone) by more than 1e-8 N, a slip speed fall by more than
    /// `vel_tol` (m/s) — far above the solver's noise at f_n = 0, far below any force that
    /// matters — before the event is taken at the restart itself.
    pub(super) fn contact_event_tolerance(&self, i: usize) -> Option<f64> {
        let h = self.hybrid.as_ref()?;
        let k = i / 2;
        let cs = &self.scene.contact_settings;
        match (h.contacts[k].model, h.state.mode[k], i % 2) {
            (ContactModel::Unilateral { .. }, ContactMode::Separated, 0) => Some(cs.gap_tol),
            (ContactModel::Unilateral { .. }, ContactMode::Sliding, 1) if h.state.onset[k].is_none() => Some(cs.vel_tol),
            (ContactModel::Unilateral { .. }, ContactMode::Sticking | ContactMode::Sliding, _) => Some(1e-8),
            _ => None,
        }
    }

    /// How far above its start gap a separated unilateral contact's touch-down function must
    /// be found inside a step to have left the table (`HybridSystem::event_departure`):
    /// [`GAP_DEPARTURE`]; the other functions' bound is their dead band.
    pub(super) fn contact_event_departure(&self, i: usize) -> Option<f64> {
        let h = self.hybrid.as_ref()?;
        let k = i / 2;
        match (h.contacts[k].model, h.state.mode[k], i % 2) {
            (ContactModel::Unilateral { .. }, ContactMode::Separated, 0) => Some(GAP_DEPARTURE),
            _ => self.contact_event_tolerance(i),
        }
    }

    /// After an [`ArmSystem::evaluate`] (whose solve leaves the separated rigid contacts
    /// untouched, `contact_rows_only`): their gaps and velocities from the kinematics it left,
    /// for the event functions and the event handler.
    fn separated_gaps(&mut self) {
        let Some(h) = self.hybrid.as_mut() else { return };
        let (contacts, mode) = (&h.contacts, &h.state.mode);
        contact_gaps_where(&self.ws.data, contacts, &mut h.cd.rows, |k| !has_rows(contacts, mode, k));
    }

    pub(super) fn contact_events(&mut self, t: f64, y: &[f64], out: &mut [f64]) -> Result<(), RunError> {
        if self.hybrid.is_none() {
            return Ok(());
        }
        self.evaluate(t, y)?;
        self.separated_gaps();
        let (tolerances, qd) = (self.scene.integrator().tolerances(), &y[self.layout.qd()]);
        let h = self.hybrid.as_mut().expect("hybrid");
        let r = &h.cd.rows;
        // the components the step control measures, for the slip stops below (the modes do not
        // change within this evaluation)
        let measured = measured_len(h, y.len());
        for (k, c) in h.contacts.iter().enumerate() {
            if h.rebound[k] {
                // the restart after the contact left with a separating speed; one the step
                // control does not resolve has its return located `zeno::DEPARTURE_DEPTH` below
                // its restart gap (`mark_rebounds`): it rises above the gap's rounding too
                // slowly for a return on g₀ itself to be one
                h.gap_ref[k] = r.gap[k].min(0.0) - h.rebound_depth[k];
                h.rebound_t[k] = t;
                h.rebound[k] = false;
            }
            let f_n = h.cd.f_n[k];
            let (e0, e1) = match (c.model, h.state.mode[k]) {
                (ContactModel::Bilateral, _) => (1.0, 1.0),
                (ContactModel::Compliant { stiffness, damping, .. }, _) => {
                    let (delta, delta_d) = (-r.gap[k], -r.vel[3 * k]);
                    (r.gap[k], if delta > 0.0 { stiffness * delta + damping * delta_d } else { 1.0 })
                }
                (_, ContactMode::Separated | ContactMode::Bilateral) => (if t == h.rebound_t[k] { REBOUND_START } else { r.gap[k] - h.gap_ref[k] }, 1.0),
                // the stick margin (a statically indeterminate contact's largest; jammed: no slip)
                (_, ContactMode::Sticking) => (f_n, if h.cd.margin[k].is_finite() { h.cd.margin[k] } else { 1.0 }),
                // an onset: the stick's excess (the slip → stick rule of an onset, `stops_here`)
                (_, ContactMode::Sliding) if c.unilateral_friction() > 0.0 && h.state.onset[k].is_some() && h.cd.onset_excess[k].is_finite() => (f_n, h.cd.onset_excess[k]),
                (_, ContactMode::Sliding) => {
                    let v = r.slip(k);
                    (f_n, if c.unilateral_friction() > 0.0 { v[0] * h.s_ref[k][0] + v[1] * h.s_ref[k][1] - slip_stop_speed(tolerances, r, k, qd, measured, h.settings.onset_slip_speed) } else { 1.0 })
                }
            };
            out[2 * k] = e0;
            out[2 * k + 1] = e1;
        }
        Ok(())
    }

    pub(super) fn contact_init_modes(&mut self, t: f64, y: &mut [f64]) -> Result<bool, RunError> {
        if self.hybrid.is_none() {
            return Ok(false);
        }
        self.prepare_at(t, y)?;
        let h = self.hybrid.as_ref().expect("hybrid");
        let st = h.settings;
        let mut approaching = Vec::new();
        let mut closed = Vec::new();
        for (k, c) in h.contacts.iter().enumerate() {
            if matches!(c.model, ContactModel::Unilateral { .. }) && h.cd.rows.gap[k].abs() <= st.gap_tol {
                if h.cd.rows.vel[3 * k] < -st.vel_tol {
                    approaching.push(k);
                } else if h.cd.rows.vel[3 * k] <= st.vel_tol {
                    closed.push(k);
                }
            }
        }
        let mut moved = false;
        if !approaching.is_empty() {
            let (c2, _) = self.impact(t, y, &approaching)?;
            closed = c2;
            moved = true;
        }
        // a contact at rest on the table at t0 is taken as closed when both are consistent
        let h = self.hybrid.as_ref().expect("hybrid");
        let preferred: Vec<ContactMode> = h
            .contacts
            .iter()
            .enumerate()
            .map(|(k, c)| if c.unilateral_friction() > 0.0 && h.cd.rows.slip(k)[0].hypot(h.cd.rows.slip(k)[1]) <= st.vel_tol { ContactMode::Sticking } else { ContactMode::Sliding })
            .collect();
        let before_log = self.hybrid.as_ref().map_or(0, |h| h.log.len());
        self.resolve_modes(t, y, &closed, &preferred, &[])?;
        self.mark_rebounds(y);
        // the initial choice is not an event
        let h = self.hybrid.as_mut().expect("hybrid");
        let n = h.log.len();
        let dropped = h.log.drain(before_log..n).filter(|e| e.kind != ContactEventKind::Impact && e.kind != ContactEventKind::Rest).count();
        h.count -= dropped as u64;
        Ok(moved)
    }

    pub(super) fn contact_handle_events(&mut self, t: f64, y: &mut [f64], fired: &[bool]) -> Result<bool, RunError> {
        if self.hybrid.is_none() {
            return Ok(false);
        }
        // forces and rows at the event in the current modes
        self.evaluate(t, y)?;
        self.separated_gaps();
        let (tolerances, qd) = (self.scene.integrator().tolerances(), self.layout.qd());
        let h = self.hybrid.as_mut().expect("hybrid");
        let st = h.settings;
        let nc = h.contacts.len();
        let mut preferred = h.state.mode.clone();
        let mut closed: Vec<usize> = (0..nc).filter(|&k| in_touch(h.state.mode[k])).collect();
        let mut approaching = Vec::new();
        let mut touched = Vec::new();
        let mut pending = Vec::new();
        let mut logged = Vec::new();
        let mut stopping = Vec::new();
        let mut slip_stopped = false;
        for k in 0..nc {
            let (f0, f1) = (fired[2 * k], fired[2 * k + 1]);
            if !(f0 || f1) {
                continue;
            }
            let gd = h.cd.rows.vel[3 * k];
            let c = &h.contacts[k];
            match (c.model, h.state.mode[k]) {
                (ContactModel::Bilateral, _) => {}
                (ContactModel::Compliant { .. }, _) => {
                    if f0 {
                        let kind = if gd < 0.0 { ContactEventKind::TouchDown } else { ContactEventKind::LiftOff };
                        pending.push(ContactEvent { t, contact: k, kind, impulse: 0.0, energy_lost: 0.0, gap_rate_before: gd, gap_rate_after: gd });
                    }
                }
                (_, ContactMode::Separated | ContactMode::Bilateral) => {
                    if f0 {
                        if gd < -st.vel_tol {
                            approaching.push(k);
                        } else if gd > st.vel_tol {
                            // separating: the gap is not closing (a contact is closed only with
                            // its gap rate at zero); its return is located from the restart
                            h.rebound[k] = true;
                            h.rebound_depth[k] = 0.0;
                        } else {
                            touched.push(k);
                            preferred[k] = if c.unilateral_friction() > 0.0 { ContactMode::Sticking } else { ContactMode::Sliding };
                        }
                    }
                }
                (_, mode) => {
                    if f0 {
                        preferred[k] = ContactMode::Separated;
                    } else if f1 && mode == ContactMode::Sticking {
                        preferred[k] = ContactMode::Sliding;
                        let f = h.cd.f_t[k];
                        let m = f[0].hypot(f[1]);
                        if m > 0.0 {
                            h.state.slip[k] = [-f[0] / m, -f[1] / m];
                        }
                        // the slide starts from rest: the stick's drift (~1e-13 m/s) is removed
                        // as at a stop, else it turns the friction's blend by |v_t|/v_s (~1e-7
                        // rad, ~1e-6 N of 13 N) and the slide from rest reads a deceleration
                        // the stick's margin does not have (one-elbow at rtol 1e-5, 0.7161 s)
                        stopping.push(k);
                    } else if f1 && stops_here(h.cd.rows.slip(k), if h.state.onset[k].is_some() { st.vel_tol.max(slip_resolution(tolerances, &h.cd.rows, k, &y[qd.clone()], measured_len(h, y.len()))) } else { st.vel_tol.max(2.0 * slip_stop_speed(tolerances, &h.cd.rows, k, &y[qd.clone()], measured_len(h, y.len()), h.settings.onset_slip_speed)) }) {
                        preferred[k] = ContactMode::Sticking;
                        stopping.push(k);
                        slip_stopped = true;
                    } else if f1 && h.state.onset[k].is_some() {
                        // the onset's stick became feasible with the slip already past the
                        // stop bound: a slip like any other from here, along its own direction,
                        // stopped at its zero
                        h.state.onset[k] = None;
                        let v = h.cd.rows.slip(k);
                        h.s_ref[k] = slip_direction(v, v);
                        h.state.slip[k] = h.s_ref[k];
                    }
                }
            }
        }
        if slip_stopped {
            // a common stop: every other sliding contact whose slip the step control does not
            // resolve (`slip_resolution`, at least `vel_tol`) stops with it, and the mode problem
            // decides the stops (and slides from rest) together. Such a slip has no direction
            // the integrator resolves; left sliding along it, the other contact's slide from
            // rest took its direction from that noise, the two slips grew across their
            // directions and stopped in turn, every ~3e-8 s (where-pair's evaluation 45,
            // `crawl-pair.json`, 0.142069 s: elbow4 at 3e-8 m/s against a resolution of 1.3e-6
            // m/s, elbow7 stopping; 100 000 events by 0.1438 s). A resolved slip stops at its
            // own zero (`contacts_start::two_slips_stopping_at_once_…`, 1e-12 s)
            for (k, pref) in preferred.iter_mut().enumerate() {
                let v = h.cd.rows.slip(k);
                let resolved = st.vel_tol.max(slip_resolution(tolerances, &h.cd.rows, k, &y[qd.clone()], measured_len(h, y.len())));
                if !stopping.contains(&k) && h.state.mode[k] == ContactMode::Sliding && h.contacts[k].unilateral_friction() > 0.0 && v[0].hypot(v[1]) <= resolved {
                    *pref = ContactMode::Sticking;
                    stopping.push(k);
                }
            }
        }
        for e in pending {
            self.log(e)?;
        }
        let mut moved = false;
        if !approaching.is_empty() {
            let (c2, opened) = self.impact(t, y, &approaching)?;
            moved = true;
            for k in c2 {
                if !closed.contains(&k) {
                    closed.push(k);
                }
                let c = &self.hybrid.as_ref().expect("hybrid").contacts[k];
                if preferred[k] == ContactMode::Separated && approaching.contains(&k) {
                    preferred[k] = if c.unilateral_friction() > 0.0 { ContactMode::Sticking } else { ContactMode::Sliding };
                }
                if approaching.contains(&k) {
                    logged.push(k);
                }
            }
            closed.retain(|k| !opened.contains(k));
            // only the approaching contacts were logged by the impact (Impact/Rest); a contact
            // that was in touch and is thrown off by the impulse gets its LiftOff from
            // resolve_modes (review F3)
            for k in opened {
                if approaching.contains(&k) {
                    logged.push(k);
                }
            }
        }
        for k in touched {
            if !closed.contains(&k) {
                closed.push(k);
            }
        }
        if !stopping.is_empty() {
            self.stop_slip(t, y, &stopping)?;
            moved = true;
        }
        self.resolve_modes(t, y, &closed, &preferred, &logged)?;
        self.mark_rebounds(y);
        Ok(moved)
    }

    pub(super) fn contact_after_step(&mut self, y: &[f64]) {
        self.refresh_slip_reference(y);
        self.release_rebounds(y);
    }
}
