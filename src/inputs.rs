//! The recordings a command reads: files as given, directories as the `*.mcap` files directly in
//! them (sorted by name), and glob patterns (`'results/**/*.mcap'`) as the files they match.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

/// Files as given; a directory stands for every `*.mcap` file directly in it, sorted by name.
pub fn expand(inputs: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for input in inputs {
        if !input.is_dir() {
            out.push(input.clone());
            continue;
        }
        let mut found = Vec::new();
        let entries = std::fs::read_dir(input).with_context(|| format!("listing {}", input.display()))?;
        for entry in entries {
            let path = entry.with_context(|| format!("listing {}", input.display()))?.path();
            let is_mcap = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("mcap"));
            if is_mcap && path.is_file() {
                found.push(path);
            }
        }
        if found.is_empty() {
            bail!("{}: no *.mcap files in this directory", input.display());
        }
        found.sort();
        out.extend(found);
    }
    Ok(out)
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
        let got = expand(&[PathBuf::from("x.mcap"), dir.path().to_path_buf()]).unwrap();
        let names: Vec<String> = got.iter().map(|p| p.file_name().unwrap().to_string_lossy().into_owned()).collect();
        assert_eq!(names, ["x.mcap", "a.mcap", "b.mcap", "c.MCAP"]);
        let empty = tempfile::tempdir().unwrap();
        let err = expand(&[empty.path().to_path_buf()]).unwrap_err().to_string();
        assert!(err.contains(&empty.path().display().to_string()) && err.contains("no *.mcap"), "{err}");
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
