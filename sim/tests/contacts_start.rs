//! Contacts whose event functions start on their firing side (the review of issue 11, F1 and
//! F4): the event driver watches such a function from its start value
//! (`sim/src/integrate/events.rs`), so a contact closed with f_n = 0 whose force then turns
//! negative lifts off at once instead of pulling, and a slip that starts very slow (below the
//! 1e-6 m/s under which the friction direction is frozen) stops at its located zero instead of
//! reversing under a frozen friction direction.

use crate::contacts_support::*;
use serde_json::json;
use sim::dynamics::contact::{ContactEventKind, ContactMode};

/// A 1 kg ball resting on the table with NO gravity (f_n = 0 and g̈ = 0 at t0: the undetermined
/// case, where the mode problem keeps the contact closed), pulled up by its z motor from t = 0
/// (PD towards a joint spline 0 → 0.4 m in 1 s). The force the closed contact would need is
/// −F(t) < 0 from the first instant: the ball must lift off at t0. Checked with and without
/// friction: one lift-off at t = 0 exactly, no other event, and the recorded normal force never
/// below −1e-8 N (the dead band of a force function; a pulling table would reach −10 N by 0.5 s).
#[test]
fn a_ball_resting_with_zero_force_lifts_off_at_once_when_pulled() {
    for keys in [json!({"model": "unilateral", "friction": 0.5}), json!({"model": "unilateral"})] {
        let mut s = passive_scene("ball", &["x", "y", "z"], &[0.0; 3], &[0.0; 3], [0.0, 0.0, 0.0], 0.5, 1e-12);
        add_table_contact(&mut s, "floor", json!({"link": "ball"}), keys.clone());
        s["passive"] = json!(["x", "y"]);
        s["controller"] = json!({"kp": [0.0, 0.0, 100.0], "kd": 0.0});
        s["target"] = json!({"kind": "joint-spline", "waypoints": [{"t": 0.0, "q": [0.0, 0.0, 0.0]}, {"t": 1.0, "q": [0.0, 0.0, 0.4]}]});
        let c = collect(&load(&s, &point_urdf(1.0)), "r");
        let kinds: Vec<(f64, ContactEventKind)> = c.events.iter().map(|e| (e.t, e.kind)).collect();
        assert_eq!(kinds, vec![(0.0, ContactEventKind::LiftOff)], "{keys}");
        let min_fn = c.samples.iter().map(|o| o.contacts[0].normal_force).fold(f64::INFINITY, f64::min);
        assert!(min_fn >= -1e-8, "{keys}: the table pulled with {min_fn} N");
        let last = c.samples.last().expect("samples");
        assert_eq!(last.contacts[0].mode, ContactMode::Separated, "{keys}");
        assert!(last.contacts[0].gap > 1e-3, "{keys}: the ball rose to {} m", last.contacts[0].gap);
    }
}

/// A block sliding at 5e-7 m/s (below the 1e-6 m/s under which the friction direction is frozen,
/// `dynamics/contact/forward.rs`): friction μ m g slows it and the slip stops at its located
/// zero, `t_s = v₀/(μ g)` = 1.02e-7 s (issue 23 item 2; the old rule stopped it at t0 by a stick
/// speed), never reversing (before the review's fix the frozen direction pushed it backwards to
/// 7.6e-14 m behind its start). Checked: one slip-to-stick at t_s to 1e-12 s, then sticking with
/// x = v₀²/(2 μ g) (1e-9 relative) and |ẋ| ≤ 1e-12 m/s, and the friction work ½ m v₀² to 1e-9
/// relative, never decreasing.
#[test]
fn a_very_slow_slip_stops_at_its_located_zero_without_reversing() {
    let (v0, mu) = (5e-7, 0.5);
    let mut s = passive_scene("ball", &["x", "y", "z"], &[0.0; 3], &[v0, 0.0, 0.0], [0.0, 0.0, -G], 0.01, 1e-12);
    add_table_contact(&mut s, "floor", json!({"link": "ball"}), json!({"model": "unilateral", "friction": mu}));
    let c = collect(&load(&s, &point_urdf(1.0)), "r");
    let kinds: Vec<ContactEventKind> = c.events.iter().map(|e| e.kind).collect();
    assert_eq!(kinds, vec![ContactEventKind::SlipToStick]);
    let t_s = v0 / (mu * G);
    assert!((c.events[0].t - t_s).abs() <= 1e-12, "stops at {} s, v₀/(μ g) = {t_s} s", c.events[0].t);
    let d = v0 * v0 / (2.0 * mu * G);
    let mut w_prev = 0.0;
    for o in &c.samples[1..] {
        assert_eq!(o.contacts[0].mode, ContactMode::Sticking, "t = {}", o.t);
        assert!((o.q[0] - d).abs() <= 1e-9 * d && o.qd[0].abs() <= 1e-12, "t = {}: x = {}, x' = {}, want x = {d}", o.t, o.q[0], o.qd[0]);
        let w = o.contacts[0].friction_work;
        assert!(w >= w_prev, "friction work decreased at t = {}: {w} < {w_prev}", o.t);
        w_prev = w;
    }
    let expected = 0.5 * v0 * v0;
    assert!((w_prev - expected).abs() <= 1e-9 * expected, "friction work {w_prev}, ½ m v0² = {expected}");
}

/// Two point masses (1 kg and 3 kg, on joints of their own: M is block-diagonal) resting on the
/// table, each sliding slowly in its own direction (5e-7 m/s along x, 3e-7 m/s along −y): each
/// slip stops at its own located zero |v|/(μ g) (1e-12 s), and each contact's friction work
/// must be ITS ball's ½ m v², to 1e-9 relative. The total alone is the projection's
/// kinetic-energy loss by construction (`sim/src/ode/stop_slip.rs` books it so); the split
/// between the contacts is what this checks: booking the loss on one contact, or splitting it
/// by any rule other than each contact's own impulse work −Λ_kᵀ(v⁻_k + v⁺_k)/2, fails.
#[test]
fn two_slips_stopping_at_once_each_book_their_own_kinetic_energy() {
    let (m1, m2, v1, v2) = (1.0, 3.0, 5e-7, -3e-7);
    let lim = r#"<limit lower="-1000" upper="1000" effort="1e6" velocity="1e3"/>"#;
    let ball = |k: usize, m: f64| {
        format!(
            r#"<joint name="x{k}" type="prismatic"><parent link="base"/><child link="cx{k}"/><origin xyz="0 0 0"/><axis xyz="1 0 0"/>{lim}</joint>
  <link name="cx{k}"/>
  <joint name="y{k}" type="prismatic"><parent link="cx{k}"/><child link="cy{k}"/><origin xyz="0 0 0"/><axis xyz="0 1 0"/>{lim}</joint>
  <link name="cy{k}"/>
  <joint name="z{k}" type="prismatic"><parent link="cy{k}"/><child link="ball{k}"/><origin xyz="0 0 0"/><axis xyz="0 0 1"/>{lim}</joint>
  <link name="ball{k}"><inertial><origin xyz="0 0 0"/><mass value="{m}"/><inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/></inertial></link>"#
        )
    };
    let urdf = format!("<?xml version=\"1.0\"?>\n<robot name=\"two-points\">\n  <link name=\"base\"/>\n  {}\n  {}\n</robot>", ball(1, m1), ball(2, m2));
    let joints = ["x1", "y1", "z1", "x2", "y2", "z2"];
    let q0 = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0];
    let qd0 = [v1, 0.0, 0.0, 0.0, v2, 0.0];
    let mut s = passive_scene("ball1", &joints, &q0, &qd0, [0.0, 0.0, -G], 0.01, 1e-12);
    add_table_contact(&mut s, "floor1", json!({"link": "ball1"}), json!({"model": "unilateral", "friction": 0.5}));
    add_table_contact(&mut s, "floor2", json!({"link": "ball2"}), json!({"model": "unilateral", "friction": 0.5}));
    let c = collect(&load(&s, &urdf), "r");
    let stops: Vec<(usize, f64)> = c.events.iter().filter(|e| e.kind == ContactEventKind::SlipToStick).map(|e| (e.contact, e.t)).collect();
    assert_eq!(stops.len(), 2, "both slips stop: {:?}", c.events);
    for (k, t) in stops {
        let v = [v1, v2][k];
        assert!((t - v.abs() / (0.5 * G)).abs() <= 1e-12, "contact {k} stops at {t} s, |v|/(μ g) = {} s", v.abs() / (0.5 * G));
    }
    let last = c.samples.last().expect("samples");
    for (k, (m, v)) in [(m1, v1), (m2, v2)].into_iter().enumerate() {
        assert_eq!(last.contacts[k].mode, ContactMode::Sticking, "contact {k}");
        let w = last.contacts[k].friction_work;
        let expected = 0.5 * m * v * v;
        assert!((w - expected).abs() <= 1e-9 * expected, "contact {k}: friction work {w} J, its ball's ½ m v² = {expected} J");
    }
    for o in &c.samples[1..] {
        assert!(o.qd.iter().all(|v| v.abs() <= 1e-12), "t = {}: q̇ = {:?}", o.t, o.qd);
    }
}
