//! [`RecordingWriter`]: deterministic, crash-safe MCAP writing.
//!
//! - **Crash safety.** Everything goes to a hidden sibling `.<name>.partial` in the target
//!   directory; only [`RecordingWriter::finish`] (MCAP summary + footer, flush, fsync, rename,
//!   fsync of the directory) makes `path` appear, atomically. Dropping the writer without
//!   `finish` (error path, panic) deletes the temporary file; a kill leaves at most that hidden
//!   file, which the next `create` for the same path overwrites.
//! - **Determinism.** Two runs that write the same calls produce byte-identical files: fixed
//!   library string, no wall-clock or host data, single-threaded zstd (zstd output depends on
//!   its worker count, which the `mcap` crate defaults to the host's core count), schema and
//!   channel ids in order of first use, metadata in `BTreeMap` order, per-channel sequence
//!   numbers counting from 0, `publish_time = log_time`.
//! - **Format version.** The `recording` metadata record ([`RecordingInfo`]) always carries
//!   `format_version = FORMAT_VERSION`: the caller's, checked, or written alone by `finish` if
//!   the caller wrote none.

use std::collections::{BTreeMap, HashMap};
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use mcap::records::{MessageHeader, Metadata};

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
    path: PathBuf,
    tmp_path: PathBuf,
    file: String,
    topics: HashMap<String, TopicChannel>,
    /// Reused for every message, so writing allocates only when a message outgrows it.
    buf: Vec<u8>,
    wrote_recording_metadata: bool,
    finished: bool,
}

impl RecordingWriter {
    /// Writes to a temporary sibling file (`.NAME.partial` in the same directory) and only
    /// [`finish`](Self::finish) renames it to `path`. If dropped without `finish` (error,
    /// panic), the temp file is removed. A kill leaves at most the hidden temp file, never `path`.
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
        let name = path
            .file_name()
            .ok_or_else(|| Error::NotAFilePath { file: file.clone() })?;
        let mut tmp_name = std::ffi::OsString::from(".");
        tmp_name.push(name);
        tmp_name.push(".partial");
        let tmp_path = path.with_file_name(tmp_name);
        let io = |op, source| Error::Io {
            file: tmp_path.display().to_string(),
            op,
            source,
        };
        let out = File::create(&tmp_path).map_err(|e| io("creating", e))?;
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
        let mcap = options
            .create(BufWriter::new(out))
            .map_err(|source| Error::McapWrite {
                file: tmp_path.display().to_string(),
                source,
            });
        let mcap = match mcap {
            Ok(w) => w,
            Err(e) => {
                let _ = std::fs::remove_file(&tmp_path);
                return Err(e);
            }
        };
        Ok(Self {
            mcap: Some(mcap),
            path: path.to_path_buf(),
            tmp_path,
            file,
            topics: HashMap::new(),
            buf: Vec::with_capacity(4096),
            wrote_recording_metadata: false,
            finished: false,
        })
    }

    /// The final path (exists only after [`finish`](Self::finish)).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The temporary file being written.
    pub fn temp_path(&self) -> &Path {
        &self.tmp_path
    }

    fn mcap_err(&self, source: mcap::McapError) -> Error {
        Error::McapWrite {
            file: self.file.clone(),
            source,
        }
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
            .map_err(|source| Error::McapWrite {
                file: self.file.clone(),
                source,
            })
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
    /// `path`. Returns `path`. On error the temporary file is removed and `path` is untouched.
    pub fn finish(mut self) -> Result<PathBuf, Error> {
        if !self.wrote_recording_metadata {
            self.write_metadata_raw(RecordingInfo::NAME, &BTreeMap::new())?;
        }
        let tmp_file = self.tmp_path.display().to_string();
        let io = |op, source| Error::Io {
            file: tmp_file.clone(),
            op,
            source,
        };
        let Some(mut w) = self.mcap.take() else {
            unreachable!("finish consumes self");
        };
        w.finish().map_err(|source| Error::McapWrite {
            file: self.file.clone(),
            source,
        })?;
        let out = w
            .into_inner()
            .into_inner()
            .map_err(|e| io("flushing", e.into_error()))?;
        out.sync_all().map_err(|e| io("fsync", e))?;
        drop(out);
        std::fs::rename(&self.tmp_path, &self.path)
            .map_err(|e| io("renaming to the final path", e))?;
        self.finished = true;
        // make the rename itself durable; best effort, since some filesystems refuse to fsync
        // a directory, and the complete file is already in place
        let dir = match self.path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        let _ = File::open(dir).and_then(|d| d.sync_all());
        Ok(self.path.clone())
    }
}

impl Drop for RecordingWriter {
    fn drop(&mut self) {
        if self.finished {
            return;
        }
        if let Some(w) = self.mcap.take() {
            // into_inner() skips writing the summary that mcap's own Drop would write
            drop(w.into_inner());
        }
        let _ = std::fs::remove_file(&self.tmp_path);
    }
}
