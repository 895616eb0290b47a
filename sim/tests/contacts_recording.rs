//! What a unilateral run's recording holds (issue 11), read back typed: the bouncing ball of
//! `contacts_point.rs` (h0 = 1 m, e = 0.5, rest velocity 0.01 m/s) recorded to a file. The
//! `/contact_events` channel carries its ten events (nine `impact`, one `rest`) at the
//! closed-form times (1e-9 relative, as in `contacts_point.rs`) with the contact's name; `/contacts`
//! one message per sample with the mode codes (0 separated in flight, 1 or 2 in touch after the
//! rest); `/constraints` is still written for old readers.


use crate::contacts_support::*;
use schemas::{ConstraintState, ContactEventMsg, ContactState};
use serde_json::json;

#[test]
fn the_bouncing_balls_events_and_contact_states_are_recorded() {
    let (h0, e, v_rest): (f64, f64, f64) = (1.0, 0.5, 0.01);
    let mut s = passive_scene("ball", &["x", "y", "z"], &[0.0, 0.0, h0], &[0.0; 3], [0.0, 0.0, -G], 2.0, 1e-12);
    add_table_contact(&mut s, "floor", json!({"link": "ball"}), json!({"model": "unilateral", "restitution": e}));
    s["events"] = json!({"rest_velocity": v_rest});
    let scene = load(&s, &point_urdf(1.0));
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ball.mcap");
    let run = scene.run("r").unwrap().clone();
    sim::run::run_to_file(&scene, &run, &path, |_| {}).unwrap();
    let rec = schemas::read_recording(&path).unwrap();
    let events: Vec<(f64, ContactEventMsg)> = rec.read().unwrap();
    let states: Vec<(f64, ContactState)> = rec.read().unwrap();
    let constraints: Vec<(f64, ConstraintState)> = rec.read().unwrap();
    let v0 = (2.0 * G * h0).sqrt();
    let mut t = vec![(2.0 * h0 / G).sqrt()];
    for k in 1..10 {
        t.push(t[k - 1] + 2.0 * v0 * e.powi(k as i32) / G);
    }
    let kinds: Vec<&str> = events.iter().map(|(_, m)| m.kind.as_str()).collect();
    let mut want = vec!["impact"; 9];
    want.push("rest");
    assert_eq!(kinds, want);
    for (k, (_, m)) in events.iter().enumerate() {
        assert_eq!(m.contact, "floor");
        assert!((m.time - t[k]).abs() <= 1e-9 * t[k], "event {k}: {} s, closed form {} s", m.time, t[k]);
    }
    assert_eq!(states.len(), 2001);
    assert_eq!(constraints.len(), 2001);
    for (_, st) in &states {
        assert_eq!(st.name, ["floor"]);
        if st.time > t[0] + 1e-3 && st.time < t[1] - 1e-3 {
            assert_eq!(st.mode, [0], "t = {}: in flight", st.time);
        }
        if st.time > t[9] + 1e-3 {
            assert!(st.mode[0] == 1 || st.mode[0] == 2, "t = {}: at rest, mode {:?}", st.time, st.mode);
            assert!((st.normal_force[0] - G).abs() <= 1e-9 * G);
        }
    }
}
