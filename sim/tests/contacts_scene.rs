//! The contact syntax of the scene (issue 11), black-box through `Scene::from_json`: bad
//! values are errors naming the field and the value (never a panic); a contact without `model`
//! stays bilateral and the paper scene's text is unchanged when re-serialised; the `table`
//! construct makes unilateral contacts active in every run; `events` settings are read.


use crate::contacts_support::*;
use serde_json::json;
use sim::dynamics::contact::ContactModel;
use sim::scene::Scene;

fn ball_with(contact: serde_json::Value, z0: f64) -> serde_json::Value {
    let mut s = passive_scene("ball", &["x", "y", "z"], &[0.0, 0.0, z0], &[0.0; 3], [0.0, 0.0, -G], 0.1, 1e-10);
    add_table_contact(&mut s, "floor", json!({"link": "ball"}), contact);
    s
}

/// The error message of a scene that must be rejected.
fn rejected(s: &serde_json::Value) -> String {
    match try_load(s, &point_urdf(1.0)) {
        Ok(_) => panic!("accepted: {s:#}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn bad_contact_values_are_errors_naming_the_field_and_the_value() {
    let cases: [(serde_json::Value, f64, &[&str]); 8] = [
        (json!({"model": "elastic"}), 0.0, &["contacts[0].model", "elastic"]),
        (json!({"model": "unilateral", "restitution": 1.5}), 0.0, &["contacts[0].restitution", "1.5"]),
        (json!({"model": "unilateral", "restitution": -0.1}), 0.0, &["contacts[0].restitution", "-0.1"]),
        (json!({"model": "unilateral", "friction": -0.2}), 0.0, &["contacts[0].friction", "-0.2"]),
        (json!({"model": "compliant", "stiffness": 0.0, "damping": 1.0}), 0.0, &["contacts[0].stiffness", "0"]),
        (json!({"model": "compliant", "stiffness": 1e4, "damping": -1.0}), 0.0, &["contacts[0].damping", "-1"]),
        // a key that does not belong to the chosen model
        (json!({"model": "unilateral", "stiffness": 1e4}), 0.0, &["contacts[0].stiffness"]),
        (json!({"restitution": 0.5}), 0.0, &["contacts[0].restitution"]),
    ];
    for (contact, z0, words) in cases {
        let e = rejected(&ball_with(contact.clone(), z0));
        for w in words {
            assert!(e.contains(w), "{contact}: the error does not name `{w}`: {e}");
        }
        assert!(e.starts_with("contact-test.json"), "{contact}: the error names the file: {e}");
    }
}

/// A unilateral contact that starts inside the table (gap −1e-6 m, beyond the 1e-9 m gap
/// tolerance) is an error that gives the gap; at −1e-12 m (within it) the scene is accepted.
#[test]
fn a_unilateral_contact_starting_inside_the_table_is_an_error_with_its_gap() {
    let e = rejected(&ball_with(json!({"model": "unilateral"}), -1e-6));
    assert!(e.contains("floor") || e.contains("contacts[0]"), "names the contact: {e}");
    assert!(e.contains("1e-6") || e.contains("0.000001") || e.contains("1.000e-6") || e.contains("-1e-6"), "gives the gap: {e}");
    assert!(try_load(&ball_with(json!({"model": "unilateral"}), -1e-12), &point_urdf(1.0)).is_ok());
    // separated at the start (above the table) is fine: found by touch-down
    assert!(try_load(&ball_with(json!({"model": "unilateral"}), 0.5), &point_urdf(1.0)).is_ok());
}

#[test]
fn bad_event_settings_are_errors_naming_the_field() {
    for (events, field) in [
        (json!({"time_tolerance": 0.0}), "events.time_tolerance"),
        (json!({"time_tolerance": -1e-12}), "events.time_tolerance"),
        (json!({"rest_velocity": -1.0}), "events.rest_velocity"),
        (json!({"bogus": 1.0}), "bogus"),
    ] {
        let mut s = ball_with(json!({"model": "unilateral"}), 0.0);
        s["events"] = events.clone();
        let e = rejected(&s);
        assert!(e.contains(field), "{events}: {e}");
    }
}

/// Compatibility: the paper scene's contacts have no `model` and stay bilateral; re-serialised,
/// its spec has none of the new keys (so recordings' stored scenes are unchanged).
#[test]
fn the_paper_scene_stays_bilateral_and_serialises_without_the_new_keys() {
    let scene = Scene::paper().unwrap();
    assert!(scene.contact_models().iter().all(|c| c.model == ContactModel::Bilateral));
    assert!(scene.runs().iter().all(|r| !scene.run_is_hybrid(r)));
    let text = serde_json::to_string(scene.spec()).unwrap();
    for key in ["\"model\"", "\"restitution\"", "\"friction\"", "\"table\"", "\"events\"", "\"stiffness\""] {
        assert!(!text.contains(key), "the paper spec serialises with {key}: {text}");
    }
}

/// The `table`: one plane under named points, unilateral by default, active in every run (a
/// run listing no contacts still has them), named as given; its keys are validated like a
/// contact's. Tested on the whole-arm table scene of the paper question.
#[test]
fn the_table_makes_unilateral_contacts_in_every_run() {
    let scene = Scene::load(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/contacts/paper_table.json")).unwrap();
    let run = scene.run("table").unwrap();
    let contacts = scene.run_contact_models(run);
    let names: Vec<&str> = contacts.iter().map(|c| c.name()).collect();
    assert_eq!(names, ["joint3", "elbow4", "joint5", "joint6", "elbow7", "joint8", "joint9", "joint10", "hand"]);
    assert!(contacts.iter().all(|c| c.model == ContactModel::Unilateral { restitution: 0.0, friction: 0.5 }), "{contacts:?}");
    assert!(scene.run_is_hybrid(run));
    // the model defaults to unilateral (frictionless, plastic)
    let mut s = ball_with(json!({}), 0.0);
    s["contacts"] = json!([]);
    s["runs"][0]["contacts"] = json!([]);
    s["table"] = json!({"plane": {"normal": [0.0, 0.0, 1.0], "offset": 0.0}, "points": [{"name": "p", "point": {"link": "ball"}}]});
    let sc = load(&s, &point_urdf(1.0));
    let c = sc.run_contact_models(sc.run("r").unwrap());
    assert_eq!(c.len(), 1);
    assert_eq!(c[0].model, ContactModel::Unilateral { restitution: 0.0, friction: 0.0 });
    s["table"]["restitution"] = json!(2.0);
    let e = rejected(&s);
    assert!(e.contains("table.restitution") && e.contains('2'), "{e}");
}
