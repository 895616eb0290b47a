//! The RRD stream of Rerun (`.rrd` files), written without the `rerun` crate.
//!
//! Framing, as Rerun 0.36-0.41 write and read it (`re_log_encoding/src/rrd/frames.rs` and
//! `encoder.rs` in <https://github.com/rerun-io/rerun>, checked against files the 0.41 Python SDK
//! and `rerun rrd migrate` write):
//! - a 12-byte stream header: FourCC `RRF2`, the writer's version `[major, minor, patch, 0]`,
//!   and the options `[compression, serializer, 0, 0]` (compression 1 = LZ4, serializer 2 =
//!   protobuf);
//! - messages, each a 16-byte header (`kind: u64 LE`, `len: u64 LE`; kind 1 = `SetStoreInfo`,
//!   2 = `ArrowMsg`, 3 = `BlueprintActivationCommand`, 0 = `End`) then `len` bytes of that
//!   protobuf message (`rerun/v1alpha1/log_msg.proto`, `common.proto`);
//! - the `End` message with the footer, the manifests of every chunk ([`super::manifest`]),
//!   then the 32-byte stream footer that points at it (`…RRF2FOOT`): what `rerun rrd verify`
//!   and the Python reader of 0.41 require of a current file.
//!
//! An `ArrowMsg`'s payload is an Arrow IPC *stream* holding one record batch, the chunk
//! ([`super::chunk`]), LZ4-compressed (block format, the size in `uncompressed_size`; Rerun's
//! own writer compresses the same way).

use prost::Message;

/// Rerun's version these files claim to be written by (the oldest that reads what we write
/// the same way: chunk metadata `sorbet:version` 0.1.4).
pub const RERUN_VERSION: (u8, u8, u8) = (0, 41, 0);

/// `rerun.common.v1alpha1.Tuid`: a time-ordered unique id (chunks, rows, store infos).
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Message)]
pub struct Tuid {
    #[prost(fixed64, optional, tag = "1")]
    pub time_ns: Option<u64>,
    #[prost(fixed64, optional, tag = "2")]
    pub inc: Option<u64>,
}

impl Tuid {
    pub fn new(time_ns: u64, inc: u64) -> Self {
        Tuid { time_ns: Some(time_ns), inc: Some(inc) }
    }

    /// The 16 bytes of a row id column (big-endian time, then big-endian increment).
    pub fn bytes(self) -> [u8; 16] {
        let mut b = [0u8; 16];
        b[..8].copy_from_slice(&self.time_ns.unwrap_or(0).to_be_bytes());
        b[8..].copy_from_slice(&self.inc.unwrap_or(0).to_be_bytes());
        b
    }

    /// The text Rerun prints for a chunk id (`chunk_18EA969B7289F519…`).
    pub fn chunk_name(self) -> String {
        format!("chunk_{:016X}{:016x}", self.time_ns.unwrap_or(0), self.inc.unwrap_or(0))
    }
}

/// `rerun.common.v1alpha1.ApplicationId`.
#[derive(Clone, PartialEq, Message)]
pub struct ApplicationId {
    #[prost(string, tag = "1")]
    pub id: String,
}

/// `rerun.common.v1alpha1.StoreKind`: 1 recording, 2 blueprint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StoreKind {
    Recording = 1,
    Blueprint = 2,
}

/// `rerun.common.v1alpha1.StoreId`.
#[derive(Clone, PartialEq, Message)]
pub struct StoreId {
    #[prost(int32, tag = "1")]
    pub kind: i32,
    #[prost(string, tag = "2")]
    pub recording_id: String,
    #[prost(message, optional, tag = "3")]
    pub application_id: Option<ApplicationId>,
}

impl StoreId {
    pub fn new(kind: StoreKind, application_id: &str, recording_id: &str) -> Self {
        StoreId {
            kind: kind as i32,
            recording_id: recording_id.into(),
            application_id: Some(ApplicationId { id: application_id.into() }),
        }
    }
}

#[derive(Clone, PartialEq, Message)]
pub struct SetStoreInfo {
    #[prost(message, optional, tag = "1")]
    pub row_id: Option<Tuid>,
    #[prost(message, optional, tag = "2")]
    pub info: Option<StoreInfo>,
}

#[derive(Clone, PartialEq, Message)]
pub struct StoreInfo {
    #[prost(message, optional, tag = "2")]
    pub store_id: Option<StoreId>,
    #[prost(message, optional, tag = "5")]
    pub store_source: Option<StoreSource>,
    #[prost(message, optional, tag = "6")]
    pub store_version: Option<StoreVersion>,
}

#[derive(Clone, PartialEq, Message)]
pub struct StoreSource {
    /// `StoreSourceKind`: 6 = other (the payload is a UTF-8 description).
    #[prost(int32, tag = "1")]
    pub kind: i32,
    #[prost(message, optional, tag = "2")]
    pub extra: Option<StoreSourceExtra>,
}

#[derive(Clone, PartialEq, Message)]
pub struct StoreSourceExtra {
    #[prost(bytes = "vec", tag = "1")]
    pub payload: Vec<u8>,
}

#[derive(Clone, PartialEq, Message)]
pub struct StoreVersion {
    /// `major << 16 | minor << 8 | patch`.
    #[prost(int32, tag = "1")]
    pub crate_version_bits: i32,
}

#[derive(Clone, PartialEq, Message)]
pub struct ArrowMsg {
    #[prost(message, optional, tag = "1")]
    pub store_id: Option<StoreId>,
    /// `Compression`: [`COMPRESSION_OFF`] or [`COMPRESSION_LZ4`].
    #[prost(int32, tag = "2")]
    pub compression: i32,
    #[prost(uint64, tag = "3")]
    pub uncompressed_size: u64,
    /// `Encoding`: 1 = Arrow IPC.
    #[prost(int32, tag = "4")]
    pub encoding: i32,
    #[prost(bytes = "vec", tag = "5")]
    pub payload: Vec<u8>,
    #[prost(message, optional, tag = "6")]
    pub chunk_id: Option<Tuid>,
    #[prost(bool, optional, tag = "7")]
    pub is_static: Option<bool>,
}

#[derive(Clone, PartialEq, Message)]
pub struct BlueprintActivationCommand {
    #[prost(message, optional, tag = "1")]
    pub blueprint_id: Option<StoreId>,
    #[prost(bool, tag = "2")]
    pub make_active: bool,
    #[prost(bool, tag = "3")]
    pub make_default: bool,
}

/// `Compression` of an [`ArrowMsg`] payload: 1 = none, 2 = LZ4 (block format, no size
/// prefix; the size is `uncompressed_size`).
pub const COMPRESSION_OFF: i32 = 1;
pub const COMPRESSION_LZ4: i32 = 2;

/// Message kinds of the frame header.
pub const KIND_END: u64 = 0;
pub const KIND_SET_STORE_INFO: u64 = 1;
pub const KIND_ARROW_MSG: u64 = 2;
pub const KIND_BLUEPRINT_ACTIVATION: u64 = 3;

/// An RRD stream being written to `W` (a file, or memory), message by message.
pub struct RrdStream<W: std::io::Write> {
    out: W,
    /// Bytes written so far.
    written: u64,
    /// One message's bytes (reused).
    scratch: Vec<u8>,
}

impl RrdStream<Vec<u8>> {
    /// A stream into memory.
    pub fn in_memory() -> std::io::Result<Self> {
        RrdStream::new(Vec::with_capacity(1 << 20))
    }

    pub fn into_bytes(self) -> Vec<u8> {
        self.out
    }
}

impl<W: std::io::Write> RrdStream<W> {
    /// A stream with its header written to `out`.
    pub fn new(mut out: W) -> std::io::Result<Self> {
        let (major, minor, patch) = RERUN_VERSION;
        let mut header = Vec::with_capacity(12);
        header.extend_from_slice(b"RRF2");
        header.extend_from_slice(&[major, minor, patch, 0]);
        // LZ4, protobuf
        header.extend_from_slice(&[1, 2, 0, 0]);
        out.write_all(&header)?;
        Ok(RrdStream { out, written: header.len() as u64, scratch: Vec::new() })
    }

    /// Bytes written so far.
    pub fn written(&self) -> u64 {
        self.written
    }

    fn message(&mut self, kind: u64, msg: &impl Message) -> std::io::Result<()> {
        self.scratch.clear();
        self.scratch.extend_from_slice(&kind.to_le_bytes());
        self.scratch.extend_from_slice(&(msg.encoded_len() as u64).to_le_bytes());
        msg.encode_raw(&mut self.scratch);
        self.out.write_all(&self.scratch)?;
        self.written += self.scratch.len() as u64;
        Ok(())
    }

    /// Opens a store (a recording or a blueprint): what every later message of it refers to.
    pub fn set_store_info(&mut self, row_id: Tuid, store: &StoreId, source: &str) -> std::io::Result<()> {
        let (major, minor, patch) = RERUN_VERSION;
        let info = StoreInfo {
            store_id: Some(store.clone()),
            store_source: Some(StoreSource { kind: 6, extra: Some(StoreSourceExtra { payload: source.as_bytes().to_vec() }) }),
            store_version: Some(StoreVersion { crate_version_bits: (i32::from(major) << 16) | (i32::from(minor) << 8) | i32::from(patch) }),
        };
        self.message(KIND_SET_STORE_INFO, &SetStoreInfo { row_id: Some(row_id), info: Some(info) })
    }

    /// One chunk: `ipc` is an Arrow IPC stream of one record batch, written LZ4-compressed.
    /// Returns where the message lies after its header: offset and length (the footer's).
    pub fn arrow_msg(&mut self, store: &StoreId, chunk_id: Tuid, is_static: bool, ipc: Vec<u8>) -> std::io::Result<(u64, u64)> {
        let payload = lz4::block::compress(&ipc, None, false)?;
        let msg = ArrowMsg {
            store_id: Some(store.clone()),
            compression: COMPRESSION_LZ4,
            uncompressed_size: ipc.len() as u64,
            encoding: 1,
            payload,
            chunk_id: Some(chunk_id),
            is_static: Some(is_static),
        };
        let start = self.written + 16;
        self.message(KIND_ARROW_MSG, &msg)?;
        Ok((start, self.written - start))
    }

    /// Ends the stream: the `End` message carrying `footer` (the protobuf `RrdFooter`), then
    /// the stream footer that points at it.
    pub fn end(&mut self, footer: &[u8]) -> std::io::Result<()> {
        let mut out = Vec::with_capacity(footer.len() + 48);
        out.extend_from_slice(&KIND_END.to_le_bytes());
        out.extend_from_slice(&(footer.len() as u64).to_le_bytes());
        let offset = self.written + 16;
        out.extend_from_slice(footer);
        out.extend_from_slice(&super::manifest::stream_footer(offset, footer));
        self.out.write_all(&out)?;
        self.written += out.len() as u64;
        Ok(())
    }

    /// Makes `blueprint` the default blueprint of its application id.
    pub fn activate_blueprint(&mut self, blueprint: &StoreId) -> std::io::Result<()> {
        self.message(
            KIND_BLUEPRINT_ACTIVATION,
            &BlueprintActivationCommand { blueprint_id: Some(blueprint.clone()), make_active: false, make_default: true },
        )
    }

    /// Flushes and gives the writer back.
    pub fn finish(mut self) -> std::io::Result<W> {
        self.out.flush()?;
        Ok(self.out)
    }
}

/// The chunk an [`ArrowMsg`] carries, as a record batch (its payload decompressed when it is
/// LZ4-compressed): how a reader gets it back, for the tests.
pub fn payload_batch(msg: &ArrowMsg) -> Result<arrow_array::RecordBatch, String> {
    let ipc = match msg.compression {
        COMPRESSION_LZ4 => {
            let size = i32::try_from(msg.uncompressed_size).map_err(|_| format!("uncompressed size {} too large", msg.uncompressed_size))?;
            lz4::block::decompress(&msg.payload, Some(size)).map_err(|e| format!("LZ4: {e}"))?
        }
        _ => msg.payload.clone(),
    };
    let mut r = arrow_ipc::reader::StreamReader::try_new(ipc.as_slice(), None).map_err(|e| e.to_string())?;
    let batch = r.next().ok_or("no record batch")?.map_err(|e| e.to_string())?;
    Ok(batch)
}
