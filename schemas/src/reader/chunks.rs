//! Reading only the chunks that hold the wanted topics.
//!
//! An MCAP file (<https://mcap.dev/spec>) stores its messages in chunks (compressed), each
//! followed in the data section by one Message Index record per channel it holds (the log
//! time and offset of each of the channel's messages in the chunk). When a file is read for
//! some topics only ([`crate::read_recording_topics`], [`crate::stream_recording`] with
//! topics), a chunk whose message indexes name only channels that are not decoded is not
//! decompressed: its messages are counted, and their log times checked for order per channel,
//! from the message indexes, exactly as the messages themselves would be. A chunk is
//! decompressed and read as before when it has no message index, or when one names a channel
//! that is decoded or not (yet) known.
//!
//! Skipping needs every channel known before the chunks are read (a skipped chunk may define a
//! channel), so it is done only when the file has a summary section (spec, "Summary Section")
//! whose Schema and Channel records are read first; without one (a recovered or truncated file,
//! a writer that writes none), every chunk is read, as always. Everything else is checked as
//! before, by the same linear pass: the data section's CRC covers the compressed bytes of a
//! skipped chunk (its own CRC is of the uncompressed bytes, so it is checked only for the
//! chunks read), the summary's CRC, the statistics against the messages counted, the schemas
//! and channels of the data section against those of the summary.

use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};

use mcap::records::{op, MessageIndexEntry, Record};

use super::{Null, State, Visitor, MAX_RECORD_BYTES};
use crate::Error;

/// Length of the Footer record (opcode, length, summary start, summary offset start, summary
/// CRC) and of the magic after it.
const FOOTER_AND_MAGIC: u64 = 1 + 8 + 8 + 8 + 4 + 8;

/// Where the summary section lies, from the footer at the end of `tail` (the file's last
/// [`FOOTER_AND_MAGIC`] bytes): `None` when the file has no summary or no valid footer.
fn summary_range(tail: &[u8], len: u64) -> Option<(u64, u64)> {
    if tail.len() as u64 != FOOTER_AND_MAGIC || &tail[29..] != mcap::MAGIC || tail[0] != op::FOOTER {
        return None;
    }
    let rec_len = u64::from_le_bytes(tail[1..9].try_into().ok()?);
    let start = u64::from_le_bytes(tail[9..17].try_into().ok()?);
    let end = len - FOOTER_AND_MAGIC;
    let ok = rec_len == 20 && start >= mcap::MAGIC.len() as u64 && start < end && end - start <= MAX_RECORD_BYTES as u64;
    ok.then_some((start, end))
}

/// The summary section of a file (the file is left at its start), `None` when it has none.
pub(super) fn summary_of_file(file: &mut BufReader<File>, len: u64) -> Option<Vec<u8>> {
    let mut read = || -> std::io::Result<Option<Vec<u8>>> {
        if len < FOOTER_AND_MAGIC + mcap::MAGIC.len() as u64 {
            return Ok(None);
        }
        let mut tail = [0u8; FOOTER_AND_MAGIC as usize];
        file.seek(SeekFrom::Start(len - FOOTER_AND_MAGIC))?;
        file.read_exact(&mut tail)?;
        let Some((start, end)) = summary_range(&tail, len) else { return Ok(None) };
        let mut summary = vec![0u8; (end - start) as usize];
        file.seek(SeekFrom::Start(start))?;
        file.read_exact(&mut summary)?;
        Ok(Some(summary))
    };
    let summary = read().ok().flatten();
    // back to the start for the linear pass (an error shows there, with its context)
    file.rewind().ok()?;
    summary
}

/// The summary section of MCAP bytes, `None` when they have none.
pub(super) fn summary_of_bytes(bytes: &[u8]) -> Option<&[u8]> {
    let len = bytes.len() as u64;
    if len < FOOTER_AND_MAGIC + mcap::MAGIC.len() as u64 {
        return None;
    }
    let (start, end) = summary_range(&bytes[(len - FOOTER_AND_MAGIC) as usize..], len)?;
    Some(&bytes[start as usize..end as usize])
}

/// Feeds the Schema and Channel records of a summary section to `state`; `false` (and `state`
/// untouched) when the section does not parse or its records are refused: the file is then
/// read without skipping, and the linear pass reports what is wrong.
pub(super) fn prefeed(state: &mut State, mut summary: &[u8]) -> bool {
    let mut records = Vec::new();
    let mut indexes = Vec::new();
    while !summary.is_empty() {
        let Some((&opcode, rest)) = summary.split_first() else { return false };
        let Some(len) = rest.get(..8).and_then(|b| b.try_into().ok()).map(u64::from_le_bytes) else { return false };
        let Some(data) = usize::try_from(len).ok().and_then(|n| rest.get(8..8usize.checked_add(n)?)) else { return false };
        if opcode == op::SCHEMA || opcode == op::CHANNEL {
            records.push((opcode, data));
        }
        if opcode == op::CHUNK_INDEX {
            indexes.push(data);
        }
        summary = &rest[8 + data.len()..];
    }
    // on a fresh copy of `state` (which has read nothing yet), so that `state` is fed all or
    // nothing; `prost-reflect` can panic on a corrupt descriptor set (see
    // `crate::read_recording_bytes`): that too leaves `state` as it was
    let mut trial = State::new(state.file.clone(), None);
    trial.only = state.only.clone();
    trial.typed = state.typed;
    trial.by_ref = state.by_ref;
    let fed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        records.iter().try_for_each(|&(opcode, data)| match mcap::parse_record(opcode, data) {
            Ok(r) => trial.record(r, &mut Null),
            Err(_) => Err(Error::Truncated { file: String::new() }),
        })
    }));
    if !matches!(fed, Ok(Ok(()))) {
        return false;
    }
    // where each chunk is and which channels it holds (one that does not parse: none planned)
    for data in indexes {
        if let Ok(Record::ChunkIndex(ix)) = mcap::parse_record(op::CHUNK_INDEX, data) {
            trial.chunk_plan.insert(ix.chunk_start_offset, (ix.chunk_length, ix.message_index_offsets.into_keys().collect()));
        }
    }
    *state = trial;
    true
}

/// What becomes of the chunks: read at once, skipped, or held back until their message
/// indexes are read.
#[derive(Default)]
pub(super) struct Skipper {
    /// The chunk record as in the file (opcode, length, content), when one is held and copied
    /// (a chunk the summary's chunk index does not describe).
    chunk: Vec<u8>,
    held: bool,
    /// Whether the held chunk was copied (else the chunk index said to skip it: not copied).
    copied: bool,
    /// File offset of the held chunk.
    offset: u64,
    /// The channels the chunk index names for the held chunk (`None`: not described).
    planned: Option<Vec<u16>>,
    /// Its message indexes: channel, and `(offset, log time)` of each message.
    indexes: Vec<(u16, Vec<MessageIndexEntry>)>,
    /// The zstd context, kept from one chunk to the next.
    zstd: Option<zstd::bulk::Decompressor<'static>>,
    /// A chunk's records, decompressed.
    out: Vec<u8>,
    pub(super) skipped: usize,
    pub(super) read: usize,
}

/// Whether a chunk whose (message or chunk) indexes name `channels` is read: when they name
/// none, or one that is decoded or unknown.
fn wanted(state: &State, channels: &mut dyn Iterator<Item = u16>) -> bool {
    let mut none = true;
    let mut decoded = false;
    for ch in channels {
        none = false;
        decoded |= !matches!(state.decoders.get(&ch), Some(super::Decoder::Skip(_)));
    }
    none || decoded
}

impl Skipper {
    /// Takes a record of the outer pass (which yields chunks whole) that starts at byte `offset`
    /// of the file, after reading or skipping the chunk held unless the record is one of its
    /// message indexes; `false` when the record is neither a chunk nor such an index (the
    /// caller reads it).
    ///
    /// A chunk that the summary's chunk index describes (same offset and length) is decided
    /// from it at once: read straight from the reader's buffer ([`Skipper::read_chunk`]), or
    /// skipped without a copy, its message indexes then counted and checked against the
    /// decision. A chunk it does not describe is copied and held until its message indexes are
    /// read.
    pub(super) fn take(&mut self, opcode: u8, data: &[u8], offset: u64, state: &mut State, visitor: &mut dyn Visitor) -> Result<bool, Error> {
        let mcap_err = |source| Error::McapRead { file: state.file.clone(), source };
        if opcode == op::MESSAGE_INDEX && self.held {
            if let Record::MessageIndex(ix) = mcap::parse_record(opcode, data).map_err(mcap_err)? {
                self.indexes.push((ix.channel_id, ix.records));
            }
            return Ok(true);
        }
        self.resolve(state, visitor)?;
        if opcode != op::CHUNK {
            return Ok(false);
        }
        let planned = state.chunk_plan.get(&offset).filter(|(len, _)| *len == 9 + data.len() as u64).map(|(_, channels)| channels.clone());
        match planned {
            Some(channels) if wanted(state, &mut channels.iter().copied()) => {
                self.read += 1;
                self.read_chunk(data, state, visitor)?;
            }
            planned => {
                self.copied = planned.is_none();
                self.chunk.clear();
                if self.copied {
                    self.chunk.push(op::CHUNK);
                    self.chunk.extend_from_slice(&(data.len() as u64).to_le_bytes());
                    self.chunk.extend_from_slice(data);
                }
                self.planned = planned;
                self.offset = offset;
                self.held = true;
                self.indexes.clear();
            }
        }
        Ok(true)
    }

    /// Reads or skips the held chunk (if any): skipped when its message indexes name only
    /// channels known and not decoded.
    pub(super) fn resolve(&mut self, state: &mut State, visitor: &mut dyn Visitor) -> Result<(), Error> {
        if !std::mem::take(&mut self.held) {
            return Ok(());
        }
        let read = self.indexes.is_empty() || wanted(state, &mut self.indexes.iter().map(|(ch, _)| *ch));
        if read && !self.copied {
            let named: Vec<u16> = self.indexes.iter().map(|(ch, _)| *ch).collect();
            return Err(state.malformed(format!(
                "the chunk at byte {}: the summary's chunk index names channels {:?}, its message indexes {:?}",
                self.offset,
                self.planned.as_deref().unwrap_or_default(),
                named
            )));
        }
        if read {
            self.read += 1;
            let chunk = std::mem::take(&mut self.chunk);
            let done = self.read_chunk(&chunk[9..], state, visitor);
            self.chunk = chunk;
            return done;
        }
        self.skipped += 1;
        for (channel, entries) in &mut self.indexes {
            entries.sort_by_key(|e| e.offset); // file order
            for e in entries.iter() {
                state.count(*channel, e.log_time)?;
            }
        }
        Ok(())
    }

    /// Reads the records of the chunk record with content `data`: decompressed (zstd, or none)
    /// with the zstd context kept, its CRC and the framing of its records checked before any
    /// record is used, then each record to `state`. A chunk that is not so (lz4, a bad CRC, a
    /// record that overruns it) goes through the MCAP reader as before, which says what is
    /// wrong.
    fn read_chunk(&mut self, data: &[u8], state: &mut State, visitor: &mut dyn Visitor) -> Result<(), Error> {
        if let Some(content) = self.unpack(data) {
            let mut rest = content;
            while let Some((&opcode, tail)) = rest.split_first() {
                let len = u64::from_le_bytes(tail[..8].try_into().unwrap_or_default()) as usize;
                let body = &tail[8..8 + len];
                rest = &tail[8 + len..];
                // a message (most records): its header read here, as `mcap::parse_record` reads it
                if let Some((header, data)) = (opcode == op::MESSAGE).then(|| message_header(body)).flatten() {
                    state.message(&header, data, visitor)?;
                    continue;
                }
                let record = mcap::parse_record(opcode, body).map_err(|source| Error::McapRead { file: state.file.clone(), source })?;
                state.record(record, visitor)?;
            }
            return Ok(());
        }
        let mut chunk = Vec::with_capacity(9 + data.len());
        chunk.push(op::CHUNK);
        chunk.extend_from_slice(&(data.len() as u64).to_le_bytes());
        chunk.extend_from_slice(data);
        let options = super::reader_options().with_skip_start_magic(true).with_skip_end_magic(true).with_check_finishes_after_end_magic(false);
        let mut input = chunk.as_slice();
        let mut n = 0;
        super::pump(&mut input, options, &state.file.clone(), &mut n, &mut |opcode, data| {
            let record = mcap::parse_record(opcode, data).map_err(|source| Error::McapRead { file: state.file.clone(), source })?;
            state.record(record, visitor)
        })
    }

    /// The records of a chunk record's content, decompressed, when it is zstd or uncompressed,
    /// decompresses to its stated size, has the CRC it states (if any), and is a sequence of
    /// whole records (opcode, length, content) of at most [`MAX_RECORD_BYTES`]; else `None`.
    fn unpack<'a>(&'a mut self, data: &'a [u8]) -> Option<&'a [u8]> {
        let Ok(Record::Chunk { header, data: std::borrow::Cow::Borrowed(compressed) }) = mcap::parse_record(op::CHUNK, data) else { return None };
        let size = usize::try_from(header.uncompressed_size).ok().filter(|&n| n <= MAX_RECORD_BYTES)?;
        let content: &[u8] = match header.compression.as_str() {
            "" => compressed,
            "zstd" => {
                if self.zstd.is_none() {
                    self.zstd = zstd::bulk::Decompressor::new().ok();
                }
                let zstd = self.zstd.as_mut()?;
                self.out.clear();
                self.out.reserve(size);
                let n = zstd.decompress_to_buffer(compressed, &mut self.out).ok()?;
                (n == size).then_some(())?;
                &self.out
            }
            _ => return None,
        };
        if content.len() != size || (header.uncompressed_crc != 0 && crc32fast::hash(content) != header.uncompressed_crc) {
            return None;
        }
        let mut rest = content;
        while !rest.is_empty() {
            let len = usize::try_from(u64::from_le_bytes(rest.get(1..9)?.try_into().ok()?)).ok()?;
            if len > MAX_RECORD_BYTES || rest.len() - 9 < len {
                return None;
            }
            rest = &rest[9 + len..];
        }
        Some(content)
    }
}

/// The header and data of a Message record's content (spec, "Message": channel id u16, sequence
/// u32, log time u64, publish time u64, all little-endian, then the data), as
/// `mcap::parse_record` gives them; `None` when the content is shorter than the header (then
/// `mcap::parse_record` gives the error).
fn message_header(body: &[u8]) -> Option<(mcap::records::MessageHeader, &[u8])> {
    let (head, data) = body.split_first_chunk::<22>()?;
    let channel_id = u16::from_le_bytes([head[0], head[1]]);
    let sequence = u32::from_le_bytes(head[2..6].try_into().ok()?);
    let log_time = u64::from_le_bytes(head[6..14].try_into().ok()?);
    let publish_time = u64::from_le_bytes(head[14..22].try_into().ok()?);
    Some((mcap::records::MessageHeader { channel_id, sequence, log_time, publish_time }, data))
}

#[cfg(test)]
mod tests {
    /// The header read by hand is `mcap::parse_record`'s, on messages of every length from the
    /// bare header up; shorter contents are left to `mcap::parse_record` (an error).
    #[test]
    fn message_header_is_mcaps() {
        let mut body: Vec<u8> = (0u8..22).map(|b| b.wrapping_mul(37).wrapping_add(11)).collect();
        for extra in 0..40u8 {
            let Ok(mcap::records::Record::Message { header, data }) = mcap::parse_record(mcap::records::op::MESSAGE, &body) else { panic!("mcap refuses {body:?}") };
            assert_eq!(super::message_header(&body), Some((header, &data[..])));
            body.push(extra.wrapping_mul(91));
        }
        for short in 0..22 {
            assert!(super::message_header(&body[..short]).is_none());
            assert!(mcap::parse_record(mcap::records::op::MESSAGE, &body[..short]).is_err());
        }
    }
}
