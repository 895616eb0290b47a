//! A recording's topics as frames in batches, read streamed ([`schemas::stream_recording`]):
//! memory bounded by the batch, not by the file (issue 29: `analyze export` held every decoded
//! message, 1.79 GB on a 40 MB, 300 s recording).
//!
//! Three reads of the file, each one record at a time:
//! 1. its channels and metadata records (every chunk skipped when the file has a summary): the
//!    joint and contact names that label the arrays, and the topics of the default set;
//! 2. the selected topics, each message's per-joint and per-contact arrays checked against the
//!    run's joint and contact counts (`DecodedMessage::check_sizes`: a message with more
//!    entries is refused, naming file, topic, field and time), row by row into [`Columns`] emptied every batch: the plan of each
//!    topic, i.e. its columns (names, fields, kinds after widening) in first-appearance order,
//!    and which columns duplicate the log time at *every* row of the whole topic (only then are
//!    they left out, as [`super::recording_frames`] decides on the topic read whole);
//! 3. per topic ([`Streamed::batches`]), the rows again into columns made from the plan, handed
//!    out as a [`TopicFrame`] each time a batch fills.
//!
//! The batches of a topic therefore have the columns, order and kinds of the frame read whole,
//! and their rows concatenated are its rows. A batch holds at most [`MAX_ROWS`] rows and at most
//! [`MAX_CELLS`] values (rows × columns), so a topic with very wide messages comes in smaller
//! batches. One difference with the whole read: a column whose kind changes between batches
//! (integers, then text) is of its final kind from the first row on, so its early values are
//! converted as they are pushed rather than afterwards (the same numbers; a boolean pushed into
//! a text column reads `true` rather than `1`).

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use schemas::topics::{array_index, ArrayIndex};

use super::flatten::{ColumnData, ColumnField, Columns};
use super::{frame_of, is_viewer_layout, time_duplicates, Selection, TopicFrame};
use crate::Error;

/// Rows of a batch at most.
pub const MAX_ROWS: usize = 65_536;
/// Values (rows × columns) of a batch at most: about 16 MB of decoded columns.
pub const MAX_CELLS: usize = 1 << 20;

/// The rows of a batch of `width` columns and at most `cells` values.
fn batch_rows(width: usize, cells: usize) -> usize {
    (cells / width.max(1)).clamp(1, MAX_ROWS)
}

/// One topic's plan: what its frame read whole would be, without its rows.
#[derive(Debug)]
pub struct TopicPlan {
    pub topic: String,
    pub schema_name: String,
    /// Rows of the whole topic.
    pub rows: usize,
    columns: Vec<(String, ColumnField, ColumnData)>,
    drop: Vec<bool>,
}

/// A recording planned for reading in batches ([`plan`]).
#[derive(Debug)]
pub struct Streamed {
    path: std::path::PathBuf,
    /// Where it was read from.
    pub source: String,
    /// The metadata records (`recording`, `run`, `result`, ...), as in the file.
    pub metadata: BTreeMap<String, BTreeMap<String, String>>,
    /// One plan per selected decoded topic with messages, in channel order.
    pub topics: Vec<TopicPlan>,
    /// Topics not loaded, and why (as [`super::RecordingFrames::skipped`]).
    pub skipped: Vec<(String, String)>,
    joints: Option<Vec<String>>,
    contacts: Option<Vec<String>>,
}

/// A topic's rows so far: columns and log times.
struct Building {
    cols: Columns,
    ns: Vec<u64>,
    /// Per column: a duplicate of the log time at every row folded so far.
    dup: Vec<bool>,
    batches: usize,
    rows: usize,
}

impl Building {
    fn fold(&mut self) {
        if self.ns.is_empty() {
            return;
        }
        let rows = self.cols.take_rows();
        let dup = time_duplicates(&rows, &self.ns);
        for (k, d) in dup.into_iter().enumerate() {
            match self.dup.get_mut(k) {
                Some(x) => *x &= d,
                // a column first seen in this batch was null in the earlier ones
                None => self.dup.push(d && self.batches == 0),
            }
        }
        self.batches += 1;
        self.ns.clear();
    }
}

/// The labels of the entries of an array at `path` of `topic`.
fn labeller<'a>(topic: &'a str, joints: Option<&'a [String]>, contacts: Option<&'a [String]>) -> impl Fn(&str) -> Option<&'a [String]> + 'a {
    move |path: &str| match array_index(topic, path)? {
        ArrayIndex::Joint => joints,
        ArrayIndex::Contact => contacts,
    }
}

/// Reads the recording at `path` twice (module docs, reads 1 and 2): the plan of the topics of
/// `select`. Errors are the reader's (the file is checked whole before any table is written).
// the visitor's error is the reader's (`schemas::Error`, large), as in `super::read_frames`
#[allow(clippy::result_large_err)]
pub fn plan(path: &Path, select: Selection<'_>) -> Result<Streamed, Error> {
    // 1: channels and metadata
    let none: &[&str] = &[];
    let mut ignore = |_: schemas::DecodedMessage<'_>| -> Result<(), schemas::Error> { Ok(()) };
    let head = schemas::stream_recording(path, Some(none), &mut ignore)?;
    let run = head.run().ok();
    let (joints, contacts) = (run.as_ref().map(|r| r.joint_names.clone()), run.as_ref().map(|r| r.contacts.clone()));
    let mut wanted: Vec<&str> = Vec::new();
    let mut excluded: Vec<(String, String)> = Vec::new();
    match select.only {
        Some(only) => wanted.extend_from_slice(only),
        None => {
            for ch in &head.channels {
                if is_viewer_layout(&ch.schema_name) && !select.includes(&ch.topic) {
                    let why = format!(
                        "a viewer's layout ({}), not signals: left out by default; `--include {}` exports it",
                        ch.schema_name,
                        ch.topic.trim_start_matches('/')
                    );
                    if !excluded.iter().any(|(t, _)| *t == ch.topic) {
                        excluded.push((ch.topic.clone(), why));
                    }
                } else if !wanted.contains(&ch.topic.as_str()) {
                    wanted.push(&ch.topic);
                }
            }
        }
    }
    // 2: the columns of each topic, in batches
    let mut building: HashMap<String, Building> = HashMap::new();
    let mut visit = |m: schemas::DecodedMessage<'_>| -> Result<(), schemas::Error> {
        // arrays bounded by the run's joints and contacts: a longer one is damage, refused
        // before it makes thousands of columns (issue 29: 5 002-entry arrays took 600 MB)
        m.check_sizes()?;
        let b = building.entry(m.topic.to_string()).or_insert_with(|| Building {
            cols: Columns::default(),
            ns: Vec::new(),
            dup: Vec::new(),
            batches: 0,
            rows: 0,
        });
        let labels = labeller(m.topic, joints.as_deref(), contacts.as_deref());
        b.cols.push_row(&m.value(), &labels);
        b.ns.push(m.log_time_ns);
        b.rows += 1;
        if b.ns.len() >= batch_rows(b.cols.width(), MAX_CELLS) {
            b.fold();
        }
        Ok(())
    };
    let rec = schemas::stream_recording(path, Some(wanted.as_slice()), &mut visit)?;
    let mut out = Streamed {
        path: path.to_path_buf(),
        source: rec.source.clone(),
        metadata: rec.metadata_records().clone(),
        topics: Vec::new(),
        skipped: Vec::new(),
        joints,
        contacts,
    };
    let mut seen = std::collections::BTreeSet::new();
    for ch in &rec.channels {
        if !seen.insert(ch.topic.clone()) {
            continue;
        }
        if let Some(why) = &ch.undecoded {
            out.skipped.push((ch.topic.clone(), why.clone()));
            continue;
        }
        let Some(mut b) = building.remove(&ch.topic) else {
            continue; // no messages
        };
        b.fold();
        let columns = b.cols.take_rows();
        let mut drop = b.dup;
        drop.resize(columns.len(), false);
        out.topics.push(TopicPlan { topic: ch.topic.clone(), schema_name: ch.schema_name.clone(), rows: b.rows, columns, drop });
    }
    out.skipped.retain(|(t, why)| !(why == schemas::NOT_SELECTED && excluded.iter().any(|(x, _)| x == t)));
    out.skipped.extend(excluded);
    Ok(out)
}

impl Streamed {
    /// Reads the topic `k` of [`Streamed::topics`] once more and hands its rows to `sink` as
    /// frames of at most [`MAX_ROWS`] rows and `cells` values (at most [`MAX_CELLS`]; less for
    /// a caller that makes more of each value: the long layout's row per value), in order.
    #[allow(clippy::result_large_err)]
    pub fn batches(&self, k: usize, cells: usize, mut sink: impl FnMut(TopicFrame) -> Result<(), Error>) -> Result<(), Error> {
        let plan = &self.topics[k];
        let topic = plan.topic.as_str();
        let mut cols = Columns::planned(plan.columns.iter().cloned());
        let limit = batch_rows(plan.columns.len(), cells.min(MAX_CELLS));
        let mut ns: Vec<u64> = Vec::with_capacity(limit);
        let mut failed: Option<Error> = None;
        let mut flush = |cols: &mut Columns, ns: &mut Vec<u64>| -> Result<(), Error> {
            if ns.is_empty() {
                return Ok(());
            }
            let rows = cols.take_rows();
            if rows.len() != plan.columns.len() {
                return Err(Error::Table {
                    file: self.source.clone(),
                    detail: format!("topic {topic}: its columns changed between two reads of the file (was it being written?)"),
                });
            }
            let (frame, columns) = frame_of(topic, ns, rows, &plan.drop).map_err(|e| Error::Table {
                file: self.source.clone(),
                detail: format!("building the frame of {topic}: {e}"),
            })?;
            ns.clear();
            sink(TopicFrame { topic: plan.topic.clone(), schema_name: plan.schema_name.clone(), frame, columns })
        };
        let labels = labeller(topic, self.joints.as_deref(), self.contacts.as_deref());
        let mut visit = |m: schemas::DecodedMessage<'_>| -> Result<(), schemas::Error> {
            cols.push_row(&m.value(), &labels);
            ns.push(m.log_time_ns);
            if ns.len() >= limit {
                if let Err(e) = flush(&mut cols, &mut ns) {
                    failed = Some(e);
                    return Err(schemas::Error::Io {
                        file: self.source.clone(),
                        op: "exporting",
                        source: std::io::Error::other("stopped"),
                    });
                }
            }
            Ok(())
        };
        let read = schemas::stream_recording(&self.path, Some(&[topic]), &mut visit);
        if let Some(e) = failed {
            return Err(e);
        }
        read?;
        flush(&mut cols, &mut ns)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The batches of every topic, stacked, are the frame read whole: the same columns, kinds,
    /// order and values, the time duplicates left out the same way; every batch is within the
    /// limits. 70 001 samples: `/motors` comes in several batches (more than [`MAX_ROWS`] rows).
    #[test]
    fn batches_stacked_are_the_frames_read_whole() {
        let dir = tempfile::tempdir().unwrap();
        let mut s = schemas::synth::Synth::new("batches", &["elbow"], 3);
        (s.dt, s.n) = (1e-3, 70_000);
        let path = s.with_setup().write_in(dir.path());
        let whole = super::super::read_frames(&path, Selection::default()).unwrap();
        let streamed = plan(&path, Selection::default()).unwrap();
        assert_eq!(streamed.skipped, whole.skipped);
        assert_eq!(streamed.topics.len(), whole.topics.len());
        let mut several = 0;
        for (k, w) in whole.topics.iter().enumerate() {
            let mut parts: Vec<TopicFrame> = Vec::new();
            streamed
                .batches(k, MAX_CELLS, |t| {
                    assert!(t.frame.height() <= MAX_ROWS && t.frame.height() * t.frame.width() <= MAX_CELLS + t.frame.height());
                    parts.push(t);
                    Ok(())
                })
                .unwrap();
            several += usize::from(parts.len() > 1);
            let mut df = parts[0].frame.clone();
            for p in &parts[1..] {
                df.vstack_mut(&p.frame).unwrap();
                assert_eq!(p.columns, w.columns);
            }
            assert_eq!(parts[0].columns, w.columns, "{}", w.topic);
            assert_eq!(streamed.topics[k].rows, w.frame.height());
            assert!(df.equals_missing(&w.frame), "{}: {df:?} vs {:?}", w.topic, w.frame);
        }
        assert!(several > 0, "no topic came in several batches");
    }
}
