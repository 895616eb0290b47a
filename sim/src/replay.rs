//! Rebuild a scene from a recording alone: the scene JSON, the URDF text and the run name are
//! in its metadata (`record.rs`), so an archived run says how to reproduce itself. The rebuilt
//! scene keeps the recorded source name, so a replay by the same version of the tool writes a
//! byte-identical file.

use std::path::Path;

use crate::record::records;
use crate::scene::Scene;

/// Why a recording cannot be replayed.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    #[error("{file}: {source}")]
    Read { file: String, source: schemas::Error },
    #[error("{file}: metadata record `{record}` has no `{key}`: not a recording written by sim, or an older format")]
    Missing { file: String, record: &'static str, key: &'static str },
    #[error("{file}: the embedded scene is not valid: {source}")]
    Scene { file: String, source: crate::error::SceneError },
}

/// The scene and the run name embedded in the recording at `path`.
pub fn scene_from_recording(path: &Path) -> Result<(Scene, String), ReplayError> {
    let file = path.display().to_string();
    let rec = schemas::read_recording(path).map_err(|source| ReplayError::Read { file: file.clone(), source })?;
    let get = |record: &'static str, key: &'static str| {
        rec.metadata_value(record, key).map(str::to_string).ok_or(ReplayError::Missing { file: file.clone(), record, key })
    };
    let json = get(records::SCENE, "json")?;
    let source = get(records::SCENE, "source")?;
    let urdf_file = get(records::URDF, "file")?;
    let urdf_xml = get(records::URDF, "xml")?;
    let run = get(records::RUN, "run")?;
    let scene = Scene::from_json(&json, &source, |name| {
        if name == urdf_file {
            Ok(urdf_xml.clone())
        } else {
            Err(format!("the recording embeds `{urdf_file}`, not `{name}`"))
        }
    })
    .map_err(|source| ReplayError::Scene { file, source })?;
    Ok((scene, run))
}
