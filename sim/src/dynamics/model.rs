//! The read-only [`Model`]: a kinematic tree of revolute joints built from a URDF.
//!
//! Fixed joints are folded into their parent body (their inertia is merged, their frame kept
//! as a [`Frame`]), as pinocchio does; each remaining body has exactly one revolute degree of
//! freedom, so body index = dof index = index into `q`. Bodies are ordered so that a parent
//! comes before its children (RBDA §4.1.2, "regular numbering").
//!
//! Conventions: SI units, radians; `x_a_b: Isometry3` maps frame-b coordinates to frame a.
//! The URDF root link is fixed to the world frame at the identity.

use std::collections::HashMap;

use nalgebra::{Isometry3, Matrix3, Translation3, Unit, UnitQuaternion, Vector3};

use super::spatial::Inertia;
use crate::error::ModelError;
use crate::limits::{xml_shape, MAX_URDF_DEPTH, MAX_URDF_JOINTS};

/// One moving body: the link after a revolute joint plus everything welded to it.
#[derive(Clone, Debug)]
pub struct Body {
    /// URDF link name of the body frame (= the joint frame).
    pub link: String,
    /// URDF name of the revolute joint that moves this body.
    pub joint: String,
    /// Parent body, or `None` when the parent is the (world-fixed) root.
    pub parent: Option<usize>,
    /// Placement of the joint frame at q = 0 in the parent body frame (or the world frame).
    pub x_parent_joint: Isometry3<f64>,
    /// Unit joint axis in the joint (= body) frame.
    pub axis: Unit<Vector3<f64>>,
    /// Inertia about the body origin in body coordinates, fixed children merged.
    pub inertia: Inertia,
    /// The joint's URDF `<limit>` and `<dynamics>`, as read.
    pub limits: JointLimits,
}

/// A joint's URDF `<limit>` and `<dynamics>` elements (ROS URDF spec, `joint` element), as
/// read; nothing here enters the dynamics unless a scene asks for it. urdf-rs fills an absent
/// `<limit>` with zeros: a zero range, speed or effort means "not given" and reads as `None`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct JointLimits {
    /// `(lower, upper)`, rad; `None` for a continuous joint or when `lower = upper`.
    pub position: Option<(f64, f64)>,
    /// Largest |q̇|, rad/s (`velocity`); `None` when not given.
    pub velocity: Option<f64>,
    /// Largest |τ|, N m (`effort`); `None` when not given.
    pub effort: Option<f64>,
    /// `<dynamics damping>`, N m s/rad (0 when absent).
    pub damping: f64,
    /// `<dynamics friction>`, Coulomb friction, N m (0 when absent).
    pub friction: f64,
}

impl JointLimits {
    fn from_urdf(joint: &urdf_rs::Joint) -> Self {
        let l = &joint.limit;
        let given = |x: f64| (x.is_finite() && x > 0.0).then_some(x);
        let position = (joint.joint_type != urdf_rs::JointType::Continuous
            && l.lower.is_finite()
            && l.upper.is_finite()
            && l.lower < l.upper)
            .then_some((l.lower, l.upper));
        let (damping, friction) = joint.dynamics.as_ref().map_or((0.0, 0.0), |d| (d.damping, d.friction));
        JointLimits { position, velocity: given(l.velocity), effort: given(l.effort), damping, friction }
    }
}

/// A named URDF link frame, attached to a body (or the world for `None`).
#[derive(Clone, Debug)]
pub struct Frame {
    pub name: String,
    pub body: Option<usize>,
    /// Placement of this frame in the body frame.
    pub x_body_frame: Isometry3<f64>,
}

/// A URDF joint as written in the file, kept for publishing `/tf`.
#[derive(Clone, Debug)]
pub struct UrdfJoint {
    pub name: String,
    pub parent_link: String,
    pub child_link: String,
    /// The joint origin in the parent link frame.
    pub origin: Isometry3<f64>,
    /// The dof index for a revolute joint, `None` for a fixed one.
    pub dof: Option<usize>,
}

/// The read-only description of a robot: built once, shared as `&Model`.
#[derive(Clone, Debug)]
pub struct Model {
    pub name: String,
    /// Name of the URDF root link, fixed to the world at the identity.
    pub root_link: String,
    /// Number of degrees of freedom (= bodies = revolute joints).
    pub nv: usize,
    pub bodies: Vec<Body>,
    /// Every URDF link, in file order.
    pub frames: Vec<Frame>,
    /// Every URDF joint, in file order.
    pub urdf_joints: Vec<UrdfJoint>,
    /// Gravitational acceleration in the world frame, m/s^2.
    pub gravity: Vector3<f64>,
}

fn pose(p: &urdf_rs::Pose) -> Isometry3<f64> {
    let [x, y, z] = p.xyz.0;
    let [r, pi, ya] = p.rpy.0;
    // URDF rpy: fixed-axis roll about x, then pitch about y, then yaw about z: R = Rz Ry Rx
    Isometry3::from_parts(Translation3::new(x, y, z), UnitQuaternion::from_euler_angles(r, pi, ya))
}

fn finite3(v: &[f64; 3]) -> bool {
    v.iter().all(|x| x.is_finite())
}

impl Model {
    /// Build a model from URDF text. `source` names the file in error messages.
    pub fn from_urdf(xml: &str, source: &str, gravity: Vector3<f64>) -> Result<Model, ModelError> {
        let file = source.to_string();
        // the XML reader recurses once per nesting level: bound the depth before it runs
        // and count the joints and links, so that too many are refused before parsing
        let shape = xml_shape(xml, MAX_URDF_DEPTH);
        if shape.depth > MAX_URDF_DEPTH {
            return Err(ModelError::TooDeep { file, limit: MAX_URDF_DEPTH });
        }
        if shape.joints > MAX_URDF_JOINTS {
            return Err(ModelError::TooMany { file, items: "joints", count: shape.joints, limit: MAX_URDF_JOINTS });
        }
        if shape.links > MAX_URDF_JOINTS + 1 {
            return Err(ModelError::TooMany { file, items: "links", count: shape.links, limit: MAX_URDF_JOINTS + 1 });
        }
        let robot = urdf_rs::read_from_string(xml)
            .map_err(|e| ModelError::Parse { file: file.clone(), message: e.to_string() })?;
        if robot.joints.len() > MAX_URDF_JOINTS {
            return Err(ModelError::TooMany { file, items: "joints", count: robot.joints.len(), limit: MAX_URDF_JOINTS });
        }
        if robot.links.len() > MAX_URDF_JOINTS + 1 {
            return Err(ModelError::TooMany { file, items: "links", count: robot.links.len(), limit: MAX_URDF_JOINTS + 1 });
        }

        let mut link_index = HashMap::new();
        for (i, link) in robot.links.iter().enumerate() {
            if link_index.insert(link.name.as_str(), i).is_some() {
                return Err(ModelError::BadValue {
                    file, item: "link", name: link.name.clone(), field: "name", value: link.name.clone(),
                    why: "defined twice",
                });
            }
        }
        // joint names are the keys of the recorded tables: each once
        let mut joint_names = std::collections::HashSet::new();
        for joint in &robot.joints {
            if !joint_names.insert(joint.name.as_str()) {
                return Err(ModelError::BadValue {
                    file, item: "joint", name: joint.name.clone(), field: "name", value: joint.name.clone(),
                    why: "defined twice",
                });
            }
        }
        // validate the links' inertias
        for link in &robot.links {
            validate_inertial(&file, link)?;
        }
        // joints: types, endpoints, one parent per link
        let mut parent_joint: Vec<Option<usize>> = vec![None; robot.links.len()];
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); robot.links.len()];
        for (ji, joint) in robot.joints.iter().enumerate() {
            match joint.joint_type {
                urdf_rs::JointType::Revolute | urdf_rs::JointType::Continuous | urdf_rs::JointType::Fixed => {}
                ref other => {
                    return Err(ModelError::UnsupportedJoint {
                        file, joint: joint.name.clone(), kind: format!("{other:?}").to_lowercase(),
                    })
                }
            }
            let lookup = |name: &str| {
                link_index.get(name).copied().ok_or_else(|| ModelError::MissingLink {
                    file: file.clone(), joint: joint.name.clone(), link: name.to_string(),
                })
            };
            let p = lookup(&joint.parent.link)?;
            let c = lookup(&joint.child.link)?;
            if let Some(first) = parent_joint[c] {
                return Err(ModelError::Loop {
                    file, link: joint.child.link.clone(), first: robot.joints[first].name.clone(),
                    second: joint.name.clone(),
                });
            }
            parent_joint[c] = Some(ji);
            children[p].push(ji);
            if !finite3(&joint.origin.xyz.0) || !finite3(&joint.origin.rpy.0) {
                return Err(ModelError::BadValue {
                    file, item: "joint", name: joint.name.clone(), field: "origin",
                    value: format!("{:?} {:?}", joint.origin.xyz.0, joint.origin.rpy.0), why: "must be finite",
                });
            }
            let axis = Vector3::from(joint.axis.xyz.0);
            if joint.joint_type != urdf_rs::JointType::Fixed && !(axis.norm() > 1e-9 && finite3(&joint.axis.xyz.0)) {
                return Err(ModelError::BadValue {
                    file, item: "joint", name: joint.name.clone(), field: "axis",
                    value: format!("{:?}", joint.axis.xyz.0), why: "must be a finite non-zero vector",
                });
            }
        }
        let roots: Vec<usize> = (0..robot.links.len()).filter(|&i| parent_joint[i].is_none()).collect();
        if roots.len() != 1 {
            return Err(ModelError::Roots { file, roots: roots.iter().map(|&i| robot.links[i].name.clone()).collect() });
        }
        let root = roots[0];

        // depth-first, pre-order from the root: a parent body gets a lower index than its children
        let mut bodies: Vec<Body> = Vec::new();
        let mut attach: Vec<Option<(Option<usize>, Isometry3<f64>)>> = vec![None; robot.links.len()];
        let mut dof_of_joint: Vec<Option<usize>> = vec![None; robot.joints.len()];
        // (link, body it hangs from, placement of the link's joint frame in that body)
        let mut stack: Vec<(usize, Option<usize>, Isometry3<f64>)> = vec![(root, None, Isometry3::identity())];
        while let Some((l, parent_body, x_body_joint)) = stack.pop() {
            let here = match parent_joint[l] {
                Some(ji) if robot.joints[ji].joint_type != urdf_rs::JointType::Fixed => {
                    let joint = &robot.joints[ji];
                    let idx = bodies.len();
                    dof_of_joint[ji] = Some(idx);
                    bodies.push(Body {
                        link: robot.links[l].name.clone(),
                        joint: joint.name.clone(),
                        parent: parent_body,
                        x_parent_joint: x_body_joint,
                        axis: Unit::new_normalize(Vector3::from(joint.axis.xyz.0)),
                        inertia: Inertia::zero(),
                        limits: JointLimits::from_urdf(joint),
                    });
                    (Some(idx), Isometry3::identity())
                }
                _ => (parent_body, x_body_joint),
            };
            attach[l] = Some(here);
            // push in reverse so that children are visited in file order
            for &ji in children[l].iter().rev() {
                let joint = &robot.joints[ji];
                let c = link_index[joint.child.link.as_str()];
                stack.push((c, here.0, here.1 * pose(&joint.origin)));
            }
        }
        // links never reached from the root sit on a closed loop of joints
        if let Some(l) = attach.iter().position(|a| a.is_none()) {
            let ji = parent_joint[l].unwrap_or(0);
            return Err(ModelError::Loop {
                file, link: robot.links[l].name.clone(), first: robot.joints[ji].name.clone(),
                second: "(a closed chain not connected to the root)".into(),
            });
        }

        // frames and merged inertias
        let mut frames = Vec::with_capacity(robot.links.len());
        for (i, link) in robot.links.iter().enumerate() {
            let Some((body, x_body_frame)) = attach[i] else { continue };
            frames.push(Frame { name: link.name.clone(), body, x_body_frame });
            if let Some(b) = body {
                let inertial = &link.inertial;
                let x_link_inertial = pose(&inertial.origin);
                let ii = &inertial.inertia;
                let i_inertial = Matrix3::new(ii.ixx, ii.ixy, ii.ixz, ii.ixy, ii.iyy, ii.iyz, ii.ixz, ii.iyz, ii.izz);
                let r = x_link_inertial.rotation.to_rotation_matrix();
                let i_link = Inertia::from_com(
                    inertial.mass.value,
                    x_link_inertial.translation.vector,
                    r * i_inertial * r.transpose(),
                );
                bodies[b].inertia = bodies[b].inertia.add(&i_link.to_parent(&x_body_frame));
            }
        }
        if bodies.is_empty() {
            return Err(ModelError::NoJoints { file });
        }
        let urdf_joints = robot
            .joints
            .iter()
            .enumerate()
            .map(|(ji, j)| UrdfJoint {
                name: j.name.clone(),
                parent_link: j.parent.link.clone(),
                child_link: j.child.link.clone(),
                origin: pose(&j.origin),
                dof: dof_of_joint[ji],
            })
            .collect();
        Ok(Model {
            name: robot.name.clone(),
            root_link: robot.links[root].name.clone(),
            nv: bodies.len(),
            bodies,
            frames,
            urdf_joints,
            gravity,
        })
    }

    /// Index of the dof driven by the joint called `name`.
    pub fn dof_of_joint(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.joint == name)
    }

    /// The frame of the URDF link called `name`.
    pub fn frame(&self, name: &str) -> Option<&Frame> {
        self.frames.iter().find(|f| f.name == name)
    }

    /// Names of the revolute joints in dof order.
    pub fn joint_names(&self) -> Vec<String> {
        self.bodies.iter().map(|b| b.joint.clone()).collect()
    }

    /// Placement of body `i` in its parent at joint angle `q_i` (RBDA §4.1, `X_J X_T`).
    #[inline]
    pub fn joint_placement(&self, i: usize, q_i: f64) -> Isometry3<f64> {
        let b = &self.bodies[i];
        b.x_parent_joint * UnitQuaternion::from_axis_angle(&b.axis, q_i)
    }

    /// Total mass of the moving bodies, kg.
    pub fn total_mass(&self) -> f64 {
        self.bodies.iter().map(|b| b.inertia.mass).sum()
    }
}

fn validate_inertial(file: &str, link: &urdf_rs::Link) -> Result<(), ModelError> {
    let bad = |field: &'static str, value: String, why: &'static str| ModelError::BadValue {
        file: file.to_string(), item: "link", name: link.name.clone(), field, value, why,
    };
    let m = link.inertial.mass.value;
    if !(m.is_finite() && m >= 0.0) {
        return Err(bad("inertial/mass", m.to_string(), "must be finite and >= 0"));
    }
    let ii = &link.inertial.inertia;
    let vals = [ii.ixx, ii.ixy, ii.ixz, ii.iyy, ii.iyz, ii.izz];
    if vals.iter().any(|v| !v.is_finite()) {
        return Err(bad("inertial/inertia", format!("{vals:?}"), "must be finite"));
    }
    if m == 0.0 && vals.iter().any(|&v| v != 0.0) {
        return Err(bad("inertial/mass", m.to_string(), "zero mass with a non-zero inertia is not a physical body"));
    }
    if !finite3(&link.inertial.origin.xyz.0) || !finite3(&link.inertial.origin.rpy.0) {
        return Err(bad("inertial/origin", format!("{:?}", link.inertial.origin.xyz.0), "must be finite"));
    }
    let i = Matrix3::new(ii.ixx, ii.ixy, ii.ixz, ii.ixy, ii.iyy, ii.iyz, ii.ixz, ii.iyz, ii.izz);
    let eig = i.symmetric_eigenvalues();
    let scale = eig.iter().fold(0.0f64, |a, b| a.max(b.abs())).max(f64::MIN_POSITIVE);
    let (a, b, c) = (eig[0], eig[1], eig[2]);
    let tol = 1e-9 * scale;
    if eig.iter().any(|&e| e < -tol) {
        return Err(bad(
            "inertial/inertia",
            format!("ixx={} ixy={} ixz={} iyy={} iyz={} izz={}", ii.ixx, ii.ixy, ii.ixz, ii.iyy, ii.iyz, ii.izz),
            "is not positive semi-definite",
        ));
    }
    if a + b < c - tol || a + c < b - tol || b + c < a - tol {
        return Err(bad(
            "inertial/inertia",
            format!("principal moments {a}, {b}, {c}"),
            "violates the triangle inequality of a physical body",
        ));
    }
    Ok(())
}
