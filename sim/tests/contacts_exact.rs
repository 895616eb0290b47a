//! Contacts exact (issue 23, items 1 and 7, and the property test of item 4): restitution that
//! ends a bounce sequence with the contact closed at rest, the stick → slip event against a
//! closed form, friction work and the rotors' impulsive work checked by balances, multi-contact
//! impacts and slips with closed forms, stabilisation with unilateral contacts, and random
//! unilateral scenes holding the contact audit at every sample.
//!
//! The laws (Pfeiffer & Glocker, *Multibody Dynamics with Unilateral Contacts*, 1996, ch. 5–7;
//! Brogliato, *Nonsmooth Mechanics*, 3rd ed., 2016, §§ 5.2, 6.1; Acary & Brogliato 2008, §1.1.1
//! for the bouncing ball and its accumulation point). The rule that ends a bounce sequence (the
//! book's `explanation/contacts.md`, "Ending a bounce sequence"): an impact whose approach speed
//! `−ġ⁻` is below `events.rest_velocity` (default 1e-4 m/s) is plastic (e = 0, kind `rest`) and
//! leaves ġ = 0; a contact closes only with |g| ≤ gap_tol and |ġ| ≤ vel_tol (1e-9 m, 1e-9 m/s).
//!
//! The contact audit is `schemas::ContactAuditor`, the one `sim` and `analyze` run
//! (`contacts_support::audit`); the energy balance is the run's own residual.

#![allow(clippy::needless_range_loop)] // per-contact arrays indexed together

use std::path::Path;

use crate::contacts_support::*;
use serde_json::json;
use sim::dynamics::contact::{ContactEventKind, ContactMode};

const M: f64 = 1.0;

fn ball(q0: [f64; 3], qd0: [f64; 3], gravity: [f64; 3], duration: f64, contact: serde_json::Value) -> serde_json::Value {
    let mut s = passive_scene("ball", &["x", "y", "z"], &q0, &qd0, gravity, duration, 1e-12);
    add_table_contact(&mut s, "floor", json!({"link": "ball"}), contact);
    s
}

fn assert_audit_holds(what: &str, scene: &sim::scene::Scene, run: &str, c: &Collected) {
    let a = audit(scene, run, c);
    assert_eq!(a.samples as usize, c.samples.len(), "{what}: every sample audited");
    assert!(a.verdict().is_none(), "{what}: the contact laws do not hold: {}", a.verdict().unwrap_or_default());
}

/// The bouncing ball (Acary & Brogliato 2008, §1.1.1) dropped from h0 = 0.1 m with e = 0.5
/// and e = 0.9 and the DEFAULT rest rule (`rest_velocity` 1e-4 m/s): the flights before rest
/// are as short as 2 e v_n / g ≈ 2e-5 s, shorter than the integrator's steps on this exactly
/// quadratic motion, so each rebound's return must be located inside a step (on main the
/// touch-down fired at the rebound's restart and closed the contact with ġ = +e v_k).
///
/// Closed form: v_0 = sqrt(2 g h0) at t_0 = sqrt(2 h0/g), v_k = e^k v_0, t_{k+1} = t_k +
/// 2 v_{k+1}/g; the rule: n = the smallest k with v_0 e^k < v_rest impacts (e = 0.5: 14; 0.9:
/// 91), the last plastic (`rest`) with ġ⁺ = 0; then at rest with f_n = m g at every sample.
///
/// Tolerances: event times 1e-9 relative (each event bracketed to 1e-12 s, the upper end
/// taken); speeds to `δv = (n + 1) · 10 · g · 1e-12` m/s (each event's bracket moves ġ by up to
/// g · 1e-12, and the errors carry on to the next flight; 2e-9 m/s for e = 0.5, 9e-9 for 0.9),
/// impulses to m (1 + e) δv; at rest |g| ≤ 1e-9 m, |ż| ≤ 1e-9 m/s, f_n = m g to 1e-9; the
/// cumulative impact loss = m g h0 to 1e-9; the audit holds at every sample.
#[test]
fn a_bouncing_ball_follows_the_closed_form_up_to_the_rest_rule_then_rests_with_f_n_m_g() {
    for (e, n_want, duration) in [(0.5f64, 14, 0.6), (0.9, 91, 3.0)] {
        let h0 = 0.1;
        let s = ball([0.0, 0.0, h0], [0.0; 3], [0.0, 0.0, -G], duration, json!({"model": "unilateral", "restitution": e}));
        let scene = load(&s, &point_urdf(M));
        let v_rest = scene.contact_settings().rest_velocity;
        assert_eq!(v_rest, 1e-4, "the default rest rule");
        let v0 = (2.0 * G * h0).sqrt();
        let n = (0..).find(|&k| v0 * e.powi(k) < v_rest).unwrap() as usize;
        assert_eq!(n, n_want, "e = {e}");
        let dv = (n as f64 + 1.0) * 10.0 * G * 1e-12;
        // the rule's decision is far from the bound at both ends
        assert!(v0 * e.powi(n as i32 - 1) - v_rest > 100.0 * dv && v_rest - v0 * e.powi(n as i32) > 100.0 * dv);
        let mut t = vec![(2.0 * h0 / G).sqrt()];
        for k in 1..=n {
            t.push(t[k - 1] + 2.0 * v0 * e.powi(k as i32) / G);
        }
        let c = collect(&scene, "r");
        let kinds: Vec<_> = c.events.iter().map(|x| x.kind).collect();
        let mut want = vec![ContactEventKind::Impact; n];
        want.push(ContactEventKind::Rest);
        assert_eq!(kinds, want, "e = {e}: the events {:?}", c.events);
        let mut worst_t = 0.0f64;
        for (k, ev) in c.events.iter().enumerate() {
            let vk = v0 * e.powi(k as i32);
            worst_t = worst_t.max((ev.t - t[k]).abs() / t[k]);
            assert!((ev.t - t[k]).abs() <= 1e-9 * t[k], "e = {e}, event {k}: t = {} s, closed form {} s", ev.t, t[k]);
            assert!((ev.gap_rate_before + vk).abs() <= dv, "e = {e}, event {k}: ġ⁻ = {}, −v_k = {}", ev.gap_rate_before, -vk);
            let e_k = if k < n { e } else { 0.0 };
            assert!((ev.gap_rate_after - e_k * vk).abs() <= dv, "e = {e}, event {k}: ġ⁺ = {}, e v_k = {}", ev.gap_rate_after, e_k * vk);
            assert!((ev.impulse - M * (1.0 + e_k) * vk).abs() <= M * (1.0 + e_k) * dv, "e = {e}, event {k}: impulse {}", ev.impulse);
        }
        eprintln!("e = {e}: {} impacts then rest at {} s (closed form {} s), worst event time error {worst_t:.1e} relative", n, c.events[n].t, t[n]);
        let at_rest: Vec<_> = c.between(t[n] + 1e-6, 10.0).collect();
        assert!(at_rest.len() > 100, "e = {e}");
        for o in at_rest {
            let f = &o.contacts[0];
            assert!(touching(f.mode), "e = {e}, t = {}: mode {:?} after rest", o.t, f.mode);
            assert!(f.gap.abs() <= 1e-9 && f.gap_rate.abs() <= 1e-9 && o.qd[2].abs() <= 1e-9, "e = {e}, t = {}: gap {} m, ġ {} m/s", o.t, f.gap, f.gap_rate);
            assert!((f.normal_force - M * G).abs() <= 1e-9 * M * G, "e = {e}, t = {}: f_n {} N", o.t, f.normal_force);
        }
        let last = &c.samples.last().unwrap().contacts[0];
        assert!((last.impact_loss - M * G * h0).abs() <= 1e-9 * M * G * h0, "e = {e}: impact loss {} J, m g h0 = {} J", last.impact_loss, M * G * h0);
        assert_audit_holds(&format!("bouncing ball e = {e}"), &scene, "r", &c);
    }
}

/// The built-in `paper-unilateral` scene (`sim/scenes/paper_unilateral.json`) with the contacts
/// elbow4 and elbow7 only, friction 0 and restitution 0.5, as the issue's reproduction, with a
/// duration of `duration` s.
pub fn paper_bounce(duration: f64) -> sim::scene::Scene {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut s: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("paper_unilateral.json")).unwrap()).unwrap();
    s["name"] = "paper-bounce".into();
    s["duration"] = duration.into();
    let contacts = s["contacts"].as_array_mut().unwrap();
    contacts.retain(|c| c["name"] == "elbow4" || c["name"] == "elbow7");
    for c in contacts.iter_mut() {
        c["friction"] = 0.0.into();
        c["restitution"] = 0.5.into();
    }
    s["runs"].as_array_mut().unwrap().retain(|r| r["name"] != "whole-table");
    sim::scene::Scene::from_json(&s.to_string(), "paper-bounce.json", |f| std::fs::read_to_string(dir.join(f)).map_err(|e| e.to_string())).unwrap()
}

/// The paper arm with restitution 0.5 (issue 23's reproduction): both runs, at the scene's own
/// integrator settings (rodas5p rtol 1e-8), hold the contact audit at every sample and close
/// the energy balance to 1e-9 of the electric energy at every sample (the acceptance's bound;
/// measured 7.5e-10 two-elbow). On main elbow7 closed 15 mm above the table (two-elbow) and
/// elbow4 7 mm (one-elbow), the residual reached 9.2e-4 E. Every impact obeys Newton's law
/// (ġ⁺ = −e ġ⁻, 1e-9 (1 + |ġ⁻|); `rest`: ġ⁺ = 0); no contact is closed by a touch-down with
/// a separating speed (|ġ| ≤ vel_tol at each touch-down). Prints the hand's final position and
/// the events (the report's numbers).
#[test]
fn the_paper_arm_with_restitution_holds_the_audit_and_closes_its_balance() {
    let scene = paper_bounce(5.0);
    let vel_tol = scene.contact_settings().vel_tol;
    for run in ["two-elbow-unilateral", "one-elbow-unilateral"] {
        let c = collect(&scene, run);
        assert_audit_holds(run, &scene, run, &c);
        let (rel, e) = balance(&c);
        let h = c.samples.last().unwrap().hand;
        eprintln!("{run}: hand at t = 5 s ({:.9}, {:.9}, {:.9}) m; Σ|E_j| = {e:.6} J; max |residual| / E = {rel:.2e}; {} events:", h.x, h.y, h.z, c.events.len());
        for ev in &c.events {
            let name = if ev.contact == 0 { "elbow4" } else { "elbow7" };
            eprintln!("  t = {:.9} s  {name:<7} {:<13} ġ⁻ = {:+.4e}  ġ⁺ = {:+.4e}  Λ = {:.4e}", ev.t, ev.kind.name(), ev.gap_rate_before, ev.gap_rate_after, ev.impulse);
        }
        assert!(rel <= 1e-9, "{run}: the balance residual reaches {rel:.2e} of E");
        for ev in &c.events {
            match ev.kind {
                ContactEventKind::Impact => {
                    assert!((ev.gap_rate_after + 0.5 * ev.gap_rate_before).abs() <= 1e-9 * (1.0 + ev.gap_rate_before.abs()), "{run}: {ev:?}")
                }
                ContactEventKind::Rest => assert!(ev.gap_rate_after.abs() <= 1e-9 * (1.0 + ev.gap_rate_before.abs()), "{run}: {ev:?}"),
                ContactEventKind::TouchDown => assert!(ev.gap_rate_after.abs() <= vel_tol, "{run}: a touch-down with ġ = {} m/s: {ev:?}", ev.gap_rate_after),
                _ => {}
            }
        }
        assert!(c.events.iter().any(|x| x.kind == ContactEventKind::Rest), "{run}: a bounce sequence ends by the rule");
    }
}

/// One impact while another contact is closed (the impact law with the closed contact as a
/// unilateral constraint, Pfeiffer & Glocker 1996 §6.2): a uniform rod (m, length 2l, inertia
/// m l²/3 about its centre) lies horizontal on the table, end A at rest on it (ġ_A = 0) and
/// end B arriving at ġ_B⁻ = −2v (centre ż = −v, rotating about A). With impulses Λ_A, Λ_B up
/// at the ends, `Δġ_A = (4 Λ_A − 2 Λ_B)/m`, `Δġ_B = (4 Λ_B − 2 Λ_A)/m`; Newton at B
/// (ġ_B⁺ = 2 e v) with A kept closed (Λ_A > 0, ġ_A⁺ = 0) gives Λ_B = 2 m v (1 + e)/3,
/// Λ_A = m v (1 + e)/3 > 0, the kinetic energy lost Λ_B v (1 − e). (An impact that ignored A
/// would leave ġ_A⁺ = −v (1 + e): into the table.) e = 0.5, v = 1 m/s, at t = 0; 1e-12
/// relative (one small solve). Then the run holds the audit at every sample.
#[test]
fn an_impact_while_another_contact_is_closed_keeps_it_closed_with_the_closed_form_impulses() {
    let (l, v, e) = (0.5, 1.0, 0.5);
    let mut s = passive_scene("rod", &["x", "z", "pitch"], &[0.0, 0.0, 0.0], &[0.0, -v, v / l], [0.0, 0.0, -G], 0.2, 1e-10);
    add_table_contact(&mut s, "a", json!({"link": "rod", "offset": [-l, 0.0, 0.0]}), json!({"model": "unilateral", "restitution": e}));
    add_table_contact(&mut s, "b", json!({"link": "rod", "offset": [l, 0.0, 0.0]}), json!({"model": "unilateral", "restitution": e}));
    let scene = load(&s, &rod_urdf(M, l));
    let c = collect(&scene, "r");
    let first = &c.samples[0];
    assert!((first.contacts[0].gap_rate).abs() <= 1e-12 && (first.contacts[1].gap_rate - 2.0 * e * v).abs() <= 1e-12 * v, "ġ⁺ = {:?}", first.contacts.iter().map(|k| k.gap_rate).collect::<Vec<_>>());
    assert!(touching(first.contacts[0].mode) && first.contacts[1].mode == ContactMode::Separated, "{:?}", first.contacts);
    let at0: Vec<_> = c.events.iter().filter(|x| x.t == 0.0).collect();
    assert_eq!(at0.len(), 1, "one impact at t = 0 (A takes an impulse but does not move: no event): {at0:?}");
    let (lb, la) = (2.0 * M * v * (1.0 + e) / 3.0, M * v * (1.0 + e) / 3.0);
    assert_eq!((at0[0].contact, at0[0].kind), (1, ContactEventKind::Impact));
    assert!((at0[0].impulse - lb).abs() <= 1e-12 * lb, "Λ_B = {}, closed form {lb}", at0[0].impulse);
    assert!((at0[0].gap_rate_before + 2.0 * v).abs() <= 1e-12);
    // A's share: the loss booked on A is −Λ_A (ġ_A⁻ + ġ_A⁺)/2 = 0, the total is B's
    let loss: f64 = first.contacts.iter().map(|k| k.impact_loss).sum();
    assert!((loss - lb * v * (1.0 - e)).abs() <= 1e-12 * loss, "lost {loss} J, Λ_B v (1 − e) = {} J", lb * v * (1.0 - e));
    // the centre and the rotation after, from the impulses: ż⁺ = −v + (Λ_A + Λ_B)/m
    assert!((first.qd[1] - (-v + (la + lb) / M)).abs() <= 1e-12, "ż⁺ = {}", first.qd[1]);
    assert_audit_holds("rod impact on a closed contact", &scene, "r", &c);
}

// ----- item 7: tests that catch a wrong contact law -----

const K_TORQUE: f64 = 0.5;
const R: f64 = 1.0;
const KP: f64 = 100.0;
const DELTA: f64 = 0.4;
const PERIOD: f64 = 1.0;

/// The motor's push on the sticking block along x, N: the x joint's quasi-static motor (L = 0,
/// gear 1) under the PD law v = k_p (q_d − q) towards the joint spline q_d = Δ (3 s² − 2 s³),
/// s = t/T (two knots at rest): with the block at rest, i = v/R and F = K k_p q_d(t)/R =
/// 20 (3 s² − 2 s³) N, a ramp from 0 to 20 N over 1 s.
fn push(t: f64) -> f64 {
    let x = (t / PERIOD).clamp(0.0, 1.0);
    K_TORQUE * KP * DELTA * (3.0 * x * x - 2.0 * x * x * x) / R
}

/// A block (the point mass) sticking on the table (μ = 0.5) under the ramped push F(t) above
/// starts to slip exactly where F(t) = μ m g (bisection of the closed form): the first event is
/// a `stick-to-slip` (not `slip-to-stick`) at that time to 1e-10 s (the event function
/// μ f_n − |f_t| is a cubic in t while the block rests, exact on the dense output); before it
/// the block sticks with f_t = (−F(t), 0) and f_n = m g (1e-9 of μ m g), after it it slides
/// forward. A law that let go at 2 μ f_n fires at F = 2 μ m g (0.23 s later); swapped labels
/// fail the kind.
#[test]
fn a_ramped_push_starts_the_block_slipping_exactly_where_it_reaches_mu_m_g() {
    let mu = 0.5;
    let mut s = ball([0.0; 3], [0.0; 3], [0.0, 0.0, -G], 0.6, json!({"model": "unilateral", "friction": mu}));
    s["passive"] = json!(["y", "z"]);
    s["controller"] = json!({"kp": [KP, 0.0, 0.0], "kd": 0.0});
    s["target"] = json!({"kind": "joint-spline", "waypoints": [{"t": 0.0, "q": [0.0, 0.0, 0.0]}, {"t": PERIOD, "q": [DELTA, 0.0, 0.0]}]});
    s["integrator"] = json!({"method": "dopri45", "rtol": 1e-12, "atol": 1e-14});
    let scene = load(&s, &point_urdf(M));
    let limit = mu * M * G;
    let t_slip = bisect(0.0, PERIOD, |t| push(t) - limit);
    let c = collect(&scene, "r");
    let first = c.events.first().unwrap_or_else(|| panic!("no event"));
    assert_eq!((first.kind, first.contact), (ContactEventKind::StickToSlip, 0), "the first event: {:?}", c.events);
    assert!((first.t - t_slip).abs() <= 1e-10, "stick → slip at {} s, F(t) = μ m g at {t_slip} s (diff {:e})", first.t, first.t - t_slip);
    eprintln!("ramped push: stick → slip at {} s, closed form {t_slip} s (diff {:.1e} s)", first.t, first.t - t_slip);
    let mut before = 0;
    for o in c.between(-1.0, t_slip) {
        let f = &o.contacts[0];
        assert_eq!(f.mode, ContactMode::Sticking, "t = {}", o.t);
        assert!((f.friction_force[0] + push(o.t)).abs() <= 1e-9 * limit && f.friction_force[1].abs() <= 1e-9 * limit, "t = {}: f_t {:?}, −F = {}", o.t, f.friction_force, -push(o.t));
        assert!((f.normal_force - M * G).abs() <= 1e-9 * M * G && o.q[0].abs() <= 1e-12, "t = {}", o.t);
        before += 1;
    }
    assert!(before > 200, "{before} samples before the slip");
    for o in c.between(t_slip + 1e-3, t_slip + 0.05) {
        assert_eq!(o.contacts[0].mode, ContactMode::Sliding, "t = {}", o.t);
        assert!(o.qd[0] > 0.0, "t = {}: slides forward", o.t);
    }
}

/// A block sliding with v0 = 2 m/s (μ = 0.4) until it stops: the friction work booked by the
/// contact, `∫ −f_t · v_t dt`, is the kinetic energy lost, `½ m (v0² − |v(t)|²)`, at every
/// sample, and ½ m v0² after the stop (the slip → stick projection's last ~1e-6 m/s included);
/// the run's energy balance (which sums the contacts' friction work) closes to 1e-9 of ½ m v0²
/// at every sample. In 1-D (along x) and in 2-D (at 37° to x: both tangent rows carry the
/// friction). 1e-9 of ½ m v0² (the motion is quadratic in t, exact in dopri45 at rtol 1e-12).
/// A friction work left out of the balance, or booked at the wrong rate, fails here — not only
/// on the whole arm.
#[test]
fn the_friction_work_of_a_sliding_block_is_its_kinetic_energy_in_one_and_two_dimensions() {
    let (v0, mu) = (2.0, 0.4);
    for deg in [0.0f64, 37.0] {
        let (cx, cy) = (deg.to_radians().cos(), deg.to_radians().sin());
        let s = ball([0.0; 3], [v0 * cx, v0 * cy, 0.0], [0.0, 0.0, -G], 0.7, json!({"model": "unilateral", "friction": mu}));
        let c = collect(&load(&s, &point_urdf(M)), "r");
        let e0 = 0.5 * M * v0 * v0;
        let t_s = v0 / (mu * G);
        assert_eq!(c.events_of(ContactEventKind::SlipToStick).len(), 1, "{deg}°: {:?}", c.events);
        for o in &c.samples {
            let f = &o.contacts[0];
            let v2 = o.qd[0] * o.qd[0] + o.qd[1] * o.qd[1];
            let want = 0.5 * M * (v0 * v0 - v2);
            assert!((f.friction_work - want).abs() <= 1e-9 * e0, "{deg}°, t = {}: friction work {} J, ½ m (v0² − v²) = {want} J", o.t, f.friction_work);
            assert!(o.balance_residual.abs() <= 1e-9 * e0, "{deg}°, t = {}: balance residual {} J", o.t, o.balance_residual);
            if o.t > t_s + 1e-6 {
                assert!((f.friction_work - e0).abs() <= 1e-9 * e0, "{deg}°, t = {}: friction work {} J after the stop, ½ m v0² = {e0} J", o.t, f.friction_work);
            }
        }
    }
}

/// A motor-driven body with rotor inertia landing on the table: the ball's z joint has a DC
/// motor (torque constant 0.05 N m/A, gear 10: K_m = 0.5 N/A; rotor 0.01 kg m²: reflected
/// J_m = I_m k² = 1 kg, as heavy as the ball; R = 1 Ω, L = 0, shorted: v = 0, so the back EMF
/// brakes it), dropped from 5 cm with e = 0.5 (rest rule 0.05 m/s). At each impact the rotor
/// takes part: Λ = (m + J_m)(1 + e)|ġ⁻| (1e-9), and it hands the link the impulsive work
/// −J_m (q̇⁺² − q̇⁻²)/2. The link-side balance through the impacts, at every sample:
/// `W_z = ½ m ż² + m g (z − h0) + E_imp` (W_z the recorded link work of eq 12, E_imp the
/// contact's impact loss: the kinetic energy of link AND rotor lost; no damping), to 1e-9 of
/// m g h0 (dopri45 rtol 1e-12). Without the rotors' impulsive work in W_j it misses by
/// ½ J_m (v⁻² − v⁺²) at the first impact (~0.2 J).
#[test]
fn a_motor_driven_ball_landing_books_the_rotors_impulsive_work_in_its_link_work() {
    let (h0, e) = (0.05, 0.5);
    let mut s = ball([0.0, 0.0, h0], [0.0; 3], [0.0, 0.0, -G], 0.5, json!({"model": "unilateral", "restitution": e}));
    s["passive"] = json!(["x", "y"]);
    s["motor"] = json!({"torque_constant": 0.05, "resistance": 1.0, "inductance": 0.0, "rotor_inertia": 0.01, "gear_ratio": 10.0, "gear_damping": 0.0});
    s["controller"] = json!({"kp": 0.0, "kd": 0.0});
    s["events"] = json!({"rest_velocity": 0.05});
    let scene = load(&s, &point_urdf(M));
    let jm = 0.01 * 10.0 * 10.0;
    let c = collect(&scene, "r");
    let impacts: Vec<_> = c.events.iter().filter(|x| matches!(x.kind, ContactEventKind::Impact | ContactEventKind::Rest)).collect();
    assert!(impacts.len() >= 2 && impacts.last().unwrap().kind == ContactEventKind::Rest, "{:?}", c.events);
    for ev in &impacts {
        let e_k = if ev.kind == ContactEventKind::Rest { 0.0 } else { e };
        let want = (M + jm) * (1.0 + e_k) * -ev.gap_rate_before;
        assert!((ev.impulse - want).abs() <= 1e-9 * want, "impulse {} N s, (m + J_m)(1 + e)|ġ⁻| = {want}", ev.impulse);
    }
    let scale = M * G * h0;
    let mut worst = 0.0f64;
    for o in &c.samples {
        let link = 0.5 * M * o.qd[2] * o.qd[2] + M * G * (o.q[2] - h0) + o.contacts[0].impact_loss;
        worst = worst.max((o.link_work[2] - link).abs());
        assert!((o.link_work[2] - link).abs() <= 1e-9 * scale, "t = {}: W_z = {} J, ½ m ż² + m g Δz + E_imp = {link} J", o.t, o.link_work[2]);
        assert!(o.balance_residual.abs() <= 1e-9 * scale, "t = {}: balance residual {} J", o.t, o.balance_residual);
    }
    eprintln!("landing with rotor inertia: {} impacts, worst link-side residual {worst:.1e} J of m g h0 = {scale} J", impacts.len());
    assert_audit_holds("landing ball", &scene, "r", &c);
}

/// Two contacts starting to slip from rest (closed form): the rod of length 2l lies on the
/// table on two points, A at −l and B at +l/2 from its centre; gravity tilted (g_x = 6 m/s²,
/// g_z = −9.81) with μ = 0.4 < g_x / g_z: sticking cannot hold, both slide from t = 0 along +x.
/// Statics of the normal forces (moments about the centre, friction acts at the centre's
/// height): N_A l = N_B l/2, N_A + N_B = m g → N_A = m g/3, N_B = 2 m g/3; friction −μ N_k each
/// along x; ẍ = g_x − μ g, the rod neither lifts nor turns. Below the limit (g_x = 3) the rod
/// stays: no motion, friction in each cone and Σ f_t = −m g_x (the split is statically
/// indeterminate: A may sit on its cone's edge, μ N_A = 1.31 N < g_x / 2). No event in either. 1e-9 of m g
/// (forces) and 1e-9 relative (x = ½ a t², exact in dopri45).
///
/// With every stabilisation the scene offers (none, Baumgarte α = β = 50 1/s, projection) the
/// same closed form, and |ġ| ≤ 1e-9 m/s (vel_tol), |g| ≤ 1e-12 m (projection) and 1e-11 m
/// (Baumgarte: it settles at the drift's g̈ / β², 1e-12 m below) at every sample. Without stabilisation the closed rows drift at the acceleration
/// level: sliding, by the integrator's error (measured 5e-17 m); sticking, where the rod's
/// out-of-plane friction rows are zero and the solve is regularised, by g̈ ≈ −2.6e-9 m/s²
/// (measured |g| 3e-10 m, |ġ| 1.3e-9 m/s at 0.5 s), held to the closing tolerance 1e-9 m
/// and 1e-8 m/s — which is what stabilisation is for.
#[test]
fn two_contacts_start_slipping_from_rest_with_the_closed_form_forces() {
    let (l, mu) = (0.5, 0.4);
    for stab in [json!({"method": "none"}), json!({"method": "baumgarte", "alpha": 50.0, "beta": 50.0}), json!({"method": "projection"})] {
        for (gx, slides) in [(6.0, true), (3.0, false)] {
            let mut s = passive_scene("rod", &["x", "z", "pitch"], &[0.0; 3], &[0.0; 3], [gx, 0.0, -G], 0.5, 1e-12);
            add_table_contact(&mut s, "a", json!({"link": "rod", "offset": [-l, 0.0, 0.0]}), json!({"model": "unilateral", "friction": mu}));
            add_table_contact(&mut s, "b", json!({"link": "rod", "offset": [l / 2.0, 0.0, 0.0]}), json!({"model": "unilateral", "friction": mu}));
            s["dynamics"] = json!({"stabilization": stab});
            let scene = load(&s, &rod_urdf(M, l));
            let c = collect(&scene, "r");
            assert!(c.events.is_empty(), "{stab}, g_x = {gx}: no event: {:?}", c.events);
            let n = [M * G / 3.0, 2.0 * M * G / 3.0];
            let a = gx - mu * G;
            // without stabilisation the closed rows drift at the acceleration level (the
            // integrator's error, ~1e-12 m/s² here); with it the rows stay on the table
            let (gap_bound, rate_bound) = match stab["method"].as_str() {
                Some("none") => (1e-9, 1e-8),
                // Baumgarte leaves the drift's g̈ / β² = 2.6e-9 / 2500 = 1e-12 m
                Some("baumgarte") => (1e-11, 1e-9),
                _ => (1e-12, 1e-9),
            };
            let (mut worst_g, mut worst_gd) = (0.0f64, 0.0f64);
            for o in &c.samples {
                let what = format!("{stab}, g_x = {gx}, t = {}", o.t);
                for k in 0..2 {
                    let f = &o.contacts[k];
                    assert!((f.normal_force - n[k]).abs() <= 1e-9 * M * G, "{what}: f_n[{k}] = {}, closed form {}", f.normal_force, n[k]);
                    worst_g = worst_g.max(f.gap.abs());
                    worst_gd = worst_gd.max(f.gap_rate.abs());
                    assert!(f.gap.abs() <= gap_bound && f.gap_rate.abs() <= rate_bound, "{what}: contact {k} gap {} ġ {}", f.gap, f.gap_rate);
                    // sticking, the tangential split between the two is statically indeterminate:
                    // the solver may put one contact on its cone's edge (sliding with v_t = 0)
                    if slides {
                        assert_eq!(f.mode, ContactMode::Sliding, "{what}: contact {k}");
                    } else {
                        assert!(touching(f.mode), "{what}: contact {k}: {:?}", f.mode);
                    }
                    if slides {
                        assert!((f.friction_force[0] + mu * n[k]).abs() <= 1e-9 * M * G, "{what}: f_t[{k}] = {:?}, −μ N = {}", f.friction_force, -mu * n[k]);
                    } else {
                        assert!(f.friction_force[0].hypot(f.friction_force[1]) <= mu * f.normal_force * (1.0 + 1e-9), "{what}: contact {k} outside its cone");
                    }
                }
                if slides {
                    assert!((o.q[0] - 0.5 * a * o.t * o.t).abs() <= 1e-9 * 0.5 * a, "{what}: x = {}, ½ a t² = {}", o.q[0], 0.5 * a * o.t * o.t);
                } else {
                    let sum = o.contacts[0].friction_force[0] + o.contacts[1].friction_force[0];
                    // (a sticking contact has no anchor: v_t = 0 is held at the acceleration level)
                    assert!((sum + M * gx).abs() <= 1e-9 * M * G && o.q[0].abs() <= 1e-9, "{what}: Σ f_t = {sum}, x = {}", o.q[0]);
                }
                assert!(o.q[1].abs() <= gap_bound && o.q[2].abs() <= gap_bound, "{what}: the rod lifts or turns: {:?}", o.q);
            }
            eprintln!("two contacts, {stab}, g_x = {gx}: worst |g| {worst_g:.1e} m, |ġ| {worst_gd:.1e} m/s");
        }
    }
}

/// Stabilisation with unilateral contacts on the arm: the paper arm over the μ = 0.5 table
/// (the shipped `paper-unilateral`, two-elbow: lift-offs, touch-downs, sticking and sliding)
/// for 0.5 s with Baumgarte (α = β = 50 1/s) and with projection holds the contact audit at
/// every sample (closed |g| ≤ 1e-6 m, |ġ| ≤ 1e-6 m/s, no pull, the cone) and its energy balance
/// to 1e-8 of E; with projection the closed contacts sit on the table to 1e-12 m at every
/// sample (the projection iterates to 1e-13 m).
#[test]
fn stabilisation_keeps_unilateral_contacts_on_the_table() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let base = sim::scene::Scene::load(&dir.join("paper_unilateral.json")).unwrap();
    for stab in ["baumgarte", "projection"] {
        let scene = base
            .vary(|s| {
                s.duration = 0.5;
                s.dynamics.stabilization = if stab == "baumgarte" {
                    sim::dynamics::forward::Stabilization::Baumgarte { alpha: 50.0, beta: 50.0 }
                } else {
                    sim::dynamics::forward::Stabilization::Projection
                };
            })
            .unwrap();
        let c = collect(&scene, "two-elbow-unilateral");
        assert_audit_holds(stab, &scene, "two-elbow-unilateral", &c);
        let (rel, _) = balance(&c);
        assert!(rel <= 1e-8, "{stab}: balance residual {rel:.2e} of E");
        let mut worst = 0.0f64;
        for o in &c.samples {
            for f in o.contacts.iter().filter(|f| touching(f.mode)) {
                worst = worst.max(f.gap.abs());
            }
        }
        eprintln!("{stab}: {} events, worst closed |g| {worst:.1e} m, balance {rel:.1e}", c.events.len());
        if stab == "projection" {
            assert!(worst <= 1e-12, "projection: closed |g| up to {worst:e} m");
        }
    }
}

// ----- item 4: random unilateral scenes hold the audit -----

/// SplitMix64 (Steele, Lea & Flood 2014): the random scene of a seed, so a failing case is
/// reproduced from its seed alone (`ELBOW_CONTACT_SEED=0x… cargo test … random_unilateral`).
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// Uniform in [a, b).
    fn uniform(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The paper arm over a unilateral table, at random: μ in [0, 1.5] and e in [0, 0.9] per
/// elbow, every joint's initial speed in ±0.5 rad/s (the elbows start on the table moving: some
/// approach it — an impact at t = 0 — some leave it), the target circle's centre moved by up
/// to ±1 cm (further leaves the arm's reach somewhere on the circle; a draw the scene still
/// rejects as out of reach is drawn again) and its phase anywhere; the two-elbow run, 0.15 s.
pub(crate) fn random_scene(seed: u64) -> (sim::scene::Scene, String) {
    let mut rng = SplitMix(seed);
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut s: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("paper_unilateral.json")).unwrap()).unwrap();
    s["duration"] = 0.15.into();
    let contacts = s["contacts"].as_array_mut().unwrap();
    contacts.retain(|c| c["name"] == "elbow4" || c["name"] == "elbow7");
    for c in contacts.iter_mut() {
        c["friction"] = rng.uniform(0.0, 1.5).into();
        c["restitution"] = rng.uniform(0.0, 0.9).into();
    }
    let qd: Vec<f64> = (0..10).map(|_| rng.uniform(-0.5, 0.5)).collect();
    s["initial"]["qd"] = json!(qd);
    s["runs"].as_array_mut().unwrap().retain(|r| r["name"] == "two-elbow-unilateral");
    let centre: Vec<f64> = (0..3).map(|i| s["target"]["circle"]["center"][i].as_f64().unwrap()).collect();
    // a circle the scene rejects as out of the arm's reach is drawn again from the same
    // stream (seed 0x73e2d0c93e07247b's first draw: "outside its reach"); any other error of
    // the scene is the generator's defect and fails
    for draw in 0.. {
        let circle = &mut s["target"]["circle"];
        for (i, c) in centre.iter().enumerate() {
            circle["center"][i] = (c + rng.uniform(-0.01, 0.01)).into();
        }
        circle["phase"] = rng.uniform(0.0, std::f64::consts::TAU).into();
        let what = format!("seed {seed:#x}: contacts {} initial qd {:?} target {} (draw {draw})", s["contacts"], qd, s["target"]["circle"]);
        match sim::scene::Scene::from_json(&s.to_string(), "random.json", |f| std::fs::read_to_string(dir.join(f)).map_err(|e| e.to_string())) {
            Ok(scene) => return (scene, what),
            Err(e) if e.to_string().contains("outside its reach") && draw < 100 => continue,
            Err(e) => panic!("{what}: the generator made a scene the simulator rejects: {e}"),
        }
    }
    unreachable!("the loop returns or panics")
}

/// One random case: every sample the run wrote holds the contact audit and closes the balance
/// to 1e-8 of E (the scene's rtol 1e-8, as the paper runs: measured ≤ 1e-9). A run may stop
/// early only with a typed error that names the contact and the law (Painlevé's inconsistency
/// of the rigid problem, or modes that chatter: issue 23 items 2 and 6, not this part), and
/// the samples before the stop must hold too. Returns the error's message when it stopped.
#[allow(clippy::result_large_err)] // RunError carries schemas::Error, as in `sim::run::simulate`
pub(crate) fn check_random(seed: u64) -> Option<String> {
    use sim::error::{DynamicsError, RunError};
    let (scene, what) = random_scene(seed);
    let run = scene.run("two-elbow-unilateral").unwrap().clone();
    let (mut samples, mut events) = (Vec::new(), Vec::new());
    let result = sim::run::simulate(&scene, &run, |o| {
        events.extend_from_slice(&o.events);
        samples.push(o.clone());
        Ok(())
    });
    let stopped = match result {
        Ok(_) => None,
        Err(e @ RunError::Dynamics(DynamicsError::InconsistentContact { .. })) => Some(e.to_string()),
        Err(e @ RunError::Chattering { .. }) => Some(e.to_string()),
        Err(e) => panic!("{what}: the run failed: {e}\nreproduce: ELBOW_CONTACT_SEED={seed:#x}"),
    };
    assert!(!samples.is_empty(), "{what}: no sample");
    let c = Collected { report: sim::run::RunReport { stats: Default::default(), samples: samples.len(), last: samples.last().unwrap().clone(), limits: None }, samples, events };
    let a = audit(&scene, "two-elbow-unilateral", &c);
    assert!(a.verdict().is_none(), "{what}: {}\nreproduce: ELBOW_CONTACT_SEED={seed:#x}", a.verdict().unwrap_or_default());
    let (rel, _) = balance(&c);
    assert!(rel <= 1e-8, "{what}: balance residual {rel:.2e} of E\nreproduce: ELBOW_CONTACT_SEED={seed:#x}");
    if let Some(why) = &stopped {
        eprintln!("seed {seed:#x} stopped at t = {} s (the audit held before): {why}", c.samples.last().unwrap().t);
    }
    stopped
}

/// 16 random unilateral scenes (`random_scene`), their seeds drawn from a fixed SplitMix64
/// stream (so CI runs the same 16 every time; a failure names its seed, which
/// `ELBOW_CONTACT_SEED` reruns alone), hold the contact audit at every sample and close the
/// balance.
#[test]
fn random_unilateral_scenes_hold_the_audit_and_close_the_balance() {
    let mut seeds = SplitMix(0x2023_1129);
    let mut stopped = 0;
    for _ in 0..16 {
        stopped += usize::from(check_random(seeds.next()).is_some());
    }
    eprintln!("16 random unilateral scenes: {} complete, {stopped} stopped with a typed error (the audit held before)", 16 - stopped);
}

/// The long sweep (issue 23 item 6), run by hand: `ELBOW_CONTACT_SWEEP=N` random scenes
/// (`random_scene`) whose seeds come from a SplitMix64 stream started at
/// `ELBOW_CONTACT_SWEEP_START` (hex; default the clock's nanoseconds, printed), each checked as
/// the 16 fixed ones; every failure is listed with its seed (`ELBOW_CONTACT_SEED` reruns it),
/// then the test fails if any did. `cargo test … contacts_exact::random_unilateral_sweep --
/// --ignored --nocapture`.
#[test]
#[ignore]
fn random_unilateral_sweep() {
    let n: usize = std::env::var("ELBOW_CONTACT_SWEEP").ok().and_then(|s| s.parse().ok()).unwrap_or(200);
    let start = std::env::var("ELBOW_CONTACT_SWEEP_START")
        .ok()
        .and_then(|s| u64::from_str_radix(s.trim_start_matches("0x"), 16).ok())
        .unwrap_or_else(|| std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(1, |d| d.as_nanos() as u64));
    eprintln!("sweep of {n} random unilateral scenes, ELBOW_CONTACT_SWEEP_START={start:#x}");
    let mut seeds = SplitMix(start);
    let (mut failed, mut stopped) = (Vec::new(), Vec::new());
    for _ in 0..n {
        let seed = seeds.next();
        match std::panic::catch_unwind(|| check_random(seed)) {
            Ok(None) => {}
            Ok(Some(why)) => stopped.push(format!("{seed:#x}: {why}")),
            Err(e) => failed.push(format!("{seed:#x}: {}", e.downcast_ref::<String>().cloned().unwrap_or_default())),
        }
    }
    eprintln!("{n} scenes: {} complete, {} stopped with a typed error, {} failed", n - stopped.len() - failed.len(), stopped.len(), failed.len());
    for s in &stopped {
        eprintln!("stopped {s}");
    }
    for f in &failed {
        eprintln!("FAILED {f}");
    }
    assert!(failed.is_empty(), "{} of {n} random scenes failed", failed.len());
}

/// The generator draws a circle the arm reaches for every seed: 0x73e2d0c93e07247b's first
/// draw is out of reach (the scene says "outside its reach"; the generator panicked on it), so
/// it is drawn again and the scene of the second draw, which the simulator accepts, is returned.
#[test]
fn the_random_scene_generator_redraws_a_circle_out_of_reach() {
    let (scene, what) = random_scene(0x73e2_d0c9_3e07_247b);
    assert!(what.ends_with("(draw 1)"), "{what}");
    assert!(scene.run("two-elbow-unilateral").is_some(), "{what}");
}

/// Seed 0xe08f20ace809c12a (elbow4 μ = 1.34, elbow7 μ = 1.44): at 0.049179627 s both sticks
/// reach their cones at once (statically indeterminate together: each one's Delassus block with
/// the other sticking is singular, det ≈ 1e-15), and the slides from rest of both along their
/// impending directions are consistent (f_n 3.2059 and 2.2064 N, p(s) 4.08 and 3.98 m/(s² N) > 0,
/// a_t ∥ s to 1e-14 m/s²). The fixed-point iteration `s ← a_t/|a_t|` read the direction from
/// |a_t| ≈ 1e-12 m/s² of rounding and the run stopped there with "no consistent contact forces";
/// with the two-angle Newton iteration (`pair_slip.rs`) it completes its 0.15 s with the audit
/// and the energy balance (≤ 1e-8 of E) at every sample (`check_random`).
#[test]
fn a_common_onset_of_two_contacts_slides_both_from_rest() {
    assert_eq!(check_random(0xe08f_20ac_e809_c12a), None);
}

/// The case of `ELBOW_CONTACT_SEED` (a failing property case's seed), when set.
#[test]
fn random_unilateral_scene_of_a_given_seed() {
    if let Ok(s) = std::env::var("ELBOW_CONTACT_SEED") {
        let seed = u64::from_str_radix(s.trim_start_matches("0x"), 16).unwrap_or_else(|_| panic!("ELBOW_CONTACT_SEED={s}: a hex seed"));
        check_random(seed);
    }
}

// ----- item 2: slip → stick located as an event -----

/// A block (M = 1 kg) sliding on the table with v₀ = 2 m/s along `dir`, μ = 0.4, no other
/// tangential force: it decelerates at μ g along its motion and stops at `t_s = v₀/(μ g)`
/// (0.5097 s), where the slip → stick event is located as the zero of the slip (not at a stick
/// speed: with the old rule, 1e-6 m/s, the event came 2.5e-7 s early). Tolerances: the event time
/// to 1e-10 s (the issue's; the bracket is 1e-12 s and the motion is quadratic in t, which
/// dopri45 reproduces to rounding), the slip at every sample before it `v₀ − μ g t` along `dir` to
/// 1e-9 m/s, and at rest after it with f_t = 0. 1-D: along x; 2-D: at 30° (the slip has two
/// components, its direction constant).
#[test]
fn a_sliding_block_stops_exactly_at_v0_over_mu_g_in_1d_and_2d() {
    let (v0, mu) = (2.0, 0.4);
    let t_s = v0 / (mu * G);
    for deg in [0.0f64, 30.0] {
        let (cx, cy) = (deg.to_radians().cos(), deg.to_radians().sin());
        let s = ball([0.0; 3], [v0 * cx, v0 * cy, 0.0], [0.0, 0.0, -G], 0.8, json!({"model": "unilateral", "friction": mu}));
        let c = collect(&load(&s, &point_urdf(M)), "r");
        assert_eq!(c.events.len(), 1, "{deg}°: one event: {:?}", c.events);
        let e = &c.events[0];
        assert_eq!(e.kind, ContactEventKind::SlipToStick, "{deg}°: {e:?}");
        assert!((e.t - t_s).abs() <= 1e-10, "{deg}°: stops at {} s, v₀/(μ g) = {t_s} s (diff {:e} s)", e.t, e.t - t_s);
        for o in c.between(0.0, t_s) {
            let v = v0 - mu * G * o.t;
            let sl = o.contacts[0].slip_velocity;
            assert!((sl[0] - v * cx).abs() <= 1e-9 && (sl[1] - v * cy).abs() <= 1e-9, "{deg}°, t = {}: slip {sl:?}, want {v} m/s along {deg}°", o.t);
            assert_eq!(o.contacts[0].mode, ContactMode::Sliding, "{deg}°, t = {}", o.t);
        }
        for o in c.between(t_s, 1.0) {
            let f = &o.contacts[0];
            assert_eq!(f.mode, ContactMode::Sticking, "{deg}°, t = {}", o.t);
            assert!(f.slip_velocity.iter().chain(&f.friction_force).all(|x| x.abs() <= 1e-9), "{deg}°, t = {}: {f:?}", o.t);
        }
    }
}

/// A block sliding across a steady tangential push (gravity tilted: g_t = 1.962 m/s² along +x,
/// below μ g = 3.924 m/s², so k = μ g / g_t = 2), started with v₀ = 1 m/s at θ₀ = 120° from the
/// push. Coulomb's law `v̇ = g_t − μ g v/|v|` turns the slip towards the push while it slows
/// (θ the angle from the push): `d|v|/dt = g_t cos θ − μ g`, `dθ/dt = −g_t sin θ / |v|`, so
/// `|v| = C tan(θ/2)^k / sin θ`, and with `u = tan(θ/2)` the time to stop is the closed form
/// `t_s = (C/g_t) · ½ [u₀^(k−1)/(k−1) + u₀^(k+1)/(k+1)]`, `C = v₀ sin θ₀ / u₀^k` (0.6797 s): the
/// slip velocity's magnitude reaches zero there (a 2-D stop with a turning direction, the case
/// the located event has to get right). The direction at each sample is checked against the same
/// closed form (|v| from θ). Tolerances: event time 1e-10 s; |v| at the samples 1e-8 m/s
/// (dopri45 at rtol 1e-12 on a slip whose direction's rate grows as 1/|v|).
#[test]
fn a_block_pushed_across_its_slip_stops_at_the_closed_form_time_in_2d() {
    let (v0, mu, gt) = (1.0, 0.4, 0.2 * G);
    let k = mu * G / gt;
    let th0 = 120f64.to_radians();
    let u0 = (th0 / 2.0).tan();
    let cc = v0 * th0.sin() / u0.powf(k);
    let t_s = cc / gt * 0.5 * (u0.powf(k - 1.0) / (k - 1.0) + u0.powf(k + 1.0) / (k + 1.0));
    let s = ball([0.0; 3], [v0 * th0.cos(), v0 * th0.sin(), 0.0], [gt, 0.0, -G], 1.0, json!({"model": "unilateral", "friction": mu}));
    let c = collect(&load(&s, &point_urdf(M)), "r");
    assert_eq!(c.events.len(), 1, "one event: {:?}", c.events);
    let e = &c.events[0];
    assert_eq!(e.kind, ContactEventKind::SlipToStick, "{e:?}");
    assert!((e.t - t_s).abs() <= 1e-10, "stops at {} s, closed form {t_s} s (diff {:e} s)", e.t, e.t - t_s);
    // |v| against the closed form |v|(θ) at the sample's own θ, and t(θ) against the sample's t
    for o in c.between(0.0, t_s - 1e-3) {
        let sl = o.contacts[0].slip_velocity;
        let th = sl[1].atan2(sl[0]);
        let u = (th / 2.0).tan();
        let speed = cc * u.powf(k) / th.sin();
        assert!((sl[0].hypot(sl[1]) - speed).abs() <= 1e-8, "t = {}: |v| = {}, closed form {speed} m/s at θ = {th}", o.t, sl[0].hypot(sl[1]));
        let t_left = cc / gt * 0.5 * (u.powf(k - 1.0) / (k - 1.0) + u.powf(k + 1.0) / (k + 1.0));
        assert!((t_s - t_left - o.t).abs() <= 1e-8, "t = {}: closed-form time at θ = {th}: {}", o.t, t_s - t_left);
    }
    for o in c.between(t_s, 1.0) {
        let f = &o.contacts[0];
        assert_eq!(f.mode, ContactMode::Sticking, "t = {}", o.t);
        assert!(f.slip_velocity.iter().all(|x| x.abs() <= 1e-9), "t = {}: {f:?}", o.t);
        assert!((f.friction_force[0] + M * gt).abs() <= 1e-9 && f.friction_force[1].abs() <= 1e-9, "t = {}: f_t {:?}, want (−m g_t, 0)", o.t, f.friction_force);
    }
}

/// A block (m = 1 kg) on the table at the end of an arm of radius r = 0.5 m that turns about the
/// world z axis (a vertical prismatic joint carries the arm so the block rests on the table; the
/// arm's own inertia about the axis is I₀ = 0.05 kg m²), spun at ω₀ = 20 rad/s: the block slides
/// with `r ω` along a direction that turns with the arm (at ω, eight full turns before it stops),
/// friction `μ m g` opposite (μ = 0.5) brakes it with the torque `μ m g r`, so
/// `ω(t) = ω₀ − μ m g r t / I`, `I = I₀ + m r²`, and the slip stops at `t_s = I ω₀ / (μ m g r)`
/// (2.4465 s; eight turns of the arm). The event function `v_t · s_ref` of a slip that turns by more than 90° within a
/// step has a zero that is no stop (|v_t| = r ω there); the rule takes only the zero with |v_t| ≤
/// `vel_tol` as the stop. Tolerances: event time 1e-10 s, ω at the samples 1e-9 rad/s (linear in
/// t), normal force m g to 1e-9 N.
#[test]
fn a_block_dragged_round_by_an_arm_stops_at_the_closed_form_time_while_its_slip_direction_turns() {
    let (m, r, i0, w0, mu) = (1.0, 0.5, 0.05, 20.0, 0.5);
    let lim = r#"<limit lower="-1000" upper="1000" effort="1e6" velocity="1e3"/>"#;
    let urdf = format!(
        r#"<?xml version="1.0"?>
<robot name="turntable">
  <link name="base"/>
  <joint name="z" type="prismatic"><parent link="base"/><child link="cz"/><origin xyz="0 0 0"/><axis xyz="0 0 1"/>{lim}</joint>
  <link name="cz"/>
  <joint name="spin" type="continuous"><parent link="cz"/><child link="arm"/><origin xyz="0 0 0"/><axis xyz="0 0 1"/></joint>
  <link name="arm"><inertial><origin xyz="{r} 0 0"/><mass value="{m}"/><inertia ixx="0.03" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="{i0}"/></inertial></link>
</robot>"#
    );
    let mut s = passive_scene("arm", &["z", "spin"], &[0.0, 0.0], &[0.0, w0], [0.0, 0.0, -G], 2.7, 1e-12);
    add_table_contact(&mut s, "block", json!({"link": "arm", "offset": [r, 0.0, 0.0]}), json!({"model": "unilateral", "friction": mu}));
    let c = collect(&load(&s, &urdf), "r");
    let inertia = i0 + m * r * r;
    let t_s = inertia * w0 / (mu * m * G * r);
    assert_eq!(c.events.len(), 1, "one event: {:?}", c.events);
    let e = &c.events[0];
    assert_eq!(e.kind, ContactEventKind::SlipToStick, "{e:?}");
    assert!((e.t - t_s).abs() <= 1e-10, "stops at {} s, I ω₀/(μ m g r) = {t_s} s (diff {:e} s)", e.t, e.t - t_s);
    for o in c.between(0.0, t_s) {
        let w = w0 - mu * m * G * r * o.t / inertia;
        assert!((o.qd[1] - w).abs() <= 1e-9, "t = {}: ω = {}, closed form {w}", o.t, o.qd[1]);
        assert!((o.contacts[0].normal_force - m * G).abs() <= 1e-9, "t = {}: f_n = {}", o.t, o.contacts[0].normal_force);
        assert_eq!(o.contacts[0].mode, ContactMode::Sliding, "t = {}", o.t);
    }
    for o in c.between(t_s, 3.0) {
        assert_eq!(o.contacts[0].mode, ContactMode::Sticking, "t = {}", o.t);
        assert!(o.qd[1].abs() <= 1e-9, "t = {}: ω = {}", o.t, o.qd[1]);
    }
}
