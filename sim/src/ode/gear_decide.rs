//! The gears' modes at an event, decided for all the joints at rest together
//! ([`ArmSystem::decide_gears`]), and the one consistent mode where the functions that decide it
//! are 0: a candidate holds when every function that must stay ≥ 0 in it does so as time goes
//! on, judged by its value, then (where the value is within its tolerance of 0) its slope, then
//! its curvature — the lexicographic test of the contacts' mode problem at `f_n = 0, g̈ = 0`
//! (Pfeiffer & Glocker, *Multibody Dynamics with Unilateral Contacts*, Wiley 1996, §5.3 and ch.
//! 6, the consistency of a transition by higher derivatives; Lötstedt, *Mechanical systems of
//! rigid bodies subject to unilateral constraints*, SIAM J. Appl. Math. 42 (1982) 281–296).
//!
//! Per joint j at rest (q̇_j = 0), with T = K_m i_j:
//!
//! - **stick**: both edges of the band (`dynamics/gear_friction.rs`), `λ − lo(T) ≥ 0` and
//!   `hi(T) − λ ≥ 0`. The edges are linear in T on each side of T = 0, so their slopes are
//!   `λ̇ − k Ṫ` (and `λ̈ − k T̈`), k the edge's slope on the side T moves to: the sign of
//!   (T, Ṫ, T̈), first not within its tolerance;
//! - **slide in s**: `s q̈ ≥ 0`, then `s q⃛`, then `s q⁗` (the velocity function `s q̇` starts at 0
//!   and must leave it upwards); its power direction σ (driving when `σ = +1`) is the sign of
//!   `s (T, Ṫ, T̈)`, so that the power function `σ s T` leaves 0 upwards too. Where T = 0 at the
//!   restart (a load released at i = 0: the band is the point λ = 0) the sign comes from the
//!   slope of T: `K_m di/dt = K_m (v − R i − K_e q̇) / L = K_m v / L` with an inductance,
//!   `K_m (dv/dt − K_e q̈) / R` quasi-static; with the PD at its target (v = 0) the inductive
//!   slope is 0 and the curvature `K_m (dv/dt − K_e q̈) / L = −K_m (k_d + K_e) q̈ / L` decides:
//!   it has the sign of −s (the back-EMF and the damping of the fall oppose it), so the joint
//!   slides back-driving, and `σ s T = |T|` grows from 0: the power function does not fire at
//!   the restart. Before, a zero torque counted as driving, and `s T` went negative at once.
//!
//! The slopes and curvatures are one-sided differences along the candidate's own flow (its
//! modes fixed; the right-hand side is smooth in them): with f = f(t, y),
//! `ḟ ≈ (f(t + h, y + h f) − f) / h` and the points `y_k = y + k h f + (k h)² ḟ / 2` (k = 1, 2,
//! second order), `ġ ≈ (−3 g_0 + 4 g_1 − g_2) / (2h)`, `g̈ ≈ (g_0 − 2 g_1 + g_2) / h²` (Fornberg,
//! Math. Comp. 51 (1988) 699–706), at h = 1e-5 s; forward only, so a target defined from t = 0
//! is not read before it. Their tolerances are the value's over 1e-4 s and (1e-4 s)²: a slope
//! below tol / 1e-4 s moves the value less than its tolerance in 0.1 ms. The rounding of the
//! differences (1e-13 of a quantity's scale over h, h²: 1e-8 and 1e-3 of it) is far below
//! those. Probed when a joint slides from rest in the candidate or some value is not clearly
//! positive (a candidate of sticking joints clearly inside their bands costs no probe).
//!
//! What happens within 1e-8 s (`TURN_TIME`) is not resolved: a value that its slope (or a
//! slope that its curvature) turns over within that time counts as 0, and the next entry
//! decides. On the paper arm at t = 0 joint 9, released at i = 0, has `s q̈ = +0.0057 rad/s²`
//! (its load) and `s q⃛ = −1.7e7 rad/s³` (its motor torque rising at `K_m v / L = 5.2e4 N m/s`):
//! sliding it would turn at 0.34 ns and stop at 0.67 ns, at a peak speed of 1e-12 rad/s, the
//! velocity function's own tolerance, so the driver fired its stop at the restart, over and
//! over (the chatter of issue 26 on joints 9 and 10). Judged over the resolved times it
//! sticks: its band, 0 wide at i = 0, widens at `(1/η_b − η) |K_m di/dt|` and holds the load
//! after `|λ| / ((1/η_b − η) |K_m di/dt|)`, a few ns — the holding torque outside the band
//! for that long is an impulse below 1e-12 N m s.

#![allow(clippy::result_large_err)] // RunError carries schemas::Error, as in `run.rs`

use crate::dynamics::gear_friction::{GearFriction, GearMode};
use crate::error::RunError;
use crate::integrate::OdeSystem;

use super::arm::ArmSystem;

/// h of the probes along a candidate's flow, s (module docs).
const PROBE_STEP: f64 = 1e-5;
/// A slope within tol / this, a curvature within tol / this², counts as 0, s (module docs).
const TIE_TIME: f64 = 1e-4;
/// What the next derivative turns over within this long counts as 0, s (module docs).
const TURN_TIME: f64 = 1e-8;

/// Values, slopes and curvatures of [`ArmSystem::probe`], each `3 a + k` for joint `which[a]`.
type Probe = (Vec<f64>, Vec<f64>, Vec<f64>);

/// A preferred mode as a candidate: a sliding mode's power direction from `km_i` (the joint is
/// at rest, its speed gives none; [`ArmSystem::gears_consistent`] settles it where K_m i ≈ 0).
fn normalise(mode: GearMode, km_i: f64) -> GearMode {
    match mode {
        GearMode::Stick => GearMode::Stick,
        GearMode::Slide { dir, .. } => GearMode::slide(f64::from(dir), km_i),
    }
}

/// The tolerances of a value `tol` and of its slope and curvature (module docs).
fn levels(tol: f64) -> [f64; 3] {
    [tol, tol / TIE_TIME, tol / (TIE_TIME * TIE_TIME)]
}

/// The sign with which `v` (value, slope, curvature) leaves its point: that of the first
/// entry beyond its tolerance, 0 if none is. An entry that the next one turns over within
/// [`TURN_TIME`] (opposite signs, `|v_k| < |v_{k+1}| TURN_TIME`) counts as 0: the decision
/// does not resolve what happens in less than that (module docs).
fn lex_sign(v: [f64; 3], tol: [f64; 3]) -> f64 {
    for k in 0..3 {
        if k < 2 && v[k] * v[k + 1] < 0.0 && v[k].abs() < v[k + 1].abs() * TURN_TIME {
            continue;
        }
        if v[k] > tol[k] {
            return 1.0;
        }
        if v[k] < -tol[k] {
            return -1.0;
        }
    }
    0.0
}

/// Whether a function that must stay ≥ 0 does, from (value, slope, curvature) `v`: the first
/// entry beyond its tolerance (the value's widened by `slack`) is positive; if none is, it holds
/// unless `strict`.
fn holds(v: [f64; 3], tol: [f64; 3], slack: f64, strict: bool) -> bool {
    let s = lex_sign(v, [tol[0] * slack, tol[1], tol[2]]);
    s > 0.0 || (s == 0.0 && !strict)
}

impl ArmSystem<'_> {
    /// The gear modes of the joints at rest, decided together at (t, y) (module docs, "The
    /// joints' modes together"): every combination of stick, slide + and slide − over the
    /// joints at rest is a candidate, tried in the order of how many joints leave their
    /// `preferred` mode (0 first), then stick before slide; the first consistent one is taken.
    /// Moving joints keep their sliding modes. No consistent combination: the gears chatter
    /// ([`RunError::GearsChatter`], naming the joints at rest). Allocates (an event).
    pub(super) fn decide_gears(&mut self, t: f64, y: &[f64], preferred: &[GearMode], fired: &[bool], log_all: bool) -> Result<(), RunError> {
        let scene = self.scene;
        let Some(g) = &scene.gear_friction else { return Ok(()) };
        let l = self.layout;
        let nv = l.nv;
        let modes = &self.drive_modes.as_ref().expect("drive modes").gear;
        let rest: Vec<usize> = (0..nv).filter(|&j| g.active(j) && (y[l.qd().start + j] == 0.0 || modes[j] == GearMode::Stick || fired.get(j).copied().unwrap_or(false))).collect();
        if rest.is_empty() {
            return Ok(());
        }
        self.inputs(t, y)?;
        let km_i: Vec<f64> = (0..nv).map(|j| self.km_i(y, j)).collect();
        let before = self.drive_modes.as_ref().expect("drive modes").gear.clone();
        let n = rest.len();
        // per joint at rest: its preferred mode first, then the others (stick, slide +, slide −)
        let options: Vec<[GearMode; 3]> = rest
            .iter()
            .map(|&j| {
                // a sliding mode keeps the power direction its events have tracked (at the root
                // of `K_m i s` the sign of K_m i says nothing); a new one takes it from K_m i
                let as_now = |mode: GearMode| match (mode, before[j]) {
                    (GearMode::Slide { dir, .. }, GearMode::Slide { dir: d0, driving }) if dir == d0 => GearMode::Slide { dir, driving },
                    _ => normalise(mode, km_i[j]),
                };
                let p = as_now(preferred[j]);
                let mut o = [p; 3];
                let mut k = 1;
                for c in [GearMode::Stick, as_now(GearMode::slide(1.0, km_i[j])), as_now(GearMode::slide(-1.0, km_i[j]))] {
                    if c != p && k < 3 {
                        o[k] = c;
                        k += 1;
                    }
                }
                o
            })
            .collect();
        let mut choice = vec![0u8; n];
        let mut tried = 0u64;
        for d in 0..=n {
            // every set of d joints off their preferred mode (bit masks of popcount d), each with
            // its two other modes (2^d)
            for mask in 0u64..(1u64 << n) {
                if mask.count_ones() as usize != d {
                    continue;
                }
                for alt in 0u64..(1u64 << d) {
                    let mut b = 0;
                    for (a, c) in choice.iter_mut().enumerate() {
                        *c = if mask >> a & 1 == 1 {
                            b += 1;
                            1 + (alt >> (b - 1) & 1) as u8
                        } else {
                            0
                        };
                    }
                    tried += 1;
                    if self.gears_consistent(t, y, g, &rest, &options, &choice, &km_i, fired)? {
                        let m = self.drive_modes.as_ref().expect("drive modes");
                        let changed: Vec<(usize, GearMode)> = rest.iter().map(|&j| (j, m.gear[j])).filter(|&(j, mode)| log_all || mode != before[j]).collect();
                        for (j, mode) in changed {
                            self.log_gear(t, j, mode);
                        }
                        return Ok(());
                    }
                }
            }
        }
        let m = self.drive_modes.as_mut().expect("drive modes");
        m.gear.copy_from_slice(&before);
        let joints: Vec<String> = rest.iter().map(|&j| scene.model.bodies[j].joint.clone()).collect();
        let breakaway = rest.iter().any(|&j| g.breakaway[j] > 0.0);
        Err(RunError::GearsChatter { t, count: tried as u32, window: 0.0, limit: 0, joints: joints.join(", "), breakaway })
    }

    /// Whether the joints at rest in the modes `options[a][choice[a]]` are consistent at (t, y)
    /// (module docs): a sticking joint's holding torque inside both edges of its band
    /// (tolerance `tol_f = 1e-8 (1 N m + max |λ|)`), a joint sliding from rest accelerating its
    /// way (`s q̈`, `tol_a = 1e-8 (1 + max |q̈|)`), the tolerances of the contacts' mode problem
    /// (`dynamics/contact/modes.rs`); where a value is within its tolerance, its slope and then
    /// its curvature decide. A joint whose own event `fired` sits on the boundary the event
    /// located, to the location's accuracy rather than to rounding: its preferred mode (the one
    /// the event implies, `choice` 0) counts as at 0 within 100 times the tolerance, another mode
    /// holds only from clearly inside (the first of value, slope, curvature beyond its
    /// tolerance positive), which only another joint's change can bring about. A joint sliding
    /// from rest takes the power direction its torque leaves 0 in (`tol_T = 1e-8 (1 N m + max
    /// |K_m i|)`).
    #[allow(clippy::too_many_arguments)]
    fn gears_consistent(&mut self, t: f64, y: &[f64], g: &GearFriction, rest: &[usize], options: &[[GearMode; 3]], choice: &[u8], km_i: &[f64], fired: &[bool]) -> Result<bool, RunError> {
        {
            let m = self.drive_modes.as_mut().expect("drive modes");
            for (a, &j) in rest.iter().enumerate() {
                m.gear[j] = options[a][choice[a] as usize];
            }
        }
        self.evaluate(t, y)?;
        let rule = |a: usize, j: usize| match (fired.get(j).copied().unwrap_or(false), choice[a] == 0) {
            (true, true) => (100.0, false),
            (true, false) => (1.0, true),
            (false, _) => (1.0, false),
        };
        let (tol_f, tol_a, tol_t) = {
            let m = self.drive_modes.as_ref().expect("drive modes");
            let qdd = self.ws.fd.qdd.as_slice();
            let scale = |f: &dyn Fn(usize) -> f64| 1e-8 * (1.0 + rest.iter().map(|&j| f(j).abs()).fold(0.0, f64::max));
            (scale(&|j| m.gear_torque[j]), 1e-8 * (1.0 + qdd.iter().map(|x| x.abs()).fold(0.0, f64::max)), scale(&|j| km_i[j]))
        };
        // the values alone, where they decide (no probe)
        let mut tie = false;
        {
            let m = self.drive_modes.as_ref().expect("drive modes");
            let qdd = self.ws.fd.qdd.as_slice();
            for (a, &j) in rest.iter().enumerate() {
                let (slack, strict) = rule(a, j);
                let (values, tol): (Vec<f64>, f64) = match m.gear[j] {
                    GearMode::Stick => {
                        let (lo, hi) = g.band(j, km_i[j]);
                        (vec![m.gear_torque[j] - lo, hi - m.gear_torque[j]], tol_f)
                    }
                    GearMode::Slide { dir, .. } => {
                        // its power direction: from how s K_m i leaves (a small torque its slope
                        // reverses within TURN_TIME counts as 0), so always probed
                        tie = true;
                        (vec![f64::from(dir) * qdd[j]], tol_a)
                    }
                };
                // a value off its side may still turn within TURN_TIME: the slopes decide
                for v in values {
                    tie |= v <= tol * slack || (strict && v < tol);
                }
            }
        }
        if !tie {
            return Ok(true);
        }
        // slopes and curvatures along this candidate's flow
        let (v0, d1, d2) = self.probe(t, y, rest)?;
        let (lf, la, lt) = (levels(tol_f), levels(tol_a), levels(tol_t));
        let m = self.drive_modes.as_mut().expect("drive modes");
        for (a, &j) in rest.iter().enumerate() {
            let (slack, strict) = rule(a, j);
            let of = |k: usize| [v0[3 * a + k], d1[3 * a + k], d2[3 * a + k]];
            let (tm, lam, qdd) = (of(0), of(1), of(2));
            let ok = match m.gear[j] {
                GearMode::Stick => {
                    let (lo, hi) = g.band(j, tm[0]);
                    let (k_lo, k_hi) = g.band_slopes(j, lex_sign(tm, lt));
                    let below = [lam[0] - lo, lam[1] - k_lo * tm[1], lam[2] - k_lo * tm[2]];
                    let above = [hi - lam[0], k_hi * tm[1] - lam[1], k_hi * tm[2] - lam[2]];
                    holds(below, lf, slack, strict) && holds(above, lf, slack, strict)
                }
                GearMode::Slide { dir, .. } => {
                    let s = f64::from(dir);
                    m.gear[j] = GearMode::Slide { dir, driving: lex_sign([s * tm[0], s * tm[1], s * tm[2]], lt) >= 0.0 };
                    holds([s * qdd[0], s * qdd[1], s * qdd[2]], la, slack, strict)
                }
            };
            if !ok {
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// (T = K_m i, λ = the gear's torque beyond the ideal train, q̈) of the joints `which` at
    /// (t, y) in the current modes, and their slopes and curvatures along the flow (module
    /// docs), each as `3 a + k` for joint `which[a]`, k = 0 (T), 1 (λ), 2 (q̈). Leaves the
    /// workspace at another state: the caller evaluates again before it reads it.
    fn probe(&mut self, t: f64, y: &[f64], which: &[usize]) -> Result<Probe, RunError> {
        let n = y.len();
        let h = PROBE_STEP;
        let values = |sys: &Self, y: &[f64]| -> Vec<f64> {
            let m = sys.drive_modes.as_ref().expect("drive modes");
            which.iter().flat_map(|&j| [sys.km_i(y, j), m.gear_torque[j], sys.ws.fd.qdd[j]]).collect()
        };
        let mut f0 = vec![0.0; n];
        self.rhs(t, y, &mut f0)?;
        let g0 = values(self, y);
        let y1: Vec<f64> = (0..n).map(|k| y[k] + h * f0[k]).collect();
        let mut f1 = vec![0.0; n];
        self.rhs(t + h, &y1, &mut f1)?;
        let at = |c: f64| -> Vec<f64> { (0..n).map(|k| y[k] + c * h * f0[k] + 0.5 * c * c * h * (f1[k] - f0[k])).collect() };
        let ya = at(1.0);
        self.evaluate(t + h, &ya)?;
        let ga = values(self, &ya);
        let yb = at(2.0);
        self.evaluate(t + 2.0 * h, &yb)?;
        let gb = values(self, &yb);
        let d1 = (0..g0.len()).map(|k| (-3.0 * g0[k] + 4.0 * ga[k] - gb[k]) / (2.0 * h)).collect();
        let d2 = (0..g0.len()).map(|k| (g0[k] - 2.0 * ga[k] + gb[k]) / (h * h)).collect();
        Ok((g0, d1, d2))
    }
}
