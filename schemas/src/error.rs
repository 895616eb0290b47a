//! The one error type of the crate.
//!
//! Every variant names the file (`file`: a path, or the label given to
//! [`crate::read_recording_bytes`]) and, where relevant, the topic, message index and field, so a
//! message printed by `sim` or `analyze` says exactly which recording and which channel went wrong.
//! Malformed input is always an `Err`, never a panic.

/// Errors from writing or reading a recording.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// An operating-system I/O error (create, write, fsync, rename, read). The message ends
    /// with the OS reason (e.g. "No space left on device (os error 28)").
    #[error("{file}: {op}: {source}")]
    Io {
        file: String,
        op: &'static str,
        #[source]
        source: std::io::Error,
    },

    /// Another writer (process or thread) holds the lock of this output's final path
    /// ([`crate::atomic`]): refused up front, nothing was written.
    #[error(
        "{file}: another process is writing it (it holds the lock {lock}); nothing was written: \
         wait until it has finished, or choose another output"
    )]
    Busy { file: String, lock: String },

    /// The path handed to [`crate::RecordingWriter::create`] has no file name.
    #[error("{file}: not a file path")]
    NotAFilePath { file: String },

    /// The `mcap` library refused to write.
    #[error("{file}: writing MCAP: {source}")]
    McapWrite {
        file: String,
        #[source]
        source: mcap::McapError,
    },

    /// One topic may carry only one message type.
    #[error("{file}: topic {topic} was first written with {first}, now with {now}")]
    TopicTypeMismatch {
        file: String,
        topic: String,
        first: String,
        now: String,
    },

    /// A message could not be encoded (cannot happen for the crate's own types).
    #[error("{file}: topic {topic}: encoding a {schema} message failed: {detail}")]
    Encode {
        file: String,
        topic: String,
        schema: String,
        detail: String,
    },

    /// Metadata given by the caller contradicts what the writer stores itself.
    #[error("{file}: metadata {record}.{key}: {detail}")]
    BadMetadata {
        file: String,
        record: String,
        key: String,
        detail: String,
    },

    /// The bytes do not start with the MCAP magic (empty file, wrong format).
    #[error("{file}: not an MCAP file ({len} bytes, no MCAP magic at the start)")]
    NotMcap { file: String, len: u64 },

    /// The path is not a regular file (a directory, a device, a FIFO): refused before reading.
    #[error("{file}: not a regular file ({kind}): a recording is read from a file")]
    NotAFile { file: String, kind: &'static str },

    /// Log time goes backwards on a channel: the messages are not a time series (a damaged,
    /// spliced or foreign file); nothing is computed from them.
    #[error(
        "{file}: topic {topic}: message #{index} has log_time {log_time_ns} ns, before the \
         previous message's {previous_ns} ns (time goes backwards)"
    )]
    TimeBackwards {
        file: String,
        topic: String,
        index: usize,
        log_time_ns: u64,
        previous_ns: u64,
    },

    /// The consumer of a streamed read ([`crate::Visitor`]) refused a message and keeps the
    /// reason (it returns that instead).
    #[error("{file}: reading stopped by its consumer")]
    Stopped { file: String },

    /// The file says it is of a format version this reader does not know.
    #[error(
        "{file}: metadata record `{record}`: format_version = {version}: this reader knows \
         versions 0 to {supported}; a newer file needs a newer reader"
    )]
    UnsupportedFormat {
        file: String,
        record: &'static str,
        version: String,
        supported: u32,
    },

    /// The `mcap` library could not parse the file (truncation, bad CRC, bad record).
    #[error("{file}: unreadable MCAP: {source}")]
    McapRead {
        file: String,
        #[source]
        source: mcap::McapError,
    },

    /// Records parsed but the file ends before its footer.
    #[error("{file}: truncated MCAP: the file ends before its footer")]
    Truncated { file: String },

    /// Records are individually valid but inconsistent with each other.
    #[error("{file}: malformed MCAP: {detail}")]
    Malformed { file: String, detail: String },

    /// The schema of a channel cannot be used to decode it (bad descriptor set, bad .msg text).
    #[error("{file}: topic {topic}: schema {schema} ({encoding}) unusable: {detail}")]
    BadSchema {
        file: String,
        topic: String,
        schema: String,
        encoding: String,
        detail: String,
    },

    /// One message does not decode with its channel's schema.
    #[error(
        "{file}: topic {topic}: message #{index} (log_time {log_time_ns} ns, {encoding}): {detail}"
    )]
    Decode {
        file: String,
        topic: String,
        index: usize,
        log_time_ns: u64,
        encoding: String,
        detail: String,
    },

    /// [`crate::Recording::series`] was asked for a topic the file does not have.
    #[error("{file}: no topic {topic} (topics: {available:?})")]
    UnknownTopic {
        file: String,
        topic: String,
        available: Vec<String>,
    },

    /// The topic exists but its encoding is not one the generic reader decodes.
    #[error("{file}: topic {topic} was not decoded: {reason}")]
    UndecodedTopic {
        file: String,
        topic: String,
        reason: String,
    },

    /// A metadata record is missing, lacks a key its format version must have, or holds a value
    /// that does not parse.
    #[error("{file}: metadata record `{record}`: {detail}")]
    Metadata {
        file: String,
        record: String,
        detail: String,
    },

    /// A message does not have the fields (and types) its topic's struct needs.
    #[error("{file}: topic {topic}: message #{index} (log_time {log_time_ns} ns): {detail}")]
    Field {
        file: String,
        topic: String,
        index: usize,
        log_time_ns: u64,
        detail: String,
    },

    /// A per-joint or per-contact array has the wrong length.
    #[error(
        "{file}: topic {topic}, field {field}, message #{index} (t = {t_s} s): \
         {found} entries, expected {expected} (one per {per})"
    )]
    WrongLength {
        file: String,
        topic: String,
        field: String,
        index: usize,
        t_s: f64,
        found: usize,
        expected: usize,
        per: &'static str,
    },
}
