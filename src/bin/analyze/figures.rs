//! `analyze figures`: the paper's figures and more, from recordings.

use std::path::PathBuf;

use anyhow::{Context, Result};
use cli::{exit, Verbosity};

/// The paper's figures (hand paths Fig. 1-3, total and per-link work and electric energy
/// Fig. 4-25) and more (currents, voltages, elbow normal forces, hand error), every run in
/// each, as SVG and PNG, with index.md and index.html listing them in order.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
Output: DIR/<figure>.svg and .png (1000x700 px), DIR/index.html and DIR/index.md.

Examples:
  analyze figures out/                      -> out/figures/
  analyze figures out/ -o paper-figures     then open paper-figures/index.html
  analyze figures out/paper-no-elbow.mcap out/paper-two-elbow.mcap -o two-runs")]
pub struct FiguresArgs {
    /// Recordings (.mcap), or directories: every *.mcap directly in them, sorted by name.
    #[arg(required = true, value_name = "FILES_OR_DIRS")]
    pub inputs: Vec<PathBuf>,
    /// Directory for the figures and index pages (created if needed).
    #[arg(short = 'o', long = "out", value_name = "DIR", default_value = "out/figures")]
    pub out: PathBuf,
}

pub fn run(a: &FiguresArgs, v: Verbosity) -> Result<u8> {
    let expanded = cli::inputs::expand_all(&a.inputs)?;
    expanded.warn_skipped();
    // each recording on its own: one that cannot be read is reported and left out (exit 1)
    let (read, failed) =
        cli::inputs::each_file(&expanded.files, |p| analyze::figures::read_run(p).with_context(|| format!("reading {}", p.display())))?;
    let (paths, runs): (Vec<_>, Vec<_>) = read.into_iter().unzip();
    let mut failed = failed;
    for (p, r) in paths.iter().zip(&runs) {
        if let Some(note) = cli::inputs::failed_run_note(p, r.result.as_ref()) {
            eprintln!("analyze: {note} (drawn with what it recorded)");
            failed += 1;
        }
    }
    let figures = analyze::figures::write_all(&runs, &paths, &a.out)?;
    if !v.quiet {
        eprintln!(
            "analyze: {} figures (SVG and PNG) of {} runs in {}; open {}",
            figures.len(),
            runs.len(),
            a.out.display(),
            a.out.join("index.html").display()
        );
    }
    Ok(if failed > 0 || !expanded.skipped.is_empty() { exit::FAILED } else { exit::SUCCESS })
}
