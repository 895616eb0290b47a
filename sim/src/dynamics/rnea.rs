//! Recursive Newton–Euler inverse dynamics, `τ = M(q) q̈ + C(q, q̇) q̇ + G(q)`, in body
//! coordinates: Featherstone, *Rigid Body Dynamics Algorithms*, §5.3, Table 5.1; Luh, Walker
//! and Paul (1980). Gravity enters as a fictitious base acceleration `a_0 = −g`.
//! O(n) in the number of bodies. A revolute joint's motion subspace is `S = [a; 0]`, a
//! prismatic joint's `S = [0; a]` (RBDA Table 4.1).

use nalgebra::{DVector, Vector3};

use super::data::Data;
use super::model::{JointKind, Model};
use super::spatial::Motion;

/// Inverse dynamics of the rigid bodies alone (no motor inertia, no friction).
/// `q`, `qd`, `qdd`: (nv) rad, rad/s, rad/s^2; `gravity_world`: m/s^2.
/// Returns the joint torques (nv, N m), stored in `data.tau`; also fills `data.x_parent_body`,
/// `data.v_body`, `data.a_body`, `data.f_body`.
pub fn rnea<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    gravity_world: &Vector3<f64>,
) -> &'d DVector<f64> {
    assert_eq!(q.len(), model.nv, "q: expected nv");
    for i in 0..model.nv {
        let x = model.joint_placement(i, q[i]);
        data.x_parent_body[i] = x;
        data.xm_parent_body[i] = (&x).into();
    }
    rnea_placed(model, data, qd, qdd, gravity_world)
}

/// [`rnea`] at the placements already in `data.xm_parent_body` (from `forward_kinematics` or
/// `rnea` at the same q), so that one evaluation of the dynamics computes them once.
pub fn rnea_placed<'d>(
    model: &Model,
    data: &'d mut Data,
    qd: &[f64],
    qdd: &[f64],
    gravity_world: &Vector3<f64>,
) -> &'d DVector<f64> {
    let nv = model.nv;
    assert_eq!(qd.len(), nv, "qd: expected nv");
    assert_eq!(qdd.len(), nv, "qdd: expected nv");
    let a_world = Motion::new(Vector3::zeros(), -gravity_world);
    // forward pass: velocities and accelerations, outward from the root
    for (i, body) in model.bodies.iter().enumerate() {
        let x = &data.xm_parent_body[i];
        let axis = body.axis.into_inner();
        let (v_parent, a_parent) = match body.parent {
            Some(p) => (data.v_body[p], data.a_body[p]),
            None => (Motion::ZERO, a_world),
        };
        // S q̇ and S q̈ with S = [a; 0] (revolute) or [0; a] (prismatic)
        let (vj, aj) = match body.kind {
            JointKind::Revolute => (Motion::new(axis * qd[i], Vector3::zeros()), Motion::new(axis * qdd[i], Vector3::zeros())),
            JointKind::Prismatic => (Motion::new(Vector3::zeros(), axis * qd[i]), Motion::new(Vector3::zeros(), axis * qdd[i])),
        };
        let v = v_parent.to_child_x(x).add(&vj);
        let a = a_parent.to_child_x(x).add(&aj).add(&v.cross_motion(&vj));
        let inertia = &body.inertia;
        data.f_body[i] = inertia.mul(&a).add(&v.cross_force(&inertia.mul(&v)));
        data.v_body[i] = v;
        data.a_body[i] = a;
    }
    // backward pass: joint torques, inward to the root
    for i in (0..nv).rev() {
        let body = &model.bodies[i];
        // τ = Sᵀ f: the moment about the axis, or the force along it
        data.tau[i] = match body.kind {
            JointKind::Revolute => body.axis.dot(&data.f_body[i].n),
            JointKind::Prismatic => body.axis.dot(&data.f_body[i].f),
        };
        if let Some(p) = body.parent {
            let f = data.f_body[i].to_parent_x(&data.xm_parent_body[i]);
            data.f_body[p] = data.f_body[p].add(&f);
        }
    }
    &data.tau
}

/// Bias forces `h(q, q̇) + G(q) = RNEA(q, q̇, 0)` (nv, N m), stored in `data.tau`.
pub fn bias_forces<'d>(model: &Model, data: &'d mut Data, q: &[f64], qd: &[f64]) -> &'d DVector<f64> {
    let zeros = std::mem::take(&mut data.zeros_nv);
    rnea(model, data, q, qd, zeros.as_slice(), &model.gravity);
    data.zeros_nv = zeros;
    &data.tau
}

/// [`bias_forces`] at the placements already in `data` (see [`rnea_placed`]).
pub fn bias_forces_placed<'d>(model: &Model, data: &'d mut Data, qd: &[f64]) -> &'d DVector<f64> {
    let zeros = std::mem::take(&mut data.zeros_nv);
    rnea_placed(model, data, qd, zeros.as_slice(), &model.gravity);
    data.zeros_nv = zeros;
    &data.tau
}
