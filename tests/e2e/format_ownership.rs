//! `schemas` owns the recording format: no code outside it spells a metadata record, a metadata
//! key or a message-field path. Checked on the source of the other crates and the binaries:
//!
//! - the names the format uses are collected from a real recording (every metadata record name
//!   and key, every field name of every message, recursively) — those with an underscore or a
//!   dot, which cannot be ordinary words of the code (`joint_names`, `integrator.rtol`,
//!   `error_norm`, `child_frame_id`, …), but for the scene's own keys (`output_rate`);
//! - no non-test source file outside `schemas` has one of them as a string literal;
//! - the generic accessors (`Value`, `metadata_records`, `messages`, `write_metadata_raw`) are
//!   used only by the generic exporter, which names no field.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use schemas::Value;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn names_of(v: &Value, out: &mut BTreeSet<String>) {
    match v {
        Value::Struct(fields) => {
            for (k, x) in fields {
                out.insert(k.clone());
                names_of(x, out);
            }
        }
        Value::List(items) => items.iter().for_each(|x| names_of(x, out)),
        _ => {}
    }
}

/// Every record name, key and message field of an archived recording.
fn format_names() -> BTreeSet<String> {
    let rec = schemas::read_recording(&root().join("recordings/paper-archive-two-elbow.mcap")).unwrap();
    let mut names = BTreeSet::new();
    for (record, keys) in rec.metadata_records() {
        names.insert(record.clone());
        names.extend(keys.keys().cloned());
    }
    for list in rec.message_map().values() {
        if let Some((_, first)) = list.first() {
            names_of(first, &mut names);
        }
    }
    names
}

/// `.rs` files below `dir`, leaving out test-only files (`tests.rs`, `tests/`, `testutil.rs`).
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        if p.is_dir() {
            if name != "tests" {
                sources(&p, out);
            }
        } else if name.ends_with(".rs") && name != "tests.rs" && name != "testutil.rs" {
            out.push(p);
        }
    }
}

/// The code of a file without its `#[cfg(test)]` module at the end (the crate's convention).
fn code(p: &Path) -> String {
    let text = std::fs::read_to_string(p).unwrap();
    match text.find("#[cfg(test)]\nmod tests") {
        Some(i) => text[..i].to_string(),
        None => text,
    }
}

/// The keys of the scene JSON (the scene owns them; a recording embeds the scene, and a few run
/// keys are named after them, e.g. `output_rate`).
fn scene_keys() -> BTreeSet<String> {
    fn keys(v: &serde_json::Value, out: &mut BTreeSet<String>) {
        match v {
            serde_json::Value::Object(m) => m.iter().for_each(|(k, x)| {
                out.insert(k.clone());
                keys(x, out)
            }),
            serde_json::Value::Array(a) => a.iter().for_each(|x| keys(x, out)),
            _ => {}
        }
    }
    let mut out = BTreeSet::new();
    keys(&serde_json::from_str(sim::scene::PAPER_SCENE_JSON).unwrap(), &mut out);
    out
}

#[test]
fn no_code_outside_schemas_spells_the_format() {
    let scene = scene_keys();
    let names: Vec<String> =
        format_names().into_iter().filter(|n| (n.contains('_') || n.contains('.')) && !scene.contains(n)).collect();
    assert!(names.iter().any(|n| n == "joint_names") && names.iter().any(|n| n == "integrator.rtol") && names.iter().any(|n| n == "error_norm"), "{names:?}");
    let mut files = Vec::new();
    for dir in ["sim/src", "analyze/src", "src"] {
        sources(&root().join(dir), &mut files);
    }
    assert!(files.len() > 40, "{} files", files.len());
    let generic = ["analyze/src/frames.rs", "analyze/src/frames/flatten.rs", "analyze/src/frames/streamed.rs"];
    let mut found = Vec::new();
    for f in &files {
        let text = code(f);
        let rel = f.strip_prefix(root()).unwrap().to_string_lossy().into_owned();
        for n in &names {
            if text.contains(&format!("\"{n}\"")) {
                found.push(format!("{rel}: \"{n}\""));
            }
        }
        let generic_api = ["schemas::Value", "metadata_records(", ".messages(", "message_map(", "write_metadata_raw("];
        if !generic.contains(&rel.as_str()) {
            for api in generic_api {
                if text.contains(api) {
                    found.push(format!("{rel}: uses {api}"));
                }
            }
        }
    }
    assert!(found.is_empty(), "the recording format spelled outside `schemas`:\n{}", found.join("\n"));
}
