//! The `.rrd` of recordings: read each ([`read_input`]), lay the runs out and encode the
//! stream ([`encode`]).

use std::io::Write;
use std::path::{Path, PathBuf};

use super::chunk::{str_lists, Chunk, Index};
use super::entities::{Bounds, Paths};
use super::rrd::{RrdStream, StoreId, StoreKind};
use super::mesh::{self, Drawn};
use super::run::Run;
use super::window::{self, Ids, Sink, WINDOW_ROWS};
use super::{blueprint, layout};

use crate::Error;

/// What wrote the stores (`StoreSource::Other`).
const SOURCE: &str = "elbow-sim analyze view";

/// A recording surveyed for `analyze view` ([`Run::survey`]: what is drawn but the samples,
/// which are read again window by window as the `.rrd` is written), its label and a hash of
/// the file's bytes.
pub struct Input {
    pub run: Run,
    /// The recording.
    pub path: PathBuf,
    /// The file stem.
    pub stem: String,
    /// FNV-1a of the file's bytes (the recording id).
    pub hash: u64,
}

/// FNV-1a, 64 bit (<http://www.isthe.com/chongo/tech/comp/fnv/>).
pub fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3))
}

/// Surveys the recording at `path` for [`encode`], through the reader's guard (a regular file
/// with the MCAP magic, bounded records, read streamed: a FIFO, a device or a 20 GB file of
/// anything else is refused before it is read).
pub fn read_input(path: &Path) -> Result<Input, Error> {
    let stem = path.file_stem().map_or_else(|| "recording".to_string(), |s| s.to_string_lossy().into_owned());
    let run = Run::survey(path, &stem)?;
    Ok(Input { run, path: path.to_path_buf(), stem, hash: fnv1a_file(path)? })
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

/// The bounds the views of `run` place their cameras by (the whole run's).
fn bounds(run: &Run) -> Bounds {
    let w = &run.whole;
    Bounds { arm_min: w.arm_min, arm_max: w.arm_max, hand_min: w.hand_min, hand_max: w.hand_max, base: w.base }
}

/// The `.rrd` bytes of `inputs` under application id `app_id` ([`encode_to`] into memory).
pub fn encode(inputs: &[Input], app_id: &str) -> Result<Vec<u8>, Error> {
    let (bytes, _, _) = encode_to(inputs, app_id, Vec::with_capacity(1 << 20), "the .rrd", WINDOW_ROWS)?;
    Ok(bytes)
}

/// Writes the `.rrd` of `inputs` under application id `app_id` to `out` (`label` names it in
/// errors): one run as is, several side by side (entity prefix per run, see
/// [`super::entities`]), with the blueprint of [`layout`]. Each recording is read again and
/// drawn in time windows of about `window_rows` samples ([`window`]), so memory does not grow
/// with the recordings; the footer lists every chunk ([`super::manifest`]). The links' meshes
/// of each run are static, read and written once before its samples, one file at a time
/// ([`mesh::draw`]). Returns the writer, the bytes written and what was drawn of each run's
/// meshes.
pub fn encode_to<W: Write>(inputs: &[Input], app_id: &str, out: W, label: &str, window_rows: usize) -> Result<(W, u64, Vec<Drawn>), Error> {
    encode_on_tab(inputs, app_id, None, out, label, window_rows)
}

/// [`encode_to`], the blueprint opening on the tab named `tab` (the first when `None`; an
/// error naming the tabs when the blueprint has none of that name).
pub fn encode_on_tab<W: Write>(inputs: &[Input], app_id: &str, tab: Option<&str>, out: W, label: &str, window_rows: usize) -> Result<(W, u64, Vec<Drawn>), Error> {
    let hash = inputs.iter().fold(fnv1a(app_id.as_bytes()), |h, i| h.rotate_left(5) ^ i.hash);
    let recording = StoreId::new(StoreKind::Recording, app_id, &format!("{app_id}-{hash:016x}"));
    let blueprint_id = StoreId::new(StoreKind::Blueprint, app_id, &format!("{app_id}-{hash:016x}-blueprint"));
    let io = |source| Error::Io { file: label.to_string(), op: "writing", source };
    let mut sink = Sink { stream: RrdStream::new(out).map_err(io)?, ids: Ids::new(hash), manifests: Default::default(), label: label.to_string() };

    // where each run goes, and the blueprint (from the surveys: the whole runs' bounds)
    let single = inputs.len() == 1;
    let labels = labels(inputs);
    let placed: Vec<(Paths, Bounds)> = inputs
        .iter()
        .zip(&labels)
        .enumerate()
        .map(|(k, (input, label))| {
            let paths = if single {
                Paths { prefix: String::new(), run: None, index: 0 }
            } else {
                Paths { prefix: layout::prefix(label), run: Some(label.clone()), index: k }
            };
            (paths, bounds(&input.run))
        })
        .collect();
    let root = if single {
        layout::single(&inputs[0].run, &placed[0].0, &placed[0].1)
    } else {
        let refs: Vec<_> = inputs.iter().zip(&placed).map(|(i, (p, b))| (&i.run, p, b)).collect();
        layout::comparison(&refs)
    };
    let root = match tab {
        Some(t) => root.open_on(t).map_err(|tabs| Error::View {
            file: label.to_string(),
            detail: format!("--tab {t:?}: no such tab in its view (its tabs: {})", tabs.iter().map(|n| format!("{n:?}")).collect::<Vec<_>>().join(", ")),
        })?,
        None => root,
    };

    // the blueprint first (as the SDK does), made the default of the application id
    let store_info = sink.ids.take(1);
    sink.stream.set_store_info(store_info, &blueprint_id, SOURCE).map_err(io)?;
    for c in blueprint::chunks(&root, hash) {
        sink.push(&blueprint_id, &c)?;
    }
    sink.stream.activate_blueprint(&blueprint_id).map_err(io)?;
    let store_info = sink.ids.take(1);
    sink.stream.set_store_info(store_info, &recording, SOURCE).map_err(io)?;
    let properties = Chunk::new("/__properties", Index::Static).with(
        "rerun.archetypes.RecordingInfo",
        "name",
        "rerun.components.Name",
        str_lists(&[vec![app_id.to_string()]]),
    );
    sink.push(&recording, &properties)?;
    // the entities of every run: its meshes once, then its samples window by window
    let mut drawn = Vec::with_capacity(inputs.len());
    for (input, (paths, _)) in inputs.iter().zip(&placed) {
        let run = &input.run;
        let world = paths.world();
        let link_path = |link: &str| run.frames.iter().any(|(n, _)| n == link).then(|| run.frame_path(link, &world));
        drawn.push(mesh::draw(&run.links, &link_path, &mut |c| sink.push(&recording, &c))?);
        window::draw_run(&input.path, run, paths, &recording, &mut sink, window_rows)?;
    }
    let (out, bytes) = sink.finish()?;
    Ok((out, bytes, drawn))
}
