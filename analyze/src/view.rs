//! `analyze view`: recordings as Rerun `.rrd` files that open on the experiment — the arm in 3D
//! with the table, the target path and the contact forces, the motors' currents and voltages,
//! the contact forces and modes, the energies and the balance residual, named by joint and
//! contact, on a `sim_time` duration timeline, laid out by a blueprint (feature `rerun`).
//!
//! Written without the `rerun` crate (whose SDK brings an HTTP stack and a newer compiler): the
//! RRD stream is framed here ([`rrd`], prost for its protobuf messages) and each chunk is an
//! Arrow record batch in Rerun's chunk layout ([`chunk`], arrow's IPC writer). The layout
//! follows what the Rerun 0.41 Python SDK writes for the same archetypes and blueprint, and the
//! acceptance test loads the result back with that SDK (TESTING.md).
//!
//! - [`run`]: one recording surveyed for drawing (typed reader of `schemas`, streamed);
//!   [`window`]: its samples drawn one time window at a time as the file streams by, so that
//!   memory is bounded by the window, not by the recording (issue 29);
//! - [`entities`]: a run's entities as chunks; [`layout`]: the blueprint; [`blueprint`]: a
//!   blueprint tree as chunks; [`urdf`], [`pose`]: the geometry; [`mesh`]: the links' meshes
//!   (STL, COLLADA, OBJ), logged once per run, and their fallbacks.
//!
//! Ids are deterministic: the recording id is the application id and a hash of the input bytes,
//! and chunk and row ids count up from a fixed time, so the same inputs give the same bytes.

#[cfg(feature = "rerun")]
pub mod blueprint;
#[cfg(feature = "rerun")]
pub mod chunk;
#[cfg(feature = "rerun")]
pub mod contacts;
#[cfg(feature = "rerun")]
pub mod entities;
#[cfg(feature = "rerun")]
pub mod layout;
#[cfg(feature = "rerun")]
pub mod manifest;
#[cfg(feature = "rerun")]
pub mod mesh;
#[cfg(feature = "rerun")]
pub mod pose;
#[cfg(feature = "rerun")]
pub mod rrd;
#[cfg(feature = "rerun")]
pub mod run;
#[cfg(feature = "rerun")]
pub mod signals;
#[cfg(feature = "rerun")]
pub mod urdf;
#[cfg(feature = "rerun")]
pub mod window;

#[cfg(feature = "rerun")]
mod encode;
#[cfg(all(test, feature = "rerun"))]
mod tests;
#[cfg(feature = "rerun")]
pub use encode::{encode, encode_on_tab, encode_to, fnv1a, labels, read_input, Input};

use std::path::{Path, PathBuf};

use crate::Error;

/// What [`convert`] wrote.
#[derive(Debug, Clone, Default)]
pub struct Converted {
    /// Bytes of the `.rrd`.
    pub bytes: u64,
    /// The `result` record of each input (in order), when it has one: a failed run is drawn
    /// with what it recorded, and the caller says it failed.
    pub results: Vec<(PathBuf, Option<schemas::RunResult>)>,
    /// The meshes drawn, over every input: entities, vertices, triangles.
    pub meshes: (usize, usize, usize),
    /// What could not be drawn as the URDF asks (a missing or unreadable mesh, and what was
    /// drawn instead), one sentence per link, without repeats.
    pub notes: Vec<String>,
}

/// Converts the recordings `inputs` into one `.rrd` at `out` (written atomically, its directory
/// created if needed), application
/// id = `out`'s file stem; `progress` is called after each input is read. Returns the bytes
/// written and the runs' results. The viewer opens on the blueprint's tab named `tab` (the
/// first, "arm", when `None`; an error naming the tabs when there is no such tab). Without the
/// feature `rerun`, an error that says how to get it.
pub fn convert(inputs: &[PathBuf], out: &Path, tab: Option<&str>, progress: &dyn Fn()) -> Result<Converted, Error> {
    #[cfg(feature = "rerun")]
    {
        let mut read = Vec::with_capacity(inputs.len());
        for p in inputs {
            read.push(read_input(p)?);
            progress();
        }
        let app_id = out.file_stem().map_or_else(|| "recording".to_string(), |s| s.to_string_lossy().into_owned());
        if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|source| Error::Io { file: dir.display().to_string(), op: "creating the directory", source })?;
        }
        // streamed into the temporary file, renamed when whole
        let label = out.display().to_string();
        let mut bytes = 0;
        let mut drawn = Vec::new();
        schemas::atomic::write_with(out, |f| -> Result<(), Error> {
            let (_, n, d) = encode_on_tab(&read, &app_id, tab, std::io::BufWriter::with_capacity(1 << 20, f), &label, window::WINDOW_ROWS)?;
            (bytes, drawn) = (n, d);
            Ok(())
        })?;
        let results = inputs.iter().zip(&read).map(|(p, i)| (p.clone(), i.run.result.clone())).collect();
        let meshes = drawn.iter().fold((0, 0, 0), |(m, v, t), d| (m + d.meshes, v + d.vertices, t + d.triangles));
        let mut notes: Vec<String> = Vec::new();
        for n in drawn.into_iter().flat_map(|d| d.notes) {
            if !notes.contains(&n) {
                notes.push(n);
            }
        }
        Ok(Converted { bytes, results, meshes, notes })
    }
    #[cfg(not(feature = "rerun"))]
    {
        let _ = (inputs, out, tab, progress);
        Err(Error::ViewUnavailable)
    }
}
