//! The read-only [`Model`]: a kinematic tree of revolute and prismatic joints built from a URDF
//! (read by [`super::urdf`]).
//!
//! Fixed joints are folded into their parent body (their inertia is merged, their frame kept
//! as a [`Frame`]), as pinocchio does; each remaining body has exactly one degree of freedom,
//! revolute (q in rad) or prismatic (q in m), so body index = dof index = index into `q`.
//! Bodies are ordered so that a parent comes before its children (RBDA §4.1.2, "regular
//! numbering"). A joint's motion subspace in its own frame is `S = [a; 0]` for a revolute
//! joint about the unit axis a and `S = [0; a]` for a prismatic one (RBDA §4.4, Table 4.1).
//!
//! A joint listed in [`UrdfOptions::locked`] becomes fixed at the given value: its child is
//! welded to its parent with the joint's transform at that value. A `<mimic>` joint is locked
//! at `multiplier · value + offset` when its leader is locked; a mimic joint whose leader
//! moves is refused with what to do (the coupling q_f = m q_l + o as a constraint is not
//! modelled): the choice is recorded in [`Model::mimics`].
//!
//! Inertias are checked (finite, positive semi-definite, triangle inequality of the principal
//! moments, as a physical body must satisfy: Traversaro, Brossette, Escande and Nori, "Identification
//! of fully physical consistent inertial parameters using optimization on manifolds", IROS 2016)
//! only on links that move: a link welded to the world never enters the dynamics. With
//! [`UrdfOptions::repair_inertia`] an implausible one is replaced by the nearest plausible one
//! with the same principal axes (see [`repair_principal_moments`]) and reported in
//! [`Model::repaired_inertias`].
//!
//! Conventions: SI units, radians; `x_a_b: Isometry3` maps frame-b coordinates to frame a.
//! The URDF root link is fixed to the world frame at the identity.

use std::collections::{BTreeMap, HashMap};

use nalgebra::{Isometry3, Matrix3, Translation3, Unit, UnitQuaternion, Vector3};

use super::spatial::{Inertia, Motion};
use super::urdf::{self, element, UrdfDoc, UrdfJointElem, UrdfJointType, UrdfLink, UrdfPose};
use crate::error::ModelError;
use crate::limits::{xml_shape, MAX_URDF_DEPTH, MAX_URDF_JOINTS};

/// The kind of a body's degree of freedom.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum JointKind {
    /// Rotation about the axis (URDF `revolute` or `continuous`); q in rad.
    #[default]
    Revolute,
    /// Translation along the axis (URDF `prismatic`); q in m.
    Prismatic,
}

/// One moving body: the link after a movable joint plus everything welded to it.
#[derive(Clone, Debug)]
pub struct Body {
    /// URDF link name of the body frame (= the joint frame).
    pub link: String,
    /// URDF name of the joint that moves this body.
    pub joint: String,
    /// Revolute or prismatic.
    pub kind: JointKind,
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

impl Body {
    /// The motion subspace S in body coordinates: `[a; 0]` (revolute) or `[0; a]` (prismatic).
    #[inline]
    pub fn subspace(&self) -> Motion {
        match self.kind {
            JointKind::Revolute => Motion::new(self.axis.into_inner(), Vector3::zeros()),
            JointKind::Prismatic => Motion::new(Vector3::zeros(), self.axis.into_inner()),
        }
    }

    /// `x · X_J(q)`: the placement `x` of the joint frame followed by the joint's motion.
    #[inline]
    pub fn after(&self, x: &Isometry3<f64>, q: f64) -> Isometry3<f64> {
        match self.kind {
            JointKind::Revolute => x * UnitQuaternion::from_axis_angle(&self.axis, q),
            JointKind::Prismatic => x * Translation3::from(self.axis.into_inner() * q),
        }
    }

    /// The joint transform `X_J(q)`: rotation by q about the axis, or translation by q along it.
    #[inline]
    pub fn joint_motion(&self, q: f64) -> Isometry3<f64> {
        joint_motion(self.kind, &self.axis, q)
    }
}

fn joint_motion(kind: JointKind, axis: &Unit<Vector3<f64>>, q: f64) -> Isometry3<f64> {
    match kind {
        JointKind::Revolute => Isometry3::from_parts(Translation3::identity(), UnitQuaternion::from_axis_angle(axis, q)),
        JointKind::Prismatic => Isometry3::from_parts(Translation3::from(axis.into_inner() * q), UnitQuaternion::identity()),
    }
}

/// A joint's URDF `<limit>` and `<dynamics>` elements (ROS URDF spec, `joint` element), as
/// read. The limits are watched in every run and enforced only as soft stops when a scene asks
/// (`joint_limits`); `damping` and `friction` are read but do not enter the dynamics (a scene
/// gives its joints' viscous friction as `joint_damping`). A zero range, speed or
/// effort (or an absent attribute) means "not given" and reads as `None`. Units follow the
/// joint: rad, rad/s, N m for a revolute joint; m, m/s, N for a prismatic one.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct JointLimits {
    /// `(lower, upper)`, rad (m); `None` for a continuous joint or when `lower = upper`.
    pub position: Option<(f64, f64)>,
    /// Largest |q̇|, rad/s (m/s) (`velocity`); `None` when not given.
    pub velocity: Option<f64>,
    /// Largest |τ|, N m (N) (`effort`); `None` when not given.
    pub effort: Option<f64>,
    /// `<dynamics damping>`, N m s/rad (N s/m) (0 when absent).
    pub damping: f64,
    /// `<dynamics friction>`, Coulomb friction, N m (N) (0 when absent).
    pub friction: f64,
}

impl JointLimits {
    fn from_urdf(joint: &UrdfJointElem) -> Self {
        let l = joint.limit.unwrap_or_default();
        let given = |x: Option<f64>| x.filter(|x| x.is_finite() && *x > 0.0);
        let position = match (l.lower, l.upper) {
            (Some(lo), Some(hi)) if joint.kind != UrdfJointType::Continuous && lo.is_finite() && hi.is_finite() && lo < hi => {
                Some((lo, hi))
            }
            _ => None,
        };
        JointLimits { position, velocity: given(l.velocity), effort: given(l.effort), damping: joint.damping, friction: joint.friction }
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
    /// The joint origin in the parent link frame (a locked joint's transform at its value
    /// included).
    pub origin: Isometry3<f64>,
    /// The dof index for a moving joint, `None` for a fixed or locked one.
    pub dof: Option<usize>,
}

/// Options of [`Model::from_urdf_with`] (the scene's `"robot"` object).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct UrdfOptions {
    /// Joints made fixed at a value (rad or m): joint name → value.
    pub locked: BTreeMap<String, f64>,
    /// Replace implausible inertias of moving links by the nearest plausible ones.
    pub repair_inertia: bool,
    /// The scene field that holds these options, for messages (e.g. `robot`).
    pub field: String,
}

/// What became of a URDF `<mimic>` joint.
#[derive(Clone, Debug, PartialEq)]
pub struct Mimic {
    pub follower: String,
    pub leader: String,
    pub multiplier: f64,
    pub offset: f64,
    /// The value the follower is locked at (`multiplier · leader value + offset`, or the
    /// scene's own value when the scene locks the follower itself).
    pub locked_at: f64,
}

/// An inertia replaced by [`UrdfOptions::repair_inertia`].
#[derive(Clone, Debug, PartialEq)]
pub struct InertiaRepair {
    pub link: String,
    /// Principal moments about the centre of mass before and after, kg m^2, ascending.
    pub before: [f64; 3],
    pub after: [f64; 3],
}

/// The read-only description of a robot: built once, shared as `&Model`.
#[derive(Clone, Debug)]
pub struct Model {
    pub name: String,
    /// Name of the URDF root link, fixed to the world at the identity.
    pub root_link: String,
    /// Number of degrees of freedom (= bodies = moving joints).
    pub nv: usize,
    pub bodies: Vec<Body>,
    /// Every URDF link, in file order.
    pub frames: Vec<Frame>,
    /// Every URDF joint, in file order.
    pub urdf_joints: Vec<UrdfJoint>,
    /// Gravitational acceleration in the world frame, m/s^2.
    pub gravity: Vector3<f64>,
    /// Joints made fixed at load, with their values (the scene's and the mimic followers').
    pub locked: Vec<(String, f64)>,
    /// The `<mimic>` joints and what became of them (each is locked; see the module docs).
    pub mimics: Vec<Mimic>,
    /// Inertias replaced at load (`repair_inertia`).
    pub repaired_inertias: Vec<InertiaRepair>,
}

fn pose(p: &UrdfPose) -> Isometry3<f64> {
    let [x, y, z] = p.xyz;
    let [r, pi, ya] = p.rpy;
    // URDF rpy: fixed-axis roll about x, then pitch about y, then yaw about z: R = Rz Ry Rx
    Isometry3::from_parts(Translation3::new(x, y, z), UnitQuaternion::from_euler_angles(r, pi, ya))
}

/// `x y z` as in a URDF attribute.
fn v3(v: &[f64; 3]) -> String {
    format!("{} {} {}", v[0], v[1], v[2])
}

fn finite3(v: &[f64; 3]) -> bool {
    v.iter().all(|x| x.is_finite())
}

fn at(file: &str, line: usize, element: String, why: impl Into<String>) -> ModelError {
    ModelError::At { file: file.to_string(), line, element, why: why.into() }
}

fn joint_elem(j: &UrdfJointElem) -> String {
    element("joint", Some(&j.name))
}

impl Model {
    /// Build a model from URDF text with no options. `source` names the file in errors.
    pub fn from_urdf(xml: &str, source: &str, gravity: Vector3<f64>) -> Result<Model, ModelError> {
        Self::from_urdf_with(xml, source, gravity, &UrdfOptions::default())
    }

    /// Build a model from URDF text. `source` names the file in errors; `options` locks joints
    /// and repairs inertias (module docs).
    pub fn from_urdf_with(xml: &str, source: &str, gravity: Vector3<f64>, options: &UrdfOptions) -> Result<Model, ModelError> {
        let file = source.to_string();
        // bound the depth and count the joints and links before parsing
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
        let doc = urdf::parse(xml, source)?;
        Self::from_doc(&doc, source, gravity, options)
    }

    /// Build a model from a parsed URDF.
    pub fn from_doc(doc: &UrdfDoc, source: &str, gravity: Vector3<f64>, options: &UrdfOptions) -> Result<Model, ModelError> {
        let file = source.to_string();
        if doc.joints.len() > MAX_URDF_JOINTS {
            return Err(ModelError::TooMany { file, items: "joints", count: doc.joints.len(), limit: MAX_URDF_JOINTS });
        }
        if doc.links.len() > MAX_URDF_JOINTS + 1 {
            return Err(ModelError::TooMany { file, items: "links", count: doc.links.len(), limit: MAX_URDF_JOINTS + 1 });
        }
        let mut link_index: HashMap<&str, usize> = HashMap::new();
        for (i, link) in doc.links.iter().enumerate() {
            if let Some(first) = link_index.insert(link.name.as_str(), i) {
                return Err(at(&file, link.line, element("link", Some(&link.name)), format!(
                    "defined twice (first on line {}); link names must be unique: rename one", doc.links[first].line
                )));
            }
        }
        // joint names are the keys of the recorded tables: each once
        let mut joint_index: HashMap<&str, usize> = HashMap::new();
        for (i, joint) in doc.joints.iter().enumerate() {
            if let Some(first) = joint_index.insert(joint.name.as_str(), i) {
                return Err(at(&file, joint.line, joint_elem(joint), format!(
                    "defined twice (first on line {}); joint names must be unique: rename one", doc.joints[first].line
                )));
            }
        }

        // the values of locked joints: the scene's, then mimic followers of locked leaders
        let field = if options.field.is_empty() { "robot" } else { options.field.as_str() };
        let opt_err = |name: &str, value: String, why: String| ModelError::Option {
            file: file.clone(), field: format!("{field}.locked.{name}"), value, why,
        };
        let mut locked: BTreeMap<&str, f64> = BTreeMap::new();
        for (name, &value) in &options.locked {
            let Some(&ji) = joint_index.get(name.as_str()) else {
                let names: Vec<&str> = doc.joints.iter().filter(|j| j.kind != UrdfJointType::Fixed).map(|j| j.name.as_str()).collect();
                return Err(opt_err(name, crate::error::short(value), format!("the URDF has no joint of that name (its movable joints: {})", names.join(", "))));
            };
            let j = &doc.joints[ji];
            if !value.is_finite() {
                return Err(opt_err(name, value.to_string(), "must be a finite number (rad, or m for a prismatic joint)".into()));
            }
            match j.kind {
                UrdfJointType::Fixed => {
                    return Err(opt_err(name, crate::error::short(value), "the joint is fixed already: remove it from the list".into()))
                }
                UrdfJointType::Floating | UrdfJointType::Planar if value != 0.0 => {
                    return Err(opt_err(name, crate::error::short(value), format!("a {} joint is locked at its origin: give 0", j.kind.as_str())))
                }
                _ => {}
            }
            if let Some((lo, hi)) = JointLimits::from_urdf(j).position {
                if value < lo - 1e-12 || value > hi + 1e-12 {
                    return Err(opt_err(name, crate::error::short(value), format!("outside the joint's <limit> [{lo}, {hi}] (line {})", j.line)));
                }
            }
            locked.insert(j.name.as_str(), value);
        }
        let mut mimics = Vec::new();
        loop {
            let mut changed = false;
            for j in &doc.joints {
                let Some(m) = &j.mimic else { continue };
                if j.kind == UrdfJointType::Fixed || mimics.iter().any(|x: &Mimic| x.follower == j.name) {
                    continue;
                }
                if let Some(&own) = locked.get(j.name.as_str()) {
                    mimics.push(Mimic { follower: j.name.clone(), leader: m.leader.clone(), multiplier: m.multiplier, offset: m.offset, locked_at: own });
                    changed = true;
                } else if let Some(&v) = locked.get(m.leader.as_str()) {
                    let value = m.multiplier * v + m.offset;
                    if let Some((lo, hi)) = JointLimits::from_urdf(j).position {
                        if value < lo - 1e-12 || value > hi + 1e-12 {
                            return Err(opt_err(
                                &m.leader,
                                crate::error::short(v),
                                format!("locks its mimic follower `{}` at {} = {} * {v} + {}, outside the follower's <limit> [{lo}, {hi}] (line {})", j.name, crate::error::short(value), m.multiplier, m.offset, j.line),
                            ));
                        }
                    }
                    locked.insert(j.name.as_str(), value);
                    mimics.push(Mimic { follower: j.name.clone(), leader: m.leader.clone(), multiplier: m.multiplier, offset: m.offset, locked_at: value });
                    changed = true;
                }
            }
            if !changed {
                break;
            }
        }

        // joints: types, endpoints, one parent per link, the placement of each child
        let mut parent_joint: Vec<Option<usize>> = vec![None; doc.links.len()];
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); doc.links.len()];
        let mut kinds: Vec<Option<JointKind>> = vec![None; doc.joints.len()];
        let mut origins: Vec<Isometry3<f64>> = Vec::with_capacity(doc.joints.len());
        let hint = |j: &UrdfJointElem| format!("\"{field}\": {{\"locked\": {{\"{}\": 0.0}}}}", j.name);
        for (ji, joint) in doc.joints.iter().enumerate() {
            let is_locked = locked.contains_key(joint.name.as_str());
            let kind = match joint.kind {
                UrdfJointType::Revolute | UrdfJointType::Continuous => Some(JointKind::Revolute),
                UrdfJointType::Prismatic => Some(JointKind::Prismatic),
                UrdfJointType::Fixed => None,
                UrdfJointType::Floating | UrdfJointType::Planar => {
                    if !is_locked {
                        return Err(at(&file, joint.line, joint_elem(joint), format!(
                            "type=\"{}\": only fixed-base arms are modelled; make the joint type=\"fixed\", or lock it at its origin in the scene: {}",
                            joint.kind.as_str(), hint(joint)
                        )));
                    }
                    None
                }
            };
            if let (Some(m), false) = (&joint.mimic, is_locked) {
                if kind.is_some() {
                    let leader_exists = joint_index.contains_key(m.leader.as_str());
                    return Err(at(&file, m.line, format!("<joint name=\"{}\"><mimic joint=\"{}\">", joint.name, m.leader), if leader_exists {
                        format!(
                            "a mimic joint follows a moving leader, which is not modelled (one motor driving two joints); lock the leader, and the follower is locked at multiplier * value + offset with it: \"{field}\": {{\"locked\": {{\"{}\": VALUE}}}}, or lock `{}` itself",
                            m.leader, joint.name
                        )
                    } else {
                        format!("the URDF has no joint `{}` to follow; correct the name, or lock `{}` in the scene: {}", m.leader, joint.name, hint(joint))
                    }));
                }
            }
            let lookup = |name: &str, role: &str| {
                link_index.get(name).copied().ok_or_else(|| at(&file, joint.line, joint_elem(joint), format!(
                    "<{role} link=\"{name}\">: the URDF defines no link `{name}`; define it or correct the name"
                )))
            };
            let p = lookup(&joint.parent, "parent")?;
            let c = lookup(&joint.child, "child")?;
            if let Some(first) = parent_joint[c] {
                return Err(at(&file, joint.line, joint_elem(joint), format!(
                    "link `{}` is the child of both `{}` (line {}) and this joint: kinematic loops are not modelled (a URDF is a tree)",
                    joint.child, doc.joints[first].name, doc.joints[first].line
                )));
            }
            parent_joint[c] = Some(ji);
            children[p].push(ji);
            if !finite3(&joint.origin.xyz) || !finite3(&joint.origin.rpy) {
                return Err(at(&file, joint.line, joint_elem(joint), format!(
                    "<origin xyz=\"{}\" rpy=\"{}\">: must be finite", v3(&joint.origin.xyz), v3(&joint.origin.rpy)
                )));
            }
            let axis = Vector3::from(joint.axis);
            if kind.is_some() && !(finite3(&joint.axis) && axis.norm() > 1e-9) {
                return Err(at(&file, joint.line, joint_elem(joint), format!(
                    "<axis xyz=\"{}\">: must be a finite non-zero vector", v3(&joint.axis)
                )));
            }
            let origin = match (kind, locked.get(joint.name.as_str())) {
                (Some(k), Some(&v)) => pose(&joint.origin) * joint_motion(k, &Unit::new_normalize(axis), v),
                _ => pose(&joint.origin),
            };
            origins.push(origin);
            kinds[ji] = if is_locked { None } else { kind };
        }
        let roots: Vec<usize> = (0..doc.links.len()).filter(|&i| parent_joint[i].is_none()).collect();
        if roots.len() != 1 {
            return Err(ModelError::Roots { file, roots: roots.iter().map(|&i| doc.links[i].name.clone()).collect() });
        }
        let root = roots[0];

        // depth-first, pre-order from the root: a parent body gets a lower index than its children
        let mut bodies: Vec<Body> = Vec::new();
        let mut attach: Vec<Option<(Option<usize>, Isometry3<f64>)>> = vec![None; doc.links.len()];
        let mut dof_of_joint: Vec<Option<usize>> = vec![None; doc.joints.len()];
        // (link, body it hangs from, placement of the link's joint frame in that body)
        let mut stack: Vec<(usize, Option<usize>, Isometry3<f64>)> = vec![(root, None, Isometry3::identity())];
        while let Some((l, parent_body, x_body_joint)) = stack.pop() {
            let here = match parent_joint[l].and_then(|ji| kinds[ji].map(|k| (ji, k))) {
                Some((ji, kind)) => {
                    let joint = &doc.joints[ji];
                    let idx = bodies.len();
                    dof_of_joint[ji] = Some(idx);
                    bodies.push(Body {
                        link: doc.links[l].name.clone(),
                        joint: joint.name.clone(),
                        kind,
                        parent: parent_body,
                        x_parent_joint: x_body_joint,
                        axis: Unit::new_normalize(Vector3::from(joint.axis)),
                        inertia: Inertia::zero(),
                        limits: JointLimits::from_urdf(joint),
                    });
                    (Some(idx), Isometry3::identity())
                }
                None => (parent_body, x_body_joint),
            };
            attach[l] = Some(here);
            // push in reverse so that children are visited in file order
            for &ji in children[l].iter().rev() {
                let joint = &doc.joints[ji];
                let c = link_index[joint.child.as_str()];
                stack.push((c, here.0, here.1 * origins[ji]));
            }
        }
        // links never reached from the root sit on a closed loop of joints
        if let Some(l) = attach.iter().position(|a| a.is_none()) {
            let line = parent_joint[l].map_or(doc.links[l].line, |ji| doc.joints[ji].line);
            return Err(at(&file, line, element("link", Some(&doc.links[l].name)), "sits on a closed chain of joints not connected to the root: kinematic loops are not modelled"));
        }

        // frames and merged inertias; inertias are checked on moving links only
        let mut frames = Vec::with_capacity(doc.links.len());
        let mut repaired_inertias = Vec::new();
        for (i, link) in doc.links.iter().enumerate() {
            let Some((body, x_body_frame)) = attach[i] else { continue };
            frames.push(Frame { name: link.name.clone(), body, x_body_frame });
            let (Some(b), Some(inertial)) = (body, &link.inertial) else { continue };
            let i_com = checked_inertia(&file, link, options.repair_inertia, field, &mut repaired_inertias)?;
            let x_link_inertial = pose(&inertial.origin);
            let r = x_link_inertial.rotation.to_rotation_matrix();
            let i_link = Inertia::from_com(inertial.mass, x_link_inertial.translation.vector, r * i_com * r.transpose());
            bodies[b].inertia = bodies[b].inertia.add(&i_link.to_parent(&x_body_frame));
        }
        if bodies.is_empty() {
            return Err(ModelError::NoJoints { file });
        }
        let urdf_joints = doc
            .joints
            .iter()
            .enumerate()
            .map(|(ji, j)| UrdfJoint {
                name: j.name.clone(),
                parent_link: j.parent.clone(),
                child_link: j.child.clone(),
                origin: origins[ji],
                dof: dof_of_joint[ji],
            })
            .collect();
        let locked = doc.joints.iter().filter_map(|j| locked.get(j.name.as_str()).map(|&v| (j.name.clone(), v))).collect();
        Ok(Model {
            name: doc.name.clone(),
            root_link: doc.links[root].name.clone(),
            nv: bodies.len(),
            bodies,
            frames,
            urdf_joints,
            gravity,
            locked,
            mimics,
            repaired_inertias,
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

    /// Names of the moving joints in dof order.
    pub fn joint_names(&self) -> Vec<String> {
        self.bodies.iter().map(|b| b.joint.clone()).collect()
    }

    /// Placement of body `i` in its parent at joint position `q_i` (rad or m) (RBDA §4.1,
    /// `X_J X_T`).
    #[inline]
    pub fn joint_placement(&self, i: usize, q_i: f64) -> Isometry3<f64> {
        let b = &self.bodies[i];
        b.after(&b.x_parent_joint, q_i)
    }

    /// The dofs that move only massless links (no `<inertial>` mass or inertia on their body
    /// and every body after it): their row of M(q) is zero at every q, so M + J_m is regular
    /// only with a rotor on that joint (the scene checks it).
    pub fn massless_dofs(&self) -> Vec<usize> {
        let mut massive: Vec<bool> = self.bodies.iter().map(|b| b.inertia.mass != 0.0 || b.inertia.i_o != Matrix3::zeros()).collect();
        for i in (0..self.bodies.len()).rev() {
            if let (Some(p), true) = (self.bodies[i].parent, massive[i]) {
                massive[p] = true;
            }
        }
        (0..self.bodies.len()).filter(|&i| !massive[i]).collect()
    }

    /// Total mass of the moving bodies, kg.
    pub fn total_mass(&self) -> f64 {
        self.bodies.iter().map(|b| b.inertia.mass).sum()
    }
}

/// The inertia about the centre of mass of a moving link's `<inertial>`, in the inertial
/// frame, checked (and repaired when `repair`, with the repair pushed to `repairs`).
fn checked_inertia(file: &str, link: &UrdfLink, repair: bool, field: &str, repairs: &mut Vec<InertiaRepair>) -> Result<Matrix3<f64>, ModelError> {
    let Some(inertial) = &link.inertial else { return Ok(Matrix3::zeros()) };
    let elem = || format!("<link name=\"{}\"><inertial>", link.name);
    let bad = |why: String| at(file, inertial.line, elem(), why);
    let m = inertial.mass;
    if !(m.is_finite() && m >= 0.0) {
        return Err(bad(format!("<mass value=\"{m}\">: must be finite and >= 0 kg")));
    }
    let [ixx, ixy, ixz, iyy, iyz, izz] = inertial.inertia;
    let vals = inertial.inertia;
    let written = format!("ixx={ixx} ixy={ixy} ixz={ixz} iyy={iyy} iyz={iyz} izz={izz}");
    if vals.iter().any(|v| !v.is_finite()) {
        return Err(bad(format!("<inertia {written}>: must be finite")));
    }
    if m == 0.0 && vals.iter().any(|&v| v != 0.0) {
        return Err(bad(format!("<mass value=\"0\"> with <inertia {written}>: zero mass with a non-zero inertia is not a physical body; give the mass, or zero the inertia")));
    }
    if !finite3(&inertial.origin.xyz) || !finite3(&inertial.origin.rpy) {
        return Err(bad(format!("<origin xyz=\"{}\" rpy=\"{}\">: must be finite", v3(&inertial.origin.xyz), v3(&inertial.origin.rpy))));
    }
    let i = Matrix3::new(ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz);
    let eig = i.symmetric_eigen();
    let ev = eig.eigenvalues;
    // ascending order of the principal moments
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&p, &q| ev[p].total_cmp(&ev[q]));
    let lam = idx.map(|k| ev[k]);
    let scale = lam.iter().fold(0.0f64, |a, b| a.max(b.abs())).max(f64::MIN_POSITIVE);
    let tol = 1e-9 * scale;
    let [a, b, c] = lam;
    let why = if lam.iter().any(|&e| e < -tol) {
        Some(format!("<inertia {written}>: is not positive semi-definite (principal moments {a}, {b}, {c} kg m^2)"))
    } else if a + b < c - tol {
        Some(format!("<inertia {written}>: principal moments {a}, {b}, {c} kg m^2 violate the triangle inequality of a physical body (the largest exceeds the sum of the other two)"))
    } else {
        None
    };
    let Some(why) = why else { return Ok(i) };
    if !repair {
        return Err(bad(format!("{why}; correct the URDF, or set \"{field}\": {{\"repair_inertia\": true}} in the scene to use the nearest plausible inertia")));
    }
    let after = repair_principal_moments(lam);
    // the same principal axes, the repaired moments (the repair keeps their order)
    let mut d = ev;
    for (k, &p) in idx.iter().enumerate() {
        d[p] = after[k];
    }
    let fixed = eig.eigenvectors * Matrix3::from_diagonal(&d) * eig.eigenvectors.transpose();
    repairs.push(InertiaRepair { link: link.name.clone(), before: lam, after });
    Ok((fixed + fixed.transpose()) * 0.5)
}

/// The nearest (Euclidean) plausible principal moments to `lam` (ascending): negative moments
/// raised to zero, then, if the largest exceeds the sum of the other two, the projection onto
/// the plane `c = a + b` (each of a, b raised and c lowered by (c − a − b)/3). The result is
/// ascending, non-negative and satisfies the triangle inequality. (MuJoCo's `balanceinertia`
/// instead sets all three to their mean.)
pub fn repair_principal_moments(lam: [f64; 3]) -> [f64; 3] {
    let [mut a, mut b, mut c] = lam.map(|x| x.max(0.0));
    if c > a + b {
        let d = (c - a - b) / 3.0;
        a += d;
        b += d;
        c -= d;
    }
    let mut out = [a, b, c];
    out.sort_by(f64::total_cmp);
    out
}

/// The repairs as one line for the recording's metadata; `None` when there are none.
pub fn repair_summary(repairs: &[InertiaRepair]) -> Option<String> {
    (!repairs.is_empty()).then(|| {
        repairs
            .iter()
            .map(|r| format!("{}: principal moments {:?} -> {:?} kg m^2", r.link, r.before, r.after))
            .collect::<Vec<_>>()
            .join("; ")
    })
}
