//! Forward dynamics of the arm with contacts of any model, in the current contact modes: the
//! general active-row path NEXT TO the untouched bilateral path of `dynamics/forward.rs` (the
//! paper's runs never come here). Same generalised force b and inertia `M_J = M + J_m` as
//! eq 21 (the same calls in the same order), then compliant forces added to b
//! (`J_nᵀ f_n + J_tᵀ f_t`), then the active rows of the modes ([`super::solve`]).
//!
//! Compliant model (Hunt–Crossley-like linear spring-damper clipped at zero, Acary & Brogliato,
//! *Numerical Methods for Nonsmooth Dynamical Systems*, 2008, §2.2): `f_n = max(0, k δ + c δ̇)`
//! for `δ = −g > 0`, friction `f_t = −μ f_n v_t / sqrt(|v_t|² + v_s²)`.

use super::rows::{contact_rows, contact_rows_only, contact_velocities_only, ContactRows};
use super::solve::{solve_active, ActiveRow, ActiveScratch, RowForce, Singular};
use super::{Contact, ContactMode, ContactModel};
use crate::dynamics::cholesky;
use crate::dynamics::data::Data;
use crate::dynamics::forward::{generalized_force_and_inertia, generalized_force_placed, ForwardData, Plant, Stabilization};
use crate::dynamics::kinematics::forward_velocities;
use crate::error::DynamicsError;

/// The discrete state of a run's contacts: the mode of each, and the slip direction
/// `[s1, s2]` (unit, in the contact's tangent basis) a sliding contact uses while its slip
/// velocity is below `vel_tol` (at the start of a slip).
#[derive(Clone, Debug, PartialEq)]
pub struct ContactState {
    pub mode: Vec<ContactMode>,
    pub slip: Vec<[f64; 2]>,
    /// Per contact: `Some(r)` for a slip that started from rest (a stick → slip onset) and has
    /// not reached [`SLIP_DIRECTION_SPEED`] at the end of a step yet. Below that speed its
    /// friction's blend turns towards the impending direction of the sticking force at the
    /// current state turned by the rotation `r = (cos, sin)` ([`onset_anchors`]; `r` takes the
    /// impending direction to the slip direction the mode problem chose at the onset), not
    /// towards the fixed `slip`.
    pub onset: Vec<Option<[f64; 2]>>,
}

impl ContactState {
    /// Bilateral contacts `Bilateral`, the others `Separated` (the mode problem at t0 decides).
    pub fn new(contacts: &[Contact]) -> Self {
        ContactState {
            mode: contacts.iter().map(|c| if c.model == ContactModel::Bilateral { ContactMode::Bilateral } else { ContactMode::Separated }).collect(),
            slip: vec![[1.0, 0.0]; contacts.len()],
            onset: vec![None; contacts.len()],
        }
    }
}

/// Scratch and outputs of the contact dynamics, sized once for (nv, nc).
#[derive(Clone, Debug)]
pub struct ContactData {
    pub rows: ContactRows,
    pub active: Vec<ActiveRow>,
    pub scratch: ActiveScratch,
    /// Per contact: normal force f_n (N) and friction force `[t1, t2]` (N) of the last solve.
    pub f_n: Vec<f64>,
    pub f_t: Vec<[f64; 2]>,
    /// Per contact: the stick margin `μ f_n − |f_t|` of the last solve (N) while sticking, the
    /// largest over the forces a statically indeterminate contact admits
    /// (`indeterminate.rs`; `+∞` when jammed); 0 in the other modes.
    pub margin: Vec<f64>,
    /// Per contact: the direction a sliding contact's friction blends towards below
    /// [`SLIP_DIRECTION_SPEED`] in the last solve (unit, tangent basis): the stored slip
    /// direction, or during an onset the impending direction ([`onset_anchors`]).
    pub anchor: Vec<[f64; 2]>,
    /// Per contact in an onset (`ContactState::onset`, sliding with friction): the excess
    /// `|f*_t| − μ f*_n` (N) of the force `f*` that would keep it sticking at this state (the
    /// largest margin's, as the stick's event), from [`onset_anchors`]; NaN otherwise. Positive
    /// while the stick stays broken; the onset's slip → stick function (`ode/hybrid.rs`).
    pub onset_excess: Vec<f64>,
    /// Per contact: in an onset in the last solve (`ContactState::onset`): its friction opposes
    /// a slip that runs back across the anchor ([`active_rows_of`]).
    onset_now: Vec<bool>,
    /// Per contact in an onset: the slip speed below which its friction's direction blends
    /// towards the anchor ([`onset_direction`]'s `v_on`), m/s, fixed at the onset's start
    /// (`ode/hybrid.rs`, `onset_speed`): [`SLIP_DIRECTION_SPEED`] unless the integrator's
    /// resolution of the slip is coarser. Read only while the contact is in an onset (set
    /// at each onset's start; a value left from an ended onset is never read).
    pub onset_speed: Vec<f64>,
    /// Scratch of [`onset_anchors`]: the modes with the onset contacts sticking.
    stick_mode: Vec<ContactMode>,
    /// Scratch of the groups of sticking contacts dependent across contacts
    /// ([`super::dependent`]).
    dependent: super::dependent::DependentScratch,
}

impl ContactData {
    pub fn new(nv: usize, nc: usize) -> Self {
        ContactData {
            rows: ContactRows::new(nv, nc),
            active: Vec::with_capacity(3 * nc),
            scratch: ActiveScratch::new(nv, nc),
            f_n: vec![0.0; nc],
            f_t: vec![[0.0; 2]; nc],
            margin: vec![0.0; nc],
            anchor: vec![[1.0, 0.0]; nc],
            onset_excess: vec![f64::NAN; nc],
            onset_now: vec![false; nc],
            onset_speed: vec![SLIP_DIRECTION_SPEED; nc],
            stick_mode: vec![ContactMode::Separated; nc],
            dependent: super::dependent::DependentScratch::new(nc),
        }
    }
}

/// Slip speeds below this blend the friction's direction towards the stored slip direction
/// (m/s): the direction `v_t/|v_t|` of Coulomb friction turns at a rate `|a_t⊥|/|v_t|`,
/// unbounded as a slip starts or stops, and below ~1e-12 m/s it is the solver's rounding. Below
/// this speed the friction acts along [`friction_direction`], which turns smoothly from the
/// stored direction (at rest: the direction `−f_t/|f_t|` of the sticking force that left the
/// cone, or the slip direction at the start of the step) to `v_t/|v_t|` (reached at this speed,
/// with its first derivative). This is a regularisation of the direction only, not a stick
/// rule: a slip stops where `v_t · s_ref` reaches 0 (a located event, `ode/hybrid.rs`). Its
/// effect on the motion is bounded by the time spent below it, `SLIP_DIRECTION_SPEED / |a_t|`
/// ≈ 2e-7 s at 5 m/s², over which the position moves ≤ `SLIP_DIRECTION_SPEED² / |a_t|` ≈
/// 2e-13 m; in 1-D (a slip along a fixed line) the direction is exact.
pub const SLIP_DIRECTION_SPEED: f64 = 1e-6;

/// The factor K between a stick → slip onset's blend speed and the integrator's resolution of
/// its slip (`ode/hybrid.rs::onset_speed`): the slip's direction resolved to 1/K rad. In the
/// prototype K = 20 and 50 gave the same ladder as 30, K = 10 left dopri45 at rtol 1e-6 at
/// 188 585 right-hand sides (BENCHMARKS.md, issue 24 "point 3 again" and "eighth pass").
pub const ONSET_RESOLUTION_FACTOR: f64 = 30.0;

/// The largest blend speed of an onset in a run integrated by `integrator`, m/s, fixed at the
/// start (the record `contacts` states it for the audit): `max(v_s, K · rtol · 1 m/s)`, K =
/// [`ONSET_RESOLUTION_FACTOR`], for the methods that take the friction's direction explicitly
/// (dopri45; imex, whose implicit part is the armature circuits; rosenbrock, whose structured
/// Jacobian, `ode/jacobian.rs`, linearises the drives and the controller, not the friction),
/// where an onset's slip held at the integrator's resolution sits at the stability limit of
/// the direction's stiffness `μ f_n / (m |v_t|)` (≈ 2e6 /s at 2e-6 m/s on elbow7 at 0.2446 s;
/// Hairer & Wanner, *Solving ODEs II*, §IV.2: an explicit method's step is bounded by its
/// stability region, whatever its accuracy). The slip
/// resolution `sqrt(n) |J_t (atol + rtol |q̇|)|` is dominated by its `rtol |q̇|` part at the
/// study's `atol = rtol/100`; on the paper's unilateral scene it is 0.08 … 0.97 × rtol × 1 m/s
/// at its onsets, so this bound caps nothing there. [`SLIP_DIRECTION_SPEED`] for rodas5p and
/// rodas4 (their Jacobian, differenced over q̇, has the direction's stiffness: no stability
/// limit, nothing to regularise), for rk4 (no tolerances) and at rtol ≤ 3.3e-8.
pub fn onset_speed_bound(integrator: &crate::integrator::Integrator) -> f64 {
    use crate::integrator::Integrator;
    const SPEED_SCALE: f64 = 1.0;
    match *integrator {
        Integrator::Dopri45(c) | Integrator::Imex(c) | Integrator::Rosenbrock { control: c, .. } => SLIP_DIRECTION_SPEED.max(ONSET_RESOLUTION_FACTOR * c.rtol * SPEED_SCALE),
        Integrator::Rodas { .. } | Integrator::Rk4 { .. } => SLIP_DIRECTION_SPEED,
    }
}

/// The direction an onset's friction opposes (unit, tangent basis; `ContactState::onset`):
/// `w/|w|` with `w = v_t + v_on ψ(|v_t|/v_on) anchor`, [`friction_direction`]'s blend (the same
/// since that lost its side-keeping sign) towards the anchor, at the onset's own speed `v_on`
/// (`ContactData::onset_speed`: `v_s`, or at loose tolerances of an explicit method up to
/// [`ONSET_RESOLUTION_FACTOR`] times the integrator's resolution of the slip, so the slip's
/// direction is resolved to 1/K rad; below v_on the friction's direction is the model's
/// regularisation, declared in the record `contacts` for the audit, [`onset_speed_bound`]). Read
/// `v_s` for `v_on` below wherever the tolerances resolve the slip below `v_s`. Coulomb's law (Glocker, *Set-Valued Force Laws*, 2001, §7; Pfeiffer &
/// Glocker 1996, §5.2): the friction opposes the slip, `−μ f_n v_t/|v_t|`, from `v_s` on in
/// every direction, a slip run back across the anchor included (it returns); below `v_s` the
/// direction is regularised towards the anchor, the direction the sticking force leaves the
/// cone ([`onset_anchors`]). `w` is smooth in `v_t` wherever it is not 0, and it is 0 at one
/// point only, `v_t = −0.525 v_s anchor` (`r = (1 − r²)²`), a slip running back along the
/// anchor at half `v_s`, 500× the integrator's noise on an onset's slip at rtol 1e-8. It
/// replaces a flip of the direction (`−friction_direction`) once the slip ran back across the
/// anchor by more than 1e-9 m/s: a jump of the friction by `2 μ f_n` (7.6 N on elbow7 at
/// 0.2446 s) on a surface `v_t · anchor = −1e-9 m/s` that the onset's noise-level slip
/// (|v_t| ≈ 4e-9 m/s, mostly across the anchor) sat on, which RODAS5P's stages straddled in
/// each of the 440 steps it rejected in that onset (two-elbow-unilateral, rtol 1e-8, with the
/// event-aware restart; BENCHMARKS.md, issue 24 item 1, fourth attempt).
pub fn onset_direction(v_t: [f64; 2], anchor: [f64; 2], v_on: f64) -> [f64; 2] {
    blended(v_t, (v_t[0] * v_t[0] + v_t[1] * v_t[1]) / (v_on * v_on), anchor, v_on)
}

/// `w/|w|`, `w = v + v_s (1 − r²)² toward` for `r² = |v_t|²/v_s² < 1` (else `w = v`): the
/// blend of [`friction_direction`] and [`onset_direction`], `v` the slip (signed by the
/// caller), `vs` the blend's speed and `r2` as the caller computed it; `toward` itself when
/// `w = 0`.
fn blended(v: [f64; 2], r2: f64, toward: [f64; 2], vs: f64) -> [f64; 2] {
    let blend = if r2 < 1.0 { vs * (1.0 - r2) * (1.0 - r2) } else { 0.0 };
    let w = [v[0] + blend * toward[0], v[1] + blend * toward[1]];
    let n = w[0].hypot(w[1]);
    if n > 0.0 {
        [w[0] / n, w[1] / n]
    } else {
        toward
    }
}

/// The slip direction of a sliding contact, continued through the stop: `±v_t/|v_t|` when
/// `|v_t|` > [`SLIP_DIRECTION_SPEED`], with the sign that keeps it on the side of `stored` (the
/// direction at the start of the step), else `stored`. While the slip runs along `stored` this is
/// `v_t/|v_t|`; past the slip's zero (`v_t · stored < 0`, where an integrator's trial stages
/// may go before the slip→stick event is located) it keeps its side instead of flipping. The
/// reference of the slip→stick function (`s_ref`, `ode/hybrid.rs`); the friction itself acts
/// along [`friction_direction`].
pub fn slip_direction(v_t: [f64; 2], stored: [f64; 2]) -> [f64; 2] {
    let s = v_t[0].hypot(v_t[1]);
    if s > SLIP_DIRECTION_SPEED {
        let sign = if v_t[0] * stored[0] + v_t[1] * stored[1] < 0.0 { -1.0 } else { 1.0 };
        [sign * v_t[0] / s, sign * v_t[1] / s]
    } else {
        stored
    }
}

/// The direction a sliding contact's friction opposes (unit, tangent basis): `w/|w|` with
/// `w = v_t + v_s ψ(|v_t|/v_s) stored`, `v_s` = [`SLIP_DIRECTION_SPEED`] and
/// `ψ(r) = (1 − r²)²` for `r < 1`, else 0: [`onset_direction`]'s blend towards the stored
/// direction (the slip direction at the start of the step). So it is Coulomb's `v_t/|v_t|`
/// from `v_s` on in every direction (the friction opposes the slip: maximal dissipation,
/// `−f_t · v_t = μ f_n |v_t|`; Moreau 1988; Glocker, *Set-Valued Force Laws*, 2001, §7),
/// `stored` at rest, and in between turns smoothly; along `stored` it is `stored` for every
/// `v_t · stored > −0.525 v_s`, so a slip that slows along a line and crosses its zero inside a
/// step meets the same friction on both sides, and the located slip → stick event
/// (`v_t · s_ref`, [`slip_direction`]) brackets the zero. `w` is 0 at one point only,
/// `v_t = −0.525 v_s stored`.
///
/// It kept the side of `stored` before (`σ v_t` for `w`'s slip, `σ` the sign of
/// `v_t · stored`), meant for the trial stages past a located stop. Past the zero that is
/// friction *along* the slip's part across `stored`: it pushes that part on where on
/// `stored`'s side it damps it (with a gain ~`μ f_n / v_s`, stiff), and beyond `v_s` it is
/// anti-Coulomb. A RODAS5P step that straddled the zero then had a dense
/// output running the slip through 0 and back to the same side (where-elbow's evaluation 95,
/// 0.5 kg, link 8 at s = 0.834, rtol 1e-5: the slip, 4.1e-6 m/s at the 3.682 s sample and
/// slowing at 4e-3 m/s², crossed 0 near 3.6828 s inside a step that ended with it at ~1.5e-5
/// m/s along `stored` again, so the slip → stick function kept its sign and the stop came
/// 4.3 ms late, at 3.687096 s; the 3.683 s sample recorded a slip of 1.36e-6 m/s reversed with
/// the friction along it: the audit's π rad; `scenes/contacts/audit-slip-reversal-05kg.json`).
pub fn friction_direction(v_t: [f64; 2], stored: [f64; 2]) -> [f64; 2] {
    let vs = SLIP_DIRECTION_SPEED;
    blended(v_t, (v_t[0] * v_t[0] + v_t[1] * v_t[1]) / (vs * vs), stored, vs)
}

/// Kinematics, b (with compliant forces), `M_J` and its Cholesky factor (in `fd.m_j`,
/// `fd.l_inv_diag`), the contact rows: everything the mode-dependent solve reads.
#[allow(clippy::too_many_arguments)]
pub fn prepare(
    plant: &Plant,
    contacts: &[Contact],
    data: &mut Data,
    fd: &mut ForwardData,
    cd: &mut ContactData,
    t: f64,
    q: &[f64],
    qd: &[f64],
    current: &[f64],
) -> Result<(), DynamicsError> {
    prepare_in_modes(plant, contacts, None, data, fd, cd, t, q, qd, current)
}

/// Whether contact k has rows in a solve in the modes `m`: all but a `Separated` rigid one (a
/// compliant contact's force goes into b through its rows whatever its mode).
pub fn has_rows(contacts: &[Contact], m: &[ContactMode], k: usize) -> bool {
    m[k] != ContactMode::Separated || matches!(contacts[k].model, ContactModel::Compliant { .. })
}

/// [`prepare`] for a solve in the modes `modes` (`None`: every contact's rows, as at an event):
/// a `Separated` unilateral contact is not touched at all — no rows, no touching point, its gap
/// and velocities left as they were ([`contact_rows_only`]; issue 24 item 2) — since nothing of
/// it enters the solve; what reads its gap (the event functions, `ode/hybrid.rs`) computes it
/// with [`super::rows::contact_gaps_where`].
#[allow(clippy::too_many_arguments)]
pub fn prepare_in_modes(
    plant: &Plant,
    contacts: &[Contact],
    modes: Option<&[ContactMode]>,
    data: &mut Data,
    fd: &mut ForwardData,
    cd: &mut ContactData,
    t: f64,
    q: &[f64],
    qd: &[f64],
    current: &[f64],
) -> Result<(), DynamicsError> {
    let model = plant.model;
    let nv = model.nv;
    generalized_force_and_inertia(plant, data, fd, q, qd, current);
    forward_velocities(model, data, qd);
    match modes {
        None => contact_rows(model, data, contacts, &mut cd.rows),
        Some(m) => contact_rows_only(model, data, contacts, &mut cd.rows, |k| has_rows(contacts, m, k)),
    }
    super::shape::check_rims(contacts, data, t)?;
    compliant_forces(contacts, fd, cd);
    if !cholesky::factor_in_place(fd.m_j.as_mut_slice(), nv, &mut fd.l_inv_diag) {
        return Err(DynamicsError::SingularMassMatrix { t });
    }
    Ok(())
}

/// The compliant contacts' forces from the rows' gaps and velocities, into b (`J_nᵀ f_n +
/// J_tᵀ f_t`) and `cd.f_n`, `cd.f_t` (0 for the other contacts).
fn compliant_forces(contacts: &[Contact], fd: &mut ForwardData, cd: &mut ContactData) {
    let nv = cd.rows.nv;
    for (k, c) in contacts.iter().enumerate() {
        cd.f_n[k] = 0.0;
        cd.f_t[k] = [0.0; 2];
        if let ContactModel::Compliant { stiffness, damping, friction, slip_velocity } = c.model {
            let (delta, delta_d) = (-cd.rows.gap[k], -cd.rows.vel[3 * k]);
            if delta > 0.0 {
                let f_n = (stiffness * delta + damping * delta_d).max(0.0);
                let v = cd.rows.slip(k);
                let w = -friction * f_n / (v[0] * v[0] + v[1] * v[1] + slip_velocity * slip_velocity).sqrt();
                let f_t = [w * v[0], w * v[1]];
                cd.f_n[k] = f_n;
                cd.f_t[k] = f_t;
                let r = &cd.rows;
                for j in 0..nv {
                    fd.b[j] += f_n * r.row(3 * k)[j] + f_t[0] * r.row(3 * k + 1)[j] + f_t[1] * r.row(3 * k + 2)[j];
                }
            }
        }
    }
}

/// The active rows of `state` (with Baumgarte's terms when asked) into `cd.active`.
pub fn active_rows(contacts: &[Contact], state: &ContactState, stabilization: Stabilization, cd: &mut ContactData) {
    for k in 0..contacts.len() {
        cd.anchor[k] = state.slip[k];
        cd.onset_now[k] = state.onset[k].is_some();
    }
    active_rows_of(contacts, &state.mode, stabilization, cd);
}

/// [`active_rows`] of the modes `mode`, a sliding contact's friction blending towards
/// `cd.anchor` below [`SLIP_DIRECTION_SPEED`].
fn active_rows_of(contacts: &[Contact], mode: &[ContactMode], stabilization: Stabilization, cd: &mut ContactData) {
    let (alpha, beta) = match stabilization {
        Stabilization::Baumgarte { alpha, beta } => (alpha, beta),
        _ => (0.0, 0.0),
    };
    let r = &cd.rows;
    cd.active.clear();
    for (k, c) in contacts.iter().enumerate() {
        if mode[k] == ContactMode::Separated {
            // no row: nothing of a separated candidate is read (issue 24 item 2)
            continue;
        }
        let normal_extra = 2.0 * alpha * r.vel[3 * k] + beta * beta * r.gap[k];
        let normal = |force| ActiveRow { row: 3 * k, force, extra: normal_extra };
        let mu = c.unilateral_friction();
        match mode[k] {
            ContactMode::Separated => {}
            ContactMode::Bilateral => cd.active.push(normal(RowForce::Same)),
            ContactMode::Sticking if mu > 0.0 => {
                cd.active.push(normal(RowForce::Same));
                for axis in 1..3 {
                    cd.active.push(ActiveRow { row: 3 * k + axis, force: RowForce::Same, extra: 2.0 * alpha * r.vel[3 * k + axis] });
                }
            }
            ContactMode::Sticking | ContactMode::Sliding => {
                let (v, anchor) = (r.slip(k), cd.anchor[k]);
                let s = if cd.onset_now[k] { onset_direction(v, anchor, cd.onset_speed[k]) } else { friction_direction(v, anchor) };
                cd.active.push(normal(if mu > 0.0 { RowForce::Sliding { mu, s } } else { RowForce::Same }));
            }
        }
    }
}

/// The mode-dependent solve after [`prepare`]: q̈ into `fd.qdd`, the forces of the rigid
/// contacts into `cd.f_n`, `cd.f_t` (compliant ones keep theirs).
pub fn solve_modes(contacts: &[Contact], state: &ContactState, stabilization: Stabilization, fd: &mut ForwardData, cd: &mut ContactData) -> Result<(), Singular> {
    for k in 0..contacts.len() {
        cd.anchor[k] = state.slip[k];
        cd.onset_now[k] = state.onset[k].is_some();
    }
    onset_anchors(contacts, state, stabilization, fd, cd);
    active_rows_of(contacts, &state.mode, stabilization, cd);
    let nv = cd.rows.nv;
    solve_active(fd.m_j.as_slice(), &fd.l_inv_diag, fd.b.as_slice(), &cd.rows, &cd.active, &mut cd.scratch, &mut fd.qdd.as_mut_slice()[..nv])?;
    forces_of(contacts, &state.mode, cd);
    Ok(())
}

/// The friction's anchor of the sliding contacts in an onset (`state.onset`): `−f_t/|f_t|` of the force that would keep them sticking at this
/// state (the same modes with those contacts sticking; a statically indeterminate contact's
/// largest-margin force), turned by the onset's rotation (at the event it is the direction the
/// mode problem chose, so the anchor starts there), into `cd.anchor` (the others keep
/// `state.slip`).
///
/// Why (issue 23, the stick → slip onset): at the onset the sticking force `f*` reaches the
/// cone, and Coulomb's slide from rest has `a_t = G (f − f*)` with `G` the contact's
/// tangential Delassus block and `f` the force of the disc nearest `f*` in G's metric
/// (Moreau's maximal dissipation; Glocker, *Set-Valued Force Laws*, 2001, §7; Pfeiffer &
/// Glocker 1996, §5.2): `a_t = O(δ)`, δ = |f*| − μ f_n, which is 0 at the event and grows
/// with time. So the slip's direction over its first ~`sqrt(2 v_s / |ȧ_t|)` seconds is decided
/// at the order of `ḟ*`, and `f*` turns while it grows. A friction held along the fixed
/// direction of the event (`s₀`) gives `ȧ_t · s₀ = G₁₁ δ̇ + G₁₂ (the turn of f*)`, which is
/// negative when f* turns faster than it leaves the cone: the slip ran backwards along `s₀` at
/// 1e-10 m/s, the located slip → stick fired, the stick broke again at once, and the modes
/// chattered (the hobby arm at μ = 1, 1.886217 s; the paper's unilateral runs at rtol 1e-4 …
/// 1e-6). Anchored on `−f*/|f*|` (the radial projection of f* on the disc, which is the G
/// projection up to O(δ/μ f_n)), `a_t · s = δ sᵀ G s > 0` whenever the stick is broken: the
/// slip grows along the direction the sticking force leaves the cone, and the anchor turns
/// with it. One more constrained solve per evaluation, only while a slip is in its onset (until
/// the end of the step where it passes v_s and the integrator's resolution along the anchor,
/// `ode/hybrid.rs`); the same solve gives the stick's excess `cd.onset_excess`, the onset's
/// slip → stick function. Above v_s the friction is Coulomb's `−μ f_n v_t/|v_t|` (the blend's
/// side taken from the anchor, and a slip run back across it opposed: [`active_rows_of`]), so
/// the anchor only decides the side and the onset's end: at rtol 1e-3 the slip's first
/// steps after an onset are the integrator's error (2e-5 … 8e-5 m/s, turning by up to 180°
/// from step to step, whole-table at 0.2448 s) and a reference kept on the side of the
/// previous step's slip turned round with them (a friction along the slip in the audit).
///
/// A member of a group of contacts with rows dependent across contacts ([`super::dependent`])
/// that is inside its own cone (its margin above the group's) keeps the direction the mode
/// problem chose at the event (`state.slip`: the slide from rest's consistent `a_t ∥ s`,
/// `modes.rs`; Pfeiffer & Glocker 1996, §5.2; Glocker 2001, §7). The group program fixes only
/// the value, the largest common margin (continuous: the onset's excess); its maximisers form a
/// convex set (Boyd & Vandenberghe 2004, §4.2), along which a binding member's `f_t` can only
/// move radially (its margin, concave, stays at the optimum, so `|f_t|` is affine there): its
/// direction is unique and the rule above holds. A member inside its cone has no direction of
/// leaving it, and its force was wherever the barrier's iterate fell (elbow4 at joint 3's
/// origin, 0.66 N inside, elbow7 binding, `scenes/contacts/crawl-joint3-origin-pair-tight.json`:
/// f_n 2.75–3.08 N between evaluations at one time, the anchor 1e-2 rad apart): the right-hand
/// side was not smooth and rtol 1e-8 / atol 1e-10 crawled (1 089 steps, 703 rejected, in the
/// first 2e-5 s).
fn onset_anchors(contacts: &[Contact], state: &ContactState, stabilization: Stabilization, fd: &mut ForwardData, cd: &mut ContactData) {
    // every onset gets its stick's excess (its slip → stick function) and its anchor
    let in_onset = |k: usize| state.onset[k].is_some() && state.mode[k] == ContactMode::Sliding && matches!(contacts[k].model, ContactModel::Unilateral { friction, .. } if friction > 0.0);
    cd.onset_excess.fill(f64::NAN);
    if !(0..contacts.len()).any(in_onset) {
        return;
    }
    for k in 0..contacts.len() {
        cd.stick_mode[k] = if in_onset(k) { ContactMode::Sticking } else { state.mode[k] };
    }
    let mode = std::mem::take(&mut cd.stick_mode);
    active_rows_of(contacts, &mode, stabilization, cd);
    let nv = cd.rows.nv;
    let ok = solve_active(fd.m_j.as_slice(), &fd.l_inv_diag, fd.b.as_slice(), &cd.rows, &cd.active, &mut cd.scratch, &mut fd.qdd.as_mut_slice()[..nv]).is_ok();
    if ok {
        forces_of(contacts, &mode, cd);
        for (k, (&now, &was)) in mode.iter().zip(&state.mode).enumerate() {
            if now == ContactMode::Sticking && was == ContactMode::Sliding {
                // a jammed stick (margin +∞) holds: a finite negative excess
                cd.onset_excess[k] = if cd.margin[k].is_finite() { -cd.margin[k] } else { -1.0 };
                let f = cd.f_t[k];
                let m = f[0].hypot(f[1]);
                // a member of a dependent group inside its own cone keeps the event's direction
                // (`state.slip`, set above): its share of the group's force is not a function
                // of the state (doc); a binding one's direction is
                let mu = contacts[k].unilateral_friction();
                let free = cd.dependent.in_group(k) && mu * cd.f_n[k] - m - cd.margin[k] > 1e-8 * (1.0 + cd.f_n[k].abs() + m);
                if let (true, Some(r), false) = (m > 1e-12 * (1.0 + cd.f_n[k].abs()), state.onset[k], free) {
                    let i = [-f[0] / m, -f[1] / m];
                    cd.anchor[k] = [r[0] * i[0] - r[1] * i[1], r[1] * i[0] + r[0] * i[1]];
                }
            }
        }
    }
    cd.stick_mode = mode;
}

/// The forces of the rigid contacts of the last solve (`cd.active`, `cd.scratch.lambda`) in
/// the modes `mode`, and the stick margins of the sticking ones.
fn forces_of(contacts: &[Contact], mode: &[ContactMode], cd: &mut ContactData) {
    for (k, c) in contacts.iter().enumerate() {
        if !matches!(c.model, ContactModel::Compliant { .. }) {
            cd.f_n[k] = 0.0;
            cd.f_t[k] = [0.0; 2];
        }
    }
    for (i, ar) in cd.active.iter().enumerate() {
        let (k, axis) = (ar.row / 3, ar.row % 3);
        let lam = cd.scratch.lambda[i];
        match (axis, ar.force) {
            (0, RowForce::Same) => cd.f_n[k] = lam,
            (0, RowForce::Sliding { mu, s }) => {
                cd.f_n[k] = lam;
                cd.f_t[k] = [-mu * lam * s[0], -mu * lam * s[1]];
            }
            (a, _) => cd.f_t[k][a - 1] = lam,
        }
    }
    stick_margins(contacts, mode, cd);
}

/// The stick margins of the sticking contacts after [`solve_modes`]; a contact whose three rows
/// are dependent gets the force of the largest margin among those it admits
/// ([`super::indeterminate`]; the accelerations do not change).
fn stick_margins(contacts: &[Contact], mode: &[ContactMode], cd: &mut ContactData) {
    for (k, c) in contacts.iter().enumerate() {
        cd.margin[k] = 0.0;
        let ContactModel::Unilateral { friction: mu, .. } = c.model else { continue };
        if mode[k] != ContactMode::Sticking || mu <= 0.0 {
            continue;
        }
        let (f_n, f_t) = (cd.f_n[k], cd.f_t[k]);
        cd.margin[k] = mu * f_n - f_t[0].hypot(f_t[1]);
        let Some(i) = cd.active.iter().position(|a| a.row == 3 * k) else { continue };
        let b: [[f64; 3]; 3] = std::array::from_fn(|r| std::array::from_fn(|s| cd.scratch.gram(&cd.rows, &cd.active, i + r, i + s)));
        if let Some(z) = super::indeterminate::null_direction(&b) {
            let (alpha, margin) = super::indeterminate::most_admissible(mu, f_n, f_t, z);
            cd.f_n[k] = f_n + alpha * z[0];
            cd.f_t[k] = [f_t[0] + alpha * z[1], f_t[1] + alpha * z[2]];
            cd.margin[k] = margin;
        }
    }
    group_margins(contacts, mode, cd);
}

/// The sticking contacts whose rows are dependent across contacts (coincident or kinematically
/// dependent points) get the distribution of the largest common margin and that margin
/// ([`super::dependent`]); the others keep theirs.
fn group_margins(contacts: &[Contact], mode: &[ContactMode], cd: &mut ContactData) {
    let sticking_count = contacts.iter().zip(mode).filter(|(c, &m)| m == ContactMode::Sticking && matches!(c.model, ContactModel::Unilateral { friction, .. } if friction > 0.0)).count();
    if sticking_count < 2 {
        cd.dependent.clear_groups();
        return;
    }
    let ContactData { rows, active, scratch, f_n, f_t, margin, dependent, .. } = cd;
    let mu = |k: usize| match contacts[k].model {
        ContactModel::Unilateral { friction, .. } if mode[k] == ContactMode::Sticking => friction,
        _ => 0.0,
    };
    let sticking = |k: usize| active.iter().position(|a| a.row == 3 * k && a.force == RowForce::Same).filter(|&i| active.get(i + 2).is_some_and(|a| a.row == 3 * k + 2));
    let gram = |i: usize, j: usize| scratch.gram(rows, active, i, j);
    let local = |k: usize| {
        sticking(k).is_some_and(|i| {
            let b: [[f64; 3]; 3] = std::array::from_fn(|r| std::array::from_fn(|s| scratch.gram(rows, active, i + r, i + s)));
            super::indeterminate::null_direction(&b).is_some()
        })
    };
    let input = super::dependent::GroupInput { mu: &mu, sticking: &sticking, gram: &gram, local: &local };
    super::dependent::group_margins(&input, dependent, f_n, f_t, margin);
}

/// Eq 21 with contacts of any model in the modes of `state` (the bilateral path's outputs in
/// `fd`: `qdd`, `di`, `tau_motor`; the contact forces in `cd`).
#[allow(clippy::too_many_arguments)]
pub fn forward_dynamics_contacts(
    plant: &Plant,
    contacts: &[Contact],
    state: &ContactState,
    data: &mut Data,
    fd: &mut ForwardData,
    cd: &mut ContactData,
    t: f64,
    q: &[f64],
    qd: &[f64],
    current: &[f64],
    voltage: &[f64],
) -> Result<(), DynamicsError> {
    prepare_in_modes(plant, contacts, Some(&state.mode), data, fd, cd, t, q, qd, current)?;
    solve_and_finish(plant, contacts, state, fd, cd, t, qd, current, voltage)
}

/// The mode solve after the preparation, its error named by the active contacts, then eq 12's
/// electrical rows ([`finish`]).
#[allow(clippy::too_many_arguments)]
fn solve_and_finish(plant: &Plant, contacts: &[Contact], state: &ContactState, fd: &mut ForwardData, cd: &mut ContactData, t: f64, qd: &[f64], current: &[f64], voltage: &[f64]) -> Result<(), DynamicsError> {
    if solve_modes(contacts, state, plant.stabilization, fd, cd).is_err() {
        let names: Vec<&str> = cd.active.iter().map(|a| contacts[a.row / 3].name()).collect();
        return Err(DynamicsError::SingularConstraints { t, constraints: names.join(", ") });
    }
    finish(plant, fd, t, qd, current, voltage)
}

/// [`forward_dynamics_contacts`] at a state that differs from the one of the last full call
/// (or the last call of this) in q̇ and the currents only, in the same modes: what depends on
/// q alone — the placements, `M_J` and its factor, the contact Jacobians and gaps, the rims'
/// check — is taken from `data`, `fd` and `cd` as that call left them, and the rest (the bias
/// forces, b, the velocities, the rows' `J̇ q̇`, the compliant forces, the mode solve, eq 12's
/// electrical rows) is computed by the same operations, so the outputs are bit for bit those
/// of a full call (`sim/tests/hybrid_jacobian.rs`). For the q̇ and current columns of the
/// difference Jacobian (`ode/jacobian.rs`, issue 24 item 1). The caller guarantees the q.
#[allow(clippy::too_many_arguments)]
pub fn forward_dynamics_contacts_same_q(
    plant: &Plant,
    contacts: &[Contact],
    state: &ContactState,
    data: &mut Data,
    fd: &mut ForwardData,
    cd: &mut ContactData,
    t: f64,
    qd: &[f64],
    current: &[f64],
    voltage: &[f64],
) -> Result<(), DynamicsError> {
    generalized_force_placed(plant, data, fd, qd, current);
    forward_velocities(plant.model, data, qd);
    let m = &state.mode;
    contact_velocities_only(data, contacts, &mut cd.rows, |k| has_rows(contacts, m, k));
    compliant_forces(contacts, fd, cd);
    solve_and_finish(plant, contacts, state, fd, cd, t, qd, current, voltage)
}

/// The electrical rows and the motor torque of eq 12, as in the bilateral path.
pub fn finish(plant: &Plant, fd: &mut ForwardData, t: f64, qd: &[f64], current: &[f64], voltage: &[f64]) -> Result<(), DynamicsError> {
    let (model, drives) = (plant.model, plant.drives);
    for j in 0..model.nv {
        fd.di[j] = drives.current_rate(j, voltage[j], current[j], qd[j]);
        fd.tau_motor[j] = drives.link_torque(j, current[j], qd[j], fd.qdd[j]);
    }
    if let Some(j) = fd.qdd.iter().position(|x| !x.is_finite()) {
        return Err(DynamicsError::NonFinite { t, what: format!("the acceleration of {}", model.bodies[j].joint) });
    }
    Ok(())
}

#[cfg(test)]
#[path = "forward_tests.rs"]
mod friction_direction_tests;
