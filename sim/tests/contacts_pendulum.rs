//! A planar double pendulum whose elbow rests on the table under a unilateral contact, against
//! an INDEPENDENT reduced model written here by hand (Lagrange's equations in absolute link
//! angles, integrated with classical RK4 at a small step; no code of the simulator), and the
//! same arm with a bilateral elbow while the force stays positive.
//!
//! The arm (`contacts_support::DoublePendulum`): shoulder at height h = 0.3 m, link1 (uniform
//! rod m1 = 1 kg, l1 = 0.5 m) down to the elbow on the table z = 0 (α1 = −asin(h/l1)), link2
//! (m2 = 0.5 kg, l2 = 0.4 m) free about the elbow; both joints passive, no damping. Absolute
//! angles α from world +x towards +z (the URDF's angles about +y are minus these:
//! q1 = −α1, q2 = α1 − α2). With u(α) = (cos α, sin α), k = m2 l1 l2/2, c = cos(α1 − α2),
//! s = sin(α1 − α2), `M11 = m1 l1²/3 + m2 l1²`, `M22 = m2 l2²/3`, `W1 = (m1/2 + m2) l1 g`:
//!
//! `M11 α̈1 + k c α̈2 + k s α̇2² + W1 cos α1 = N l1 cos α1`
//! `k c α̈1 + M22 α̈2 − k s α̇1² + m2 g (l2/2) cos α2 = 0`
//!
//! (the elbow height is `h + l1 sin α1`, so the table's upward force N does the generalised work
//! `N l1 cos α1` on α1). In contact α1 is fixed: link2 is a pendulum about the elbow and the
//! first equation gives N; after lift-off (N = 0) both equations with N = 0.


use crate::contacts_support::*;
use serde_json::json;
use sim::dynamics::contact::{ContactEventKind, ContactMode};

const ARM: DoublePendulum = DoublePendulum { h: 0.3, l1: 0.5, m1: 1.0, l2: 0.4, m2: 0.5 };

/// The reduced model's state: (α1, α2, α̇1, α̇2).
type S = [f64; 4];

struct Reference {
    a: DoublePendulum,
}

impl Reference {
    fn k(&self) -> f64 {
        self.a.m2 * self.a.l1 * self.a.l2 / 2.0
    }
    fn m22(&self) -> f64 {
        self.a.m2 * self.a.l2 * self.a.l2 / 3.0
    }
    fn w1(&self) -> f64 {
        (self.a.m1 / 2.0 + self.a.m2) * self.a.l1 * G
    }
    /// In contact: α̈2 of the pendulum about the fixed elbow.
    fn contact_acc(&self, x: &S) -> f64 {
        -self.a.m2 * G * self.a.l2 / 2.0 * x[1].cos() / self.m22()
    }
    /// In contact: the table's normal force N, N.
    fn normal_force(&self, x: &S) -> f64 {
        let (c, s) = ((x[0] - x[1]).cos(), (x[0] - x[1]).sin());
        (self.k() * c * self.contact_acc(x) + self.k() * s * x[3] * x[3] + self.w1() * x[0].cos()) / (self.a.l1 * x[0].cos())
    }
    fn rhs(&self, free: bool, x: &S) -> S {
        if !free {
            return [0.0, x[3], 0.0, self.contact_acc(x)];
        }
        let a = &self.a;
        let (c, s) = ((x[0] - x[1]).cos(), (x[0] - x[1]).sin());
        let m11 = a.m1 * a.l1 * a.l1 / 3.0 + a.m2 * a.l1 * a.l1;
        let (m12, m22) = (self.k() * c, self.m22());
        let r1 = -self.k() * s * x[3] * x[3] - self.w1() * x[0].cos();
        let r2 = self.k() * s * x[2] * x[2] - a.m2 * G * a.l2 / 2.0 * x[1].cos();
        let det = m11 * m22 - m12 * m12;
        [x[2], x[3], (m22 * r1 - m12 * r2) / det, (m11 * r2 - m12 * r1) / det]
    }
    fn rk4(&self, free: bool, x: &S, h: f64) -> S {
        let add = |x: &S, k: &S, f: f64| -> S { [x[0] + f * k[0], x[1] + f * k[1], x[2] + f * k[2], x[3] + f * k[3]] };
        let k1 = self.rhs(free, x);
        let k2 = self.rhs(free, &add(x, &k1, h / 2.0));
        let k3 = self.rhs(free, &add(x, &k2, h / 2.0));
        let k4 = self.rhs(free, &add(x, &k3, h));
        let mut y = *x;
        for i in 0..4 {
            y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        y
    }
    fn elbow_height(&self, x: &S) -> f64 {
        self.a.h + self.a.l1 * x[0].sin()
    }
    /// Integrate from (t, x) in steps ≤ `h` until `t_end` or until `stop(x)` turns negative,
    /// whose root is then found by bisection on the length of a single RK4 step from the last
    /// accepted state (local error O(τ⁵)). Returns (t, x, stopped).
    fn run(&self, free: bool, mut t: f64, mut x: S, t_end: f64, h: f64, stop: impl Fn(&S) -> f64) -> (f64, S, bool) {
        while t < t_end {
            let step = h.min(t_end - t);
            let y = self.rk4(free, &x, step);
            if stop(&y) < 0.0 {
                let tau = bisect(0.0, step, |tau| stop(&self.rk4(free, &x, tau)));
                return (t + tau, self.rk4(free, &x, tau), true);
            }
            x = y;
            t += step;
        }
        (t, x, false)
    }
}

/// The URDF's (q1, q2, q̇1, q̇2) of a reduced state.
fn joint_state(x: &S) -> [f64; 4] {
    [-x[0], x[0] - x[1], -x[2], x[2] - x[3]]
}

fn scene(alpha2: f64, omega2: f64, contact: serde_json::Value, duration: f64) -> (sim::scene::Scene, S) {
    let a1 = -(ARM.h / ARM.l1).asin();
    let x0 = [a1, alpha2, 0.0, omega2];
    let j = joint_state(&x0);
    let mut s = passive_scene("link2", &["joint1", "joint2"], &j[..2], &j[2..], [0.0, 0.0, -G], duration, 1e-11);
    add_table_contact(&mut s, "elbow", json!({"joint": "joint2"}), contact);
    (load(&s, &ARM.urdf()), x0)
}

/// Link2 starts nearly upright (α2 = 1.5 rad) falling forwards at 6 rad/s; as it swings down
/// and round, its pull at the elbow lifts the elbow: N crosses zero (transversally) at
/// t_lo ≈ 0.140 s (Ṅ ≈ −71 N/s there). The elbow then flies up and comes back down (a plastic impact, e = 0).
///
/// Compared: the lift-off time ≤ 1e-8 s (the reference's RK4 at 1e-5 s has local errors
/// ~1e-20 and its bisected root is exact to round-off, ~1e-14 s; the simulator's is located to
/// 1e-12 s on a dense output whose state error at rtol 1e-11 moves the zero of N by
/// δN / |Ṅ| ~ 1e-10 N / 70 N/s: 1e-8 is 100× those); the joint angles and rates at every
/// sample after lift-off until the touch-down ≤ 1e-8 (rad, rad/s: the state is continuous at
/// lift-off and N → 0 continuously, so the lift-off time error enters only at second order; the
/// rest is the integrators' global errors, ~100 rtol); the touch-down time ≤ 1e-8 s.
///
/// Run with μ = 0 and μ = 0.5: the elbow of this planar arm cannot slide while it touches
/// (its position on the table is fixed by α1 alone), so friction changes nothing, and the
/// sticking rows (normal and two tangential, of rank 1 here: the t2 row is zero and the t1 row
/// is parallel to the normal one) must be handled, not make the run fail.
#[test]
fn the_elbow_lifts_off_when_the_reduced_model_says_and_flies_as_it_says() {
    let r = Reference { a: ARM };
    for mu in [0.0, 0.5] {
        let (scene, x0) = scene(1.5, -6.0, json!({"model": "unilateral", "restitution": 0.0, "friction": mu}), 0.6);
        let h = 1e-5;
        assert!(r.normal_force(&x0) > 5.0, "starts pressed: N = {}", r.normal_force(&x0));
        let (t_lo, x_lo, lifted) = r.run(false, 0.0, x0, 0.6, h, |x| r.normal_force(x));
        assert!(lifted && (0.12..0.16).contains(&t_lo), "reference lift-off at {t_lo}");
        let (t_td, _, touched) = r.run(true, t_lo, x_lo, 0.6, h, |x| r.elbow_height(x).max(if x[2] > 0.0 { 1.0 } else { -1.0 }));
        assert!(touched, "the reference elbow comes back down before 0.6 s");
        let c = collect(&scene, "r");
        let lift = c.events_of(ContactEventKind::LiftOff);
        assert!(!lift.is_empty(), "μ = {mu}: no lift-off; events {:?}", c.events);
        assert!((lift[0].t - t_lo).abs() <= 1e-8, "μ = {mu}: lift-off at {} s, reference {t_lo} s (diff {:e})", lift[0].t, lift[0].t - t_lo);
        // before lift-off: in contact, N as the reduced model's
        for o in c.between(0.0, t_lo - 1e-6) {
            assert!(touching(o.contacts[0].mode), "μ = {mu}, t = {}: {:?}", o.t, o.contacts[0].mode);
        }
        let down: Vec<_> = c.events.iter().filter(|e| matches!(e.kind, ContactEventKind::Impact | ContactEventKind::TouchDown | ContactEventKind::Rest)).collect();
        assert!(!down.is_empty(), "μ = {mu}: no touch-down; events {:?}", c.events);
        assert!((down[0].t - t_td).abs() <= 1e-8, "μ = {mu}: touch-down at {} s, reference {t_td} s", down[0].t);
        // after lift-off: the free double pendulum, integrated to each sample time
        let (mut t, mut x) = (t_lo, x_lo);
        let mut compared = 0;
        for o in c.between(t_lo, t_td) {
            let (t1, x1, _) = r.run(true, t, x, o.t, h, |_| 1.0);
            (t, x) = (t1, x1);
            assert_eq!(o.contacts[0].mode, ContactMode::Separated, "μ = {mu}, t = {}", o.t);
            let want = joint_state(&x);
            let got = [o.q[0], o.q[1], o.qd[0], o.qd[1]];
            for i in 0..4 {
                assert!((got[i] - want[i]).abs() <= 1e-8, "μ = {mu}, t = {}: state {got:?}, reference {want:?}", o.t);
            }
            assert!((o.contacts[0].gap - r.elbow_height(&x)).abs() <= 1e-8, "μ = {mu}, t = {}: gap {}", o.t, o.contacts[0].gap);
            compared += 1;
        }
        assert!(compared > 20, "μ = {mu}: {compared} samples in flight");
        // and the contact force before lift-off, at the samples, from the reduced model's
        // pendulum. With friction the split between N and the tangential force F (along x) is
        // NOT unique (the elbow's x and z rows both act on α1 alone: x_E = l1 cos α1): only the
        // generalised force on α1, `l1 (N cos α1 − F sin α1)`, is; it must equal the reference's
        // `l1 N_ref cos α1`, and (N, F) must lie in the friction cone. Frictionless: N = N_ref.
        let (mut t, mut x) = (0.0, x0);
        for o in c.between(0.0, t_lo - 1e-3) {
            let (t1, x1, _) = r.run(false, t, x, o.t, h, |_| 1.0);
            (t, x) = (t1, x1);
            let n_ref = r.normal_force(&x);
            let (n, f) = (o.contacts[0].normal_force, o.contacts[0].friction_force[0]);
            let q = n * x[0].cos() - f * x[0].sin();
            assert!((q - n_ref * x[0].cos()).abs() <= 1e-7, "μ = {mu}, t = {}: N = {n}, F = {f}: N cos α1 − F sin α1 = {q}, reference {}", o.t, n_ref * x[0].cos());
            // (the t2 = y component acts on nothing here, so it is not determined either: only
            // the cone is checked, on |f_t|)
            let ft = o.contacts[0].friction_force[0].hypot(o.contacts[0].friction_force[1]);
            assert!(n >= -1e-9 && ft <= mu * n + 1e-9, "μ = {mu}, t = {}: N = {n}, f_t = {:?} outside the cone", o.t, o.contacts[0].friction_force);
        }
    }
}

/// Unilateral ≡ bilateral while f_n > 0: link2 starting horizontal at 4 rad/s upwards keeps the
/// elbow pressed for the whole 1 s (the reduced model: min N > 0, checked below), so the
/// frictionless unilateral run must match the bilateral run (the paper's path) sample by
/// sample. The two go through different code (the hybrid driver and the active-row solve vs
/// the bilateral Schur path) with different state layouts (the contact quadratures), so their
/// steps differ: the bound is the integrators' global error at rtol 1e-11 (~100 rtol on angles
/// of order 1): 1e-8 rad, rad/s, and 1e-7 N on forces of ~5 N. No event may fire.
///
/// (The paper's one-elbow run does NOT qualify: its bilateral elbow force is negative early,
/// −3.08 N at the start transient (recordings/paper-archive-energy.csv, fn_min.elbow4_n), so a
/// unilateral elbow lifts off there.)
#[test]
fn unilateral_equals_bilateral_while_the_force_stays_positive() {
    let r = Reference { a: ARM };
    let (uni, x0) = scene(0.0, 4.0, json!({"model": "unilateral"}), 1.0);
    let (bi, _) = scene(0.0, 4.0, json!({}), 1.0);
    let (_, _, lifted) = r.run(false, 0.0, x0, 1.0, 1e-4, |x| r.normal_force(x) - 0.5);
    assert!(!lifted, "the reduced model keeps N > 0.5 N for 1 s");
    let (cu, cb) = (collect(&uni, "r"), collect(&bi, "r"));
    assert!(cu.events.is_empty(), "{:?}", cu.events);
    assert!(cb.samples.iter().all(|o| o.contacts.is_empty()), "a bilateral run records no contact outputs");
    assert_eq!(cu.samples.len(), cb.samples.len());
    for (u, b) in cu.samples.iter().zip(&cb.samples) {
        assert_eq!(u.t, b.t);
        for j in 0..2 {
            assert!((u.q[j] - b.q[j]).abs() <= 1e-8 && (u.qd[j] - b.qd[j]).abs() <= 1e-8, "t = {}: {:?} vs {:?}", u.t, (&u.q, &u.qd), (&b.q, &b.qd));
        }
        assert!((u.normal_force[0] - b.normal_force[0]).abs() <= 1e-7, "t = {}: f_n {} vs {}", u.t, u.normal_force[0], b.normal_force[0]);
        assert!((u.contacts[0].normal_force - b.normal_force[0]).abs() <= 1e-7);
        assert!(touching(u.contacts[0].mode));
    }
}

/// The reference itself, checked where today's simulator already applies: held bilaterally the
/// elbow stays on the table for the whole run (the contact-phase equations, N of either sign),
/// and with no contact at all the arm is the free double pendulum (the flight equations). Same
/// tolerances as above (1e-8 on the state, 1e-7 N). This keeps a wrong reference from passing
/// or failing the unilateral tests for the wrong reason.
#[test]
fn the_reduced_model_agrees_with_the_simulator_held_and_free() {
    let r = Reference { a: ARM };
    let h = 1e-5;
    let (held, x0) = scene(1.5, -6.0, json!({}), 0.6);
    let c = collect(&held, "r");
    let (mut t, mut x) = (0.0, x0);
    let mut min_n = f64::INFINITY;
    for o in c.between(0.0, 0.6 + 1e-9) {
        (t, x) = { let (t1, x1, _) = r.run(false, t, x, o.t, h, |_| 1.0); (t1, x1) };
        let want = joint_state(&x);
        let got = [o.q[0], o.q[1], o.qd[0], o.qd[1]];
        for i in 0..4 {
            assert!((got[i] - want[i]).abs() <= 1e-8, "held, t = {}: {got:?} vs reference {want:?}", o.t);
        }
        let n = r.normal_force(&x);
        min_n = min_n.min(n);
        assert!((o.normal_force[0] - n).abs() <= 1e-7, "held, t = {}: f_n {} vs reference {n}", o.t, o.normal_force[0]);
    }
    assert!(min_n < -1.0, "the held elbow is pulled down after t_lo (min N = {min_n} N): the lift-off case is real");
    // free: no contact, from the state of the reference at lift-off with the elbow 1 cm up
    let a1 = (-(ARM.h - 0.01) / ARM.l1).asin();
    let x0 = [a1, 0.3, 0.5, -2.0];
    let j = joint_state(&x0);
    let s = passive_scene("link2", &["joint1", "joint2"], &j[..2], &j[2..], [0.0, 0.0, -G], 0.3, 1e-11);
    let c = collect(&load(&s, &ARM.urdf()), "r");
    let (mut t, mut x) = (0.0, x0);
    for o in c.between(0.0, 0.3 + 1e-9) {
        (t, x) = { let (t1, x1, _) = r.run(true, t, x, o.t, h, |_| 1.0); (t1, x1) };
        let want = joint_state(&x);
        let got = [o.q[0], o.q[1], o.qd[0], o.qd[1]];
        for i in 0..4 {
            assert!((got[i] - want[i]).abs() <= 1e-8, "free, t = {}: {got:?} vs reference {want:?}", o.t);
        }
    }
}
