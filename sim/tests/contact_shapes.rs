//! Contact shapes (issue 23, item 5): a sphere pad that rolls, slides then rolls, and a
//! capsule (its two end spheres, from the `table` construct) that tips from one end to lying
//! flat and slides on its side — each against its closed form at every sample (rolling
//! constraint, friction in the cone, gap zero while closed, the forces), and the event times.
//!
//! Closed forms: the ball pushed by a force and the ball that slides then rolls (Goldstein,
//! Poole & Safko, *Classical Mechanics*, 3rd ed., 2002, §1.3 and problem 1.22; Marion &
//! Thornton, *Classical Dynamics*, 5th ed., §7.10 / Meriam & Kraige, *Engineering Mechanics:
//! Dynamics*, §6/6 for the slide-then-roll time 2 v0/(7 μ g) and speed 5/7 v0); the rod tipping
//! on a frictionless floor (its centre falls straight down: Routh, *Dynamics of a System of
//! Rigid Bodies*, 1905, §§ 140–141; the energy integral below); the rod sliding on its side
//! (Coulomb, with the normal forces from the moments about the centre).
//!
//! Frames: world z up, the table z = 0, tangent basis (x, y). The planar robots move in x–z
//! (prismatic x, prismatic z, revolute pitch about world y); a body with pitch rate θ̇ and
//! centre speed ẋ has its lowest point moving at `ẋ − r θ̇` (so rolling is `ẋ = r θ̇`).

use crate::contacts_support::*;
use serde_json::{json, Value};
use sim::dynamics::contact::{ContactEventKind, ContactMode};

/// The slip left when a slip → stick is located (issue 23 item 2: the stop is the zero of
/// `v_t · s_ref`, located to the driver's 1e-12 s bracket, and what is left is projected away),
/// m/s: a bound on |ẋ − closed form| after a stop and on the work it leaves unbooked.
const STOP_BAND: f64 = 1e-9;
/// The event times of a located slip → stick against the closed form, s.
const STOP_TIME: f64 = 1e-10;

/// A solid ball (or a disk with the inertia of one, `2/5 m r²` about y) of mass `mass` and
/// radius `radius` on prismatic x, prismatic z, prismatic y and revolute pitch (world y):
/// q = (x, z, y, θ) of its centre, massless carriages. (The y joint gives the t2 row a column:
/// without it the row is zero, the contact solve regularises the singular set, A + 1e-10
/// max diag(A) I, and a rolling contact drifts by ε f_n ≈ 3e-9 m/s² in g̈.)
fn ball_urdf(mass: f64, radius: f64) -> String {
    let lim = r#"<limit lower="-1000" upper="1000" effort="1e6" velocity="1e3"/>"#;
    let i = 0.4 * mass * radius * radius;
    format!(
        r#"<?xml version="1.0"?>
<robot name="ball">
  <link name="base"/>
  <joint name="x" type="prismatic"><parent link="base"/><child link="cx"/><origin xyz="0 0 0"/><axis xyz="1 0 0"/>{lim}</joint>
  <link name="cx"/>
  <joint name="z" type="prismatic"><parent link="cx"/><child link="cz"/><origin xyz="0 0 0"/><axis xyz="0 0 1"/>{lim}</joint>
  <link name="cz"/>
  <joint name="y" type="prismatic"><parent link="cz"/><child link="cy"/><origin xyz="0 0 0"/><axis xyz="0 1 0"/>{lim}</joint>
  <link name="cy"/>
  <joint name="pitch" type="continuous"><parent link="cy"/><child link="ball"/><origin xyz="0 0 0"/><axis xyz="0 1 0"/></joint>
  <link name="ball"><inertial><origin xyz="0 0 0"/><mass value="{mass}"/><inertia ixx="{i}" ixy="0" ixz="0" iyy="{i}" iyz="0" izz="{i}"/></inertial></link>
</robot>"#
    )
}

/// A ball scene: the pad `pad`, a sphere of `r` at the ball's centre, on the table with `keys`.
fn ball_scene(r: f64, q0: [f64; 4], qd0: [f64; 4], gravity: [f64; 3], duration: f64, keys: Value) -> Value {
    let mut s = passive_scene("ball", &["x", "z", "y", "pitch"], &q0, &qd0, gravity, duration, 1e-12);
    let mut k = keys;
    k["shape"] = json!({"kind": "sphere", "radius": r});
    add_table_contact(&mut s, "pad", json!({"link": "ball"}), k);
    s
}

/// A rod of half-length `h` (the `rod_urdf` of the support) whose capsule of radius `r` runs
/// end to end along its axis, on the table construct (`model` unilateral, `keys` added):
/// contacts `rod/0` at the −x end and `rod/1` at the +x end.
fn capsule_scene(h: f64, r: f64, q0: [f64; 3], qd0: [f64; 3], duration: f64, keys: Value) -> Value {
    let mut s = passive_scene("rod", &["x", "z", "pitch"], &q0, &qd0, [0.0, 0.0, -G], duration, 1e-12);
    let mut table = json!({
        "plane": {"normal": [0.0, 0.0, 1.0], "offset": 0.0},
        "points": [{"name": "rod", "point": {"link": "rod", "offset": [-h, 0.0, 0.0]},
                    "shape": {"kind": "capsule", "radius": r, "to": {"link": "rod", "offset": [h, 0.0, 0.0]}}}],
    });
    for (k, v) in keys.as_object().unwrap() {
        table[k] = v.clone();
    }
    s["table"] = table;
    s
}

fn in_cone(what: &str, t: f64, f: &sim::dynamics::contact::ContactOutput, mu: f64) {
    let ft = f.friction_force[0].hypot(f.friction_force[1]);
    assert!(ft <= mu * f.normal_force * (1.0 + 1e-9) + 1e-12, "{what}, t = {t}: |f_t| = {ft} N > μ f_n = {} N", mu * f.normal_force);
    assert!(f.normal_force >= -1e-9, "{what}, t = {t}: f_n = {} N pulls", f.normal_force);
}

/// A solid ball (m = 2 kg, r = 0.1 m, μ = 0.5) at rest on the table under g = (2, 0, −9.81)
/// m/s²: the push m g_x at the centre rolls it without slip, `ẍ = 5/7 g_x`, held by the
/// friction `f_t = −2/7 m g_x` (0.57 N ≤ μ m g = 9.8 N) at the touching point, `f_n = m g`.
/// At every sample: x = 5/14 g_x t², ẋ = 5/7 g_x t, the rolling constraint `ẋ = r θ̇` (the
/// recorded slip velocity is 0), z = r with the gap 0, sticking. Tolerances 1e-9 (the motion is
/// quadratic in t: dopri45 at rtol 1e-12 is exact up to round-off). A point contact at the
/// centre would hold the centre on the table (gap −r at start: refused); one at the ball's
/// bottom as a material point would leave the table as the ball turns.
#[test]
fn a_ball_pushed_by_a_force_rolls_without_slip_at_five_sevenths_of_its_acceleration() {
    let (m, r, mu, gx) = (2.0, 0.1, 0.5, 2.0);
    let s = ball_scene(r, [0.0, r, 0.0, 0.0], [0.0; 4], [gx, 0.0, -G], 1.0, json!({"model": "unilateral", "friction": mu}));
    let c = collect(&load(&s, &ball_urdf(m, r)), "r");
    assert!(c.events.is_empty(), "no event: {:?}", c.events);
    assert!(c.samples.len() > 900);
    let a = 5.0 / 7.0 * gx;
    for o in &c.samples {
        let (t, f) = (o.t, &o.contacts[0]);
        assert_eq!(f.mode, ContactMode::Sticking, "t = {t}");
        assert!((o.q[0] - 0.5 * a * t * t).abs() <= 1e-9, "t = {t}: x = {} m, 5/14 g_x t² = {} m", o.q[0], 0.5 * a * t * t);
        assert!((o.qd[0] - a * t).abs() <= 1e-9, "t = {t}: ẋ = {} m/s, 5/7 g_x t = {}", o.qd[0], a * t);
        assert!((o.qd[0] - r * o.qd[3]).abs() <= 1e-9, "t = {t}: rolling: ẋ = {}, r θ̇ = {}", o.qd[0], r * o.qd[3]);
        assert!(f.slip_velocity[0].abs() <= 1e-9 && f.slip_velocity[1].abs() <= 1e-12, "t = {t}: slip {:?}", f.slip_velocity);
        assert!(f.gap.abs() <= 1e-9 && f.gap_rate.abs() <= 1e-9 && (o.q[1] - r).abs() <= 1e-9, "t = {t}: gap {} m, rate {} m/s", f.gap, f.gap_rate);
        assert!((f.normal_force - m * G).abs() <= 1e-9 * m * G, "t = {t}: f_n = {} N, m g = {} N", f.normal_force, m * G);
        assert!((f.friction_force[0] + 2.0 / 7.0 * m * gx).abs() <= 1e-9 * m * G, "t = {t}: f_t = {:?} N, −2/7 m g_x = {}", f.friction_force, -2.0 / 7.0 * m * gx);
        in_cone("rolling ball", t, f, mu);
        assert!(f.friction_work.abs() <= 1e-9, "t = {t}: rolling does no friction work: {} J", f.friction_work);
        assert!(o.balance_residual.abs() <= 1e-9, "t = {t}: balance residual {} J", o.balance_residual);
    }
}

/// A solid ball (m = 1.5 kg, r = 0.08 m) thrown along the table with v0 = 2 m/s and no spin,
/// μ = 0.3: it slides, `ẋ = v0 − μ g t`, `r θ̇ = 5/2 μ g t` (the friction's moment), until the
/// slip `ẋ − r θ̇ = v0 − 7/2 μ g t` vanishes at `t* = 2 v0 / (7 μ g)` (a `slip-to-stick` event,
/// the only event); then it rolls at `5/7 v0` with no friction. Every sample: the closed form
/// (1e-9), f_n = m g, the friction on the cone's edge against the slip while sliding (|f_t| = μ
/// f_n, opposed to v_t), in the cone and zero while rolling, the gap 0; the friction work is
/// the kinetic energy lost, `½ m v0² · 2/7` after t*, and the balance closes (1e-9). The stop
/// time to `STOP_TIME`.
#[test]
fn a_ball_that_slides_then_rolls_stops_slipping_at_two_sevenths_v0_over_mu_g() {
    let (m, r, mu, v0) = (1.5, 0.08, 0.3, 2.0);
    let s = ball_scene(r, [0.0, r, 0.0, 0.0], [v0, 0.0, 0.0, 0.0], [0.0, 0.0, -G], 0.5, json!({"model": "unilateral", "friction": mu}));
    let c = collect(&load(&s, &ball_urdf(m, r)), "r");
    let t_star = 2.0 * v0 / (7.0 * mu * G);
    let kinds: Vec<_> = c.events.iter().map(|e| e.kind).collect();
    assert_eq!(kinds, [ContactEventKind::SlipToStick], "{:?}", c.events);
    let band = STOP_TIME;
    eprintln!("slide then roll: slip → stick at {} s, closed form {t_star} s, Δ = {:e} s", c.events[0].t, c.events[0].t - t_star);
    assert!((c.events[0].t - t_star).abs() <= band, "slip → stick at {} s, 2 v0/(7 μ g) = {t_star} s (band {band:e} s)", c.events[0].t);
    let e0 = 0.5 * m * v0 * v0;
    for o in &c.samples {
        let (t, f) = (o.t, &o.contacts[0]);
        assert!(f.gap.abs() <= 1e-9 && f.gap_rate.abs() <= 1e-9, "t = {t}: gap {} m, rate {} m/s", f.gap, f.gap_rate);
        assert!((f.normal_force - m * G).abs() <= 1e-9 * m * G, "t = {t}: f_n = {}", f.normal_force);
        in_cone("slide then roll", t, f, mu);
        let slip = o.qd[0] - r * o.qd[3];
        assert!((f.slip_velocity[0] - slip).abs() <= 1e-12, "t = {t}: the recorded slip {} is ẋ − r θ̇ = {slip}", f.slip_velocity[0]);
        let ke = 0.5 * m * o.qd[0] * o.qd[0] + 0.5 * 0.4 * m * r * r * o.qd[3] * o.qd[3];
        assert!((f.friction_work - (e0 - ke)).abs() <= 1e-9 * e0, "t = {t}: friction work {} J, kinetic energy lost {} J", f.friction_work, e0 - ke);
        assert!(o.balance_residual.abs() <= 1e-9 * e0, "t = {t}: balance residual {} J", o.balance_residual);
        if t < t_star - band {
            assert_eq!(f.mode, ContactMode::Sliding, "t = {t}");
            assert!((o.qd[0] - (v0 - mu * G * t)).abs() <= 1e-9, "t = {t}: ẋ = {}, v0 − μ g t = {}", o.qd[0], v0 - mu * G * t);
            assert!((r * o.qd[3] - 2.5 * mu * G * t).abs() <= 1e-9, "t = {t}: r θ̇ = {}, 5/2 μ g t = {}", r * o.qd[3], 2.5 * mu * G * t);
            assert!((f.friction_force[0] + mu * m * G).abs() <= 1e-9 * m * G, "t = {t}: f_t = {:?}, −μ m g = {}", f.friction_force, -mu * m * G);
        } else if t > t_star + band {
            assert_eq!(f.mode, ContactMode::Sticking, "t = {t}");
            // the stop removes the last ≤ 2e-6 m/s of slip by an impulse: ẋ within that of 5/7 v0
            assert!((o.qd[0] - 5.0 / 7.0 * v0).abs() <= STOP_BAND, "t = {t}: ẋ = {}, 5/7 v0 = {}", o.qd[0], 5.0 / 7.0 * v0);
            assert!(f.slip_velocity[0].abs() <= 1e-9, "t = {t}: rolling: slip {:?}", f.slip_velocity);
            assert!(f.friction_force[0].abs() <= 1e-9, "t = {t}: no friction while rolling: {:?}", f.friction_force);
            assert!((f.friction_work - e0 * 2.0 / 7.0).abs() <= 1e-9 * e0 + m * v0 * STOP_BAND, "t = {t}: friction work {} J, m v0²/7 = {} J", f.friction_work, e0 * 2.0 / 7.0);
        }
    }
}

/// The time a uniform rod of half-length h with a capsule of radius r, released at rest with
/// its lower end sphere on a frictionless table and its axis at θ0 above the horizontal, takes
/// to lie flat. Frictionless: the table's force is vertical, so the centre falls straight down,
/// `z_c = r + h sin θ`, and energy gives `θ̇² = 2 g (sin θ0 − sin θ) / (h (cos²θ + 1/3))`
/// (I = m h²/3). `T = ∫_0^θ0 dθ/|θ̇|`, with θ = θ0 − s² (which takes out the 1/√ at the
/// release), by 3-point Gauss–Legendre on 4000 panels (converged to round-off: halving the
/// panels moves it by < 1e-15 s).
fn tipping_time(h: f64, theta0: f64) -> f64 {
    time_to_lie_flat(theta0, |th| 2.0 * G * (theta0.sin() - th.sin()) / (h * (th.cos().powi(2) + 1.0 / 3.0)))
}

/// `T = ∫_0^θ0 dθ/|θ̇|` for a rod released at rest at θ0, given `θ̇²(θ)`: with θ = θ0 − s²
/// (which takes out the 1/√ at the release), by 3-point Gauss–Legendre on 4000 panels.
fn time_to_lie_flat(theta0: f64, theta_dot_sq: impl Fn(f64) -> f64) -> f64 {
    let f = |s: f64| 2.0 * s / theta_dot_sq(theta0 - s * s).sqrt();
    let (n, b) = (4000, theta0.sqrt());
    let dx = b / n as f64;
    let (x3, w) = ((0.6f64).sqrt(), [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0]);
    (0..n)
        .map(|i| {
            let m = (i as f64 + 0.5) * dx;
            let half = 0.5 * dx;
            half * (w[0] * f(m - half * x3) + w[1] * f(m) + w[2] * f(m + half * x3))
        })
        .sum()
}

/// A capsule (m = 1 kg, segment 0.6 m, r = 0.04 m) released at rest on its lower end at 30°
/// on a frictionless table (e = 0) tips until it lies flat: its upper end sphere `rod/1`
/// touches down with an `impact` at the closed-form time (1e-10 s), the lower one `rod/0`
/// stays closed throughout (gap 0, f_n ≥ 0, never lifting off), the centre falls straight down
/// (x_c = 0, z_c = r + h sin θ: 1e-9), and after the plastic impact both ends rest with f_n = m
/// g / 2 each, the kinetic energy at the impact, `m g h sin θ0`, lost in it (1e-9).
#[test]
fn a_capsule_tipping_from_one_end_lies_flat_at_the_closed_form_time() {
    let (m, h, r, th0) = (1.0, 0.3, 0.04, 30f64.to_radians());
    let s = capsule_scene(h, r, [0.0, r + h * th0.sin(), -th0], [0.0; 3], 0.6, json!({"model": "unilateral"}));
    let scene = load(&s, &rod_urdf(m, h));
    let names: Vec<String> = scene.run_contact_models(scene.run("r").unwrap()).iter().map(|c| c.name().to_string()).collect();
    assert_eq!(names, ["rod/0", "rod/1"]);
    let c = collect(&scene, "r");
    let t_down = tipping_time(h, th0);
    assert!(t_down > 0.2 && t_down < 0.5, "{t_down}");
    let kinds: Vec<_> = c.events.iter().map(|e| (e.contact, e.kind)).collect();
    assert_eq!(kinds, [(1, ContactEventKind::Impact)], "{:?}", c.events);
    let ev = &c.events[0];
    eprintln!("capsule tipping: touch-down at {} s, closed form {t_down} s, Δ = {:e} s", ev.t, ev.t - t_down);
    assert!((ev.t - t_down).abs() <= 1e-10, "touch-down of the upper end at {} s, closed form {t_down} s (Δ {:e} s)", ev.t, ev.t - t_down);
    assert!(ev.gap_rate_before < -0.1 && ev.gap_rate_after.abs() <= 1e-9, "{ev:?}");
    let e_lost = m * G * h * th0.sin();
    assert!((ev.energy_lost - e_lost).abs() <= 1e-9 * e_lost, "impact loss {} J, m g h sin θ0 = {e_lost} J", ev.energy_lost);
    for o in &c.samples {
        let (t, lo, hi) = (o.t, &o.contacts[0], &o.contacts[1]);
        assert!(touching(lo.mode), "t = {t}: the lower end stays on the table: {:?}", lo.mode);
        assert!(lo.gap.abs() <= 1e-9 && lo.gap_rate.abs() <= 1e-9, "t = {t}: lower end gap {} m, rate {} m/s", lo.gap, lo.gap_rate);
        assert!(lo.normal_force >= 0.0 && lo.friction_force == [0.0; 2], "t = {t}: lower end {lo:?}");
        assert!(o.q[0].abs() <= 1e-9 && o.qd[0].abs() <= 1e-9, "t = {t}: the centre falls straight down: x = {} m, ẋ = {} m/s", o.q[0], o.qd[0]);
        let th = -o.q[2];
        assert!((o.q[1] - (r + h * th.sin())).abs() <= 1e-9, "t = {t}: z_c = {} m, r + h sin θ = {} m", o.q[1], r + h * th.sin());
        if t < ev.t {
            assert_eq!(hi.mode, ContactMode::Separated, "t = {t}");
            assert!((hi.gap - 2.0 * h * th.sin()).abs() <= 1e-9 && hi.gap > 0.0, "t = {t}: upper end gap {} m, 2 h sin θ = {}", hi.gap, 2.0 * h * th.sin());
            let w2 = 2.0 * G * (th0.sin() - th.sin()) / (h * (th.cos().powi(2) + 1.0 / 3.0));
            assert!((o.qd[2] - w2.sqrt()).abs() <= 1e-8, "t = {t}: |θ̇| = {}, energy integral {}", o.qd[2], w2.sqrt());
        } else {
            assert!(touching(hi.mode), "t = {t}: {:?}", hi.mode);
            for (end, f) in [("lower", lo), ("upper", hi)] {
                assert!((f.normal_force - 0.5 * m * G).abs() <= 1e-9 * m * G, "t = {t}: {end} f_n = {} N, m g / 2 = {}", f.normal_force, 0.5 * m * G);
                assert!(f.gap.abs() <= 1e-9 && f.gap_rate.abs() <= 1e-9, "t = {t}: {end}: {f:?}");
            }
        }
        assert!(o.balance_residual.abs() <= 1e-9 * e_lost, "t = {t}: balance residual {} J", o.balance_residual);
    }
}

/// A capsule (m = 1 kg, segment 0.6 m, r = 0.05 m) lying flat and pushed along its axis with
/// v0 = 1.5 m/s, μ = 0.4, slides to a stop at `v0 / (μ g)` having done friction work ½ m v0²
/// (both end spheres' together). While sliding, the friction acts at the touching points, r
/// below the centre, so its moment loads the front end: `f_n = m g / 2 (1 ± μ r / h)` (front
/// +, rear −; a contact at the centres would carry m g / 2 each); ẋ = v0 − μ g t (1e-9); each
/// friction on the cone's edge, opposed to the slip; gaps 0 and θ = 0 at every sample. After
/// the stop both stick with m g / 2 each and no friction.
#[test]
fn a_capsule_sliding_on_its_side_stops_at_v0_over_mu_g_with_its_kinetic_energy_as_friction_work() {
    let (m, h, r, mu, v0) = (1.0, 0.3, 0.05, 0.4, 1.5);
    let s = capsule_scene(h, r, [0.0, r, 0.0], [v0, 0.0, 0.0], 0.6, json!({"model": "unilateral", "friction": mu}));
    let c = collect(&load(&s, &rod_urdf(m, h)), "r");
    let t_s = v0 / (mu * G);
    let stops = c.events_of(ContactEventKind::SlipToStick);
    assert!(!stops.is_empty() && c.events.iter().all(|e| e.kind == ContactEventKind::SlipToStick), "{:?}", c.events);
    let band = STOP_TIME;
    for e in &stops {
        eprintln!("capsule on its side: slip → stick of {} at {} s, closed form {t_s} s, Δ = {:e} s", e.contact, e.t, e.t - t_s);
        assert!((e.t - t_s).abs() <= band, "slip → stick of contact {} at {} s, v0/(μ g) = {t_s} s", e.contact, e.t);
    }
    let e0 = 0.5 * m * v0 * v0;
    for o in &c.samples {
        let t = o.t;
        assert!(o.q[2].abs() <= 1e-9 && o.qd[2].abs() <= 1e-9 && (o.q[1] - r).abs() <= 1e-9, "t = {t}: lies flat: q = {:?}", o.q);
        let work: f64 = o.contacts.iter().map(|f| f.friction_work).sum();
        assert!((work - 0.5 * m * (v0 * v0 - o.qd[0] * o.qd[0])).abs() <= 1e-9 * e0, "t = {t}: friction work {work} J");
        assert!(o.balance_residual.abs() <= 1e-9 * e0, "t = {t}: balance residual {} J", o.balance_residual);
        for (k, f) in o.contacts.iter().enumerate() {
            assert!(f.gap.abs() <= 1e-9 && f.gap_rate.abs() <= 1e-9, "t = {t}, end {k}: {f:?}");
            in_cone("capsule on its side", t, f, mu);
            if t < t_s - band {
                assert_eq!(f.mode, ContactMode::Sliding, "t = {t}, end {k}");
                let sign = if k == 1 { 1.0 } else { -1.0 };
                let fn_want = 0.5 * m * G * (1.0 + sign * mu * r / h);
                assert!((f.normal_force - fn_want).abs() <= 1e-9 * m * G, "t = {t}, end {k}: f_n = {} N, m g/2 (1 ± μ r/h) = {fn_want} N", f.normal_force);
                assert!((f.friction_force[0] + mu * f.normal_force).abs() <= 1e-9 * m * G, "t = {t}, end {k}: f_t {:?}", f.friction_force);
            } else if t > t_s + band {
                assert_eq!(f.mode, ContactMode::Sticking, "t = {t}, end {k}");
                assert!((f.normal_force - 0.5 * m * G).abs() <= 1e-9 * m * G, "t = {t}, end {k}: {f:?}");
            }
        }
        if t > t_s + band {
            // the two ends' tangential rows are the same row (statically indeterminate): only
            // their sum is fixed, and it is zero at rest
            let sum: f64 = o.contacts.iter().map(|f| f.friction_force[0]).sum();
            assert!(sum.abs() <= 1e-9 * m * G, "t = {t}: the friction forces at rest sum to {sum} N");
        }
        if t < t_s - band {
            assert!((o.qd[0] - (v0 - mu * G * t)).abs() <= 1e-9, "t = {t}: ẋ = {}, v0 − μ g t = {}", o.qd[0], v0 - mu * G * t);
        } else if t > t_s + band {
            assert!(o.qd[0].abs() <= STOP_BAND && (work - e0).abs() <= 1e-9 * e0 + m * v0 * STOP_BAND, "t = {t}: ẋ = {}, work {work}", o.qd[0]);
        }
    }
}

/// The shape is validated once, with the file, the field and the value in every error.
#[test]
fn bad_shapes_are_refused_naming_the_field_and_the_value() {
    let err = |s: &Value, urdf: &str| try_load(s, urdf).map(|_| ()).unwrap_err().to_string();
    let (m, r) = (1.0, 0.1);
    let ok = ball_scene(r, [0.0, r, 0.0, 0.0], [0.0; 4], [0.0, 0.0, -G], 0.1, json!({"model": "unilateral"}));
    let urdf = ball_urdf(m, r);
    assert!(try_load(&ok, &urdf).is_ok());
    for (radius, why) in [(0.0, "must be in (0, 10] m"), (-0.1, "must be in (0, 10] m"), (20.0, "must be in (0, 10] m")] {
        let mut s = ok.clone();
        s["contacts"][0]["shape"]["radius"] = json!(radius);
        let e = err(&s, &urdf);
        assert!(e.contains("contact-test.json") && e.contains("contacts[0].shape.radius") && e.contains(&format!("{radius}")) && e.contains(why), "{e}");
    }
    let mut s = ok.clone();
    s["contacts"][0]["model"] = json!("bilateral");
    let e = err(&s, &urdf);
    assert!(e.contains("contacts[0].shape.kind") && e.contains("sphere") && e.contains("plane.offset"), "{e}");
    let mut s = ok.clone();
    s["contacts"][0]["shape"] = json!({"kind": "cube", "radius": 0.1});
    let e = err(&s, &urdf);
    assert!(e.contains("contacts[0].shape") && e.contains("cube"), "{e}");
    let mut s = ok.clone();
    s["contacts"][0]["shape"] = json!({"kind": "capsule", "radius": 0.1, "to": {"link": "ball", "offset": [0.1, 0.0, 0.0]}});
    let e = err(&s, &urdf);
    assert!(e.contains("contacts[0].shape.kind") && e.contains("table.points"), "{e}");
    // a sphere that starts inside the table (its centre 5 cm above, radius 10 cm)
    let s = ball_scene(r, [0.0, 0.05, 0.0, 0.0], [0.0; 4], [0.0, 0.0, -G], 0.1, json!({"model": "unilateral"}));
    let e = err(&s, &urdf);
    assert!(e.contains("contacts[0]") && e.contains("sphere starts inside the plane") && e.contains("-5.000e-2"), "{e}");
    // capsules: the other end on another link, or on the point itself
    let rod = rod_urdf(1.0, 0.3);
    let cap = capsule_scene(0.3, 0.04, [0.0, 0.04, 0.0], [0.0; 3], 0.1, json!({}));
    assert!(try_load(&cap, &rod).is_ok());
    let mut s = cap.clone();
    s["table"]["points"][0]["shape"]["to"] = json!({"link": "cz", "offset": [0.3, 0.0, 0.0]});
    let e = err(&s, &rod);
    assert!(e.contains("table.points[0].shape.to") && e.contains("cz") && e.contains("same link"), "{e}");
    let mut s = cap.clone();
    s["table"]["points"][0]["shape"]["to"] = json!({"link": "rod", "offset": [-0.3, 0.0, 0.0]});
    let e = err(&s, &rod);
    assert!(e.contains("table.points[0].shape.to") && e.contains("zero length"), "{e}");
    let mut s = cap.clone();
    s["table"]["points"][0]["shape"]["to"] = json!({"link": "nope", "offset": [0.3, 0.0, 0.0]});
    let e = err(&s, &rod);
    assert!(e.contains("table.points[0].shape.to.link") && e.contains("nope"), "{e}");
}

// ---------------------------------------------------------------------------------------------
// Cylinder rims and the table's contacts from URDF <collision> shapes (`table.from_collisions`).
//
// A rim's lowest point sits at `c + r u`, u the in-plane direction most opposed to the normal,
// so a cylinder tilted by θ about an axis normal to its own touches at `z_end − r cos θ` (a
// capsule's end sphere would touch at `z_end − r`), and the point moves along the rim as the
// link turns (`dynamics/contact/shape.rs`).

/// The rod of `rod_urdf` with a `<collision>` cylinder of radius `r` along its x axis, end to
/// end (length 2h), on a table that takes its contacts from the rod's collisions: `rod/c0/0`
/// (the −x rim) and `rod/c0/1` (the +x rim).
fn cylinder_rod(m: f64, h: f64, r: f64) -> String {
    rod_urdf(m, h).replace(
        r#"<link name="rod"><inertial>"#,
        &format!(r#"<link name="rod"><collision><origin xyz="0 0 0" rpy="0 1.5707963267948966 0"/><geometry><cylinder radius="{r}" length="{}"/></geometry></collision><inertial>"#, 2.0 * h),
    )
}

fn collisions_table(s: &mut Value, links: &[&str], keys: Value) {
    let mut table = json!({"plane": {"normal": [0.0, 0.0, 1.0], "offset": 0.0}, "from_collisions": links});
    for (k, v) in keys.as_object().unwrap() {
        table[k] = v.clone();
    }
    s["table"] = table;
}

/// The time a rod (I = m h²/3) with a cylinder of radius r and half-length h, released at
/// rest on its lower rim on a frictionless table at θ0, takes to lie flat: the centre falls
/// straight down, `z_c = h sin θ + r cos θ` (the rim's lowest point), `ż_c = (h cos θ −
/// r sin θ) θ̇`, and energy gives `θ̇² = 2 g (z_c(θ0) − z_c(θ)) / ((h cos θ − r sin θ)² +
/// h²/3)`. Quadrature as [`tipping_time`].
fn rim_tipping_time(h: f64, r: f64, theta0: f64) -> f64 {
    let z = |th: f64| h * th.sin() + r * th.cos();
    time_to_lie_flat(theta0, |th| 2.0 * G * (z(theta0) - z(th)) / ((h * th.cos() - r * th.sin()).powi(2) + h * h / 3.0))
}

/// A cylinder (m = 1 kg, length 0.6 m, r = 0.05 m) from the URDF's `<collision>`, released at
/// rest on its lower rim at 30° on a frictionless table, tips until it lies on its side: the
/// lower rim stays closed with its lowest point moving along the rim (gap 0 at every sample,
/// `z_c = h sin θ + r cos θ`, 1e-9: a capsule would give r + h sin θ, 3.3 mm higher at θ0), the
/// centre falls straight down, θ̇ follows the energy integral, and the upper rim touches down
/// with an impact at the closed-form time (1e-10 s), losing `m g (z_c(θ0) − r)`; then both rims
/// rest with m g / 2 each.
#[test]
fn a_cylinder_tipping_on_its_rim_lies_on_its_side_at_the_closed_form_time() {
    let (m, h, r, th0) = (1.0, 0.3, 0.05, 30f64.to_radians());
    let z0 = h * th0.sin() + r * th0.cos();
    let mut s = passive_scene("rod", &["x", "z", "pitch"], &[0.0, z0, -th0], &[0.0; 3], [0.0, 0.0, -G], 0.6, 1e-12);
    collisions_table(&mut s, &["rod"], json!({"model": "unilateral"}));
    let scene = load(&s, &cylinder_rod(m, h, r));
    let names: Vec<String> = scene.run_contact_models(scene.run("r").unwrap()).iter().map(|c| c.name().to_string()).collect();
    assert_eq!(names, ["rod/c0/0", "rod/c0/1"]);
    let c = collect(&scene, "r");
    let t_down = rim_tipping_time(h, r, th0);
    assert!(t_down > 0.2 && t_down < 0.5, "{t_down}");
    let kinds: Vec<_> = c.events.iter().map(|e| (e.contact, e.kind)).collect();
    assert_eq!(kinds, [(1, ContactEventKind::Impact)], "{:?}", c.events);
    let ev = &c.events[0];
    eprintln!("cylinder tipping on its rim: touch-down at {} s, closed form {t_down} s, Δ = {:e} s", ev.t, ev.t - t_down);
    assert!((ev.t - t_down).abs() <= 1e-10, "touch-down of the upper rim at {} s, closed form {t_down} s (Δ {:e} s)", ev.t, ev.t - t_down);
    let e_lost = m * G * (z0 - r);
    assert!((ev.energy_lost - e_lost).abs() <= 1e-9 * e_lost, "impact loss {} J, m g (z_c(θ0) − r) = {e_lost} J", ev.energy_lost);
    for o in &c.samples {
        let (t, lo, hi) = (o.t, &o.contacts[0], &o.contacts[1]);
        assert!(touching(lo.mode), "t = {t}: the lower rim stays on the table: {:?}", lo.mode);
        assert!(lo.gap.abs() <= 1e-9 && lo.gap_rate.abs() <= 1e-9, "t = {t}: lower rim gap {} m, rate {} m/s", lo.gap, lo.gap_rate);
        assert!(lo.normal_force >= 0.0, "t = {t}: lower rim {lo:?}");
        assert!(o.q[0].abs() <= 1e-9 && o.qd[0].abs() <= 1e-9, "t = {t}: the centre falls straight down: x = {} m, ẋ = {} m/s", o.q[0], o.qd[0]);
        let th = -o.q[2];
        assert!((o.q[1] - (h * th.sin() + r * th.cos())).abs() <= 1e-9, "t = {t}: z_c = {} m, h sin θ + r cos θ = {} m", o.q[1], h * th.sin() + r * th.cos());
        if t < ev.t {
            assert_eq!(hi.mode, ContactMode::Separated, "t = {t}");
            assert!((hi.gap - 2.0 * h * th.sin()).abs() <= 1e-9, "t = {t}: upper rim gap {} m, 2 h sin θ = {}", hi.gap, 2.0 * h * th.sin());
            let w2 = 2.0 * G * (z0 - o.q[1]) / ((h * th.cos() - r * th.sin()).powi(2) + h * h / 3.0);
            assert!((o.qd[2] - w2.sqrt()).abs() <= 1e-8, "t = {t}: |θ̇| = {}, energy integral {}", o.qd[2], w2.sqrt());
        } else {
            assert!(touching(hi.mode), "t = {t}: {:?}", hi.mode);
            for (end, f) in [("lower", lo), ("upper", hi)] {
                assert!((f.normal_force - 0.5 * m * G).abs() <= 1e-9 * m * G, "t = {t}: {end} f_n = {} N, m g / 2 = {}", f.normal_force, 0.5 * m * G);
                assert!(f.gap.abs() <= 1e-9 && f.gap_rate.abs() <= 1e-9, "t = {t}: {end}: {f:?}");
            }
        }
        assert!(o.balance_residual.abs() <= 1e-9 * e_lost, "t = {t}: balance residual {} J", o.balance_residual);
    }
}

/// A disk (m = 2 kg, r = 0.1 m, width 2 cm, I = ½ m r² about its axis, world y) from a URDF
/// `<collision>` cylinder, standing on its rims on the table (μ = 0.5) and pushed by the
/// force F = m g_x at its centre (g = (3, 0, −9.81) m/s²): it rolls, `a = F / (m + I/r²)` =
/// 2/3 g_x, held by the friction `F I/r² / (m + I/r²)` = F/3 against the push. At every sample
/// (1e-9): x = ½ a t², ẋ = a t, `v = ω r` (ẋ = r θ̇), both rims closed with gap 0 (1e-8) and no
/// slip, the normal forces summing to m g and the friction forces to −F/3 (the two rims' rows
/// are the same rows, so only their sums are determined), and the balance closed to 1e-8 of F x. The touching
/// points move along the rims as the disk turns (a material point would leave the table).
#[test]
fn a_disk_pushed_on_its_rims_rolls_at_f_over_m_plus_i_over_r_squared() {
    let (m, r, w, mu, gx) = (2.0, 0.1, 0.02, 0.5, 3.0);
    let i = 0.5 * m * r * r;
    let urdf = ball_urdf(m, r).replace(&format!(r#"iyy="{}""#, 0.4 * m * r * r), &format!(r#"iyy="{i}""#)).replace(
        r#"<link name="ball"><inertial>"#,
        &format!(r#"<link name="ball"><collision><origin xyz="0 0 0" rpy="1.5707963267948966 0 0"/><geometry><cylinder radius="{r}" length="{w}"/></geometry></collision><inertial>"#),
    );
    assert!(urdf.contains(&format!(r#"iyy="{i}""#)));
    let mut s = passive_scene("ball", &["x", "z", "y", "pitch"], &[0.0, r, 0.0, 0.0], &[0.0; 4], [gx, 0.0, -G], 1.0, 1e-12);
    collisions_table(&mut s, &["ball"], json!({"model": "unilateral", "friction": mu}));
    let c = collect(&load(&s, &urdf), "r");
    assert!(c.events.is_empty(), "no event: {:?}", c.events);
    assert!(c.samples.len() > 900);
    let f = m * gx;
    let a = f / (m + i / (r * r));
    assert!((a - 2.0 / 3.0 * gx).abs() < 1e-15);
    for o in &c.samples {
        let t = o.t;
        assert!((o.q[0] - 0.5 * a * t * t).abs() <= 1e-9, "t = {t}: x = {} m, ½ a t² = {} m", o.q[0], 0.5 * a * t * t);
        assert!((o.qd[0] - a * t).abs() <= 1e-9, "t = {t}: ẋ = {} m/s, a t = {}", o.qd[0], a * t);
        assert!((o.qd[0] - r * o.qd[3]).abs() <= 1e-9, "t = {t}: v = ω r: ẋ = {}, r θ̇ = {}", o.qd[0], r * o.qd[3]);
        assert!((o.q[1] - r).abs() <= 1e-9 && o.q[2].abs() <= 1e-9, "t = {t}: q = {:?}", o.q);
        for (k, fk) in o.contacts.iter().enumerate() {
            assert_eq!(fk.mode, ContactMode::Sticking, "t = {t}, rim {k}");
            // 1e-8: the two rims' identical rows go through the regularised singular set, which
            // drifts g̈ by ε f_n (see `ball_urdf`; measured |ġ| 1.0e-9 m/s at t = 0.68 s)
            assert!(fk.gap.abs() <= 1e-8 && fk.gap_rate.abs() <= 1e-8, "t = {t}, rim {k}: gap {} m, rate {} m/s", fk.gap, fk.gap_rate);
            assert!(fk.slip_velocity[0].abs() <= 1e-9 && fk.slip_velocity[1].abs() <= 1e-9, "t = {t}, rim {k}: slip {:?}", fk.slip_velocity);
            in_cone("disk on its rims", t, fk, mu);
        }
        let fn_sum: f64 = o.contacts.iter().map(|x| x.normal_force).sum();
        let ft_sum: f64 = o.contacts.iter().map(|x| x.friction_force[0]).sum();
        assert!((fn_sum - m * G).abs() <= 1e-9 * m * G, "t = {t}: Σ f_n = {fn_sum} N, m g = {} N", m * G);
        assert!((ft_sum + f / 3.0).abs() <= 1e-9 * m * G, "t = {t}: Σ f_t = {ft_sum} N, −F/3 = {} N", -f / 3.0);
        // relative to the work of the push, F x (6 J at t = 1 s); 1e-8: the two rims' rows are
        // the same rows, solved through the regularised singular set (measured 1.7e-9 J at
        // t = 0.345 s)
        assert!(o.balance_residual.abs() <= 1e-8 * (1.0 + f * o.q[0]), "t = {t}: balance residual {} J", o.balance_residual);
    }
}

/// A box (m = 1 kg, 0.2 × 0.1 × 0.05 m) from the URDF `<collision>`, held flat 5 cm above the
/// table and dropped: its 8 corners are point contacts; the bottom ones touch down together
/// with plastic impacts at `√(2 h0/g)` (1e-10 s) whose impulses sum to m √(2 g h0), the four
/// top ones stay separated with gap = the box's height; before, the fall is z = z0 − ½ g t²;
/// after, the box rests with its four bottom corners at gap 0 and Σ f_n = m g (each 1e-9).
/// (The corners that differ only in y have the same rows here, no roll joint: the event driver
/// logs the impact on one of each such pair — measured: corners 0 and 1 — so the test checks
/// the impulses' sum, not which corner of a redundant pair carries it.)
#[test]
fn a_box_dropped_flat_lands_on_its_four_bottom_corners_at_the_free_fall_time() {
    let (m, size, h0) = (1.0, [0.2, 0.1, 0.05], 0.05);
    let urdf = ball_urdf(m, 0.1).replace(
        r#"<link name="ball"><inertial>"#,
        &format!(r#"<link name="ball"><collision><geometry><box size="{} {} {}"/></geometry></collision><inertial>"#, size[0], size[1], size[2]),
    );
    let z0 = h0 + 0.5 * size[2];
    let mut s = passive_scene("ball", &["x", "z", "y", "pitch"], &[0.0, z0, 0.0, 0.0], &[0.0; 4], [0.0, 0.0, -G], 0.3, 1e-12);
    collisions_table(&mut s, &["ball"], json!({"model": "unilateral", "friction": 0.5}));
    let scene = load(&s, &urdf);
    let names: Vec<String> = scene.run_contact_models(scene.run("r").unwrap()).iter().map(|c| c.name().to_string()).collect();
    assert_eq!(names, (0..8).map(|j| format!("ball/c0/{j}")).collect::<Vec<_>>());
    let c = collect(&scene, "r");
    let t_land = (2.0 * h0 / G).sqrt();
    // corner j has z = ±size_z/2 by bit 2: the bottom ones are 0..4
    assert!(!c.events.is_empty(), "the box lands");
    let impulse: f64 = c.events.iter().map(|e| e.impulse).sum();
    assert!((impulse - m * (2.0 * G * h0).sqrt()).abs() <= 1e-9, "Σ impulses {impulse} N s, m √(2 g h0) = {}", m * (2.0 * G * h0).sqrt());
    for e in &c.events {
        assert_eq!(e.kind, ContactEventKind::Impact, "{e:?}");
        assert!(e.contact < 4, "only bottom corners land: {e:?}");
        assert!((e.t - t_land).abs() <= 1e-10, "corner {} lands at {} s, √(2 h0/g) = {t_land} s", e.contact, e.t);
    }
    for o in &c.samples {
        let t = o.t;
        for (k, f) in o.contacts.iter().enumerate() {
            if k >= 4 {
                assert_eq!(f.mode, ContactMode::Separated, "t = {t}, corner {k}");
                assert!((f.gap - (o.q[1] + 0.5 * size[2])).abs() <= 1e-12, "t = {t}, corner {k}: gap {}", f.gap);
            }
        }
        if t < t_land {
            assert!((o.q[1] - (z0 - 0.5 * G * t * t)).abs() <= 1e-9, "t = {t}: z = {}", o.q[1]);
            assert!(o.contacts.iter().all(|f| f.mode == ContactMode::Separated), "t = {t}");
        } else if t > t_land + 1e-9 {
            assert!((o.q[1] - 0.5 * size[2]).abs() <= 1e-9 && o.qd[1].abs() <= 1e-9, "t = {t}: at rest: z = {}, ż = {}", o.q[1], o.qd[1]);
            let fn_sum: f64 = o.contacts[..4].iter().map(|f| f.normal_force).sum();
            assert!((fn_sum - m * G).abs() <= 1e-9 * m * G, "t = {t}: Σ f_n = {fn_sum} N");
            for f in &o.contacts[..4] {
                assert!(f.gap.abs() <= 1e-9 && f.normal_force >= -1e-9, "t = {t}: {f:?}");
            }
            assert!(o.contacts[..4].iter().filter(|f| touching(f.mode)).count() >= 2, "t = {t}: rests on its bottom corners");
        }
    }
}

/// `table.from_collisions`: a collision sphere becomes a sphere contact at its centre; the
/// field and `table.cylinders` are validated once, naming the file, the field, the value and
/// the links without shapes; a cylinder standing on its face is refused.
#[test]
fn collision_shapes_on_the_table_are_validated_naming_the_field_the_value_and_the_links() {
    let err = |s: &Value, urdf: &str| try_load(s, urdf).map(|_| ()).unwrap_err().to_string();
    let (m, h, r) = (1.0, 0.3, 0.05);
    let urdf = cylinder_rod(m, h, r);
    let mut ok = passive_scene("rod", &["x", "z", "pitch"], &[0.0, r, 0.0], &[0.0; 3], [0.0, 0.0, -G], 0.1, 1e-12);
    collisions_table(&mut ok, &["rod"], json!({"model": "unilateral"}));
    assert!(try_load(&ok, &urdf).is_ok());
    // cylinders as a capsule: two end spheres (touching at z_c − r with the rod flat)
    let mut s = ok.clone();
    s["table"]["cylinders"] = json!("capsule");
    let scene = load(&s, &urdf);
    let names: Vec<String> = scene.run_contact_models(scene.run("r").unwrap()).iter().map(|c| c.name().to_string()).collect();
    assert_eq!(names, ["rod/c0/0", "rod/c0/1"]);
    let mut s = ok.clone();
    s["table"]["cylinders"] = json!("discs");
    let e = err(&s, &urdf);
    assert!(e.contains("contact-test.json") && e.contains("table.cylinders") && e.contains("discs") && e.contains("rims"), "{e}");
    let mut s = ok.clone();
    s["table"]["from_collisions"] = json!(["rod", "cz", "cx"]);
    let e = err(&s, &urdf);
    assert!(e.contains("table.from_collisions") && e.contains("cz (no <collision>)") && e.contains("cx (no <collision>)") && !e.contains("rod ("), "{e}");
    let mesh = urdf.replace(r#"<cylinder radius="0.05" length="0.6"/>"#, r#"<mesh filename="rod.stl"/>"#);
    assert_ne!(mesh, urdf);
    let e = err(&ok, &mesh);
    assert!(e.contains("table.from_collisions") && e.contains("rod (1 <collision> of meshes only)"), "{e}");
    let mut s = ok.clone();
    s["table"]["from_collisions"] = json!(["nope"]);
    let e = err(&s, &urdf);
    assert!(e.contains("table.from_collisions[0]") && e.contains("nope") && e.contains("no such link"), "{e}");
    let mut s = ok.clone();
    s["table"]["from_collisions"] = json!(["rod", "rod"]);
    let e = err(&s, &urdf);
    assert!(e.contains("table.from_collisions[1]") && e.contains("twice"), "{e}");
    let mut s = ok.clone();
    s["table"]["model"] = json!("bilateral");
    let e = err(&s, &urdf);
    assert!(e.contains("table.from_collisions") && e.contains("bilateral"), "{e}");
    // a cylinder that starts inside the table: its rims are r below the centre
    let mut s = ok.clone();
    s["initial"]["q"][1] = json!(0.03);
    let e = err(&s, &urdf);
    assert!(e.contains("table.from_collisions[0]") && e.contains("rod/c0/0") && e.contains("rim starts inside the plane"), "{e}");
    // standing on its face (axis along the normal): refused at the start
    let mut s = ok.clone();
    s["initial"]["q"][1] = json!(h);
    s["initial"]["q"][2] = json!(-std::f64::consts::FRAC_PI_2);
    let e = err(&s, &urdf);
    assert!(e.contains("rod/c0/0") && e.contains("stands on its face") && e.contains("0.000°"), "{e}");
    // a bad collision in the URDF names its line
    let bad = urdf.replace(r#"radius="0.05""#, r#"radius="-1""#);
    let e = err(&ok, &bad);
    assert!(e.contains("radius=\"-1\"") && e.contains("positive length"), "{e}");
    // a collision sphere: a sphere contact at its centre (offset in the link)
    let ball = ball_urdf(1.0, 0.1).replace(
        r#"<link name="ball"><inertial>"#,
        r#"<link name="ball"><collision><origin xyz="0 0 -0.02"/><geometry><sphere radius="0.08"/></geometry></collision><inertial>"#,
    );
    let mut s = passive_scene("ball", &["x", "z", "y", "pitch"], &[0.0, 0.1, 0.0, 0.0], &[0.0; 4], [0.0, 0.0, -G], 0.2, 1e-12);
    collisions_table(&mut s, &["ball"], json!({"model": "unilateral"}));
    let c = collect(&load(&s, &ball), "r");
    assert!(c.events.is_empty(), "resting on its sphere: {:?}", c.events);
    for o in &c.samples {
        let f = &o.contacts[0];
        assert!(f.gap.abs() <= 1e-9 && (o.q[1] - 0.1).abs() <= 1e-9 && (f.normal_force - G).abs() <= 1e-9 * G, "t = {}: {f:?}", o.t);
    }
}
