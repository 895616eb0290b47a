//! Generic, schema-driven reading of a whole recording.
//!
//! Nothing here assumes the file was written by [`crate::RecordingWriter`]: every channel is
//! decoded from the schema stored in the file (MCAP spec, <https://mcap.dev/spec>):
//!
//! - `protobuf` messages with a `protobuf` schema (a `FileDescriptorSet`): through a
//!   `prost-reflect` descriptor pool, one per schema;
//! - `cdr` messages with a `ros2msg` schema: the private `ros2msg` module parses the schema text,
//!   [`crate::cdr`] decodes;
//! - `json` messages (any schema or none): `serde_json`.
//!
//! A channel with any other encoding (ros1, flatbuffer, ros2idl, cbor, ...) is **skipped**: it
//! is listed in [`Recording::channels`] with [`ChannelInfo::undecoded`] saying why, and asking
//! [`Recording::series`] for it is an [`Error::UndecodedTopic`]. A channel that claims a supported
//! encoding but does not decode is an error, as is anything structurally wrong with the file
//! (no magic, truncated, CRC mismatch, message on an unknown channel, statistics disagreeing
//! with the data). Chunk CRCs are checked.

use std::collections::BTreeMap;
use std::path::Path;

use mcap::records::Record;
use prost_reflect::{DescriptorPool, DynamicMessage, MessageDescriptor, ReflectMessage};

use crate::value::Value;

mod recover;
mod typed;
use crate::{ros2msg, Error};
pub use typed::ArraySizes;
pub use recover::{read_recording_recover, read_recording_recover_bytes, RecoverReport};

/// One channel of the file.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelInfo {
    pub topic: String,
    pub schema_name: String,
    pub schema_encoding: String,
    pub message_encoding: String,
    pub message_count: usize,
    /// MCAP channel id.
    pub channel_id: u16,
    /// `Some(reason)` when the reader does not decode this encoding (its messages are skipped).
    pub undecoded: Option<String>,
}

/// A whole recording, decoded.
#[derive(Debug, Clone)]
pub struct Recording {
    /// The label errors use: the path, or the `source` given to [`read_recording_bytes`].
    pub source: String,
    /// Metadata records by name (records with the same name are merged, later keys win); read
    /// them typed ([`Recording::record`], [`Recording::run`], …).
    pub(crate) metadata: BTreeMap<String, BTreeMap<String, String>>,
    /// Channels in channel-id order.
    pub channels: Vec<ChannelInfo>,
    /// Decoded messages by topic, sorted by log time (stable: file order among equal times);
    /// read them typed ([`Recording::read`]) or generically ([`Recording::messages`]).
    pub(crate) messages: BTreeMap<String, Vec<(u64, Value)>>,
}

/// Reads and decodes the MCAP file at `path`; errors name the file.
pub fn read_recording(path: &Path) -> Result<Recording, Error> {
    read_recording_topics(path, None)
}

/// Like [`read_recording`], but decodes only the messages of `topics` (all when `None`).
///
/// The whole file is still read and checked (CRCs, statistics); messages of other channels are
/// counted and dropped undecoded, which is most of the cost of a recording with many
/// transforms. Those channels are listed in [`Recording::channels`] with
/// [`ChannelInfo::undecoded`] = "not selected", so asking for them is an error, never an empty
/// series.
pub fn read_recording_topics(path: &Path, topics: Option<&[&str]>) -> Result<Recording, Error> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| Error::Io {
        file: file.clone(),
        op: "reading",
        source,
    })?;
    read_recording_bytes_topics(&bytes, &file, topics)
}

struct SchemaRec {
    name: String,
    encoding: String,
    data: Vec<u8>,
}

enum Decoder {
    Protobuf(MessageDescriptor),
    Ros2(ros2msg::MsgSchema),
    Json,
    Skip(String),
}

/// Chooses and builds the decoder of a channel from its encodings and schema.
fn decoder_for(
    file: &str,
    info: &ChannelInfo,
    schema: Option<&SchemaRec>,
) -> Result<Decoder, Error> {
    let bad = |detail: String| Error::BadSchema {
        file: file.to_string(),
        topic: info.topic.clone(),
        schema: info.schema_name.clone(),
        encoding: info.schema_encoding.clone(),
        detail,
    };
    let (menc, senc) = (
        info.message_encoding.as_str(),
        info.schema_encoding.as_str(),
    );
    match (menc, senc, schema) {
        ("json", _, _) => Ok(Decoder::Json),
        ("protobuf", "protobuf", Some(s)) => {
            let pool = DescriptorPool::decode(s.data.as_slice()).map_err(|e| bad(e.to_string()))?;
            let desc = pool
                .get_message_by_name(&s.name)
                .ok_or_else(|| bad(format!("the descriptor set has no message {}", s.name)))?;
            Ok(Decoder::Protobuf(desc))
        }
        ("cdr", "ros2msg", Some(s)) => {
            let text = std::str::from_utf8(&s.data)
                .map_err(|e| bad(format!("schema text is not UTF-8: {e}")))?;
            Ok(Decoder::Ros2(ros2msg::parse(&s.name, text).map_err(bad)?))
        }
        _ => Ok(Decoder::Skip(format!(
            "message encoding {menc:?} with schema encoding {senc:?} is not decoded by this reader"
        ))),
    }
}

/// [`ChannelInfo::undecoded`] of a channel left out by [`read_recording_topics`].
pub const NOT_SELECTED: &str = "not selected: the file was read for other topics only";

/// Smallest record-length limit: no record (inside a chunk or not) may be longer than the
/// larger of this and the file itself, so a corrupt length cannot make us allocate wildly.
const MIN_RECORD_LENGTH_LIMIT: usize = 64 << 20;

/// Reads and decodes MCAP bytes; `source` labels the bytes in errors (e.g. a path).
///
/// Two dependencies can panic on corrupt input that no CRC protects (found by
/// `tests/robustness.rs`): `mcap` 0.26 (integer overflow when a record overruns an
/// uncompressed chunk, in builds with overflow checks) and `prost-reflect` 0.16 (index out of
/// bounds while describing an error in a corrupt descriptor set). Such a panic is caught and
/// returned as [`Error::Malformed`]; the panic hook still prints it to stderr.
pub fn read_recording_bytes(bytes: &[u8], source: &str) -> Result<Recording, Error> {
    read_recording_bytes_topics(bytes, source, None)
}

/// [`read_recording_bytes`] decoding only the messages of `topics` (see
/// [`read_recording_topics`]).
pub fn read_recording_bytes_topics(
    bytes: &[u8],
    source: &str,
    topics: Option<&[&str]>,
) -> Result<Recording, Error> {
    let parsed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        read_mcap(bytes, source, topics)
    }));
    parsed.unwrap_or_else(|panic| {
        let why = panic
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_default();
        Err(Error::Malformed {
            file: source.to_string(),
            detail: format!("the MCAP parser panicked on this input: {why}"),
        })
    })
}

/// The reader options: every CRC the format has is checked, chunks before any of their records
/// are used, and no record may be longer than the larger of the input and
/// [`MIN_RECORD_LENGTH_LIMIT`].
fn reader_options(len: usize) -> mcap::sans_io::LinearReaderOptions {
    mcap::sans_io::LinearReaderOptions::default()
        .with_record_length_limit(len.max(MIN_RECORD_LENGTH_LIMIT))
        .with_validate_chunk_crcs(true)
        .with_prevalidate_chunk_crcs(true)
        .with_validate_data_section_crc(true)
        .with_validate_summary_section_crc(true)
        .with_check_finishes_after_end_magic(true)
}

/// Runs `bytes` through a linear reader with `options`, handing every record to `state`.
fn feed(
    bytes: &[u8],
    options: mcap::sans_io::LinearReaderOptions,
    state: &mut State,
) -> Result<(), Error> {
    use mcap::sans_io::{LinearReadEvent, LinearReader};
    let mut reader = LinearReader::new_with_options(options);
    let mut rest = bytes;
    while let Some(event) = reader.next_event() {
        let event = event.map_err(|source| Error::McapRead {
            file: state.file.clone(),
            source,
        })?;
        match event {
            LinearReadEvent::ReadRequest(need) => {
                let n = need.min(rest.len());
                reader.insert(n).copy_from_slice(&rest[..n]);
                reader.notify_read(n);
                rest = &rest[n..];
            }
            LinearReadEvent::Record { opcode, data } => {
                let record =
                    mcap::parse_record(opcode, data).map_err(|source| Error::McapRead {
                        file: state.file.clone(),
                        source,
                    })?;
                state.record(record)?;
            }
        }
    }
    Ok(())
}

fn read_mcap(bytes: &[u8], source: &str, topics: Option<&[&str]>) -> Result<Recording, Error> {
    let file = source.to_string();
    if !bytes.starts_with(mcap::MAGIC) {
        return Err(Error::NotMcap {
            file,
            len: bytes.len(),
        });
    }
    let mut state = State {
        file,
        only: topics.map(|t| t.iter().map(|s| s.to_string()).collect()),
        ..State::default()
    };
    feed(bytes, reader_options(bytes.len()), &mut state)?;
    state.finish()
}

/// What has been read so far.
#[derive(Default)]
struct State {
    file: String,
    /// Topics whose messages are decoded (`None`: all).
    only: Option<std::collections::BTreeSet<String>>,
    schemas: BTreeMap<u16, SchemaRec>,
    channels: BTreeMap<u16, ChannelInfo>,
    decoders: BTreeMap<u16, Decoder>,
    metadata: BTreeMap<String, BTreeMap<String, String>>,
    messages: BTreeMap<String, Vec<(u64, Value)>>,
    stats_count: Option<u64>,
    total: u64,
    footer: bool,
}

impl State {
    fn malformed(&self, detail: String) -> Error {
        Error::Malformed {
            file: self.file.clone(),
            detail,
        }
    }

    fn record(&mut self, record: Record<'_>) -> Result<(), Error> {
        match record {
            Record::Schema { header, data } => {
                let new = SchemaRec {
                    name: header.name,
                    encoding: header.encoding,
                    data: data.into_owned(),
                };
                match self.schemas.get(&header.id) {
                    Some(old)
                        if (&old.name, &old.encoding, &old.data)
                            != (&new.name, &new.encoding, &new.data) =>
                    {
                        return Err(self.malformed(format!(
                            "schema id {} defined twice, differently",
                            header.id
                        )));
                    }
                    Some(_) => {}
                    None => {
                        self.schemas.insert(header.id, new);
                    }
                }
            }
            Record::Channel(ch) => self.channel(ch)?,
            Record::Message { header, data } => self.message(&header, &data)?,
            Record::Metadata(m) => self.metadata.entry(m.name).or_default().extend(m.metadata),
            Record::Statistics(s) => self.stats_count = Some(s.message_count),
            Record::Footer(_) => self.footer = true,
            _ => {}
        }
        Ok(())
    }

    fn channel(&mut self, ch: mcap::records::Channel) -> Result<(), Error> {
        let schema = match ch.schema_id {
            0 => None,
            id => Some(self.schemas.get(&id).ok_or_else(|| {
                self.malformed(format!(
                    "channel {} ({}) uses unknown schema id {id}",
                    ch.id, ch.topic
                ))
            })?),
        };
        let mut info = ChannelInfo {
            topic: ch.topic,
            schema_name: schema.map(|s| s.name.clone()).unwrap_or_default(),
            schema_encoding: schema.map(|s| s.encoding.clone()).unwrap_or_default(),
            message_encoding: ch.message_encoding,
            message_count: 0,
            channel_id: ch.id,
            undecoded: None,
        };
        if let Some(old) = self.channels.get(&ch.id) {
            if (&old.topic, &old.schema_name, &old.message_encoding)
                != (&info.topic, &info.schema_name, &info.message_encoding)
            {
                return Err(
                    self.malformed(format!("channel id {} defined twice, differently", ch.id))
                );
            }
            return Ok(()); // the summary section repeats channels
        }
        let selected = self.only.as_ref().is_none_or(|only| only.contains(&info.topic));
        let decoder = if selected {
            decoder_for(&self.file, &info, schema)?
        } else {
            Decoder::Skip(NOT_SELECTED.to_string())
        };
        if let Decoder::Skip(why) = &decoder {
            info.undecoded = Some(why.clone());
        }
        self.decoders.insert(ch.id, decoder);
        self.channels.insert(ch.id, info);
        Ok(())
    }

    fn message(&mut self, header: &mcap::records::MessageHeader, data: &[u8]) -> Result<(), Error> {
        let (Some(info), Some(decoder)) = (
            self.channels.get_mut(&header.channel_id),
            self.decoders.get(&header.channel_id),
        ) else {
            return Err(self.malformed(format!(
                "message on unknown channel id {}",
                header.channel_id
            )));
        };
        let index = info.message_count;
        info.message_count += 1;
        self.total += 1;
        let decode_err = |detail: String| Error::Decode {
            file: self.file.clone(),
            topic: info.topic.clone(),
            index,
            log_time_ns: header.log_time,
            encoding: info.message_encoding.clone(),
            detail,
        };
        let value = match decoder {
            Decoder::Skip(_) => return Ok(()),
            Decoder::Protobuf(desc) => DynamicMessage::decode(desc.clone(), data)
                .map(|m| message_to_value(&m))
                .map_err(|e| decode_err(e.to_string()))?,
            Decoder::Ros2(schema) => crate::cdr::decode(schema, data).map_err(decode_err)?,
            Decoder::Json => serde_json::from_slice::<serde_json::Value>(data)
                .map(|j| Value::from_json(&j))
                .map_err(|e| decode_err(e.to_string()))?,
        };
        self.messages
            .entry(info.topic.clone())
            .or_default()
            .push((header.log_time, value));
        Ok(())
    }

    fn finish(self) -> Result<Recording, Error> {
        if !self.footer {
            return Err(Error::Truncated { file: self.file });
        }
        if let Some(n) = self.stats_count.filter(|&n| n != self.total) {
            return Err(self.malformed(format!(
                "statistics count {n} messages, the data section has {}",
                self.total
            )));
        }
        Ok(self.into_recording())
    }

    /// The recording read so far, messages sorted by log time (stable).
    fn into_recording(mut self) -> Recording {
        for list in self.messages.values_mut() {
            list.sort_by_key(|(t, _)| *t);
        }
        Recording {
            source: self.file,
            metadata: self.metadata,
            channels: self.channels.into_values().collect(),
            messages: self.messages,
        }
    }
}

/// Converts a decoded protobuf message, fields in descriptor order. Members of a oneof (and
/// proto3 `optional` fields) that are not set are left out; other unset fields read as their
/// default, as protobuf defines.
fn message_to_value(msg: &DynamicMessage) -> Value {
    let mut out = Vec::new();
    for fd in msg.descriptor().fields() {
        if fd.containing_oneof().is_some() && !msg.has_field(&fd) {
            continue;
        }
        out.push((fd.name().to_string(), proto_to_value(&msg.get_field(&fd))));
    }
    Value::Struct(out)
}

fn proto_to_value(v: &prost_reflect::Value) -> Value {
    use prost_reflect::{MapKey, Value as P};
    match v {
        P::Bool(b) => Value::Bool(*b),
        P::I32(x) => Value::I64(i64::from(*x)),
        P::I64(x) => Value::I64(*x),
        P::U32(x) => Value::U64(u64::from(*x)),
        P::U64(x) => Value::U64(*x),
        P::F32(x) => Value::F64(f64::from(*x)),
        P::F64(x) => Value::F64(*x),
        P::String(s) => Value::String(s.clone()),
        P::Bytes(b) => Value::Bytes(b.to_vec()),
        P::EnumNumber(n) => Value::I64(i64::from(*n)),
        P::Message(m) => message_to_value(m),
        P::List(items) => Value::List(items.iter().map(proto_to_value).collect()),
        P::Map(map) => {
            let mut entries: Vec<(&MapKey, &P)> = map.iter().collect();
            entries.sort_by(|a, b| a.0.cmp(b.0));
            let key = |k: &MapKey| match k {
                MapKey::Bool(b) => Value::Bool(*b),
                MapKey::I32(x) => Value::I64(i64::from(*x)),
                MapKey::I64(x) => Value::I64(*x),
                MapKey::U32(x) => Value::U64(u64::from(*x)),
                MapKey::U64(x) => Value::U64(*x),
                MapKey::String(s) => Value::String(s.clone()),
            };
            Value::List(
                entries
                    .into_iter()
                    .map(|(k, v)| {
                        Value::Struct(vec![
                            ("key".into(), key(k)),
                            ("value".into(), proto_to_value(v)),
                        ])
                    })
                    .collect(),
            )
        }
    }
}

impl Recording {
    /// The channel of `topic` (the first one, if several share the topic).
    pub fn channel(&self, topic: &str) -> Option<&ChannelInfo> {
        self.channels.iter().find(|c| c.topic == topic)
    }

    /// Every decoded message by topic, sorted by log time: for tools that handle any topic
    /// generically (tables, export, checks).
    pub fn message_map(&self) -> &BTreeMap<String, Vec<(u64, Value)>> {
        &self.messages
    }

    /// Every decoded message of `topic` (log time in ns, decoded value), for tools that handle
    /// any topic generically (tables, export); `None` when the file has none decoded.
    pub fn messages(&self, topic: &str) -> Option<&[(u64, Value)]> {
        self.messages.get(topic).map(Vec::as_slice)
    }
}
