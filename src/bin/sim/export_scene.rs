//! `sim export-scene`: a built-in scene (the paper's by default) and its URDF, as files to edit.

use std::path::PathBuf;

use anyhow::{bail, Result};
use cli::{exit, Verbosity};
use sim::scene::builtin;

/// Write a built-in scene (`sim list`; default: the paper's, paper.json and paper_arm.urdf) and
/// its URDF into a directory, to edit; existing files are not overwritten.
#[derive(Debug, Clone, clap::Args)]
#[command(after_help = "\
Output: DIR/<scene>.json and the URDF it names (paper.json and paper_arm.urdf by default).

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
    let files: Vec<(&str, &str)> = std::iter::once((b.file, b.json)).chain(b.files.iter().copied()).collect();
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
