//! Reading the intact part of a damaged recording (`analyze ... --recover`).
//!
//! A recording cut short (a killed run leaves its hidden `.NAME.<pid>-<n>.partial`, a copy stops, a
//! disk fills) has no summary and no footer, so [`super::read_recording_bytes`] rejects it. Its
//! data section is still a sequence of self-contained records (MCAP spec: a chunk carries its own
//! schemas and channels, is compressed on its own and has its own CRC), so everything before the
//! damage can be read: [`read_recording_recover_bytes`] walks the top-level records from the start
//! and decodes them one at a time (a chunk as a whole: its CRC is checked before any of its
//! messages is used, and a chunk that fails anywhere contributes nothing), and stops at the first
//! record that is cut short or does not read, or at the end of the data section. Messages and
//! metadata records before that point are returned, with a [`RecoverReport`] saying how much was
//! read and where and why it stopped.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt;
use std::path::Path;

use mcap::records::op;

use super::{feed, read_recording_bytes, reader_options, Recording, State};
use crate::Error;

/// How much of a recording [`read_recording_recover`] read.
#[derive(Debug, Clone, PartialEq)]
pub struct RecoverReport {
    /// The file (or the label given to [`read_recording_recover_bytes`]).
    pub source: String,
    /// Size of the input, bytes.
    pub file_len: u64,
    /// The normal reader accepted the whole file: nothing was lost, the recording is exactly
    /// what [`crate::read_recording`] returns.
    pub complete: bool,
    /// Byte offset where reading stopped: the start of the first record that is cut short or
    /// unreadable (or of the data-end record when only the summary is damaged); the file
    /// length when `complete`.
    pub stopped_at: u64,
    /// Why reading stopped; `None` when `complete`.
    pub reason: Option<String>,
    /// Chunk records read.
    pub chunks: usize,
    /// Messages read (every channel, decoded or not).
    pub messages: u64,
    /// Largest log time of the messages read, ns.
    pub t_end_ns: Option<u64>,
    /// Names of the metadata records read.
    pub metadata: Vec<String>,
}

impl RecoverReport {
    /// Largest log time of the messages read, s.
    pub fn t_end_s(&self) -> Option<f64> {
        self.t_end_ns.map(crate::from_log_time)
    }
}

impl fmt::Display for RecoverReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let t_end = self
            .t_end_s()
            .map_or("no messages".to_string(), |t| format!("t_end = {t} s"));
        let meta = if self.metadata.is_empty() {
            "none".to_string()
        } else {
            self.metadata.join(", ")
        };
        if self.complete {
            return write!(
                f,
                "{}: complete: {} messages in {} chunks, {t_end}, metadata {meta}",
                self.source, self.messages, self.chunks
            );
        }
        write!(
            f,
            "{}: damaged recording: stopped at byte {} of {}: {}; recovered {} messages in {} \
             complete chunks ({t_end}) and metadata records: {meta}",
            self.source,
            self.stopped_at,
            self.file_len,
            self.reason.as_deref().unwrap_or("unknown"),
            self.messages,
            self.chunks
        )
    }
}

/// Reads the intact part of the MCAP file at `path` (see the module docs). An intact file
/// gives what [`crate::read_recording`] gives, with `complete: true`.
///
/// Errors only when nothing can be read at all: the file cannot be read, or is not MCAP (no
/// magic). A file whose damage starts at its first record gives an empty recording.
pub fn read_recording_recover(path: &Path) -> Result<(Recording, RecoverReport), Error> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| Error::Io {
        file: file.clone(),
        op: "reading",
        source,
    })?;
    read_recording_recover_bytes(&bytes, &file)
}

/// [`read_recording_recover`] on bytes; `source` labels them in errors and in the report.
pub fn read_recording_recover_bytes(
    bytes: &[u8],
    source: &str,
) -> Result<(Recording, RecoverReport), Error> {
    let normal = match read_recording_bytes(bytes, source) {
        Ok(rec) => {
            let report = RecoverReport {
                source: source.to_string(),
                file_len: bytes.len() as u64,
                complete: true,
                stopped_at: bytes.len() as u64,
                reason: None,
                chunks: count_chunks(bytes),
                messages: rec.channels.iter().map(|c| c.message_count as u64).sum(),
                t_end_ns: rec
                    .messages
                    .values()
                    .filter_map(|l| l.iter().map(|(t, _)| *t).max())
                    .max(),
                metadata: rec.metadata.keys().cloned().collect(),
            };
            return Ok((rec, report));
        }
        Err(e @ Error::NotMcap { .. }) => return Err(e),
        Err(e) => e,
    };
    Ok(scan(bytes, source, &normal))
}

/// Opcode (1 byte) and length (u64 LE) before every record.
const RECORD_HEAD: usize = 9;

/// Chunk records in the data section of an intact file.
fn count_chunks(bytes: &[u8]) -> usize {
    let mut at = mcap::MAGIC.len();
    let mut n = 0;
    while let Some(head) = bytes.get(at..at + RECORD_HEAD) {
        let len = u64::from_le_bytes(head[1..].try_into().unwrap_or([0; 8]));
        match head[0] {
            op::DATA_END | op::FOOTER => break,
            op::CHUNK => n += 1,
            _ => {}
        }
        let Some(next) = usize::try_from(len)
            .ok()
            .and_then(|l| at.checked_add(RECORD_HEAD)?.checked_add(l))
        else {
            break;
        };
        at = next;
    }
    n
}

/// What the state held before a record, to undo a record that fails halfway.
struct Snapshot {
    schemas: BTreeSet<u16>,
    channels: BTreeMap<u16, usize>,
    messages: BTreeMap<String, usize>,
    metadata: BTreeMap<String, BTreeMap<String, String>>,
    total: u64,
}

impl Snapshot {
    fn take(s: &State) -> Self {
        Snapshot {
            schemas: s.schemas.keys().copied().collect(),
            channels: s
                .channels
                .iter()
                .map(|(&id, c)| (id, c.message_count))
                .collect(),
            messages: s
                .messages
                .iter()
                .map(|(t, l)| (t.clone(), l.len()))
                .collect(),
            metadata: s.metadata.clone(),
            total: s.total,
        }
    }

    fn restore(self, s: &mut State) {
        s.schemas.retain(|id, _| self.schemas.contains(id));
        s.channels.retain(|id, _| self.channels.contains_key(id));
        s.decoders.retain(|id, _| self.channels.contains_key(id));
        for (id, c) in &mut s.channels {
            c.message_count = self.channels[id];
        }
        s.messages.retain(|t, _| self.messages.contains_key(t));
        for (t, l) in &mut s.messages {
            l.truncate(self.messages[t]);
        }
        s.metadata = self.metadata;
        s.total = self.total;
    }
}

fn scan(bytes: &[u8], source: &str, normal: &Error) -> (Recording, RecoverReport) {
    let mut state = State {
        file: source.to_string(),
        ..State::default()
    };
    // one record at a time: no magic before it, none expected after it
    let options = reader_options(bytes.len())
        .with_skip_start_magic(true)
        .with_skip_end_magic(true)
        .with_check_finishes_after_end_magic(false);
    let prefix = format!("{source}: ");
    let mut at = mcap::MAGIC.len();
    let mut chunks = 0;
    let mut t_end_ns: Option<u64> = None;
    let reason = loop {
        let left = bytes.len() - at;
        if left == 0 {
            break "the file ends after a complete record, before the end of the data section"
                .to_string();
        }
        if left < RECORD_HEAD {
            break format!("a record header is cut short ({left} of {RECORD_HEAD} bytes)");
        }
        let opcode = bytes[at];
        let len = u64::from_le_bytes(bytes[at + 1..at + RECORD_HEAD].try_into().unwrap_or([0; 8]));
        if len > (left - RECORD_HEAD) as u64 {
            break format!(
                "record (opcode {opcode:#04x}) of {len} bytes is cut short: {} bytes remain",
                left - RECORD_HEAD
            );
        }
        if opcode == op::DATA_END || opcode == op::FOOTER {
            let why = normal.to_string();
            break format!(
                "the data section is intact, what follows it is not: {}",
                why.strip_prefix(&prefix).unwrap_or(&why)
            );
        }
        let end = at + RECORD_HEAD + len as usize;
        let snapshot = Snapshot::take(&state);
        let before: BTreeMap<String, usize> = snapshot.messages.clone();
        let fed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            feed(&bytes[at..end], options.clone(), &mut state)
        }));
        let failure = match fed {
            Ok(Ok(())) => None,
            Ok(Err(e)) => {
                let why = e.to_string();
                Some(why.strip_prefix(&prefix).unwrap_or(&why).to_string())
            }
            Err(panic) => {
                let why = panic
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| panic.downcast_ref::<String>().cloned())
                    .unwrap_or_default();
                Some(format!("the MCAP parser panicked on this record: {why}"))
            }
        };
        if let Some(why) = failure {
            snapshot.restore(&mut state);
            break format!("record (opcode {opcode:#04x}) is unreadable: {why}");
        }
        for (topic, list) in &state.messages {
            let from = before.get(topic).copied().unwrap_or(0);
            if let Some(t) = list[from..].iter().map(|(t, _)| *t).max() {
                t_end_ns = Some(t_end_ns.map_or(t, |e| e.max(t)));
            }
        }
        if opcode == op::CHUNK {
            chunks += 1;
        }
        at = end;
    };
    // messages of undecoded channels count too, but have no time in `state.messages`
    let report = RecoverReport {
        source: source.to_string(),
        file_len: bytes.len() as u64,
        complete: false,
        stopped_at: at as u64,
        reason: Some(reason),
        chunks,
        messages: state.total,
        t_end_ns,
        metadata: state.metadata.keys().cloned().collect(),
    };
    (state.into_recording(), report)
}
