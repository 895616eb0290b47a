//! Reading the intact part of a damaged recording (`analyze ... --recover`).
//!
//! A recording cut short (a killed run leaves its hidden `.NAME.<pid>-<n>.partial`, a copy stops, a disk
//! fills) has no summary and no footer, so [`super::stream_recording`] rejects it. Its data
//! section is still a sequence of self-contained records (MCAP spec: a chunk carries its own
//! schemas and channels, is compressed on its own and has its own CRC), so everything before the
//! damage can be read: [`stream_recording_recover`] first checks the file as the normal reader
//! does without decoding anything; if that fails, it walks the top-level records from the start
//! and decodes them one at a time (a chunk as a whole: its CRC is checked before any of its
//! messages is used, and a chunk that fails anywhere contributes nothing), and stops at the first
//! record that is cut short or does not read, or at the end of the data section. Messages and
//! metadata records up to the last *flush point* before that (below) are returned, with a
//! [`RecoverReport`] saying how much was read and where and why it stopped.
//!
//! **Flush points: every topic up to the same time.** Our writer writes the chunks of every
//! topic together (a flush group, `writer/worker.rs`), each group strictly later in log time
//! than the one before. A flush point is where a group ends: before a record whose messages all
//! start after the end of every message read before it (the first chunk of the next group),
//! before a metadata record (the writer writes every staged chunk before one), and at the end
//! of the data section. Messages after the last flush point (the group a cut falls into, even
//! when some of its chunks are whole) are left out and counted
//! ([`RecoverReport::held_back_chunks`]): the recovered part is then every message logged up to
//! [`RecoverReport::t_end_ns`] on every topic, i.e. the intact recording restricted to that
//! interval, and never a topic that stops earlier than another. A file whose records show no
//! flush point within [`HOLD_LIMIT_BYTES`] of chunk data (another writer's) is read as before,
//! up to the last whole record, and the report says its topics may stop at different times
//! ([`RecoverReport::aligned`] = false). Memory: the decoded messages of one group at most.
//!
//! Nothing that failed a CRC is used:
//! - a chunk is used only after its own CRC matched;
//! - metadata records lie outside chunks and have no CRC of their own: the data section's CRC
//!   (in its Data End record) covers them. When that CRC does not match, the damage is outside
//!   the chunks that passed, so **every metadata record is left out** (the report says so) — a
//!   record with swapped contact names would otherwise label the forces wrongly. When the file
//!   ends before the Data End record, its metadata cannot be checked and the report says
//!   [`RecoverReport::metadata_verified`] = false;
//! - a chunk that is byte for byte a repeat of one already read (a copy that went wrong) is
//!   skipped and counted ([`RecoverReport::duplicate_chunks`]); any other repeat makes time go
//!   backwards on a channel, which stops the reading there.
//!
//! Memory: one record at a time (at most [`super::MAX_RECORD_BYTES`]), the decoded messages of
//! one flush group until it is confirmed whole (at most [`HOLD_LIMIT_BYTES`] of chunk data), and
//! a fingerprint (length and CRC-32) per chunk.

use std::collections::{BTreeMap, BTreeSet, HashSet};
use std::fmt;
use std::io::Read;
use std::path::Path;

use mcap::records::op;

use super::input::{open, read_up_to};
use super::{feed, read_state, reader_options, Collect, Null, Recording, State, Visitor, MAX_RECORD_BYTES};
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
    /// Chunk records read and kept (up to the last flush point).
    pub chunks: usize,
    /// Chunk records read whole but left out: after the last flush point (the flush group the
    /// damage falls into), so that every topic stops at the same time.
    pub held_back_chunks: usize,
    /// Every topic was read up to the same time ([`RecoverReport::t_end_ns`]): false only for a
    /// file whose flush points this reader cannot see (module docs), where the topics recovered
    /// may stop at different times.
    pub aligned: bool,
    /// Messages read and kept (every channel, decoded or not).
    pub messages: u64,
    /// Largest log time of the messages kept, ns.
    pub t_end_ns: Option<u64>,
    /// Names of the metadata records read.
    pub metadata: Vec<String>,
    /// Whether the metadata records were checked by the data section's CRC (always when
    /// `complete`; never when the file ends before its Data End record). Metadata that failed
    /// the check is not read at all.
    pub metadata_verified: bool,
    /// Chunks skipped because they repeat, byte for byte, a chunk already read.
    pub duplicate_chunks: usize,
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
             complete chunks ({t_end}{}) and metadata records: {meta}{}",
            self.source,
            self.stopped_at,
            self.file_len,
            self.reason.as_deref().unwrap_or("unknown"),
            self.messages,
            self.chunks,
            match (self.aligned, self.t_end_ns) {
                (true, Some(_)) => ", every topic up to it",
                (true, None) => "",
                (false, _) => ", the topics may stop at different times: no flush points seen",
            },
            if self.metadata_verified || self.metadata.is_empty() {
                ""
            } else {
                " (not checked by a CRC: the file ends before the data section's CRC)"
            }
        )?;
        if self.held_back_chunks > 0 {
            write!(f, "; {} complete chunks after the last flush point left out", self.held_back_chunks)?;
        }
        if self.duplicate_chunks > 0 {
            write!(f, "; {} repeated chunks skipped", self.duplicate_chunks)?;
        }
        Ok(())
    }
}

/// Reads the intact part of the MCAP file at `path`, keeping every message (see the module
/// docs). An intact file gives what [`crate::read_recording`] gives, with `complete: true`.
///
/// Errors only when nothing can be read at all: the file cannot be read, is not a regular
/// file, or is not MCAP (no magic). A file whose damage starts at its first record gives an
/// empty recording.
pub fn read_recording_recover(path: &Path) -> Result<(Recording, RecoverReport), Error> {
    let mut all = Collect::default();
    let (mut rec, report) = stream_recording_recover(path, None, &mut all)?;
    rec.messages = all.0;
    Ok((rec, report))
}

/// [`read_recording_recover`] on bytes; `source` labels them in errors and in the report.
pub fn read_recording_recover_bytes(bytes: &[u8], source: &str) -> Result<(Recording, RecoverReport), Error> {
    if !bytes.starts_with(mcap::MAGIC) {
        return Err(Error::NotMcap { file: source.to_string(), len: bytes.len() as u64 });
    }
    let mut all = Collect::default();
    let open_bytes = || -> Result<(Box<dyn Read + '_>, u64, String), Error> { Ok((Box::new(bytes), bytes.len() as u64, source.to_string())) };
    let (mut rec, report) = recover_from(open_bytes, None, &mut all)?;
    rec.messages = all.0;
    Ok((rec, report))
}

/// Streams the intact part of the MCAP file at `path` to `visitor` (see the module docs):
/// the messages of `topics` (all when `None`), then the metadata and channels read, and the
/// report. An intact file is read twice (checked first without decoding anything, then read).
pub fn stream_recording_recover(
    path: &Path,
    topics: Option<&[&str]>,
    visitor: &mut dyn Visitor,
) -> Result<(Recording, RecoverReport), Error> {
    let open_path = || -> Result<(Box<dyn Read>, u64, String), Error> {
        let (file, len, label) = open(path)?;
        Ok((Box::new(file), len, label))
    };
    recover_from(open_path, topics, visitor)
}

/// `open` gives the input from its start, its length and its label, each time it is called.
fn recover_from<'a>(
    open: impl Fn() -> Result<(Box<dyn Read + 'a>, u64, String), Error>,
    topics: Option<&[&str]>,
    visitor: &mut dyn Visitor,
) -> Result<(Recording, RecoverReport), Error> {
    let (mut input, len, label) = open()?;
    let checked = read_state(&mut input, len, label, Some(&[]), None, &mut Null);
    let (state, report) = match checked {
        Ok(_) => {
            let (mut input, len, label) = open()?;
            let state = read_state(&mut input, len, label, topics, None, visitor)?;
            let report = complete_report(&state, len);
            (state, report)
        }
        Err(e @ (Error::NotMcap { .. } | Error::NotAFile { .. } | Error::Io { .. })) => return Err(e),
        Err(e) => {
            let (mut input, len, label) = open()?;
            scan(&mut input, len, &label, topics, visitor, &e)?
        }
    };
    Ok((state.into_recording(), report))
}

/// The report of a file the normal reader accepted whole.
fn complete_report(state: &State, len: u64) -> RecoverReport {
    RecoverReport {
        source: state.file.clone(),
        file_len: len,
        complete: true,
        stopped_at: len,
        reason: None,
        chunks: state.stats_chunks.map_or(0, |n| n as usize),
        messages: state.total,
        t_end_ns: state.t_end_ns,
        metadata: state.metadata.keys().cloned().collect(),
        metadata_verified: true,
        duplicate_chunks: 0,
        held_back_chunks: 0,
        aligned: true,
    }
}

/// Chunk data (uncompressed) held back at most while waiting for a flush point: past it the
/// group is kept as it is, and the report says the topics may not be aligned.
pub const HOLD_LIMIT_BYTES: u64 = 64 << 20;

/// Opcode (1 byte) and length (u64 LE) before every record.
const RECORD_HEAD: usize = 9;

/// What the state held before a record, to undo a record that fails halfway.
struct Snapshot {
    schemas: BTreeSet<u16>,
    channels: BTreeMap<u16, usize>,
    last_time: super::IdMap<u64>,
    t_end_ns: Option<u64>,
    metadata: BTreeMap<String, BTreeMap<String, String>>,
    first_joint_array_len: Option<usize>,
    energy_has_gear_friction: Option<bool>,
    total: u64,
    /// Messages held back (the pending list's length).
    pending: usize,
}

impl Snapshot {
    fn take(s: &State) -> Self {
        Snapshot {
            schemas: s.schemas.keys().copied().collect(),
            channels: s.channels.iter().map(|(&id, c)| (id, c.message_count)).collect(),
            last_time: s.last_time.clone(),
            t_end_ns: s.t_end_ns,
            metadata: s.metadata.clone(),
            first_joint_array_len: s.first_joint_array_len,
            energy_has_gear_friction: s.energy_has_gear_friction,
            total: s.total,
            pending: s.pending.as_ref().map_or(0, Vec::len),
        }
    }

    fn restore(&self, s: &mut State) {
        s.schemas.retain(|id, _| self.schemas.contains(id));
        s.channels.retain(|id, _| self.channels.contains_key(id));
        s.decoders.retain(|id, _| self.channels.contains_key(id));
        for (id, c) in &mut s.channels {
            c.message_count = self.channels[id];
        }
        s.last_time.clone_from(&self.last_time);
        s.t_end_ns = self.t_end_ns;
        s.metadata.clone_from(&self.metadata);
        s.first_joint_array_len = self.first_joint_array_len;
        s.energy_has_gear_friction = self.energy_has_gear_friction;
        s.total = self.total;
        if let Some(p) = s.pending.as_mut() {
            p.truncate(self.pending);
        }
    }
}

/// Walks the top-level records of `input` (at its start, `len` bytes) one at a time; `normal`
/// is why the normal reader refused the file.
fn scan(
    input: &mut dyn Read,
    len: u64,
    source: &str,
    topics: Option<&[&str]>,
    visitor: &mut dyn Visitor,
    normal: &Error,
) -> Result<(State, RecoverReport), Error> {
    let mut state = State::new(source.to_string(), topics);
    state.typed = visitor.typed();
    state.pending = Some(Vec::new());
    // one record at a time: no magic before it, none expected after it
    let options = reader_options()
        .with_skip_start_magic(true)
        .with_skip_end_magic(true)
        .with_check_finishes_after_end_magic(false);
    let read_err = |e: std::io::Error| Error::Io { file: source.to_string(), op: "reading", source: e };
    let prefix = format!("{source}: ");
    let strip = |e: &Error| {
        let why = e.to_string();
        why.strip_prefix(&prefix).unwrap_or(&why).to_string()
    };
    // the data section's CRC covers every byte from the magic to the Data End record
    let mut crc = crc32fast::Hasher::new();
    let mut magic = [0u8; 8];
    let n = read_up_to(input, &mut magic).map_err(read_err)?;
    crc.update(&magic[..n]);
    let mut at = n as u64;
    let mut chunks = 0;
    let mut duplicate_chunks = 0;
    let mut seen_chunks: HashSet<(u64, u32)> = HashSet::new();
    let mut metadata_verified = false;
    let mut buf: Vec<u8> = Vec::new();
    // the state at the last flush point, the chunks read before it, and the largest log time
    // of the messages read so far (module docs: flush points)
    let mut confirmed = Snapshot::take(&state);
    let mut confirmed_chunks = 0;
    let mut max_end: Option<u64> = None;
    let mut held_bytes = 0u64;
    let mut aligned = true;
    let mut mixed = false;
    let mut data_end = false;
    let reason = loop {
        let left = len - at;
        if left == 0 {
            break "the file ends after a complete record, before the end of the data section".to_string();
        }
        let mut head = [0u8; RECORD_HEAD];
        let got = read_up_to(input, &mut head).map_err(read_err)?;
        if got < RECORD_HEAD {
            break format!("a record header is cut short ({got} of {RECORD_HEAD} bytes)");
        }
        let opcode = head[0];
        let rec_len = u64::from_le_bytes(head[1..].try_into().unwrap_or([0; 8]));
        let rest = left - RECORD_HEAD as u64;
        if rec_len > rest {
            break format!("record (opcode {opcode:#04x}) of {rec_len} bytes is cut short: {rest} bytes remain");
        }
        if rec_len > MAX_RECORD_BYTES as u64 {
            break format!(
                "record (opcode {opcode:#04x}) of {rec_len} bytes is longer than this reader's limit of {MAX_RECORD_BYTES} bytes"
            );
        }
        buf.clear();
        buf.extend_from_slice(&head);
        buf.resize(RECORD_HEAD + rec_len as usize, 0);
        let got = read_up_to(input, &mut buf[RECORD_HEAD..]).map_err(read_err)?;
        if got < rec_len as usize {
            break format!("record (opcode {opcode:#04x}) of {rec_len} bytes is cut short: {got} bytes remain");
        }
        if opcode == op::DATA_END || opcode == op::FOOTER {
            // the end of the data section: the last flush point
            data_end = true;
            if opcode == op::DATA_END {
                let saved = buf.get(RECORD_HEAD..RECORD_HEAD + 4).map_or(0, |b| u32::from_le_bytes(b.try_into().unwrap_or([0; 4])));
                let calculated = crc.clone().finalize();
                if saved != 0 && saved != calculated {
                    let dropped: Vec<String> = state.metadata.keys().cloned().collect();
                    state.metadata.clear();
                    break format!(
                        "the data section's CRC does not match (saved {saved:#010x}, calculated {calculated:#010x}): the chunks passed their own CRCs, so the damage is outside them, and the metadata records ({}) are left out",
                        if dropped.is_empty() { "none".to_string() } else { dropped.join(", ") }
                    );
                }
                metadata_verified = true;
            }
            break format!("the data section is intact, what follows it is not: {}", strip(normal));
        }
        // a repeat is skipped and left out of the CRC: a file whose only damage is a repeated
        // chunk still has its metadata verified
        if opcode == op::CHUNK && !seen_chunks.insert((rec_len, crc32fast::hash(&buf))) {
            duplicate_chunks += 1;
            at += buf.len() as u64;
            continue;
        }
        crc.update(&buf);
        let snapshot = Snapshot::take(&state);
        state.span = None;
        let mut record = buf.as_slice();
        if let Err(e) = feed(&mut record, options.clone(), &mut state, visitor) {
            snapshot.restore(&mut state);
            break format!("record (opcode {opcode:#04x}) at byte {at} is unreadable: {}", strip(&e));
        }
        // a flush point before this record (its messages start after every message before it)
        // or after it (a metadata record): hand over the messages before it
        // a record with messages of several channels: not our writer's chunks of one topic each
        mixed |= state.channels.iter().filter(|(id, c)| snapshot.channels.get(id).map_or(c.message_count > 0, |&n| c.message_count > n)).count() > 1;
        let starts_group = state.span.zip(max_end).is_some_and(|((first, _), end)| first > end);
        let flush = if starts_group {
            Some((snapshot, chunks))
        } else if opcode == op::METADATA {
            Some((Snapshot::take(&state), chunks))
        } else if held_bytes > HOLD_LIMIT_BYTES {
            aligned = false;
            Some((Snapshot::take(&state), chunks + usize::from(opcode == op::CHUNK)))
        } else {
            None
        };
        if let Some((mut point, chunks_before)) = flush {
            if let Err(e) = state.commit_first(point.pending, visitor) {
                // the visitor refused a message: nothing after the last flush point is kept
                confirmed.restore(&mut state);
                break format!("record (opcode {opcode:#04x}) at byte {at} is unreadable: {}", strip(&e));
            }
            point.pending = 0;
            confirmed = point;
            confirmed_chunks = chunks_before;
            held_bytes = 0;
        }
        if let Some((_, end)) = state.span {
            max_end = Some(max_end.map_or(end, |m| m.max(end)));
        }
        if opcode == op::CHUNK {
            chunks += 1;
            // the chunk's uncompressed size (MCAP "Chunk": after its start and end times)
            held_bytes += buf.get(RECORD_HEAD + 16..RECORD_HEAD + 24).map_or(0, |b| u64::from_le_bytes(b.try_into().unwrap_or([0; 8])));
        }
        at += buf.len() as u64;
    };
    let mut reason = reason;
    // at the end of the data section everything read is whole; otherwise the messages after
    // the last flush point are left out
    // (chunks that mix topics, another writer's: kept up to the last whole record, as their
    // flush points cannot be seen, and the report says so)
    let keep_all = data_end || (mixed && chunks > confirmed_chunks);
    aligned &= data_end || !keep_all;
    let committed = if keep_all { state.commit(visitor) } else { Ok(()) };
    if let Err(e) = &committed {
        reason = format!("a message after the last flush point is unreadable: {}", strip(e));
    }
    let held_back_chunks = if keep_all && committed.is_ok() {
        0
    } else {
        confirmed.restore(&mut state);
        let held = chunks - confirmed_chunks;
        chunks = confirmed_chunks;
        held
    };
    let report = RecoverReport {
        source: source.to_string(),
        file_len: len,
        complete: false,
        stopped_at: at,
        reason: Some(reason),
        chunks,
        messages: state.total,
        t_end_ns: state.t_end_ns,
        metadata: state.metadata.keys().cloned().collect(),
        metadata_verified,
        duplicate_chunks,
        held_back_chunks,
        aligned,
    };
    Ok((state, report))
}
