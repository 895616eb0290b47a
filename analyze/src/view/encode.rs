//! The `.rrd` of recordings: read each ([`read_input`]), lay the runs out and encode the
//! stream ([`encode`]).

use std::path::Path;

use super::chunk::{str_lists, Chunk, Index};
use super::entities::{self, Paths};
use super::rrd::{RrdStream, StoreId, StoreKind, Tuid};
use super::run::Run;
use super::{blueprint, layout};

use crate::Error;

/// What wrote the stores (`StoreSource::Other`).
const SOURCE: &str = "elbow-sim analyze view";
/// The first id: 2026-01-01T00:00:00Z in ns (ids count up from it).
const ID_TIME0_NS: u64 = 1_767_225_600_000_000_000;

/// A recording read for `analyze view`: the run, its label and a hash of the file's bytes.
pub struct Input {
    pub run: Run,
    /// The file stem.
    pub stem: String,
    /// FNV-1a of the file's bytes (the recording id).
    pub hash: u64,
}

/// FNV-1a, 64 bit (<http://www.isthe.com/chongo/tech/comp/fnv/>).
pub fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3))
}

/// Reads the recording at `path` for [`encode`], through the reader's guard (a regular file
/// with the MCAP magic, bounded records, read streamed: a FIFO, a device or a 20 GB file of
/// anything else is refused before it is read).
pub fn read_input(path: &Path) -> Result<Input, Error> {
    let rec = schemas::read_recording(path)?;
    let stem = path.file_stem().map_or_else(|| "recording".to_string(), |s| s.to_string_lossy().into_owned());
    let run = Run::read(&rec, &stem)?;
    Ok(Input { run, stem, hash: fnv1a_file(path)? })
}

/// [`fnv1a`] of the file at `path`, read in blocks (the file has passed the reader's guard).
fn fnv1a_file(path: &Path) -> Result<u64, Error> {
    use std::io::Read;
    let file = path.display().to_string();
    let io = |source| Error::Io { file: file.clone(), op: "reading", source };
    let (mut f, _) = schemas::open_regular(path)?;
    let mut buf = vec![0u8; 1 << 16];
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    loop {
        let n = match f.read(&mut buf) {
            Ok(0) => return Ok(h),
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(io(e)),
        };
        h = buf[..n].iter().fold(h, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3));
    }
}

struct Ids {
    next: u64,
    inc: u64,
}

impl Ids {
    /// `n` consecutive ids; the first.
    fn take(&mut self, n: u64) -> Tuid {
        let t = Tuid::new(ID_TIME0_NS + self.next, self.inc);
        self.next += n.max(1);
        t
    }
}

fn push(stream: &mut RrdStream, store: &StoreId, ids: &mut Ids, chunk: &Chunk) -> Result<(), Error> {
    let chunk_id = ids.take(1);
    let first_row = ids.take(chunk.rows as u64);
    let ipc = chunk
        .to_ipc(chunk_id, first_row)
        .map_err(|e| Error::View { file: chunk.entity_path.clone(), detail: format!("encoding the chunk as Arrow IPC: {e}") })?;
    stream.arrow_msg(store, chunk_id, chunk.is_static(), ipc);
    Ok(())
}

/// The labels of the runs in a comparison: their run names when those differ, else the file
/// stems (which differ, or the caller has refused the inputs).
pub fn labels(inputs: &[Input]) -> Vec<String> {
    let names: Vec<String> = inputs.iter().map(|i| i.run.name.clone()).collect();
    let mut sorted = names.clone();
    sorted.sort();
    sorted.dedup();
    if sorted.len() == names.len() {
        names
    } else {
        inputs.iter().map(|i| i.stem.clone()).collect()
    }
}

/// The `.rrd` bytes of `inputs` under application id `app_id`: one run as is, several side by
/// side (entity prefix per run, see [`entities`]), with the blueprint of [`layout`].
pub fn encode(inputs: &[Input], app_id: &str) -> Result<Vec<u8>, Error> {
    let hash = inputs.iter().fold(fnv1a(app_id.as_bytes()), |h, i| h.rotate_left(5) ^ i.hash);
    let recording = StoreId::new(StoreKind::Recording, app_id, &format!("{app_id}-{hash:016x}"));
    let blueprint_id = StoreId::new(StoreKind::Blueprint, app_id, &format!("{app_id}-{hash:016x}-blueprint"));
    let mut ids = Ids { next: 0, inc: hash };

    // the entities of every run
    let single = inputs.len() == 1;
    let labels = labels(inputs);
    let mut chunks = vec![Chunk::new("/__properties", Index::Static).with(
        "rerun.archetypes.RecordingInfo",
        "name",
        "rerun.components.Name",
        str_lists(&[vec![app_id.to_string()]]),
    )];
    let mut placed = Vec::with_capacity(inputs.len());
    for (k, (input, label)) in inputs.iter().zip(&labels).enumerate() {
        let paths = if single {
            Paths { prefix: String::new(), run: None, index: 0 }
        } else {
            Paths { prefix: layout::prefix(label), run: Some(label.clone()), index: k }
        };
        let (c, bounds) = entities::run_chunks(&input.run, &paths);
        chunks.extend(c);
        placed.push((paths, bounds));
    }
    let root = if single {
        layout::single(&inputs[0].run, &placed[0].0, &placed[0].1)
    } else {
        let refs: Vec<_> = inputs.iter().zip(&placed).map(|(i, (p, b))| (&i.run, p, b)).collect();
        layout::comparison(&refs)
    };

    let mut stream = RrdStream::new();
    // the blueprint first (as the SDK does), made the default of the application id
    stream.set_store_info(ids.take(1), &blueprint_id, SOURCE);
    for c in blueprint::chunks(&root, hash) {
        push(&mut stream, &blueprint_id, &mut ids, &c)?;
    }
    stream.activate_blueprint(&blueprint_id);
    stream.set_store_info(ids.take(1), &recording, SOURCE);
    for c in &chunks {
        push(&mut stream, &recording, &mut ids, c)?;
    }
    Ok(stream.into_bytes())
}

