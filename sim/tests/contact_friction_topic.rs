//! `/contact_friction` (issue 27 item 4: the Foxglove half of the slip/stick view), read back
//! from a recording and checked against `/contacts` at every sample and against the closed form
//! of a sliding block (`contacts_point.rs`: v0 = 2 m/s at 30°, μ = 0.4, it slides with
//! `|v_t| = v0 − μ g t` and `|f_t| = μ m g` until `t_s = v0/(μ g)`, then sticks).
//!
//! The run has a second contact, `lid`, with μ = 0.3 on a plane 0.5 m below the ball: always
//! separated, f_n = 0, so its friction use is the documented 0 (not 0/0). A run whose contacts
//! have no friction (μ = 0) writes no `/contact_friction`.
//!
//! Tolerances: the topic against `/contacts` 1e-12 (relative, for |v_t| and |f_t|/(μ f_n): the
//! same few floating-point operations); the closed form 1e-9 of v0 (the motion is quadratic in
//! t, dopri45 at rtol 1e-12), friction use 1 ± 1e-9 while sliding and ≤ 1e-9 while sticking.

use crate::contacts_support::*;
use schemas::{ContactFriction, ContactState};
use serde_json::json;

const M: f64 = 1.0;

fn sliding_block(mu: f64, lid_mu: f64) -> serde_json::Value {
    let (v0, dir) = (2.0, 30f64.to_radians());
    let mut s = passive_scene("ball", &["x", "y", "z"], &[0.0; 3], &[v0 * dir.cos(), v0 * dir.sin(), 0.0], [0.0, 0.0, -G], 1.0, 1e-12);
    add_table_contact(&mut s, "floor", json!({"link": "ball"}), json!({"model": "unilateral", "friction": mu}));
    add_table_contact(&mut s, "lid", json!({"link": "ball"}), json!({"model": "unilateral", "friction": lid_mu}));
    s["contacts"][1]["plane"]["offset"] = json!(-0.5);
    s
}

fn record(s: &serde_json::Value, dir: &std::path::Path) -> schemas::Recording {
    let scene = load(s, &point_urdf(M));
    let path = dir.join("block.mcap");
    let run = scene.run("r").unwrap().clone();
    sim::run::run_to_file(&scene, &run, &path, |_| {}).unwrap();
    schemas::read_recording(&path).unwrap()
}

#[test]
fn the_friction_topic_is_the_contacts_slip_speed_and_friction_use_at_every_sample() {
    let (v0, mu, lid_mu) = (2.0, 0.4, 0.3);
    let dir = tempfile::tempdir().unwrap();
    let rec = record(&sliding_block(mu, lid_mu), dir.path());
    let states: Vec<(f64, ContactState)> = rec.read().unwrap();
    let friction: Vec<(f64, ContactFriction)> = rec.read().unwrap();
    let log_times = |topic: &str| -> Vec<u64> { rec.messages(topic).unwrap().iter().map(|(t, _)| *t).collect() };
    assert_eq!(states.len(), 1001);
    assert_eq!(log_times(schemas::topics::CONTACT_FRICTION), log_times(schemas::topics::CONTACTS), "one message per /contacts sample, at its log time");
    let mus = [mu, lid_mu];
    let t_s = v0 / (mu * G);
    let (mut sliding, mut sticking) = (0, 0);
    for ((_, s), (_, f)) in states.iter().zip(&friction) {
        assert_eq!(f.time, s.time);
        assert_eq!(f.name, ["floor", "lid"]);
        assert_eq!(f.mode, s.mode, "t = {}", s.time);
        assert_eq!((f.slip_speed.len(), f.friction_use.len()), (2, 2));
        for (k, mu_k) in mus.iter().enumerate() {
            let speed = s.slip_velocity_t1[k].hypot(s.slip_velocity_t2[k]);
            assert!((f.slip_speed[k] - speed).abs() <= 1e-12 * speed.max(1e-300), "t = {} {}: |v_t| {} vs {speed}", s.time, f.name[k], f.slip_speed[k]);
            let (f_t, cone) = (s.friction_force_t1[k].hypot(s.friction_force_t2[k]), mu_k * s.normal_force[k]);
            let want = if cone > 0.0 { f_t / cone } else { 0.0 };
            assert!((f.friction_use[k] - want).abs() <= 1e-12 * want, "t = {} {}: use {} vs {want}", s.time, f.name[k], f.friction_use[k]);
        }
        // the lid: separated, no normal force, friction use 0 (not 0/0)
        assert_eq!((f.mode[1], s.normal_force[1], f.friction_use[1]), (0, 0.0, 0.0), "t = {}", s.time);
        // the floor: the closed form
        let t = s.time;
        if t < t_s - 1e-3 {
            sliding += 1;
            assert_eq!(f.mode[0], schemas::contact_mode::SLIDING, "t = {t}");
            assert!((f.slip_speed[0] - (v0 - mu * G * t)).abs() <= 1e-9 * v0, "t = {t}: |v_t| {} vs {}", f.slip_speed[0], v0 - mu * G * t);
            assert!((f.friction_use[0] - 1.0).abs() <= 1e-9, "t = {t}: sliding uses the whole cone, {}", f.friction_use[0]);
        } else if t > t_s + 1e-3 {
            sticking += 1;
            assert_eq!(f.mode[0], schemas::contact_mode::STICKING, "t = {t}");
            assert!(f.slip_speed[0] <= 1e-9 && f.friction_use[0] <= 1e-9, "t = {t}: at rest, {} m/s, use {}", f.slip_speed[0], f.friction_use[0]);
        }
    }
    // t_s = 0.51 s: about half the samples on each side
    assert!(sliding > 500 && sticking > 480, "{sliding} sliding, {sticking} sticking samples");
}

#[test]
fn a_run_without_friction_writes_no_friction_topic() {
    let dir = tempfile::tempdir().unwrap();
    let rec = record(&sliding_block(0.0, 0.0), dir.path());
    assert!(rec.channel(schemas::topics::CONTACTS).is_some());
    assert!(rec.channel(schemas::topics::CONTACT_FRICTION).is_none());
}
