//! The `analyze` binary as a process: exit codes and messages on bad input, `--help`.

use crate::run_analyze;

/// Empty, non-MCAP and missing files: bad input, exit status 2, the file named on stderr, no
/// panic, nothing on stdout.
#[test]
fn bad_files_exit_non_zero_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let empty = dir.path().join("empty.mcap");
    let text = dir.path().join("text.mcap");
    std::fs::write(&empty, "").unwrap();
    std::fs::write(&text, "hello").unwrap();
    let missing = dir.path().join("missing.mcap");
    for path in [&empty, &text, &missing] {
        for cmd in ["compare", "metrics"] {
            let out = run_analyze(&[cmd, path.to_str().unwrap()]);
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{cmd} {}: {stderr}", path.display());
            assert!(stderr.contains(&path.display().to_string()), "{stderr}");
            assert!(
                !stderr.contains("panicked") && out.stdout.is_empty(),
                "{stderr}"
            );
        }
    }
    let out = run_analyze(&[
        "compare",
        dir.path().join("nothing-here").to_str().unwrap(),
        "-f",
        "xml",
    ]);
    assert_eq!(out.status.code(), Some(2)); // clap: bad command line
}

#[test]
fn help_shows_commands_and_examples() {
    let out = run_analyze(&["--help"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    for want in ["compare", "metrics", "Examples:", "analyze compare out/"] {
        assert!(text.contains(want), "{want:?} not in\n{text}");
    }
}
