//! Inverse kinematics of the paper's eqs 28–29 in closed form, for an arm whose hand position
//! is set by one "yaw" joint on a fixed axis through the base and two parallel "planar" joints
//! whose axes are normal to the arm's plane, every other joint held at a fixed angle.
//!
//! - The yaw angle turns the arm's plane onto the target: `q_yaw = ∠(e_2, r_⊥)` about the yaw
//!   axis a, with r_⊥ the target's component normal to a and e_2 the plane's forward direction.
//! - In the plane, with 2D coordinates along (e_1 = a, e_2 = n × a) in which a rotation about
//!   the planar axis n is counter-clockwise, the two links are vectors A (planar joint 1 to
//!   planar joint 2) and B (planar joint 2 to the hand) at zero angle, and d is the target seen
//!   from planar joint 1. The law of cosines gives
//!   `cos(q_2 + δ) = (|d|² − |A|² − |B|²) / (2 |A| |B|)`, δ = ∠B − ∠A, and then
//!   `q_1 = ∠d − ∠(A + R(q_2) B)` (Craig, *Introduction to Robotics*, §4.4; Siciliano et al.,
//!   *Robotics*, §2.12.1).
//! - Velocities are the exact time derivatives of these closed forms.
//!
//! `branch` picks the sign of `q_2 + δ` (the paper's scene: positive).

use std::f64::consts::PI;

use nalgebra::{Vector2, Vector3};

use crate::dynamics::kinematics::{forward_kinematics, BodyPoint};
use crate::dynamics::{Data, Model};

/// Why a yaw-planar IK cannot be built for a model.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IkSetupError {
    #[error("the yaw joint `{0}` must hang from the world-fixed base (its axis must not move)")]
    YawNotAtBase(String),
    #[error("the planar joints `{0}` and `{1}` must have parallel axes, normal to the yaw axis")]
    NotPlanar(String, String),
    #[error("the arm's plane must contain the yaw axis: `{0}` is {1:.3e} m out of it")]
    OffPlane(String, f64),
    #[error("planar joint `{0}` must be an ancestor of `{1}`")]
    NotAncestor(String, String),
    #[error("a planar link has zero length")]
    ZeroLink,
    #[error("joint `{0}` is prismatic: the closed-form IK needs revolute joints (use a cartesian target with the general IK, `\"ik\": {{\"solver\": \"dls\"}}`)")]
    Prismatic(String),
}

/// Closed-form IK: yaw joint + two planar joints; all other joints held.
#[derive(Clone, Debug)]
pub struct YawPlanarIk {
    pub yaw_dof: usize,
    pub planar_dofs: [usize; 2],
    /// Held joint angles (nv); the yaw and planar entries are overwritten on every call.
    pub q_held: Vec<f64>,
    /// +1 or −1: the sign of q_2 + δ.
    pub branch: f64,
    yaw_origin: Vector3<f64>,
    yaw_axis: Vector3<f64>,
    e2: Vector3<f64>,
    p1_2d: Vector2<f64>,
    link_a: Vector2<f64>,
    link_b: Vector2<f64>,
    delta: f64,
    /// Reference angles the solution is unwrapped towards (the initial q of yaw, planar 1, 2).
    q_ref: [f64; 3],
}

fn ang(v: &Vector2<f64>) -> f64 {
    v.y.atan2(v.x)
}

fn rot(a: f64, v: &Vector2<f64>) -> Vector2<f64> {
    let (s, c) = a.sin_cos();
    Vector2::new(c * v.x - s * v.y, s * v.x + c * v.y)
}

/// The angle equal to `a` modulo 2π closest to `reference`.
fn unwrap_near(a: f64, reference: f64) -> f64 {
    a + 2.0 * PI * ((reference - a) / (2.0 * PI)).round()
}

impl YawPlanarIk {
    /// Build from the model at the held angles `q_held` (nv). The yaw and planar angles of
    /// `q_held` are used only as references for unwrapping.
    pub fn new(
        model: &Model,
        q_held: &[f64],
        yaw_dof: usize,
        planar_dofs: [usize; 2],
        hand: &BodyPoint,
        branch: f64,
    ) -> Result<Self, IkSetupError> {
        let name = |j: usize| model.bodies[j].joint.clone();
        for j in [yaw_dof, planar_dofs[0], planar_dofs[1]] {
            if model.bodies[j].kind == crate::dynamics::model::JointKind::Prismatic {
                return Err(IkSetupError::Prismatic(name(j)));
            }
        }
        if model.bodies[yaw_dof].parent.is_some() {
            return Err(IkSetupError::YawNotAtBase(name(yaw_dof)));
        }
        let is_ancestor = |anc: usize, mut b: Option<usize>| {
            while let Some(k) = b {
                if k == anc {
                    return true;
                }
                b = model.bodies[k].parent;
            }
            false
        };
        let [p1, p2] = planar_dofs;
        if !is_ancestor(p1, Some(p2)) || p1 == p2 {
            return Err(IkSetupError::NotAncestor(name(p1), name(p2)));
        }
        if !is_ancestor(p2, hand.body) {
            return Err(IkSetupError::NotAncestor(name(p2), "the hand".into()));
        }
        let mut q = q_held.to_vec();
        q[yaw_dof] = 0.0;
        q[p1] = 0.0;
        q[p2] = 0.0;
        let mut data = Data::new(model);
        forward_kinematics(model, &mut data, &q);
        let x_yaw = data.x_world_body[yaw_dof];
        let yaw_axis = (x_yaw.rotation * model.bodies[yaw_dof].axis.into_inner()).normalize();
        let yaw_origin = x_yaw.translation.vector;
        let n1 = data.x_world_body[p1].rotation * model.bodies[p1].axis.into_inner();
        let n2 = data.x_world_body[p2].rotation * model.bodies[p2].axis.into_inner();
        if n1.cross(&n2).norm() > 1e-9 || n1.dot(&yaw_axis).abs() > 1e-9 {
            return Err(IkSetupError::NotPlanar(name(p1), name(p2)));
        }
        // rotations about n (= n1, or −n1 flipped so both agree) are counter-clockwise in (e1, e2)
        let n = n1;
        let sign2 = if n2.dot(&n1) > 0.0 { 1.0 } else { -1.0 };
        let e1 = yaw_axis;
        let e2 = n.cross(&e1);
        let to_2d = |p: Vector3<f64>| Vector2::new(e1.dot(&(p - yaw_origin)), e2.dot(&(p - yaw_origin)));
        let pts = [
            (name(p1), data.x_world_body[p1].translation.vector),
            (name(p2), data.x_world_body[p2].translation.vector),
            ("the hand".to_string(), hand.position(&data)),
        ];
        for (label, p) in &pts {
            let off = n.dot(&(p - yaw_origin));
            if off.abs() > 1e-9 {
                return Err(IkSetupError::OffPlane(label.clone(), off));
            }
        }
        let p1_2d = to_2d(pts[0].1);
        let link_a = to_2d(pts[1].1) - p1_2d;
        let link_b = to_2d(pts[2].1) - to_2d(pts[1].1);
        if link_a.norm() < 1e-12 || link_b.norm() < 1e-12 {
            return Err(IkSetupError::ZeroLink);
        }
        if sign2 < 0.0 {
            // the second planar joint turns the other way: handled by negating its angle
            return Err(IkSetupError::NotPlanar(name(p1), name(p2)));
        }
        Ok(Self {
            yaw_dof,
            planar_dofs,
            q_held: q_held.to_vec(),
            branch: if branch < 0.0 { -1.0 } else { 1.0 },
            yaw_origin,
            yaw_axis,
            e2,
            p1_2d,
            link_a,
            link_b,
            delta: ang(&link_b) - ang(&link_a),
            q_ref: [q_held[yaw_dof], q_held[p1], q_held[p2]],
        })
    }

    /// Longest reach of the planar pair, m.
    pub fn reach(&self) -> f64 {
        self.link_a.norm() + self.link_b.norm()
    }

    /// Joint targets for a hand target `r` (m) moving at `r_dot` (m/s), world frame. Writes
    /// q_d (rad) and q̇_d (rad/s) for all nv joints (held joints: their angle, zero speed).
    /// `Err(why)` when the target is out of reach or at a singular configuration.
    pub fn solve(
        &self,
        r: &Vector3<f64>,
        r_dot: &Vector3<f64>,
        q_des: &mut [f64],
        qd_des: &mut [f64],
    ) -> Result<(), String> {
        q_des.copy_from_slice(&self.q_held);
        qd_des.fill(0.0);
        let a = self.yaw_axis;
        let rel = r - self.yaw_origin;
        let r_perp = rel - a * a.dot(&rel);
        let rho2 = r_perp.norm_squared();
        if rho2 < 1e-12 {
            return Err(format!("target {r:?} is on the yaw axis"));
        }
        let rdot_perp = r_dot - a * a.dot(r_dot);
        // yaw: signed angle from e2 to r_perp about a
        let yaw = self.e2.cross(&r_perp).dot(&a).atan2(self.e2.dot(&r_perp));
        let yaw_dot = a.dot(&r_perp.cross(&rdot_perp)) / rho2;
        // the target in the arm's plane, seen from planar joint 1
        let rho = rho2.sqrt();
        let d = Vector2::new(a.dot(&rel), rho) - self.p1_2d;
        let d_dot = Vector2::new(a.dot(r_dot), r_perp.dot(&rdot_perp) / rho);
        let (la, lb) = (self.link_a.norm(), self.link_b.norm());
        let c = (d.norm_squared() - la * la - lb * lb) / (2.0 * la * lb);
        if !(-1.0..=1.0).contains(&c) {
            return Err(format!(
                "target {:?} is {:.6} m from the first planar joint, outside its reach [{:.6}, {:.6}] m",
                r.as_slice(), d.norm(), (la - lb).abs(), la + lb
            ));
        }
        let s = self.branch * (1.0 - c * c).sqrt();
        if s.abs() < 1e-9 {
            return Err(format!("target {:?} is at the reach limit (the planar links are aligned)", r.as_slice()));
        }
        let q2 = self.branch * c.acos() - self.delta;
        let rb = rot(q2, &self.link_b);
        let w = self.link_a + rb;
        let q1 = ang(&d) - ang(&w);
        // time derivatives of the closed form
        let c_dot = d.dot(&d_dot) / (la * lb);
        let q2_dot = -c_dot / s;
        let q1_dot = (d.x * d_dot.y - d.y * d_dot.x) / d.norm_squared() - q2_dot * w.dot(&rb) / w.norm_squared();

        let [p1, p2] = self.planar_dofs;
        q_des[self.yaw_dof] = unwrap_near(yaw, self.q_ref[0]);
        q_des[p1] = unwrap_near(q1, self.q_ref[1]);
        q_des[p2] = unwrap_near(q2, self.q_ref[2]);
        qd_des[self.yaw_dof] = yaw_dot;
        qd_des[p1] = q1_dot;
        qd_des[p2] = q2_dot;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::kinematics::body_point;

    /// A yaw joint and two planar joints, the second prismatic: refused by name, not solved
    /// as if it turned.
    #[test]
    fn a_prismatic_planar_joint_is_refused_by_name() {
        let inertial = r#"<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>"#;
        let xml = format!(
            r#"<robot name="r"><link name="base"/>
            <link name="a">{inertial}</link><link name="b">{inertial}</link><link name="c">{inertial}</link>
            <joint name="yaw" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="10" velocity="1"/></joint>
            <joint name="p1" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="10" velocity="1"/></joint>
            <joint name="slide" type="prismatic"><parent link="b"/><child link="c"/><origin xyz="0.3 0 0"/><axis xyz="1 0 0"/><limit lower="0" upper="0.2" effort="10" velocity="1"/></joint>
            </robot>"#
        );
        let model = Model::from_urdf(&xml, "t.urdf", Vector3::new(0.0, 0.0, -9.81)).unwrap();
        let hand = body_point(&model, "c", Vector3::new(0.1, 0.0, 0.0)).unwrap();
        let e = YawPlanarIk::new(&model, &[0.0; 3], 0, [1, 2], &hand, 1.0).unwrap_err();
        assert_eq!(e, IkSetupError::Prismatic("slide".into()));
        assert!(e.to_string().contains("general IK"), "{e}");
    }
}
