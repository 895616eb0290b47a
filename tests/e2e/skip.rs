//! The one policy for tests that need a tool this machine may lack (Rerun's Python SDK,
//! Foxglove's npm packages, pyarrow, `script`, a tmpfs in a user namespace, `/dev/full`), so
//! that no test reports `ok` for a check it did not make without saying so:
//!
//! - under CI (`CI` set to anything but empty, `0` or `false`) a missing tool **fails** the
//!   test, naming what is missing and how to get it: CI (`.ci/run`) sets every tool up, and a
//!   machine like ours has them all;
//! - with `ELBOW_REQUIRE_TOOLS=1` the same outside CI (for a user who wants every check made);
//! - otherwise the test passes without checking, and says so where `cargo test` shows it: a
//!   line `SKIPPED <test>: <why>` written straight to the process's standard error (the test
//!   harness captures only `print!`/`eprint!`, so this line is shown without `--nocapture`,
//!   between the `test … ok` lines).
//!
//! A fresh clone has neither the Python venv nor `tests/foxglove/node_modules`: there
//! `cargo test` prints one `SKIPPED` line per viewer test, with the command that sets it up.

use std::io::Write;

/// Whether the tests run under CI (`CI` set, and not empty, `0` or `false`).
pub fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| means_ci(&v))
}

/// Whether a value of `CI` means CI: `CI=false` and `CI=0` (a shell's way of unsetting it) do not.
fn means_ci(v: &str) -> bool {
    !matches!(v.trim().to_ascii_lowercase().as_str(), "" | "0" | "false")
}

/// Whether a missing tool must fail the test: under CI or with `ELBOW_REQUIRE_TOOLS=1`.
pub fn required() -> bool {
    in_ci() || std::env::var("ELBOW_REQUIRE_TOOLS").is_ok_and(|v| v == "1")
}

/// The test `test` cannot make its check because of `why`: panics when the tool is
/// [`required`], else writes the visible `SKIPPED` line (not captured by the harness) and
/// returns, so the caller returns too.
pub fn skip(test: &str, why: &str) {
    if required() {
        let by = if in_ci() { "CI (`CI` is set)" } else { "ELBOW_REQUIRE_TOOLS=1" };
        panic!("{test}: {why}; {by} requires every check to run");
    }
    let _ = writeln!(std::io::stderr().lock(), "SKIPPED {test}: {why} (under CI this fails; see tests/e2e/skip.rs)");
}

#[test]
fn ci_values() {
    for v in ["true", "1", "yes", "TRUE"] {
        assert!(means_ci(v), "{v}");
    }
    for v in ["false", "0", "", "FALSE", " false "] {
        assert!(!means_ci(v), "{v:?}");
    }
}
