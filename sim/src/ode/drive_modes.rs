//! The drives' discrete state as events of the hybrid driver (`integrate::events`): the gears'
//! stick/slide and power-direction modes (`dynamics/gear_friction.rs`) and the sides of the
//! supply's max() functions (`dynamics/supply.rs`). Present only in scenes with `gear_friction`
//! or `supply` (the paper's runs have neither: their state, steps and bytes are unchanged).
//!
//! Event functions, after the contacts' `2 n_c` (all of direction −1):
//!
//! | function | mode | value | at its root |
//! |---|---|---|---|
//! | `2 j` (gear j) | slide in `s` | `s q̇_j` | stick if the holding torque is in the band, else reverse |
//! | `2 j` | stick | `τ_s + \|1 − c_s\| \|K_m i\| − \|λ_j\|` | break away in `s = −sign λ_j` |
//! | `2 j + 1` | slide, driving (σ = 1) or back-driving (σ = −1) | `σ s K_m i_j` | the other power direction |
//! | `2 nv + j` (supply) | a drive without regeneration, side σ | `σ p_j` | the other side |
//! | `3 nv` | the bus, side σ | `σ P_b` | the other side |
//!
//! The right-hand side in fixed modes (the sliding torques, the holding torques of the sticking
//! joints, the gear loss and the supply's rates) is `drive_forces.rs`; the decision of the
//! joints' modes at an event (together, and by slopes where the deciding functions are 0: an
//! efficiency-only gear at i = 0) is `gear_decide.rs`. When a sliding joint
//! stops (slide → stick), the speed the root location leaves (|q̇_j| of the order of the event
//! time tolerance times q̈) is removed and the kinetic energy it carried booked as gear loss,
//! as the contacts' slip → stick does (`stop_slip.rs`; Pfeiffer & Glocker 1996, ch. 6).

#![allow(clippy::result_large_err)] // RunError carries schemas::Error, as in `run.rs`

use crate::dynamics::gear_friction::GearMode;
use crate::error::RunError;
use crate::integrate::HybridSystem;

use super::arm::ArmSystem;
use super::gear_hold::HoldScratch;

/// A change of a gear's mode: at time `t` (s), joint `joint` entered `mode`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GearEvent {
    pub t: f64,
    pub joint: usize,
    pub mode: GearMode,
}

/// The gear log keeps the first this many events of a run (a diagnostic; bounded memory).
const MAX_GEAR_LOG: usize = 10_000;

/// The drives' modes and the scratch of the sticking solve (sized once).
#[derive(Clone, Debug)]
pub(crate) struct DriveModes {
    /// Per joint: its gear's mode (`Slide` with no torque on joints without a gear law).
    pub(crate) gear: Vec<GearMode>,
    /// Per joint: the gear's torque beyond the ideal train (sliding terms, or the holding λ
    /// while sticking), N m; written by every evaluation.
    pub(crate) gear_torque: Vec<f64>,
    /// Per joint: the supply takes its power as ≥ 0.
    pub(crate) pos: Vec<bool>,
    /// The bus power is taken as ≥ 0.
    pub(crate) bus_pos: bool,
    /// Scratch: the sticking joints, q̈ without the holding torques, G_SS, λ, the torques saved.
    pub(super) stuck: Vec<usize>,
    pub(super) qdd0: Vec<f64>,
    pub(super) g: Vec<f64>,
    pub(super) lambda: Vec<f64>,
    /// Scratch: the sticking joints' bands and the choice among their holding torques.
    pub(super) lo: Vec<f64>,
    pub(super) hi: Vec<f64>,
    pub(super) hold: HoldScratch,
    /// Scratch: the electric powers p_j (nv).
    pub(crate) power: Vec<f64>,
    /// The gears' mode changes (events and the start), first [`MAX_GEAR_LOG`].
    log: Vec<GearEvent>,
}

impl DriveModes {
    pub(crate) fn new(nv: usize) -> Self {
        DriveModes {
            gear: vec![GearMode::Slide { dir: 1, driving: true }; nv],
            gear_torque: vec![0.0; nv],
            pos: vec![true; nv],
            bus_pos: true,
            stuck: Vec::with_capacity(nv),
            qdd0: vec![0.0; nv],
            g: vec![0.0; nv * nv],
            lambda: vec![0.0; nv],
            lo: vec![0.0; nv],
            hi: vec![0.0; nv],
            hold: HoldScratch::new(nv),
            power: vec![0.0; nv],
            log: Vec::new(),
        }
    }
}

impl ArmSystem<'_> {
    /// Whether the run is integrated event by event: a non-bilateral contact, or drive modes.
    pub fn is_event_driven(&self) -> bool {
        self.hybrid.is_some() || self.drive_modes.is_some()
    }

    /// Number of the drives' event functions: `2 nv` with a gear law, `nv + 1` with a supply.
    pub(super) fn n_drive_events(&self) -> usize {
        if self.drive_modes.is_none() {
            return 0;
        }
        let nv = self.layout.nv;
        2 * nv + nv + 1
    }

    /// The drives' event functions at (t, y) after an evaluation there (module docs).
    pub(super) fn drive_events(&mut self, y: &[f64], out: &mut [f64]) {
        let l = self.layout;
        let nv = l.nv;
        out.fill(1.0);
        if let Some(g) = &self.scene.gear_friction {
            let m = self.drive_modes.as_ref().expect("drive modes");
            for j in 0..nv {
                if !g.active(j) {
                    continue;
                }
                let km_i = self.km_i(y, j);
                match m.gear[j] {
                    GearMode::Stick => out[2 * j] = g.stick_margin(j, km_i, m.gear_torque[j]),
                    GearMode::Slide { dir, driving } => {
                        let s = f64::from(dir);
                        out[2 * j] = s * y[l.qd().start + j];
                        out[2 * j + 1] = if driving { 1.0 } else { -1.0 } * s * km_i;
                    }
                }
            }
        }
        if let Some(s) = &self.scene.supply {
            self.powers_into_scratch(y);
            let m = self.drive_modes.as_ref().expect("drive modes");
            for j in 0..nv {
                if s.clips(j) {
                    out[2 * nv + j] = if m.pos[j] { 1.0 } else { -1.0 } * m.power[j];
                }
            }
            // the bus (or the summed supplies): P_s has the sign of P_b, and the energy
            // regenerated switches there
            let w = s.powers(&m.power, &m.pos, m.bus_pos);
            out[3 * nv] = if m.bus_pos { 1.0 } else { -1.0 } * w.bus;
        }
    }

    /// Every drive function is watched from its start value when it starts on its firing side
    /// (`integrate::events`): a mode is chosen at a point where its function is 0 (a joint
    /// breaking away from rest, a power that starts at 0), and the function may leave 0 to
    /// either side; how far it must move: a sticking margin 1e-9 N m, a speed 1e-12 rad/s, a
    /// torque `K_m i` 1e-10 N m, a power 1e-10 W (far below anything that matters, far above
    /// the rounding of the solve).
    pub(super) fn drive_event_tolerance(&self, i: usize) -> Option<f64> {
        let m = self.drive_modes.as_ref()?;
        let nv = self.layout.nv;
        Some(if i < 2 * nv {
            match (m.gear[i / 2], i % 2) {
                (GearMode::Stick, 0) => 1e-9,
                (_, 0) => 1e-12,
                _ => 1e-10,
            }
        } else {
            1e-10
        })
    }

    /// The gears' mode changes so far, in time order (empty without `gear_friction`).
    pub fn gear_events(&self) -> &[GearEvent] {
        self.drive_modes.as_ref().map_or(&[], |m| &m.log[..])
    }

    pub(super) fn log_gear(&mut self, t: f64, joint: usize, mode: GearMode) {
        let m = self.drive_modes.as_mut().expect("drive modes");
        if m.log.len() < MAX_GEAR_LOG {
            m.log.push(GearEvent { t, joint, mode });
        }
    }

    /// Set joint j's speed to 0 (it stops): the M_J-weighted velocity projection that keeps the
    /// bilateral constraints' velocity rows and the sticking joints at rest (as the contacts'
    /// slip → stick, `stop_slip.rs`; in a closed chain other joints move with j), its
    /// kinetic-energy change booked as gear loss, the rotors' share into W_j as at impacts.
    /// Uses M and J_c of the evaluation at y. Allocates (an event, not the step loop).
    fn stop_joint(&mut self, y: &mut [f64], j: usize) {
        use nalgebra::{DMatrix, DVector};
        let l = self.layout;
        let nv = l.nv;
        let d = &self.scene.drives;
        let m = &self.ws.data.m;
        let modes = self.drive_modes.as_ref().expect("drive modes");
        let qd = DVector::from_column_slice(&y[l.qd()]);
        let mut m_j = m.clone();
        for k in 0..nv {
            m_j[(k, k)] += d.jm[k];
        }
        // rows: the bilateral constraints (a hybrid run's contact rows are the contacts' own
        // and are left to their handler), the sticking joints, and j
        let nc = if self.hybrid.is_some() { 0 } else { self.contacts.len() };
        let held: Vec<usize> = (0..nv).filter(|&k| k == j || modes.gear[k] == GearMode::Stick).collect();
        let rows = nc + held.len();
        let mut a = DMatrix::zeros(rows, nv);
        let mut b = DVector::zeros(rows);
        for r in 0..nc {
            for c in 0..nv {
                a[(r, c)] = self.ws.fd.jac[(r, c)];
            }
        }
        for (r, &k) in held.iter().enumerate() {
            a[(nc + r, k)] = 1.0;
            b[nc + r] = -qd[k];
        }
        let Some(chol) = m_j.clone().cholesky() else { return };
        let minv_at = chol.solve(&a.transpose());
        let s = &a * &minv_at;
        let mu = match s.svd(true, true).solve(&b, 1e-12) {
            Ok(mu) => mu,
            Err(_) => return,
        };
        let dq = &minv_at * mu;
        let d_t = qd.dot(&(&m_j * &dq)) + 0.5 * dq.dot(&(&m_j * &dq));
        for k in 0..nv {
            let (before, after) = (qd[k], qd[k] + dq[k]);
            y[l.work().start + k] += -d.jm[k] * (after * after - before * before) / 2.0;
            y[l.qd().start + k] = after;
        }
        // the held joints exactly at rest (the projection leaves them there to rounding)
        for &k in &held {
            y[l.qd().start + k] = 0.0;
        }
        if let Some(k) = l.loss_gear() {
            y[k] -= d_t;
        }
    }

    /// Stop the sliding joints `which` (their speed the root location leaves, |q̇| of the order
    /// of the dense output's error at the root, removed and its kinetic energy booked as gear
    /// loss; each held at rest while the next stops). Returns whether y moved.
    fn stop_joints(&mut self, t: f64, y: &mut [f64], which: &[usize]) -> Result<bool, RunError> {
        let l = self.layout;
        let mut moved = false;
        for &j in which {
            if y[l.qd().start + j] != 0.0 {
                self.evaluate(t, y)?;
                self.stop_joint(y, j);
                moved = true;
            }
            self.drive_modes.as_mut().expect("drive modes").gear[j] = GearMode::Stick;
        }
        Ok(moved)
    }

    /// The supply's sides at the true signs at (t, y).
    fn settle_supply(&mut self, t: f64, y: &[f64]) -> Result<(), RunError> {
        if self.scene.supply.is_none() {
            return Ok(());
        }
        self.evaluate(t, y)?;
        self.powers_into_scratch(y);
        let s = self.scene.supply.as_ref().expect("supply");
        let m = self.drive_modes.as_mut().expect("drive modes");
        m.bus_pos = s.sides(&m.power, &mut m.pos);
        Ok(())
    }

    /// The drives' modes at the start: a moving joint slides its way; the joints at rest are
    /// decided together, preferring for each what it would do alone (stick when its holding
    /// torque with every joint at rest sticking is in its band, else slide the way it pushes).
    pub(super) fn init_drive_modes(&mut self, t: f64, y: &mut [f64]) -> Result<bool, RunError> {
        if self.drive_modes.is_none() {
            return Ok(false);
        }
        let scene = self.scene;
        if let Some(g) = &scene.gear_friction {
            let l = self.layout;
            let nv = l.nv;
            self.inputs(t, y)?;
            for j in 0..nv {
                let (qd, km_i) = (y[l.qd().start + j], self.km_i(y, j));
                let mode = if qd != 0.0 || !g.active(j) { GearMode::slide(qd, km_i) } else { GearMode::Stick };
                self.drive_modes.as_mut().expect("drive modes").gear[j] = mode;
                if qd != 0.0 && g.active(j) {
                    self.log_gear(t, j, mode);
                }
            }
            // a first guess for the joints at rest: from every one sticking, free the one
            // whose holding torque is furthest out of its band (the way it pushes), again
            // until every sticking joint holds to its rounding (at most one pass per joint;
            // a joint on its band's edge, e.g. unloaded at i = 0, is left to the decision)
            for _ in 0..nv {
                self.evaluate(t, y)?;
                let m = self.drive_modes.as_ref().expect("drive modes");
                let worst = (0..nv)
                    .filter(|&j| g.active(j) && m.gear[j] == GearMode::Stick)
                    .map(|j| (j, g.stick_margin(j, self.km_i(y, j), m.gear_torque[j])))
                    .filter(|&(j, margin)| margin < -1e-8 * (1.0 + m.gear_torque[j].abs()))
                    .min_by(|a, b| a.1.total_cmp(&b.1));
                let Some((j, _)) = worst else { break };
                let (km_i, lambda) = (self.km_i(y, j), m.gear_torque[j]);
                self.drive_modes.as_mut().expect("drive modes").gear[j] = GearMode::slide(if lambda > 0.0 { -1.0 } else { 1.0 }, km_i);
            }
            let preferred = self.drive_modes.as_ref().expect("drive modes").gear.clone();
            for j in 0..nv {
                if g.active(j) && y[l.qd().start + j] == 0.0 {
                    self.drive_modes.as_mut().expect("drive modes").gear[j] = GearMode::Stick;
                }
            }
            self.decide_gears(t, y, &preferred, &[], true)?;
        }
        self.settle_supply(t, y)?;
        Ok(false)
    }

    /// The drives' events `fired` (their own indices) at (t, y).
    pub(super) fn handle_drive_events(&mut self, t: f64, y: &mut [f64], fired: &[bool]) -> Result<bool, RunError> {
        if self.drive_modes.is_none() {
            return Ok(false);
        }
        let nv = self.layout.nv;
        let mut moved = false;
        // the power directions of sliding joints: a flip each
        for j in 0..nv.min(fired.len() / 2) {
            if !fired[2 * j] && fired[2 * j + 1] {
                if let GearMode::Slide { dir, driving } = self.drive_modes.as_ref().expect("drive modes").gear[j] {
                    self.drive_modes.as_mut().expect("drive modes").gear[j] = GearMode::Slide { dir, driving: !driving };
                    self.log_gear(t, j, GearMode::Slide { dir, driving: !driving });
                }
            }
        }
        // stick/slip: the stopping joints stop, the breaking-away ones prefer to slide the way
        // their holding torque pushed, then every joint at rest is decided together
        let stick_slip: Vec<usize> = (0..nv.min(fired.len() / 2)).filter(|&j| fired[2 * j]).collect();
        if !stick_slip.is_empty() {
            self.evaluate(t, y)?;
            let m = self.drive_modes.as_ref().expect("drive modes");
            let mut preferred = m.gear.clone();
            let mut stopping = Vec::new();
            for &j in &stick_slip {
                if m.gear[j] == GearMode::Stick {
                    let lambda = m.gear_torque[j];
                    preferred[j] = GearMode::slide(if lambda > 0.0 { -1.0 } else { 1.0 }, self.km_i(y, j));
                } else {
                    preferred[j] = GearMode::Stick;
                    stopping.push(j);
                }
            }
            let was = self.drive_modes.as_ref().expect("drive modes").gear.clone();
            moved |= self.stop_joints(t, y, &stopping)?;
            // a stopped joint prefers to stick when its holding torque (the others in their
            // modes) is in its band, else to slide the way that torque pushes
            if !stopping.is_empty() {
                self.evaluate(t, y)?;
                let g = self.scene.gear_friction.as_ref().expect("gear friction");
                let m = self.drive_modes.as_ref().expect("drive modes");
                for &j in &stopping {
                    let (km_i, lambda) = (self.km_i(y, j), m.gear_torque[j]);
                    if g.stick_margin(j, km_i, lambda) < 0.0 {
                        preferred[j] = GearMode::slide(if lambda > 0.0 { -1.0 } else { 1.0 }, km_i);
                    }
                }
            }
            self.drive_modes.as_mut().expect("drive modes").gear.copy_from_slice(&was);
            let fired_joint: Vec<bool> = (0..nv).map(|j| stick_slip.contains(&j)).collect();
            self.decide_gears(t, y, &preferred, &fired_joint, false)?;
        }
        if fired.get(2 * nv..).is_some_and(|f| f.iter().any(|&x| x)) {
            let m = self.drive_modes.as_mut().expect("drive modes");
            for j in 0..nv {
                if fired[2 * nv + j] {
                    m.pos[j] = !m.pos[j];
                }
            }
            if fired[3 * nv] {
                m.bus_pos = !m.bus_pos;
            }
        }
        Ok(moved)
    }

    /// The joints whose gear functions are all of `text`'s event functions (the driver's
    /// "event functions [i, j, ...]" of a chattering error), and whether any of their gears has
    /// a breakaway torque; `None` when another function is among them (a contact's, a
    /// supply's) or the text is not such a list.
    pub fn chattering_gears(&self, text: &str) -> Option<(Vec<String>, bool)> {
        let list = text.strip_prefix("event functions [")?.strip_suffix(']')?;
        let nc = self.contact_n_events();
        let nv = self.layout.nv;
        let g = self.scene.gear_friction.as_ref()?;
        let mut joints: Vec<String> = Vec::new();
        let mut breakaway = false;
        for part in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let i = part.parse::<usize>().ok()?.checked_sub(nc)?;
            if i >= 2 * nv {
                return None;
            }
            breakaway |= g.breakaway[i / 2] > 0.0;
            let name = self.scene.model.bodies[i / 2].joint.clone();
            if !joints.contains(&name) {
                joints.push(name);
            }
        }
        (!joints.is_empty()).then_some((joints, breakaway))
    }

    /// "gear of <joint> (...)" or "supply (...)" for the drives' event function `i`.
    pub(super) fn describe_drive_event(&self, i: usize) -> Option<String> {
        let m = self.drive_modes.as_ref()?;
        let nv = self.layout.nv;
        let joint = |j: usize| self.scene.model.bodies[j].joint.clone();
        Some(if i < 2 * nv {
            let what = match (m.gear[i / 2], i % 2) {
                (GearMode::Stick, 0) => "stick-to-slide",
                (GearMode::Stick, _) => "sticking: constant",
                (_, 0) => "velocity reversal",
                _ => "power direction",
            };
            format!("gear of {} ({what} function)", joint(i / 2))
        } else if i < 3 * nv {
            format!("supply of {} (power sign function)", joint(i - 2 * nv))
        } else if i == 3 * nv {
            "supply bus (power sign function)".into()
        } else {
            return None;
        })
    }
}

/// The arm's events: the contacts' `2 n_c` functions (`hybrid.rs`), then the drives' (this
/// file).
impl HybridSystem for ArmSystem<'_> {
    fn n_events(&self) -> usize {
        self.contact_n_events() + self.n_drive_events()
    }

    fn event_direction(&self, i: usize) -> i8 {
        let nc = self.contact_n_events();
        if i < nc {
            self.contact_event_direction(i)
        } else {
            -1
        }
    }

    fn event_tolerance(&self, i: usize) -> Option<f64> {
        let nc = self.contact_n_events();
        if i < nc {
            self.contact_event_tolerance(i)
        } else {
            self.drive_event_tolerance(i - nc)
        }
    }

    fn event_departure(&self, i: usize) -> Option<f64> {
        let nc = self.contact_n_events();
        if i < nc {
            self.contact_event_departure(i)
        } else {
            self.drive_event_tolerance(i - nc)
        }
    }

    fn events(&mut self, t: f64, y: &[f64], out: &mut [f64]) -> Result<(), RunError> {
        let nc = self.contact_n_events();
        self.contact_events(t, y, &mut out[..nc])?;
        if self.drive_modes.is_some() {
            if self.hybrid.is_none() {
                self.evaluate(t, y)?;
            }
            self.drive_events(y, &mut out[nc..]);
        }
        Ok(())
    }

    fn init_modes(&mut self, t: f64, y: &mut [f64]) -> Result<bool, RunError> {
        let moved = self.contact_init_modes(t, y)?;
        Ok(self.init_drive_modes(t, y)? || moved)
    }

    fn handle_events(&mut self, t: f64, y: &mut [f64], fired: &[bool]) -> Result<bool, RunError> {
        let nc = self.contact_n_events();
        let mut moved = false;
        if fired[..nc].iter().any(|&f| f) {
            moved = self.contact_handle_events(t, y, &fired[..nc])?;
        }
        Ok(self.handle_drive_events(t, y, &fired[nc..])? || moved)
    }

    fn after_step(&mut self, _t: f64, y: &[f64]) {
        self.contact_after_step(y);
    }

    /// Only without the drives' events (gear friction, the supply): carrying RODAS5P's step
    /// over them broke its error ∝ rtol (`HybridSystem::restart_keeps_step_size`); over the
    /// contacts' events it keeps the event lists and cuts the paper-unilateral runs' work by
    /// 45 % (BENCHMARKS.md, issue 24).
    fn restart_keeps_step_size(&self) -> bool {
        self.drive_modes.is_none()
    }
}
