//! Puts the git commit of the build into `ELBOW_GIT_COMMIT` for `--version`
//! (`sim 0.1.0 (commit 1a2b3c4)`; `-dirty` when tracked files differ from it; `unknown` outside a
//! git checkout, e.g. a source tarball; `GIT_COMMIT=…` overrides). Recordings never contain it:
//! they store the package version only, so that they do not change with every commit.

use std::path::Path;
use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git").args(args).output().ok()?;
    out.status.success().then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

fn main() {
    println!("cargo:rerun-if-env-changed=GIT_COMMIT");
    let commit = std::env::var("GIT_COMMIT").ok().or_else(|| {
        let hash = git(&["rev-parse", "--short", "HEAD"])?;
        let dirty = git(&["status", "--porcelain", "--untracked-files=no"]).is_some_and(|s| !s.is_empty());
        Some(if dirty { format!("{hash}-dirty") } else { hash })
    });
    // refresh on a new commit or checkout (only paths that exist: a missing one re-runs always)
    if let (Some(git_dir), Some(common)) = (
        git(&["rev-parse", "--path-format=absolute", "--git-dir"]),
        git(&["rev-parse", "--path-format=absolute", "--git-common-dir"]),
    ) {
        let head_ref = git(&["symbolic-ref", "-q", "HEAD"]).map(|r| format!("{common}/{r}"));
        let watched = [Some(format!("{git_dir}/HEAD")), Some(format!("{git_dir}/index")), Some(format!("{common}/packed-refs")), head_ref];
        for p in watched.into_iter().flatten() {
            if Path::new(&p).exists() {
                println!("cargo:rerun-if-changed={p}");
            }
        }
    }
    println!("cargo:rustc-env=ELBOW_GIT_COMMIT={}", commit.unwrap_or_else(|| "unknown".into()));
}
