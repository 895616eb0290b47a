//! The scene and sweep files' JSON Schema as an editor uses it (issue 28): `sim schema` prints
//! the committed schemas and reference pages; every scene and sweep file of the repository
//! validates against its schema with Ajv (the JSON Schema ecosystem's validator, draft 2020-12,
//! strict mode: `tests/foxglove/check_scenes.mjs`); a misspelt key is refused by Ajv and by
//! `sim check` alike; and the schema and the parser agree on tricky values (a per-joint number
//! or array, `"from-target"`, the tagged integrator and target, `"$schema"` itself).
//!
//! Needs node (on PATH) and `npm ci --prefix tests/foxglove` (or `ELBOW_NODE_DIR` = a directory
//! with check_scenes.mjs and its node_modules). Missing: the Ajv tests fail when `CI` is set,
//! else they say so on stderr and pass without checking.

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::{json, Value};
use sim::scene::schema::{self, FileKind};

use crate::run_sim;

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn stdout(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The checker's directory; `None` when it cannot run (the policy of `skip.rs`: a visible
/// `SKIPPED` line, a failure under CI).
fn ajv_or_skip(test: &str) -> Option<PathBuf> {
    let dir = std::env::var_os("ELBOW_NODE_DIR").map(PathBuf::from).unwrap_or_else(|| repo().join("tests/foxglove"));
    let why = if !dir.join("node_modules").is_dir() {
        format!("no {}/node_modules: run `npm ci --prefix {}`", dir.display(), dir.display())
    } else if !Command::new("node").arg("--version").output().is_ok_and(|o| o.status.success()) {
        "`node` is not on PATH (node 20 or later)".to_string()
    } else {
        return Some(dir);
    };
    crate::skip::skip(test, &format!("the scene schema check (Ajv) needs node and tests/foxglove/node_modules: {why}"));
    None
}

/// Ajv's verdict on each file against `schema`: (valid, errors) per file, in order.
fn ajv(dir: &Path, schema: &Path, files: &[PathBuf]) -> Vec<(bool, Vec<String>)> {
    let o = Command::new("node").arg(dir.join("check_scenes.mjs")).arg(schema).args(files).output().expect("node starts");
    assert!(matches!(o.status.code(), Some(0 | 1)), "check_scenes.mjs: {}\n{}", stderr(&o), stdout(&o));
    let summary: Value = serde_json::from_slice(&o.stdout).unwrap_or_else(|e| panic!("{e}: {}", stdout(&o)));
    let results: Vec<(bool, Vec<String>)> = summary["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| (f["valid"].as_bool().unwrap(), f["errors"].as_array().unwrap().iter().map(|e| e.as_str().unwrap().to_string()).collect()))
        .collect();
    assert_eq!(results.len(), files.len());
    assert_eq!(o.status.code() == Some(0), results.iter().all(|r| r.0), "the exit status says whether all are valid");
    results
}

fn committed_schema(kind: FileKind) -> PathBuf {
    repo().join("sim/scenes").join(kind.schema_file())
}

#[test]
fn sim_schema_prints_the_committed_schemas_and_pages() {
    for kind in FileKind::ALL {
        let committed = std::fs::read_to_string(committed_schema(kind)).unwrap();
        let o = run_sim(&["schema", kind.name()]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(stdout(&o) == committed, "sim schema {} differs from sim/scenes/{}: `ELBOW_BLESS=1 cargo test -p sim --lib scene::schema` rewrites it", kind.name(), kind.schema_file());
        let page = std::fs::read_to_string(repo().join("docs/src/reference").join(kind.fields_page())).unwrap();
        let o = run_sim(&["schema", kind.name(), "-f", "markdown"]);
        assert!(o.status.success() && stdout(&o) == page, "sim schema {} -f markdown differs from docs/src/reference/{}", kind.name(), kind.fields_page());
    }
    // the default is the scene's; -o writes the same text into a file (its directory made)
    assert_eq!(stdout(&run_sim(&["schema"])), schema::schema_text(FileKind::Scene));
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("new/scene.schema.json");
    let o = run_sim(&["schema".as_ref(), "-o".as_ref(), out.as_os_str()]);
    assert!(o.status.success() && o.stdout.is_empty(), "{}", stderr(&o));
    assert!(stderr(&o).contains("wrote"), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(&out).unwrap(), schema::schema_text(FileKind::Scene));
}

/// The repository's JSON files: each scene or sweep file (it names one of the two schemas as
/// its `$schema`), and the others, which must be known not to be scenes.
fn repository_json() -> (Vec<(PathBuf, FileKind)>, Vec<PathBuf>) {
    let o = Command::new("git").args(["ls-files", "-z", "*.json"]).current_dir(repo()).output().expect("git starts");
    assert!(o.status.success(), "git ls-files: {}", stderr(&o));
    let (mut files, mut others) = (Vec::new(), Vec::new());
    for name in o.stdout.split(|b| *b == 0).filter(|n| !n.is_empty()) {
        let path = repo().join(String::from_utf8_lossy(name).as_ref());
        let doc: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let named = doc.get("$schema").and_then(Value::as_str).and_then(|s| Path::new(s).file_name()).map(|f| f.to_string_lossy().into_owned());
        match named.as_deref() {
            Some("scene.schema.json") => files.push((path, FileKind::Scene)),
            Some("sweep.schema.json") => files.push((path, FileKind::Sweep)),
            Some("study.schema.json") => files.push((path, FileKind::Study)),
            _ => others.push(path),
        }
    }
    (files, others)
}

#[test]
fn every_scene_and_sweep_file_validates_against_its_schema_with_ajv() {
    let (files, others) = repository_json();
    // a JSON file that names no schema is one of these (not a scene): a new scene without
    // `$schema` fails here
    for p in &others {
        let name = p.file_name().unwrap().to_string_lossy();
        // (sim/catalogue/: the drive catalogue, read by `scene/catalogue.rs` and checked there)
        let known = name == "MANIFEST.json"
            || name.ends_with(".foxglove-layout.json")
            || name.starts_with("package")
            || name.ends_with(".schema.json")
            || p.parent().is_some_and(|d| d.ends_with("sim/catalogue"));
        assert!(known, "{} names no `$schema`: a scene or sweep file should start with \"$schema\": \"<path to sim/scenes/scene.schema.json>\"", p.display());
    }
    let scenes: Vec<PathBuf> = files.iter().filter(|f| f.1 == FileKind::Scene).map(|f| f.0.clone()).collect();
    let sweeps: Vec<PathBuf> = files.iter().filter(|f| f.1 == FileKind::Sweep).map(|f| f.0.clone()).collect();
    assert!(scenes.len() >= 26 && sweeps.len() >= 3, "{scenes:?} {sweeps:?}");
    assert!(scenes.iter().any(|p| p.ends_with("recordings/paper-archive.json")));
    let Some(node) = ajv_or_skip("scene_schema::every_scene_and_sweep_file_validates_against_its_schema_with_ajv") else { return };
    let studies: Vec<PathBuf> = files.iter().filter(|f| f.1 == FileKind::Study).map(|f| f.0.clone()).collect();
    for (kind, list) in [(FileKind::Scene, &scenes), (FileKind::Sweep, &sweeps), (FileKind::Study, &studies)] {
        for (p, (valid, errors)) in list.iter().zip(ajv(&node, &committed_schema(kind), list)) {
            assert!(valid, "{}: not valid against sim/scenes/{}: {errors:?}", p.display(), kind.schema_file());
        }
    }
}

#[test]
fn a_misspelt_key_is_refused_by_ajv_and_by_sim_check() {
    // an exported scene names the schema written next to it
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let o = run_sim(&["export-scene".as_ref(), "-o".as_ref(), d.as_os_str(), "-q".as_ref()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(d.join("paper.json")).unwrap();
    assert!(text.starts_with("{\n  \"$schema\": \"scene.schema.json\",\n"), "{}", &text[..80]);
    assert_eq!(std::fs::read_to_string(d.join("scene.schema.json")).unwrap(), schema::schema_text(FileKind::Scene));
    // a second export into the same directory keeps the same schema
    let o = run_sim(&["export-scene".as_ref(), "hobby-arm".as_ref(), "-o".as_ref(), d.as_os_str(), "-q".as_ref()]);
    assert!(o.status.success(), "{}", stderr(&o));

    // misspelt keys, at the top and nested; `$schema` where it does not belong
    let paper: Value = serde_json::from_str(&text).unwrap();
    let cases: [(&str, fn(&mut Value), &str); 4] = [
        ("controler", |v| {
            let c = v.as_object_mut().unwrap().remove("controller").unwrap();
            v["controler"] = c;
        }, "field `controler`"),
        ("resistnce", |v| {
            let r = v["motor"].as_object_mut().unwrap().remove("resistance").unwrap();
            v["motor"]["resistnce"] = r;
        }, "field `motor.resistnce`"),
        ("stepp", |v| v["integrator"] = json!({"method": "rk4", "stepp": 1e-4}), "field `integrator.stepp`"),
        ("$schema", |v| v["motor"]["$schema"] = json!("scene.schema.json"), "field `motor.$schema`"),
    ];
    let mut files = vec![d.join("paper.json")];
    for (name, edit, _) in &cases {
        let mut v = paper.clone();
        edit(&mut v);
        let p = d.join(format!("bad-{}.json", name.trim_start_matches('$')));
        std::fs::write(&p, serde_json::to_string_pretty(&v).unwrap()).unwrap();
        files.push(p);
    }
    for (k, (name, _, field)) in cases.iter().enumerate() {
        let o = run_sim(&["check".as_ref(), files[k + 1].as_os_str()]);
        assert_eq!(o.status.code(), Some(2), "{name}: {}", stdout(&o));
        assert!(stderr(&o).contains(field) && stderr(&o).contains(&format!("unknown field `{name}`")), "{name}: {}", stderr(&o));
    }
    assert!(run_sim(&["check".as_ref(), files[0].as_os_str()]).status.success());
    let Some(node) = ajv_or_skip("scene_schema::a_misspelt_key_is_refused_by_ajv_and_by_sim_check") else { return };
    let verdicts = ajv(&node, &d.join("scene.schema.json"), &files);
    assert!(verdicts[0].0, "the exported scene: {:?}", verdicts[0].1);
    for (k, (name, _, _)) in cases.iter().enumerate() {
        let (valid, errors) = &verdicts[k + 1];
        assert!(!valid, "{name}: Ajv accepted it");
        assert!(errors.iter().any(|e| e.contains(&format!("\"additionalProperty\":\"{name}\""))), "{name}: {errors:?}");
    }
}

/// Tricky values, each accepted by both the schema (Ajv) and `sim` (the scene validated whole,
/// as `sim check` does) or refused by both.
#[test]
fn the_schema_and_the_parser_agree_on_tricky_values() {
    type Edit = fn(&mut Value);
    let cases: &[(&str, Edit, bool)] = &[
        ("kp: one number", |v| v["controller"]["kp"] = json!(500), true),
        ("kp: an integer array", |v| v["controller"]["kp"] = json!([500, 500, 500, 500, 500, 500, 500, 500, 500, 500]), true),
        ("kp: a string", |v| v["controller"]["kp"] = json!("500"), false),
        ("kp: a string in the array", |v| v["controller"]["kp"] = json!([500, "x", 500, 500, 500, 500, 500, 500, 500, 500]), false),
        ("kp: null", |v| v["controller"]["kp"] = Value::Null, false),
        ("kp: an object", |v| v["controller"]["kp"] = json!({"all": 500}), false),
        ("voltage_limit: null (absent)", |v| v["motor"]["voltage_limit"] = Value::Null, true),
        ("initial.qd: one number", |v| v["initial"]["qd"] = json!(0), true),
        ("initial.current: an array", |v| v["initial"]["current"] = json!([0, 0, 0, 0, 0, 0, 0, 0, 0, 0]), true),
        ("initial.q: from-target", |v| {
            v["initial"]["q"] = json!("from-target");
            v["target"] = json!({"kind": "joint-spline", "waypoints": [{"t": 0, "q": [0, 0, 0, 0, 0, 0, 0, 0, 0, 0]}]});
            free(v)
        }, true),
        ("initial.q: from_target", |v| v["initial"]["q"] = json!("from_target"), false),
        ("initial.q: true", |v| v["initial"]["q"] = json!(true), false),
        ("law: pd-gravity", |v| v["controller"]["law"] = json!("pd-gravity"), true),
        ("law: pd_gravity", |v| v["controller"]["law"] = json!("pd_gravity"), false),
        ("integrator: rk4 with its step", |v| v["integrator"] = json!({"method": "rk4", "step": 1e-3}), true),
        ("integrator: rk4 with rtol", |v| v["integrator"] = json!({"method": "rk4", "step": 1e-3, "rtol": 1e-6}), false),
        ("integrator: dopri45 with jacobian_reuse", |v| v["integrator"] = json!({"method": "dopri45", "rtol": 1e-6, "atol": 1e-8, "jacobian_reuse": 2}), false),
        ("integrator: rodas5p with jacobian_reuse", |v| v["integrator"] = json!({"method": "rodas5p", "rtol": 1e-6, "atol": 1e-8, "jacobian_reuse": 2}), true),
        ("integrator: max_steps 1.5", |v| v["integrator"] = json!({"method": "dopri45", "rtol": 1e-6, "atol": 1e-8, "max_steps": 1.5}), false),
        ("integrator: no method", |v| v["integrator"] = json!({"rtol": 1e-6, "atol": 1e-8}), false),
        ("integrator: euler", |v| v["integrator"]["method"] = json!("euler"), false),
        ("stabilization: baumgarte", |v| v["dynamics"]["stabilization"] = json!({"method": "baumgarte", "alpha": 20, "beta": 20}), true),
        ("stabilization: baumgarte with gamma", |v| v["dynamics"]["stabilization"] = json!({"method": "baumgarte", "alpha": 20, "beta": 20, "gamma": 1}), false),
        // (not here: {"method": "none", "alpha": 20}: serde accepts keys beside the tag of a
        // unit variant despite deny_unknown_fields, the schema refuses them)
        ("mass_matrix: walker-orin", |v| v["dynamics"]["mass_matrix"] = json!("walker-orin"), true),
        ("circle direction: cw", |v| v["target"]["circle"]["direction"] = json!("cw"), false),
        ("circle direction: clockwise", |v| v["target"]["circle"]["direction"] = json!("clockwise"), true),
        ("target: paper form with a kind", |v| v["target"]["kind"] = json!("cartesian"), false),
        ("target: joint spline", |v| v["target"] = json!({"kind": "joint-spline", "interpolation": "quintic", "waypoints": [{"t": 0, "q": [0, 0, 0, 0, 0, 0, 0, 0, 0, 0]}]}), true),
        ("target: joint spline, q a number", |v| v["target"] = json!({"kind": "joint-spline", "waypoints": [{"t": 0, "q": 0.0}]}), false),
        ("target: joint spline with a circle", |v| { let c = v["target"]["circle"].clone(); v["target"] = json!({"kind": "joint-spline", "circle": c, "waypoints": []}); }, false),
        ("contact model: unilateral", |v| { v["contacts"][0]["model"] = json!("unilateral"); v["contacts"][0]["friction"] = json!(0.5) }, true),
        ("contact model: rigid", |v| v["contacts"][0]["model"] = json!("rigid"), false),
        ("gravity: 2 numbers", |v| v["gravity"] = json!([0, -9.81]), false),
        ("$schema: a URL", |v| v["$schema"] = json!("https://example.org/scene.schema.json"), true),
        ("$schema: a number", |v| v["$schema"] = json!(3), false),
        ("$schema in initial", |v| v["initial"]["$schema"] = json!("s.json"), false),
    ];
    let dir = tempfile::tempdir().unwrap();
    let paper: Value = serde_json::from_str(sim::scene::PAPER_SCENE_JSON).unwrap();
    let read_urdf = |name: &str| if name == "paper_arm.urdf" { Ok(sim::scene::PAPER_URDF.to_string()) } else { Err(format!("no {name}")) };
    let mut files = Vec::new();
    for (k, (what, edit, want)) in cases.iter().enumerate() {
        let mut v = paper.clone();
        edit(&mut v);
        let text = serde_json::to_string_pretty(&v).unwrap();
        let parsed = sim::scene::Scene::from_json(&text, "case.json", read_urdf);
        assert_eq!(parsed.is_ok(), *want, "{what}: sim says {:?}", parsed.err().map(|e| e.to_string()));
        let p = dir.path().join(format!("case-{k}.json"));
        std::fs::write(&p, text).unwrap();
        files.push(p);
    }
    // and a sweep: `$schema` accepted; `axis` for `axes` refused
    let sweeps = [(json!({"$schema": "sweep.schema.json", "name": "s", "axes": [{"field": "controller.kp", "values": [1, [2, 3]]}]}), true), (json!({"name": "s", "axis": []}), false)];
    for (v, want) in &sweeps {
        let parsed = sim::sweep::Sweep::from_json_paper(&v.to_string(), "s.json");
        assert_eq!(parsed.is_ok(), *want, "{v}: sim says {:?}", parsed.err().map(|e| e.to_string()));
    }
    let Some(node) = ajv_or_skip("scene_schema::the_schema_and_the_parser_agree_on_tricky_values") else { return };
    for ((what, _, want), (valid, errors)) in cases.iter().zip(ajv(&node, &committed_schema(FileKind::Scene), &files)) {
        assert_eq!(valid, *want, "{what}: Ajv says {errors:?}");
    }
    let sweep_files: Vec<PathBuf> = sweeps.iter().enumerate().map(|(k, (v, _))| {
        let p = dir.path().join(format!("sweep-{k}.json"));
        std::fs::write(&p, v.to_string()).unwrap();
        p
    }).collect();
    for ((v, want), (valid, errors)) in sweeps.iter().zip(ajv(&node, &committed_schema(FileKind::Sweep), &sweep_files)) {
        assert_eq!(valid, *want, "{v}: Ajv says {errors:?}");
    }
}

/// The paper scene without contacts (a start that need not hold them).
fn free(v: &mut Value) {
    v["contacts"] = json!([]);
    v["runs"] = json!([{"name": "free", "contacts": []}]);
}
