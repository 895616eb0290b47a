//! Where output goes: tables to standard output (`--format table|json|csv`), files into a
//! directory (`-o DIR`), every file through `schemas::atomic` (a lock on the final name, a
//! temporary name of its own and a rename) so that neither a crash nor a second writer ever
//! leaves a half-written file under its final name. Text for people fits the terminal when
//! standard output is one ([`terminal_width`]).

use std::io::{IsTerminal, Write};
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

/// The width text for people is fitted to when nothing says otherwise (a terminal of unknown
/// size; `sim`'s brief table on a pipe or in a file), columns.
pub const TEXT_WIDTH: usize = 100;

/// The number of columns of the terminal standard output is, or `None` when it is no terminal
/// (a pipe, a file: text keeps its own width there, for tools and diffs). A terminal whose
/// size cannot be read counts as [`TEXT_WIDTH`] columns.
pub fn terminal_width() -> Option<usize> {
    if !std::io::stdout().is_terminal() {
        return None;
    }
    Some(console::Term::stdout().size_checked().map_or(TEXT_WIDTH, |(_, cols)| usize::from(cols)))
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
