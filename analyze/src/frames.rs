//! Any recording -> polars DataFrames, one per topic (feature `tables`); `export.rs` writes them
//! as Parquet or CSV.
//!
//! The frames are built from the generic reader ([`schemas::read_recording`]), so every channel
//! is decoded through the schema stored in the file, not through this program's message types:
//! recordings written by older versions of the tool load as they were written (a field an old
//! version did not have is simply not a column). Each frame has
//!
//! - `t`: the message's log time in s (simulated time, [`schemas::from_log_time`]), Float64;
//! - one column per field, arrays expanded per entry and named by joint, contact, frame or
//!   index (the rule is in `frames/flatten.rs`): `current.joint4`, `normal_force.elbow7`,
//!   `actual.z`, `position.joint2` (`/joint_states`), `transforms.link3.rotation.w` (`/tf`).
//!
//! Units are the recording's (SI, radians; see the `schemas` crate's message docs).

use std::collections::BTreeMap;
use std::path::Path;

use polars::prelude::*;
use schemas::topics::{array_index, ArrayIndex};
use schemas::Recording;

use crate::Error;

mod flatten;
pub use flatten::ColumnData;
use flatten::Columns;

/// Name of the time column of every frame.
pub const TIME_COLUMN: &str = "t";

/// A recording as DataFrames.
#[derive(Debug, Clone)]
pub struct RecordingFrames {
    /// Where it was read from.
    pub source: String,
    /// The metadata records (`recording`, `run`, `result`, ...), as in the file.
    pub metadata: BTreeMap<String, BTreeMap<String, String>>,
    /// One frame per decoded topic with messages, in channel order.
    pub topics: Vec<(String, DataFrame)>,
    /// Topics not loaded, and why (an encoding the reader does not decode, not selected).
    pub skipped: Vec<(String, String)>,
}

impl RecordingFrames {
    /// The frame of `topic`.
    pub fn get(&self, topic: &str) -> Option<&DataFrame> {
        self.topics.iter().find(|(t, _)| t == topic).map(|(_, df)| df)
    }
}

/// Reads the recording at `path` into frames: every topic, or only `topics`.
pub fn read_frames(path: &Path, topics: Option<&[&str]>) -> Result<RecordingFrames, Error> {
    let rec = schemas::read_recording_topics(path, topics)?;
    recording_frames(&rec)
}

/// The frames of a decoded recording.
pub fn recording_frames(rec: &Recording) -> Result<RecordingFrames, Error> {
    // the names of per-joint and per-contact entries (format 0: `joint1..N`, by the reader);
    // none for a file without a `run` record (another producer's), whose arrays keep indices
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
        let mut t = Vec::with_capacity(messages.len());
        for (ns, msg) in messages {
            t.push(schemas::from_log_time(*ns));
            cols.push_row(msg, &labels);
        }
        debug_assert_eq!(cols.rows(), t.len());
        let df = frame(t, cols).map_err(|e| Error::Table {
            file: rec.source.clone(),
            detail: format!("building the frame of {topic}: {e}"),
        })?;
        out.topics.push((ch.topic.clone(), df));
    }
    Ok(out)
}

fn frame(t: Vec<f64>, cols: Columns) -> PolarsResult<DataFrame> {
    let height = t.len();
    let mut columns = vec![Column::new(TIME_COLUMN.into(), t)];
    for (name, data) in cols.into_columns() {
        let name = if name == TIME_COLUMN {
            format!("{TIME_COLUMN}_field") // a message field called `t` must not shadow it
        } else {
            name
        };
        columns.push(match data {
            ColumnData::F64(v) => Column::new(name.into(), v),
            ColumnData::I64(v) => Column::new(name.into(), v),
            ColumnData::U64(v) => Column::new(name.into(), v),
            ColumnData::Bool(v) => Column::new(name.into(), v),
            ColumnData::Str(v) => Column::new(name.into(), v),
        });
    }
    DataFrame::new(height, columns)
}
