//! The recordings a command reads: files as given, directories as the `*.mcap` files directly in
//! them (sorted by name), and glob patterns (`'results/**/*.mcap'`) as the files they match.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

/// The files a command reads, and the `*.mcap` entries of its directories it left out.
#[derive(Debug, Default)]
pub struct Expanded {
    pub files: Vec<PathBuf>,
    /// `(entry, why)`: an entry named `*.mcap` that is not a regular file (a dangling or looping
    /// link, a directory, a FIFO, a device).
    pub skipped: Vec<(PathBuf, String)>,
}

impl Expanded {
    /// Prints one warning per skipped entry on standard error, naming it and why.
    pub fn warn_skipped(&self) {
        for (path, why) in &self.skipped {
            eprintln!("{}: warning: {}: skipped: {why}", program(), path.display());
        }
    }
}

/// The name of the running program (`analyze`, `sim`), for messages.
pub fn program() -> String {
    std::env::args_os()
        .next()
        .and_then(|a| Path::new(&a).file_stem().map(|s| s.to_string_lossy().into_owned()))
        .unwrap_or_else(|| "analyze".into())
}

/// Why a directory entry named `*.mcap` is not read, or `None` when it is a regular file (a
/// link to one included).
fn not_a_recording(path: &Path) -> Option<String> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() => None,
        Ok(m) if m.is_dir() => Some("a directory, not a recording".into()),
        Ok(_) => Some("not a regular file (a FIFO, socket or device)".into()),
        Err(e) => match std::fs::symlink_metadata(path) {
            Ok(l) if l.file_type().is_symlink() => Some(match std::fs::read_link(path) {
                Ok(target) => format!("a link to {} that cannot be followed ({e})", target.display()),
                Err(_) => format!("a link that cannot be followed ({e})"),
            }),
            _ => Some(format!("cannot be read ({e})")),
        },
    }
}

/// Files as given; a directory stands for every `*.mcap` file directly in it, sorted by name;
/// its `*.mcap` entries that are not regular files (dangling or looping links, directories,
/// FIFOs) are listed in [`Expanded::skipped`] with the reason.
pub fn expand_all(inputs: &[PathBuf]) -> Result<Expanded> {
    let mut out = Expanded::default();
    for input in inputs {
        if !input.is_dir() {
            out.files.push(input.clone());
            continue;
        }
        let mut found = Vec::new();
        let mut skipped = Vec::new();
        let entries = std::fs::read_dir(input).with_context(|| format!("listing {}", input.display()))?;
        for entry in entries {
            let path = entry.with_context(|| format!("listing {}", input.display()))?.path();
            let is_mcap = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("mcap"));
            if !is_mcap {
                continue;
            }
            match not_a_recording(&path) {
                None => found.push(path),
                Some(why) => skipped.push((path, why)),
            }
        }
        skipped.sort();
        if found.is_empty() {
            let also = skipped.iter().map(|(p, why)| format!("; {}: {why}", p.display())).collect::<String>();
            bail!("{}: no *.mcap files in this directory{also}", input.display());
        }
        found.sort();
        out.files.extend(found);
        out.skipped.extend(skipped);
    }
    Ok(out)
}

/// [`expand_all`], with a warning on standard error for each entry left out.
pub fn expand(inputs: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let e = expand_all(inputs)?;
    e.warn_skipped();
    Ok(e.files)
}

/// The line that says a recording is of a failed run, with its status and reason
/// (`FILE: the run failed at t = 0 s: REASON`), or `None` for a complete run or one without a
/// `result` record. The commands that read recordings print it on standard error and exit 1.
pub fn failed_run_note(file: &Path, result: Option<&schemas::RunResult>) -> Option<String> {
    let r = result.filter(|r| r.status == schemas::RunStatus::Failed)?;
    let at = r.error_time_s.map(|t| format!(" at t = {t} s")).unwrap_or_default();
    let why = r.error.as_deref().unwrap_or("no reason recorded");
    Some(format!("{}: the run {}{at}: {why}", file.display(), r.status_text()))
}

/// Runs `each` on every file in order; a file that fails is reported on standard error
/// (`program: error: …`, naming it) and the others go on. Returns the results of the files that
/// worked and the number that failed, or the first error when none worked (a bad input, exit
/// status 2, rather than an empty result).
pub fn each_file<T>(files: &[PathBuf], mut each: impl FnMut(&Path) -> Result<T>) -> Result<(Vec<(PathBuf, T)>, usize)> {
    let mut done = Vec::new();
    let mut errors = Vec::new();
    for f in files {
        match each(f) {
            Ok(t) => done.push((f.clone(), t)),
            Err(e) => errors.push(e),
        }
    }
    if done.is_empty() && !errors.is_empty() {
        let mut errors = errors.into_iter();
        let first = errors.next().expect("one error");
        for e in errors {
            eprintln!("{}: error: {}", program(), crate::exit::message(&e));
        }
        return Err(first);
    }
    for e in &errors {
        eprintln!("{}: error: {}", program(), crate::exit::message(e));
    }
    Ok((done, errors.len()))
}

/// [`expand`], and glob patterns (`*`, `?`, `[`) as the files they match; sorted by path, each
/// once. A pattern that matches nothing is an error.
pub fn expand_patterns(inputs: &[String]) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for input in inputs {
        if input.contains(['*', '?', '[']) && !Path::new(input).exists() {
            let mut found = Vec::new();
            for entry in glob::glob(input).with_context(|| format!("glob pattern {input:?}"))? {
                let path = entry.with_context(|| format!("listing the matches of {input:?}"))?;
                if path.is_file() {
                    found.push(path);
                }
            }
            if found.is_empty() {
                bail!("{input:?}: the pattern matches no files");
            }
            out.extend(found);
        } else {
            out.extend(expand(&[PathBuf::from(input)])?);
        }
    }
    out.sort();
    out.dedup();
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directories_expand_to_their_mcap_files_sorted() {
        let dir = tempfile::tempdir().unwrap();
        for name in ["b.mcap", "a.mcap", "notes.txt", "c.MCAP"] {
            std::fs::write(dir.path().join(name), "").unwrap();
        }
        std::fs::create_dir(dir.path().join("sub.mcap")).unwrap();
        let got = expand_all(&[PathBuf::from("x.mcap"), dir.path().to_path_buf()]).unwrap();
        let names: Vec<String> = got.files.iter().map(|p| p.file_name().unwrap().to_string_lossy().into_owned()).collect();
        assert_eq!(names, ["x.mcap", "a.mcap", "b.mcap", "c.MCAP"]);
        assert_eq!(got.skipped.len(), 1);
        assert!(got.skipped[0].0.ends_with("sub.mcap") && got.skipped[0].1.contains("a directory"), "{:?}", got.skipped);
        let empty = tempfile::tempdir().unwrap();
        let err = expand(&[empty.path().to_path_buf()]).unwrap_err().to_string();
        assert!(err.contains(&empty.path().display().to_string()) && err.contains("no *.mcap"), "{err}");
    }

    /// Dangling and looping `*.mcap` links are named with the reason, not dropped silently.
    #[cfg(unix)]
    #[test]
    fn links_that_cannot_be_followed_are_reported() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("good.mcap"), "").unwrap();
        std::os::unix::fs::symlink(dir.path().join("gone.mcap"), dir.path().join("dangling.mcap")).unwrap();
        std::os::unix::fs::symlink(dir.path().join("loop-b.mcap"), dir.path().join("loop-a.mcap")).unwrap();
        std::os::unix::fs::symlink(dir.path().join("loop-a.mcap"), dir.path().join("loop-b.mcap")).unwrap();
        let got = expand_all(&[dir.path().to_path_buf()]).unwrap();
        assert_eq!(got.files, [dir.path().join("good.mcap")]);
        let names: Vec<String> = got.skipped.iter().map(|(p, _)| p.file_name().unwrap().to_string_lossy().into_owned()).collect();
        assert_eq!(names, ["dangling.mcap", "loop-a.mcap", "loop-b.mcap"]);
        assert!(got.skipped.iter().all(|(_, why)| why.contains("a link to") && why.contains("cannot be followed")), "{:?}", got.skipped);
        // a directory of nothing but such links: the error names them
        std::fs::remove_file(dir.path().join("good.mcap")).unwrap();
        let err = expand_all(&[dir.path().to_path_buf()]).unwrap_err().to_string();
        assert!(err.contains("no *.mcap files") && err.contains("dangling.mcap"), "{err}");
    }

    #[test]
    fn patterns_match_files_once_and_an_empty_match_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("r")).unwrap();
        for name in ["r/a.mcap", "r/b.mcap", "c.mcap"] {
            std::fs::write(dir.path().join(name), "").unwrap();
        }
        let d = dir.path().display();
        let got = expand_patterns(&[format!("{d}/**/*.mcap"), format!("{d}/r/a.mcap")]).unwrap();
        assert_eq!(got.len(), 3, "{got:?}");
        assert!(expand_patterns(&[format!("{d}/*.nothing")]).unwrap_err().to_string().contains("matches no files"));
    }
}
