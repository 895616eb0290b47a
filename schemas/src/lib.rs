//! The recording format shared by `sim` (writer) and `analyze` (reader).
//!
//! This crate is the one place that knows how a run is stored, so the two never disagree:
//! topic names ([`topics`]), message structs and their schemas ([`messages`], [`cdr`]), the
//! time convention ([`to_log_time`]), the writer ([`RecordingWriter`]) and a generic,
//! schema-driven reader ([`read_recording`]) that decodes any protobuf / ROS 2 CDR / JSON
//! channel from the schema stored in the file. It also owns how every file the tools write
//! appears under its name: atomically, complete, with one writer at a time ([`atomic`]).
//!
//! # Conventions
//! - A recording is one MCAP file (<https://mcap.dev/spec>), zstd-compressed chunks.
//! - Time: `log_time` = simulated time in ns from t = 0 ([`to_log_time`]); every message's own
//!   timestamp (`time` field, header stamp, Foxglove `timestamp`) equals it.
//! - SI units everywhere; arrays are indexed by actuated joint (0-based, URDF order of the
//!   revolute joints) or by constraint; positions in the world frame unless a frame is named.
//! - Which encoding for which topic follows `../shared/VIEWERS.md` (the workplace notes beside the repository) so that recordings open
//!   in both Foxglove and Rerun: URDF and joint states as ROS 2 CDR, transforms and point
//!   clouds as Foxglove protobuf schemas, our own signals as derived protobuf.
//! - Metadata records are typed ([`meta`]): [`RecordingInfo`] carries [`FORMAT_VERSION`]; bump the
//!   version whenever a message struct or a metadata record changes its fields.
//!
//! # References
//! - MCAP format and well-known encodings: <https://mcap.dev/spec>, <https://mcap.dev/spec/registry>.
//! - CDR: OMG "Common Object Request Broker Architecture", Part 2, §9.3 (CDR), and
//!   DDS-XTypes 1.3 §7.4.3 (XCDR1 encapsulation); ROS 2 uses it through Fast-CDR.
//! - Foxglove schemas: <https://docs.foxglove.dev/docs/visualization/message-schemas/>.

pub mod atomic;
pub mod cdr;
pub mod error;
mod flat;
pub mod messages;
pub mod layout;
pub mod markers;
pub mod meta;
pub mod reader;
mod ros2msg;
#[cfg(feature = "synth")]
pub mod synth;
pub mod topics;
pub mod reference;
pub mod units;
pub mod value;
pub mod writer;

pub use error::Error;
pub use messages::{
    frame_transform, hand_points, set_hand_points, timestamp, HAND_ACTUAL_RGBA, HAND_DESIRED_RGBA, ConstraintState, EnergyState, HandState, JointState,
    Message, MotorState, MotorThermalState, Quat, RosString, TopicMessage, TransformEntry, Transforms, Vec3, contact_event_kind, contact_mode, ContactEventMsg, ContactFriction, ContactState, SupplyState, CONTACT_EVENT_KINDS,
};
pub use meta::{
    AuditBounds, ContactAudit, ContactAuditRecord, ContactAuditor, ContactLaws, Worst, ContactInfo, ContactShapeInfo, ContactsRecord, EnergyTermsRecord, IntegratorInfo, LimitEventInfo, LimitsRecord, MetadataRecord, ModelInfo, RecordingInfo,
    RunDescription, RunInfo, RunNames, RunResult, RunStatus, SceneRecord, Setup, UrdfRecord,
};
pub use reader::{
    open_regular, starts_with_mcap_magic, read_recording, read_recording_bytes, read_recording_bytes_topics, read_recording_recover,
    read_recording_recover_bytes, read_recording_topics, stream_recording, stream_recording_recover,
    ArraySizes, Body, ChannelInfo, DecodedMessage, Known, Recording, RecoverReport, Tap, Tapped, Visitor, MAX_RECORD_BYTES,
    NOT_SELECTED,
};
#[cfg(feature = "synth")]
pub use reader::regroup_chunks;
pub use value::Value;
pub use writer::{Compression, Mirror, RecordingWriter, WriterOptions};

/// Foxglove's generated message types (all of them, e.g. `SceneUpdate`).
pub use foxglove::messages as foxglove_messages;
pub use foxglove::messages::{
    FrameTransform, FrameTransforms, PackedElementField, PointCloud, Pose, Quaternion, Timestamp,
    Vector3,
};

/// Version of the recording layout (topics, message fields, metadata keys). Stored in the
/// metadata record `recording` ([`RecordingInfo`]); [`meta`] lists what each version holds.
///
/// History: 0 had no `run.joint_names`; 1 added them; 2 added `/energy`
/// `gear_friction_loss` (the D_m part of the friction loss); 3 added the names of the arrays
/// inside `/motors`, `/energy` and `/constraints` (`name`), each channel's units (MCAP channel
/// metadata `units`, [`units`]) and the scene topics for the viewers ([`topics::SCENE`],
/// [`topics::CONTACT_MARKERS`]).
pub const FORMAT_VERSION: u32 = 3;

/// Simulated seconds -> log time in ns, rounded to nearest. Negative times and NaN give 0,
/// times beyond ~584 years saturate at `u64::MAX`.
pub fn to_log_time(t_s: f64) -> u64 {
    // `as` saturates and maps NaN to 0
    (t_s * 1e9).round() as u64
}

/// Log time in ns -> simulated seconds (the nearest f64; exact in ns below 2^53 ns ≈ 104 days).
pub fn from_log_time(ns: u64) -> f64 {
    ns as f64 / 1e9
}

// the sim may hand the writer to a recording thread, analyze may read on a worker thread
const _: () = {
    const fn send<T: Send>() {}
    send::<RecordingWriter>();
    send::<Recording>();
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_time_rounds_to_nearest_and_round_trips() {
        assert_eq!(to_log_time(0.0), 0);
        assert_eq!(to_log_time(1e-3), 1_000_000);
        assert_eq!(to_log_time(0.1 + 0.2), 300_000_000); // 0.30000000000000004 s
        assert_eq!(to_log_time(1.4e-9), 1);
        assert_eq!(to_log_time(1.6e-9), 2);
        assert_eq!(to_log_time(-1.0), 0);
        assert_eq!(to_log_time(f64::NAN), 0);
        // ns -> s -> ns is exact over a simulation-sized range (tolerance: 0 ns)
        for ns in (0..10_000_000_000_000u64)
            .step_by(999_999_937)
            .chain([1, 7, 123_456_789_012])
        {
            assert_eq!(to_log_time(from_log_time(ns)), ns, "ns = {ns}");
        }
        // s -> ns -> s is within half a ns
        for k in 0..1000 {
            let t = k as f64 * 0.0123456789;
            assert!(
                (from_log_time(to_log_time(t)) - t).abs() <= 0.5e-9 + 1e-15 * t,
                "t = {t}"
            );
        }
    }
}
