//! `sim export-scene`: the built-in paper scene and its URDF, as files to edit.

use std::path::PathBuf;

use anyhow::{bail, Result};
use cli::{exit, Verbosity};
use sim::scene::{PAPER_SCENE_JSON, PAPER_URDF};

/// Write the built-in paper scene (paper.json) and its URDF (paper_arm.urdf) into a directory,
/// to edit; existing files are not overwritten.
#[derive(Debug, Clone, clap::Args)]
#[command(after_help = "\
Output: DIR/paper.json and DIR/paper_arm.urdf.

Example:
  sim export-scene -o my-scene/ && sim check my-scene/paper.json")]
pub struct ExportSceneArgs {
    /// Directory to write into (created if missing).
    #[arg(short = 'o', long = "out", value_name = "DIR", default_value = "scene")]
    pub out: PathBuf,
}

pub fn run(a: &ExportSceneArgs, v: Verbosity) -> Result<u8> {
    cli::create_dir(&a.out)?;
    let files = [("paper.json", PAPER_SCENE_JSON), ("paper_arm.urdf", PAPER_URDF)];
    for (name, _) in files {
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
