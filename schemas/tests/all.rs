//! The integration tests of `schemas` as one test binary (its modules are the files beside this
//! one, each as it was a binary of its own), so that a cold `cargo test` compiles and links the
//! library's generic code once instead of once per file, and the tests of every file share the
//! test harness's threads. Files that must stay binaries of their own (a counting global
//! allocator) are `[[test]]` targets of their own in `Cargo.toml`; the root package's test
//! `e2e::test_binaries` fails if a file of `tests/` is in neither place, so no test file can
//! silently stop running.

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
#[path = "wire.rs"]
mod wire;
#[path = "writer.rs"]
mod writer;
#[path = "writer_options.rs"]
mod writer_options;

