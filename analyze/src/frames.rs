//! Any recording -> polars DataFrames, one per topic, and their export to Parquet and CSV
//! (feature `tables`).
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
use std::path::{Path, PathBuf};

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

pub use crate::export::ExportFormat;

/// The file name of a topic's table: `/joint_states` -> `joint_states.parquet`.
pub fn topic_file_name(topic: &str, format: ExportFormat) -> String {
    let stem: String = topic
        .trim_start_matches('/')
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' })
        .collect();
    let stem = if stem.is_empty() { "topic".into() } else { stem };
    format!("{stem}.{}", format.extension())
}

/// The file of each topic: [`topic_file_name`], with `_2`, `_3` ... before the extension when
/// two topics map to one name (`/a/b` and `/a_b`).
fn file_names(frames: &RecordingFrames, format: ExportFormat) -> Vec<String> {
    let mut used = std::collections::BTreeSet::new();
    frames
        .topics
        .iter()
        .map(|(t, _)| {
            let base = topic_file_name(t, format);
            let mut name = base.clone();
            let mut k = 2;
            while !used.insert(name.clone()) {
                let stem = base.trim_end_matches(&format!(".{}", format.extension()));
                name = format!("{stem}_{k}.{}", format.extension());
                k += 1;
            }
            name
        })
        .collect()
}

/// Writes one file per topic into `dir` (created if needed) plus `metadata.json` (the
/// metadata records, and the topics skipped with the reason); returns the files written.
/// Each file is written to a temporary name and renamed, so a killed export never leaves a
/// half-written table under the final name.
pub fn export(frames: &mut RecordingFrames, dir: &Path, format: ExportFormat) -> Result<Vec<PathBuf>, Error> {
    std::fs::create_dir_all(dir).map_err(|source| Error::Io {
        file: dir.display().to_string(),
        op: "creating",
        source,
    })?;
    let mut written = Vec::new();
    let files = file_names(frames, format);
    for ((_, df), name) in frames.topics.iter_mut().zip(&files) {
        let path = dir.join(name);
        write_atomic(&path, |f| match format {
            ExportFormat::Parquet => ParquetWriter::new(f).finish(df).map(drop),
            ExportFormat::Csv => CsvWriter::new(f).include_header(true).finish(df),
        })
        .map_err(|e| e.into_error(&path))?;
        written.push(path);
    }
    let meta = serde_json::json!({
        "source": frames.source,
        "metadata": frames.metadata,
        "topics": frames.topics.iter().zip(&files).map(|((t, df), file)| serde_json::json!({
            "topic": t,
            "file": file,
            "rows": df.height(),
            "columns": df.get_column_names().iter().map(|c| c.as_str()).collect::<Vec<_>>(),
        })).collect::<Vec<_>>(),
        "skipped": frames.skipped.iter().map(|(t, why)| serde_json::json!({"topic": t, "reason": why})).collect::<Vec<_>>(),
    });
    let path = dir.join("metadata.json");
    let text = serde_json::to_string_pretty(&meta).unwrap_or_default() + "\n";
    write_atomic(&path, |f| {
        use std::io::Write;
        f.write_all(text.as_bytes()).map_err(PolarsError::from)
    })
    .map_err(|e| e.into_error(&path))?;
    written.push(path);
    Ok(written)
}

enum WriteError {
    Io(std::io::Error),
    Polars(PolarsError),
}

impl WriteError {
    /// The library's error, naming the file being written.
    fn into_error(self, path: &Path) -> Error {
        let file = path.display().to_string();
        match self {
            WriteError::Io(source) => Error::Io { file, op: "writing", source },
            WriteError::Polars(e) => Error::Table { file, detail: format!("writing the table: {e}") },
        }
    }
}

/// Writes through `.NAME.partial` in the same directory, then renames over `path`.
fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut std::fs::File) -> PolarsResult<()>,
) -> Result<(), WriteError> {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = path.with_file_name(format!(".{name}.partial"));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp).map_err(WriteError::Io)?;
        write(&mut f).map_err(WriteError::Polars)?;
        f.sync_all().map_err(WriteError::Io)?;
        std::fs::rename(&tmp, path).map_err(WriteError::Io)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}
