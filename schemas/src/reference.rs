//! The reference page of the recording format (the docs book's `reference/topics.md`),
//! generated from this crate's own definitions so that it cannot drift from what is written:
//! the topics ([`crate::topics`]), the message type of each with its schema name and encodings
//! ([`crate::Message`]), its fields read from the very schema stored in every file (the
//! protobuf `FileDescriptorSet`, or the ROS 2 `.msg` text), their units ([`crate::units`]) and
//! what their arrays are indexed by ([`crate::topics::array_index`]). A test of the root
//! package compares the committed page with [`topics_markdown`] (`ELBOW_BLESS=1` rewrites it).
//!
//! Formats followed: MCAP and its well-known encodings (<https://mcap.dev/spec/registry>),
//! protobuf descriptors (<https://protobuf.dev/reference/protobuf/descriptor/>), ROS 2 `.msg`
//! (<https://docs.ros.org/en/rolling/Concepts/Basic/About-Interfaces.html>).

use std::fmt::Write as _;

use foxglove::messages as fm;
use prost_reflect::{Cardinality, DescriptorPool, Kind};

use crate::messages::{ConstraintState, ContactEventMsg, ContactFriction, ContactState, EnergyState, HandState, JointState, Message, MotorState, MotorThermalState, RosString, SupplyState};
use crate::topics::{self, ArrayIndex};
use crate::units;

/// One topic as the page describes it.
struct TopicDoc {
    topic: &'static str,
    /// Which recordings have it, and how often it is written.
    when: &'static str,
    /// What it carries, in one sentence.
    what: &'static str,
    schema_name: String,
    schema_encoding: &'static str,
    message_encoding: &'static str,
    schema_data: Vec<u8>,
}

fn doc<M: Message>(topic: &'static str, when: &'static str, what: &'static str) -> TopicDoc {
    TopicDoc {
        topic,
        when,
        what,
        schema_name: M::schema_name(),
        schema_encoding: M::schema_encoding(),
        message_encoding: M::message_encoding(),
        schema_data: M::schema_data(),
    }
}

/// Every topic a recording can have, in the order a recording registers them.
fn topic_docs() -> Vec<TopicDoc> {
    const EVERY: &str = "every recording, every sample";
    const CONTACTS: &str = "runs with a unilateral or compliant contact, at each event";
    const CONTACTS_EVERY: &str = "runs with a unilateral or compliant contact, every sample";
    vec![
        doc::<RosString>(topics::ROBOT_DESCRIPTION, "every recording, once at t = 0", "the URDF (XML text) of the robot that ran"),
        doc::<fm::FrameTransforms>(topics::TF, EVERY, "world → base link and every URDF joint's transform (fixed joints included)"),
        doc::<JointState>(topics::JOINT_STATES, EVERY, "joint angles q, velocities q̇ and efforts τ (eq 12) of the actuated joints"),
        doc::<MotorState>(topics::MOTORS, EVERY, "each motor's current, voltage, back-EMF, electric power and torque on its link"),
        doc::<ConstraintState>(topics::CONSTRAINTS, EVERY, "per bilateral contact: normal force, constraint C and its rate Ċ (empty arrays without one)"),
        doc::<HandState>(topics::HAND, EVERY, "the hand's actual and desired position and their difference, world frame"),
        doc::<EnergyState>(topics::ENERGY, EVERY, "the energy balance, cumulative from t = 0: W_j, E_j, stored energies, losses, residual"),
        doc::<fm::PointCloud>(topics::HAND_POINTS, EVERY, "the actual and desired hand as two coloured points (Foxglove's rgba fields)"),
        doc::<ContactState>(topics::CONTACTS, CONTACTS_EVERY, "per contact: mode, gap, gap rate, normal and friction force, slip velocity, cumulative losses"),
        doc::<ContactEventMsg>(topics::CONTACT_EVENTS, CONTACTS, "one message per contact event (lift-off, touch-down, impact, rest, stick ↔ slip), at its time"),
        doc::<ContactFriction>(
            topics::CONTACT_FRICTION,
            "runs with a unilateral or compliant contact whose friction coefficient μ > 0, every sample",
            "per contact: slip speed ‖v_t‖, friction use ‖f_t‖/(μ f_n) (0 where μ f_n = 0: separated, frictionless or bilateral) and mode, for plots",
        ),
        doc::<SupplyState>(topics::SUPPLY, "runs whose scene has a `supply`, every sample", "the supply's power, the bus power, and the energy delivered, regenerated, dumped and lost, cumulative"),
        doc::<MotorThermalState>(
            topics::MOTOR_TEMPERATURES,
            "runs with the motors' thermal model (scene `thermal`), every sample",
            "per motor: winding and housing temperature, winding resistance R(T_w), copper loss",
        ),
        doc::<fm::SceneUpdate>(topics::SCENE, "every recording (format ≥ 3), once at t = 0", "the table (each contact plane) and the hand's target path, for 3D panels"),
        doc::<fm::SceneUpdate>(
            topics::CONTACT_MARKERS,
            "every recording (format ≥ 3), every sample",
            "markers of the contacts that touch, coloured by mode (a contact that separates is deleted in that sample's message and absent while it stays separated), contact forces as arrows, the actual and desired hand",
        ),
    ]
}

/// One field of a schema: its name, its type as the schema says it, whether it is an array.
struct Field {
    name: String,
    ty: String,
    repeated: bool,
}

/// The top-level fields of `d`'s schema, read from the schema bytes stored in every file.
fn fields(d: &TopicDoc) -> Vec<Field> {
    match d.schema_encoding {
        "protobuf" => {
            let pool = DescriptorPool::decode(d.schema_data.as_slice()).expect("our schemas decode");
            let msg = pool.get_message_by_name(&d.schema_name).expect("the schema names its message");
            msg.fields()
                .map(|f| Field {
                    name: f.name().to_string(),
                    ty: match f.kind() {
                        Kind::Message(m) => m.full_name().to_string(),
                        Kind::Enum(e) => e.full_name().to_string(),
                        k => format!("{k:?}").to_lowercase(),
                    },
                    repeated: f.cardinality() == Cardinality::Repeated && !f.is_map(),
                })
                .collect()
        }
        _ => {
            // ros2msg: the main definition is the text before the first `===` separator line
            let text = String::from_utf8_lossy(&d.schema_data).into_owned();
            text.lines()
                .take_while(|l| !l.starts_with("==="))
                .map(|l| l.split('#').next().unwrap_or("").trim())
                .filter(|l| !l.is_empty() && !l.contains('='))
                .filter_map(|l| {
                    let mut it = l.split_whitespace();
                    let (ty, name) = (it.next()?, it.next()?);
                    let repeated = ty.contains('[');
                    let base = ty.split('[').next().unwrap_or(ty);
                    Some(Field { name: name.to_string(), ty: base.to_string(), repeated })
                })
                .collect()
        }
    }
}

/// The unit of `field` of `topic` (the unit of each entry for an array), or of a nested field
/// under it (`actual` of `/hand` has `actual.x` … in m), from [`units::fields`].
fn unit_of(topic: &str, field: &str) -> String {
    let table = units::fields(topic);
    if let Some((_, u)) = table.iter().find(|(f, _)| *f == field) {
        return (*u).to_string();
    }
    let prefix = format!("{field}.");
    let mut nested: Vec<String> = Vec::new();
    for (f, u) in table {
        if let Some(rest) = f.strip_prefix(&prefix) {
            let entry = format!("{rest}: {u}");
            if !nested.contains(&entry) {
                nested.push(entry);
            }
        }
    }
    nested.join(", ")
}

fn index_of(topic: &str, field: &str, repeated: bool) -> &'static str {
    match topics::array_index(topic, field) {
        Some(ArrayIndex::Joint) if repeated => "per joint",
        Some(ArrayIndex::Contact) if repeated => "per contact",
        _ if repeated => "list",
        _ => "",
    }
}

/// The page: a summary table of every topic, then one section per topic with its fields.
pub fn topics_markdown() -> String {
    let docs = topic_docs();
    let mut s = String::new();
    s.push_str("<!-- generated from the schemas crate (schemas::reference::topics_markdown): do not edit; ELBOW_BLESS=1 cargo test --all-features --test e2e docs rewrites it -->\n\n");
    s.push_str("# Recording topics and units\n\n");
    let _ = writeln!(
        s,
        "Every recording is one MCAP file. Its `log_time` is the simulated time in ns from t = 0, on the scene's output grid \
         (1 kHz by default) whatever the integrator's steps; every message's own time field equals it. Units are SI with \
         radians; every channel also carries its units in its MCAP metadata (`units`, a JSON object field → unit). Arrays are \
         indexed per actuated joint (URDF order, named by the message's `name` list and the `run` record's `joint_names`) or \
         per contact (the `run` record's `contacts`). This page is generated from the `schemas` crate, which writes and reads \
         every file (recording format version {}).\n",
        crate::FORMAT_VERSION
    );
    s.push_str("| topic | written in | schema | encoding | what |\n|---|---|---|---|---|\n");
    for d in &docs {
        let _ = writeln!(
            s,
            "| [`{}`](#{}) | {} | `{}` | {} / {} | {} |",
            d.topic,
            anchor(d.topic),
            d.when,
            d.schema_name,
            d.schema_encoding,
            d.message_encoding,
            d.what
        );
    }
    for d in &docs {
        let _ = writeln!(s, "\n## {}\n", d.topic);
        let _ = writeln!(s, "{}. Schema `{}` ({}), messages in {}; written in {}.\n", capitalise(d.what), d.schema_name, d.schema_encoding, d.message_encoding, d.when);
        if d.schema_name.starts_with("foxglove.") {
            let _ = writeln!(
                s,
                "A Foxglove well-known schema: <https://docs.foxglove.dev/docs/visualization/message-schemas/{}>.\n",
                kebab(d.schema_name.trim_start_matches("foxglove."))
            );
        }
        s.push_str("| field | type | array | unit |\n|---|---|---|---|\n");
        for f in fields(d) {
            let _ = writeln!(s, "| `{}` | `{}` | {} | {} |", f.name, f.ty, index_of(d.topic, &f.name, f.repeated), unit_of(d.topic, &f.name));
        }
    }
    s
}

/// mdBook's anchor of a heading made of `text` (lower case, spaces to `-`, other punctuation
/// but `-` and `_` dropped).
fn anchor(text: &str) -> String {
    text.chars()
        .filter_map(|c| match c {
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c.to_ascii_lowercase()),
            ' ' => Some('-'),
            _ => None,
        })
        .collect()
}

fn capitalise(s: &str) -> String {
    let mut c = s.chars();
    c.next().map(|f| f.to_uppercase().collect::<String>() + c.as_str()).unwrap_or_default()
}

/// `SceneUpdate` → `scene-update` (the Foxglove docs' page names).
fn kebab(s: &str) -> String {
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if c.is_uppercase() && i > 0 {
            out.push('-');
        }
        out.push(c.to_ascii_lowercase());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_topic_and_every_unit_is_on_the_page() {
        let page = topics_markdown();
        for t in topics::ALL.iter().chain(&topics::CONTACT_TOPICS).chain(&topics::VIEWER_TOPICS).chain(&topics::THERMAL_TOPICS).chain(&topics::SUPPLY_TOPICS).chain(&topics::FRICTION_TOPICS) {
            assert!(page.contains(&format!("\n## {t}\n")), "{t} has no section");
        }
        // every unit of the units table appears on its topic's section
        for d in topic_docs() {
            let section = page.split(&format!("\n## {}\n", d.topic)).nth(1).unwrap().split("\n## ").next().unwrap().to_string();
            for (field, unit) in units::fields(d.topic) {
                assert!(section.contains(unit), "{} {field}: unit {unit} not in its section", d.topic);
            }
            assert!(!fields(&d).is_empty(), "{}: no fields read from its schema", d.topic);
        }
    }

    #[test]
    fn fields_come_from_the_stored_schemas() {
        let motors = topic_docs().into_iter().find(|d| d.topic == topics::MOTORS).unwrap();
        let f = fields(&motors);
        let current = f.iter().find(|f| f.name == "current").unwrap();
        assert!(current.repeated && current.ty == "double", "{} {}", current.ty, current.repeated);
        let joints = topic_docs().into_iter().find(|d| d.topic == topics::JOINT_STATES).unwrap();
        let f = fields(&joints);
        assert_eq!(f.iter().map(|f| f.name.as_str()).collect::<Vec<_>>(), ["header", "name", "position", "velocity", "effort"]);
        assert_eq!(index_of(topics::JOINT_STATES, "position", true), "per joint");
        assert_eq!(unit_of(topics::HAND, "actual"), "x: m, y: m, z: m");
        assert_eq!(anchor("/contact_events"), "contact_events");
        assert_eq!(kebab("SceneUpdate"), "scene-update");
    }
}
