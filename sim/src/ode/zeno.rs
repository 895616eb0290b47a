//! The end of an accumulation of impacts of the hybrid arm (issue 23 item 6, issue 25: the
//! frictionless see-saw of two landings; `hybrid.rs::ArmSystem::impact` uses it beside
//! `gap_resolution`). Two closed contacts whose Delassus coupling `G₁₂` is positive make each
//! plastic landing lift the other off at `G₂₁/G₁₁` (or `G₁₂/G₂₂`) of its speed (the impact LCP,
//! Pfeiffer & Glocker 1996, §6.2); with μ = 0, G symmetric positive definite, both the impact
//! and the acceleration-level problems are P-matrix LCPs with one solution each (Cottle, Pang &
//! Stone, *The Linear Complementarity Problem*, 1992, Thm 3.3.7), the sequence contracts by
//! `G₁₂²/(G₁₁G₂₂) < 1` per cycle (Cauchy–Schwarz), and with each contact accelerating into the
//! table while the other is closed (w < 0) its flights `2ġ⁺/|w|` sum to a finite time: a Zeno
//! sequence whose limit is both closed (Brogliato, *Nonsmooth Mechanics*, 2016, §1.3 and §5.3).
//! An event-driven scheme ends it by closing the contact once a threshold is met (Acary &
//! Brogliato 2008, §7.2); here the threshold is the position resolution a closed contact is held
//! to: a flight that would rise at most `gap_tol` ([`flight_within_gap_tol`]). Holding it (the
//! impact re-solved with ġ⁺ = 0 on it) truncates the tail: the tail's impulses plus its flights'
//! free accelerations and the held impact plus the closed contact's force both bring ġ of the
//! pair to 0 through impulses along `M⁻¹Jᵀ`, so the states after differ by O(the tail's
//! duration) in velocity and by at most the tail's flight height in position. Also here: the
//! return of a contact an impact closed and the mode problem separates at ġ = 0, and of a
//! rebound, located below the gap's rounding ([`DEPARTURE_DEPTH`]).

use crate::dynamics::contact::forward::{slip_direction, solve_modes};
use crate::dynamics::contact::impact::Impact;
use crate::dynamics::contact::ContactMode;
use crate::error::RunError;

use super::arm::ArmSystem;
use super::hybrid::in_touch;

/// How far below its restart gap g₀ a contact that an impact closed and the mode problem then
/// separates at ġ ≈ 0 (an acceleration-level departure, g̈ > 0) counts as back on the table, m.
/// Such a departure rises as ½ g̈ τ², below the rounding of a gap (~1e-16 m at arm positions
/// of ~1 m) for τ < √(2e-16/g̈) ~ 1e-8 s, so a touch-down function `g − g₀` reads that rounding
/// at the restart and its root is located there again, at one instant (where-pair-frictionless's
/// evaluation 23 at 0.044062663 s: elbow7 lands at −0.106 m/s, the mode problem separates it at
/// g̈ = +1.18 m/s², and its touch-down fired 33 times within 8e-12 s). `g − (g₀ − 1e-12 m)` is
/// 1e4 times that rounding above zero at the restart and a thousandth of `gap_tol` below it at
/// the return: the flight's return is located inside the closed band. The same scale as the
/// departure bound of a separated contact inside a step ([`super::contact_events::GAP_DEPARTURE`],
/// 1000 × the gap's rounding): one constant for both.
///
/// The same depth is under the return of a *rebound* (a contact that leaves the table at
/// ġ⁺ > `vel_tol`) that the step control does not resolve, ġ⁺ ≤ `resolution::gap_resolution` (its
/// touch-down function `g − (min(g₀, 0) − DEPARTURE_DEPTH)`, `hybrid.rs::mark_rebounds`): such a
/// rebound rises above the gap's rounding only after `~1e-16 m / ġ⁺` (2e-9 s at 4.6e-8 m/s),
/// and with the return located from g₀ itself each rounding dip below g₀ inside that time was a
/// root. A resolved rebound returns to g₀ itself: the depth would move its return by
/// `DEPARTURE_DEPTH / |ġ|` in time and `g · DEPARTURE_DEPTH / |ġ|` in speed (3.6e-9 m/s at the
/// bouncing ball's 2.7e-3 m/s, above its closed form's 1.5e-9 m/s bound, `contacts_exact`). Traced (where-pair-frictionless's evaluation 93, `departure-pair.json`, rtol 1e-5): elbow4
/// lands at 0.0627154 s and is separated at ġ = 0; 3e-7 s later its gap, integrated to ~1e-12 m
/// at this tolerance, is 1e-12 m below g₀ while ġ reads +4.6e-8 m/s, the touch-down fires with the
/// contact separating (a rebound), and from there each dip of the gap's rounding below the new g₀
/// fired again ~3e-11 s after the restart: 9 550 restarts (none logged: the mode stays separated)
/// in 6.4e-7 s, 9 670 steps for the 0.07-s run (7 790 at atol 1e-10). With the depth: 128 and
/// 150 steps, the same events. A return whose flight is longer than a step is unchanged: once a
/// step ends with the contact above the table its function is `g` again (`release_rebounds`).
pub const DEPARTURE_DEPTH: f64 = super::contact_events::GAP_DEPARTURE;

/// Whether a contact leaving the table at `gap_rate` (m/s, > 0) with the normal acceleration
/// `accel` (m/s², its g̈ in the flight) stays within the closed band: a ballistic flight
/// `g(τ) = ġ⁺ τ + ½ g̈ τ²` with `g̈ < 0` rises to `ġ⁺² / (2 |g̈|)`, and at most `gap_tol` (m) it
/// never leaves the band `|g| ≤ gap_tol` in which a contact counts as closed.
pub(super) fn flight_within_gap_tol(gap_rate: f64, accel: f64, gap_tol: f64) -> bool {
    accel < 0.0 && gap_rate * gap_rate <= 2.0 * -accel * gap_tol
}

impl ArmSystem<'_> {
    /// The normal accelerations g̈ (m/s², per contact; NaN where not computed) just after the
    /// impact `imp` at (t, y) (y before it): the joint speeds jumped by `imp.dqd`, the impact's
    /// contacts `uni` that it leaves separating (ġ⁺ > `vel_tol`) separated, those it leaves
    /// closed in touch (a landing one sticking when frictional and its slip is at most
    /// `vel_tol`, else sliding along its slip), the others in their modes: each separating
    /// contact's acceleration in its flight ([`flight_within_gap_tol`]). Leaves the rows and
    /// the factor prepared at (t, y) again, for the impact's re-solve.
    pub(super) fn flight_accelerations(&mut self, t: f64, y: &[f64], imp: &Impact, uni: &[(usize, f64)]) -> Result<Vec<f64>, RunError> {
        let l = self.layout;
        let mut after = y.to_vec();
        for (v, d) in after[l.qd()].iter_mut().zip(&imp.dqd) {
            *v += d;
        }
        self.prepare_at(t, &after)?;
        let stab = self.scene.stabilization;
        let h = self.hybrid.as_mut().expect("hybrid");
        let vel_tol = h.settings.vel_tol;
        let mut state = h.state.clone();
        for &(k, _) in uni {
            if imp.gap_rate_after[k] > vel_tol {
                state.mode[k] = ContactMode::Separated;
                state.onset[k] = None;
            } else if !in_touch(state.mode[k]) {
                let v = h.cd.rows.slip(k);
                let sliding = h.contacts[k].unilateral_friction() == 0.0 || v[0].hypot(v[1]) > vel_tol;
                state.mode[k] = if sliding { ContactMode::Sliding } else { ContactMode::Sticking };
                state.slip[k] = slip_direction(v, state.slip[k]);
                state.onset[k] = None;
            }
        }
        let mut w = vec![f64::NAN; h.contacts.len()];
        if solve_modes(&h.contacts, &state, stab, &mut self.ws.fd, &mut h.cd).is_ok() {
            let nv = h.cd.rows.nv;
            let qdd = &self.ws.fd.qdd.as_slice()[..nv];
            for &(k, _) in uni {
                if state.mode[k] == ContactMode::Separated {
                    w[k] = h.cd.rows.dot(3 * k, qdd) + h.cd.rows.bias[3 * k];
                }
            }
        }
        self.prepare_at(t, y)?;
        Ok(w)
    }
}
