//! Holonomic point-on-plane contacts, the paper's `C = z = 0` at the elbows (eqs 13–15), as
//! bilateral, frictionless constraints (`f_t = 0`): `C(q) = n · p(q) − d = 0` for a world plane
//! with unit normal n and offset d. Its Jacobian is `J_c = n^T J_p(q)` (J_p the point's linear
//! Jacobian), and differentiating twice gives the acceleration-level constraint of eq 15,
//! `J_c q̈ = −n · (J̇_p q̇)`. The multiplier is the normal force along n (N): positive pushes
//! the point away from the plane, negative means the plane would have to pull.

use nalgebra::{DMatrix, DVector, Unit, Vector3};

use super::data::Data;
use super::kinematics::BodyPoint;
use super::model::{JointKind, Model};

/// One point held on a world plane.
#[derive(Clone, Debug, PartialEq)]
pub struct PointOnPlane {
    pub name: String,
    pub point: BodyPoint,
    pub normal_world: Unit<Vector3<f64>>,
    /// Plane offset d along the normal, m (the plane is n · x = d).
    pub offset: f64,
}

impl PointOnPlane {
    /// `C(q)`, m. Needs `forward_kinematics`.
    pub fn position(&self, data: &Data) -> f64 {
        self.normal_world.dot(&self.point.position(data)) - self.offset
    }

    /// `Ċ = J_c q̇`, m/s. Needs `forward_velocities`.
    pub fn velocity(&self, data: &Data) -> f64 {
        self.normal_world.dot(&self.point.velocity(data))
    }

    /// `J̇_c q̇`, m/s^2. Needs `forward_velocities`.
    pub fn bias(&self, data: &Data) -> f64 {
        self.normal_world.dot(&self.point.bias_acceleration(data))
    }
}

/// Fill the constraint Jacobian (nc x nv) and `J̇q̇` (nc). Needs `forward_kinematics` and
/// `forward_velocities` at the current state.
pub fn constraint_jacobian(
    model: &Model,
    data: &Data,
    contacts: &[PointOnPlane],
    jac: &mut DMatrix<f64>,
    jdqd: &mut DVector<f64>,
) {
    assert_eq!(jac.shape(), (contacts.len(), model.nv), "jac: expected nc x nv");
    jac.as_mut_slice().fill(0.0);
    for (k, c) in contacts.iter().enumerate() {
        c.point.jacobian_along(model, data, &c.normal_world, &mut jac.row_mut(k));
        jdqd[k] = c.bias(data);
    }
}

/// [`constraint_jacobian`] plus the constraint positions `C` and velocities `Ċ` (nc each), with
/// each contact point's world position computed once for its four quantities (the formulas of
/// `PointOnPlane::{position, velocity, bias}` and `BodyPoint::jacobian_along`, in the same
/// order of operations, so the values are the same to the last bit). Needs
/// `forward_kinematics` and `forward_velocities` at the current state.
pub fn constraint_rows(
    model: &Model,
    data: &Data,
    contacts: &[PointOnPlane],
    jac: &mut DMatrix<f64>,
    jdqd: &mut DVector<f64>,
    c: &mut DVector<f64>,
    cd: &mut DVector<f64>,
) {
    let nc = contacts.len();
    assert_eq!(jac.shape(), (nc, model.nv), "jac: expected nc x nv");
    assert!(jdqd.len() == nc && c.len() == nc && cd.len() == nc, "jdqd, c, cd: expected nc");
    jac.as_mut_slice().fill(0.0);
    for (k, contact) in contacts.iter().enumerate() {
        let n = &contact.normal_world;
        let p = contact.point.position(data);
        c[k] = n.dot(&p) - contact.offset;
        let Some(b) = contact.point.body else {
            cd[k] = n.dot(&Vector3::zeros());
            jdqd[k] = n.dot(&Vector3::zeros());
            continue;
        };
        let r = p - data.x_world_body[b].translation.vector;
        let w = data.w_world[b];
        cd[k] = n.dot(&(data.v_world[b] + w.cross(&r)));
        jdqd[k] = n.dot(&(data.a_bias_world[b] + data.alpha_bias_world[b].cross(&r) + w.cross(&w.cross(&r))));
        let mut cur = Some(b);
        while let Some(j) = cur {
            let z = data.x_world_body[j].rotation * model.bodies[j].axis.into_inner();
            jac[(k, j)] = match model.bodies[j].kind {
                JointKind::Revolute => n.dot(&z.cross(&(p - data.x_world_body[j].translation.vector))),
                JointKind::Prismatic => n.dot(&z),
            };
            cur = model.bodies[j].parent;
        }
    }
}
