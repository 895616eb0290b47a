//! Joint limits (a scene's `"joint_limits"`) and drive limits: the soft stops that enforce the
//! URDF position limits when a scene asks, and the monitor that flags every limit crossed.
//!
//! **Soft stops** (`"position": "stop"`): beyond a limit a linear spring-damper acts on the
//! joint, `τ_s = −k (q − q_hi) − c q̇` for `q > q_hi` (and with `q_lo` for `q < q_lo`), zero
//! inside — the penalty (compliant) method of joint-limit enforcement (Featherstone, *Rigid Body
//! Dynamics Algorithms*, §11.2, compliant contact; a unilateral-constraint solve is not used).
//! It stores `V_s = ½ k (q − q_hi)²` (part of the energy balance as a stored energy) and
//! dissipates `c q̇²` while beyond (a new quadrature `E_s = ∫ Σ c q̇² [beyond] dt`, present only
//! when stops are configured). The damper acts over the whole penetration (it can pull while
//! the joint leaves the stop; the energy account is exact either way). One k and one c serve
//! every joint, in N m/rad and N m s/rad on revolute joints and in N/m and N s/m on prismatic
//! ones: on an arm with both kinds, choose them for the kind whose stops matter.
//!
//! **Monitor** (on when the scene has `"joint_limits"` or a voltage or current limit): at every
//! output sample — the resolution of every time below is the output interval `1 / output_rate`
//! — per joint and kind: the first sample time beyond, the time spent beyond (samples beyond ×
//! interval), the peak, and the intervals beyond (first and last sample time of each run of
//! samples beyond; the first 100 kept, their count recorded). Kinds: `position` (q outside the URDF `lower..upper`), `velocity`
//! (|q̇| > URDF `velocity`), `effort` (|τ| of eq 12 > URDF `effort`), `current` (|i| > the
//! driver's limit by more than 1e-6 relative — the integration error of inductive motors at
//! their barrier is below that), and the drive's saturations, which are not limits crossed but
//! are reported: `voltage-saturation` (the commanded |v*| above the supply) and `current-limit`
//! (the driver clipped the command, |v* − K_e k q̇| > R I).

use crate::dynamics::Model;
use crate::dynamics::motor::Drives;
use crate::ode::Outputs;

/// Soft stops at the URDF position limits (module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct JointStops {
    /// Lower and upper limit per joint, rad (∓∞ where the URDF gives none).
    pub lower: Vec<f64>,
    pub upper: Vec<f64>,
    /// k, N m/rad.
    pub stiffness: f64,
    /// c, N m s/rad.
    pub damping: f64,
}

impl JointStops {
    /// From the URDF limits of `model`.
    pub fn new(model: &Model, stiffness: f64, damping: f64) -> Self {
        let lim = |f: fn((f64, f64)) -> f64, none: f64| model.bodies.iter().map(|b| b.limits.position.map_or(none, f)).collect();
        Self { lower: lim(|p| p.0, f64::NEG_INFINITY), upper: lim(|p| p.1, f64::INFINITY), stiffness, damping }
    }

    /// Penetration beyond the limits of joint j, rad (positive above, negative below, 0 inside).
    #[inline]
    fn beyond(&self, j: usize, q: f64) -> f64 {
        if q > self.upper[j] {
            q - self.upper[j]
        } else if q < self.lower[j] {
            q - self.lower[j]
        } else {
            0.0
        }
    }

    /// The stop torque on joint j, N m.
    #[inline]
    pub fn torque(&self, j: usize, q: f64, qd: f64) -> f64 {
        let d = self.beyond(j, q);
        if d == 0.0 {
            0.0
        } else {
            -self.stiffness * d - self.damping * qd
        }
    }

    /// `Σ ½ k δ²`, J.
    pub fn energy(&self, q: &[f64]) -> f64 {
        q.iter().enumerate().map(|(j, &x)| 0.5 * self.stiffness * self.beyond(j, x).powi(2)).sum()
    }

    /// `Σ c q̇² [beyond]`, W.
    #[inline]
    pub fn loss_rate(&self, q: &[f64], qd: &[f64]) -> f64 {
        let mut p = 0.0;
        for j in 0..q.len() {
            if self.beyond(j, q[j]) != 0.0 {
                p += self.damping * qd[j] * qd[j];
            }
        }
        p
    }
}

/// What is monitored ([`LimitMonitor`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum LimitKind {
    Position,
    Velocity,
    Effort,
    Current,
    VoltageSaturation,
    CurrentLimit,
    /// The winding temperature above the datasheet's maximum (thermal model on), °C.
    WindingTemperature,
    /// The torque delivered to the link above the gearhead's max intermittent torque, N m.
    GearTorque,
}

impl LimitKind {
    pub fn name(self) -> &'static str {
        match self {
            LimitKind::Position => "position",
            LimitKind::Velocity => "velocity",
            LimitKind::Effort => "effort",
            LimitKind::Current => "current",
            LimitKind::VoltageSaturation => "voltage-saturation",
            LimitKind::CurrentLimit => "current-limit",
            LimitKind::WindingTemperature => "winding-temperature",
            LimitKind::GearTorque => "gear-torque",
        }
    }

    /// A limit crossed (else a saturation of the drive, which is its designed behaviour).
    pub fn is_exceeded(self) -> bool {
        !matches!(self, LimitKind::VoltageSaturation | LimitKind::CurrentLimit)
    }
}

/// One joint and kind, as monitored.
#[derive(Clone, Debug, PartialEq)]
pub struct LimitEvent {
    pub joint: String,
    pub kind: LimitKind,
    /// The limit, in the quantity's unit (rad, rad/s, N m, A, V; the crossed bound for
    /// positions).
    pub limit: f64,
    /// First sample time beyond, s.
    pub first_time: f64,
    /// Samples beyond × the output interval, s.
    pub time_beyond: f64,
    /// The most extreme value seen: q for positions, else the magnitude (|q̇|, |τ|, |i|, |v*|,
    /// and |v* − K_e k q̇| / R for `current-limit`, the current asked for).
    pub peak: f64,
    /// The intervals beyond, `[first, last]` sample time of each run of consecutive samples
    /// beyond (the first [`MAX_INTERVALS`]), s.
    pub intervals: Vec<[f64; 2]>,
    /// How many intervals there were (more than `intervals` holds when it was cut).
    pub interval_count: u64,
}

/// At most this many intervals are kept per joint and kind (a chattering saturation would
/// otherwise grow the record without bound).
pub const MAX_INTERVALS: usize = 100;

/// The monitor's verdict on one run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LimitsSummary {
    /// One per joint and kind that happened, in joint then kind order.
    pub events: Vec<LimitEvent>,
    /// The output interval, s: the resolution of the times.
    pub resolution: f64,
    /// What was monitored, for the record.
    pub monitored: String,
}

impl LimitsSummary {
    /// Limits crossed (position, velocity, effort, current), joint and kind counted once.
    pub fn exceeded(&self) -> usize {
        self.events.iter().filter(|e| e.kind.is_exceeded()).count()
    }
    /// Saturations of the drives (voltage, current window), joint and kind counted once.
    pub fn saturated(&self) -> usize {
        self.events.len() - self.exceeded()
    }
    /// "complete", "complete, 3 limits exceeded", "complete, 1 limit exceeded, 2 saturations".
    pub fn status(&self, status: &str) -> String {
        status_text(status, Some(self.exceeded() as u64), Some(self.saturated() as u64))
    }
}

/// The status line of a run: `status`, then the limits exceeded and saturations when non-zero.
pub fn status_text(status: &str, exceeded: Option<u64>, saturated: Option<u64>) -> String {
    let mut s = status.to_string();
    let plural = |n: u64| if n == 1 { "" } else { "s" };
    if let Some(n) = exceeded.filter(|&n| n > 0) {
        s += &format!(", {n} limit{} exceeded", plural(n));
    }
    if let Some(n) = saturated.filter(|&n| n > 0) {
        s += &format!(", {n} saturation{}", plural(n));
    }
    s
}

#[derive(Clone, Debug)]
struct Slot {
    joint: usize,
    kind: LimitKind,
    limit: f64,
    first_time: Option<f64>,
    samples: u64,
    peak: f64,
    /// Which bound a position crossed first (for the record).
    bound: f64,
    /// Whether the last sample was beyond.
    inside_interval: bool,
    intervals: Vec<[f64; 2]>,
    interval_count: u64,
}

/// Watches every output sample of a run (module docs). Slots are made once; `observe` does not
/// allocate.
#[derive(Clone, Debug)]
pub struct LimitMonitor {
    joints: Vec<String>,
    slots: Vec<Slot>,
    position: Vec<Option<(f64, f64)>>,
    dt: f64,
    ke: Vec<f64>,
    r: Vec<f64>,
    /// The drivers' current limits, A (infinite where none).
    i_max: Vec<f64>,
    monitored: String,
}

impl LimitMonitor {
    /// The monitor of a scene's run: [`LimitMonitor::new`], plus the datasheet drives'
    /// ratings: the max winding temperature (thermal model on) and the gearhead's max
    /// intermittent torque.
    pub fn for_scene(scene: &crate::scene::Scene, dt: f64) -> Option<Self> {
        let mut extra = Vec::new();
        if let Some(th) = scene.thermal() {
            for (j, p) in th.params.iter().enumerate() {
                if let Some(p) = p {
                    extra.push((j, LimitKind::WindingTemperature, p.max_winding_temperature));
                }
            }
        }
        for (j, d) in scene.datasheets().iter().enumerate() {
            if let Some(t) = d.as_ref().and_then(|d| d.gear_torque_intermittent) {
                if !scene.drives().passive[j] {
                    extra.push((j, LimitKind::GearTorque, t));
                }
            }
        }
        let mut m = Self::new(scene.model(), scene.drives(), scene.monitors_joint_limits() || !extra.is_empty(), dt)?;
        if !extra.is_empty() {
            m.monitored += if m.monitored.is_empty() { "" } else { "; " };
            m.monitored += "datasheet ratings (max winding temperature, gearhead max intermittent torque)";
        }
        for (joint, kind, limit) in extra {
            m.slots.push(Slot { joint, kind, limit, first_time: None, samples: 0, peak: 0.0, bound: 0.0, inside_interval: false, intervals: Vec::new(), interval_count: 0 });
        }
        Some(m)
    }

    /// The monitor of a scene: joints' limits when `joints` (the scene has `"joint_limits"`),
    /// the drives' when they have limits; `None` when neither (nothing is monitored).
    pub fn new(model: &Model, drives: &Drives, joints: bool, dt: f64) -> Option<Self> {
        if !joints && !drives.has_limits {
            return None;
        }
        let mut slots = Vec::new();
        let mut what = Vec::new();
        let slot = |joint, kind, limit| Slot {
            joint,
            kind,
            limit,
            first_time: None,
            samples: 0,
            peak: 0.0,
            bound: 0.0,
            inside_interval: false,
            intervals: Vec::new(),
            interval_count: 0,
        };
        for (j, b) in model.bodies.iter().enumerate() {
            if joints {
                if let Some((lo, hi)) = b.limits.position {
                    slots.push(Slot { peak: f64::NAN, ..slot(j, LimitKind::Position, hi.max(lo)) });
                }
                if let Some(v) = b.limits.velocity {
                    slots.push(slot(j, LimitKind::Velocity, v));
                }
                if let Some(e) = b.limits.effort {
                    slots.push(slot(j, LimitKind::Effort, e));
                }
            }
            if drives.passive[j] {
                continue;
            }
            if drives.current_limit[j].is_finite() {
                slots.push(slot(j, LimitKind::Current, drives.current_limit[j]));
                slots.push(slot(j, LimitKind::CurrentLimit, drives.current_limit[j]));
            }
            if drives.voltage_limit[j].is_finite() {
                slots.push(slot(j, LimitKind::VoltageSaturation, drives.voltage_limit[j]));
            }
        }
        if joints {
            what.push("URDF position, velocity and effort limits");
        }
        if drives.has_limits {
            what.push("drive voltage and current limits");
        }
        Some(Self {
            joints: model.joint_names(),
            slots,
            position: model.bodies.iter().map(|b| b.limits.position).collect(),
            dt,
            ke: drives.ke.iter().copied().collect(),
            r: drives.r.iter().copied().collect(),
            i_max: drives.current_limit.iter().copied().collect(),
            monitored: what.join("; "),
        })
    }

    /// Look at one sample (full outputs: q, q̇, τ, i, and the commanded voltage when the drives
    /// have limits).
    pub fn observe(&mut self, o: &Outputs) {
        for s in &mut self.slots {
            let j = s.joint;
            let (beyond, value) = match s.kind {
                LimitKind::Position => {
                    let (lo, hi) = self.position[j].unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
                    let q = o.q[j];
                    let beyond = q > hi || q < lo;
                    if beyond && s.first_time.is_none() {
                        s.bound = if q > hi { hi } else { lo };
                    }
                    // the peak is the q farthest beyond its bound
                    let excess = |x: f64| if x > hi { x - hi } else if x < lo { lo - x } else { 0.0 };
                    if beyond && (s.peak.is_nan() || excess(q) > excess(s.peak)) {
                        s.peak = q;
                    }
                    (beyond, None)
                }
                LimitKind::Velocity => (o.qd[j].abs() > s.limit, Some(o.qd[j].abs())),
                LimitKind::Effort => match o.tau_motor.get(j) {
                    Some(t) => (t.abs() > s.limit, Some(t.abs())),
                    None => (false, None),
                },
                LimitKind::Current => match o.current.get(j) {
                    Some(i) => (i.abs() > s.limit * (1.0 + 1e-6), Some(i.abs())),
                    None => (false, None),
                },
                // the supply clips what the driver's current window leaves of the command
                LimitKind::VoltageSaturation => match o.voltage_command.get(j) {
                    Some(&v) => {
                        let w = o.resistance.get(j).copied().unwrap_or(self.r[j]) * self.i_max[j];
                        let v = if w.is_finite() { v.clamp(self.ke[j] * o.qd[j] - w, self.ke[j] * o.qd[j] + w) } else { v };
                        (v.abs() > s.limit, Some(v.abs()))
                    }
                    None => (false, None),
                },
                LimitKind::WindingTemperature => match o.winding_temperature.get(j) {
                    Some(&t) => (t > s.limit, Some(t)),
                    None => (false, None),
                },
                LimitKind::GearTorque => match o.tau_motor.get(j) {
                    Some(t) => (t.abs() > s.limit, Some(t.abs())),
                    None => (false, None),
                },
                LimitKind::CurrentLimit => match o.voltage_command.get(j) {
                    Some(v) => {
                        // at the winding's resistance now (R(T_w) with the thermal model)
                        let r = o.resistance.get(j).copied().unwrap_or(self.r[j]);
                        let asked = (v - self.ke[j] * o.qd[j]).abs() / r;
                        (asked > s.limit, Some(asked))
                    }
                    None => (false, None),
                },
            };
            if beyond {
                s.first_time.get_or_insert(o.t);
                s.samples += 1;
                if let Some(v) = value {
                    s.peak = s.peak.max(v);
                }
                if !s.inside_interval {
                    s.interval_count += 1;
                    if s.intervals.len() < MAX_INTERVALS {
                        s.intervals.push([o.t, o.t]);
                    }
                } else if s.interval_count as usize <= MAX_INTERVALS {
                    if let Some(last) = s.intervals.last_mut() {
                        last[1] = o.t;
                    }
                }
            }
            s.inside_interval = beyond;
        }
    }

    /// What happened, one event per joint and kind that was beyond at some sample.
    pub fn summary(&self) -> LimitsSummary {
        let events = self
            .slots
            .iter()
            .filter_map(|s| {
                let first_time = s.first_time?;
                let limit = if s.kind == LimitKind::Position { s.bound } else { s.limit };
                Some(LimitEvent {
                    joint: self.joints[s.joint].clone(),
                    kind: s.kind,
                    limit,
                    first_time,
                    time_beyond: s.samples as f64 * self.dt,
                    peak: s.peak,
                    intervals: s.intervals.clone(),
                    interval_count: s.interval_count,
                })
            })
            .collect();
        LimitsSummary { events, resolution: self.dt, monitored: self.monitored.clone() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::motor::MotorParams;

    fn small() -> (Model, Drives) {
        let xml = include_str!("../scenes/small/small_arm.urdf").replace(r#"lower="-3.14" upper="3.14" effort="100""#, r#"lower="-1" upper="2" effort="100""#);
        let model = Model::from_urdf(&xml, "small_arm.urdf", nalgebra::Vector3::new(0.0, 0.0, -9.81)).unwrap();
        let m = MotorParams { torque_constant: 0.2, resistance: 1.0, inductance: 0.0, rotor_inertia: 0.0, gear_ratio: 1.0, gear_damping: 0.0 };
        let drives = Drives::new(&[m; 4], &[0.0; 4]);
        (model, drives)
    }

    /// The stop's spring is conservative with the stored energy it reports: τ = −∂V_s/∂q
    /// (central differences, h = 1e-6 rad: exact for a quadratic up to rounding, 1e-6 N m;
    /// on a limit itself V_s is C¹ but not C², and the difference straddling it is off by
    /// k h / 4, so the tolerance there is k h), zero inside the limits, and the damper
    /// dissipates c q̇² only beyond.
    #[test]
    fn the_stop_torque_is_minus_the_gradient_of_its_energy() {
        let (model, _) = small();
        let st = JointStops::new(&model, 1500.0, 3.0);
        assert_eq!((st.lower[0], st.upper[0]), (-1.0, 2.0));
        for &q in &[-1.3, -1.0, 0.0, 1.99, 2.0, 2.2] {
            let at = |x: f64| st.energy(&[x, 0.0, 0.0, 0.0]);
            let h = 1e-6;
            let grad = (at(q + h) - at(q - h)) / (2.0 * h);
            let tol = if q == -1.0 || q == 2.0 { 1500.0 * h } else { 1e-6 };
            assert!((st.torque(0, q, 0.0) + grad).abs() < tol, "q = {q}: τ = {}, -dV/dq = {}", st.torque(0, q, 0.0), -grad);
            let beyond = !(-1.0..=2.0).contains(&q);
            let damper = st.torque(0, q, 0.7) - st.torque(0, q, 0.0);
            assert!((damper - if beyond { -3.0 * 0.7 } else { 0.0 }).abs() < 1e-12, "q = {q}: damper {damper}");
            let loss = st.loss_rate(&[q, 0.0, 0.0, 0.0], &[0.7, 0.0, 0.0, 0.0]);
            assert!((loss - if beyond { 3.0 * 0.7 * 0.7 } else { 0.0 }).abs() < 1e-12, "q = {q}: loss {loss}");
        }
    }

    /// Sample by sample: the first time, the time beyond (samples × interval), the peak and
    /// the intervals of a joint that crosses its upper limit twice.
    #[test]
    fn the_monitor_reports_first_time_duration_peak_and_intervals() {
        let (model, drives) = small();
        let mut mon = LimitMonitor::new(&model, &drives, true, 0.1).unwrap();
        let qs = [1.0, 2.1, 2.3, 1.9, 1.5, 2.05, 1.0];
        for (k, &q) in qs.iter().enumerate() {
            let o = Outputs { t: 0.1 * k as f64, q: vec![q, 0.0, 0.0, 0.0], qd: vec![0.0; 4], tau_motor: vec![0.0; 4], ..Outputs::default() };
            mon.observe(&o);
        }
        let s = mon.summary();
        assert_eq!(s.events.len(), 1, "{s:?}");
        let e = &s.events[0];
        assert_eq!((e.joint.as_str(), e.kind, e.limit, e.peak), ("joint1", LimitKind::Position, 2.0, 2.3));
        assert_eq!(e.first_time, 0.1);
        assert!((e.time_beyond - 0.3).abs() < 1e-15);
        assert_eq!(e.intervals, vec![[0.1, 0.2], [0.5, 0.5]]);
        assert_eq!(e.interval_count, 2);
        assert_eq!((s.exceeded(), s.saturated()), (1, 0));
        assert_eq!(s.status("complete"), "complete, 1 limit exceeded");
        // nothing is monitored without joint limits or drive limits
        assert!(LimitMonitor::new(&model, &drives, false, 0.1).is_none());
    }
}
