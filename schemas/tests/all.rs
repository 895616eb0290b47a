//! The integration tests of `schemas` as one test binary (its modules are the files beside this
//! one, each as it was a binary of its own), so that a cold `cargo test` compiles and links the
//! library's generic code once instead of once per file, and the tests of every file share the
//! test harness's threads. Files that must stay binaries of their own (a counting global
//! allocator) are `[[test]]` targets of their own in `Cargo.toml`; the last test here fails if a
//! file of `tests/` is in neither place, so no test file can silently stop running.

#[cfg(feature = "synth")]
mod common;
#[path = "contacts.rs"]
mod contacts;
// the fast reader against the generic one, on files regrouped by `schemas::regroup_chunks`
// (`cargo test -p schemas --features synth`; the workspace's tests enable it)
#[cfg(feature = "synth")]
#[path = "fast_read.rs"]
mod fast_read;
#[path = "mirror.rs"]
mod mirror;
#[path = "properties.rs"]
mod properties;
#[path = "recover.rs"]
mod recover;
#[path = "robustness.rs"]
mod robustness;
#[path = "round_trip.rs"]
mod round_trip;
#[path = "writer.rs"]
mod writer;
#[path = "writer_options.rs"]
mod writer_options;

/// Every `.rs` file of `tests/` is a module here or a `[[test]]` target of its own.
#[test]
fn every_test_file_runs() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    let here = include_str!("all.rs");
    let manifest = include_str!("../Cargo.toml");
    let mut lost = Vec::new();
    for e in std::fs::read_dir(&dir).unwrap().map(Result::unwrap) {
        let name = e.file_name().to_string_lossy().to_string();
        if !name.ends_with(".rs") || name == "all.rs" {
            continue;
        }
        let as_module = format!("#[path = \"{name}\"]");
        let as_target = format!("path = \"tests/{name}\"");
        if !here.contains(&as_module) && !manifest.contains(&as_target) {
            lost.push(name);
        }
    }
    assert!(lost.is_empty(), "test files that no test binary compiles (add them to tests/all.rs): {lost:?}");
}
