//! `sim replay`: re-run a recording from its own metadata (embedded scene, URDF and run).

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use cli::{Jobs, TableFormat, Verbosity};

/// Re-run an experiment from a recording alone (its embedded scene, URDF and settings); with
/// the same version of the tool the new recording is byte-identical to the original.
#[derive(Debug, Clone, clap::Args)]
#[command(after_help = "\
Output: DIR/<the recording's file name>, and on stdout the table of the replayed run (as `sim
run` prints it).

Examples:
  sim replay out/paper-two-elbow.mcap                -> out/replay/paper-two-elbow.mcap
  sim replay recordings/paper-archive-no-elbow.mcap -o /tmp/r && cmp recordings/paper-archive-no-elbow.mcap /tmp/r/paper-archive-no-elbow.mcap")]
pub struct ReplayArgs {
    /// A recording written by `sim` (format version 1 or later).
    #[arg(value_name = "RECORDING")]
    pub recording: PathBuf,
    /// Directory for the new recording (same file name as the original).
    #[arg(short = 'o', long = "out", value_name = "DIR", default_value = "out/replay")]
    pub out: PathBuf,
    #[command(flatten)]
    pub format: TableFormat,
    #[command(flatten)]
    pub wall_time: crate::run::WallTime,
}

pub fn run(a: &ReplayArgs, v: Verbosity) -> Result<u8> {
    let (scene, run_name) = sim::replay::scene_from_recording(&a.recording)?;
    let run = scene
        .run(&run_name)
        .cloned()
        .with_context(|| format!("{}: the embedded scene has no run `{run_name}`", a.recording.display()))?;
    let name = a.recording.file_name().context("the recording path has no file name")?;
    cli::create_dir(&a.out)?;
    let path = a.out.join(name);
    if path.canonicalize().ok() == a.recording.canonicalize().ok() {
        bail!("{}: replaying into the same file would overwrite the original; choose another -o", path.display());
    }
    let done = crate::run::run_all(&scene, &[run], |_| path.clone(), &Jobs { jobs: Some(1) }, a.wall_time.budget(), v);
    crate::run::finish(&done, a.format, None, v)
}
