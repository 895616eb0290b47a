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
//! t = 0 naming the contact; μ = 1.2 < 4/3 runs, with the closed-form normal force
//! `N = m g / B` (B = 0.16: six times the weight) and friction +μ N along x at t = 0 (1e-9
//! relative: one small LU solve, condition ~ 1/B).

mod contacts_support;

use contacts_support::*;
use serde_json::json;
use sim::dynamics::contact::ContactMode;
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
