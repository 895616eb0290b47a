//! Cross-algorithm identities on random chains and trees (the pinocchio way): each one is a
//! property that only holds when both algorithms are right.

use nalgebra::{DMatrix, DVector, Unit, Vector3};

use super::constraints::{constraint_jacobian, constraint_rows, PointOnPlane};
use super::crba::{crba, crba_world};
use super::data::Data;
use super::energy::{link_kinetic_energy, potential_energy};
use super::forward::{forward_dynamics, ConstraintSolver, ForwardData, MassMatrixMethod, Plant};
use super::kinematics::{forward_kinematics, forward_velocities, BodyPoint};
use super::model::Model;
use super::motor::{Drives, MotorParams};
use super::rnea::{bias_forces, rnea};
use super::samples::{random_branching_tree, random_chain, random_mixed_chain, random_mixed_tree, SplitMix64};
use super::walker_orin;

fn models() -> Vec<Model> {
    let mut v = Vec::new();
    for (k, n) in [1usize, 2, 3, 7, 10, 16].iter().enumerate() {
        v.push(random_chain(*n, 100 + k as u64));
        v.push(random_branching_tree(*n, 200 + k as u64));
        // revolute and prismatic joints mixed: every identity below holds for them too
        v.push(random_mixed_chain(*n, 400 + k as u64));
        v.push(random_mixed_tree(*n, 500 + k as u64));
    }
    // the mixed samples do hold prismatic joints (a test that cannot fail is no test)
    let prismatic = v.iter().flat_map(|m| &m.bodies).filter(|b| b.kind == super::model::JointKind::Prismatic).count();
    assert!(prismatic >= 10, "only {prismatic} prismatic joints in the samples");
    v
}

fn rel_diff(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    (a - b).amax() / a.amax().max(1.0)
}

/// Walker–Orin (n RNEA calls, eq 26) equals CRBA to 1e-12 (relative to max |M|, >= 1).
#[test]
fn walker_orin_mass_matrix_equals_crba() {
    for model in models() {
        let mut rng = SplitMix64(7 + model.nv as u64);
        let mut data = Data::new(&model);
        for _ in 0..5 {
            let q = rng.vector(model.nv, -3.0, 3.0);
            let m_crba = crba(&model, &mut data, &q).clone();
            let m_wo = walker_orin::mass_matrix(&model, &mut data, &q).clone();
            let d = rel_diff(&m_crba, &m_wo);
            assert!(d <= 1e-12, "{}: |M_crba - M_wo| = {d:e}", model.name);
        }
    }
}

/// M is symmetric (exactly, both triangles written from one value) and positive definite.
#[test]
fn mass_matrix_is_symmetric_positive_definite() {
    for model in models() {
        let mut rng = SplitMix64(11);
        let mut data = Data::new(&model);
        for _ in 0..5 {
            let q = rng.vector(model.nv, -3.0, 3.0);
            let m = crba(&model, &mut data, &q).clone();
            assert_eq!(m, m.transpose(), "{}", model.name);
            let eig = m.clone().symmetric_eigenvalues();
            assert!(eig.min() > 0.0, "{}: min eigenvalue {}", model.name, eig.min());
            // WO is symmetric up to rounding
            let m_wo = walker_orin::mass_matrix(&model, &mut data, &q).clone();
            assert!(rel_diff(&m_wo, &m_wo.transpose()) < 1e-13);
        }
    }
}

/// M q̈ + h(q, q̇) + G(q) = RNEA(q, q̇, q̈), to 1e-11 relative.
#[test]
fn crba_plus_bias_equals_rnea() {
    for model in models() {
        let mut rng = SplitMix64(13);
        let mut data = Data::new(&model);
        for _ in 0..5 {
            let q = rng.vector(model.nv, -3.0, 3.0);
            let qd = rng.vector(model.nv, -2.0, 2.0);
            let qdd = rng.vector(model.nv, -5.0, 5.0);
            let tau = rnea(&model, &mut data, &q, &qd, &qdd, &model.gravity).clone();
            let bias = bias_forces(&model, &mut data, &q, &qd).clone();
            let m = crba(&model, &mut data, &q).clone();
            let lhs = &m * DVector::from_column_slice(&qdd) + bias;
            let err = (&lhs - &tau).amax() / tau.amax().max(1.0);
            assert!(err < 1e-11, "{}: {err:e}", model.name);
        }
    }
}

/// ½ q̇ᵀ M q̇ equals the sum of the bodies' kinetic energies, to 1e-12 relative.
#[test]
fn kinetic_energy_matches_mass_matrix() {
    for model in models() {
        let mut rng = SplitMix64(17);
        let mut data = Data::new(&model);
        let q = rng.vector(model.nv, -3.0, 3.0);
        let qd = DVector::from_vec(rng.vector(model.nv, -2.0, 2.0));
        let m = crba(&model, &mut data, &q).clone();
        bias_forces(&model, &mut data, &q, qd.as_slice());
        let t_bodies = link_kinetic_energy(&model, &data);
        let t_m = 0.5 * qd.dot(&(&m * &qd));
        assert!((t_bodies - t_m).abs() < 1e-12 * t_m.max(1.0), "{}", model.name);
    }
}

/// G(q) = ∂V/∂q: gravity torques equal the gradient of the potential energy (central
/// differences, h = 1e-6, tolerance 1e-7 relative).
#[test]
fn gravity_torque_is_gradient_of_potential() {
    for model in models() {
        let mut rng = SplitMix64(19);
        let mut data = Data::new(&model);
        let q = rng.vector(model.nv, -3.0, 3.0);
        let g = bias_forces(&model, &mut data, &q, &vec![0.0; model.nv]).clone();
        for j in 0..model.nv {
            let h = 1e-6;
            let mut qp = q.clone();
            qp[j] += h;
            forward_kinematics(&model, &mut data, &qp);
            let vp = potential_energy(&model, &data);
            qp[j] -= 2.0 * h;
            forward_kinematics(&model, &mut data, &qp);
            let vm = potential_energy(&model, &data);
            let fd = (vp - vm) / (2.0 * h);
            assert!((fd - g[j]).abs() < 1e-7 * g.amax().max(1.0), "{} dof {j}: {fd} vs {}", model.name, g[j]);
        }
    }
}

fn random_point(model: &Model, rng: &mut SplitMix64) -> BodyPoint {
    let body = Some((rng.next_u64() % model.nv as u64) as usize);
    BodyPoint { body, p_body: Vector3::new(rng.range(-0.2, 0.2), rng.range(-0.2, 0.2), rng.range(0.0, 0.4)) }
}

/// The point Jacobian against central differences of the position (h = 1e-6, tol 1e-8), and
/// J̇q̇ against the central difference of (J q̇) along the motion q(s) = q + s q̇ (tol 1e-6).
#[test]
fn point_jacobian_and_bias_match_finite_differences() {
    for model in models() {
        let mut rng = SplitMix64(23);
        let mut data = Data::new(&model);
        let nv = model.nv;
        for _ in 0..3 {
            let point = random_point(&model, &mut rng);
            let q = rng.vector(nv, -3.0, 3.0);
            let qd = DVector::from_vec(rng.vector(nv, -2.0, 2.0));
            let mut jac = DMatrix::zeros(3, nv);
            forward_kinematics(&model, &mut data, &q);
            point.jacobian(&model, &data, &mut jac);
            let h = 1e-6;
            for j in 0..nv {
                let mut qp = q.clone();
                qp[j] += h;
                forward_kinematics(&model, &mut data, &qp);
                let pp = point.position(&data);
                qp[j] -= 2.0 * h;
                forward_kinematics(&model, &mut data, &qp);
                let pm = point.position(&data);
                let col = (pp - pm) / (2.0 * h);
                assert!((col - jac.column(j)).amax() < 1e-8, "{} col {j}", model.name);
            }
            // velocity = J q̇
            forward_kinematics(&model, &mut data, &q);
            forward_velocities(&model, &mut data, qd.as_slice());
            let v = point.velocity(&data);
            assert!((v - &jac * &qd).amax() < 1e-12 * (1.0 + v.amax()));
            let bias = point.bias_acceleration(&data);
            // d/ds [J(q + s q̇) q̇] at s = 0 is J̇ q̇
            let jqd_at = |s: f64, data: &mut Data| {
                let qs: Vec<f64> = q.iter().zip(qd.iter()).map(|(a, b)| a + s * b).collect();
                forward_kinematics(&model, data, &qs);
                let mut js = DMatrix::zeros(3, nv);
                point.jacobian(&model, data, &mut js);
                js * &qd
            };
            let fd = (jqd_at(h, &mut data) - jqd_at(-h, &mut data)) / (2.0 * h);
            assert!((&fd - bias).amax() < 1e-6 * (1.0 + bias.amax()), "{}: {fd} vs {bias}", model.name);
        }
    }
}

fn paper_like_drives(nv: usize) -> Drives {
    let m = MotorParams {
        torque_constant: 0.203, resistance: 1.1, inductance: 0.0017, rotor_inertia: 0.000164,
        gear_ratio: 3.0, gear_damping: 0.01,
    };
    Drives::new(&vec![m; nv], &vec![0.5; nv])
}

/// With contacts, the solved accelerations satisfy J q̈ + J̇ q̇ = 0 (to 1e-9 relative), the
/// Schur and the full block (eq 21) solutions agree (1e-9), and CRBA and Walker–Orin agree,
/// on revolute chains and on chains with prismatic joints.
#[test]
fn constrained_accelerations_satisfy_the_constraints() {
    // revolute chains, and chains with prismatic joints mixed in
    for (n, model) in [4usize, 7, 10].into_iter().flat_map(|n| [(n, random_chain(n, 300 + n as u64)), (n, random_mixed_chain(n, 600 + n as u64))]) {
        let drives = paper_like_drives(n);
        let mut rng = SplitMix64(29);
        let contacts: Vec<PointOnPlane> = (0..2)
            .map(|k| PointOnPlane {
                name: format!("c{k}"),
                point: BodyPoint { body: Some(n / 2 + k * (n / 2 - 1)), p_body: Vector3::new(0.0, 0.0, 0.1) },
                normal_world: Unit::new_normalize(rng.unit_vector()),
                offset: 0.0,
            })
            .collect();
        let q = rng.vector(n, -2.0, 2.0);
        let qd = rng.vector(n, -1.0, 1.0);
        let cur = rng.vector(n, -3.0, 3.0);
        let volt = rng.vector(n, -10.0, 10.0);
        let mut data = Data::new(&model);
        let mut results = Vec::new();
        for (mm, solver) in [
            (MassMatrixMethod::Crba, ConstraintSolver::Schur),
            (MassMatrixMethod::Crba, ConstraintSolver::Kkt),
            (MassMatrixMethod::WalkerOrin, ConstraintSolver::Kkt),
        ] {
            let plant = Plant { model: &model, drives: &drives, contacts: &contacts, mass_matrix: mm, solver, stabilization: Default::default() };
            let mut fd = ForwardData::new(n, contacts.len());
            forward_dynamics(&plant, &mut data, &mut fd, 0.0, &q, &qd, &cur, &volt).expect("solvable");
            // residual of eq 15
            let mut jac = DMatrix::zeros(2, n);
            let mut jdqd = DVector::zeros(2);
            forward_kinematics(&model, &mut data, &q);
            forward_velocities(&model, &mut data, &qd);
            constraint_jacobian(&model, &data, &contacts, &mut jac, &mut jdqd);
            let res = &jac * &fd.qdd + &jdqd;
            assert!(res.amax() < 1e-9 * (1.0 + fd.qdd.amax()), "n={n} {mm:?} {solver:?}: residual {res}");
            results.push((fd.qdd.clone(), fd.f_n.clone()));
        }
        for r in &results[1..] {
            assert!((&r.0 - &results[0].0).amax() < 1e-9 * (1.0 + results[0].0.amax()));
            assert!((&r.1 - &results[0].1).amax() < 1e-9 * (1.0 + results[0].1.amax()));
        }
    }
}

/// CRBA in world-aligned coordinates equals CRBA in body coordinates entry by entry on the
/// scale of each entry, max |ΔM_ij| / √(M_ii M_jj) < 1e-14, on chains and trees of 1 to 16
/// bodies at random q (the zeros of tree branches too, exactly); the world-origin form this
/// replaced missed that bound on published URDFs (crba.rs).
#[test]
fn world_frame_crba_equals_body_frame_crba() {
    let mut rng = SplitMix64(43);
    for model in models() {
        let q = rng.vector(model.nv, -3.0, 3.0);
        let mut data = Data::new(&model);
        let m_body = crba(&model, &mut data, &q).clone();
        forward_kinematics(&model, &mut data, &q);
        let m_world = crba_world(&model, &mut data).clone();
        let n = model.nv;
        for i in 0..n {
            for j in 0..n {
                let e = (m_body[(i, j)] - m_world[(i, j)]).abs() / (m_body[(i, i)] * m_body[(j, j)]).sqrt();
                assert!(e < 1e-14, "{} M[{i},{j}]: {} vs {} ({e:e})", model.name, m_body[(i, j)], m_world[(i, j)]);
                if m_body[(i, j)] == 0.0 {
                    assert_eq!(m_world[(i, j)], 0.0, "{} M[{i},{j}]: a branch's zero", model.name);
                }
            }
        }
    }
}

/// The fused contact rows (`constraint_rows`: J_c, J̇_c q̇, C, Ċ with one position per contact)
/// equal the separate functions bit for bit, on chains and trees, for points on bodies and a
/// world-fixed point (whose row is zero).
#[test]
fn fused_constraint_rows_equal_the_separate_functions() {
    let mut rng = SplitMix64(41);
    for model in models() {
        let n = model.nv;
        let mut contacts: Vec<PointOnPlane> = (0..3)
            .map(|k| PointOnPlane {
                name: format!("c{k}"),
                point: random_point(&model, &mut rng),
                normal_world: Unit::new_normalize(rng.unit_vector()),
                offset: rng.range(-0.5, 0.5),
            })
            .collect();
        contacts[2].point.body = None;
        let (q, qd) = (rng.vector(n, -2.0, 2.0), rng.vector(n, -1.0, 1.0));
        let mut data = Data::new(&model);
        forward_kinematics(&model, &mut data, &q);
        forward_velocities(&model, &mut data, &qd);
        let (mut jac, mut jdqd) = (DMatrix::from_element(3, n, 7.0), DVector::from_element(3, 7.0));
        constraint_jacobian(&model, &data, &contacts, &mut jac, &mut jdqd);
        let (mut jac2, mut jdqd2) = (DMatrix::from_element(3, n, 7.0), DVector::from_element(3, 7.0));
        let (mut c, mut cd) = (DVector::from_element(3, 7.0), DVector::from_element(3, 7.0));
        constraint_rows(&model, &data, &contacts, &mut jac2, &mut jdqd2, &mut c, &mut cd);
        assert_eq!(jac, jac2);
        assert_eq!(jdqd, jdqd2);
        assert!(jac2.row(2).iter().all(|&x| x == 0.0) && jdqd2[2] == 0.0 && cd[2] == 0.0);
        for (k, contact) in contacts.iter().enumerate() {
            assert_eq!(c[k], contact.position(&data));
            assert_eq!(cd[k], contact.velocity(&data));
        }
    }
}

/// The same point twice makes J_c rank deficient: solved without NaN by the regularised
/// Schur complement. q̈ equals the single-contact q̈ (1e-8 relative), the constraint residual
/// stays ~0 (1e-8), and the two forces split the single contact's force equally (1e-5: the
/// split is set only by ε = 1e-10 against rounding of 1e-16, so to about 1e-6).
#[test]
fn redundant_contacts_are_solved_not_nan() {
    let n = 5;
    let model = random_chain(n, 5);
    let drives = paper_like_drives(n);
    let c = PointOnPlane {
        name: "p".into(),
        point: BodyPoint { body: Some(3), p_body: Vector3::new(0.0, 0.0, 0.1) },
        normal_world: Vector3::z_axis(),
        offset: 0.0,
    };
    let twice = vec![c.clone(), PointOnPlane { name: "p-again".into(), ..c.clone() }];
    let once = vec![c];
    let mut data = Data::new(&model);
    let x = vec![0.1; n];
    let solve = |contacts: &[PointOnPlane], data: &mut Data| {
        let plant = Plant {
            model: &model, drives: &drives, contacts, mass_matrix: MassMatrixMethod::Crba,
            solver: ConstraintSolver::Schur,
        stabilization: Default::default(),
        };
        let mut fd = ForwardData::new(n, contacts.len());
        forward_dynamics(&plant, data, &mut fd, 1.25, &x, &x, &x, &x).expect("solved");
        fd
    };
    let one = solve(&once, &mut data);
    let two = solve(&twice, &mut data);
    assert!(!one.regularized && two.regularized);
    assert!(two.qdd.iter().all(|v| v.is_finite()));
    assert!((&two.qdd - &one.qdd).amax() < 1e-8 * one.qdd.amax().max(1.0));
    let split = (two.f_n[0] - 0.5 * one.f_n[0]).abs().max((two.f_n[1] - 0.5 * one.f_n[0]).abs());
    assert!(split < 1e-5 * one.f_n[0].abs().max(1.0), "{} {} vs {}", two.f_n[0], two.f_n[1], one.f_n[0]);
    let res = &two.jac * &two.qdd + &two.jdqd;
    assert!(res.amax() < 1e-8 * (1.0 + two.qdd.amax()), "{res}");
}

/// A contact on a point that cannot move along the normal (on the base axis of a vertical
/// revolute joint) makes A exactly zero: reported as singular with the time, never NaN.
#[test]
fn an_immovable_contact_is_reported() {
    let model = random_chain(1, 3);
    let drives = paper_like_drives(1);
    // the origin of body 0 lies on its own joint axis: it cannot move at all
    let contacts = vec![PointOnPlane {
        name: "stuck".into(),
        point: BodyPoint { body: Some(0), p_body: Vector3::zeros() },
        normal_world: Vector3::z_axis(),
        offset: 0.0,
    }];
    let plant = Plant {
        model: &model, drives: &drives, contacts: &contacts, mass_matrix: MassMatrixMethod::Crba,
        solver: ConstraintSolver::Schur,
        stabilization: Default::default(),
    };
    let mut data = Data::new(&model);
    let mut fd = ForwardData::new(1, 1);
    let err = forward_dynamics(&plant, &mut data, &mut fd, 2.5, &[0.1], &[0.2], &[1.0], &[3.0]).unwrap_err();
    assert!(err.to_string().contains("t = 2.5"), "{err}");
    assert!(err.to_string().contains("singular"), "{err}");
}

/// `<limit>` and `<dynamics>` are read per dof: a range for a revolute joint, none for a
/// continuous one or an absent `<limit>`, speed and effort only when given.
#[test]
fn urdf_limits_and_dynamics_are_read_per_dof() {
    let xml = r#"<robot name="r">
      <link name="base"/>
      <link name="a"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
      <link name="b"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
      <link name="c"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
      <joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
        <limit lower="-1.5" upper="2.5" effort="30" velocity="3.1"/><dynamics damping="0.2" friction="0.4"/></joint>
      <joint name="j2" type="continuous"><parent link="a"/><child link="b"/><axis xyz="0 1 0"/>
        <limit effort="12" velocity="0"/></joint>
      <joint name="j3" type="revolute"><parent link="b"/><child link="c"/><axis xyz="0 1 0"/></joint>
    </robot>"#;
    let m = Model::from_urdf(xml, "t.urdf", nalgebra::Vector3::zeros()).unwrap();
    let l = |j: &str| m.bodies[m.dof_of_joint(j).unwrap()].limits;
    assert_eq!(l("j1").position, Some((-1.5, 2.5)));
    assert_eq!((l("j1").velocity, l("j1").effort), (Some(3.1), Some(30.0)));
    assert_eq!((l("j1").damping, l("j1").friction), (0.2, 0.4));
    assert_eq!(l("j2").position, None);
    assert_eq!((l("j2").velocity, l("j2").effort), (None, Some(12.0)));
    assert_eq!(l("j3"), crate::dynamics::model::JointLimits::default());
}
