//! Painlevé's paradox (Painlevé 1895; Pfeiffer & Glocker 1996, §7.3; Acary & Brogliato 2008,
//! §3.2 and the rod example): a uniform rod (mass m, length 2l, inertia m l²/3 about its centre)
//! whose lower end A touches the table and slides with the end leading.
//!
//! Coordinates: the centre (x, z) and θ, the rod's angle above the horizontal (the URDF's
//! revolute angle about y is φ = −θ); A = (x − l cos θ, z − l sin θ). With the normal force N
//! and the friction F at A, Newton–Euler:
//! `m ẍ = F`, `m z̈ = N − m g`, `(m l²/3) θ̈ = F l sin θ − N l cos θ`, and
//! `g̈ = z̈ − l cos θ θ̈ + l sin θ θ̇² = −g + l sin θ θ̇² + (N/m)(1 + 3 cos² θ) − (3 F/m) sin θ cos θ`.
//! Sliding towards −x (v_A < 0, the end leading), F = +μ N:
//! `g̈ = a0 + (N/m) B`, `a0 = −g + l sin θ θ̇²`, `B = 1 + 3 cos² θ − 3 μ sin θ cos θ`.
//! For `μ > μ_c(θ) = (tan² θ + 4) / (3 tan θ)` B < 0, and with a0 < 0 (θ̇ = 0) neither N = 0
//! (g̈ = a0 < 0) nor N > 0 with g̈ = 0 (N = −m a0 / B < 0) is consistent: no solution. μ_c is
//! smallest, 4/3, at tan θ = 2.
//!
//! Tested at tan θ = 2, θ̇ = 0, ẋ = −1 m/s: μ = 1.5 > 4/3 is reported as an inconsistency at
//! t = 0 naming the contact, with B/m = G_nn − μ G_nt·s = −0.2 and the critical friction 4/3
//! in the message; μ = 1.2 < 4/3 runs, with the closed-form normal force
//! `N = m g / B` (B = 0.16: six times the weight) and friction +μ N along x at t = 0 (1e-9
//! relative: one small LU solve, condition ~ 1/B).

#![allow(clippy::needless_range_loop)] // per-contact arrays indexed together


use crate::contacts_support::*;
use serde_json::json;
use sim::dynamics::contact::{ContactEventKind, ContactMode};
use sim::error::{DynamicsError, RunError};

const M: f64 = 1.0;
const L: f64 = 0.5;

fn rod_scene(mu: f64) -> (sim::scene::Scene, f64) {
    rod_scene_with(json!({"model": "unilateral", "friction": mu}))
}

fn rod_scene_with(contact: serde_json::Value) -> (sim::scene::Scene, f64) {
    let theta = 2f64.atan();
    let q0 = [0.0, L * theta.sin(), -theta];
    let mut s = passive_scene("rod", &["x", "z", "pitch"], &q0, &[-1.0, 0.0, 0.0], [0.0, 0.0, -G], 0.05, 1e-10);
    add_table_contact(&mut s, "tip", json!({"link": "rod", "offset": [-L, 0.0, 0.0]}), contact);
    (load(&s, &rod_urdf(M, L)), theta)
}

#[test]
fn the_critical_friction_of_the_rod_is_four_thirds_at_tan_theta_two() {
    // the closed form the two runs below rest on: μ_c(θ) = (tan²θ + 4)/(3 tan θ), min 4/3 at tan θ = 2
    let mu_c = |t: f64| (t * t + 4.0) / (3.0 * t);
    assert!((mu_c(2.0) - 4.0 / 3.0).abs() < 1e-15);
    assert!(mu_c(1.9) > 4.0 / 3.0 && mu_c(2.1) > 4.0 / 3.0);
    let b = |mu: f64, th: f64| 1.0 + 3.0 * th.cos().powi(2) - 3.0 * mu * th.sin() * th.cos();
    let th = 2f64.atan();
    assert!(b(1.5, th) < 0.0 && b(1.2, th) > 0.0 && b(4.0 / 3.0, th).abs() < 1e-15);
}

#[test]
fn a_rod_above_the_critical_friction_is_reported_as_inconsistent() {
    let (scene, _) = rod_scene(1.5);
    match try_collect(&scene, "r") {
        Err(RunError::Dynamics(DynamicsError::InconsistentContact { t, contact, why })) => {
            assert_eq!(contact, "tip");
            assert!(t.abs() <= 1e-12, "at t = {t} s, the start");
            assert!(why.to_lowercase().contains("painlev") || why.contains("no consistent"), "{why}");
            // the diagnosis (`modes::one_contact`): the effective Delassus terms of the tip at
            // t = 0 against the closed form, G_nn = (1 + 3 cos²θ)/m = 1.6 and
            // G_nt·s = 3 sinθ cosθ / m = 1.2 for s = (−1, 0) (the slip direction), so
            // G_nn − μ G_nt·s = B/m = −0.2 m/(s² N) and the critical friction G_nn/(G_nt·s) =
            // 4/3; separated, the tip falls at g (the message's 7 digits: a 3 × 3 solve)
            for part in ["G_nn - mu G_nt.s = -2.000000e-1", "G_nn = 1.600000e0", "G_nt.s = 1.200000e0", "a_n = -9.810000e0", "friction below G_nn/(G_nt.s) = 1.3333 makes the slide consistent"] {
                assert!(why.contains(part), "the message lacks {part:?}: {why}");
            }
        }
        Err(e) => panic!("expected InconsistentContact, got: {e}"),
        Ok(c) => panic!("a Painlevé-inconsistent rod was integrated silently ({} samples)", c.samples.len()),
    }
}

#[test]
fn a_rod_below_the_critical_friction_slides_with_the_closed_form_forces() {
    let (scene, theta) = rod_scene(1.2);
    let c = collect(&scene, "r");
    let mu = 1.2;
    let b = 1.0 + 3.0 * theta.cos().powi(2) - 3.0 * mu * theta.sin() * theta.cos();
    let n = M * G / b;
    let f = &c.samples[0].contacts[0];
    assert_eq!(f.mode, ContactMode::Sliding);
    assert!((f.normal_force - n).abs() <= 1e-9 * n, "N = {} N, m g / B = {n} N", f.normal_force);
    assert!((f.friction_force[0] - mu * n).abs() <= 1e-9 * n, "F = {:?} N, μ N = {}", f.friction_force, mu * n);
    assert!(f.friction_force[1].abs() <= 1e-9 * n);
    // ẍ = F/m at the start (the rod is decelerated by μ N = 7.4 g)
    assert!((c.samples[0].qdd[0] - mu * n / M).abs() <= 1e-9 * n, "ẍ = {}", c.samples[0].qdd[0]);
    assert_eq!(c.samples.len(), 51);
}

/// The rod's geometry on today's path: held bilaterally (frictionless) the tip's force at the
/// start is `N = m g / (1 + 3 cos² θ)` (B with μ = 0), 1e-9 relative.
#[test]
fn the_held_frictionless_rod_has_the_closed_form_normal_force() {
    let (scene, theta) = rod_scene_with(json!({}));
    let c = collect(&scene, "r");
    let n = M * G / (1.0 + 3.0 * theta.cos().powi(2));
    assert!((c.samples[0].normal_force[0] - n).abs() <= 1e-9 * n, "N = {}, m g / (1 + 3 cos² θ) = {n}", c.samples[0].normal_force[0]);
}

/// Two simultaneous impacts (the velocity-level complementarity over the closed contacts): the
/// rod (half-length l = 0.5 m, m = 1 kg, its centre of mass moved d = 0.1 m towards end 2)
/// falls flat from h0 = 0.2 m, frictionless, and hits the table with both ends at once at
/// `t = sqrt(2 h0 / g)`, speed v = sqrt(2 g h0). With both impulses positive (Newton's law at
/// both: ġ⁺ = −e ġ⁻), the rod's vertical speed becomes e v and its rotation stays 0, so by linear
/// and angular momentum (about the centre of mass) `Λ1 + Λ2 = m (1 + e) v`,
/// `Λ1 (l + d) = Λ2 (l − d)`: `Λ1 = m (1 + e) v (l − d)/(2l)`, `Λ2 = m (1 + e) v (l + d)/(2l)`
/// (independent of the inertia); each contact's loss `Λ_k (1 − e) v / 2`. e = 0: the rod stays
/// down and rests on both ends with the statics `f_1 = m g (l − d)/(2l)`, `f_2 = m g (l + d)/(2l)`.
/// e = 0.5: both ends leave at e v. Tolerances 1e-9 relative (free fall is exact in dopri45; the
/// event bracket 1e-12 s moves v by 1e-11 m/s).
#[test]
fn simultaneous_impacts_of_a_rod_falling_flat_split_the_impulse_by_the_centre_of_mass() {
    let (h0, d) = (0.2, 0.1);
    let urdf = rod_urdf(M, L).replace(r#"<inertial><origin xyz="0 0 0"/>"#, &format!(r#"<inertial><origin xyz="{d} 0 0"/>"#));
    assert!(urdf.contains(&format!(r#"<origin xyz="{d} 0 0"/><mass"#)));
    let v = (2.0 * G * h0).sqrt();
    let t_hit = (2.0 * h0 / G).sqrt();
    for e in [0.0, 0.5] {
        let mut s = passive_scene("rod", &["x", "z", "pitch"], &[0.0, h0, 0.0], &[0.0; 3], [0.0, 0.0, -G], 0.3, 1e-12);
        add_table_contact(&mut s, "end1", json!({"link": "rod", "offset": [-L, 0.0, 0.0]}), json!({"model": "unilateral", "restitution": e}));
        add_table_contact(&mut s, "end2", json!({"link": "rod", "offset": [L, 0.0, 0.0]}), json!({"model": "unilateral", "restitution": e}));
        let c = collect(&load(&s, &urdf), "r");
        let first: Vec<_> = c.events.iter().filter(|ev| (ev.t - t_hit).abs() <= 1e-9 * t_hit).collect();
        assert_eq!(first.len(), 2, "e = {e}: one impact per end at {t_hit} s: {:?}", c.events);
        let share = [(L - d) / (2.0 * L), (L + d) / (2.0 * L)];
        for ev in first {
            let k = ev.contact;
            let lam = M * (1.0 + e) * v * share[k];
            assert!((ev.impulse - lam).abs() <= 1e-9 * lam, "e = {e}, end {}: Λ = {} N s, closed form {lam}", k + 1, ev.impulse);
            let lost = lam * (1.0 - e) * v / 2.0;
            assert!((ev.energy_lost - lost).abs() <= 1e-9 * M * v * v, "e = {e}, end {}: lost {} J, closed form {lost}", k + 1, ev.energy_lost);
            assert!((ev.gap_rate_after - e * v).abs() <= 1e-9 * v, "e = {e}, end {}: ġ⁺ = {}", k + 1, ev.gap_rate_after);
        }
        if e == 0.0 {
            assert_eq!(c.events.len(), 2, "then at rest: {:?}", c.events);
            for o in c.between(t_hit + 1e-3, 1.0) {
                for k in 0..2 {
                    let want = M * G * share[k];
                    assert!(touching(o.contacts[k].mode), "t = {}, end {}: {:?}", o.t, k + 1, o.contacts[k].mode);
                    assert!((o.contacts[k].normal_force - want).abs() <= 1e-9 * want, "t = {}, end {}: f_n {} vs statics {want}", o.t, k + 1, o.contacts[k].normal_force);
                }
                assert!(o.qd.iter().all(|x| x.abs() <= 1e-9), "t = {}: at rest {:?}", o.t, o.qd);
            }
        } else {
            // both ends leave together and the rod stays level
            for o in c.between(t_hit + 1e-3, t_hit + 2.0 * e * v / G - 1e-3) {
                assert!(o.contacts.iter().all(|f| f.mode == ContactMode::Separated), "t = {}", o.t);
                assert!(o.q[2].abs() <= 1e-9 && o.qd[2].abs() <= 1e-9, "t = {}: the rod tilts: {:?}", o.t, o.q);
            }
        }
    }
}

/// Review F3: a contact in touch that another contact's impact throws off logs a lift-off.
/// The rod (m, half-length l, I = m l²/3 about its centre) rests frictionless on a contact A
/// at its centre and turns freely at φ̇ = ω (gravity and N = m g both act at the centre: no
/// torque, so φ is linear and the centre stays on the table). Its end B (offset +l, height
/// −l sin φ) reaches the table at φ = 0, t* = −φ0/ω, with ġ_B⁻ = −l ω = −v. Newton's law over
/// {A, B} (W M⁻¹ Wᵀ = [[1, 1], [1, 4]]/m): Λ_A = 0, Λ_B = m (1+e) v / 4, so A leaves with
/// ġ_A⁺ = (1+e) v / 4 and B with e v. Expected at t*: one impact (B) and one lift-off (A).
/// Tolerances: t* to 1e-9 s (event bracket 1e-12 s), rates 1e-9 relative.
#[test]
fn a_contact_thrown_off_by_another_contacts_impact_logs_a_lift_off() {
    let (phi0, omega, e) = (-0.1, 1.0, 0.5);
    let mut s = passive_scene("rod", &["x", "z", "pitch"], &[0.0, 0.0, phi0], &[0.0, 0.0, omega], [0.0, 0.0, -G], 0.12, 1e-12);
    add_table_contact(&mut s, "centre", json!({"link": "rod", "offset": [0.0, 0.0, 0.0]}), json!({"model": "unilateral"}));
    add_table_contact(&mut s, "end", json!({"link": "rod", "offset": [L, 0.0, 0.0]}), json!({"model": "unilateral", "restitution": e}));
    let c = collect(&load(&s, &rod_urdf(M, L)), "r");
    let t_star = -phi0 / omega;
    let v = L * omega;
    let at: Vec<_> = c.events.iter().filter(|ev| (ev.t - t_star).abs() <= 1e-9).collect();
    let impacts: Vec<_> = at.iter().filter(|ev| ev.kind == ContactEventKind::Impact).collect();
    let lifts: Vec<_> = at.iter().filter(|ev| ev.kind == ContactEventKind::LiftOff).collect();
    assert_eq!(impacts.len(), 1, "one impact at {t_star} s: {:?}", c.events);
    assert_eq!(impacts[0].contact, 1, "the end hits: {:?}", impacts[0]);
    let lam = M * (1.0 + e) * v / 4.0;
    assert!((impacts[0].impulse - lam).abs() <= 1e-9 * lam, "Λ_B = {} N s, closed form {lam}", impacts[0].impulse);
    assert_eq!(lifts.len(), 1, "one lift-off of the centre at {t_star} s: {:?}", c.events);
    assert_eq!(lifts[0].contact, 0, "the centre leaves: {:?}", lifts[0]);
    let rate = (1.0 + e) * v / 4.0;
    assert!((lifts[0].gap_rate_after - rate).abs() <= 1e-9 * rate, "ġ_A⁺ = {} m/s, closed form {rate}", lifts[0].gap_rate_after);
    assert_eq!(c.events.len(), 2, "nothing else before the centre lands again: {:?}", c.events);
    for o in c.between(t_star + 1e-3, 0.12) {
        assert_eq!(o.contacts[0].mode, ContactMode::Separated, "t = {}: the centre is in the air", o.t);
    }
}
