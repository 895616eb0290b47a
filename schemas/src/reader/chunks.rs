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
    while !summary.is_empty() {
        let Some((&opcode, rest)) = summary.split_first() else { return false };
        let Some(len) = rest.get(..8).and_then(|b| b.try_into().ok()).map(u64::from_le_bytes) else { return false };
        let Some(data) = usize::try_from(len).ok().and_then(|n| rest.get(8..8usize.checked_add(n)?)) else { return false };
        if opcode == op::SCHEMA || opcode == op::CHANNEL {
            records.push((opcode, data));
        }
        summary = &rest[8 + data.len()..];
    }
    // on a fresh copy of `state` (which has read nothing yet), so that `state` is fed all or
    // nothing; `prost-reflect` can panic on a corrupt descriptor set (see
    // `crate::read_recording_bytes`): that too leaves `state` as it was
    let mut trial = State::new(state.file.clone(), None);
    trial.only = state.only.clone();
    trial.typed = state.typed;
    let fed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        records.iter().try_for_each(|&(opcode, data)| match mcap::parse_record(opcode, data) {
            Ok(r) => trial.record(r, &mut Null),
            Err(_) => Err(Error::Truncated { file: String::new() }),
        })
    }));
    if !matches!(fed, Ok(Ok(()))) {
        return false;
    }
    *state = trial;
    true
}

/// A chunk held back until its message indexes are read, and what became of the chunks.
#[derive(Default)]
pub(super) struct Skipper {
    /// The chunk record as in the file (opcode, length, content), when one is held.
    chunk: Vec<u8>,
    held: bool,
    /// Its message indexes: channel, and `(offset, log time)` of each message.
    indexes: Vec<(u16, Vec<MessageIndexEntry>)>,
    pub(super) skipped: usize,
    pub(super) read: usize,
}

impl Skipper {
    /// Takes a record of the outer pass (which yields chunks whole), after reading or skipping
    /// the chunk held unless the record is one of its message indexes; `false` when the record
    /// is neither a chunk nor such an index (the caller reads it).
    pub(super) fn take(&mut self, opcode: u8, data: &[u8], state: &mut State, visitor: &mut dyn Visitor) -> Result<bool, Error> {
        let mcap_err = |source| Error::McapRead { file: state.file.clone(), source };
        if opcode == op::MESSAGE_INDEX && self.held {
            if let Record::MessageIndex(ix) = mcap::parse_record(opcode, data).map_err(mcap_err)? {
                self.indexes.push((ix.channel_id, ix.records));
            }
            return Ok(true);
        }
        self.resolve(state, visitor)?;
        if opcode == op::CHUNK {
            self.chunk.clear();
            self.chunk.push(op::CHUNK);
            self.chunk.extend_from_slice(&(data.len() as u64).to_le_bytes());
            self.chunk.extend_from_slice(data);
            self.held = true;
            self.indexes.clear();
            return Ok(true);
        }
        Ok(false)
    }

    /// Reads or skips the held chunk (if any): skipped when its message indexes name only
    /// channels known and not decoded.
    pub(super) fn resolve(&mut self, state: &mut State, visitor: &mut dyn Visitor) -> Result<(), Error> {
        if !std::mem::take(&mut self.held) {
            return Ok(());
        }
        let decoded = |ch: &u16| !matches!(state.decoders.get(ch), Some(super::Decoder::Skip(_)));
        if self.indexes.is_empty() || self.indexes.iter().any(|(ch, _)| decoded(ch)) {
            self.read += 1;
            let options = super::reader_options().with_skip_start_magic(true).with_skip_end_magic(true).with_check_finishes_after_end_magic(false);
            let mut input = self.chunk.as_slice();
            let mut n = 0;
            return super::pump(&mut input, options, &state.file.clone(), &mut n, &mut |opcode, data| {
                let record = mcap::parse_record(opcode, data).map_err(|source| Error::McapRead { file: state.file.clone(), source })?;
                state.record(record, visitor)
            });
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
}
