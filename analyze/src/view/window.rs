//! The samples of a recording drawn one time window at a time, as the file streams by (issue
//! 29: `analyze view` in memory bounded by the work, not by the file).
//!
//! [`draw_run`] reads the recording once more (after [`Run::survey`]) and hands each drawn
//! message to [`Windows`], which keeps the messages of each topic in a queue. When a queue
//! holds [`WINDOW_ROWS`] samples, the window is cut at the earliest of the latest times seen
//! on the topics that are not finished (the file's message counts say which): every message
//! before that time has been read, whatever the order of the topics in the file, so the
//! samples of one time on `/tf` and on the force topic land in the same window (the contact
//! arrows pair them by index). The window's samples go into the [`Run`], become chunks
//! ([`entities::run_chunks`]) and are written at once; each static chunk (geometry, styles)
//! once, with the first window that has it. A file whose topics do not interleave (one topic whole, then
//! the next) is cut by size instead, at 8 [`WINDOW_ROWS`] of one queue.
//!
//! A recording that fits in one window (every paper run: 50 Hz, 5 s) gives exactly the chunks
//! of the whole run, in the same order, so its `.rrd` is the one the whole-file encoder wrote.
//! Contact events are sparse: each window takes the events read so far.

use std::collections::{BTreeMap, VecDeque};
use std::io::Write;
use std::path::Path;

use schemas::{ArraySizes, ConstraintState, ContactEventMsg, ContactState, EnergyState, HandState, MotorState, Transforms};

use super::chunk::Chunk;
use super::entities::{self, Paths};
use super::manifest::Manifests;
use super::pose::Pose;
use super::rrd::{RrdStream, StoreId, Tuid};
use super::run::{first_error, ns, stop, Run, DRAWN};
use crate::Error;

/// Samples of one topic that start a cut: about 8 MB of decoded messages of the paper's arm
/// per window, and one window for a 5 s run at 1 kHz.
pub const WINDOW_ROWS: usize = 8192;

/// The first id: 2026-01-01T00:00:00Z in ns (ids count up from it).
const ID_TIME0_NS: u64 = 1_767_225_600_000_000_000;

/// Chunk and row ids: deterministic, counting up from a fixed time.
pub struct Ids {
    next: u64,
    inc: u64,
}

impl Ids {
    pub fn new(inc: u64) -> Self {
        Ids { next: 0, inc }
    }

    /// `n` consecutive ids; the first.
    pub fn take(&mut self, n: u64) -> Tuid {
        let t = Tuid::new(ID_TIME0_NS + self.next, self.inc);
        self.next += n.max(1);
        t
    }
}

/// Where chunks go: the stream, its ids, and the manifests of its footer.
pub struct Sink<W: Write> {
    pub stream: RrdStream<W>,
    pub ids: Ids,
    pub manifests: Manifests,
    /// The output, for errors.
    pub label: String,
}

impl<W: Write> Sink<W> {
    pub fn io(&self, source: std::io::Error) -> Error {
        Error::Io { file: self.label.clone(), op: "writing", source }
    }

    /// Encodes `chunk` (Arrow IPC) and writes it to `store`.
    pub fn push(&mut self, store: &StoreId, chunk: &Chunk) -> Result<(), Error> {
        let chunk_id = self.ids.take(1);
        let first_row = self.ids.take(chunk.rows as u64);
        let ipc = chunk
            .to_ipc(chunk_id, first_row)
            .map_err(|e| Error::View { file: chunk.entity_path.clone(), detail: format!("encoding the chunk as Arrow IPC: {e}") })?;
        let ipc_len = ipc.len() as u64;
        let (offset, size) = self.stream.arrow_msg(store, chunk_id, chunk.is_static(), ipc).map_err(|e| self.io(e))?;
        self.manifests.add(store, chunk, chunk_id, offset, size, ipc_len);
        Ok(())
    }

    /// Ends the stream with its footer; the writer and the bytes written.
    pub fn finish(mut self) -> Result<(W, u64), Error> {
        let footer = self.manifests.footer().map_err(|e| Error::View { file: self.label.clone(), detail: format!("encoding the RRD footer: {e}") })?;
        self.stream.end(&footer).map_err(|e| self.io(e))?;
        let written = self.stream.written();
        let label = self.label.clone();
        let out = self.stream.finish().map_err(|source| Error::Io { file: label, op: "writing", source })?;
        Ok((out, written))
    }
}

/// The messages of one topic read and not yet drawn.
struct Queue<M> {
    items: VecDeque<(f64, M)>,
    /// Messages read, and in the file.
    seen: usize,
    total: usize,
    last_t: f64,
}

impl<M> Queue<M> {
    fn new(total: usize) -> Self {
        Queue { items: VecDeque::new(), seen: 0, total, last_t: f64::NEG_INFINITY }
    }

    fn push(&mut self, t: f64, m: M) {
        self.items.push_back((t, m));
        self.seen += 1;
        self.last_t = t;
    }

    /// The time before which every message of this topic has been read (`None`: all read).
    fn complete_before(&self) -> Option<f64> {
        (self.seen < self.total).then_some(self.last_t)
    }

    /// The queued messages before `t`.
    fn before(&self, t: f64) -> usize {
        self.items.partition_point(|(s, _)| *s < t)
    }

    fn take(&mut self, n: usize) -> Vec<(f64, M)> {
        self.items.drain(..n).collect()
    }
}

/// The windowed drawing of one run: a [`schemas::Visitor`] of [`draw_run`].
struct Windows<'a, W: Write> {
    run: Run,
    sizes: ArraySizes,
    paths: &'a Paths,
    store: &'a StoreId,
    sink: &'a mut Sink<W>,
    window_rows: usize,
    /// Windows written.
    windows: usize,
    tf: Queue<Transforms>,
    hand: Queue<HandState>,
    motors: Queue<MotorState>,
    energy: Queue<EnergyState>,
    constraints: Queue<ConstraintState>,
    contacts: Queue<ContactState>,
    events: Vec<(f64, ContactEventMsg)>,
    /// The static chunks written: entity and component fields.
    statics: std::collections::BTreeSet<(String, String)>,
    /// Each frame's latest pose in its parent (kept from one window to the next).
    latest: Vec<Pose>,
    frame_index: BTreeMap<String, usize>,
    error: Option<Error>,
}

impl<W: Write> Windows<'_, W> {
    fn queued(&self) -> [usize; 6] {
        [self.tf.items.len(), self.hand.items.len(), self.motors.items.len(), self.energy.items.len(), self.constraints.items.len(), self.contacts.items.len()]
    }

    /// Draws the window of the queued samples before the cut (every queued sample when `last`).
    fn cut(&mut self, last: bool) -> Result<(), Error> {
        let mut t_cut = if last {
            f64::INFINITY
        } else {
            [
                self.tf.complete_before(),
                self.hand.complete_before(),
                self.motors.complete_before(),
                self.energy.complete_before(),
                self.constraints.complete_before(),
                self.contacts.complete_before(),
            ]
            .into_iter()
            .flatten()
            .fold(f64::INFINITY, f64::min)
        };
        let counts = |t: f64, s: &Self| {
            [s.tf.before(t), s.hand.before(t), s.motors.before(t), s.energy.before(t), s.constraints.before(t), s.contacts.before(t)]
        };
        let mut n = counts(t_cut, self);
        if !last && n.iter().all(|&k| k == 0) {
            // the topics do not interleave: cut by size
            if self.queued().iter().any(|&k| k >= 8 * self.window_rows) {
                t_cut = f64::INFINITY;
                n = counts(t_cut, self);
            } else {
                return Ok(());
            }
        }
        if self.windows > 0 && n.iter().all(|&k| k == 0) && self.events.is_empty() {
            return Ok(());
        }
        // the window's samples into the run
        let [n_tf, n_hand, n_motors, n_energy, n_constraints, n_contacts] = n;
        for (t, msg) in self.tf.take(n_tf) {
            for e in &msg.transforms {
                if e.child_frame_id == e.parent_frame_id {
                    continue;
                }
                if let Some(&i) = self.frame_index.get(&e.child_frame_id) {
                    self.latest[i] = Pose {
                        translation: [e.translation.x, e.translation.y, e.translation.z],
                        rotation: [e.rotation.x, e.rotation.y, e.rotation.z, e.rotation.w],
                    };
                }
            }
            self.run.tf_times_ns.push(ns(t));
            for (i, (_, f)) in self.run.frames.iter_mut().enumerate() {
                f.in_parent.push(self.latest[i]);
            }
        }
        self.run.hand = self.hand.take(n_hand);
        self.run.motors = self.motors.take(n_motors);
        self.run.energy = self.energy.take(n_energy);
        self.run.constraints = self.constraints.take(n_constraints);
        self.run.contact_states = self.run.whole.has_contact_states.then(|| self.contacts.take(n_contacts));
        self.run.events = std::mem::take(&mut self.events);

        let (chunks, _) = entities::run_chunks(&self.run, self.paths);
        for c in &chunks {
            // each static chunk once (with the first window that has it); no temporal chunk
            // without rows (an entity whose topic has no sample in this window, or none at all)
            if c.is_static() {
                let key = (c.entity_path.clone(), c.columns.iter().map(|k| k.field).collect::<Vec<_>>().join(","));
                if !self.statics.insert(key) {
                    continue;
                }
            } else if c.rows == 0 {
                continue;
            }
            self.sink.push(self.store, c)?;
        }
        self.windows += 1;
        self.run.clear_samples();
        Ok(())
    }

    fn take(&mut self, m: schemas::DecodedMessage<'_>) -> Result<(), Error> {
        let t = m.t_s();
        let sizes = Some(self.sizes);
        let full = match m.topic {
            schemas::topics::TF => {
                self.tf.push(t, m.decode::<Transforms>(None)?);
                self.tf.items.len()
            }
            schemas::topics::HAND => {
                self.hand.push(t, m.decode::<HandState>(None)?);
                self.hand.items.len()
            }
            schemas::topics::MOTORS => {
                self.motors.push(t, m.decode::<MotorState>(sizes)?);
                self.motors.items.len()
            }
            schemas::topics::ENERGY => {
                self.energy.push(t, m.decode::<EnergyState>(sizes)?);
                self.energy.items.len()
            }
            schemas::topics::CONSTRAINTS => {
                self.constraints.push(t, m.decode::<ConstraintState>(sizes)?);
                self.constraints.items.len()
            }
            schemas::topics::CONTACTS => {
                self.contacts.push(t, m.decode::<ContactState>(sizes)?);
                self.contacts.items.len()
            }
            schemas::topics::CONTACT_EVENTS => {
                self.events.push((t, m.decode::<ContactEventMsg>(None)?));
                0
            }
            _ => 0,
        };
        if full >= self.window_rows {
            self.cut(false)?;
        }
        Ok(())
    }
}

impl<W: Write> schemas::Visitor for Windows<'_, W> {
    fn message(&mut self, m: schemas::DecodedMessage<'_>) -> Result<(), schemas::Error> {
        match self.take(m) {
            Ok(()) => Ok(()),
            Err(Error::Read(e)) => Err(*e),
            Err(e) => Err(stop(&mut self.error, e)),
        }
    }

    fn typed(&self) -> bool {
        true
    }
}

/// Draws the samples of the recording at `path` (surveyed into `run`) under `paths` into
/// `store`, one window of at most about `window_rows` samples per topic at a time. Returns the
/// number of windows written.
pub fn draw_run<W: Write>(
    path: &Path,
    run: &Run,
    paths: &Paths,
    store: &StoreId,
    sink: &mut Sink<W>,
    window_rows: usize,
) -> Result<usize, Error> {
    let count = |topic: &str| run.whole.counts.get(topic).copied().unwrap_or(0);
    let mut run = run.clone();
    run.clear_samples();
    let frame_index = run.frames.iter().enumerate().map(|(i, (name, _))| (name.clone(), i)).collect();
    let mut w = Windows {
        sizes: ArraySizes { joints: run.joints.len(), contacts: run.contacts.len() },
        latest: vec![Pose::IDENTITY; run.frames.len()],
        frame_index,
        run,
        paths,
        store,
        sink,
        window_rows: window_rows.max(1),
        windows: 0,
        tf: Queue::new(count(schemas::topics::TF)),
        hand: Queue::new(count(schemas::topics::HAND)),
        motors: Queue::new(count(schemas::topics::MOTORS)),
        energy: Queue::new(count(schemas::topics::ENERGY)),
        constraints: Queue::new(count(schemas::topics::CONSTRAINTS)),
        contacts: Queue::new(count(schemas::topics::CONTACTS)),
        events: Vec::new(),
        statics: Default::default(),
        error: None,
    };
    let read = schemas::stream_recording(path, Some(&DRAWN), &mut w);
    first_error(read, w.error.take())?;
    w.cut(true)?;
    Ok(w.windows)
}
