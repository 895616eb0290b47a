//! Where output goes: tables to standard output (`--format table|json|csv`), files into a
//! directory (`-o DIR`), every file through `schemas::atomic` (a lock on the final name, a
//! temporary name of its own and a rename) so that neither a crash nor a second writer ever
//! leaves a half-written file under its final name.

use std::io::Write;
use std::path::Path;

use anyhow::{Context, Result};

/// Writes `text` to standard output; a closed pipe (`sim … | head`) ends the output quietly.
pub fn print_out(text: &str) -> Result<()> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        r => r.context("writing to standard output"),
    }
}

/// Writes `bytes` to `path` atomically and exclusively (`schemas::atomic`): `path` is either
/// absent, the old file, or the whole new one; a second writer of `path` at the same time is
/// refused. Errors name the path and the OS reason.
pub fn write_file(path: &Path, bytes: impl AsRef<[u8]>) -> Result<()> {
    schemas::atomic::write_file(path, bytes)?;
    Ok(())
}

/// Creates the output directory `dir` (and its parents).
pub fn create_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create the output directory {}", dir.display()))
}
