//! The per-contact metrics of `/contacts` and `/contact_events` on the synthetic unilateral run
//! (closed-form answers: [`schemas::synth::UnilateralTruth`]), and the hidden pull of the
//! paper's bilateral two-elbow run on its archived recording.

use std::path::Path;

use schemas::synth::{unilateral, Synth};
use schemas::{ConstraintState, ContactEventMsg};

use super::super::*;

fn read(s: &Synth) -> (tempfile::TempDir, Result<RunMetrics, Error>) {
    let dir = tempfile::tempdir().unwrap();
    let m = read_run_metrics(&s.write_in(dir.path()));
    (dir, m)
}

/// Times to 1e-12 s (sums of a few intervals of 0.01 s), energies and ratios to 1e-15 (sums of
/// two numbers), counts exact; the same from a stream, from memory, and through the generic trees.
#[test]
fn unilateral_contacts_have_the_known_times_counts_and_losses() {
    let (s, truth) = unilateral();
    let dir = tempfile::tempdir().unwrap();
    let path = s.write_in(dir.path());
    let m = read_run_metrics(&path).unwrap();
    assert_eq!(m.contact_states.len(), 2);
    let [e4, e7] = [&m.contact_states[0], &m.contact_states[1]];
    assert_eq!((e4.contact.as_str(), e7.contact.as_str()), ("elbow4", "elbow7"));
    assert_eq!((e4.model.as_deref(), e4.friction), (Some("unilateral"), Some(0.6)));
    for (c, want) in [e4, e7].iter().zip(truth.time_in_contact) {
        assert!((c.time_in_contact_s - want).abs() <= 1e-12, "{}: {} vs {want}", c.contact, c.time_in_contact_s);
    }
    let [lift, touch, impacts, rests, s2s, s2st] = truth.elbow4_counts.map(|n| n as u64);
    assert_eq!(
        e4.events,
        EventCounts { lift_offs: lift, touch_downs: touch, impacts, rests, stick_to_slip: s2s, slip_to_stick: s2st }
    );
    assert_eq!(e7.events, EventCounts::default());
    assert!((e4.impact_energy_lost_j - truth.elbow4_impact_loss).abs() <= 1e-15);
    assert!((e4.impact_loss_j - truth.elbow4_impact_loss).abs() <= 1e-15);
    assert!((e4.friction_work_j - truth.elbow4_friction_work).abs() <= 1e-15);
    assert_eq!((e7.impact_loss_j, e7.friction_work_j, e7.damping_loss_j), (0.0, 0.0, 0.0));
    for (c, [stick, all]) in [e4, e7].iter().zip(truth.stick_ratio) {
        assert!((c.stick_friction_needed.unwrap() - stick).abs() <= 1e-15, "{c:?}");
        assert!((c.contact_friction_needed.unwrap() - all).abs() <= 1e-15, "{c:?}");
    }
    for (c, [lo, hi]) in [e4, e7].iter().zip(truth.normal_force_in_contact) {
        assert_eq!((c.min_normal_force_in_contact_n, c.max_normal_force_in_contact_n), (Some(lo), Some(hi)));
    }
    let terms = m.energy_terms.as_ref().unwrap();
    assert_eq!((terms.impact_loss, terms.friction_work), (Some(0.06), Some(0.006)));
    // in memory, and through the generic trees: the same numbers
    let rec = schemas::read_recording(&path).unwrap();
    assert_eq!(serde_json::to_string(&run_metrics(&rec).unwrap()).unwrap(), serde_json::to_string(&m).unwrap());
    assert_eq!(serde_json::to_string(&super::generic_metrics(&path).unwrap()).unwrap(), serde_json::to_string(&m).unwrap());
    // the JSON round-trips (the field is skipped only when empty)
    let back: RunMetrics = serde_json::from_str(&serde_json::to_string(&m).unwrap()).unwrap();
    assert_eq!(back.contact_states, m.contact_states);
}

/// Without events in the recording the status changes are put at the sample midpoints (the
/// trapezoid rule): elbow4 is then 0.30 + 0.005 + 0.005 + 0.29 = 0.6 s in contact.
#[test]
fn without_events_the_changes_fall_at_midpoints() {
    let (mut s, _) = unilateral();
    s.contact_events.clear();
    let (_d, m) = read(&s);
    let m = m.unwrap();
    assert!((m.contact_states[0].time_in_contact_s - 0.6).abs() <= 1e-12, "{:?}", m.contact_states[0]);
    assert_eq!((m.contact_states[0].events.impacts, m.contact_states[0].impact_energy_lost_j), (0, 0.0));
}

/// A bilateral recording has no contact states; the JSON has no such key.
#[test]
fn a_bilateral_run_has_no_contact_states() {
    let (_d, m) = read(&Synth::new("two-elbow", &["elbow4", "elbow7"], 3));
    let m = m.unwrap();
    assert!(m.contact_states.is_empty());
    assert!(!serde_json::to_string(&m).unwrap().contains("contact_states"));
}

/// An event of a contact the run does not have, or of an unknown kind, is an error naming it.
#[test]
fn bad_events_are_named() {
    let (mut s, _) = unilateral();
    s.contact_events.push(ContactEventMsg { time: 0.9, contact: "knee".into(), kind: "impact".into(), ..Default::default() });
    let e = read(&s).1.unwrap_err().to_string();
    assert!(e.contains("/contact_events") && e.contains("\"knee\"") && e.contains("elbow4, elbow7"), "{e}");
    let (mut s, _) = unilateral();
    s.contact_events.push(ContactEventMsg { time: 0.9, contact: "elbow4".into(), kind: "wobble".into(), ..Default::default() });
    let e = read(&s).1.unwrap_err().to_string();
    assert!(e.contains("kind = \"wobble\"") && e.contains("lift-off"), "{e}");
}

/// The paper's hidden pull: in the archived two-elbow run (5 s at 50 Hz) the table pulls
/// elbow4 (f_n < 0) from t ≈ 0.038 s to the end. The metric is within 1 ms of a direct scan of
/// `/constraints` read whole (Σ over the sample intervals of dt × (½·1[f_n(t_k) < 0] +
/// ½·1[f_n(t_k+1) < 0]), the definition of `pull_time_s`), and within dt/2 + 1 ms of 4.964 s, the
/// README's value from the 1 kHz run (the one sign change, between the samples 0.02 s and 0.04 s,
/// counts half an interval at 50 Hz: 4.97 s; with the crossing interpolated linearly the scan
/// gives 4.962 s, within 3 ms of it).
#[test]
fn the_archived_two_elbow_run_pulls_elbow4_for_most_of_the_run() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../recordings/paper-archive-two-elbow.mcap");
    let m = read_run_metrics(&path).unwrap();
    assert!(m.contact_states.is_empty(), "a bilateral run");
    let k = m.contacts.iter().position(|c| c == "elbow4").unwrap();
    let rec = schemas::read_recording(&path).unwrap();
    let c = rec.read::<ConstraintState>().unwrap();
    let neg = |f: f64| if f < 0.0 { 0.5 } else { 0.0 };
    let scan: f64 = c.windows(2).map(|w| (w[1].0 - w[0].0) * (neg(w[0].1.normal_force[k]) + neg(w[1].1.normal_force[k]))).sum();
    // the crossings interpolated linearly
    let interpolated: f64 = c
        .windows(2)
        .map(|w| {
            let (t0, f0, t1, f1) = (w[0].0, w[0].1.normal_force[k], w[1].0, w[1].1.normal_force[k]);
            match (f0 < 0.0, f1 < 0.0) {
                (true, true) => t1 - t0,
                (false, false) => 0.0,
                (true, false) => (t1 - t0) * f0 / (f0 - f1),
                (false, true) => (t1 - t0) * f1 / (f1 - f0),
            }
        })
        .sum();
    let dt = c[1].0 - c[0].0;
    let pull = m.contact_forces[k].pull_time_s;
    assert!((pull - scan).abs() <= 1e-3, "metric {pull} s, scan {scan} s");
    assert!((pull - 4.964).abs() <= 0.5 * dt + 1e-3, "elbow4 pulls for {pull} s (dt {dt} s)");
    assert!((interpolated - 4.964).abs() <= 3e-3, "interpolated {interpolated} s");
    assert!(m.contact_forces[k].min_normal_force_n < 0.0);
}
