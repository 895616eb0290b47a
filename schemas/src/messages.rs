//! Message types of a recording and the [`Message`] trait the writer takes.
//!
//! Our own signals are protobuf produced by `#[derive(foxglove::Encode)]`: the schema is a
//! `FileDescriptorSet` generated from the struct (schema name `<lowercased struct>.<Struct>`,
//! field numbers in declaration order, so **do not reorder fields** without bumping
//! [`crate::FORMAT_VERSION`]). Every message starts with `time` (simulated s), and every array
//! is indexed by actuated joint (0-based, URDF order of the revolute joints) or by constraint.
//!
//! Transforms and the hand point cloud use Foxglove's well-known protobuf schemas
//! (<https://docs.foxglove.dev/docs/visualization/message-schemas/>), built here by
//! [`frame_transform`] and [`hand_points`]. The two ROS 2 messages, [`RosString`] and
//! [`JointState`], are hand-encoded as CDR in [`crate::cdr`].

use serde::Deserialize;

use crate::topics;
use foxglove::messages::{
    packed_element_field::NumericType, FrameTransform, PackedElementField, PointCloud, Pose,
    Quaternion, Timestamp, Vector3,
};

/// Anything that can be written to a channel.
pub trait Message {
    /// MCAP schema name, e.g. `motorstate.MotorState` or `sensor_msgs/msg/JointState`.
    fn schema_name() -> String;
    /// MCAP schema encoding (`protobuf`, `ros2msg`).
    fn schema_encoding() -> &'static str;
    /// Schema bytes: a serialized `FileDescriptorSet`, or `.msg` text.
    fn schema_data() -> Vec<u8>;
    /// MCAP message encoding (`protobuf`, `cdr`).
    fn message_encoding() -> &'static str;
    /// Appends the encoded message to `buf` (does not clear it).
    fn encode_into(&self, buf: &mut Vec<u8>);
    /// Like [`Message::encode_into`] but reports an encoder failure instead of dropping it.
    /// The writer calls this one; the default forwards to `encode_into`.
    fn try_encode_into(&self, buf: &mut Vec<u8>) -> Result<(), String> {
        self.encode_into(buf);
        Ok(())
    }
}

/// Electrical and mechanical state of every motor (topic [`crate::topics::MOTORS`]).
/// Arrays have one entry per actuated joint.
#[derive(Debug, Clone, PartialEq, Default, foxglove::Encode, Deserialize)]
pub struct MotorState {
    /// Simulated time, s.
    pub time: f64,
    /// Armature current i, A.
    pub current: Vec<f64>,
    /// Terminal voltage v, V.
    pub voltage: Vec<f64>,
    /// Back-EMF k_e·ω, V.
    pub back_emf: Vec<f64>,
    /// Electric power drawn, i·v, W.
    pub electric_power: Vec<f64>,
    /// Torque delivered to the link (after gearing and friction), N·m.
    pub torque: Vec<f64>,
    /// Joint names, in array order (= metadata `run.joint_names`), so that a viewer can label
    /// the arrays without the metadata (since format version 3; empty in older files).
    #[serde(default)]
    pub name: Vec<String>,
}

/// The motors' thermal state (topic [`crate::topics::MOTOR_TEMPERATURES`], runs with the
/// thermal model only): the two-node network of each motor (winding, housing) after the
/// datasheet's thermal data. Arrays have one entry per actuated joint (a passive joint's stay
/// at the initial temperature, with no copper loss).
#[derive(Debug, Clone, PartialEq, Default, foxglove::Encode, Deserialize)]
pub struct MotorThermalState {
    /// Simulated time, s.
    pub time: f64,
    /// Winding temperature T_w, °C.
    pub winding_temperature: Vec<f64>,
    /// Housing temperature T_h, °C.
    pub housing_temperature: Vec<f64>,
    /// Winding resistance R(T_w) = R_ref (1 + α_20 (T_w − 20)) / (1 + α_20 (T_ref − 20)), Ω.
    pub resistance: Vec<f64>,
    /// Copper loss R(T_w) i², W: the heat into the winding.
    pub copper_loss: Vec<f64>,
    /// Joint names, in array order (= metadata `run.joint_names`).
    #[serde(default)]
    pub name: Vec<String>,
}

/// State of every constraint (topic [`crate::topics::CONSTRAINTS`]), one entry per constraint.
#[derive(Debug, Clone, PartialEq, Default, foxglove::Encode, Deserialize)]
pub struct ConstraintState {
    /// Simulated time, s.
    pub time: f64,
    /// Normal (constraint) force, N.
    pub normal_force: Vec<f64>,
    /// Constraint value C(q), m.
    pub position: Vec<f64>,
    /// Constraint rate dC/dt, m/s.
    pub velocity: Vec<f64>,
    /// Contact names, in array order (= metadata `run.contacts`; since format version 3, empty
    /// in older files).
    #[serde(default)]
    pub name: Vec<String>,
}

/// A 3-vector (m unless stated otherwise).
#[derive(Debug, Clone, Copy, PartialEq, Default, foxglove::Encode, Deserialize)]
pub struct Vec3 {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

/// Hand position, world frame, m (topic [`crate::topics::HAND`]).
#[derive(Debug, Clone, PartialEq, Default, foxglove::Encode, Deserialize)]
pub struct HandState {
    /// Simulated time, s.
    pub time: f64,
    /// Where the hand is.
    pub actual: Vec3,
    /// Where the trajectory wants it.
    pub desired: Vec3,
    /// `actual - desired`.
    pub error: Vec3,
    /// `|error|`, m.
    pub error_norm: f64,
}

/// Energy bookkeeping, J, cumulative from t = 0 (topic [`crate::topics::ENERGY`]).
#[derive(Debug, Clone, PartialEq, Default, foxglove::Encode, Deserialize)]
pub struct EnergyState {
    /// Simulated time, s.
    pub time: f64,
    /// Work done by each motor on its link, ∫ τ·ω dt (one per actuated joint).
    pub link_work: Vec<f64>,
    /// Electric energy drawn by each motor, ∫ i·v dt (one per actuated joint).
    pub electric_energy: Vec<f64>,
    /// Sum of `link_work`.
    pub link_work_total: f64,
    /// Sum of `electric_energy`.
    pub electric_energy_total: f64,
    /// Kinetic energy of the links (absolute, not cumulative).
    pub kinetic: f64,
    /// Gravitational potential energy (absolute).
    pub potential: f64,
    /// Magnetic energy ½ L i² of the windings (absolute).
    pub magnetic: f64,
    /// Cumulative resistive (R i²) loss.
    pub resistive_loss: f64,
    /// Cumulative friction loss.
    pub friction_loss: f64,
    /// Energy balance residual: input − stored − dissipated (should stay ≈ 0).
    pub balance_residual: f64,
    /// The gears' part of `friction_loss`, ∫ Σ D_m q̇² dt (since format version 2; the joints'
    /// own part, ∫ Σ D q̇² dt, is `friction_loss − gear_friction_loss`). Read as 0 from older
    /// files: ask [`crate::Recording::has_gear_friction_loss`].
    #[serde(default)]
    pub gear_friction_loss: f64,
    /// Joint names of `link_work` and `electric_energy`, in array order (= metadata
    /// `run.joint_names`; since format version 3, empty in older files).
    #[serde(default)]
    pub name: Vec<String>,
}

/// The state of every contact of a run that has a non-bilateral contact (topic
/// [`crate::topics::CONTACTS`]; absent from the recordings of purely bilateral runs). Arrays
/// have one entry per contact, in the order of `name` (= metadata `run.contacts`). Sign
/// conventions: gap `g = n · p − d` (> 0 separated), normal force `f_n` (> 0 pushes the point
/// off the plane); tangential quantities in the plane's tangent basis `(t1, t2)` (world frame,
/// recorded in the `contacts` metadata record).
#[derive(Debug, Clone, PartialEq, Default, foxglove::Encode, Deserialize)]
pub struct ContactState {
    /// Simulated time, s.
    pub time: f64,
    /// Contact names, in array order.
    pub name: Vec<String>,
    /// Mode code: 0 separated, 1 sticking, 2 sliding (also frictionless in touch), 3 bilateral.
    pub mode: Vec<u32>,
    /// Gap g, m.
    pub gap: Vec<f64>,
    /// Gap rate dg/dt, m/s.
    pub gap_rate: Vec<f64>,
    /// Normal force f_n, N.
    pub normal_force: Vec<f64>,
    /// Friction force on the point along t1, N.
    pub friction_force_t1: Vec<f64>,
    /// Friction force on the point along t2, N.
    pub friction_force_t2: Vec<f64>,
    /// Slip velocity of the point relative to the plane along t1, m/s.
    pub slip_velocity_t1: Vec<f64>,
    /// Slip velocity along t2, m/s.
    pub slip_velocity_t2: Vec<f64>,
    /// Kinetic energy lost in this contact's impacts since t = 0 (rotors included), J.
    pub impact_loss: Vec<f64>,
    /// Work dissipated by this contact's friction since t = 0, `∫ −f_t · v_t dt ≥ 0`, J.
    pub friction_work: Vec<f64>,
    /// A compliant contact's damping loss since t = 0, `∫ (f_n − k δ) dδ/dt dt`, J (0 for the
    /// other models).
    pub damping_loss: Vec<f64>,
}

/// What Foxglove cannot combine from [`ContactState`] (topic
/// [`crate::topics::CONTACT_FRICTION`]; only in runs with a frictional unilateral or compliant
/// contact): per contact, in the order of `name` (= `/contacts`' and metadata `run.contacts`),
/// the slip speed, the friction use and the mode, at the same log times as `/contacts`.
/// Computed from the `/contacts` sample by [`ContactFriction::set`].
#[derive(Debug, Clone, PartialEq, Default, foxglove::Encode, Deserialize)]
pub struct ContactFriction {
    /// Simulated time, s.
    pub time: f64,
    /// Contact names, in array order (= `/contacts`' `name`).
    pub name: Vec<String>,
    /// Mode code, as `/contacts`' `mode`: 0 separated, 1 sticking, 2 sliding, 3 bilateral.
    pub mode: Vec<u32>,
    /// Slip speed |v_t| = √(v_t1² + v_t2²) of the point relative to the plane, m/s.
    pub slip_speed: Vec<f64>,
    /// Friction use |f_t| / (μ f_n), 1: how much of the Coulomb cone the friction force takes
    /// (≤ 1 sticking, 1 sliding for a rigid contact; below 1 in a compliant contact's regularised
    /// slip). 0 where μ f_n ≤ 0: a separated contact (f_n = 0, no friction force; its mode says
    /// separated), a frictionless one (μ = 0) or a bilateral one (no friction law).
    pub friction_use: Vec<f64>,
}

impl ContactFriction {
    /// This message from the `/contacts` sample `s` and each contact's friction coefficient
    /// `mu` (in `s`'s order; 0 for a frictionless or bilateral contact). The names are copied
    /// only when they differ, the arrays reused: no allocation once they have their size.
    pub fn set(&mut self, s: &ContactState, mu: &[f64]) {
        self.time = s.time;
        if self.name != s.name {
            self.name.clone_from(&s.name);
        }
        self.mode.clone_from(&s.mode);
        self.slip_speed.clear();
        self.slip_speed.extend(s.slip_velocity_t1.iter().zip(&s.slip_velocity_t2).map(|(a, b)| a.hypot(*b)));
        self.friction_use.clear();
        for k in 0..s.normal_force.len() {
            let cone = mu.get(k).copied().unwrap_or(0.0) * s.normal_force[k];
            // |f_t| only where it is used: not for a separated candidate (issue 24 item 2)
            self.friction_use.push(if cone > 0.0 {
                s.friction_force_t1.get(k).copied().unwrap_or(0.0).hypot(s.friction_force_t2.get(k).copied().unwrap_or(0.0)) / cone
            } else {
                0.0
            });
        }
    }
}

/// The electric supply behind the drives (topic [`crate::topics::SUPPLY`]; only runs whose
/// scene has a `supply`, absent from every other recording). Powers at the sample, energies
/// cumulative from t = 0; `energy = Σ E_j + dumped + loss` (E_j = ∫ i v dt of `/energy`).
#[derive(Debug, Clone, PartialEq, Default, foxglove::Encode, Deserialize)]
pub struct SupplyState {
    /// Simulated time, s.
    pub time: f64,
    /// Power the supply delivers P_s, W (< 0: it takes energy back).
    pub power: f64,
    /// The drives' DC power on the bus (or summed, without a bus) P_b, W.
    pub bus_power: f64,
    /// Energy the supply delivered, ∫ P_s dt, J.
    pub energy: f64,
    /// Energy the supply took back (regenerated), ∫ max(−P_s, 0) dt, J.
    pub regenerated: f64,
    /// Energy dumped in the drives' and the bus's brake resistors, J.
    pub dumped: f64,
    /// The supply's conversion loss, J.
    pub loss: f64,
}

/// One contact event (topic [`crate::topics::CONTACT_EVENTS`]): log time = event time, written
/// before the sample that follows the event.
#[derive(Debug, Clone, PartialEq, Default, foxglove::Encode, Deserialize)]
pub struct ContactEventMsg {
    /// Event time, s (located on the integrator's dense output).
    pub time: f64,
    /// The contact's name (metadata `run.contacts`).
    pub contact: String,
    /// `lift-off`, `touch-down`, `impact`, `rest`, `stick-to-slip` or `slip-to-stick`
    /// ([`CONTACT_EVENT_KINDS`]).
    pub kind: String,
    /// Normal impulse of an impact, N·s (0 for the other kinds).
    pub impulse: f64,
    /// Kinetic energy lost in an impact (rotors included), J (0 for the other kinds).
    pub energy_lost: f64,
    /// Gap rate just before the event, m/s.
    pub gap_rate_before: f64,
    /// Gap rate just after the event, m/s.
    pub gap_rate_after: f64,
}

/// The values of [`ContactEventMsg::kind`].
pub mod contact_event_kind {
    /// `f_n` fell to zero: the contact opens.
    pub const LIFT_OFF: &str = "lift-off";
    /// The gap closed with no approach speed: the contact closes without an impact.
    pub const TOUCH_DOWN: &str = "touch-down";
    /// The gap closed with approach speed: an impulse (Newton's restitution).
    pub const IMPACT: &str = "impact";
    /// A bouncing sequence ended (the approach speed fell below the rest velocity): a plastic
    /// impact, the contact closes.
    pub const REST: &str = "rest";
    pub const STICK_TO_SLIP: &str = "stick-to-slip";
    pub const SLIP_TO_STICK: &str = "slip-to-stick";
}

/// Every value of [`ContactEventMsg::kind`].
pub const CONTACT_EVENT_KINDS: [&str; 6] = {
    use contact_event_kind::*;
    [LIFT_OFF, TOUCH_DOWN, IMPACT, REST, STICK_TO_SLIP, SLIP_TO_STICK]
};

/// The mode codes of [`ContactState::mode`], by name.
pub mod contact_mode {
    pub const SEPARATED: u32 = 0;
    pub const STICKING: u32 = 1;
    pub const SLIDING: u32 = 2;
    pub const BILATERAL: u32 = 3;

    /// `separated`, `sticking`, `sliding`, `bilateral`, or `None` for an unknown code.
    pub fn name(code: u32) -> Option<&'static str> {
        ["separated", "sticking", "sliding", "bilateral"].get(code as usize).copied()
    }
}

/// A message type bound to the one topic that carries it, for typed reading
/// ([`crate::Recording::read`]).
pub trait TopicMessage: serde::de::DeserializeOwned {
    const TOPIC: &'static str;
}

impl TopicMessage for MotorState {
    const TOPIC: &'static str = topics::MOTORS;
}
impl TopicMessage for ConstraintState {
    const TOPIC: &'static str = topics::CONSTRAINTS;
}
impl TopicMessage for HandState {
    const TOPIC: &'static str = topics::HAND;
}
impl TopicMessage for EnergyState {
    const TOPIC: &'static str = topics::ENERGY;
}
impl TopicMessage for MotorThermalState {
    const TOPIC: &'static str = topics::MOTOR_TEMPERATURES;
}
impl TopicMessage for ContactState {
    const TOPIC: &'static str = topics::CONTACTS;
}
impl TopicMessage for ContactFriction {
    const TOPIC: &'static str = topics::CONTACT_FRICTION;
}
impl TopicMessage for SupplyState {
    const TOPIC: &'static str = topics::SUPPLY;
}
impl TopicMessage for ContactEventMsg {
    const TOPIC: &'static str = topics::CONTACT_EVENTS;
}
impl TopicMessage for JointState {
    const TOPIC: &'static str = topics::JOINT_STATES;
}
impl TopicMessage for Transforms {
    const TOPIC: &'static str = topics::TF;
}

/// A `/tf` message (`foxglove.FrameTransforms`) as read back: for readers that place geometry
/// (`analyze view`). The writer writes [`crate::FrameTransforms`]; this is its read side, by
/// field name, without the timestamps (equal to the log time).
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
pub struct Transforms {
    pub transforms: Vec<TransformEntry>,
}

/// One transform of [`Transforms`]: the pose of `child_frame_id` in `parent_frame_id`.
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
pub struct TransformEntry {
    pub parent_frame_id: String,
    pub child_frame_id: String,
    /// Position of the child frame's origin in the parent frame, m.
    pub translation: Vec3,
    /// Orientation of the child frame in the parent frame, unit quaternion.
    pub rotation: Quat,
}

/// A unit quaternion `x i + y j + z k + w` (`foxglove.Quaternion`).
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize)]
pub struct Quat {
    pub x: f64,
    pub y: f64,
    pub z: f64,
    pub w: f64,
}

/// `std_msgs/msg/String` (ROS 2, CDR). Carries the URDF on [`crate::topics::ROBOT_DESCRIPTION`].
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct RosString {
    pub data: String,
}

/// `sensor_msgs/msg/JointState` (ROS 2, CDR), for [`crate::topics::JOINT_STATES`].
/// The header stamp is `stamp_ns` (ns since t = 0, normally equal to the log time).
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(from = "JointStateWire")]
pub struct JointState {
    /// Header stamp, ns (split into `sec`/`nanosec` on the wire; saturates at i32::MAX s).
    pub stamp_ns: u64,
    /// Header frame id (may be empty).
    pub frame_id: String,
    /// Joint names (URDF joint names).
    pub name: Vec<String>,
    /// rad.
    pub position: Vec<f64>,
    /// rad/s.
    pub velocity: Vec<f64>,
    /// N·m.
    pub effort: Vec<f64>,
}

/// `sensor_msgs/msg/JointState` as decoded from CDR (`.msg` field names).
#[derive(Deserialize)]
struct JointStateWire {
    header: HeaderWire,
    name: Vec<String>,
    position: Vec<f64>,
    velocity: Vec<f64>,
    effort: Vec<f64>,
}

#[derive(Deserialize)]
struct HeaderWire {
    stamp: TimeWire,
    frame_id: String,
}

#[derive(Deserialize)]
struct TimeWire {
    sec: i64,
    nanosec: u64,
}

impl From<JointStateWire> for JointState {
    fn from(w: JointStateWire) -> Self {
        let ns = u64::try_from(w.header.stamp.sec).unwrap_or(0).saturating_mul(1_000_000_000).saturating_add(w.header.stamp.nanosec);
        JointState { stamp_ns: ns, frame_id: w.header.frame_id, name: w.name, position: w.position, velocity: w.velocity, effort: w.effort }
    }
}

/// Encodes a protobuf [`foxglove::Encode`] message into a growable buffer.
fn encode_protobuf<T: foxglove::Encode>(msg: &T, buf: &mut Vec<u8>) -> Result<(), String> {
    if let Some(n) = msg.encoded_len() {
        buf.reserve(n);
    }
    msg.encode(buf).map_err(|e| e.to_string())
}

fn protobuf_schema<T: foxglove::Encode>() -> Option<foxglove::Schema> {
    T::get_schema()
}

/// The schema half of [`Message`] for a protobuf type (its schema from [`foxglove::Encode`]),
/// shared by [`protobuf_message`] and [`flat_message`].
macro_rules! protobuf_schema_methods {
    ($t:ty) => {
        fn schema_name() -> String {
            protobuf_schema::<$t>().map(|s| s.name).unwrap_or_default()
        }
        fn schema_encoding() -> &'static str {
            "protobuf"
        }
        fn schema_data() -> Vec<u8> {
            protobuf_schema::<$t>().map(|s| s.data.into_owned()).unwrap_or_default()
        }
        fn message_encoding() -> &'static str {
            "protobuf"
        }
    };
}

/// Implements [`Message`] for protobuf types that implement [`foxglove::Encode`].
macro_rules! protobuf_message {
    ($($t:ty),* $(,)?) => {$(
        impl Message for $t {
            protobuf_schema_methods!($t);
            fn encode_into(&self, buf: &mut Vec<u8>) {
                // a Vec grows on demand, so the encoder has no failure mode here;
                // the writer uses try_encode_into, which does report one
                let _ = encode_protobuf(self, buf);
            }
            fn try_encode_into(&self, buf: &mut Vec<u8>) -> Result<(), String> {
                encode_protobuf(self, buf)
            }
        }
    )*};
}

protobuf_message!(MotorState, Vec3, HandState, EnergyState, ContactEventMsg, MotorThermalState, SupplyState);

/// Implements [`Message`] for the protobuf types whose encoding is hand-written in
/// `flat.rs` (the derive's bytes, in one pass: their size grows with a run's contacts).
macro_rules! flat_message {
    ($($t:ty => $encode:path),* $(,)?) => {$(
        impl Message for $t {
            protobuf_schema_methods!($t);
            fn encode_into(&self, buf: &mut Vec<u8>) {
                $encode(self, buf);
            }
        }
    )*};
}

flat_message!(
    ContactState => crate::flat::contact_state,
    ContactFriction => crate::flat::contact_friction,
    ConstraintState => crate::flat::constraint_state,
);

// every Foxglove well-known schema, so `sim` can record any of them without touching this crate
use foxglove::messages as fm;
protobuf_message!(
    fm::ArrowPrimitive,
    fm::CameraCalibration,
    fm::CircleAnnotation,
    fm::Color,
    fm::CompressedImage,
    fm::CompressedPointCloud,
    fm::CompressedVideo,
    fm::CubePrimitive,
    fm::CylinderPrimitive,
    fm::FrameTransform,
    fm::FrameTransforms,
    fm::GeoJson,
    fm::Grid,
    fm::ImageAnnotations,
    fm::JointState,
    fm::JointStates,
    fm::KeyValuePair,
    fm::LaserScan,
    fm::LinePrimitive,
    fm::LocationFix,
    fm::LocationFixes,
    fm::Log,
    fm::ModelPrimitive,
    fm::Odometry,
    fm::PackedElementField,
    fm::Point2,
    fm::Point3,
    fm::Point3InFrame,
    fm::PointCloud,
    fm::PointsAnnotation,
    fm::Pose,
    fm::PoseInFrame,
    fm::PosesInFrame,
    fm::Quaternion,
    fm::RawImage,
    fm::SceneEntity,
    fm::SceneEntityDeletion,
    fm::SceneUpdate,
    fm::SpherePrimitive,
    fm::TextAnnotation,
    fm::TextPrimitive,
    fm::TriangleListPrimitive,
    fm::Vector2,
    fm::Vector3,
    fm::VoxelGrid,
);

/// A Foxglove timestamp for `t_ns` nanoseconds since t = 0 (saturates past u32::MAX s).
pub fn timestamp(t_ns: u64) -> Timestamp {
    let sec = t_ns / 1_000_000_000;
    let nsec = (t_ns % 1_000_000_000) as u32;
    match u32::try_from(sec) {
        Ok(sec) => Timestamp::new(sec, nsec),
        Err(_) => Timestamp::MAX,
    }
}

/// One `parent -> child` transform at `t_ns`: `translation` in m (parent frame), rotation as a
/// unit quaternion `[x, y, z, w]` (child orientation in the parent frame).
pub fn frame_transform(
    t_ns: u64,
    parent: &str,
    child: &str,
    translation: [f64; 3],
    rotation_xyzw: [f64; 4],
) -> FrameTransform {
    let [x, y, z] = translation;
    let [qx, qy, qz, qw] = rotation_xyzw;
    FrameTransform {
        timestamp: Some(timestamp(t_ns)),
        parent_frame_id: parent.to_string(),
        child_frame_id: child.to_string(),
        translation: Some(Vector3 { x, y, z }),
        rotation: Some(Quaternion {
            x: qx,
            y: qy,
            z: qz,
            w: qw,
        }),
    }
}

/// Bytes per point of [`hand_points`]: x, y, z as little-endian float64, then red, green,
/// blue, alpha as uint8.
pub const HAND_POINT_STRIDE: u32 = 28;

/// The colour of the actual hand's point, RGBA bytes (purple `#9467bd`, [`crate::markers::colors`]).
pub const HAND_ACTUAL_RGBA: [u8; 4] = [0x94, 0x67, 0xbd, 255];
/// The colour of the desired hand's point, RGBA bytes (orange `#ff7f0e`).
pub const HAND_DESIRED_RGBA: [u8; 4] = [0xff, 0x7f, 0x0e, 255];

/// A `foxglove.PointCloud` of `points` (position in `frame_id`, m; colour as RGBA bytes) at
/// `t_ns`. The colour is in the four uint8 fields `red`, `green`, `blue`, `alpha`: Foxglove's 3D
/// panel colours a point cloud that has these four fields by them (its "RGBA (separate fields)"
/// colour mode, chosen automatically: `autoSelectColorSettings` / `hasSeparateRgbaFields` in
/// `packages/suite-base/src/panels/ThreeDeeRender/renderables/colorMode.ts` of the open-source
/// Foxglove Studio, now Lichtblick; integer fields are normalised by 255, `PointClouds.ts`).
pub fn hand_points(t_ns: u64, frame_id: &str, points: &[([f64; 3], [u8; 4])]) -> PointCloud {
    let field = |name: &str, offset: u32, t: NumericType| PackedElementField {
        name: name.to_string(),
        offset,
        r#type: t as i32,
    };
    let mut cloud = PointCloud {
        timestamp: None,
        frame_id: frame_id.to_string(),
        pose: Some(Pose {
            position: Some(Vector3 {
                x: 0.0,
                y: 0.0,
                z: 0.0,
            }),
            orientation: Some(Quaternion {
                x: 0.0,
                y: 0.0,
                z: 0.0,
                w: 1.0,
            }),
        }),
        point_stride: HAND_POINT_STRIDE,
        fields: vec![
            field("x", 0, NumericType::Float64),
            field("y", 8, NumericType::Float64),
            field("z", 16, NumericType::Float64),
            field("red", 24, NumericType::Uint8),
            field("green", 25, NumericType::Uint8),
            field("blue", 26, NumericType::Uint8),
            field("alpha", 27, NumericType::Uint8),
        ],
        data: Default::default(),
    };
    set_hand_points(&mut cloud, t_ns, points);
    cloud
}

/// Moves the points of a cloud made by [`hand_points`] to `points` at `t_ns`: the frame, pose
/// and fields are kept, so a recorder builds the cloud once and pays one allocation per sample
/// (the point bytes) instead of one per field name.
pub fn set_hand_points(cloud: &mut PointCloud, t_ns: u64, points: &[([f64; 3], [u8; 4])]) {
    let mut data = Vec::with_capacity(points.len() * HAND_POINT_STRIDE as usize);
    for (p, rgba) in points {
        for c in p {
            data.extend_from_slice(&c.to_le_bytes());
        }
        data.extend_from_slice(rgba);
    }
    cloud.timestamp = Some(timestamp(t_ns));
    cloud.data = data.into();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derived_schema_names_follow_the_derive_convention() {
        assert_eq!(MotorState::schema_name(), "motorstate.MotorState");
        assert_eq!(HandState::schema_name(), "handstate.HandState");
        assert_eq!(
            fm::FrameTransforms::schema_name(),
            "foxglove.FrameTransforms"
        );
        assert!(!EnergyState::schema_data().is_empty());
    }

    #[test]
    fn timestamp_splits_and_saturates() {
        let t = timestamp(3_000_000_007);
        assert_eq!((t.sec(), t.nsec()), (3, 7));
        assert_eq!(timestamp(u64::MAX), Timestamp::MAX);
    }

    #[test]
    fn hand_points_packs_little_endian_f64() {
        let pc = hand_points(5, "world", &[([1.0, 2.0, 3.0], HAND_ACTUAL_RGBA), ([4.0, 5.0, -6.5], HAND_DESIRED_RGBA)]);
        assert_eq!(pc.data.len(), 56);
        assert_eq!(&pc.data[28 + 16..28 + 24], &(-6.5f64).to_le_bytes());
        assert_eq!(&pc.data[24..28], &HAND_ACTUAL_RGBA);
        assert_eq!(&pc.data[52..56], &HAND_DESIRED_RGBA);
        assert_eq!(pc.fields[2].offset, 16);
        let names: Vec<&str> = pc.fields.iter().map(|f| f.name.as_str()).collect();
        assert_eq!(names, ["x", "y", "z", "red", "green", "blue", "alpha"]);
    }
}
