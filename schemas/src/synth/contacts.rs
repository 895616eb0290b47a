//! A synthetic recording of a run with unilateral contacts ([`unilateral`]), with a known
//! history of modes, forces and events ([`UnilateralTruth`]) for the tests of readers.

use super::{linear_energy, Synth};
use crate::meta::{ContactInfo, ContactsRecord, EnergyTermsRecord};
use crate::{ConstraintState, ContactEventMsg, ContactState};

/// What [`unilateral`] wrote, in closed form (for exact assertions).
#[derive(Debug, Clone, PartialEq)]
pub struct UnilateralTruth {
    /// Time in contact per contact (mode ≠ separated), s: elbow4 0.303 + 0.293 = 0.596 (events off the sample midpoints: the trapezoid rule on the samples would give 0.6), elbow7 1.
    pub time_in_contact: [f64; 2],
    /// Lift-offs, touch-downs, impacts, rests, stick-to-slip, slip-to-stick of elbow4 (elbow7: none).
    pub elbow4_counts: [usize; 6],
    /// Impact energy lost by elbow4, J (0.05 + 0.01).
    pub elbow4_impact_loss: f64,
    /// Friction work of elbow4 at the end, J (6 N × 0.01 m/s × 0.1 s).
    pub elbow4_friction_work: f64,
    /// `max |f_t| / f_n` over the sticking samples, and over all samples in contact.
    pub stick_ratio: [[f64; 2]; 2],
    /// `min` and `max f_n` over the samples in contact, N.
    pub normal_force_in_contact: [[f64; 2]; 2],
}

/// Scene `synthetic`, run `unilateral`, contacts `elbow4` and `elbow7` (unilateral, μ = 0.6,
/// e = 0.5), 3 joints, 1 s at dt = 0.01 s (101 samples), complete. `elbow7` sticks all the time
/// (`f_n = 20` N, `f_t = (3, 4)` N). `elbow4`:
///
/// | time | mode | event |
/// |---|---|---|
/// | 0 ≤ t ≤ 0.30 | sticking, f_n = 10 N, f_t = (2, 0) N | |
/// | 0.303 | | lift-off |
/// | 0.31 ≤ t ≤ 0.59 | separated, g = 0.01 + 0.1 (t − 0.3), ġ = 0.1 m/s (made up) | |
/// | 0.595 | | impact, ġ −0.2 → 0.1 m/s, impulse 0.3 N s, 0.05 J lost |
/// | 0.60 ≤ t ≤ 0.70 | separated | |
/// | 0.707 | | rest, ġ −0.05 → 0 m/s, impulse 0.1 N s, 0.01 J lost |
/// | 0.71 ≤ t ≤ 0.80 | sliding, f_n = 10 N, f_t = (−6, 0) N, v_t = (0.01, 0) m/s | |
/// | 0.807 | | slip-to-stick |
/// | 0.81 ≤ t ≤ 1 | sticking, f_n = 10 N, f_t = (3, 0) N | |
///
/// `/constraints` carries the same `f_n`, `g`, `ġ`; the `energy_terms` record the totals.
pub fn unilateral() -> (Synth, UnilateralTruth) {
    let mut s = Synth::new("unilateral", &["elbow4", "elbow7"], 3).with_setup();
    // elbow4 at t: (mode, g, ġ, f_n, f_t1, v_t1, impact loss, friction work)
    fn elbow4(t: f64) -> (u32, f64, f64, f64, f64, f64, f64, f64) {
        let friction_work = 0.06 * (t - 0.707).clamp(0.0, 0.1);
        let impact_loss = if t < 0.595 { 0.0 } else if t < 0.707 { 0.05 } else { 0.06 };
        if t <= 0.30 + 1e-9 {
            (1, 0.0, 0.0, 10.0, 2.0, 0.0, impact_loss, friction_work)
        } else if t < 0.707 {
            // a made-up flight: positive gap, rate of either sign
            (0, 0.01 + 0.1 * (t - 0.3), 0.1, 0.0, 0.0, 0.0, impact_loss, friction_work)
        } else if t <= 0.80 + 1e-9 {
            (2, 0.0, 0.0, 10.0, -6.0, 0.01, impact_loss, friction_work)
        } else {
            (1, 0.0, 0.0, 10.0, 3.0, 0.0, impact_loss, friction_work)
        }
    }
    s.contacts = Some(Box::new(|t| {
        let (mode, g, gd, f_n, f_t1, v_t1, imp, fric) = elbow4(t);
        ContactState {
            time: t,
            name: vec!["elbow4".into(), "elbow7".into()],
            mode: vec![mode, 1],
            gap: vec![g, 0.0],
            gap_rate: vec![gd, 0.0],
            normal_force: vec![f_n, 20.0],
            friction_force_t1: vec![f_t1, 3.0],
            friction_force_t2: vec![0.0, 4.0],
            slip_velocity_t1: vec![v_t1, 0.0],
            slip_velocity_t2: vec![0.0, 0.0],
            impact_loss: vec![imp, 0.0],
            friction_work: vec![fric, 0.0],
            damping_loss: vec![0.0, 0.0],
        }
    }));
    s.constraints = Some(Box::new(|t| {
        let (_, g, gd, f_n, ..) = elbow4(t);
        ConstraintState { time: t, normal_force: vec![f_n, 20.0], position: vec![g, 0.0], velocity: vec![gd, 0.0], name: Vec::new() }
    }));
    s.energy = Some(Box::new(|t| linear_energy(t, 3, 1.0, 2.0)));
    let event = |time: f64, kind: &str, impulse: f64, energy_lost: f64, before: f64, after: f64| ContactEventMsg {
        time,
        contact: "elbow4".into(),
        kind: kind.into(),
        impulse,
        energy_lost,
        gap_rate_before: before,
        gap_rate_after: after,
    };
    s.contact_events = vec![
        event(0.303, "lift-off", 0.0, 0.0, 0.0, 0.0),
        event(0.595, "impact", 0.3, 0.05, -0.2, 0.1),
        event(0.707, "rest", 0.1, 0.01, -0.05, 0.0),
        event(0.807, "slip-to-stick", 0.0, 0.0, 0.0, 0.0),
    ];
    let info = |name: &str| ContactInfo { restitution: Some(0.5), friction: Some(0.6), ..ContactInfo::on_floor(name, "unilateral") };
    s.contacts_record = Some(ContactsRecord {
        contacts: vec![info("elbow4"), info("elbow7")],
        time_tolerance: 1e-12,
        gap_tolerance: 1e-9,
        velocity_tolerance: 1e-9,
        rest_velocity: 1e-4,
        max_events: 100_000,
        onset_slip_speed: None,
    });
    s.energy_terms = Some(EnergyTermsRecord { impact_loss: Some(0.06), friction_work: Some(0.006), damping_loss: Some(0.0), ..Default::default() });
    let truth = UnilateralTruth {
        time_in_contact: [0.596, 1.0],
        elbow4_counts: [1, 0, 1, 1, 0, 1],
        elbow4_impact_loss: 0.06,
        elbow4_friction_work: 0.006,
        stick_ratio: [[0.3, 0.6], [0.25, 0.25]],
        normal_force_in_contact: [[10.0, 10.0], [20.0, 20.0]],
    };
    (s, truth)
}
