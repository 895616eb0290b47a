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

/// What one read of a message gave, for [`typed_reads_equal_the_generic_read_on_a_whole_table_recording`].
struct Keep {
    typed: bool,
    by_ref: bool,
    seen: Vec<(String, usize, bool, schemas::Value)>,
}

impl schemas::Visitor for Keep {
    fn message(&mut self, m: schemas::DecodedMessage<'_>) -> Result<(), schemas::Error> {
        self.message_ref(&m)
    }
    fn message_ref(&mut self, m: &schemas::DecodedMessage<'_>) -> Result<(), schemas::Error> {
        self.seen.push((m.topic.to_string(), m.index, matches!(m.body, schemas::Body::Known(_)), m.value().into_owned()));
        Ok(())
    }
    fn typed(&self) -> bool {
        self.typed
    }
    fn by_ref(&self) -> bool {
        self.by_ref
    }
}

/// The typed reads of the metric messages (`schemas/src/reader/wire.rs`, the hand-written
/// protobuf walk; and into kept storage, as `analyze summary` and `sim`'s table read them) give
/// the tree `prost-reflect` decodes through the file's own schemas, bit for bit, on every
/// message of a real recording with contacts: 0.3 s of the paper's whole-table run (nine
/// candidate contacts, `/contacts` with all 13 fields).
#[test]
fn typed_reads_equal_the_generic_read_on_a_whole_table_recording() {
    use schemas::{topics, Value};
    let scene = sim::scene::Scene::load(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/paper_unilateral.json")).unwrap();
    let scene = scene.vary(|spec| spec.duration = 0.3).unwrap();
    let run = scene.run("whole-table").unwrap().clone();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("whole-table.mcap");
    sim::run::run_to_file(&scene, &run, &path, |_| {}).unwrap();
    let metric = [topics::HAND, topics::MOTORS, topics::CONSTRAINTS, topics::ENERGY, topics::CONTACTS];
    let read = |typed, by_ref| {
        let mut keep = Keep { typed, by_ref, seen: Vec::new() };
        schemas::stream_recording(&path, Some(&metric), &mut keep).unwrap();
        keep.seen
    };
    let generic = read(false, false);
    assert_eq!(generic.len(), 5 * 301, "five metric topics, 301 samples");
    for typed in [read(true, false), read(true, true)] {
        assert_eq!(typed.len(), generic.len());
        for (g, t) in generic.iter().zip(&typed) {
            assert!(!g.2 && t.2, "{} #{}: typed", g.0, g.1);
            assert!(g.3.same_bits(&t.3), "{} #{}:\n{:?}\n{:?}", g.0, g.1, g.3, t.3);
        }
    }
    // the file's /contacts: nine contacts, two of them in touch at some sample
    let contacts: Vec<&Value> = generic.iter().filter(|s| s.0 == topics::CONTACTS).map(|s| &s.3).collect();
    assert!(contacts.iter().all(|v| matches!(v.get("name"), Some(Value::List(n)) if n.len() == 9)));
    assert!(contacts.iter().any(|v| matches!(v.get("mode"), Some(Value::List(m)) if m.iter().any(|c| *c != Value::U64(0)))));
}
