//! Where output goes: tables to standard output (`--format table|json|csv`), files into a
//! directory (`-o DIR`), every file through a temporary name and a rename so that a crash never
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

/// Writes `bytes` to `path` through a hidden temporary sibling (`.NAME.partial`) renamed into
/// place, so `path` is either absent, the old file, or the whole new one.
pub fn write_file(path: &Path, bytes: impl AsRef<[u8]>) -> Result<()> {
    let name = path.file_name().with_context(|| format!("{}: not a file path", path.display()))?;
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(name);
    tmp_name.push(".partial");
    let tmp = path.with_file_name(tmp_name);
    let written = std::fs::File::create(&tmp)
        .and_then(|mut f| f.write_all(bytes.as_ref()).and_then(|()| f.sync_all()))
        .and_then(|()| std::fs::rename(&tmp, path));
    if let Err(e) = written {
        let _ = std::fs::remove_file(&tmp);
        return Err(e).with_context(|| format!("writing {}", path.display()));
    }
    Ok(())
}

/// Creates the output directory `dir` (and its parents).
pub fn create_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create the output directory {}", dir.display()))
}
