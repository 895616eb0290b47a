//! `sim export-scene`: a built-in scene (the paper's by default) and its URDF, as files to edit,
//! with the scene files' JSON Schema next to them (named by the scene's `"$schema"`).

use std::path::PathBuf;

use anyhow::{bail, Result};
use cli::{exit, Verbosity};
use sim::scene::builtin;
use sim::scene::schema::{self, FileKind};

/// Write a built-in scene (`sim list`; default: the paper's, paper.json and paper_arm.urdf), its
/// URDF and the scene files' JSON Schema into a directory, to edit; existing files are not
/// overwritten.
#[derive(Debug, Clone, clap::Args)]
#[command(after_help = "\
Output: DIR/<scene>.json and the URDF it names (paper.json and paper_arm.urdf by default), and
DIR/scene.schema.json, which the scene names as its \"$schema\" so that an editor checks it
(`sim schema`; one already there is kept when it is the same).

Examples:
  sim export-scene -o my-scene/ && sim check my-scene/paper.json
  sim export-scene hobby-arm -o my-arm/")]
pub struct ExportSceneArgs {
    /// The built-in scene to write (`sim list`).
    #[arg(value_name = "NAME", default_value = "paper")]
    pub name: String,
    /// Directory to write into (created if missing).
    #[arg(short = 'o', long = "out", value_name = "DIR", default_value = "scene")]
    pub out: PathBuf,
}

pub fn run(a: &ExportSceneArgs, v: Verbosity) -> Result<u8> {
    let Some(b) = builtin::find(&a.name) else {
        bail!("no built-in scene `{}` (built-in scenes: {})", a.name, builtin::names().join(", "));
    };
    cli::create_dir(&a.out)?;
    // the scene names the schema beside it (in the repository it is one directory up or here)
    let schema_file = FileKind::Scene.schema_file();
    let scene = schema::with_schema_path(b.json, schema_file);
    let schema = schema::schema_text(FileKind::Scene);
    let mut files: Vec<(&str, &str)> = std::iter::once((b.file, scene.as_str())).chain(b.files.iter().copied()).collect();
    // a schema already there from another export is left as it is when it is this one
    let schema_path = a.out.join(schema_file);
    if std::fs::read_to_string(&schema_path).ok().as_deref() != Some(schema.as_str()) {
        files.push((schema_file, schema.as_str()));
    }
    for (name, _) in &files {
        let p = a.out.join(name);
        if p.exists() {
            bail!("{} exists; not overwriting it", p.display());
        }
    }
    for (name, text) in files {
        let p = a.out.join(name);
        cli::write_file(&p, text)?;
        if !v.quiet {
            eprintln!("wrote {}", p.display());
        }
    }
    Ok(exit::SUCCESS)
}
