//! [`RecordingWriter`]: deterministic, crash-safe, exclusive MCAP writing.
//!
//! - **Crash safety and exclusion.** The writer is an [`atomic::Output`](crate::atomic::Output):
//!   it locks the final name (a second writer of the same path, in this or another process, is
//!   refused with [`Error::Busy`]), writes a hidden sibling `.<name>.<pid>-<n>.partial` of its
//!   own, and only [`RecordingWriter::finish`] (MCAP summary + footer, flush, fsync, rename,
//!   fsync of the directory) makes `path` appear, atomically. Dropping the writer without
//!   `finish` (error path, panic) deletes the temporary file; a kill leaves at most that hidden
//!   file (and the lock file), which the next writer of the same path deletes.
//! - **Errors.** An I/O failure at any point is an [`Error::Io`] naming `path` and carrying the
//!   OS reason (the `mcap` crate's own I/O error hides it; it is unwrapped here).
//! - **Determinism.** Two runs that write the same calls produce byte-identical files: fixed
//!   library string, no wall-clock or host data (the temporary name never reaches the bytes),
//!   single-threaded zstd (zstd output depends on its worker count, which the `mcap` crate
//!   defaults to the host's core count), schema and channel ids in order of first use (from 1;
//!   identical schemas share one id), metadata
//!   in `BTreeMap` order, per-channel sequence numbers counting from 0, `publish_time = log_time`.
//! - **Off the caller's thread** (the default, [`WriterOptions::background`]): the caller
//!   encodes each message into a buffer taken from a free list and hands it over a bounded
//!   channel ([`WriterOptions::queue`] messages at most) to a thread that owns the `mcap`
//!   writer (chunking, compression, CRCs, summary) and hands the buffer back for reuse: no
//!   allocation per message once the buffers have grown, bounded memory, and a caller that
//!   runs ahead blocks rather than queues without limit. The thread runs the calls in order,
//!   so the bytes do not depend on its timing. An error of the thread (a full disk) is
//!   returned by the next call after it (a `write`, a record, or `finish`); a panic of it is an
//!   [`Error::Io`] naming the file. Dropping the writer stops the thread and deletes the
//!   temporary file as before.
//! - **Chunks per topic** (the default, [`WriterOptions::chunk_per_topic`]): each chunk holds
//!   the messages of one topic, so a reader of some topics skips the chunks of the others (the
//!   summary's chunk indexes name the channels of each chunk). See `writer/worker.rs`.
//! - **What a crash leaves** (the default, [`WriterOptions::flush_interval_ns`]): the chunks of
//!   every topic are written together, a *flush group*, at least every second of log time and
//!   whenever one is full, so a killed run's `.partial` (or any cut copy) holds every topic up
//!   to its last complete group, and [`crate::read_recording_recover`] reads exactly those
//!   groups (`analyze metrics --recover`). See `writer/worker.rs`.
//! - **Compression** ([`Compression`]): chosen by measurement (`cargo bench -p sim --bench
//!   record`): see [`WriterOptions::default`].
//! - **A tap** ([`RecordingWriter::create_tapped`]): every record written is also fed, on the
//!   writer's thread, to the reader's own record consumer ([`crate::Tap`]), which hands the
//!   messages of the chosen topics to a [`crate::Visitor`] exactly as a read of the finished
//!   file would: `sim` prints its table from what it wrote without reading it back.
//! - **A mirror** ([`RecordingWriter::create_mirrored`]): every record written is also handed,
//!   as written, to a [`Mirror`] (the tap is one; `sim --live` streams them to Foxglove). It
//!   only observes, so the file's bytes do not depend on it; with none, nothing is done or
//!   allocated per message for it.
//! - **Format version.** The `recording` metadata record ([`RecordingInfo`]) always carries
//!   `format_version = FORMAT_VERSION`: the caller's, checked, or written alone by `finish` if
//!   the caller wrote none.

use std::collections::{BTreeMap, HashMap};
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, SyncSender};
use std::sync::Arc;
use std::thread::JoinHandle;

use mcap::records::{MessageHeader, Metadata};

use crate::atomic::Output;
use crate::messages::Message;
use crate::meta::{to_entries, MetadataRecord, RecordingInfo};
use crate::reader::{Tap, Tapped};
use crate::{Error, FORMAT_VERSION};

mod mirror;
mod worker;
pub use mirror::Mirror;
use worker::{Done, Job, Worker};

/// The MCAP header's library string (fixed, so files do not depend on the build).
pub fn library_string() -> String {
    format!("elbow-sim schemas {FORMAT_VERSION}")
}

/// How chunks are compressed (MCAP spec "Chunk": `compression` is `""`, `zstd` or `lz4`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Compression {
    None,
    /// Zstandard at this level (1 fastest … 19 and up; 3 is zstd's default).
    Zstd { level: u32 },
    /// LZ4 frames at liblz4's default (fast) setting.
    Lz4,
}

/// How a [`RecordingWriter`] writes. [`Default`] is the project's choice, by measurement.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WriterOptions {
    pub compression: Compression,
    /// A chunk is closed once it holds at least this many uncompressed bytes.
    pub chunk_size: u64,
    /// Every chunk holds one topic (`false`: chunks hold the topics as written, interleaved).
    pub chunk_per_topic: bool,
    /// With a chunk per topic: the open chunks of every topic are written together (a flush
    /// group) at the first new log time once this much log time has passed, ns (0: only when a
    /// chunk is full). A cut file keeps every topic up to its last complete group (see
    /// `writer/worker.rs`, and [`crate::read_recording_recover`]).
    pub flush_interval_ns: u64,
    /// The `mcap` writer runs on a thread of its own (`false`: on the caller's).
    pub background: bool,
    /// Messages handed to the background thread and not yet written, at most.
    pub queue: usize,
}

impl WriterOptions {
    /// The writer of format versions up to this change: zstd level 3 in interleaved 1 MiB
    /// chunks, on the caller's thread (the baseline of `cargo bench -p sim --bench record`).
    pub const INLINE_MIXED_ZSTD3: WriterOptions =
        WriterOptions { compression: Compression::Zstd { level: 3 }, chunk_size: 1 << 20, chunk_per_topic: false, flush_interval_ns: 0, background: false, queue: 0 };
}

impl Default for WriterOptions {
    /// zstd level 1 (on a paper run, `cargo bench -p sim --bench record`: 0.74–0.78x the time
    /// of level 3 for +2 % size; level 6 2–3x the time for −0.2 %; lz4 +19–28 % size and not
    /// clearly faster; none 1.9x the size), 1 MiB chunks, one topic per chunk (+7–9 % size:
    /// the price of chunks a reader can skip), every topic's chunk written together at least
    /// every 1 s of log time (so a crash loses at most that; on the paper's 1 kHz two-elbow
    /// run +0.3 % size, the same write and `analyze metrics` time; +3.4–3.7 % on the archive's
    /// 50 Hz runs), on a
    /// background thread with 1024 messages in flight.
    fn default() -> Self {
        WriterOptions {
            compression: Compression::Zstd { level: 1 },
            chunk_size: 1 << 20,
            chunk_per_topic: true,
            flush_interval_ns: 1_000_000_000,
            background: true,
            queue: 1024,
        }
    }
}

/// A channel registered on first use of its topic.
struct TopicChannel {
    channel_id: u16,
    rust_type: &'static str,
    sequence: u32,
}

/// Where the jobs go.
enum Backend {
    /// The worker on the caller's thread (`None` once finished).
    Inline(Option<Box<Worker>>),
    Thread {
        jobs: SyncSender<Job>,
        /// Buffers the worker is done with.
        free: Receiver<Vec<u8>>,
        /// `None` once joined.
        handle: Option<JoinHandle<Result<Done, Error>>>,
        abort: Arc<AtomicBool>,
    },
}

/// Writes one recording. See the module docs for the guarantees.
pub struct RecordingWriter {
    backend: Backend,
    /// The lock of the final name and the temporary file; committed by `finish`, and deletes
    /// the temporary file when dropped uncommitted. `None` only inside `finish`.
    output: Option<Output>,
    path: PathBuf,
    file: String,
    topics: HashMap<String, TopicChannel>,
    /// Schemas registered, id = index + 1: (name, encoding, data).
    schemas: Vec<(String, &'static str, Vec<u8>)>,
    /// The buffer of the inline worker, reused for every message.
    spare: Vec<u8>,
    wrote_recording_metadata: bool,
}

/// An error of the `mcap` writer as ours: its I/O errors (disk full, …) as [`Error::Io`] with
/// the OS reason, which `mcap::McapError::Io`'s message leaves out.
fn write_error(file: &str, source: mcap::McapError) -> Error {
    match source {
        mcap::McapError::Io(source) => Error::Io { file: file.to_string(), op: "writing", source },
        source => Error::McapWrite { file: file.to_string(), source },
    }
}

fn thread_error(file: &str, detail: String) -> Error {
    Error::Io { file: file.to_string(), op: "writing", source: std::io::Error::other(detail) }
}

impl RecordingWriter {
    /// Locks `path` against other writers ([`Error::Busy`] if one holds it), writes to a
    /// temporary sibling file (`.NAME.<pid>-<n>.partial` in the same directory), and only
    /// [`finish`](Self::finish) renames it to `path`. If dropped without `finish` (error,
    /// panic), the temp file is removed. A kill leaves at most the hidden temp file, never
    /// `path`. See [`crate::atomic`]. Writes with [`WriterOptions::default`].
    pub fn create(path: &Path) -> Result<Self, Error> {
        Self::create_with(path, WriterOptions::default())
    }

    /// [`create`](Self::create), but closing a chunk once it holds more than `chunk_size`
    /// uncompressed bytes instead of the default (1 MiB), in chunks that interleave the topics
    /// as written: smaller chunks lose less of a file that is cut short (see
    /// [`crate::read_recording_recover`]).
    pub fn create_with_chunk_size(path: &Path, chunk_size: u64) -> Result<Self, Error> {
        Self::create_with(path, WriterOptions { chunk_size, chunk_per_topic: false, ..WriterOptions::default() })
    }

    /// [`create`](Self::create) with `options`.
    pub fn create_with(path: &Path, options: WriterOptions) -> Result<Self, Error> {
        Self::create_tapped(path, options, None)
    }

    /// [`create_with`](Self::create_with), and every record written is also fed to `tap`
    /// ([`Tap`]: the reader's own consumer of records, on the writer's thread); its
    /// [`Tapped`] comes back from [`finish_tapped`](Self::finish_tapped).
    pub fn create_tapped(path: &Path, options: WriterOptions, tap: Option<Tap>) -> Result<Self, Error> {
        Self::create_mirrored(path, options, tap, None)
    }

    /// [`create_tapped`](Self::create_tapped), and every record written is also handed to
    /// `mirror` ([`Mirror`]: after the tap, on the writer's thread, with the bytes written), up
    /// to [`Mirror::finish`] when the writer finishes or stops.
    pub fn create_mirrored(path: &Path, options: WriterOptions, tap: Option<Tap>, mirror: Option<Box<dyn Mirror>>) -> Result<Self, Error> {
        let file = path.display().to_string();
        let (output, out) = Output::create(path)?;
        // Profile "": the MCAP registry's "ros2" profile means every channel is cdr/ros2msg,
        // and ours mix protobuf with CDR. Neither Foxglove nor Rerun needs a profile
        // (VIEWERS.md; check_mcap.py only reports it).
        let (compression, level) = match options.compression {
            Compression::None => (None, 0),
            Compression::Zstd { level } => (Some(mcap::Compression::Zstd), level),
            Compression::Lz4 => (Some(mcap::Compression::Lz4), 0),
        };
        let mcap_options = mcap::WriteOptions::new()
            .profile("")
            .library(library_string())
            .compression(compression)
            .compression_level(level)
            .compression_threads(0)
            // with a chunk per topic the worker closes every chunk itself
            .chunk_size((!options.chunk_per_topic).then_some(options.chunk_size));
        // (an error drops `output`, which deletes the temporary file)
        let mcap = mcap_options.create(BufWriter::new(out)).map_err(|source| write_error(&file, source))?;
        // a mirror's panic must not take the recording with it (writer/mirror.rs)
        let mirror = mirror.map(|m| Box::new(mirror::Guarded::new(m)) as Box<dyn Mirror>);
        let worker = Worker::new(mcap, file.clone(), options, tap, mirror);
        let backend = if options.background {
            let queue = options.queue.max(1);
            let (jobs, inbox) = mpsc::sync_channel(queue);
            let (give_back, free) = mpsc::sync_channel(queue);
            let abort = Arc::new(AtomicBool::new(false));
            let stop = abort.clone();
            let handle = std::thread::Builder::new()
                .name("mcap-writer".into())
                .spawn(move || worker::run(worker, inbox, give_back, stop))
                .map_err(|source| Error::Io { file: file.clone(), op: "starting the writer thread", source })?;
            Backend::Thread { jobs, free, handle: Some(handle), abort }
        } else {
            Backend::Inline(Some(Box::new(worker)))
        };
        Ok(Self {
            backend,
            output: Some(output),
            path: path.to_path_buf(),
            file,
            topics: HashMap::new(),
            schemas: Vec::new(),
            spare: Vec::with_capacity(4096),
            wrote_recording_metadata: false,
        })
    }

    /// The final path (exists only after [`finish`](Self::finish)).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The temporary file being written.
    pub fn temp_path(&self) -> &Path {
        self.output.as_ref().map_or(Path::new(""), Output::temp_path)
    }

    /// The worker's error, once it stopped (its channel is closed): joins it.
    fn stopped(&mut self) -> Error {
        let Backend::Thread { handle, .. } = &mut self.backend else {
            return thread_error(&self.file, "the writer was used after it finished".into());
        };
        match handle.take().map(JoinHandle::join) {
            Some(Ok(Err(e))) => e,
            Some(Ok(Ok(_))) => thread_error(&self.file, "the writer thread stopped early".into()),
            Some(Err(panic)) => thread_error(&self.file, format!("the writer thread panicked: {}", crate::reader::panic_text(&*panic))),
            None => thread_error(&self.file, "an earlier write failed".into()),
        }
    }

    /// Runs `job`, here or on the worker; an error of the worker comes back here.
    fn send(&mut self, job: Job) -> Result<(), Error> {
        match &mut self.backend {
            Backend::Inline(Some(w)) => {
                let spare = &mut self.spare;
                w.job(job, &mut |buf| *spare = buf)
            }
            Backend::Inline(None) => Err(self.stopped()),
            Backend::Thread { jobs, .. } => match jobs.send(job) {
                Ok(()) => Ok(()),
                Err(_) => Err(self.stopped()),
            },
        }
    }

    /// An empty buffer for the next message: the inline worker's, or one the thread gave back.
    fn buffer(&mut self) -> Vec<u8> {
        match &self.backend {
            Backend::Thread { free, .. } => free.try_recv().unwrap_or_default(),
            Backend::Inline(_) => {
                let mut b = std::mem::take(&mut self.spare);
                b.clear();
                b
            }
        }
    }

    /// Writes the metadata record `record` ([`crate::meta`]). The [`RecordingInfo`] record must
    /// carry this writer's [`FORMAT_VERSION`] (use [`RecordingInfo::new`]).
    pub fn write_record<R: MetadataRecord>(&mut self, record: &R) -> Result<(), Error> {
        let entries = to_entries(record).map_err(|detail| Error::BadMetadata {
            file: self.file.clone(),
            record: R::NAME.into(),
            key: String::new(),
            detail,
        })?;
        self.write_metadata_raw(R::NAME, &entries)
    }

    /// Writes an MCAP metadata record `name` with any `entries` (in key order), bypassing the
    /// typed records: for tests of readers (malformed or foreign metadata). For the record
    /// `recording` the writer adds `format_version`; a different `format_version` is an error.
    pub fn write_metadata_raw(&mut self, name: &str, entries: &BTreeMap<String, String>) -> Result<(), Error> {
        let mut metadata = entries.clone();
        if name == RecordingInfo::NAME {
            let version = FORMAT_VERSION.to_string();
            let key = "format_version";
            match metadata.get(key) {
                Some(v) if *v != version => {
                    return Err(Error::BadMetadata {
                        file: self.file.clone(),
                        record: name.into(),
                        key: key.into(),
                        detail: format!("caller gave {v}, this writer writes format {version}"),
                    })
                }
                _ => metadata.insert(key.to_string(), version),
            };
            self.wrote_recording_metadata = true;
        }
        self.send(Job::Metadata(Metadata { name: name.to_string(), metadata }))
    }

    /// Writes `msg` on `topic` at `log_time_ns` (also its publish time). The first message on
    /// a topic registers its schema and channel; later messages must have the same type.
    pub fn write<M: Message>(
        &mut self,
        topic: &str,
        log_time_ns: u64,
        msg: &M,
    ) -> Result<(), Error> {
        let rust_type = std::any::type_name::<M>();
        if !self.topics.contains_key(topic) {
            let channel_id = self.register::<M>(topic)?;
            self.topics.insert(
                topic.to_string(),
                TopicChannel {
                    channel_id,
                    rust_type,
                    sequence: 0,
                },
            );
        }
        let Some(ch) = self.topics.get_mut(topic) else {
            unreachable!("registered above");
        };
        if ch.rust_type != rust_type {
            return Err(Error::TopicTypeMismatch {
                file: self.file.clone(),
                topic: topic.into(),
                first: ch.rust_type.into(),
                now: rust_type.into(),
            });
        }
        let header = MessageHeader {
            channel_id: ch.channel_id,
            sequence: ch.sequence,
            log_time: log_time_ns,
            publish_time: log_time_ns,
        };
        ch.sequence = ch.sequence.wrapping_add(1);

        let mut data = self.buffer();
        if let Err(detail) = msg.try_encode_into(&mut data) {
            return Err(Error::Encode {
                file: self.file.clone(),
                topic: topic.into(),
                schema: M::schema_name(),
                detail,
            });
        }
        self.send(Job::Message { header, data })
    }

    /// The schema (shared by identical ones) and channel of `topic`, numbered in order of first
    /// use from 1 (as the `mcap` writer numbers them).
    fn register<M: Message>(&mut self, topic: &str) -> Result<u16, Error> {
        let (name, encoding, data) = (M::schema_name(), M::schema_encoding(), M::schema_data());
        let too_many = |e| write_error(&self.file, e);
        let schema_id = match self.schemas.iter().position(|(n, e, d)| (n, *e, d) == (&name, encoding, &data)) {
            Some(k) => u16::try_from(k + 1).map_err(|_| too_many(mcap::McapError::TooManySchemas))?,
            None => {
                let id = u16::try_from(self.schemas.len() + 1).map_err(|_| too_many(mcap::McapError::TooManySchemas))?;
                self.schemas.push((name.clone(), encoding, data.clone()));
                self.send(Job::Schema { id, name, encoding, data })?;
                id
            }
        };
        let id = u16::try_from(self.topics.len() + 1).map_err(|_| write_error(&self.file, mcap::McapError::TooManyChannels))?;
        self.send(Job::Channel { id, schema_id, topic: topic.to_string(), encoding: M::message_encoding() })?;
        Ok(id)
    }

    /// Finishes the MCAP (summary, footer), flushes, fsyncs and renames the temporary file to
    /// `path`, and releases the lock. Returns `path`. On error the temporary file is removed
    /// and `path` is untouched.
    pub fn finish(self) -> Result<PathBuf, Error> {
        self.finish_tapped().map(|(path, _)| path)
    }

    /// [`finish`](Self::finish), and what the tap of [`create_tapped`](Self::create_tapped)
    /// saw (`None` without a tap).
    pub fn finish_tapped(mut self) -> Result<(PathBuf, Option<Tapped>), Error> {
        if !self.wrote_recording_metadata {
            self.write_metadata_raw(RecordingInfo::NAME, &BTreeMap::new())?;
        }
        let done = match &mut self.backend {
            Backend::Inline(w) => match w.take() {
                Some(w) => w.finish()?,
                None => return Err(self.stopped()),
            },
            Backend::Thread { jobs, handle, .. } => {
                let sent = jobs.send(Job::Finish);
                match (sent, handle.take().map(JoinHandle::join)) {
                    (Ok(()), Some(Ok(Ok(done)))) => done,
                    (_, Some(Ok(Err(e)))) => return Err(e),
                    (_, Some(Err(panic))) => return Err(thread_error(&self.file, format!("the writer thread panicked: {}", crate::reader::panic_text(&*panic)))),
                    _ => return Err(thread_error(&self.file, "the writer thread stopped early".into())),
                }
            }
        };
        let Some(file) = done.file else {
            return Err(thread_error(&self.file, "the writer thread stopped early".into()));
        };
        let Some(output) = self.output.take() else {
            unreachable!("finish consumes self");
        };
        Ok((output.commit(file)?, done.tapped))
    }
}

impl Drop for RecordingWriter {
    fn drop(&mut self) {
        // stop the worker, leaving the file unfinished; the `output` field, dropped next,
        // deletes the temporary file
        match std::mem::replace(&mut self.backend, Backend::Inline(None)) {
            Backend::Inline(w) => drop(w),
            Backend::Thread { jobs, handle, abort, free } => {
                abort.store(true, Ordering::Relaxed);
                drop((jobs, free));
                if let Some(h) = handle {
                    let _ = h.join();
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A full disk, for real: the `mcap` writer over `/dev/full` (every write fails with
    /// ENOSPC), its error mapped as the writer maps it. The OS reason must reach the message,
    /// which `mcap::McapError::Io` alone ("I/O error from writing ...") leaves out.
    #[test]
    fn a_full_disk_is_reported_with_the_os_reason() {
        let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
            eprintln!("skipped: no /dev/full here");
            return;
        };
        // more than the buffer, so the error surfaces at a write or at finish
        let meta = Metadata { name: "x".into(), metadata: BTreeMap::from([("k".into(), "v".repeat(1 << 16))]) };
        let result = (|| -> Result<(), mcap::McapError> {
            let mut w = mcap::WriteOptions::new()
                .compression(None)
                .create(BufWriter::with_capacity(16, full))?;
            w.write_metadata(&meta)?;
            w.finish().map(drop)
        })();
        let e = write_error("out/run.mcap", result.expect_err("writing to /dev/full fails"));
        let msg = e.to_string();
        assert!(matches!(e, Error::Io { .. }), "{msg}");
        assert!(msg.starts_with("out/run.mcap: ") && msg.contains("No space left on device"), "{msg}");
        let Error::Io { source, .. } = e else { unreachable!() };
        assert_eq!(source.raw_os_error(), Some(28)); // ENOSPC
    }
}
