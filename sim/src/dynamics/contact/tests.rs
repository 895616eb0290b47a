//! Unit tests of the contact dynamics on small models: a point mass (3 prismatic joints x, y,
//! z), a 2-link arm, and a rod on a table (Painlevé's example). Tolerances are stated per test.

use nalgebra::{DVector, Unit, Vector3};

use super::forward::{forward_dynamics_contacts, prepare, solve_modes, ContactData, ContactState};
use super::impact::solve_impact;
use super::modes::choose_modes;
use super::rows::{contact_rows, ContactRows};
use super::{Contact, ContactMode, ContactModel};
use crate::dynamics::constraints::PointOnPlane;
use crate::dynamics::data::Data;
use crate::dynamics::forward::{forward_dynamics, ForwardData, Plant};
use crate::dynamics::kinematics::{body_point, forward_kinematics, forward_velocities, BodyPoint};
use crate::dynamics::model::Model;
use crate::dynamics::motor::{Drives, MotorParams};
use crate::dynamics::samples::{random_chain, SplitMix64};
use crate::error::DynamicsError;

const G: f64 = 9.81;

fn link(name: &str, mass: f64, inertia: [f64; 3]) -> String {
    if mass == 0.0 {
        return format!(r#"<link name="{name}"/>"#);
    }
    format!(
        r#"<link name="{name}"><inertial><origin xyz="0 0 0"/><mass value="{mass}"/><inertia ixx="{}" ixy="0" ixz="0" iyy="{}" iyz="0" izz="{}"/></inertial></link>"#,
        inertia[0], inertia[1], inertia[2]
    )
}

fn joint(name: &str, kind: &str, parent: &str, child: &str, axis: &str) -> String {
    format!(r#"<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/><axis xyz="{axis}"/><limit lower="-100" upper="100" effort="1" velocity="1"/></joint>"#)
}

/// A point mass m: joints x, y, z (prismatic), the mass on link `ball`.
fn point_mass(m: f64) -> Model {
    let xml = format!(
        r#"<robot name="pm">{}{}{}{}{}{}{}</robot>"#,
        link("base", 0.0, [0.0; 3]),
        link("lx", 0.0, [0.0; 3]),
        link("ly", 0.0, [0.0; 3]),
        link("ball", m, [1e-3; 3]),
        joint("x", "prismatic", "base", "lx", "1 0 0"),
        joint("y", "prismatic", "lx", "ly", "0 1 0"),
        joint("z", "prismatic", "ly", "ball", "0 0 1"),
    );
    Model::from_urdf(&xml, "pm.urdf", Vector3::new(0.0, 0.0, -G)).expect("point mass URDF")
}

/// A uniform rod of mass m and half-length l in the x-z plane: joints x, z (prismatic) and
/// theta (revolute about −y, so the rod's axis is (cos θ, 0, sin θ)).
fn rod(m: f64, l: f64) -> Model {
    let i = m * l * l / 3.0;
    let xml = format!(
        r#"<robot name="rod">{}{}{}{}{}{}{}</robot>"#,
        link("base", 0.0, [0.0; 3]),
        link("lx", 0.0, [0.0; 3]),
        link("lz", 0.0, [0.0; 3]),
        link("rod", m, [1e-6, i, i]),
        joint("x", "prismatic", "base", "lx", "1 0 0"),
        joint("z", "prismatic", "lx", "lz", "0 0 1"),
        joint("theta", "continuous", "lz", "rod", "0 -1 0"),
    );
    Model::from_urdf(&xml, "rod.urdf", Vector3::new(0.0, 0.0, -G)).expect("rod URDF")
}

/// Motors with K_m = 1 N m/A (or N/A), no rotor, no friction: the current is the joint force.
fn force_drives(nv: usize) -> Drives {
    let m = MotorParams { torque_constant: 1.0, resistance: 1.0, inductance: 0.0, rotor_inertia: 0.0, gear_ratio: 1.0, gear_damping: 0.0 };
    Drives::new(&vec![m; nv], &vec![0.0; nv])
}

fn table(model: &Model, link: &str, offset: Vector3<f64>, name: &str, cm: ContactModel) -> Contact {
    let point = body_point(model, link, offset).expect("link");
    Contact::new(PointOnPlane { name: name.into(), point, normal_world: Unit::new_normalize(Vector3::z()), offset: 0.0 }, cm)
}

fn plant<'a>(model: &'a Model, drives: &'a Drives) -> Plant<'a> {
    Plant { model, drives, contacts: &[], mass_matrix: Default::default(), solver: Default::default(), stabilization: Default::default() }
}

/// The rows against central differences of the kinematics (step 1e-6, tolerance 1e-7
/// absolute on O(1) quantities: truncation O(h²) ~ 1e-12, rounding ~ 1e-10/h... ≤ 1e-9):
/// `J_n, J_t` = ∂(n·p, t·p)/∂q, the velocities = J q̇, and the biases `J̇ q̇` = d/dt(J q̇) along
/// the motion at q̈ = 0, on a random 5-joint chain with a tilted plane.
#[test]
fn rows_match_finite_differences() {
    let model = random_chain(5, 77);
    let nv = model.nv;
    let mut rng = SplitMix64(5);
    let plane = PointOnPlane {
        name: "c".into(),
        point: BodyPoint { body: Some(nv - 1), p_body: Vector3::new(0.1, -0.05, 0.2) },
        normal_world: Unit::new_normalize(Vector3::new(0.3, -0.2, 1.0)),
        offset: 0.1,
    };
    let contacts = [Contact::new(plane, ContactModel::Unilateral { restitution: 0.0, friction: 0.5 })];
    let q: Vec<f64> = rng.vector(nv, -1.5, 1.5).iter().copied().collect();
    let qd: Vec<f64> = rng.vector(nv, -1.0, 1.0).iter().copied().collect();
    let mut data = Data::new(&model);
    let mut rows = ContactRows::new(nv, 1);
    let eval = |data: &mut Data, rows: &mut ContactRows, q: &[f64], qd: &[f64]| {
        forward_kinematics(&model, data, q);
        forward_velocities(&model, data, qd);
        contact_rows(&model, data, &contacts, rows);
        let p = contacts[0].plane.point.position(data);
        (rows.gap[0], contacts[0].t1.dot(&p), contacts[0].t2.dot(&p), rows.vel.clone())
    };
    let (_, _, _, vel) = eval(&mut data, &mut rows, &q, &qd);
    let r0 = rows.clone();
    let h = 1e-6;
    for j in 0..nv {
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[j] += h;
        qm[j] -= h;
        let (gp, t1p, t2p, _) = eval(&mut data, &mut rows, &qp, &qd);
        let (gm, t1m, t2m, _) = eval(&mut data, &mut rows, &qm, &qd);
        for (axis, d) in [(gp - gm) / (2.0 * h), (t1p - t1m) / (2.0 * h), (t2p - t2m) / (2.0 * h)].iter().enumerate() {
            let e = (r0.row(axis)[j] - d).abs();
            assert!(e <= 1e-7, "J[{axis}][{j}] = {} vs finite difference {d}: {e:e}", r0.row(axis)[j]);
        }
    }
    for axis in 0..3 {
        let e = (r0.dot(axis, &qd) - vel[axis]).abs();
        assert!(e <= 1e-12, "velocity {axis}: J q̇ vs the point's velocity: {e:e}");
    }
    // J̇ q̇ = d/dt (J(q) q̇) at fixed q̇ along q̇
    let qp: Vec<f64> = q.iter().zip(&qd).map(|(a, b)| a + h * b).collect();
    let qm: Vec<f64> = q.iter().zip(&qd).map(|(a, b)| a - h * b).collect();
    let (_, _, _, vp) = eval(&mut data, &mut rows, &qp, &qd);
    let (_, _, _, vm) = eval(&mut data, &mut rows, &qm, &qd);
    for axis in 0..3 {
        let d = (vp[axis] - vm[axis]) / (2.0 * h);
        let e = (r0.bias[axis] - d).abs();
        assert!(e <= 1e-7, "bias {axis}: {} vs finite difference {d}: {e:e}", r0.bias[axis]);
    }
}

/// With only normal rows (bilateral contacts, or unilateral ones closed and frictionless), the
/// active-row path gives today's bilateral forward dynamics (`forward_dynamics` with
/// `PointOnPlane` rows, Schur): q̈ and f_n to 1e-12 relative, on random chains with 2 contacts.
#[test]
fn normal_rows_equal_the_bilateral_path() {
    for (n, seed) in [(4usize, 1u64), (7, 2), (10, 3)] {
        let model = random_chain(n, 300 + seed);
        let m = MotorParams { torque_constant: 0.2, resistance: 1.1, inductance: 0.0017, rotor_inertia: 1.6e-4, gear_ratio: 3.0, gear_damping: 0.01 };
        let drives = Drives::new(&vec![m; n], &vec![0.5; n]);
        let mut rng = SplitMix64(40 + seed);
        let planes: Vec<PointOnPlane> = (0..2)
            .map(|k| PointOnPlane {
                name: format!("c{k}"),
                point: BodyPoint { body: Some(n / 2 + k * (n / 2 - 1)), p_body: Vector3::new(0.0, 0.0, 0.1) },
                normal_world: Unit::new_normalize(rng.unit_vector()),
                offset: 0.0,
            })
            .collect();
        let q: Vec<f64> = rng.vector(n, -2.0, 2.0).iter().copied().collect();
        let qd: Vec<f64> = rng.vector(n, -1.0, 1.0).iter().copied().collect();
        let cur: Vec<f64> = rng.vector(n, -3.0, 3.0).iter().copied().collect();
        let volt: Vec<f64> = rng.vector(n, -10.0, 10.0).iter().copied().collect();
        let mut data = Data::new(&model);
        let p = Plant { model: &model, drives: &drives, contacts: &planes, mass_matrix: Default::default(), solver: Default::default(), stabilization: Default::default() };
        let mut fd0 = ForwardData::new(n, 2);
        forward_dynamics(&p, &mut data, &mut fd0, 0.0, &q, &qd, &cur, &volt).expect("bilateral");
        for models in [[ContactModel::Bilateral; 2], [ContactModel::Unilateral { restitution: 0.0, friction: 0.0 }; 2]] {
            let contacts: Vec<Contact> = planes.iter().zip(models).map(|(pl, m)| Contact::new(pl.clone(), m)).collect();
            let mut state = ContactState::new(&contacts);
            for (k, c) in contacts.iter().enumerate() {
                if c.model != ContactModel::Bilateral {
                    state.mode[k] = ContactMode::Sliding;
                }
            }
            let mut fd = ForwardData::new(n, 2);
            let mut cd = ContactData::new(n, 2);
            forward_dynamics_contacts(&plant(&model, &drives), &contacts, &state, &mut data, &mut fd, &mut cd, 0.0, &q, &qd, &cur, &volt).expect("active rows");
            let scale = fd0.qdd.amax().max(1.0);
            let dq = (&fd.qdd - &fd0.qdd).amax() / scale;
            let df = (0..2).map(|k| (cd.f_n[k] - fd0.f_n[k]).abs()).fold(0.0, f64::max) / fd0.f_n.amax().max(1.0);
            assert!(dq <= 1e-12 && df <= 1e-12, "n = {n} {models:?}: q̈ differs by {dq:e}, f_n by {df:e} (relative)");
            assert!((&fd.di - &fd0.di).amax() <= 1e-12 * fd0.di.amax().max(1.0) && (&fd.tau_motor - &fd0.tau_motor).amax() <= 1e-12 * fd0.tau_motor.amax().max(1.0));
        }
    }
}

/// A sticking contact is a weld of the point: the same as three bilateral planes through the
/// point with normals n, t1, t2 (q̈ to 1e-12 relative), on a random chain.
#[test]
fn sticking_is_a_three_row_weld() {
    let n = 6;
    let model = random_chain(n, 91);
    let drives = force_drives(n);
    let mut rng = SplitMix64(3);
    let q: Vec<f64> = rng.vector(n, -2.0, 2.0).iter().copied().collect();
    let qd: Vec<f64> = rng.vector(n, -1.0, 1.0).iter().copied().collect();
    let cur: Vec<f64> = rng.vector(n, -3.0, 3.0).iter().copied().collect();
    let point = BodyPoint { body: Some(n - 1), p_body: Vector3::new(0.05, 0.0, 0.1) };
    let normal = Unit::new_normalize(Vector3::new(0.2, 0.1, 1.0));
    let contact = Contact::new(PointOnPlane { name: "c".into(), point, normal_world: normal, offset: 0.0 }, ContactModel::Unilateral { restitution: 0.0, friction: 0.8 });
    let planes: Vec<PointOnPlane> = [normal.into_inner(), contact.t1, contact.t2]
        .iter()
        .enumerate()
        .map(|(k, d)| PointOnPlane { name: format!("w{k}"), point, normal_world: Unit::new_normalize(*d), offset: 0.0 })
        .collect();
    let mut data = Data::new(&model);
    let p = Plant { model: &model, drives: &drives, contacts: &planes, mass_matrix: Default::default(), solver: Default::default(), stabilization: Default::default() };
    let mut fd0 = ForwardData::new(n, 3);
    forward_dynamics(&p, &mut data, &mut fd0, 0.0, &q, &qd, &cur, &cur).expect("weld");
    let contacts = [contact];
    let state = ContactState { mode: vec![ContactMode::Sticking], slip: vec![[1.0, 0.0]], onset: vec![None] };
    let (mut fd, mut cd) = (ForwardData::new(n, 1), ContactData::new(n, 1));
    forward_dynamics_contacts(&plant(&model, &drives), &contacts, &state, &mut data, &mut fd, &mut cd, 0.0, &q, &qd, &cur, &cur).expect("sticking");
    let d = (&fd.qdd - &fd0.qdd).amax() / fd0.qdd.amax().max(1.0);
    assert!(d <= 1e-12, "sticking vs weld: q̈ differs by {d:e}");
    let df = (cd.f_n[0] - fd0.f_n[0]).abs().max((cd.f_t[0][0] - fd0.f_n[1]).abs()).max((cd.f_t[0][1] - fd0.f_n[2]).abs());
    assert!(df <= 1e-10 * fd0.f_n.amax().max(1.0), "forces differ by {df:e}");
}

/// A block (point mass m = 2 kg, μ = 0.5) resting on the table, pushed along x by F: the mode
/// problem sticks for F < μ m g (f_t = −F, f_n = m g, q̈ = 0) and slides above it with
/// ẍ = (F − μ m g)/m; tolerance 1e-9 relative (one dense solve).
#[test]
fn block_sticks_below_the_friction_limit_and_slides_above() {
    let m = 2.0;
    let mu = 0.5;
    let model = point_mass(m);
    let drives = force_drives(3);
    let contacts = [table(&model, "ball", Vector3::zeros(), "block", ContactModel::Unilateral { restitution: 0.0, friction: mu })];
    let limit = mu * m * G;
    for (f, sticks) in [(0.3 * limit, true), (0.99 * limit, true), (1.01 * limit, false), (3.0 * limit, false)] {
        let mut data = Data::new(&model);
        let (mut fd, mut cd) = (ForwardData::new(3, 1), ContactData::new(3, 1));
        let cur = [f, 0.0, 0.0];
        prepare(&plant(&model, &drives), &contacts, &mut data, &mut fd, &mut cd, 0.0, &[0.0; 3], &[0.0; 3], &cur).expect("prepare");
        let mut state = ContactState::new(&contacts);
        choose_modes(&contacts, &mut state, &[0], &[ContactMode::Sticking], 1e-9, Default::default(), &mut fd, &mut cd, 0.0).expect("consistent");
        let tol = 1e-9 * limit;
        assert!((cd.f_n[0] - m * G).abs() <= tol, "F = {f}: f_n = {}", cd.f_n[0]);
        if sticks {
            assert_eq!(state.mode[0], ContactMode::Sticking, "F = {f}");
            assert!((cd.f_t[0][0] + f).abs() <= tol && cd.f_t[0][1].abs() <= tol, "F = {f}: f_t = {:?}", cd.f_t[0]);
            assert!(fd.qdd.amax() <= 1e-9, "F = {f}: q̈ = {}", fd.qdd);
        } else {
            assert_eq!(state.mode[0], ContactMode::Sliding, "F = {f}");
            assert!((state.slip[0][0] - 1.0).abs() <= 1e-12, "slip direction {:?}", state.slip[0]);
            let a = (f - limit) / m;
            assert!((fd.qdd[0] - a).abs() <= 1e-9 * a.abs().max(1.0), "F = {f}: ẍ = {} vs {a}", fd.qdd[0]);
            assert!((cd.f_t[0][0] + limit).abs() <= tol, "F = {f}: f_t = {:?}", cd.f_t[0]);
        }
    }
    // pulled up harder than gravity: it separates (f_n = 0, z̈ = F/m − g)
    let mut data = Data::new(&model);
    let (mut fd, mut cd) = (ForwardData::new(3, 1), ContactData::new(3, 1));
    prepare(&plant(&model, &drives), &contacts, &mut data, &mut fd, &mut cd, 0.0, &[0.0; 3], &[0.0; 3], &[0.0, 0.0, 1.5 * m * G]).expect("prepare");
    let mut state = ContactState::new(&contacts);
    choose_modes(&contacts, &mut state, &[0], &[ContactMode::Sticking], 1e-9, Default::default(), &mut fd, &mut cd, 0.0).expect("consistent");
    assert_eq!(state.mode[0], ContactMode::Separated);
    assert!((fd.qdd[2] - 0.5 * G).abs() <= 1e-12 * G);
}

/// A point mass m hitting the table with ġ⁻ = −2 m/s and also sliding at 1 m/s: Newton's law
/// gives ġ⁺ = −e ġ⁻, the tangential velocity is unchanged (frictionless impulse), the impulse is
/// m (1 + e) |ġ⁻| and the energy lost ½ m (1 − e²) ġ⁻²; 1e-12 relative.
#[test]
fn impact_on_a_point_mass_follows_newton() {
    let m = 1.5;
    let model = point_mass(m);
    let drives = force_drives(3);
    for e in [0.0, 0.5, 1.0] {
        let contacts = [table(&model, "ball", Vector3::zeros(), "ball", ContactModel::Unilateral { restitution: e, friction: 0.3 })];
        let mut data = Data::new(&model);
        let (mut fd, mut cd) = (ForwardData::new(3, 1), ContactData::new(3, 1));
        let qd = [1.0, 0.0, -2.0];
        prepare(&plant(&model, &drives), &contacts, &mut data, &mut fd, &mut cd, 0.0, &[0.0; 3], &qd, &[0.0; 3]).expect("prepare");
        let imp = solve_impact(&contacts, &cd.rows, fd.m_j.as_slice(), &fd.l_inv_diag, &[(0, e)], &[], 0.0).expect("impact");
        let after: Vec<f64> = qd.iter().zip(&imp.dqd).map(|(a, b)| a + b).collect();
        assert!((after[2] - 2.0 * e).abs() <= 1e-12 && (after[0] - 1.0).abs() <= 1e-12 && after[1].abs() <= 1e-12, "e = {e}: q̇⁺ = {after:?}");
        assert!((imp.impulse[0] - m * (1.0 + e) * 2.0).abs() <= 1e-12 * m, "e = {e}: impulse {}", imp.impulse[0]);
        let lost = 0.5 * m * (1.0 - e * e) * 4.0;
        assert!((imp.energy_lost[0] - lost).abs() <= 1e-12 * m, "e = {e}: lost {} vs {lost}", imp.energy_lost[0]);
        let t_before = 0.5 * m * qd.iter().map(|x| x * x).sum::<f64>();
        let t_after = 0.5 * m * after.iter().map(|x| x * x).sum::<f64>();
        assert!((t_before - t_after - imp.energy_lost[0]).abs() <= 1e-12 * t_before, "e = {e}: the split does not sum to the loss");
    }
}

/// Painlevé's rod (uniform, half-length l, I = m l²/3) touching the table at its lower end A at
/// angle θ, A sliding in −x. With `F_x = −μ N s` the contact's normal acceleration is
/// `g̈ = N/m (1 + 3 cos²θ + 3 μ s sinθ cosθ) − g + l sinθ θ̇²`, so for s = −1 the coefficient
/// is negative when `μ > (1 + 3 cos²θ)/(3 sinθ cosθ)`, smallest (4/3) at tanθ = 2. At
/// tanθ = 2: μ = 1 slides with `N = m g / (1 + 3/5 − 6μ/5)` (1e-9); μ = 1.5 with θ̇ = 0 has no
/// consistent solution (InconsistentContact, "Painleve"); μ = 1.5 with `l sinθ θ̇² = 2 g` has
/// two (separate, or slide with N > 0): indeterminate.
#[test]
fn painleve_rod_inconsistent_and_indeterminate() {
    let (m, l) = (1.0, 0.5);
    let model = rod(m, l);
    let drives = force_drives(3);
    let theta = 2.0f64.atan();
    let q = [0.0, l * theta.sin(), theta];
    let run = |mu: f64, theta_d: f64| -> (Result<(), DynamicsError>, ContactState, ContactData) {
        let contacts = [table(&model, "rod", Vector3::new(-l, 0.0, 0.0), "tip", ContactModel::Unilateral { restitution: 0.0, friction: mu })];
        // A's velocity (−1, 0) with θ̇: ẋ_A = ẋ + l sinθ θ̇, ż_A = ż − l cosθ θ̇ = 0
        let qd = [-1.0 - l * theta.sin() * theta_d, l * theta.cos() * theta_d, theta_d];
        let mut data = Data::new(&model);
        let (mut fd, mut cd) = (ForwardData::new(3, 1), ContactData::new(3, 1));
        prepare(&plant(&model, &drives), &contacts, &mut data, &mut fd, &mut cd, 0.0, &q, &qd, &[0.0; 3]).expect("prepare");
        assert!(cd.rows.gap[0].abs() <= 1e-12 && cd.rows.vel[0].abs() <= 1e-12 && (cd.rows.vel[1] + 1.0).abs() <= 1e-12, "set-up: A on the table sliding at -1 m/s");
        let mut state = ContactState::new(&contacts);
        let r = choose_modes(&contacts, &mut state, &[0], &[ContactMode::Sliding], 1e-9, Default::default(), &mut fd, &mut cd, 0.0);
        (r, state, cd)
    };
    let (r, state, cd) = run(1.0, 0.0);
    r.expect("mu = 1 < 4/3 is consistent");
    assert_eq!(state.mode[0], ContactMode::Sliding);
    let n = m * G / (1.0 + 0.6 - 1.2 * 1.0);
    assert!((cd.f_n[0] - n).abs() <= 1e-9 * n, "N = {} vs {n}", cd.f_n[0]);
    assert!((cd.f_t[0][0] - 1.0 * n).abs() <= 1e-9 * n, "F_x = {:?} vs mu N", cd.f_t[0]);
    let (r, _, _) = run(1.5, 0.0);
    match r {
        Err(DynamicsError::InconsistentContact { contact, why, .. }) => assert!(contact == "tip" && why.contains("Painleve") && why.contains("no consistent"), "{why}"),
        other => panic!("mu = 1.5 must be inconsistent, got {other:?}"),
    }
    let theta_d = (2.0 * G / (l * theta.sin())).sqrt();
    let (r, _, _) = run(1.5, theta_d);
    match r {
        Err(DynamicsError::InconsistentContact { why, .. }) => assert!(why.contains("indeterminate"), "{why}"),
        other => panic!("mu = 1.5 with a fast rotation must be indeterminate, got {other:?}"),
    }
}

/// The nonsymmetric (sliding) solve: the accelerations satisfy the active normal row
/// (J_n q̈ + J̇_n q̇ = 0 to 1e-10) and M_J q̈ − b equals the applied contact force
/// `(J_n − μ sᵀ J_t)ᵀ f_n` (1e-10), on a random chain.
#[test]
fn sliding_solve_satisfies_its_equations() {
    let n = 5;
    let model = random_chain(n, 17);
    let drives = force_drives(n);
    let mut rng = SplitMix64(9);
    let q: Vec<f64> = rng.vector(n, -2.0, 2.0).iter().copied().collect();
    let qd: Vec<f64> = rng.vector(n, -1.0, 1.0).iter().copied().collect();
    let cur: Vec<f64> = rng.vector(n, -3.0, 3.0).iter().copied().collect();
    let point = BodyPoint { body: Some(n - 1), p_body: Vector3::new(0.05, 0.0, 0.1) };
    let contacts = [Contact::new(PointOnPlane { name: "c".into(), point, normal_world: Unit::new_normalize(Vector3::z()), offset: 0.0 }, ContactModel::Unilateral { restitution: 0.0, friction: 0.7 })];
    let mut data = Data::new(&model);
    let (mut fd, mut cd) = (ForwardData::new(n, 1), ContactData::new(n, 1));
    prepare(&plant(&model, &drives), &contacts, &mut data, &mut fd, &mut cd, 0.0, &q, &qd, &cur).expect("prepare");
    let state = ContactState { mode: vec![ContactMode::Sliding], slip: vec![[0.6, 0.8]], onset: vec![None] };
    solve_modes(&contacts, &state, Default::default(), &mut fd, &mut cd).expect("solvable");
    let qdd = fd.qdd.as_slice();
    let res = cd.rows.dot(0, qdd) + cd.rows.bias[0];
    assert!(res.abs() <= 1e-10 * (1.0 + fd.qdd.amax()), "normal row residual {res:e}");
    let mut mj = data.m.clone();
    for j in 0..n {
        mj[(j, j)] += drives.jm[j];
    }
    let lhs = &mj * DVector::from_column_slice(qdd) - &fd.b;
    let v = cd.rows.slip(0);
    let s = super::forward::slip_direction(v, [0.6, 0.8]);
    for j in 0..n {
        let col = cd.rows.row(0)[j] - 0.7 * (s[0] * cd.rows.row(1)[j] + s[1] * cd.rows.row(2)[j]);
        let e = (lhs[j] - col * cd.f_n[0]).abs();
        assert!(e <= 1e-10 * (1.0 + fd.b.amax()), "joint {j}: M q̈ − b differs from the contact force by {e:e}");
    }
}

/// A compliant contact on a point mass m (k = 1e4 N/m, c = 50 N s/m, μ = 0.4, v_s = 1e-3 m/s) at
/// penetration δ = 2 mm, δ̇ = 0.1 m/s, slip (0.3, −0.4) m/s: f_n = k δ + c δ̇, the friction
/// `−μ f_n v_t / sqrt(|v_t|² + v_s²)`, and m q̈ = m g + f (1e-12 relative); pulled out fast
/// (k δ + c δ̇ < 0) the force is 0, and above the plane nothing acts.
#[test]
fn compliant_forces_on_a_point_mass() {
    let m = 0.7;
    let model = point_mass(m);
    let drives = force_drives(3);
    let (k, c, mu, vs) = (1e4, 50.0, 0.4, 1e-3);
    let contacts = [table(&model, "ball", Vector3::zeros(), "pad", ContactModel::Compliant { stiffness: k, damping: c, friction: mu, slip_velocity: vs })];
    for (z, zd, expect_force) in [(-2e-3, -0.1, true), (-2e-3, 1.0, false), (1e-3, -0.1, false)] {
        let qd = [0.3, -0.4, zd];
        let mut data = Data::new(&model);
        let (mut fd, mut cd) = (ForwardData::new(3, 1), ContactData::new(3, 1));
        let state = ContactState::new(&contacts);
        forward_dynamics_contacts(&plant(&model, &drives), &contacts, &state, &mut data, &mut fd, &mut cd, 0.0, &[0.0, 0.0, z], &qd, &[0.0; 3], &[0.0; 3]).expect("solve");
        let (delta, delta_d) = (-z, -zd);
        let f_n = if delta > 0.0 { (k * delta + c * delta_d).max(0.0) } else { 0.0 };
        assert_eq!(f_n > 0.0, expect_force, "z = {z}, ż = {zd}");
        let w = -mu * f_n / (0.3f64 * 0.3 + 0.4 * 0.4 + vs * vs).sqrt();
        let f = [w * 0.3, w * -0.4, f_n];
        assert!((cd.f_n[0] - f_n).abs() <= 1e-12 * f_n.max(1.0), "f_n {} vs {f_n}", cd.f_n[0]);
        for (j, fj) in f.iter().enumerate() {
            let a = fj / m - if j == 2 { G } else { 0.0 };
            assert!((fd.qdd[j] - a).abs() <= 1e-12 * a.abs().max(1.0), "z = {z}: q̈[{j}] = {} vs {a}", fd.qdd[j]);
        }
    }
}

/// The mode enumeration reads the run's budget before every combination after the first
/// (issue 29): with the deadline already past, the block of the test above stops after one of
/// its three combinations (stick, slide, separate) with how far it got, its modes unchanged.
#[test]
fn the_mode_enumeration_stops_at_the_deadline() {
    use crate::dynamics::contact::modes::choose_modes_within;
    use crate::integrate::{Phase, Watch};
    let model = point_mass(2.0);
    let drives = force_drives(3);
    let contacts = [table(&model, "ball", Vector3::zeros(), "block", ContactModel::Unilateral { restitution: 0.0, friction: 0.5 })];
    let mut data = Data::new(&model);
    let (mut fd, mut cd) = (ForwardData::new(3, 1), ContactData::new(3, 1));
    prepare(&plant(&model, &drives), &contacts, &mut data, &mut fd, &mut cd, 0.25, &[0.0; 3], &[0.0; 3], &[1.0, 0.0, 0.0]).expect("prepare");
    let mut state = ContactState::new(&contacts);
    let before = state.mode.clone();
    let past = Watch::until(std::time::Instant::now());
    let err = choose_modes_within(&contacts, &mut state, &[0], &[ContactMode::Sticking], 1e-9, Default::default(), &mut fd, &mut cd, 0.25, past).unwrap_err();
    assert_eq!(err, DynamicsError::OutOfTime { t: 0.25, during: Phase::ChoosingModes { tried: 1, of: 3 } });
    assert_eq!(state.mode, before);
    assert!(err.to_string().contains("while choosing the contact modes (1 of 3 combinations tried)"), "{err}");
}

/// The onset anchor (`forward::onset_anchors`, issue 23): a contact sliding from rest
/// (`onset: Some(r)`, v_t = 0) on a random chain has its friction along the impending direction
/// of the sticking force at the same state, `−f*/|f*|`, turned by r (1e-12), and then slips
/// forwards along it, `a_t · s > 0` (Coulomb's maximal dissipation: the radial projection of
/// the broken sticking force on the disc), for a stick broken by 1e-6 of its force and by half
/// of it. Without an onset the friction stays along the stored direction (here 90° off the
/// impending one), where the slip acceleration along it is not the law's.
#[test]
fn a_slide_from_rest_in_an_onset_acts_along_the_impending_direction_and_slips_forwards() {
    let n = 5;
    let model = random_chain(n, 23);
    let drives = force_drives(n);
    let mut rng = SplitMix64(31);
    let q: Vec<f64> = rng.vector(n, -2.0, 2.0).iter().copied().collect();
    let qd = vec![0.0; n];
    let cur: Vec<f64> = rng.vector(n, -3.0, 3.0).iter().copied().collect();
    let point = BodyPoint { body: Some(n - 1), p_body: Vector3::new(0.05, 0.0, 0.1) };
    let make = |mu: f64| [Contact::new(PointOnPlane { name: "c".into(), point, normal_world: Unit::new_normalize(Vector3::z()), offset: 0.0 }, ContactModel::Unilateral { restitution: 0.0, friction: mu })];
    let mut data = Data::new(&model);
    let (mut fd, mut cd) = (ForwardData::new(n, 1), ContactData::new(n, 1));
    // the sticking force f* at this state (μ large: it sticks)
    let stick = ContactState { mode: vec![ContactMode::Sticking], slip: vec![[1.0, 0.0]], onset: vec![None] };
    prepare(&plant(&model, &drives), &make(100.0), &mut data, &mut fd, &mut cd, 0.0, &q, &qd, &cur).expect("prepare");
    assert!(cd.rows.slip(0).iter().all(|v| v.abs() <= 1e-15), "at rest");
    solve_modes(&make(100.0), &stick, Default::default(), &mut fd, &mut cd).expect("sticking");
    let (f_n, f_t) = (cd.f_n[0], cd.f_t[0]);
    assert!(f_n > 0.0, "pressed on the table: f_n = {f_n}");
    let ft = f_t[0].hypot(f_t[1]);
    let imp = [-f_t[0] / ft, -f_t[1] / ft];
    for excess in [1e-6, 0.5] {
        let mu = (1.0 - excess) * ft / f_n;
        let contacts = make(mu);
        for turn in [0.0f64, 0.3] {
            let r = [turn.cos(), turn.sin()];
            let off = [-imp[1], imp[0]];
            let state = ContactState { mode: vec![ContactMode::Sliding], slip: vec![off], onset: vec![Some(r)] };
            solve_modes(&contacts, &state, Default::default(), &mut fd, &mut cd).expect("sliding");
            let s = [r[0] * imp[0] - r[1] * imp[1], r[1] * imp[0] + r[0] * imp[1]];
            let a = cd.anchor[0];
            assert!((a[0] - s[0]).hypot(a[1] - s[1]) <= 1e-12, "excess {excess}, turn {turn}: anchor {a:?}, impending turned {s:?}");
            let f = cd.f_t[0];
            assert!((f[0] + mu * cd.f_n[0] * s[0]).hypot(f[1] + mu * cd.f_n[0] * s[1]) <= 1e-12 * (1.0 + cd.f_n[0]), "friction {f:?} not −μ f_n s");
            if turn == 0.0 {
                let qdd = fd.qdd.as_slice();
                let at = [cd.rows.dot(1, qdd) + cd.rows.bias[1], cd.rows.dot(2, qdd) + cd.rows.bias[2]];
                assert!(at[0] * s[0] + at[1] * s[1] > 0.0, "excess {excess}: the slip decelerates along its direction: a_t = {at:?}");
            }
        }
        // no onset: the stored direction, as before
        let state = ContactState { mode: vec![ContactMode::Sliding], slip: vec![[-imp[1], imp[0]]], onset: vec![None] };
        solve_modes(&contacts, &state, Default::default(), &mut fd, &mut cd).expect("sliding");
        assert_eq!(cd.anchor[0], [-imp[1], imp[0]]);
    }
}

/// The onset's friction direction (`forward::onset_direction`): Coulomb's `v_t/|v_t|` from
/// `v_s` on in every direction (to 1e-15), a slip run back across the anchor included (the
/// friction opposes it, so it returns); the anchor at rest; and continuous in v_t with a
/// bounded slope near rest: over a grid within |v_t| ≤ 0.1 v_s, 1e-3 v_s apart, the direction
/// moves by at most `4 |Δv| / v_s` (there `|w| ≥ v_s (0.99² − 0.1) ≥ 0.88 v_s` and
/// `|Δw| ≤ (1 + 4 |v_t|/v_s) |Δv|`, and `|Δ(w/|w|)| ≤ 2 |Δw| / |w|`), on the
/// surface `v_t · anchor = −1e-9 m/s` too, where the flip it replaced (`−friction_direction`
/// past that surface) jumped by 2 (the 440 rejected steps of elbow7's onset at 0.2446 s,
/// BENCHMARKS.md issue 24 item 1, fourth attempt).
#[test]
fn an_onsets_friction_direction_is_coulombs_past_v_s_and_smooth_near_rest() {
    use super::forward::{onset_direction, SLIP_DIRECTION_SPEED as VS};
    let dist = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    for &anchor_angle in &[0.0f64, 0.7, -2.1, 2.8] {
        let anchor = [anchor_angle.cos(), anchor_angle.sin()];
        assert!(dist(onset_direction([0.0, 0.0], anchor, VS), anchor) <= 1e-15, "at rest");
        for k in 0..36 {
            let ray = [(anchor_angle + 0.1745 * f64::from(k)).cos(), (anchor_angle + 0.1745 * f64::from(k)).sin()];
            for &speed in &[VS, 1.5 * VS, 1e-3, 2.0] {
                let d = onset_direction([speed * ray[0], speed * ray[1]], anchor, VS);
                assert!(dist(d, ray) <= 1e-15, "Coulomb's direction at {speed:e} m/s, ray {k}: {d:?}");
            }
        }
        let step = 1e-3 * VS;
        let bound = 4.0 * step / VS;
        for i in -70..=70 {
            for j in -70..70 {
                // (along, across) the anchor, and the next point across
                let at = |a: f64, c: f64| onset_direction([a * anchor[0] - c * anchor[1], a * anchor[1] + c * anchor[0]], anchor, VS);
                let (a, c) = (step * f64::from(i), step * f64::from(j));
                let (d, next) = (at(a, c), at(a, c + step));
                assert!(dist(d, next) <= bound, "a jump of {} at ({a:e}, {c:e}) m/s", dist(d, next));
                if i < 70 {
                    assert!(dist(d, at(a + step, c)) <= bound, "a jump of {} at ({a:e}, {c:e}) m/s", dist(d, at(a + step, c)));
                }
            }
        }
        // elbow7's onset: 4e-9 m/s, mostly across the anchor, on both sides of v_t · a = −1e-9
        let across = [-anchor[1], anchor[0]];
        let side = |along: f64| onset_direction([along * anchor[0] + 3.7e-9 * across[0], along * anchor[1] + 3.7e-9 * across[1]], anchor, VS);
        assert!(dist(side(-0.9e-9), side(-1.1e-9)) <= 1e-3, "{:?} vs {:?}", side(-0.9e-9), side(-1.1e-9));
    }
}

/// Past the slip's zero the friction opposes the slip (Coulomb's law, maximal
/// dissipation) from `v_s` on, in every direction: on rays 91°…179° from `stored` at
/// `v_s`, 1.5 `v_s`, 1e-3 and 2 m/s, `friction_direction` is `v_t/|v_t|` to 1e-15. Along
/// `−stored` it stays `stored` up to 0.5 `v_s` (the zero of a slip slowing along a line
/// is crossed smoothly and bracketed) and is `−stored` from `v_s` on. Before the fix
/// (side-keeping: `σ v_t`, σ the sign of `v_t · stored`) it was `−v_t/|v_t|` on every
/// such ray, π from Coulomb's: where-elbow's evaluation 95 recorded that (the audit's
/// "friction not opposing the slip 3.142 rad").
#[test]
fn past_the_zero_the_friction_opposes_the_slip() {
    use super::forward::{friction_direction, SLIP_DIRECTION_SPEED as VS};
    let unit = |a: f64| [a.cos(), a.sin()];
    let dist = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    for &stored_angle in &[0.0, 0.7, -2.1] {
        let stored = unit(stored_angle);
        for k in 1..=88 {
            let off = (90.0 + f64::from(k)) * std::f64::consts::PI / 180.0;
            for ray in [unit(stored_angle + off), unit(stored_angle - off)] {
                for &speed in &[VS, 1.5 * VS, 1e-3, 2.0] {
                    let d = friction_direction([speed * ray[0], speed * ray[1]], stored);
                    assert!(dist(d, ray) <= 1e-15, "past the zero at {speed:e}, {off} rad from stored: {d:?} vs the slip {ray:?}");
                }
            }
        }
        for &speed in &[1e-12, 1e-8, 0.25 * VS, 0.5 * VS] {
            let d = friction_direction([-speed * stored[0], -speed * stored[1]], stored);
            assert!(dist(d, stored) <= 1e-15, "just past the zero along the line, {speed:e}: {d:?}");
        }
        for &speed in &[VS, 3.0 * VS, 1.0] {
            let d = friction_direction([-speed * stored[0], -speed * stored[1]], stored);
            assert!(dist(d, [-stored[0], -stored[1]]) <= 1e-15, "reversed along the line, {speed:e}: {d:?}");
        }
    }
}
