//! The scene's robot: its URDF loaded with the scene's `robot` options (locked joints, inertia
//! repair) and its mesh references resolved against `robot.package_paths`.

use std::path::Path;

use nalgebra::Vector3;

use super::ctx::Ctx;
use super::SceneSpec;
use crate::dynamics::model::UrdfOptions;
use crate::dynamics::urdf::{resolve_meshes, MeshInfo};
use crate::dynamics::Model;
use crate::error::{ModelError, SceneError};

/// The model of the scene's URDF with the scene's `robot` options, and the URDF text with its
/// meshes resolved (the same text when it has none).
pub(super) fn load_robot(
    c: &Ctx,
    spec: &SceneSpec,
    urdf_xml: String,
    gravity: Vector3<f64>,
    dir: Option<&Path>,
) -> Result<(Model, String, Vec<MeshInfo>), SceneError> {
    let robot = &spec.robot;
    let options = UrdfOptions { locked: robot.locked.clone(), repair_inertia: robot.repair_inertia, field: "robot".into() };
    let model = Model::from_urdf_with(&urdf_xml, &spec.urdf, gravity, &options).map_err(|e| match e {
        ModelError::Option { field, value, why, .. } => c.err(field, value, why),
        e => c.err("urdf", &spec.urdf, e.to_string()),
    })?;
    let mut packages = std::collections::BTreeMap::new();
    for (pkg, d) in &robot.package_paths {
        let p = dir.map_or_else(|| Path::new(d).to_path_buf(), |base| base.join(d));
        let p = std::path::absolute(&p).unwrap_or(p);
        if !p.is_dir() {
            return Err(c.err(format!("robot.package_paths.{pkg}"), d, format!("no directory {} (relative to the scene file)", p.display())));
        }
        packages.insert(pkg.clone(), p);
    }
    // meshes are resolved (to this machine's absolute paths) only when the scene asks, so that
    // a scene that does not writes the same recording on every machine
    let urdf_dir = dir.filter(|_| !packages.is_empty()).map(|d| {
        let p = d.join(&spec.urdf);
        let p = p.parent().map(Path::to_path_buf).unwrap_or_default();
        std::path::absolute(&p).unwrap_or(p)
    });
    let (text, meshes) = resolve_meshes(&urdf_xml, &spec.urdf, &packages, urdf_dir.as_deref())
        .map_err(|e| c.err("urdf", &spec.urdf, e.to_string()))?;
    // the text as read when nothing was rewritten
    let urdf_xml = if text == urdf_xml { urdf_xml } else { text };
    Ok((model, urdf_xml, meshes))
}
