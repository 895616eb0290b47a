//! Claims checked against computations written by hand in this file, independent of the
//! simulator's own algorithms (issue 29, item 6):
//!
//! - the general IK's posture term: on a redundant 4-DoF arm (yaw, then three pitch joints) the
//!   solution nearest the posture is found by brute force over the one-dimensional null space
//!   (the self-motion, parametrised by the last link's pitch, with the planar 2-link IK in
//!   closed form; Siciliano et al., *Robotics*, §2.12) and compared with `GeneralIk::solve`;
//! - `<mimic>` joints with multiplier ≠ 1 and offset ≠ 0 (URDF spec: `q_follower = multiplier ·
//!   q_leader + offset`) against the closed-form forward kinematics of the locked arm;
//! - PD + gravity on a moving target and computed torque against the closed-form dynamics of a
//!   planar two-link arm (Spong, Hutchinson & Vidyasagar, *Robot Modeling and Control*, §7.4.2:
//!   M(q), the Coriolis terms and G(q) of the two-link arm), not the plant's RNEA, so an error
//!   the plant and the controller would share (a sign in `rnea`) cannot hide.

#![allow(clippy::needless_range_loop)] // per-joint arrays indexed together

use std::collections::BTreeMap;

use nalgebra::{DVector, Vector3};
use sim::control::general_ik::GeneralIk;
use sim::control::{ControlInput, Controller, ControllerScratch, Law, PdGains};
use sim::dynamics::kinematics::{body_point, forward_kinematics};
use sim::dynamics::model::UrdfOptions;
use sim::dynamics::motor::{Drives, Electrical};
use sim::dynamics::{Data, Model};

const G: f64 = 9.81;

// ---------------------------------------------------------------------------------------------
// the general IK's posture term

/// Link lengths of the redundant arm, m.
const L: [f64; 3] = [0.5, 0.4, 0.3];

/// Yaw about z at the base, then three pitch joints about y, links along z at q = 0, the hand
/// `L[2]` beyond the last joint.
fn redundant_arm() -> Model {
    let link = |n: &str| {
        format!("<link name=\"{n}\"><inertial><mass value=\"1\"/><origin xyz=\"0 0 0.1\"/><inertia ixx=\"0.01\" iyy=\"0.01\" izz=\"0.01\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link>")
    };
    let joint = |n: &str, p: &str, c: &str, z: f64, axis: &str| {
        format!("<joint name=\"{n}\" type=\"continuous\"><parent link=\"{p}\"/><child link=\"{c}\"/><origin xyz=\"0 0 {z}\"/><axis xyz=\"{axis}\"/></joint>")
    };
    let xml = format!(
        "<robot name=\"r4\"><link name=\"base\"/>{}{}{}{}{}{}{}{}{}<link name=\"hand\"/><joint name=\"jh\" type=\"fixed\"><parent link=\"l4\"/><child link=\"hand\"/><origin xyz=\"0 0 {}\"/></joint></robot>",
        link("l1"),
        joint("yaw", "base", "l1", 0.0, "0 0 1"),
        link("l2"),
        joint("p1", "l1", "l2", 0.0, "0 1 0"),
        link("l3"),
        joint("p2", "l2", "l3", L[0], "0 1 0"),
        link("l4"),
        joint("p3", "l3", "l4", L[1], "0 1 0"),
        "",
        L[2]
    );
    Model::from_urdf(&xml, "r4.urdf", Vector3::new(0.0, 0.0, -G)).unwrap()
}

/// The hand of the redundant arm in closed form: a pitch θ about y turns (0, 0, l) into
/// (l sin θ, 0, l cos θ), the yaw turns the plane about z.
fn hand_closed_form(q: &[f64]) -> Vector3<f64> {
    let (a1, a2, a3) = (q[1], q[1] + q[2], q[1] + q[2] + q[3]);
    let r = L[0] * a1.sin() + L[1] * a2.sin() + L[2] * a3.sin();
    let z = L[0] * a1.cos() + L[1] * a2.cos() + L[2] * a3.cos();
    Vector3::new(r * q[0].cos(), r * q[0].sin(), z)
}

/// `x − p` wrapped into (−π, π]: a joint angle and the same angle plus 2π are one pose.
fn wrap(x: f64, p: f64) -> f64 {
    let d = (x - p).rem_euclid(std::f64::consts::TAU);
    if d > std::f64::consts::PI {
        d - std::f64::consts::TAU
    } else {
        d
    }
}

/// The arm's joint angles reaching `target` with the last link at absolute pitch `phi`, yaw
/// branch `flip` (the plane turned by π and the reach negative) and elbow branch `elbow`, each
/// angle taken nearest the posture; `None` where the wrist is out of the two links' reach.
fn on_the_self_motion(target: &Vector3<f64>, phi: f64, flip: bool, elbow: f64, post: &[f64]) -> Option<[f64; 4]> {
    let rho = target.x.hypot(target.y);
    let (yaw, r) = if flip { (target.y.atan2(target.x) + std::f64::consts::PI, -rho) } else { (target.y.atan2(target.x), rho) };
    // the wrist: the target minus the last link, in the arm's plane (r, z)
    let (wr, wz) = (r - L[2] * phi.sin(), target.z - L[2] * phi.cos());
    let c = (wr * wr + wz * wz - L[0] * L[0] - L[1] * L[1]) / (2.0 * L[0] * L[1]);
    if !(-1.0..=1.0).contains(&c) {
        return None;
    }
    let q2 = elbow * c.acos();
    let q1 = wr.atan2(wz) - (L[1] * q2.sin()).atan2(L[0] + L[1] * q2.cos());
    let q = [yaw, q1, q2, phi - q1 - q2];
    Some(std::array::from_fn(|j| post[j] + wrap(q[j], post[j])))
}

/// ½ |q − q_post|² at the self-motion point `phi` (+∞ off the reach).
fn posture_cost(target: &Vector3<f64>, phi: f64, flip: bool, elbow: f64, post: &[f64]) -> f64 {
    on_the_self_motion(target, phi, flip, elbow, post).map_or(f64::INFINITY, |q| 0.5 * q.iter().zip(post).map(|(a, b)| (a - b).powi(2)).sum::<f64>())
}

/// The solution nearest the posture by brute force: every branch on a grid of 100 000 pitches
/// of the last link, then the minimum refined by bisection on the cost's derivative (central
/// differences, h = 1e-5 rad: truncation h² f‴/6 and rounding ε f / h both ~1e-11, so the
/// pitch is found to ~1e-10 rad).
fn brute_force(target: &Vector3<f64>, post: &[f64]) -> [f64; 4] {
    let n = 100_000;
    let mut best = (f64::INFINITY, 0.0, false, 1.0);
    for flip in [false, true] {
        for elbow in [1.0, -1.0] {
            for k in 0..n {
                let phi = -std::f64::consts::PI + std::f64::consts::TAU * k as f64 / n as f64;
                let f = posture_cost(target, phi, flip, elbow, post);
                if f < best.0 {
                    best = (f, phi, flip, elbow);
                }
            }
        }
    }
    let (_, phi, flip, elbow) = best;
    let h = 1e-5;
    let slope = |p: f64| (posture_cost(target, p + h, flip, elbow, post) - posture_cost(target, p - h, flip, elbow, post)) / (2.0 * h);
    let step = std::f64::consts::TAU / n as f64;
    let (mut lo, mut hi) = (phi - step, phi + step);
    assert!(slope(lo) < 0.0 && slope(hi) > 0.0, "the grid's minimum is not bracketed");
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if slope(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    on_the_self_motion(target, 0.5 * (lo + hi), flip, elbow, post).unwrap()
}

/// The general IK's null-space posture term: on a redundant arm (4 joints, a 3-D position task,
/// a one-dimensional self-motion) started from a solution that is NOT the nearest to the
/// posture, the IK must slide along the self-motion to the solution nearest the posture, which
/// a brute-force search over the whole self-motion (both yaw and both elbow branches) finds
/// independently: the joint angles agree to 1e-8 rad (the brute force's ~1e-10 rad, the IK's
/// stationarity 1e-10 rad times the conditioning). The start solves the task already, so an IK
/// without the posture term does not move and misses by ~0.3 rad. Three targets and postures.
#[test]
fn general_ik_finds_the_solution_nearest_the_posture_found_by_brute_force() {
    let model = redundant_arm();
    let hand = body_point(&model, "hand", Vector3::zeros()).unwrap();
    let mut data = Data::new(&model);
    for (q_start, shift) in [
        ([0.3, 0.4, 0.8, 0.6], [0.2, -0.4, 0.3, 0.5]),
        ([-1.0, -0.5, 1.2, -0.3], [0.0, 0.5, -0.2, 0.6]),
        ([2.0, 0.9, -1.1, 1.4], [-0.3, -0.3, -0.3, -0.3]),
    ] {
        // the closed form is the model's forward kinematics (1e-14 m: rounding)
        forward_kinematics(&model, &mut data, &q_start);
        let target = hand.position(&data);
        assert!((target - hand_closed_form(&q_start)).norm() < 1e-14, "{target} vs {}", hand_closed_form(&q_start));
        let posture: Vec<f64> = q_start.iter().zip(shift).map(|(q, s)| q + s).collect();
        let expected = brute_force(&target, &posture);
        assert!((hand_closed_form(&expected) - target).norm() < 1e-12, "the brute force's solution misses the target");
        let moved = q_start.iter().zip(&expected).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(moved > 0.05, "the start is already (nearly) the optimum: the case tests nothing ({moved} rad)");

        let ik = GeneralIk { hand, orientation: None, contacts: vec![], active: vec![true; 4], posture: posture.clone() };
        let mut s = ik.scratch(&model);
        let mut q = q_start.to_vec();
        let st = ik.solve(&model, &mut s, &target, &mut q).unwrap_or_else(|e| panic!("{q_start:?}: {e:?}"));
        let miss = q.iter().zip(&expected).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(miss <= 1e-8, "{q_start:?}: the IK ends at {q:?}, the posture's nearest solution is {expected:?} ({miss:e} rad; {st:?})");
        assert!(st.residual <= 1e-12 && st.stationarity <= 1e-10, "{st:?}");
    }
}

// ---------------------------------------------------------------------------------------------
// mimic joints

/// A movable pitch joint `s` at the base, then a chain whose joints are locked: the leader `a`
/// (revolute about z), `b` (revolute about z, 0.5 m out) mimicking `a` with multiplier −0.5 and
/// offset 0.1 rad, `c` (prismatic along x, 0.4 m out) mimicking `a` with multiplier 2 m/rad and
/// offset −0.05 m; the hand 0.3 m beyond `c`.
const MIMIC_ARM: &str = r#"<robot name="mimic">
  <link name="base"/>
  <link name="s_link"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="a_link"><inertial><mass value="1"/><origin xyz="0.2 0 0"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="b_link"><inertial><mass value="0.5"/><origin xyz="0.1 0 0"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="c_link"><inertial><mass value="0.2"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="hand"/>
  <joint name="s" type="continuous"><parent link="base"/><child link="s_link"/><axis xyz="0 1 0"/></joint>
  <joint name="a" type="revolute"><parent link="s_link"/><child link="a_link"/><axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="b" type="revolute"><parent link="a_link"/><child link="b_link"/><origin xyz="0.5 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/><mimic joint="a" multiplier="-0.5" offset="0.1"/></joint>
  <joint name="c" type="prismatic"><parent link="b_link"/><child link="c_link"/><origin xyz="0.4 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="2" effort="1" velocity="1"/><mimic joint="a" multiplier="2" offset="-0.05"/></joint>
  <joint name="h" type="fixed"><parent link="c_link"/><child link="hand"/><origin xyz="0.3 0 0"/></joint>
</robot>"#;

/// Mimic joints with multiplier ≠ 1 and offset ≠ 0: locking the leader `a` at v locks `b` at
/// −0.5 v + 0.1 rad and `c` at 2 v − 0.05 m, and the hand is where the closed form puts it:
/// `Ry(q_s) [0.5 u(v) + (0.4 + d + 0.3) u(v + θ_b)]`, u(θ) = (cos θ, sin θ, 0), to 1e-14 m
/// (rounding of a few products on lengths ~1.5 m). Four leader values, two angles of the moving joint.
#[test]
fn mimic_joints_with_a_multiplier_and_an_offset_follow_the_closed_form() {
    for v in [0.7, -0.3, 0.0, 0.45] {
        let options = UrdfOptions { locked: BTreeMap::from([("a".to_string(), v)]), ..Default::default() };
        let model = Model::from_urdf_with(MIMIC_ARM, "mimic.urdf", Vector3::new(0.0, 0.0, -G), &options).unwrap();
        assert_eq!(model.joint_names(), ["s"]);
        let (theta_b, d) = (-0.5 * v + 0.1, 2.0 * v - 0.05);
        let hand = body_point(&model, "hand", Vector3::zeros()).unwrap();
        let mut data = Data::new(&model);
        for qs in [0.0, 0.8] {
            forward_kinematics(&model, &mut data, &[qs]);
            let u = |t: f64| Vector3::new(t.cos(), t.sin(), 0.0);
            let flat = 0.5 * u(v) + (0.4 + d + 0.3) * u(v + theta_b);
            let expected = nalgebra::Rotation3::from_axis_angle(&Vector3::y_axis(), qs) * flat;
            let got = hand.position(&data);
            assert!((got - expected).norm() <= 1e-14, "v = {v}, q_s = {qs}: hand {got} vs {expected}");
        }
    }
}

// ---------------------------------------------------------------------------------------------
// the controllers against a two-link arm by hand

/// Masses, COM distances along the link, inertias about the COM (axis y), link 1's length.
const M1: f64 = 2.0;
const M2: f64 = 1.3;
const C1: f64 = 0.25;
const C2: f64 = 0.18;
const I1: f64 = 0.04;
const I2: f64 = 0.015;
const L1: f64 = 0.5;

/// A planar two-link arm in the vertical x-z plane: both joints about y, links along z at q = 0.
fn two_link() -> Model {
    let xml = format!(
        r#"<robot name="two"><link name="base"/>
  <link name="l1"><inertial><origin xyz="0 0 {C1}"/><mass value="{M1}"/><inertia ixx="{I1}" iyy="{I1}" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="l2"><inertial><origin xyz="0 0 {C2}"/><mass value="{M2}"/><inertia ixx="{I2}" iyy="{I2}" izz="0.005" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j1" type="continuous"><parent link="base"/><child link="l1"/><axis xyz="0 1 0"/></joint>
  <joint name="j2" type="continuous"><parent link="l1"/><child link="l2"/><origin xyz="0 0 {L1}"/><axis xyz="0 1 0"/></joint>
</robot>"#
    );
    Model::from_urdf(&xml, "two.urdf", Vector3::new(0.0, 0.0, -G)).unwrap()
}

/// M(q), the Coriolis/centrifugal torques C(q, q̇) q̇ and G(q) of the two-link arm, from its
/// Lagrangian (Spong et al. §7.4.2, with the angles measured from the vertical: the potential
/// is g [m₁ c₁ cos q₁ + m₂ (L₁ cos q₁ + c₂ cos(q₁ + q₂))]).
fn two_link_by_hand(q: &[f64], qd: &[f64]) -> ([[f64; 2]; 2], [f64; 2], [f64; 2]) {
    let (c2, s2) = (q[1].cos(), q[1].sin());
    let m11 = I1 + I2 + M1 * C1 * C1 + M2 * (L1 * L1 + C2 * C2 + 2.0 * L1 * C2 * c2);
    let m12 = I2 + M2 * (C2 * C2 + L1 * C2 * c2);
    let m22 = I2 + M2 * C2 * C2;
    let h = M2 * L1 * C2 * s2;
    let cor = [-h * (2.0 * qd[0] * qd[1] + qd[1] * qd[1]), h * qd[0] * qd[0]];
    let s12 = (q[0] + q[1]).sin();
    let grav = [-G * ((M1 * C1 + M2 * L1) * q[0].sin() + M2 * C2 * s12), -G * M2 * C2 * s12];
    ([[m11, m12], [m12, m22]], cor, grav)
}

/// Drives with every constant distinct (K_e ≠ K_m, D and D_m non-zero), link side.
fn drives() -> Drives {
    let v = |a: f64, b: f64| DVector::from_vec(vec![a, b]);
    Drives {
        km: v(2.4, 1.1),
        ke: v(1.9, 1.6),
        voltage_limit: vec![f64::INFINITY; 2],
        current_limit: vec![f64::INFINITY; 2],
        passive: vec![false; 2],
        has_limits: false,
        has_conversion: true,
        r: v(1.3, 0.7),
        l: v(2e-3, 1e-3),
        jm: v(0.03, 0.02),
        dm: v(0.05, 0.12),
        d: v(0.4, 0.25),
        electrical: Electrical::Inductive,
        has_friction: true,
    }
}

/// Measured and desired states of a moving target (rad, rad/s, rad/s²) and currents (A).
struct Moment {
    q: [f64; 2],
    qd: [f64; 2],
    q_des: [f64; 2],
    qd_des: [f64; 2],
    qdd_des: [f64; 2],
    i: [f64; 2],
}

fn moments() -> Vec<Moment> {
    vec![
        Moment { q: [0.4, -0.9], qd: [0.7, -1.2], q_des: [0.45, -0.85], qd_des: [0.9, -1.5], qdd_des: [-2.0, 3.0], i: [0.8, -0.3] },
        Moment { q: [-1.2, 2.1], qd: [-0.4, 2.5], q_des: [-1.1, 2.0], qd_des: [-0.6, 2.2], qdd_des: [1.5, -0.7], i: [-1.1, 0.6] },
        Moment { q: [2.5, 0.3], qd: [1.9, 0.2], q_des: [2.45, 0.35], qd_des: [2.1, -0.4], qdd_des: [0.3, 4.0], i: [0.1, 2.0] },
    ]
}

fn voltage(controller: &Controller, model: &Model, d: &Drives, x: &Moment, current: bool) -> [f64; 2] {
    let mut data = Data::new(model);
    let mut scratch = ControllerScratch::new(2);
    let mut v = [0.0; 2];
    let input = ControlInput { q: &x.q, qd: &x.qd, current: current.then_some(&x.i[..]), q_des: &x.q_des, qd_des: &x.qd_des, qdd_des: &x.qdd_des };
    controller.voltage(model, d, &mut data, &mut scratch, &input, &mut v);
    v
}

const KP: [f64; 2] = [120.0, 80.0];
const KD: [f64; 2] = [9.0, 6.5];

fn gains() -> PdGains {
    PdGains { kp: DVector::from_vec(KP.to_vec()), kd: DVector::from_vec(KD.to_vec()) }
}

/// PD + gravity on a moving target (q̇_d ≠ 0), with and without `friction`, against the law
/// computed by hand: `v = k_p e + k_d ė + (R / K_m)(G(q) + [D + D_m] q̇_d) + K_e q̇_d` with the
/// two-link G(q) by hand, to 1e-12 of the voltage (rounding: the same law, different
/// arithmetic). The back-EMF and friction feed-forwards are each ~1–4 V here, so dropping
/// either misses by far more.
#[test]
fn pd_gravity_on_a_moving_target_is_the_law_computed_by_hand() {
    let model = two_link();
    let d = drives();
    for friction in [true, false] {
        let controller = Controller { law: Law::PdGravity { friction }, gains: gains() };
        for x in moments() {
            let (_, _, grav) = two_link_by_hand(&x.q, &x.qd);
            let got = voltage(&controller, &model, &d, &x, false);
            for j in 0..2 {
                let pd = KP[j] * (x.q_des[j] - x.q[j]) + KD[j] * (x.qd_des[j] - x.qd[j]);
                let fric = if friction { (d.d[j] + d.dm[j]) * x.qd_des[j] } else { 0.0 };
                let expected = pd + d.r[j] / d.km[j] * (grav[j] + fric) + d.ke[j] * x.qd_des[j];
                assert!((got[j] - expected).abs() <= 1e-12 * expected.abs().max(1.0), "friction {friction}, joint {j}: {} V vs {expected} V by hand", got[j]);
            }
        }
    }
}

/// Computed torque against the two-link arm's dynamics by hand (not the plant's RNEA):
/// `a = q̈_d + k_p e + k_d ė`, `τ* = (M + J_m) a + C q̇ + G + (D + D_m) q̇`, `i* = τ*/K_m`,
/// `v = R i* + K_e q̇ + k_i (i* − i)` (inductive motors, current read) and without the current
/// loop, to 1e-12 of the voltage.
#[test]
fn computed_torque_is_the_two_link_dynamics_computed_by_hand() {
    let model = two_link();
    let d = drives();
    let ki = [3.0, 5.0];
    let controller = Controller { law: Law::ComputedTorque { current_gain: DVector::from_vec(ki.to_vec()) }, gains: gains() };
    for x in moments() {
        let (m, cor, grav) = two_link_by_hand(&x.q, &x.qd);
        let a: [f64; 2] = std::array::from_fn(|j| x.qdd_des[j] + KP[j] * (x.q_des[j] - x.q[j]) + KD[j] * (x.qd_des[j] - x.qd[j]));
        for current in [true, false] {
            let got = voltage(&controller, &model, &d, &x, current);
            for j in 0..2 {
                let tau = m[j][0] * a[0] + m[j][1] * a[1] + d.jm[j] * a[j] + cor[j] + grav[j] + (d.d[j] + d.dm[j]) * x.qd[j];
                let i_star = tau / d.km[j];
                let loop_term = if current { ki[j] * (i_star - x.i[j]) } else { 0.0 };
                let expected = d.r[j] * i_star + d.ke[j] * x.qd[j] + loop_term;
                assert!((got[j] - expected).abs() <= 1e-12 * expected.abs().max(1.0), "current loop {current}, joint {j}: {} V vs {expected} V by hand", got[j]);
            }
        }
    }
}
