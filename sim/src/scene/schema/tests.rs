use std::path::{Path, PathBuf};

use super::*;
use crate::scene::builtin::BUILTINS;
use crate::scene::schema_key::SkipSchemaKey;
use serde::Deserialize;

/// The repository's root (the workspace).
fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

/// `path` (from the repository's root) holds `want`; with `ELBOW_BLESS=1` it is rewritten.
fn committed(path: &str, want: &str, how: &str) {
    let p = repo().join(path);
    if std::env::var_os("ELBOW_BLESS").is_some_and(|v| v == "1") {
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(&p, want).unwrap();
        return;
    }
    let have = std::fs::read_to_string(&p).unwrap_or_default();
    assert!(
        have == want,
        "{path} is not what `{how}` generates from the code: regenerate it with `ELBOW_BLESS=1 cargo test -p sim --lib scene::schema` (or `{how}`), review the diff and commit it"
    );
}

#[test]
fn the_committed_schemas_are_generated_from_the_code() {
    for kind in FileKind::ALL {
        committed(&format!("sim/scenes/{}", kind.schema_file()), &schema_text(kind), &format!("sim schema {} -o sim/scenes/{}", kind.name(), kind.schema_file()));
    }
}

#[test]
fn the_committed_reference_pages_are_generated_from_the_code() {
    for kind in FileKind::ALL {
        let page = format!("docs/src/reference/{}", kind.fields_page());
        committed(&page, &markdown(kind), &format!("sim schema {} -f markdown -o {page}", kind.name()));
    }
}

/// Every scene and sweep file the repository ships (by directory: the sweeps in
/// `sim/scenes/sweeps/`, the archive's scene, every other JSON under `sim/scenes/`).
fn shipped_files() -> Vec<(PathBuf, FileKind)> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|x| x == "json") && !p.to_string_lossy().ends_with(".schema.json") {
                out.push(p);
            }
        }
    }
    let mut files = Vec::new();
    walk(&repo().join("sim/scenes"), &mut files);
    files.push(repo().join("recordings/paper-archive.json"));
    files.sort();
    files.into_iter().map(|p| {
        let kind = if p.parent().is_some_and(|d| d.ends_with("sweeps")) {
            FileKind::Sweep
        } else if p.parent().is_some_and(|d| d.ends_with("studies")) {
            FileKind::Study
        } else {
            FileKind::Scene
        };
        (p, kind)
    }).collect()
}

#[test]
fn every_shipped_file_names_its_schema_first_and_parses() {
    let files = shipped_files();
    assert!(files.len() >= 29, "{files:?}");
    for (p, kind) in files {
        let text = std::fs::read_to_string(&p).unwrap();
        let doc: Value = serde_json::from_str(&text).unwrap();
        let (first, value) = doc.as_object().unwrap().iter().next().unwrap();
        assert_eq!(first, SCHEMA_KEY, "{}: `$schema` is not the first key", p.display());
        // relative to the file, it is the committed schema of its kind
        let target = p.parent().unwrap().join(value.as_str().unwrap());
        assert_eq!(
            std::fs::canonicalize(&target).ok(),
            std::fs::canonicalize(repo().join("sim/scenes").join(kind.schema_file())).ok(),
            "{}: `$schema` = {value} is not sim/scenes/{}",
            p.display(),
            kind.schema_file()
        );
        let de = &mut serde_json::Deserializer::from_str(&text);
        let read = match kind {
            FileKind::Scene => SceneSpec::deserialize(SkipSchemaKey(de)).map(drop),
            FileKind::Sweep => SweepSpec::deserialize(SkipSchemaKey(de)).map(drop),
            FileKind::Study => crate::study::StudySpec::deserialize(SkipSchemaKey(de)).map(drop),
        };
        read.unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    }
}

#[test]
fn the_builtin_scenes_name_their_schema_and_export_it_next_to_them() {
    for b in BUILTINS {
        let text = with_schema_path(b.json, "scene.schema.json");
        assert!(text.starts_with("{\n  \"$schema\": \"scene.schema.json\",\n  \"name\""), "{}", b.name);
        // only the value changed
        let strip = |t: &str| t.lines().filter(|l| !l.contains("\"$schema\"")).collect::<Vec<_>>().join("\n");
        assert_eq!(strip(&text), strip(b.json), "{}", b.name);
    }
    // a text without the key gets it first
    assert_eq!(with_schema_path("{\"name\": \"x\"}", "s.json"), "{\n  \"$schema\": \"s.json\",\"name\": \"x\"}");
}

#[test]
fn the_schema_is_draft_2020_12_and_closed_like_the_parser() {
    let s = schema(FileKind::Scene);
    assert_eq!(s["$schema"], "https://json-schema.org/draft/2020-12/schema");
    assert_eq!(s["additionalProperties"], false);
    assert_eq!(s["properties"]["$schema"]["type"], "string");
    // every object the parser reads with deny_unknown_fields is closed; `$schema` only on top
    let defs = s["$defs"].as_object().unwrap();
    for (name, d) in defs {
        if d.get("properties").is_some() {
            assert_eq!(d["additionalProperties"], false, "{name}");
            assert!(d["properties"].get("$schema").is_none(), "{name}");
        }
    }
    for (name, d) in defs.iter().filter(|(n, _)| ["IntegratorSpec", "KindedTarget", "PathSpec", "Stabilization"].contains(&n.as_str())) {
        for v in d["oneOf"].as_array().unwrap_or_else(|| panic!("{name}: {d}")) {
            assert_eq!(v["additionalProperties"], false, "{name}: {v}");
        }
    }
    // no numeric `format` is left (Ajv's strict mode and editors do not know them)
    assert!(!schema_text(FileKind::Scene).contains("\"format\""));
    assert_eq!(schema(FileKind::Sweep)["properties"]["axes"]["items"]["$ref"], "#/$defs/AxisSpec");
}

/// Every key a user writes has a description, and the descriptions of numbers say a unit or
/// that they have none.
#[test]
fn every_key_is_described() {
    for kind in FileKind::ALL {
        let s = schema(kind);
        let mut objects: Vec<(String, &Value)> = vec![("(top)".into(), &s)];
        for (n, d) in s["$defs"].as_object().unwrap() {
            objects.push((n.clone(), d));
            for v in d.get("oneOf").and_then(Value::as_array).into_iter().flatten() {
                objects.push((n.clone(), v));
            }
        }
        for (owner, o) in objects {
            for (k, p) in o.get("properties").and_then(Value::as_object).into_iter().flatten() {
                let d = p.get("description").and_then(Value::as_str).unwrap_or_default();
                let is_tag = p.get("const").is_some();
                assert!(is_tag || d.len() >= 8, "{}: `{k}` of {owner} has no description", kind.name());
            }
        }
    }
}

#[test]
fn the_markdown_page_has_a_section_per_object_and_a_row_per_key() {
    let md = markdown(FileKind::Scene);
    for heading in ["## The scene file", "## MotorSpec", "## IntegratorSpec", "### `\"method\": \"rodas5p\"`", "## PerJoint", "## InitialQ", "## ContactSpec"] {
        assert!(md.contains(&format!("\n{heading}\n")), "{heading} missing");
    }
    assert!(md.contains("| `torque_constant` | [PerJoint](#perjoint) | required | Torque constant K, N m/A (= V s/rad), per joint. |"), "{md}");
    assert!(md.contains("| `qd` | [PerJoint](#perjoint) | `0.0` |"));
    assert!(md.contains("| `\"from-target\"` |") || md.contains("`\"from-target\"`"));
    // every link points at a section
    for (i, _) in md.match_indices("](#") {
        let anchor: String = md[i + 3..].chars().take_while(|c| *c != ')').collect();
        assert!(md.lines().any(|l| l.starts_with("## ") && l[3..].to_lowercase() == anchor), "no section for #{anchor}");
    }
    let sweep = markdown(FileKind::Sweep);
    assert!(sweep.contains("| `axes` | array of [AxisSpec](#axisspec) | `[]` |"), "{sweep}");
}
