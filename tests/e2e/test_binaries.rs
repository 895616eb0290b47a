//! Every integration-test file of the workspace runs: `sim` and `schemas` compile their test
//! files as modules of one binary each (`tests/all.rs`, so a cold `cargo test` links the
//! library's generic code once), with `autotests = false`; a file added to `tests/` that is
//! neither a module of `all.rs` nor a `[[test]]` target of its own would silently never run.

use std::path::Path;

#[test]
fn every_test_file_of_a_crate_runs() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut lost = Vec::new();
    for krate in ["sim", "schemas"] {
        let dir = root.join(krate).join("tests");
        let all = std::fs::read_to_string(dir.join("all.rs")).unwrap();
        let manifest = std::fs::read_to_string(root.join(krate).join("Cargo.toml")).unwrap();
        assert!(manifest.contains("autotests = false") && manifest.contains("path = \"tests/all.rs\""), "{krate}/Cargo.toml");
        for e in std::fs::read_dir(&dir).unwrap().map(Result::unwrap) {
            let name = e.file_name().to_string_lossy().to_string();
            if !name.ends_with(".rs") || name == "all.rs" {
                continue;
            }
            let as_module = format!("#[path = \"{name}\"]");
            let as_target = format!("path = \"tests/{name}\"");
            if !all.contains(&as_module) && !manifest.contains(&as_target) {
                lost.push(format!("{krate}/tests/{name}"));
            }
        }
    }
    assert!(lost.is_empty(), "test files that no test binary compiles (add them to tests/all.rs of their crate): {lost:?}");
}
