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
//!   defaults to the host's core count), schema and channel ids in order of first use, metadata
//!   in `BTreeMap` order, per-channel sequence numbers counting from 0, `publish_time = log_time`.
//! - **Format version.** The `recording` metadata record ([`RecordingInfo`]) always carries
//!   `format_version = FORMAT_VERSION`: the caller's, checked, or written alone by `finish` if
//!   the caller wrote none.

use std::collections::{BTreeMap, HashMap};
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use mcap::records::{MessageHeader, Metadata};

use crate::atomic::Output;
use crate::messages::Message;
use crate::meta::{to_entries, MetadataRecord, RecordingInfo};
use crate::{Error, FORMAT_VERSION};

/// The MCAP header's library string (fixed, so files do not depend on the build).
pub fn library_string() -> String {
    format!("elbow-sim schemas {FORMAT_VERSION}")
}

/// A channel registered on first use of its topic.
struct TopicChannel {
    channel_id: u16,
    rust_type: &'static str,
    sequence: u32,
}

/// Writes one recording. See the module docs for the guarantees.
pub struct RecordingWriter {
    /// `None` only after `finish` took it.
    mcap: Option<mcap::Writer<BufWriter<File>>>,
    /// The lock of the final name and the temporary file; committed by `finish`, and deletes
    /// the temporary file when dropped uncommitted. `None` only inside `finish`.
    output: Option<Output>,
    path: PathBuf,
    file: String,
    topics: HashMap<String, TopicChannel>,
    /// Reused for every message, so writing allocates only when a message outgrows it.
    buf: Vec<u8>,
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

impl RecordingWriter {
    /// Locks `path` against other writers ([`Error::Busy`] if one holds it), writes to a
    /// temporary sibling file (`.NAME.<pid>-<n>.partial` in the same directory), and only
    /// [`finish`](Self::finish) renames it to `path`. If dropped without `finish` (error,
    /// panic), the temp file is removed. A kill leaves at most the hidden temp file, never
    /// `path`. See [`crate::atomic`].
    pub fn create(path: &Path) -> Result<Self, Error> {
        Self::create_with(path, None)
    }

    /// [`create`](Self::create), but closing a chunk once it holds more than `chunk_size`
    /// uncompressed bytes instead of the `mcap` default (1 MiB): smaller chunks lose less of
    /// a file that is cut short (see [`crate::read_recording_recover`]). `create` output is
    /// unchanged by this option's existence.
    pub fn create_with_chunk_size(path: &Path, chunk_size: u64) -> Result<Self, Error> {
        Self::create_with(path, Some(chunk_size))
    }

    fn create_with(path: &Path, chunk_size: Option<u64>) -> Result<Self, Error> {
        let file = path.display().to_string();
        let (output, out) = Output::create(path)?;
        // Profile "": the MCAP registry's "ros2" profile means every channel is cdr/ros2msg,
        // and ours mix protobuf with CDR. Neither Foxglove nor Rerun needs a profile
        // (VIEWERS.md; check_mcap.py only reports it).
        let options = mcap::WriteOptions::new()
            .profile("")
            .library(library_string())
            .compression(Some(mcap::Compression::Zstd))
            .compression_threads(0);
        let options = match chunk_size {
            Some(n) => options.chunk_size(Some(n)),
            None => options,
        };
        // (an error drops `output`, which deletes the temporary file)
        let mcap = options
            .create(BufWriter::new(out))
            .map_err(|source| write_error(&file, source))?;
        Ok(Self {
            mcap: Some(mcap),
            output: Some(output),
            path: path.to_path_buf(),
            file,
            topics: HashMap::new(),
            buf: Vec::with_capacity(4096),
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

    fn mcap_err(&self, source: mcap::McapError) -> Error {
        write_error(&self.file, source)
    }

    fn mcap(&mut self) -> &mut mcap::Writer<BufWriter<File>> {
        // the Option is None only inside finish(), which consumes self
        self.mcap
            .as_mut()
            .expect("RecordingWriter used after finish")
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
        let record = Metadata { name: name.to_string(), metadata };
        self.mcap().write_metadata(&record).map_err(|e| self.mcap_err(e))
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

        self.buf.clear();
        if let Err(detail) = msg.try_encode_into(&mut self.buf) {
            return Err(Error::Encode {
                file: self.file.clone(),
                topic: topic.into(),
                schema: M::schema_name(),
                detail,
            });
        }
        let Some(w) = self.mcap.as_mut() else {
            unreachable!("RecordingWriter used after finish");
        };
        w.write_to_known_channel(&header, &self.buf)
            .map_err(|source| write_error(&self.file, source))
    }

    fn register<M: Message>(&mut self, topic: &str) -> Result<u16, Error> {
        let (name, data) = (M::schema_name(), M::schema_data());
        let w = self.mcap();
        let result = w
            .add_schema(&name, M::schema_encoding(), &data)
            .and_then(|schema_id| {
                w.add_channel(schema_id, topic, M::message_encoding(), &BTreeMap::new())
            });
        result.map_err(|e| self.mcap_err(e))
    }

    /// Finishes the MCAP (summary, footer), flushes, fsyncs and renames the temporary file to
    /// `path`, and releases the lock. Returns `path`. On error the temporary file is removed
    /// and `path` is untouched.
    pub fn finish(mut self) -> Result<PathBuf, Error> {
        if !self.wrote_recording_metadata {
            self.write_metadata_raw(RecordingInfo::NAME, &BTreeMap::new())?;
        }
        let Some(mut w) = self.mcap.take() else {
            unreachable!("finish consumes self");
        };
        w.finish().map_err(|source| write_error(&self.file, source))?;
        let out = w.into_inner().into_inner().map_err(|e| Error::Io {
            file: self.file.clone(),
            op: "writing",
            source: e.into_error(),
        })?;
        let Some(output) = self.output.take() else {
            unreachable!("finish consumes self");
        };
        output.commit(out)
    }
}

impl Drop for RecordingWriter {
    fn drop(&mut self) {
        if let Some(w) = self.mcap.take() {
            // into_inner() skips writing the summary that mcap's own Drop would write; the
            // `output` field, dropped next, deletes the temporary file
            drop(w.into_inner());
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
