//! Topic names of a recording and the message type each one carries.
//!
//! The layout follows `/work/shared/VIEWERS.md` ("A recipe that worked in both"): the URDF and
//! the joint states as ROS 2 CDR (which Foxglove and Rerun both understand natively), transforms
//! and the hand point cloud as Foxglove well-known protobuf schemas, our own signals as derived
//! protobuf messages.

/// [`crate::RosString`] (`std_msgs/msg/String`, cdr): the URDF XML, written once at t = 0.
/// The name must contain `robot_description` for Rerun to build URDF geometry.
pub const ROBOT_DESCRIPTION: &str = "/robot_description";
/// [`crate::FrameTransforms`] (`foxglove.FrameTransforms`): `world -> base link` plus one
/// transform per URDF joint (fixed joints included), every output tick.
pub const TF: &str = "/tf";
/// [`crate::JointState`] (`sensor_msgs/msg/JointState`, cdr): actuated joints in URDF order.
pub const JOINT_STATES: &str = "/joint_states";
/// [`crate::MotorState`]: per-actuator electrical and mechanical signals.
pub const MOTORS: &str = "/motors";
/// [`crate::ConstraintState`]: per-constraint force and residuals.
pub const CONSTRAINTS: &str = "/constraints";
/// [`crate::HandState`]: hand position actual / desired / error, world frame.
pub const HAND: &str = "/hand";
/// [`crate::EnergyState`]: cumulative energy bookkeeping.
pub const ENERGY: &str = "/energy";
/// [`crate::PointCloud`] (`foxglove.PointCloud`): actual and desired hand as 2 points.
pub const HAND_POINTS: &str = "/hand_points";

/// Every topic above, in the order a recording normally registers them.
pub const ALL: [&str; 8] = [
    ROBOT_DESCRIPTION,
    TF,
    JOINT_STATES,
    MOTORS,
    CONSTRAINTS,
    HAND,
    ENERGY,
    HAND_POINTS,
];

/// What the entries of an array field of our topics stand for (readers label columns with it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ArrayIndex {
    /// One entry per actuated joint, names in metadata `run.joint_names` (a JSON list).
    Joint,
    /// One entry per contact, names in metadata `run.contacts` (a JSON list).
    Contact,
}

impl ArrayIndex {
    /// The metadata record and key holding the names, as a JSON list of strings.
    pub fn names_key(self) -> (&'static str, &'static str) {
        match self {
            ArrayIndex::Joint => ("run", "joint_names"),
            ArrayIndex::Contact => ("run", "contacts"),
        }
    }
}

/// The index of the array `field` of messages on `topic`, for the arrays of [`MOTORS`],
/// [`ENERGY`] and [`CONSTRAINTS`]; `None` for anything else.
pub fn array_index(topic: &str, field: &str) -> Option<ArrayIndex> {
    match (topic, field) {
        (MOTORS, "current" | "voltage" | "back_emf" | "electric_power" | "torque")
        | (ENERGY, "link_work" | "electric_energy") => Some(ArrayIndex::Joint),
        (CONSTRAINTS, "normal_force" | "position" | "velocity") => Some(ArrayIndex::Contact),
        _ => None,
    }
}
