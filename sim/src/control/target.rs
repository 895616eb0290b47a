//! [`Target`]: what the arm is asked to do, chosen once when the scene is built. At time t it
//! writes the joint targets q_d (rad), q̇_d (rad/s) and q̈_d (rad/s²) for every joint, exact
//! derivatives of one function of t (no finite differences), and gives the desired hand
//! position that is recorded. Nothing is allocated per call.
//!
//! | target | q_d(t) | q̇_d, q̈_d | desired hand |
//! |---|---|---|---|
//! | `Paper` | the closed-form IK of the circle ([`super::YawPlanarIk`], unchanged) | its closed-form q̇_d; q̈_d = J₃⁻¹ (r̈_d − J̇ q̇_d) on the three IK joints (J₃ the hand's 3 x 3 Jacobian in them; the others hold) | the circle |
//! | `Joint` | a named spline through waypoints or a CSV ([`super::spline`]) | the spline's derivatives | FK of q_d(t) |
//! | `Cartesian` | the general IK solved on a grid and joined by a C² cubic spline ([`super::general_ik::track`]) | the spline's derivatives | the path |

use nalgebra::{Matrix3, Vector3};

use super::general_ik::TrackStats;
use super::path::CartesianPath;
use super::spline::{CubicSpline, JointSpline};
use super::{Circle, YawPlanarIk};
use crate::dynamics::kinematics::{forward_kinematics, forward_velocities, BodyPoint};
use crate::dynamics::{Data, Model};

#[derive(Clone, Debug)]
pub enum Target {
    /// The paper's circle and closed-form IK.
    Paper { circle: Circle, ik: YawPlanarIk },
    /// A joint-space spline.
    Joint(JointSpline),
    /// A hand path, tracked by the general IK (`q` is its joint-space interpolant).
    Cartesian { path: CartesianPath, q: CubicSpline, stats: TrackStats },
}

/// Scratch of [`Target::eval`] and [`Target::hand_desired`]: sized once, read by nothing else.
#[derive(Clone, Debug)]
pub struct TargetScratch {
    data: Data,
    q: Vec<f64>,
    qd: Vec<f64>,
    qdd: Vec<f64>,
}

impl TargetScratch {
    pub fn new(model: &Model) -> Self {
        let nv = model.nv;
        Self { data: Data::new(model), q: vec![0.0; nv], qd: vec![0.0; nv], qdd: vec![0.0; nv] }
    }
}

impl Target {
    /// q_d, q̇_d (nv each) at t, and q̈_d when `qdd_des` is given (the paper target computes it
    /// only then: its q_d, q̇_d are the closed form's, whatever is asked). `Err(why)` when the
    /// paper IK cannot reach the target.
    #[allow(clippy::too_many_arguments)]
    pub fn eval(
        &self,
        t: f64,
        model: &Model,
        hand: &BodyPoint,
        scratch: &mut TargetScratch,
        q_des: &mut [f64],
        qd_des: &mut [f64],
        qdd_des: Option<&mut [f64]>,
    ) -> Result<(), String> {
        match self {
            Target::Paper { circle, ik } => {
                ik.solve(&circle.position(t), &circle.velocity(t), q_des, qd_des)?;
                if let Some(qdd) = qdd_des {
                    paper_acceleration(circle, ik, t, model, hand, &mut scratch.data, q_des, qd_des, qdd)?;
                }
                Ok(())
            }
            Target::Joint(s) => {
                match qdd_des {
                    Some(qdd) => s.eval(t, q_des, qd_des, qdd),
                    None => s.eval(t, q_des, qd_des, &mut scratch.qdd),
                }
                Ok(())
            }
            Target::Cartesian { q, .. } => {
                match qdd_des {
                    Some(qdd) => q.eval(t, q_des, qd_des, qdd),
                    None => q.eval(t, q_des, qd_des, &mut scratch.qdd),
                }
                Ok(())
            }
        }
    }

    /// The desired hand position at t, world frame, m: the path for the paper and Cartesian
    /// targets, the forward kinematics of q_d(t) for joint targets.
    pub fn hand_desired(&self, t: f64, model: &Model, hand: &BodyPoint, scratch: &mut TargetScratch) -> Vector3<f64> {
        match self {
            Target::Paper { circle, .. } => circle.position(t),
            Target::Cartesian { path, .. } => path.position(t),
            Target::Joint(s) => {
                s.eval(t, &mut scratch.q, &mut scratch.qd, &mut scratch.qdd);
                forward_kinematics(model, &mut scratch.data, &scratch.q);
                hand.position(&scratch.data)
            }
        }
    }

    /// One phrase for people (`sim check` may print it): what is tracked and how q_d is made.
    pub fn describe(&self, model: &Model) -> String {
        let names = |dofs: &[usize]| dofs.iter().map(|&j| model.bodies[j].joint.as_str()).collect::<Vec<_>>().join(", ");
        match self {
            Target::Paper { circle, ik } => format!(
                "the paper's circle (centre {:?} m, radius {} m, {} s per turn), closed-form IK on {}",
                circle.center.as_slice(), circle.radius, circle.period,
                names(&[ik.yaw_dof, ik.planar_dofs[0], ik.planar_dofs[1]])
            ),
            Target::Joint(JointSpline::Cubic(s)) => format!("joint-space cubic spline (C², at rest at the ends) through {} knots", s.knots().len()),
            Target::Joint(JointSpline::Quintic(_)) => "joint-space minimum-jerk quintics, at rest at each waypoint".to_string(),
            Target::Cartesian { path, stats, .. } => format!(
                "hand {} tracked by the general IK (damped least squares): {} knots every {} s, task error <= {:.1e} at the knots, <= {:.1e} between",
                match path {
                    CartesianPath::Circle(_) => "circle",
                    CartesianPath::Lines(_) => "line segments",
                    CartesianPath::Waypoints(_) => "waypoint spline",
                },
                stats.knots, stats.step, stats.at_knots, stats.between_knots
            ),
        }
    }

    /// The paper's circle, if this is the paper target.
    pub fn circle(&self) -> Option<&Circle> {
        match self {
            Target::Paper { circle, .. } => Some(circle),
            _ => None,
        }
    }

    /// The paper's closed-form IK, if this is the paper target.
    pub fn paper_ik(&self) -> Option<&YawPlanarIk> {
        match self {
            Target::Paper { ik, .. } => Some(ik),
            _ => None,
        }
    }

    /// The general IK's grid and its measured errors, for a Cartesian target.
    pub fn track_stats(&self) -> Option<&TrackStats> {
        match self {
            Target::Cartesian { stats, .. } => Some(stats),
            _ => None,
        }
    }
}

/// q̈_d of the closed-form IK: differentiating r_d = p(q_d) twice,
/// `r̈_d = J q̈_d + J̇ q̇_d`; only the yaw and planar joints move, so with J₃ their three
/// columns, `q̈ = J₃⁻¹ (r̈_d − J̇ q̇_d)` (Siciliano et al., *Robotics*, §3.9).
#[allow(clippy::too_many_arguments)]
fn paper_acceleration(
    circle: &Circle,
    ik: &YawPlanarIk,
    t: f64,
    model: &Model,
    hand: &BodyPoint,
    data: &mut Data,
    q: &[f64],
    qd: &[f64],
    qdd: &mut [f64],
) -> Result<(), String> {
    forward_kinematics(model, data, q);
    forward_velocities(model, data, qd);
    let p = hand.position(data);
    let dofs = [ik.yaw_dof, ik.planar_dofs[0], ik.planar_dofs[1]];
    let mut j3 = Matrix3::zeros();
    for (c, &j) in dofs.iter().enumerate() {
        let z = data.x_world_body[j].rotation * model.bodies[j].axis.into_inner();
        j3.set_column(c, &z.cross(&(p - data.x_world_body[j].translation.vector)));
    }
    let rhs = circle.acceleration(t) - hand.bias_acceleration(data);
    let sol = j3.lu().solve(&rhs).ok_or_else(|| format!("the IK Jacobian is singular at t = {t}"))?;
    qdd.fill(0.0);
    for (c, &j) in dofs.iter().enumerate() {
        qdd[j] = sol[c];
    }
    Ok(())
}
