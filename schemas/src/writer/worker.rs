//! The writer's back end: the `mcap` writer (chunking, compression, CRCs, index, summary), run
//! on its own thread by [`super::RecordingWriter`] and fed [`Job`]s in the order the caller wrote
//! them, so the bytes are a function of the calls alone (determinism does not depend on the
//! thread's timing).
//!
//! **Chunks per topic** ([`super::WriterOptions::chunk_per_topic`]): each channel's messages are
//! staged in a buffer of their own and written as one chunk, so every chunk holds one channel,
//! and its channel record sits in the first chunk of that channel. A reader that wants some
//! topics finds in the summary's chunk indexes (their message-index offsets name the channels
//! of each chunk, MCAP spec "Chunk Index") which chunks to decompress and skips the rest.
//! Messages stay in log-time order within each channel (MCAP asks no order across channels;
//! the chunk indexes give each chunk's time range). Memory: at most one chunk per channel staged.
//!
//! **Flush groups: what a cut file keeps.** The staged chunks are written *all together* (a
//! *flush group*), never one channel alone, so that a file cut anywhere (a killed run's
//! `.partial`, a copy that stopped) holds every topic up to the same time:
//! - at the first message of a new log time (strictly later than every message before it) once
//!   [`super::WriterOptions::flush_interval_ns`] of log time has passed (the group boundaries
//!   are the multiples of the interval: 1 s of simulated time by default), or once any
//!   channel's staged chunk has reached [`super::WriterOptions::chunk_size`];
//! - before a metadata record and at the end;
//! - and, only for a caller that writes more than twice the chunk size on one channel at one
//!   log time, at once (a group that then splits one instant, which the reader below treats as
//!   one with the next).
//!
//! Within a group the chunks are written in order of their last log time, latest first (then
//! by channel id). With a caller that writes in log-time order (`sim` does: the contact events
//! since the previous sample, at their own times, before it), every message of a group is
//! strictly earlier than every message of the next, so the first chunk of a group is the first
//! chunk in the file that starts after the end of every chunk before it, and no other chunk
//! is: a reader that walks a cut file ([`crate::reader`]'s `recover.rs`) finds each flush point
//! from the chunks' own messages, without a marker record, and keeps exactly the groups that a
//! later flush point confirms whole. The price (measured, `writer.rs` [`super::WriterOptions`]
//! default): more, smaller chunks.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, SyncSender};
use std::sync::Arc;

use mcap::records::{MessageHeader, Metadata};

use super::{write_error, Mirror, WriterOptions};
use crate::reader::{Tap, Tapped};
use crate::Error;

/// One call of the writer, in order.
pub(super) enum Job {
    Schema { id: u16, name: String, encoding: &'static str, data: Vec<u8> },
    Channel { id: u16, schema_id: u16, topic: String, encoding: &'static str },
    Metadata(Metadata),
    /// The encoded message; its buffer goes back to the writer for reuse.
    Message { header: MessageHeader, data: Vec<u8> },
    /// Summary and footer: the last job.
    Finish,
}

/// What the worker leaves when it is done: the file (written to the end after `Finish`), and
/// what the tap saw.
pub(super) struct Done {
    pub(super) file: Option<File>,
    pub(super) tapped: Option<Tapped>,
}

/// A channel known to the writer, registered with `mcap` when its first chunk is written.
struct Chan {
    schema_id: u16,
    topic: String,
    encoding: &'static str,
    /// The channel's metadata record entries (its `units`: [`crate::units::channel_metadata`]).
    metadata: BTreeMap<String, String>,
    registered: bool,
    /// The staged messages (chunks per topic): headers with their end in `bytes`.
    staged: Vec<(MessageHeader, usize)>,
    bytes: Vec<u8>,
    /// Bytes the staged messages take in a chunk (records included).
    chunk_bytes: u64,
}

/// A schema, registered with `mcap` before the first channel that uses it.
struct Schema {
    name: String,
    encoding: &'static str,
    data: Vec<u8>,
    registered: bool,
}

pub(super) struct Worker {
    /// `None` only once finished or abandoned (see `Drop`).
    mcap: Option<mcap::Writer<BufWriter<File>>>,
    file: String,
    options: WriterOptions,
    schemas: BTreeMap<u16, Schema>,
    channels: BTreeMap<u16, Chan>,
    tap: Option<Tap>,
    /// Another consumer of the records (a live view), after the tap.
    mirror: Option<Box<dyn Mirror>>,
    /// Largest log time written so far, ns (a message later than it starts a new instant).
    last_ns: Option<u64>,
    /// The log time at or after which the next new instant closes the group, ns.
    next_flush_ns: Option<u64>,
    /// Some channel's staged chunk has reached the chunk size: the next new instant closes
    /// the group.
    full: bool,
    /// Scratch for the order of a group's chunks: (last log time, channel id).
    order: Vec<(u64, u16)>,
}

/// Bytes of a message record in a chunk besides its data: opcode, length, channel id,
/// sequence, log and publish time (MCAP spec "Message").
const MESSAGE_RECORD_OVERHEAD: u64 = 1 + 8 + 2 + 4 + 8 + 8;

impl Worker {
    pub(super) fn new(mcap: mcap::Writer<BufWriter<File>>, file: String, options: WriterOptions, tap: Option<Tap>, mirror: Option<Box<dyn Mirror>>) -> Self {
        Worker {
            mcap: Some(mcap),
            file,
            options,
            schemas: BTreeMap::new(),
            channels: BTreeMap::new(),
            tap,
            mirror,
            last_ns: None,
            next_flush_ns: None,
            full: false,
            order: Vec::new(),
        }
    }

    /// The tap and the mirror, those there are (none: nothing to do, nothing allocated).
    fn mirrors(&mut self) -> impl Iterator<Item = &mut (dyn Mirror + 'static)> {
        let tap = self.tap.as_mut().map(|t| t as &mut (dyn Mirror + 'static));
        tap.into_iter().chain(self.mirror.as_deref_mut())
    }

    fn err(&self, source: mcap::McapError) -> Error {
        write_error(&self.file, source)
    }

    fn w(&mut self) -> &mut mcap::Writer<BufWriter<File>> {
        // None only after finish or abandon, which consume self
        let Some(w) = self.mcap.as_mut() else { unreachable!("worker used after it finished") };
        w
    }

    /// Runs one job; `recycle` takes a message's buffer back.
    pub(super) fn job(&mut self, job: Job, recycle: &mut dyn FnMut(Vec<u8>)) -> Result<(), Error> {
        match job {
            Job::Schema { id, name, encoding, data } => {
                for m in self.mirrors() {
                    m.schema(id, &name, encoding, &data);
                }
                self.schemas.insert(id, Schema { name, encoding, data, registered: false });
            }
            Job::Channel { id, schema_id, topic, encoding } => {
                let metadata = crate::units::channel_metadata(&topic);
                for m in self.mirrors() {
                    m.channel(id, schema_id, &topic, encoding, &metadata);
                }
                let chan = Chan { schema_id, topic, encoding, metadata, registered: false, staged: Vec::new(), bytes: Vec::new(), chunk_bytes: 0 };
                self.channels.insert(id, chan);
                if !self.options.chunk_per_topic {
                    self.register(id)?;
                }
            }
            Job::Metadata(m) => {
                for mirror in self.mirrors() {
                    mirror.metadata(&m.name, &m.metadata);
                }
                // after every message written before it
                self.flush_all()?;
                let r = self.w().write_metadata(&m);
                r.map_err(|e| self.err(e))?;
            }
            Job::Message { header, data } => {
                for m in self.mirrors() {
                    m.message(header.channel_id, header.sequence, header.log_time, &data);
                }
                let result = self.message(&header, &data);
                recycle(data);
                result?;
            }
            Job::Finish => {}
        }
        Ok(())
    }

    fn message(&mut self, header: &MessageHeader, data: &[u8]) -> Result<(), Error> {
        if !self.options.chunk_per_topic {
            let r = self.w().write_to_known_channel(header, data);
            return r.map_err(|e| self.err(e));
        }
        // a new instant closes the group when it is due (module docs: flush groups)
        let t = header.log_time;
        let new_instant = self.last_ns.is_none_or(|last| t > last);
        if new_instant {
            if self.full || self.next_flush_ns.is_some_and(|due| t >= due) {
                self.flush_all()?;
            }
            if self.next_flush_ns.is_none_or(|due| t >= due) {
                let every = self.options.flush_interval_ns;
                self.next_flush_ns = (every > 0).then(|| (t / every).saturating_add(1).saturating_mul(every));
            }
            self.last_ns = Some(t);
        }
        let Some(chan) = self.channels.get_mut(&header.channel_id) else {
            unreachable!("the writer sends a channel before its messages");
        };
        chan.bytes.extend_from_slice(data);
        chan.staged.push((*header, chan.bytes.len()));
        chan.chunk_bytes += MESSAGE_RECORD_OVERHEAD + data.len() as u64;
        if chan.chunk_bytes >= self.options.chunk_size {
            self.full = true;
        }
        if chan.chunk_bytes >= self.options.chunk_size.saturating_mul(2) {
            // one instant larger than two chunks: bound the memory, split the instant
            self.flush_all()?;
        }
        Ok(())
    }

    /// Registers channel `id` (and its schema) with `mcap`: written into the open chunk.
    fn register(&mut self, id: u16) -> Result<(), Error> {
        let Some(chan) = self.channels.get_mut(&id) else { return Ok(()) };
        if chan.registered {
            return Ok(());
        }
        chan.registered = true;
        let Some(w) = self.mcap.as_mut() else { unreachable!("worker used after it finished") };
        if let Some(s) = self.schemas.get_mut(&chan.schema_id).filter(|s| !s.registered) {
            s.registered = true;
            w.add_schema_with_id(chan.schema_id, &s.name, s.encoding, &s.data).map_err(|e| write_error(&self.file, e))?;
        }
        w.add_channel_with_id(id, chan.schema_id, &chan.topic, chan.encoding, &chan.metadata).map_err(|e| write_error(&self.file, e))?;
        Ok(())
    }

    /// Writes the staged messages of channel `id` as one chunk (with the channel's record if it
    /// is its first).
    fn flush_channel(&mut self, id: u16) -> Result<(), Error> {
        let Some(chan) = self.channels.get(&id) else { return Ok(()) };
        if chan.staged.is_empty() {
            return Ok(());
        }
        // close the chunk another channel may have left open
        let r = self.w().flush();
        r.map_err(|e| self.err(e))?;
        self.register(id)?;
        let (Some(chan), Some(w)) = (self.channels.get_mut(&id), self.mcap.as_mut()) else { return Ok(()) };
        let mut start = 0;
        for (header, end) in &chan.staged {
            w.write_to_known_channel(header, &chan.bytes[start..*end]).map_err(|e| write_error(&self.file, e))?;
            start = *end;
        }
        chan.staged.clear();
        chan.bytes.clear();
        chan.chunk_bytes = 0;
        w.flush().map_err(|e| write_error(&self.file, e))
    }

    /// Writes every staged chunk (a flush group): latest last log time first, then by channel
    /// id (module docs).
    fn flush_all(&mut self) -> Result<(), Error> {
        if !self.options.chunk_per_topic {
            return Ok(());
        }
        let mut order = std::mem::take(&mut self.order);
        order.clear();
        order.extend(self.channels.iter().filter_map(|(&id, c)| c.staged.last().map(|(h, _)| (h.log_time, id))));
        order.sort_unstable_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
        let flushed = order.iter().try_for_each(|&(_, id)| self.flush_channel(id));
        self.order = order;
        self.full = false;
        flushed
    }

    /// Summary and footer; the file, flushed, and what the tap saw.
    pub(super) fn finish(mut self) -> Result<Done, Error> {
        self.flush_all()?;
        let ids: Vec<u16> = self.channels.keys().copied().collect();
        for id in ids {
            self.register(id)?;
        }
        let r = self.w().finish();
        r.map_err(|e| self.err(e))?;
        let Some(w) = self.mcap.take() else { unreachable!("finish consumes the worker") };
        let file = w.into_inner().into_inner().map_err(|e| Error::Io { file: self.file.clone(), op: "writing", source: e.into_error() })?;
        if let Some(m) = &mut self.mirror {
            m.finish();
        }
        Ok(Done { file: Some(file), tapped: self.tap.take().map(Tap::finish) })
    }

    /// Leaves the file without its summary (the caller deletes it).
    pub(super) fn abandon(mut self) -> Done {
        if let Some(m) = &mut self.mirror {
            m.finish();
        }
        Done { file: None, tapped: self.tap.take().map(Tap::finish) }
    }
}

impl Drop for Worker {
    fn drop(&mut self) {
        if let Some(w) = self.mcap.take() {
            // into_inner() skips the summary that mcap's own Drop would write (an unfinished
            // file is deleted by the caller)
            drop(w.into_inner());
        }
    }
}

/// The worker thread: runs the jobs until `Finish` (then writes the summary) or until the
/// writer is dropped or `abort` is set (then leaves the file unfinished). The first error
/// ends it; the writer sees the channel closed and collects the error here.
pub(super) fn run(mut worker: Worker, jobs: Receiver<Job>, free: SyncSender<Vec<u8>>, abort: Arc<AtomicBool>) -> Result<Done, Error> {
    let mut recycle = |mut buf: Vec<u8>| {
        buf.clear();
        let _ = free.try_send(buf); // a full free list drops the buffer
    };
    while let Ok(job) = jobs.recv() {
        if abort.load(Ordering::Relaxed) {
            break;
        }
        if matches!(job, Job::Finish) {
            return worker.finish();
        }
        worker.job(job, &mut recycle)?; // (dropping the worker leaves the file unfinished)
    }
    Ok(worker.abandon())
}
