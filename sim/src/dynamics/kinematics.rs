//! Forward kinematics in the world frame: body placements, velocities, the velocity-product
//! ("bias") accelerations at q̈ = 0, and the positions, velocities and Jacobians of points.
//!
//! With z_i the world joint axis and o_i the joint origin (Craig, *Introduction to Robotics*,
//! §5.7; Siciliano et al., *Robotics*, §3.1):
//! `ω_i = ω_λ + z_i q̇_i`, `v_i = v_λ + ω_λ × (o_i − o_λ)`,
//! `α_i = α_λ + ω_λ × z_i q̇_i (+ z_i q̈_i)`, `a_i = a_λ + α_λ × r + ω_λ × (ω_λ × r)`, r = o_i − o_λ.
//! A point p on body b: `v_p = v_b + ω_b × (p − o_b)`, the Jacobian column of an ancestor joint
//! j is `z_j × (p − o_j)` (`z_j` for a prismatic joint, which adds `z_i q̇_i` to `v_i`, nothing
//! to `ω_i`, and the Coriolis term `2 ω_λ × z_i q̇_i` to `a_i`), and `J̇q̇ = a_b + α_b × r + ω_b × (ω_b × r)` with the bias values.

use nalgebra::{DMatrix, Vector3};

use super::data::Data;
use super::model::{JointKind, Model};

/// Placements of every body, in its parent (`data.x_parent_body`, `data.xm_parent_body`) and
/// in the world (`data.x_world_body`). `q`: joint angles (nv), rad.
pub fn forward_kinematics(model: &Model, data: &mut Data, q: &[f64]) {
    assert_eq!(q.len(), model.nv, "q: expected nv");
    for (i, body) in model.bodies.iter().enumerate() {
        let x_parent_body = model.joint_placement(i, q[i]);
        data.x_parent_body[i] = x_parent_body;
        data.xm_parent_body[i] = (&x_parent_body).into();
        data.x_world_body[i] = match body.parent {
            Some(p) => data.x_world_body[p] * x_parent_body,
            None => x_parent_body,
        };
    }
}

/// World-frame velocities of every body and their accelerations at q̈ = 0 (no gravity).
/// Needs `forward_kinematics` first. `qd`: joint velocities (nv), rad/s.
pub fn forward_velocities(model: &Model, data: &mut Data, qd: &[f64]) {
    assert_eq!(qd.len(), model.nv, "qd: expected nv");
    for (i, body) in model.bodies.iter().enumerate() {
        let z_world = data.x_world_body[i].rotation * body.axis.into_inner();
        let o = data.x_world_body[i].translation.vector;
        let (w_p, v_p, al_p, a_p, o_p) = match body.parent {
            Some(p) => (
                data.w_world[p],
                data.v_world[p],
                data.alpha_bias_world[p],
                data.a_bias_world[p],
                data.x_world_body[p].translation.vector,
            ),
            None => (Vector3::zeros(), Vector3::zeros(), Vector3::zeros(), Vector3::zeros(), Vector3::zeros()),
        };
        let r = o - o_p;
        match body.kind {
            JointKind::Revolute => {
                let wz = z_world * qd[i];
                data.w_world[i] = w_p + wz;
                data.v_world[i] = v_p + w_p.cross(&r);
                data.alpha_bias_world[i] = al_p + w_p.cross(&wz);
                data.a_bias_world[i] = a_p + al_p.cross(&r) + w_p.cross(&w_p.cross(&r));
            }
            JointKind::Prismatic => {
                // the origin slides along z at q̇: a relative velocity z q̇ in the parent, whose
                // Coriolis term is 2 ω_λ × z q̇ (Craig §6.5, eq 6.47 for a prismatic joint)
                let vz = z_world * qd[i];
                data.w_world[i] = w_p;
                data.v_world[i] = v_p + w_p.cross(&r) + vz;
                data.alpha_bias_world[i] = al_p;
                data.a_bias_world[i] = a_p + al_p.cross(&r) + w_p.cross(&w_p.cross(&r)) + 2.0 * w_p.cross(&vz);
            }
        }
    }
}

/// A point fixed on a body: `body` (None = world-fixed) and its coordinates in the body frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyPoint {
    pub body: Option<usize>,
    pub p_body: Vector3<f64>,
}

impl BodyPoint {
    /// World position, m. Needs `forward_kinematics`.
    pub fn position(&self, data: &Data) -> Vector3<f64> {
        match self.body {
            Some(b) => data.x_world_body[b] * nalgebra::Point3::from(self.p_body),
            None => self.p_body.into(),
        }
        .coords
    }

    /// World velocity, m/s. Needs `forward_velocities`.
    pub fn velocity(&self, data: &Data) -> Vector3<f64> {
        match self.body {
            Some(b) => {
                let r = self.position(data) - data.x_world_body[b].translation.vector;
                data.v_world[b] + data.w_world[b].cross(&r)
            }
            None => Vector3::zeros(),
        }
    }

    /// `J̇ q̇`: the world acceleration of the point at q̈ = 0, m/s^2. Needs `forward_velocities`.
    pub fn bias_acceleration(&self, data: &Data) -> Vector3<f64> {
        match self.body {
            Some(b) => {
                let r = self.position(data) - data.x_world_body[b].translation.vector;
                let w = data.w_world[b];
                data.a_bias_world[b] + data.alpha_bias_world[b].cross(&r) + w.cross(&w.cross(&r))
            }
            None => Vector3::zeros(),
        }
    }

    /// Writes the 3 x nv world linear-velocity Jacobian into `jac` (overwrites every entry).
    /// Needs `forward_kinematics`.
    pub fn jacobian(&self, model: &Model, data: &Data, jac: &mut DMatrix<f64>) {
        assert_eq!(jac.shape(), (3, model.nv), "jac: expected 3 x nv");
        jac.fill(0.0);
        let p = self.position(data);
        let mut cur = self.body;
        while let Some(j) = cur {
            let z = data.x_world_body[j].rotation * model.bodies[j].axis.into_inner();
            let col = match model.bodies[j].kind {
                JointKind::Revolute => z.cross(&(p - data.x_world_body[j].translation.vector)),
                JointKind::Prismatic => z,
            };
            jac.fixed_view_mut::<3, 1>(0, j).copy_from(&col);
            cur = model.bodies[j].parent;
        }
    }

    /// `n · J` for a world direction `n`, written into the entries of `row` (length nv) of this
    /// point's ancestor joints, without forming J. Needs `forward_kinematics`.
    pub fn jacobian_along<R>(&self, model: &Model, data: &Data, n: &Vector3<f64>, row: &mut R)
    where
        R: std::ops::IndexMut<usize, Output = f64> + ?Sized,
    {
        self.jacobian_along_at(model, data, &self.position(data), n, row);
    }

    /// `n · J` of the material point of this point's body that is at world position `p` now
    /// (a contact point that moves over the body, `dynamics/contact/shape.rs`), written as
    /// [`Self::jacobian_along`] does. Needs `forward_kinematics`.
    pub fn jacobian_along_at<R>(&self, model: &Model, data: &Data, p: &Vector3<f64>, n: &Vector3<f64>, row: &mut R)
    where
        R: std::ops::IndexMut<usize, Output = f64> + ?Sized,
    {
        let p = *p;
        let mut cur = self.body;
        while let Some(j) = cur {
            let z = data.x_world_body[j].rotation * model.bodies[j].axis.into_inner();
            row[j] = match model.bodies[j].kind {
                JointKind::Revolute => n.dot(&z.cross(&(p - data.x_world_body[j].translation.vector))),
                JointKind::Prismatic => n.dot(&z),
            };
            cur = model.bodies[j].parent;
        }
    }
}

/// Resolve a point given by URDF link name and an offset in that link's frame.
pub fn body_point(model: &Model, link: &str, offset: Vector3<f64>) -> Option<BodyPoint> {
    let f = model.frame(link)?;
    Some(BodyPoint { body: f.body, p_body: (f.x_body_frame * nalgebra::Point3::from(offset)).coords })
}
