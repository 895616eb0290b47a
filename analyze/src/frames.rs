//! Any recording -> polars DataFrames, one per topic (feature `tables`); `export.rs` writes them
//! as Parquet or CSV, wide (as here) or long (`frames/long.rs`).
//!
//! The frames are built from the generic reader ([`schemas::read_recording`]), so every channel
//! is decoded through the schema stored in the file, not through this program's message types:
//! recordings written by older versions of the tool load as they were written (a field an old
//! version did not have is simply not a column). Each frame has
//!
//! - [`TIME_COLUMN`] `time`: the sample's time in s, the message's log time (simulated time,
//!   [`schemas::from_log_time`]: whole nanoseconds, so the times of every topic of a run are
//!   equal where the samples are, and tables join on it), Float64. It is the only time column:
//!   a message's own `time` field (our signals) and a `sec` + `nanosec` stamp (`header.stamp`
//!   of `/joint_states`) are left out when they are that same time at every message (they are,
//!   in every recording `sim` writes); a field that differs is kept (`time_field` for `time`);
//! - one column per field, arrays expanded per entry and named by joint, contact, frame or
//!   index (the rule is in `frames/flatten.rs`): `current.joint4`, `normal_force.elbow7`,
//!   `actual.z`, `position.joint2` (`/joint_states`), `transforms.link3.rotation.w` (`/tf`).
//!
//! Each column's unit is `schemas::units`'s (the one table of units; SI, radians) for its field:
//! [`TopicFrame::columns`].
//!
//! Which topics: by default every decoded topic but those a viewer draws, whose messages are
//! layout rather than signals ([`is_viewer_layout`]: `foxglove.FrameTransforms` on `/tf`,
//! `foxglove.PointCloud` on `/hand_points`, `foxglove.SceneUpdate` on `/scene` and
//! `/contact_markers`); those are read only when named ([`Selection`]).

use std::collections::BTreeMap;
use std::path::Path;

use polars::prelude::*;
use schemas::topics::{array_index, ArrayIndex};
use schemas::Recording;

use crate::Error;

mod flatten;
pub mod long;
pub mod streamed;
pub use flatten::{ColumnData, ColumnField};
use flatten::Columns;

/// Name of the time column of every frame.
pub const TIME_COLUMN: &str = "time";
/// Unit of [`TIME_COLUMN`].
pub const TIME_UNIT: &str = "s";

/// Whether a topic with the schema `schema_name` is a viewer's layout (3D scene entities, point
/// clouds, transform trees: the Foxglove well-known schemas, <https://docs.foxglove.dev/docs/visualization/message-schemas/introduction>)
/// rather than signals; such topics are exported only when asked for.
pub fn is_viewer_layout(schema_name: &str) -> bool {
    schema_name.starts_with("foxglove.")
}

/// Which topics to read.
#[derive(Debug, Clone, Copy, Default)]
pub struct Selection<'a> {
    /// Exactly these topics (`--topics`), viewer layouts too; `None`: the default set.
    pub only: Option<&'a [&'a str]>,
    /// Viewer-layout topics to add to the default set (`--include tf,hand_points`; the leading
    /// `/` optional; `all`: every one). Names the recording does not have are ignored.
    pub include: &'a [&'a str],
}

impl Selection<'_> {
    fn includes(&self, topic: &str) -> bool {
        self.include.iter().any(|i| *i == "all" || i.trim_start_matches('/') == topic.trim_start_matches('/'))
    }
}

/// What a column of a [`TopicFrame`] holds.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ColumnInfo {
    /// The column's name in the wide table (`current.joint4`).
    pub name: String,
    /// The message field (`current`; [`TIME_COLUMN`] for the time).
    pub field: String,
    /// The joint, contact, frame or index of the array entry (`joint4`), if any.
    pub label: Option<String>,
    /// The unit (`schemas::units`), if the field has one.
    pub unit: Option<&'static str>,
}

/// One topic as a DataFrame.
#[derive(Debug, Clone)]
pub struct TopicFrame {
    pub topic: String,
    /// The channel's schema name (`elbow_sim.MotorState`, `sensor_msgs/msg/JointState`).
    pub schema_name: String,
    /// [`TIME_COLUMN`], then one column per field.
    pub frame: DataFrame,
    /// One per column of `frame`, in its order.
    pub columns: Vec<ColumnInfo>,
}

/// A recording as DataFrames.
#[derive(Debug, Clone)]
pub struct RecordingFrames {
    /// Where it was read from.
    pub source: String,
    /// The metadata records (`recording`, `run`, `result`, ...), as in the file.
    pub metadata: BTreeMap<String, BTreeMap<String, String>>,
    /// One frame per selected decoded topic with messages, in channel order.
    pub topics: Vec<TopicFrame>,
    /// Topics not loaded, and why (a viewer's layout not asked for, an encoding the reader does
    /// not decode, not selected).
    pub skipped: Vec<(String, String)>,
}

impl RecordingFrames {
    /// The frame of `topic`.
    pub fn get(&self, topic: &str) -> Option<&DataFrame> {
        self.topic(topic).map(|t| &t.frame)
    }

    /// The frame of `topic` with its columns' units and labels.
    pub fn topic(&self, topic: &str) -> Option<&TopicFrame> {
        self.topics.iter().find(|t| t.topic == topic)
    }
}

/// Reads the recording at `path` into frames: the topics of `select`.
///
/// For the default set the file is read twice: once for its channels alone (every chunk is
/// skipped undecompressed when the file has a summary), then for the topics chosen, so the
/// transforms and point clouds left out are never decoded.
pub fn read_frames(path: &Path, select: Selection<'_>) -> Result<RecordingFrames, Error> {
    let (rec, excluded) = match select.only {
        Some(only) => (schemas::read_recording_topics(path, Some(only))?, Vec::new()),
        None => {
            let none: &[&str] = &[];
            let mut ignore = |_: schemas::DecodedMessage<'_>| -> Result<(), schemas::Error> { Ok(()) };
            let channels = schemas::stream_recording(path, Some(none), &mut ignore)?.channels;
            let mut wanted: Vec<&str> = Vec::new();
            let mut excluded = Vec::new();
            for ch in &channels {
                if is_viewer_layout(&ch.schema_name) && !select.includes(&ch.topic) {
                    let why = format!(
                        "a viewer's layout ({}), not signals: left out by default; `--include {}` exports it",
                        ch.schema_name,
                        ch.topic.trim_start_matches('/')
                    );
                    if !excluded.iter().any(|(t, _): &(String, String)| *t == ch.topic) {
                        excluded.push((ch.topic.clone(), why));
                    }
                } else if !wanted.contains(&ch.topic.as_str()) {
                    wanted.push(&ch.topic);
                }
            }
            (schemas::read_recording_topics(path, Some(wanted.as_slice()))?, excluded)
        }
    };
    let mut out = recording_frames(&rec)?;
    out.skipped.retain(|(t, why)| !(why == schemas::NOT_SELECTED && excluded.iter().any(|(x, _)| x == t)));
    out.skipped.extend(excluded);
    Ok(out)
}

/// The frames of a decoded recording: every decoded topic.
pub fn recording_frames(rec: &Recording) -> Result<RecordingFrames, Error> {
    // the names of per-joint and per-contact entries (format 0: `joint1..N`, by the reader);
    // none for a file without a `run` record (another producer's), whose arrays keep indices.
    // Since format 3 the messages carry them too (`name`), which flatten.rs prefers.
    let run = rec.run().ok();
    let (joints, contacts) = (run.as_ref().map(|r| r.joint_names.clone()), run.as_ref().map(|r| r.contacts.clone()));
    let mut out = RecordingFrames {
        source: rec.source.clone(),
        metadata: rec.metadata_records().clone(),
        topics: Vec::new(),
        skipped: Vec::new(),
    };
    let mut seen = std::collections::BTreeSet::new();
    for ch in &rec.channels {
        if !seen.insert(ch.topic.clone()) {
            continue; // several channels on one topic: their messages are already merged
        }
        if let Some(why) = &ch.undecoded {
            out.skipped.push((ch.topic.clone(), why.clone()));
            continue;
        }
        let Some(messages) = rec.messages(&ch.topic) else {
            continue;
        };
        let topic = ch.topic.as_str();
        let labels = |path: &str| -> Option<&[String]> {
            match array_index(topic, path)? {
                ArrayIndex::Joint => joints.as_deref(),
                ArrayIndex::Contact => contacts.as_deref(),
            }
        };
        let mut cols = Columns::default();
        let mut ns = Vec::with_capacity(messages.len());
        for (t_ns, msg) in messages {
            ns.push(*t_ns);
            cols.push_row(msg, &labels);
        }
        debug_assert_eq!(cols.rows(), ns.len());
        let (frame, columns) = frame(topic, &ns, cols).map_err(|e| Error::Table {
            file: rec.source.clone(),
            detail: format!("building the frame of {topic}: {e}"),
        })?;
        out.topics.push(TopicFrame { topic: ch.topic.clone(), schema_name: ch.schema_name.clone(), frame, columns });
    }
    Ok(out)
}

/// Whether `col` is the time `ns` (s, rounded to the ns as the writer rounds) at every row.
fn is_log_time_s(col: &ColumnData, ns: &[u64]) -> bool {
    match col {
        ColumnData::F64(v) => v.len() == ns.len() && v.iter().zip(ns).all(|(x, n)| x.is_some_and(|x| schemas::to_log_time(x) == *n)),
        _ => false,
    }
}

fn integers(col: &ColumnData) -> Option<Vec<i128>> {
    match col {
        ColumnData::I64(v) => v.iter().map(|x| x.map(i128::from)).collect(),
        ColumnData::U64(v) => v.iter().map(|x| x.map(i128::from)).collect(),
        _ => None,
    }
}

/// Whether the columns `sec` and `nanosec` are the time `ns` at every row.
fn is_log_time_stamp(sec: &ColumnData, nanosec: &ColumnData, ns: &[u64]) -> bool {
    match (integers(sec), integers(nanosec)) {
        (Some(s), Some(n)) => s.len() == ns.len() && s.iter().zip(&n).zip(ns).all(|((s, n), t)| s * 1_000_000_000 + n == i128::from(*t)),
        _ => false,
    }
}

/// The stamp suffixes (ROS 2 `builtin_interfaces/Time`, Foxglove `Timestamp`).
const STAMPS: [(&str, &str); 2] = [(".sec", ".nanosec"), (".seconds", ".nanos")];

fn frame(topic: &str, ns: &[u64], cols: Columns) -> PolarsResult<(DataFrame, Vec<ColumnInfo>)> {
    let cols: Vec<(String, ColumnField, ColumnData)> = cols.into_columns().collect();
    let drop = time_duplicates(&cols, ns);
    frame_of(topic, ns, cols, &drop)
}

/// Which of `cols` duplicate the log time `ns` at every row (a `time` field, a `sec` +
/// `nanosec` stamp): those are left out of the frame.
fn time_duplicates(cols: &[(String, ColumnField, ColumnData)], ns: &[u64]) -> Vec<bool> {
    let mut drop = vec![false; cols.len()];
    for (k, (name, field, data)) in cols.iter().enumerate() {
        if name == TIME_COLUMN && field.label.is_none() && is_log_time_s(data, ns) {
            drop[k] = true;
        }
        for (sec, nanosec) in STAMPS {
            let Some(prefix) = name.strip_suffix(sec) else { continue };
            let partner = format!("{prefix}{nanosec}");
            if let Some(j) = cols.iter().position(|(n, _, _)| *n == partner) {
                if is_log_time_stamp(data, &cols[j].2, ns) {
                    (drop[k], drop[j]) = (true, true);
                }
            }
        }
    }
    drop
}

/// The frame of `cols` at the times `ns`, without the columns `drop` marks.
fn frame_of(topic: &str, ns: &[u64], cols: Vec<(String, ColumnField, ColumnData)>, drop: &[bool]) -> PolarsResult<(DataFrame, Vec<ColumnInfo>)> {
    let t: Vec<f64> = ns.iter().map(|&n| schemas::from_log_time(n)).collect();
    let mut columns = vec![Column::new(TIME_COLUMN.into(), t)];
    let mut info = vec![ColumnInfo {
        name: TIME_COLUMN.into(),
        field: TIME_COLUMN.into(),
        label: None,
        unit: Some(TIME_UNIT),
    }];
    for ((name, field, data), &drop) in cols.into_iter().zip(drop) {
        if drop {
            continue;
        }
        let name = if name == TIME_COLUMN {
            format!("{TIME_COLUMN}_field") // a message field called `time` that is not the log time
        } else {
            name
        };
        info.push(ColumnInfo { unit: schemas::units::unit(topic, &field.field), name: name.clone(), field: field.field, label: field.label });
        columns.push(match data {
            ColumnData::F64(v) => Column::new(name.into(), v),
            ColumnData::I64(v) => Column::new(name.into(), v),
            ColumnData::U64(v) => Column::new(name.into(), v),
            ColumnData::Bool(v) => Column::new(name.into(), v),
            ColumnData::Str(v) => Column::new(name.into(), v),
        });
    }
    Ok((DataFrame::new(ns.len(), columns)?, info))
}
