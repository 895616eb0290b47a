//! Rebuild a scene from a recording alone: the scene JSON, the URDF text, the text of a
//! `joint-csv` target's file and the run name are in its metadata (`record.rs`), so an archived run says how to reproduce itself. The rebuilt
//! scene keeps the recorded source name, so a replay by the same version of the tool writes a
//! byte-identical file.

use std::path::Path;

use crate::scene::Scene;

/// Why a recording cannot be replayed.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// Unreadable, or its metadata lacks what a replay needs (not written by `sim`, or format 0).
    #[error("{0} (a replay needs the scene, URDF and run records that `sim` writes since format 1)")]
    Read(#[from] schemas::Error),
    #[error("{file}: the embedded scene is not valid: {source}")]
    Scene { file: String, source: crate::error::SceneError },
}

/// The scene and the run name embedded in the recording at `path`.
pub fn scene_from_recording(path: &Path) -> Result<(Scene, String), ReplayError> {
    let rec = schemas::read_recording_topics(path, Some(&[]))?;
    let (scene, urdf, run) = (rec.scene()?, rec.urdf()?, rec.run()?.run);
    let scene = Scene::from_json(&scene.json, &scene.source, |name| {
        match &scene.target_csv {
            _ if name == urdf.file => Ok(urdf.xml.clone()),
            Some(csv) => Ok(csv.clone()),
            None => Err(format!("the recording embeds `{}`, not `{name}`", urdf.file)),
        }
    })
    .map_err(|source| ReplayError::Scene { file: path.display().to_string(), source })?;
    Ok((scene, run))
}
