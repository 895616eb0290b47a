//! Topic names of a recording and the message type each one carries.
//!
//! The layout follows `../shared/VIEWERS.md` (the workplace notes beside the repository) ("A recipe that worked in both"): the URDF and
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

/// [`crate::ContactState`]: mode, gap, forces, slip and cumulative losses per contact. Only in
/// runs with a non-bilateral contact ([`CONTACT_TOPICS`]); not in [`ALL`].
pub const CONTACTS: &str = "/contacts";
/// [`crate::ContactEventMsg`]: one message per contact event, at the event time. Only in runs
/// with a non-bilateral contact; not in [`ALL`].
pub const CONTACT_EVENTS: &str = "/contact_events";

/// [`crate::ContactFriction`]: per contact (the entries of `/contacts`) the slip speed |v_t|, the
/// friction use |f_t|/(μ f_n) and the mode, every sample: what Foxglove's plots cannot combine
/// from `/contacts` (a plot series is one field). Only in runs with a unilateral or compliant
/// contact whose friction coefficient μ is above 0 ([`FRICTION_TOPICS`]); not in [`ALL`], so a
/// run without friction (the paper's bilateral ones) writes nothing new.
pub const CONTACT_FRICTION: &str = "/contact_friction";
/// The topics only runs with a frictional non-bilateral contact have, registered after
/// [`CONTACT_TOPICS`].
pub const FRICTION_TOPICS: [&str; 1] = [CONTACT_FRICTION];

/// [`crate::SupplyState`]: the supply's power and energies (delivered, regenerated, dumped,
/// lost). Only in runs whose scene has a `supply` ([`SUPPLY_TOPICS`]); not in [`ALL`].
pub const SUPPLY: &str = "/supply";
/// The topics only runs with a `supply` have.
pub const SUPPLY_TOPICS: [&str; 1] = [SUPPLY];

/// [`crate::MotorThermalState`]: each motor's winding and housing temperature, winding
/// resistance and copper loss. Only in runs whose scene turns the thermal model on
/// ([`THERMAL_TOPICS`]); not in [`ALL`].
pub const MOTOR_TEMPERATURES: &str = "/motor_temperatures";

/// The topics only runs with the motors' thermal model have, registered after the others.
pub const THERMAL_TOPICS: [&str; 1] = [MOTOR_TEMPERATURES];

/// `foxglove.SceneUpdate`, written once at t = 0: what does not move in the run, for the 3D
/// panels of Foxglove (Rerun draws it from its own `.rrd`, `analyze view`): the table (each
/// contact plane), the target path of the hand. Since format version 3.
pub const SCENE: &str = "/scene";
/// `foxglove.SceneUpdate`, every sample: per contact a marker at the contact point coloured by
/// its mode and an arrow of the contact force (a pulling bilateral force drawn distinctly), and
/// the actual and desired hand as spheres coloured apart. Since format version 3.
pub const CONTACT_MARKERS: &str = "/contact_markers";

/// The topics written once, at t = 0 (what does not change in a run: the URDF, the table and
/// the target path): a live viewer that connects after they were sent must still get them
/// (`sim --live` sends them again to every new subscriber, as ROS latches such topics).
pub const LATCHED: [&str; 2] = [ROBOT_DESCRIPTION, SCENE];
/// The scene topics for the viewers, written by every recording since format version 3 (older
/// files lack them); not in [`ALL`].
pub const VIEWER_TOPICS: [&str; 2] = [SCENE, CONTACT_MARKERS];

/// The topics only runs with a non-bilateral (unilateral or compliant) contact have, in the
/// order they are registered (after [`ALL`]).
pub const CONTACT_TOPICS: [&str; 2] = [CONTACTS, CONTACT_EVENTS];

/// Every topic every recording has (the ones above but [`CONTACT_TOPICS`]), in the order a recording normally registers them.
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
    /// One entry per actuated joint ([`crate::RunDescription::joint_names`]).
    Joint,
    /// One entry per contact ([`crate::RunDescription::contacts`]).
    Contact,
}

impl ArrayIndex {
    /// The names of the entries, in array order.
    pub fn names(self, run: &crate::RunDescription) -> &[String] {
        match self {
            ArrayIndex::Joint => &run.joint_names,
            ArrayIndex::Contact => &run.contacts,
        }
    }
}

/// Whether the array `field` of `topic` must always be recorded. The others may be empty in a
/// message (not recorded by a producer, e.g. the voltages of an older test file); when present
/// they have one entry per joint or contact like the rest.
pub fn array_required(topic: &str, field: &str) -> bool {
    matches!(
        (topic, field),
        (MOTORS, "current") | (ENERGY, "link_work" | "electric_energy") | (CONSTRAINTS, "normal_force" | "position" | "velocity")
            | (CONTACTS, "name" | "mode" | "gap" | "gap_rate" | "normal_force")
            | (CONTACT_FRICTION, "name" | "mode" | "slip_speed" | "friction_use")
    )
}

/// The field of a message that names the entries of its sibling arrays
/// (`sensor_msgs/JointState`'s `name`: `position[k]` is joint `name[k]`).
pub const LABEL_LIST_FIELD: &str = "name";

/// The label an entry of a list gives itself, for tools that expand lists into named columns:
/// a `foxglove.FrameTransform` is named by its child frame (`/tf`: `transforms.link3.…`).
pub fn entry_label(item: &crate::Value) -> Option<&str> {
    item.get("child_frame_id").and_then(crate::Value::as_str).filter(|s| !s.is_empty())
}

/// The index of the array `field` of messages on `topic`, for the arrays of [`MOTORS`],
/// [`ENERGY`], [`JOINT_STATES`], [`CONSTRAINTS`] and [`CONTACTS`]; `None` for anything else.
pub fn array_index(topic: &str, field: &str) -> Option<ArrayIndex> {
    match (topic, field) {
        (MOTORS, "current" | "voltage" | "back_emf" | "electric_power" | "torque" | "name")
        | (ENERGY, "link_work" | "electric_energy" | "name") => Some(ArrayIndex::Joint),
        (CONSTRAINTS, "normal_force" | "position" | "velocity" | "name") => Some(ArrayIndex::Contact),
        (
            CONTACTS,
            "name" | "mode" | "gap" | "gap_rate" | "normal_force" | "friction_force_t1" | "friction_force_t2" | "slip_velocity_t1"
            | "slip_velocity_t2" | "impact_loss" | "friction_work" | "damping_loss",
        ) => Some(ArrayIndex::Contact),
        (CONTACT_FRICTION, "name" | "mode" | "slip_speed" | "friction_use") => Some(ArrayIndex::Contact),
        (JOINT_STATES, "position" | "velocity" | "effort") => Some(ArrayIndex::Joint),
        (MOTOR_TEMPERATURES, "winding_temperature" | "housing_temperature" | "resistance" | "copper_loss" | "name") => Some(ArrayIndex::Joint),
        _ => None,
    }
}
