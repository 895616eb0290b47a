//! Generic, schema-driven reading of a recording, streamed.
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
//! for its messages is an [`Error::UndecodedTopic`]. A channel that claims a supported encoding
//! but does not decode is an error, as is anything structurally wrong with the file (no magic,
//! truncated, CRC mismatch, message on an unknown channel, statistics disagreeing with the data,
//! a record over [`MAX_RECORD_BYTES`], log time going backwards on a channel, a format version
//! newer than [`crate::FORMAT_VERSION`]). Chunk CRCs are checked before a chunk's records are
//! used, and the data section's CRC at its end.
//!
//! **Memory is bounded by the work, not by the file.** The file is read through the `mcap`
//! crate's sans-I/O linear reader ([`mcap::sans_io::LinearReader`]) from a buffered `File`, one
//! record at a time (a chunk is at most [`MAX_RECORD_BYTES`] compressed and uncompressed), and
//! each decoded message is handed to a [`Visitor`] ([`stream_recording`]) that keeps what its
//! command needs — running sums for `analyze metrics`, the whole series for a table. Only
//! [`read_recording`] collects every decoded message (as [`Value`]s, several times the file's
//! size: use it for what needs the series). A path is checked before anything is read: it must
//! be a regular file (not a directory, FIFO or `/dev/zero`) that starts with the MCAP magic.

use std::collections::BTreeMap;
use std::io::Read;
use std::path::Path;

use mcap::records::Record;
use prost_reflect::DynamicMessage;

use crate::meta::{MetadataRecord, RunDescription};
use crate::topics::{array_index, ArrayIndex};
use crate::value::Value;

mod chunks;
mod decode;
mod idmap;
use idmap::IdMap;
mod input;
mod known;
mod recover;
mod tap;
#[cfg(feature = "synth")]
mod regroup;
mod typed;
mod visit;
mod wire;
use crate::Error;
pub use input::{open_regular, starts_with_mcap_magic};
pub use recover::{read_recording_recover, read_recording_recover_bytes, stream_recording_recover, RecoverReport};
pub use tap::{Tap, Tapped};
pub use typed::ArraySizes;
#[cfg(feature = "synth")]
pub use regroup::regroup_chunks;
pub use visit::{Body, DecodedMessage, Known, Visitor};
pub(crate) use visit::{decode_typed, Collect};
use decode::{decoder_for, message_to_value, Decoder, SchemaRec};

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

/// A recording, decoded: its metadata and channels, and the decoded messages when it was read
/// by [`read_recording`] (a [`stream_recording`] hands them to its visitor instead).
#[derive(Debug, Clone)]
pub struct Recording {
    /// The label errors use: the path, or the `source` given to [`read_recording_bytes`].
    pub source: String,
    /// Metadata records by name (records with the same name are merged, later keys win); read
    /// them typed ([`Recording::record`], [`Recording::run`], …).
    pub(crate) metadata: BTreeMap<String, BTreeMap<String, String>>,
    /// Channels in channel-id order.
    pub channels: Vec<ChannelInfo>,
    /// Decoded messages by topic, in log-time order (which the reader checks per channel);
    /// read them typed ([`Recording::read`]) or generically ([`Recording::messages`]).
    pub(crate) messages: BTreeMap<String, Vec<(u64, Value)>>,
    /// Length of the first per-joint array decoded (names the joints of format 0).
    pub(crate) first_joint_array_len: Option<usize>,
    /// Whether the first `/energy` message decoded has `gear_friction_loss` (format ≥ 2).
    pub(crate) energy_has_gear_friction: bool,
    /// Chunks that were not decompressed: they hold none of the topics read.
    pub(crate) chunks_skipped: usize,
}

/// Reads and decodes the MCAP file at `path`, keeping every message; errors name the file.
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
    let mut all = Collect::default();
    let mut rec = stream_recording(path, topics, &mut all)?;
    rec.messages = all.0;
    Ok(rec)
}

/// Reads the MCAP file at `path` once, from the start, handing every decoded message of
/// `topics` (all when `None`) to `visitor` as it is read, and returns the metadata and
/// channels (its `messages` are empty). Memory: one record at a time plus what `visitor`
/// keeps. The visitor may have seen messages of a file that turns out bad: only an `Ok`
/// result says the whole file was read and checked.
pub fn stream_recording(path: &Path, topics: Option<&[&str]>, visitor: &mut dyn Visitor) -> Result<Recording, Error> {
    let (mut file, len, label) = input::open(path)?;
    let summary = topics.and_then(|_| chunks::summary_of_file(&mut file, len));
    // read through maps of the file, a window at a time (`input::Windows`)
    let mut input = input::Windows::new(file.into_inner(), len).map_err(|source| Error::Io { file: label.clone(), op: "reading", source })?;
    Ok(read_state(&mut input, len, label, topics, summary.as_deref(), visitor)?.into_recording())
}

/// Reads a whole MCAP input of `len` bytes into the state (messages to `visitor`) and checks
/// that it is complete and consistent.
///
/// With `summary` (the file's summary section, read first) and `topics`, the chunks that hold
/// none of `topics` are not decompressed ([`chunks`]).
fn read_state(
    input: &mut dyn Read,
    len: u64,
    label: String,
    topics: Option<&[&str]>,
    summary: Option<&[u8]>,
    visitor: &mut dyn Visitor,
) -> Result<State, Error> {
    let mut state = State::new(label, topics);
    state.typed = visitor.typed();
    state.by_ref = state.typed && visitor.by_ref();
    if let (Some(summary), Some(_)) = (summary, topics) {
        state.skip = chunks::prefeed(&mut state, summary);
    }
    feed(input, reader_options(), &mut state, visitor)?;
    state.check_read_all(len)?;
    state.check_complete()?;
    Ok(state)
}

/// Drops every message (a check of the file alone).
struct Null;

impl Visitor for Null {
    fn message(&mut self, _: DecodedMessage<'_>) -> Result<(), Error> {
        Ok(())
    }
}

/// [`ChannelInfo::undecoded`] of a channel left out by [`read_recording_topics`].
pub const NOT_SELECTED: &str = "not selected: the file was read for other topics only";

/// The longest record (and the longest chunk, compressed or uncompressed) the reader accepts:
/// it bounds the reader's memory whatever the file says. `sim` writes chunks of 1 MiB; a file
/// with a longer record (a large attachment, a huge chunk) is refused with the record's size.
pub const MAX_RECORD_BYTES: usize = 64 << 20;

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
    if !bytes.starts_with(mcap::MAGIC) {
        return Err(Error::NotMcap { file: source.to_string(), len: bytes.len() as u64 });
    }
    let mut all = Collect::default();
    let mut input = bytes;
    let summary = topics.and_then(|_| chunks::summary_of_bytes(bytes));
    let mut rec = read_state(&mut input, bytes.len() as u64, source.to_string(), topics, summary, &mut all)?.into_recording();
    rec.messages = all.0;
    Ok(rec)
}

/// The text of a caught panic.
pub(crate) fn panic_text(panic: &(dyn std::any::Any + Send)) -> String {
    panic
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_default()
}

/// The reader options: every CRC the format has is checked, chunks before any of their records
/// are used, and no record may be longer than [`MAX_RECORD_BYTES`].
/// The error of message `index` of `info`'s channel that did not decode (`detail` says why).
fn decode_error(file: &str, info: &ChannelInfo, index: usize, header: &mcap::records::MessageHeader, detail: String) -> Error {
    Error::Decode { file: file.to_owned(), topic: info.topic.clone(), index, log_time_ns: header.log_time, encoding: info.message_encoding.clone(), detail }
}

fn reader_options() -> mcap::sans_io::LinearReaderOptions {
    mcap::sans_io::LinearReaderOptions::default()
        .with_record_length_limit(MAX_RECORD_BYTES)
        .with_validate_chunk_crcs(true)
        .with_prevalidate_chunk_crcs(true)
        .with_validate_data_section_crc(true)
        .with_validate_summary_section_crc(true)
        .with_check_finishes_after_end_magic(true)
}

/// Runs `input` through a linear reader with `options`, handing every record to `state` (and
/// its messages to `visitor`). A panic of a dependency on corrupt input is caught and returned
/// as [`Error::Malformed`] (see [`read_recording_bytes`]).
fn feed(
    input: &mut dyn Read,
    options: mcap::sans_io::LinearReaderOptions,
    state: &mut State,
    visitor: &mut dyn Visitor,
) -> Result<(), Error> {
    let fed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        feed_records(input, options, state, visitor)
    }));
    fed.unwrap_or_else(|panic| {
        Err(Error::Malformed {
            file: state.file.clone(),
            detail: format!("the MCAP parser panicked on this input: {}", panic_text(&*panic)),
        })
    })
}

fn feed_records(
    input: &mut dyn Read,
    options: mcap::sans_io::LinearReaderOptions,
    state: &mut State,
    visitor: &mut dyn Visitor,
) -> Result<(), Error> {
    let file = state.file.clone();
    let mut bytes = 0;
    // skipping chunks: the reader yields them whole, and the skipper decides
    let mut skipper = state.skip.then(chunks::Skipper::default);
    let options = options.with_emit_chunks(skipper.is_some());
    // where the next record starts: after the magic, each record is opcode, length, content
    let mut offset = mcap::MAGIC.len() as u64;
    let fed = pump(input, options, &file, &mut bytes, &mut |opcode, data| {
        let mcap_err = |source| Error::McapRead { file: file.clone(), source };
        let at = offset;
        offset += 9 + data.len() as u64;
        if let Some(sk) = skipper.as_mut() {
            if sk.take(opcode, data, at, state, visitor)? {
                return Ok(());
            }
        }
        state.record(mcap::parse_record(opcode, data).map_err(mcap_err)?, visitor)
    });
    state.bytes_read += bytes;
    fed?;
    if let Some(mut sk) = skipper {
        sk.resolve(state, visitor)?;
        state.chunks_skipped += sk.skipped;
    }
    Ok(())
}

/// What [`pump`] does with each record: its opcode and content.
type OnRecord<'a> = dyn FnMut(u8, &[u8]) -> Result<(), Error> + 'a;

/// Runs `input` through a linear reader with `options`, handing each record (opcode, content)
/// to `on_record`; `bytes` counts the bytes read.
fn pump(
    input: &mut dyn Read,
    options: mcap::sans_io::LinearReaderOptions,
    file: &str,
    bytes: &mut u64,
    on_record: &mut OnRecord<'_>,
) -> Result<(), Error> {
    use mcap::sans_io::{LinearReadEvent, LinearReader};
    let mut reader = LinearReader::new_with_options(options);
    while let Some(event) = reader.next_event() {
        let event = event.map_err(|source| Error::McapRead { file: file.to_string(), source })?;
        match event {
            LinearReadEvent::ReadRequest(need) => {
                let buf = reader.insert(need);
                let n = loop {
                    match input.read(buf) {
                        Ok(n) => break n,
                        Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                        Err(source) => {
                            return Err(Error::Io { file: file.to_string(), op: "reading", source });
                        }
                    }
                };
                *bytes += n as u64;
                reader.notify_read(n);
            }
            LinearReadEvent::Record { opcode, data } => on_record(opcode, data)?,
        }
    }
    Ok(())
}

/// A decoded message waiting for its record to be read whole (recovery: a chunk that fails
/// halfway gives nothing).
struct Pending {
    channel_id: u16,
    index: usize,
    log_time_ns: u64,
    body: Body,
}

/// What has been read so far.
#[derive(Default)]
struct State {
    file: String,
    /// Topics whose messages are decoded (`None`: all).
    only: Option<std::collections::BTreeSet<String>>,
    /// Decode this crate's metric messages typed when their schema is ours ([`Visitor::typed`]).
    typed: bool,
    schemas: BTreeMap<u16, SchemaRec>,
    channels: IdMap<ChannelInfo>,
    decoders: IdMap<Decoder>,
    metadata: BTreeMap<String, BTreeMap<String, String>>,
    /// Log time of the last message of each channel (time must not go backwards).
    last_time: IdMap<u64>,
    /// Largest log time of any message, ns.
    t_end_ns: Option<u64>,
    /// Smallest and largest log time of the messages counted since it was last reset, ns
    /// (recovery: the time span of one record).
    span: Option<(u64, u64)>,
    first_joint_array_len: Option<usize>,
    energy_has_gear_friction: Option<bool>,
    /// The `run` record as read so far ([`DecodedMessage::run`]).
    run: Option<RunDescription>,
    /// `Some` while messages are held back until their record is complete ([`State::commit`]).
    pending: Option<Vec<Pending>>,
    stats_count: Option<u64>,
    stats_chunks: Option<u32>,
    total: u64,
    footer: bool,
    /// Bytes handed to the MCAP reader.
    bytes_read: u64,
    /// Skip the chunks without decoded channels (the summary's channels were read first).
    skip: bool,
    /// Chunks not decompressed ([`chunks`]).
    chunks_skipped: usize,
    /// The summary's chunk indexes: chunk start offset -> (record length, channels it holds).
    chunk_plan: BTreeMap<u64, (u64, Vec<u16>)>,
    /// The visitor takes messages by reference ([`Visitor::by_ref`], with [`State::typed`]).
    by_ref: bool,
    /// The last typed message of each kind, decoded into again for a visitor that takes them by
    /// reference (indexed by [`known::KnownKind`]).
    slots: [known::Slot; known::KINDS],
}

impl State {
    fn new(file: String, topics: Option<&[&str]>) -> Self {
        State {
            file,
            only: topics.map(|t| t.iter().map(|s| s.to_string()).collect()),
            ..State::default()
        }
    }

    fn malformed(&self, detail: String) -> Error {
        Error::Malformed {
            file: self.file.clone(),
            detail,
        }
    }

    fn record(&mut self, record: Record<'_>, visitor: &mut dyn Visitor) -> Result<(), Error> {
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
            Record::Message { header, data } => self.message(&header, &data, visitor)?,
            Record::Metadata(m) => {
                if m.name == crate::meta::RecordingInfo::NAME {
                    self.check_format_version(&m.metadata)?;
                }
                let run = m.name == crate::meta::RunNames::NAME || m.name == crate::meta::RecordingInfo::NAME;
                visitor.metadata(&m.name, &m.metadata);
                self.metadata.entry(m.name).or_default().extend(m.metadata);
                if run {
                    self.update_run();
                }
            }
            Record::Statistics(s) => {
                self.stats_count = Some(s.message_count);
                self.stats_chunks = Some(s.chunk_count);
            }
            Record::Footer(_) => self.footer = true,
            // 0x00 is no MCAP opcode (the spec reserves it): zeros where a record should be
            Record::Unknown { opcode: 0, .. } => {
                return Err(self.malformed(
                    "a record with opcode 0x00, which MCAP does not define (zeros where a record should start)".into(),
                ));
            }
            _ => {}
        }
        Ok(())
    }

    /// A `recording` record with a format version this reader does not know is an error: its
    /// fields may mean something else.
    fn check_format_version(&self, entries: &BTreeMap<String, String>) -> Result<(), Error> {
        let Some(v) = entries.get("format_version") else { return Ok(()) };
        match v.trim().parse::<u64>() {
            Ok(n) if n <= u64::from(crate::FORMAT_VERSION) => Ok(()),
            _ => Err(Error::UnsupportedFormat {
                file: self.file.clone(),
                version: v.clone(),
                supported: crate::FORMAT_VERSION,
                record: crate::meta::RecordingInfo::NAME,
            }),
        }
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
        let known = schema.and_then(|s| known::known_kind(&info.topic, &info.message_encoding, &s.encoding, &s.name, &s.data));
        let decoder = match known {
            Some(kind) if selected && self.typed => Decoder::Known(kind),
            _ if selected => decoder_for(&self.file, &info, schema)?,
            _ => Decoder::Skip(NOT_SELECTED.to_string()),
        };
        if let Decoder::Skip(why) = &decoder {
            info.undecoded = Some(why.clone());
        }
        self.decoders.insert(ch.id, decoder);
        self.channels.insert(ch.id, info);
        Ok(())
    }

    fn message(
        &mut self,
        header: &mcap::records::MessageHeader,
        data: &[u8],
        visitor: &mut dyn Visitor,
    ) -> Result<(), Error> {
        let Some(decoder) = self.decoders.get(&header.channel_id) else {
            return Err(self.malformed(format!("message on unknown channel id {}", header.channel_id)));
        };
        let skip = matches!(decoder, Decoder::Skip(_));
        let known = match decoder {
            Decoder::Known(kind) => Some(*kind),
            _ => None,
        };
        let index = self.count(header.channel_id, header.log_time)?;
        if skip {
            return Ok(());
        }
        if let (Some(kind), true, None) = (known, self.by_ref, &self.pending) {
            return self.message_by_ref(kind, header, index, data, visitor);
        }
        let (Some(info), Some(decoder)) = (self.channels.get(&header.channel_id), self.decoders.get(&header.channel_id)) else {
            return Ok(()); // (known: counted above)
        };
        let decode_err = |detail: String| decode_error(&self.file, info, index, header, detail);
        let value = match decoder {
            Decoder::Skip(_) => return Ok(()),
            Decoder::Known(kind) => Body::Known(known::decode(*kind, data).map_err(decode_err)?),
            Decoder::Protobuf(desc) => Body::Value(DynamicMessage::decode(desc.clone(), data)
                .map(|m| message_to_value(&m))
                .map_err(|e| decode_err(e.to_string()))?),
            Decoder::Ros2(schema) => Body::Value(crate::cdr::decode(schema, data).map_err(decode_err)?),
            Decoder::Json => Body::Value(serde_json::from_slice::<serde_json::Value>(data)
                .map(|j| Value::from_json(&j))
                .map_err(|e| decode_err(e.to_string()))?),
        };
        if self.first_joint_array_len.is_none() {
            let topic = &info.topic;
            self.first_joint_array_len = match &value {
                Body::Known(k) => k.first_joint_array_len(topic),
                Body::Value(Value::Struct(fields)) => fields.iter().find_map(|(field, v)| match (array_index(topic, field), v) {
                    (Some(ArrayIndex::Joint), Value::List(items)) => Some(items.len()),
                    _ => None,
                }),
                Body::Value(_) => None,
            };
            if self.first_joint_array_len.is_some() && self.run.as_ref().is_some_and(|r| r.joint_names.is_empty()) {
                self.update_run(); // format 0 names its joints after this length
            }
        }
        let topic = &self.channels[&header.channel_id].topic;
        if topic == crate::topics::ENERGY && self.energy_has_gear_friction.is_none() {
            self.energy_has_gear_friction = Some(match &value {
                Body::Value(v) => v.get("gear_friction_loss").is_some(),
                Body::Known(_) => true, // this crate's schema has the field
            });
        }
        let channel_id = header.channel_id;
        match &mut self.pending {
            Some(pending) => pending.push(Pending { channel_id, index, log_time_ns: header.log_time, body: value }),
            None => visitor.message(DecodedMessage { file: &self.file, topic, index, log_time_ns: header.log_time, body: value, run: self.run.as_ref() })?,
        }
        Ok(())
    }

    /// A typed message for a visitor that takes them by reference ([`Visitor::by_ref`]): decoded
    /// into the message kept for its kind ([`State::slots`]), handed over, kept for the next.
    /// What the visitor sees, and what is checked, is what [`State::message`] gives.
    fn message_by_ref(
        &mut self,
        kind: known::KnownKind,
        header: &mcap::records::MessageHeader,
        index: usize,
        data: &[u8],
        visitor: &mut dyn Visitor,
    ) -> Result<(), Error> {
        let slot = &mut self.slots[kind as usize];
        known::decode_into(kind, data, slot).map_err(|detail| decode_error(&self.file, &self.channels[&header.channel_id], index, header, detail))?;
        let Some(known) = slot.message.take() else { return Ok(()) };
        let body = Body::Known(known);
        if self.first_joint_array_len.is_none() {
            if let Body::Known(k) = &body {
                self.first_joint_array_len = k.first_joint_array_len(&self.channels[&header.channel_id].topic);
            }
            if self.first_joint_array_len.is_some() && self.run.as_ref().is_some_and(|r| r.joint_names.is_empty()) {
                self.update_run(); // format 0 names its joints after this length
            }
        }
        let info = &self.channels[&header.channel_id];
        if info.topic == crate::topics::ENERGY && self.energy_has_gear_friction.is_none() {
            self.energy_has_gear_friction = Some(true); // this crate's schema has the field
        }
        let m = DecodedMessage { file: &self.file, topic: &info.topic, index, log_time_ns: header.log_time, body, run: self.run.as_ref() };
        let seen = visitor.message_ref(&m);
        if let Body::Known(k) = m.body {
            self.slots[kind as usize].message = Some(k);
        }
        seen
    }

    /// Counts a message of the known channel `channel_id` logged at `log_time` (ns), which must
    /// not be before the channel's previous one; its index in the channel.
    fn count(&mut self, channel_id: u16, log_time: u64) -> Result<usize, Error> {
        let Some(info) = self.channels.get_mut(&channel_id) else {
            return Err(Error::Malformed { file: self.file.clone(), detail: format!("message on unknown channel id {channel_id}") });
        };
        let index = info.message_count;
        match self.last_time.get_mut(&channel_id) {
            Some(last) => {
                let previous_ns = *last;
                if log_time < previous_ns {
                    return Err(Error::TimeBackwards { file: self.file.clone(), topic: info.topic.clone(), index, log_time_ns: log_time, previous_ns });
                }
                *last = log_time;
            }
            None => {
                self.last_time.insert(channel_id, log_time);
            }
        }
        self.t_end_ns = Some(self.t_end_ns.map_or(log_time, |t| t.max(log_time)));
        self.span = Some(self.span.map_or((log_time, log_time), |(a, b)| (a.min(log_time), b.max(log_time))));
        info.message_count += 1;
        self.total += 1;
        Ok(index)
    }

    /// [`State::run`] from the metadata read so far (`None` while it does not read: the typed
    /// accessors of the finished [`Recording`] report why).
    fn update_run(&mut self) {
        // only the records `run()` reads (not the scene and URDF texts)
        let records = [crate::meta::RunNames::NAME, crate::meta::RecordingInfo::NAME];
        let view = Recording {
            source: self.file.clone(),
            metadata: self.metadata.iter().filter(|(name, _)| records.contains(&name.as_str())).map(|(k, v)| (k.clone(), v.clone())).collect(),
            channels: Vec::new(),
            messages: BTreeMap::new(),
            first_joint_array_len: self.first_joint_array_len,
            energy_has_gear_friction: false,
            chunks_skipped: 0,
        };
        self.run = view.run_opt().ok().flatten();
    }

    /// Hands the messages held back to `visitor` (recovery, after their record read whole).
    fn commit(&mut self, visitor: &mut dyn Visitor) -> Result<(), Error> {
        self.commit_first(usize::MAX, visitor)
    }

    /// Hands the first `n` messages held back to `visitor` (recovery: those before a flush
    /// point), keeping the others held.
    fn commit_first(&mut self, n: usize, visitor: &mut dyn Visitor) -> Result<(), Error> {
        let Some(pending) = self.pending.as_mut() else { return Ok(()) };
        let n = n.min(pending.len());
        for p in pending.drain(..n) {
            let topic = &self.channels[&p.channel_id].topic;
            visitor.message(DecodedMessage { file: &self.file, topic, index: p.index, log_time_ns: p.log_time_ns, body: p.body, run: self.run.as_ref() })?;
        }
        Ok(())
    }

    /// The reader stopped at the end magic; a file that goes on (trailing bytes) was refused by
    /// the MCAP reader, one that changed size while read is refused here.
    fn check_read_all(&self, len: u64) -> Result<(), Error> {
        if self.bytes_read != len {
            return Err(self.malformed(format!(
                "read {} bytes, but the file has {len} (it changed while being read?)",
                self.bytes_read
            )));
        }
        Ok(())
    }

    /// The file had its footer and its statistics agree with the data.
    fn check_complete(&self) -> Result<(), Error> {
        if !self.footer {
            return Err(Error::Truncated { file: self.file.clone() });
        }
        if let Some(n) = self.stats_count.filter(|&n| n != self.total) {
            return Err(self.malformed(format!(
                "statistics count {n} messages, the data section has {}",
                self.total
            )));
        }
        Ok(())
    }

    /// The recording read so far (its messages went to the visitor).
    fn into_recording(self) -> Recording {
        Recording {
            source: self.file,
            metadata: self.metadata,
            channels: self.channels.into_values().collect(),
            messages: BTreeMap::new(),
            first_joint_array_len: self.first_joint_array_len,
            energy_has_gear_friction: self.energy_has_gear_friction.unwrap_or(false),
            chunks_skipped: self.chunks_skipped,
        }
    }
}

impl Recording {
    /// How many chunks the reader did not decompress because they hold none of the topics read
    /// (0 when read for every topic, or from a file without a summary section).
    pub fn chunks_skipped(&self) -> usize {
        self.chunks_skipped
    }

    /// The channel of `topic` (the first one, if several share the topic).
    pub fn channel(&self, topic: &str) -> Option<&ChannelInfo> {
        self.channels.iter().find(|c| c.topic == topic)
    }

    /// Every decoded message by topic, in log-time order (the reader refuses time going backwards): for tools that handle any topic
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
