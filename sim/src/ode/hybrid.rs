//! The arm as a hybrid (event-driven) system when its run has a non-bilateral contact
//! (Pfeiffer & Glocker, *Multibody Dynamics with Unilateral Contacts*, 1996, ch. 5–6; Acary &
//! Brogliato, *Numerical Methods for Nonsmooth Dynamical Systems*, 2008, ch. 7 on event-driven
//! schemes): the contacts' modes are discrete state, changed at events located by the driver
//! (`integrate::events`) as roots of two functions per contact:
//!
//! | mode | ev0 (direction) | ev1 (direction) |
//! |---|---|---|
//! | separated (unilateral) | g − g_ref (−1, touch-down) | 1 |
//! | sticking | f_n (−1, lift-off) | μ f_n − \|f_t\| (−1, stick→slip; a statically indeterminate contact's largest, `contact/indeterminate.rs`) |
//! | sliding | f_n (−1, lift-off) | v_t · s_ref − `slip_stop_speed` (−1, slip→stick at its zero, `stops_here` in `contact_events.rs`; 1 when μ = 0) |
//! | compliant | g (0) | k δ + c δ̇ while δ > 0, else 1 (0) |
//! | bilateral | 1 | 1 |
//!
//! `s_ref` is the slip direction at the start of the step (refreshed in `after_step`).
//! `g_ref` is 0, except after a contact left the table with a separating speed (a rebound):
//! then it is the restart's gap (less `zeno::DEPARTURE_DEPTH`, 1e-12 m, when the step control
//! does not resolve the rebound's ġ⁺: a return on the gap's rounding is none), and the
//! function is positive at the restart itself ([`REBOUND_START`]), so the return is located as
//! a root however short the flight. A fired touch-down with ġ > `vel_tol` (separating) closes
//! nothing: a contact is closed only with |g| ≤ `gap_tol` and |ġ| ≤ `vel_tol`.
//! The force-type functions need a full evaluation of eq 21 at the interpolated state.
//! At an event ([`HybridSystem::handle_events`]): touch-downs with approach speed above
//! `vel_tol` are impacts (`dynamics/contact/impact.rs`; below `rest_velocity` plastic: the Zeno
//! rule, kind `rest`); then the mode problem (`dynamics/contact/modes.rs`) over the closed
//! contacts, preferring the modes the events imply. An impact jumps q̇ (currents continuous),
//! adds its kinetic-energy loss to the contacts' impact-loss quadratures and the rotors'
//! impulsive torque work `−J_m (q̇⁺² − q̇⁻²)/2` to the link works W_j. Allocation happens at
//! events only (the mode enumeration, the impact), not in the step loop. The event functions
//! and the event handler are in `contact_events.rs` (file size); the end of an accumulation of
//! impacts (a lift-off whose flight stays within `gap_tol` held closed, a landed contact's
//! departure at ġ = 0) in `zeno.rs`.

use crate::dynamics::contact::forward::{prepare, slip_direction, ContactData, ContactState, SLIP_DIRECTION_SPEED};
use crate::dynamics::contact::impact::solve_impact;
use crate::dynamics::contact::modes::choose_modes_within;
use crate::dynamics::contact::{Contact, ContactEvent, ContactEventKind, ContactMode, ContactModel, ContactOutput, ContactSettings};
use crate::dynamics::kinematics::{forward_kinematics, forward_velocities};
use crate::error::{DynamicsError, RunError};
use crate::integrate::Watch;
use crate::scene::{Run, Scene};

use super::arm::{currents_in, plant, ArmSystem};
use super::resolution::{gap_resolution, measured_len, onset_speed, slip_resolution};
use super::zeno::{flight_within_gap_tol, DEPARTURE_DEPTH};

/// The hybrid part of an [`ArmSystem`].
pub(crate) struct Hybrid {
    pub(crate) contacts: Vec<Contact>,
    pub(crate) state: ContactState,
    pub(crate) cd: ContactData,
    pub(crate) settings: ContactSettings,
    /// Events since the last drain, in time order.
    pub(crate) log: Vec<ContactEvent>,
    /// Events handled in the whole run.
    pub(crate) count: u64,
    /// Slip direction of each sliding contact at the start of the step (for ev1).
    pub(crate) s_ref: Vec<[f64; 2]>,
    /// The projection's identity "factor" (nv x nv), its unit diagonal, a zero force, its
    /// rows and correction (nv).
    pub(crate) eye: Vec<f64>,
    pub(crate) ones: Vec<f64>,
    pub(crate) zeros: Vec<f64>,
    pub(crate) proj_rows: Vec<crate::dynamics::contact::solve::ActiveRow>,
    pub(crate) proj_dx: Vec<f64>,
    /// The run's deadline, read by the mode enumeration ([`ArmSystem::set_watch`]).
    pub(crate) watch: Watch,
    /// A separated contact's touch-down function is `g − gap_ref` (m): `gap_ref` is 0 except
    /// after the contact left the table with a separating speed (a rebound, or thrown off by
    /// another contact's impulse), where it is the restart's gap `min(g₀, 0)` (less
    /// `rebound_depth`), and the function's value AT the restart time `rebound_t` is
    /// [`REBOUND_START`] (the contact is leaving: on the open side), so its return to g₀ is
    /// located as a root.
    pub(crate) gap_ref: Vec<f64>,
    /// The restart time of that rebound, s (NaN: none).
    pub(crate) rebound_t: Vec<f64>,
    /// Whether `gap_ref` is to be taken at the next evaluation of the event functions (the
    /// restart after the event that made the contact leave).
    pub(crate) rebound: Vec<bool>,
    /// How far below the restart gap that rebound's return is located, m: `zeno::DEPARTURE_DEPTH`
    /// when the step control does not resolve its ġ⁺ (`gap_resolution`), else 0.
    pub(crate) rebound_depth: Vec<f64>,
    /// The contacts an impact at the current event landed and closed (ġ⁺ ≤ `vel_tol`), read
    /// (and cleared) by the mode problem's call after it (`resolve_modes`).
    pub(crate) landed: Vec<bool>,
}

impl Hybrid {
    pub(crate) fn new(scene: &Scene, run: &Run) -> Self {
        let contacts = scene.run_contact_models(run);
        let nc = contacts.len();
        let nv = scene.model.nv;
        let state = ContactState::new(&contacts);
        Hybrid {
            cd: ContactData::new(scene.model.nv, nc),
            state,
            settings: scene.contact_settings(),
            log: Vec::with_capacity(64),
            count: 0,
            s_ref: vec![[1.0, 0.0]; nc],
            eye: (0..nv * nv).map(|i| if i % (nv + 1) == 0 { 1.0 } else { 0.0 }).collect(),
            ones: vec![1.0; nv],
            zeros: vec![0.0; nv],
            proj_rows: Vec::with_capacity(3 * nc),
            proj_dx: vec![0.0; nv],
            watch: Watch::default(),
            gap_ref: vec![0.0; nc],
            rebound_t: vec![f64::NAN; nc],
            rebound: vec![false; nc],
            rebound_depth: vec![0.0; nc],
            landed: vec![false; nc],
            contacts,
        }
    }
}

/// The value of a rebounding contact's touch-down function at its restart, m (issue 23). A
/// contact that leaves the table with ġ > `vel_tol` restarts at a gap g₀ that is 0 up to the
/// event's bracket (≤ |ġ| · 1e-12 s inside); its touch-down function is `g − min(g₀, 0)` after
/// the restart (less `zeno::DEPARTURE_DEPTH` for a rebound the step control does not resolve:
/// a return on the gap's rounding is none) and this positive value at it, so the driver sees it
/// on the open side, watches nothing, and locates its return to g₀ like any root — even when
/// the whole flight is shorter than one step (the end of a bounce sequence). Without it the function started at
/// g₀ ≤ 0, was watched from there, and a flight inside the first step fired the touch-down at
/// the restart itself, closing a contact that separates. Once a step ends with the contact
/// above the table (g > 0) the function is `g` again (`release_rebounds`).
pub const REBOUND_START: f64 = 1e-14;


pub(super) fn in_touch(m: ContactMode) -> bool {
    matches!(m, ContactMode::Sticking | ContactMode::Sliding)
}

impl ArmSystem<'_> {
    /// The run's deadline for the system's own long loop (the contact mode enumeration, up to
    /// 3^8 constrained solves at one event): past it, [`crate::error::DynamicsError::OutOfTime`]. A run
    /// without events has no such loop.
    pub fn set_watch(&mut self, watch: Watch) {
        if let Some(h) = self.hybrid.as_mut() {
            h.watch = watch;
        }
    }

    /// Whether this run is event-driven: it has a non-bilateral contact (then the run uses
    /// `integrate_hybrid`, records `/contacts` and fills `Outputs::contacts`).
    pub fn is_hybrid(&self) -> bool {
        self.hybrid.is_some()
    }

    /// Take over `other`'s discrete contact modes (the run's output probe follows the
    /// stepper's system before each sample).
    pub fn copy_modes_from(&mut self, other: &ArmSystem<'_>) {
        if let (Some(h), Some(o)) = (&mut self.hybrid, &other.hybrid) {
            h.state.mode.copy_from_slice(&o.state.mode);
            h.state.slip.copy_from_slice(&o.state.slip);
            h.state.onset.copy_from_slice(&o.state.onset);
            h.cd.onset_speed.copy_from_slice(&o.cd.onset_speed);
            h.s_ref.copy_from_slice(&o.s_ref);
        }
        if let (Some(m), Some(o)) = (&mut self.drive_modes, &other.drive_modes) {
            m.gear.copy_from_slice(&o.gear);
            m.pos.copy_from_slice(&o.pos);
            m.bus_pos = o.bus_pos;
        }
    }

    /// Move the logged contact events (in time order) to the end of `into`.
    pub fn drain_events(&mut self, into: &mut Vec<ContactEvent>) {
        if let Some(h) = &mut self.hybrid {
            into.append(&mut h.log);
        }
    }

    /// The contacts' modes (empty for a bilateral run).
    pub fn contact_modes(&self) -> &[ContactMode] {
        self.hybrid.as_ref().map_or(&[], |h| &h.state.mode[..])
    }

    /// `Σ ½ k δ²` of the compliant contacts at the kinematics in the workspace, J.
    pub(super) fn contact_energy(&self) -> f64 {
        let Some(h) = &self.hybrid else { return 0.0 };
        h.contacts
            .iter()
            .map(|c| match c.model {
                ContactModel::Compliant { stiffness, .. } => {
                    let delta = -c.gap(&self.ws.data);
                    if delta > 0.0 {
                        0.5 * stiffness * delta * delta
                    } else {
                        0.0
                    }
                }
                _ => 0.0,
            })
            .sum()
    }

    /// The contact quadratures' rates after an evaluation: friction work `−f_t · v_t` and a
    /// compliant contact's damping loss `(f_n − k δ) δ̇` (impact losses change at events only).
    pub(super) fn contact_loss_rates(&self, dydt: &mut [f64]) {
        let l = self.layout;
        let Some(h) = &self.hybrid else { return };
        let r = &h.cd.rows;
        // contact k's three quadratures are `impact_loss(0) + 3k + (0, 1, 2)` (`Layout`): the
        // offset once, not three layout sums per contact and evaluation (issue 24 item 2)
        let base = l.impact_loss(0);
        let rates = &mut dydt[base..base + 3 * h.contacts.len()];
        for ((k, c), out) in h.contacts.iter().enumerate().zip(rates.chunks_exact_mut(3)) {
            let v = r.slip(k);
            let f_t = h.cd.f_t[k];
            out[0] = 0.0;
            out[1] = -(f_t[0] * v[0] + f_t[1] * v[1]);
            out[2] = match c.model {
                ContactModel::Compliant { stiffness, .. } => {
                    let (delta, delta_d) = (-r.gap[k], -r.vel[3 * k]);
                    if delta > 0.0 {
                        (h.cd.f_n[k] - stiffness * delta) * delta_d
                    } else {
                        0.0
                    }
                }
                _ => 0.0,
            };
        }
    }

    /// `Σ_k (E_imp + E_fric + E_damp)` at y, J.
    pub(super) fn contact_losses(&self, y: &[f64]) -> f64 {
        let l = self.layout;
        (0..l.contacts).map(|k| y[l.impact_loss(k)] + y[l.friction_work(k)] + y[l.damping_loss(k)]).sum()
    }

    /// The contacts' recorded quantities after a full evaluation at y (forces from it).
    pub(super) fn contact_outputs(&self, y: &[f64], forces: bool, out: &mut Vec<ContactOutput>) {
        out.clear();
        let Some(h) = &self.hybrid else { return };
        let l = self.layout;
        let data = &self.ws.data;
        for (k, c) in h.contacts.iter().enumerate() {
            let p = &c.plane;
            let (gap, vel) = (c.gap(data), c.touch_velocity(data));
            let slip = [c.t1.dot(&vel), c.t2.dot(&vel)];
            let (f_n, f_t) = if forces { (h.cd.f_n[k], h.cd.f_t[k]) } else { (f64::NAN, [f64::NAN; 2]) };
            let mode = match c.model {
                ContactModel::Compliant { .. } if forces => {
                    if f_n > 0.0 {
                        ContactMode::Sliding
                    } else {
                        ContactMode::Separated
                    }
                }
                _ => h.state.mode[k],
            };
            out.push(ContactOutput {
                mode,
                gap,
                gap_rate: p.normal_world.dot(&vel),
                normal_force: f_n,
                friction_force: f_t,
                slip_velocity: slip,
                impact_loss: y[l.impact_loss(k)],
                friction_work: y[l.friction_work(k)],
                damping_loss: y[l.damping_loss(k)],
            });
        }
    }

    /// Inputs and [`prepare`] at (t, y) for the hybrid path (no mode-dependent solve).
    pub(super) fn prepare_at(&mut self, t: f64, y: &[f64]) -> Result<(), DynamicsError> {
        self.inputs(t, y)?;
        let l = self.layout;
        let s = self.scene;
        let plant = plant(s, &s.drives, &self.contacts);
        let h = self.hybrid.as_mut().expect("hybrid");
        let current = currents_in(&l, y, &self.ws.current_qs);
        prepare(&plant, &h.contacts, &mut self.ws.data, &mut self.ws.fd, &mut h.cd, t, &y[l.q()], &y[l.qd()], current)
    }

    pub(super) fn log(&mut self, e: ContactEvent) -> Result<(), RunError> {
        let h = self.hybrid.as_mut().expect("hybrid");
        h.count += 1;
        if h.count > h.settings.max_events {
            return Err(RunError::TooManyEvents { t: e.t, max_events: h.settings.max_events });
        }
        h.log.push(e);
        Ok(())
    }

    /// An impact at (t, y): the contacts in touch and the separated unilateral ones at the
    /// table take part; q̇ jumps, the losses and the rotors' work are booked, events logged.
    /// Returns the contacts that stay closed (ġ⁺ ≤ vel_tol) and those that separate.
    pub(super) fn impact(&mut self, t: f64, y: &mut [f64], approaching: &[usize]) -> Result<(Vec<usize>, Vec<usize>), RunError> {
        let l = self.layout;
        let nv = l.nv;
        self.prepare_at(t, y)?;
        let h = self.hybrid.as_ref().expect("hybrid");
        let st = h.settings;
        let nc = h.contacts.len();
        let mut uni = Vec::new();
        let mut bil = Vec::new();
        for (k, c) in h.contacts.iter().enumerate() {
            match c.model {
                ContactModel::Bilateral => bil.push(k),
                ContactModel::Unilateral { restitution, .. } => {
                    if in_touch(h.state.mode[k]) || h.cd.rows.gap[k].abs() <= st.gap_tol || approaching.contains(&k) {
                        let gd = h.cd.rows.vel[3 * k];
                        let e = if -gd < st.rest_velocity { 0.0 } else { restitution };
                        uni.push((k, e));
                    }
                }
                ContactModel::Compliant { .. } => {}
            }
        }
        let fd = &self.ws.fd;
        let mut imp = solve_impact(&h.contacts, &h.cd.rows, fd.m_j.as_slice(), &fd.l_inv_diag, &uni, &bil, t)?;
        // the end of an accumulation of impacts ([`gap_resolution`], `zeno::flight_within_gap_tol`):
        // a plastic contact the impulse leaves separating slower than the step control resolves,
        // or whose flight would not rise above the closed band `gap_tol`, stays closed, its ġ⁺
        // held at 0 as a bilateral row's in the impact (its impulse and the energy it takes are
        // the impact's, booked below); repeated while the held set grows (≤ m solves)
        let tolerances = self.scene.integrator().tolerances();
        let qd0 = y[l.qd()].to_vec();
        let mut held: Vec<usize> = Vec::new();
        loop {
            let h = self.hybrid.as_ref().expect("hybrid");
            let (vel_tol, gap_tol) = (h.settings.vel_tol, h.settings.gap_tol);
            let lifted: Vec<usize> = uni.iter().filter(|&&(k, e)| e == 0.0 && !held.contains(&k) && imp.gap_rate_after[k] > vel_tol).map(|&(k, _)| k).collect();
            if lifted.is_empty() {
                break;
            }
            let noise: Vec<bool> = lifted.iter().map(|&k| imp.gap_rate_after[k] <= gap_resolution(tolerances, &h.cd.rows, k, &qd0, measured_len(h, y.len()))).collect();
            let w = if noise.iter().all(|&n| n) { vec![f64::NAN; nc] } else { self.flight_accelerations(t, y, &imp, &uni)? };
            let more: Vec<usize> = lifted.iter().zip(&noise).filter(|&(&k, &n)| n || flight_within_gap_tol(imp.gap_rate_after[k], w[k], gap_tol)).map(|(&k, _)| k).collect();
            if more.is_empty() {
                break;
            }
            let mut trial = held.clone();
            trial.extend(more);
            let free: Vec<(usize, f64)> = uni.iter().copied().filter(|(k, _)| !trial.contains(k)).collect();
            let fixed: Vec<usize> = bil.iter().chain(&trial).copied().collect();
            let h = self.hybrid.as_ref().expect("hybrid");
            let fd = &self.ws.fd;
            // no solution with them held (every active set singular or infeasible): the impact
            // as solved, they leave as before
            let Ok(i) = solve_impact(&h.contacts, &h.cd.rows, fd.m_j.as_slice(), &fd.l_inv_diag, &free, &fixed, t) else { break };
            imp = i;
            held = trial;
        }
        let h = self.hybrid.as_ref().expect("hybrid");
        let st = h.settings;
        let d = &self.scene.drives;
        for j in 0..nv {
            let before = y[l.qd().start + j];
            let after = before + imp.dqd[j];
            y[l.work().start + j] += -d.jm[j] * (after * after - before * before) / 2.0;
            y[l.qd().start + j] = after;
        }
        let mut closed = Vec::new();
        let mut opened = Vec::new();
        let mut landed = Vec::new();
        let vel_tol = st.vel_tol;
        let rest_velocity = st.rest_velocity;
        for &k in uni.iter().map(|(k, _)| k).chain(bil.iter()) {
            y[l.impact_loss(k)] += imp.energy_lost[k];
        }
        for &(k, _) in &uni {
            let (before, after) = (imp.gap_rate_before[k], imp.gap_rate_after[k]);
            if after <= vel_tol {
                closed.push(k);
                if approaching.contains(&k) {
                    landed.push(k);
                }
            } else {
                opened.push(k);
            }
            if before < -vel_tol && imp.impulse[k] > 0.0 {
                let kind = if -before < rest_velocity { ContactEventKind::Rest } else { ContactEventKind::Impact };
                self.log(ContactEvent { t, contact: k, kind, impulse: imp.impulse[k], energy_lost: imp.energy_lost[k], gap_rate_before: before, gap_rate_after: after })?;
            }
        }
        let h = self.hybrid.as_mut().expect("hybrid");
        for k in landed {
            h.landed[k] = true;
        }
        Ok((closed, opened))
    }

    /// The mode problem over `closed` at (t, y) with `preferred` modes; logs the mode changes
    /// not logged yet (`logged`), and refreshes `s_ref`.
    pub(super) fn resolve_modes(&mut self, t: f64, y: &[f64], closed: &[usize], preferred: &[ContactMode], logged: &[usize]) -> Result<(), RunError> {
        self.prepare_at(t, y)?;
        let stab = self.scene.stabilization;
        let h = self.hybrid.as_mut().expect("hybrid");
        let before = h.state.mode.clone();
        let onset_before = h.state.onset.clone();
        for (k, c) in h.contacts.iter().enumerate() {
            if matches!(c.model, ContactModel::Unilateral { .. }) && !closed.contains(&k) {
                h.state.mode[k] = ContactMode::Separated;
            }
        }
        choose_modes_within(&h.contacts, &mut h.state, closed, preferred, h.settings.vel_tol, stab, &mut self.ws.fd, &mut h.cd, t, h.watch)?;
        let tolerances = self.scene.integrator().tolerances();
        for (k, was) in onset_before.iter().enumerate() {
            // a new onset's blend speed, fixed for the onset (`onset_speed`)
            if h.state.onset[k].is_some() && was.is_none() {
                h.cd.onset_speed[k] = onset_speed(tolerances, &h.cd.rows, k, &y[self.layout.qd()], measured_len(h, y.len()), h.settings.onset_slip_speed);
            }
        }
        for k in 0..h.contacts.len() {
            // a contact an impact closed and the mode problem separates at ġ ≈ 0 (g̈ > 0):
            // its departure is located from g₀ − `zeno::DEPARTURE_DEPTH`
            let st = h.settings;
            if std::mem::take(&mut h.landed[k]) && h.state.mode[k] == ContactMode::Separated && h.cd.rows.gap[k].abs() <= st.gap_tol && h.cd.rows.vel[3 * k].abs() <= st.vel_tol {
                h.gap_ref[k] = h.cd.rows.gap[k].min(0.0) - DEPARTURE_DEPTH;
                h.rebound_t[k] = t;
                h.rebound[k] = false;
            }
        }
        let mut events = Vec::new();
        for k in 0..h.contacts.len() {
            let (a, b) = (before[k], h.state.mode[k]);
            if b == ContactMode::Sliding {
                h.s_ref[k] = slip_direction(h.cd.rows.slip(k), h.state.slip[k]);
            }
            if a == b || logged.contains(&k) {
                continue;
            }
            let kind = match (a, b) {
                (ContactMode::Separated, _) => ContactEventKind::TouchDown,
                (_, ContactMode::Separated) => ContactEventKind::LiftOff,
                (ContactMode::Sticking, ContactMode::Sliding) => ContactEventKind::StickToSlip,
                _ => ContactEventKind::SlipToStick,
            };
            let gd = h.cd.rows.vel[3 * k];
            events.push(ContactEvent { t, contact: k, kind, impulse: 0.0, energy_lost: 0.0, gap_rate_before: gd, gap_rate_after: gd });
        }
        for e in events {
            self.log(e)?;
        }
        Ok(())
    }

    /// After the modes are chosen at an event (rows at the post-event state, from
    /// `resolve_modes`): every separated unilateral contact at the table (|g| ≤ gap_tol) that
    /// leaves it with ġ > vel_tol has its touch-down function re-based at the restart
    /// ([`REBOUND_START`]); a contact that closes has it at `g` again.
    /// A rebound the step control does not resolve (ġ⁺ ≤ [`gap_resolution`] at `y`) has its
    /// return located `zeno::DEPARTURE_DEPTH` below its restart gap (`rebound_depth`).
    pub(super) fn mark_rebounds(&mut self, y: &[f64]) {
        let (tolerances, qd) = (self.scene.integrator().tolerances(), self.layout.qd());
        let Some(h) = &mut self.hybrid else { return };
        let st = h.settings;
        for (k, c) in h.contacts.iter().enumerate() {
            if !matches!(c.model, ContactModel::Unilateral { .. }) {
                continue;
            }
            if h.state.mode[k] == ContactMode::Separated {
                let gd = h.cd.rows.vel[3 * k];
                if h.cd.rows.gap[k].abs() <= st.gap_tol && gd > st.vel_tol {
                    h.rebound[k] = true;
                    let resolved = gap_resolution(tolerances, &h.cd.rows, k, &y[qd.clone()], measured_len(h, y.len()));
                    h.rebound_depth[k] = if gd <= resolved { DEPARTURE_DEPTH } else { 0.0 };
                }
            } else {
                h.gap_ref[k] = 0.0;
                h.rebound_t[k] = f64::NAN;
                h.rebound[k] = false;
            }
        }
    }

    /// After an accepted step: a contact that left with a separating speed and is now above the
    /// table (g > 0) has its touch-down function back at `g` (the next step's start values are
    /// taken after this), so its next touch-down is located at g = 0. A flight shorter than one
    /// step returns to its restart gap g₀ (≤ |ġ| · 1e-12 s below the table).
    pub(super) fn release_rebounds(&mut self, y: &[f64]) {
        let l = self.layout;
        let model = &self.scene.model;
        let Some(h) = &mut self.hybrid else { return };
        if h.rebound_t.iter().all(|t| t.is_nan()) {
            return;
        }
        forward_kinematics(model, &mut self.ws.data, &y[l.q()]);
        for (k, c) in h.contacts.iter().enumerate() {
            if !h.rebound_t[k].is_nan() && h.state.mode[k] == ContactMode::Separated && c.gap(&self.ws.data) > 0.0 {
                h.gap_ref[k] = 0.0;
                h.rebound_t[k] = f64::NAN;
            }
        }
    }

    /// After an accepted step: the slip directions the next step's ev1 refers to.
    pub(super) fn refresh_slip_reference(&mut self, y: &[f64]) {
        let l = self.layout;
        let model = &self.scene.model;
        let tolerances = self.scene.integrator().tolerances();
        let Some(h) = &mut self.hybrid else { return };
        if !h.state.mode.iter().any(|&m| m == ContactMode::Sliding) {
            return;
        }
        forward_kinematics(model, &mut self.ws.data, &y[l.q()]);
        forward_velocities(model, &mut self.ws.data, &y[l.qd()]);
        for (k, c) in h.contacts.iter().enumerate() {
            if h.state.mode[k] == ContactMode::Sliding {
                let v = c.touch_velocity(&self.ws.data);
                let v_t = [c.t1.dot(&v), c.t2.dot(&v)];
                // an onset ends once its slip is past the blend (`forward::onset_anchors`) along
                // the direction its friction opposes (`cd.anchor`, the last solve's); its friction
                // followed the turning anchor, not the event's direction, so the slip's own
                // direction is the reference from here (keeping the side of the event's
                // direction flipped it when the anchor had turned by more than 90°: the friction
                // then pushed the slip on, random seed 0xd65892bc06595083 at 0.0669 s). A slip
                // past the blend but run back across the anchor is the integrator's noise (at
                // rtol 1e-3 a step's slip error is ~atol = 1e-5 m/s): the onset goes on, its
                // friction opposing that slip and its stop the stick's excess (ending it there
                // made the noise the reference: whole-table at rtol 1e-3 took a slip of 2.7e-5
                // m/s against the anchor for the slip at 0.24477 s, stopped it 2e-8 s later, and
                // recorded friction along the slip, π rad, at 0.245 s). "Past the blend" is past
                // what the integrator resolves too ([`slip_resolution`]; above v_s only at loose
                // tolerances): at rtol 1e-3, atol 1e-5 the slip's first steps after whole-table's
                // onset at 0.24476 s were its error (2e-5 … 8e-5 m/s, turning by up to 180°
                // from step to step, where rtol 1e-6 has 1e-8 m/s along the anchor); an onset
                // ended on the first of them (2.3e-5 m/s, 35° off the anchor) took that noise
                // as its reference, the reference turned round with the next steps, a slip
                // reversal inside a step went unseen by v_t · s_ref and the friction kept on
                // the reference's side pushed it on (π rad at 0.245 s). Until then the
                // reference keeps the anchor's side (the sticking force's impending direction)
                let a = h.cd.anchor[k];
                // (and past twice a plain slip's stop speed, so the slip it becomes is not
                // stopped at once: `contact_events::slip_stop_speed`; and past the onset's own
                // blend speed, `onset_speed`, so its friction is Coulomb's when it ends)
                let res = slip_resolution(tolerances, &h.cd.rows, k, &y[l.qd()], measured_len(h, y.len()));
                let resolved = SLIP_DIRECTION_SPEED.max(res).max(2.0 * super::contact_events::slip_stop_speed(tolerances, &h.cd.rows, k, &y[l.qd()], measured_len(h, y.len()), h.settings.onset_slip_speed)).max(h.cd.onset_speed[k]);
                let ends = h.state.onset[k].is_some() && v_t[0].hypot(v_t[1]) > resolved && v_t[0] * a[0] + v_t[1] * a[1] > 0.0;
                h.s_ref[k] = slip_direction(v_t, if ends { v_t } else { a });
                h.state.slip[k] = h.s_ref[k];
                if ends {
                    h.state.onset[k] = None;
                }
            }
        }
    }
}
