//! The Foxglove view of the recordings, checked with Foxglove's own libraries (issue 13,
//! acceptance): `sim` writes one layout per recording beside it and `analyze layout`
//! writes one for any recordings; `tests/foxglove/check.mjs` (node: ajv, @mcap/core, protobufjs,
//! @foxglove/schemas, pinned in its package-lock.json) validates each layout against the schema
//! derived from Foxglove's types, resolves every topic and plot path in the recordings, and
//! decodes every `/scene` and `/contact_markers` message (entity counts, mode colours, arrow
//! lengths = |F| × scale within 1e-9 m, spheres on the contact points and the hand).
//!
//! Needs node (on PATH) and `npm ci --prefix tests/foxglove` (or `ELBOW_NODE_DIR` = a directory
//! with check.mjs and its node_modules). Missing: the test fails when `CI` is set, else it says
//! why and passes without checking.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::{run_analyze, run_sim};

/// The checker's directory, or why it cannot run (node or node_modules missing).
fn checker() -> Result<PathBuf, String> {
    let dir = std::env::var_os("ELBOW_NODE_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/foxglove"));
    if !dir.join("node_modules").is_dir() {
        return Err(format!("no {}/node_modules: run `npm ci --prefix {}`", dir.display(), dir.display()));
    }
    match Command::new("node").arg("--version").output() {
        Ok(o) if o.status.success() => Ok(dir),
        _ => Err("`node` is not on PATH (node 20 or later)".into()),
    }
}

/// The checker's directory; `None` when it cannot run (the policy of `skip.rs`: a visible
/// `SKIPPED` line, a failure under CI).
fn checker_or_skip(test: &str) -> Option<PathBuf> {
    match checker() {
        Ok(d) => Some(d),
        Err(why) => {
            crate::skip::skip(test, &format!("the Foxglove check needs node and tests/foxglove/node_modules: {why}"));
            None
        }
    }
}

/// Runs check.mjs on `layout` and `recordings`: (exit code, stdout, stderr).
fn check(dir: &Path, layout: &Path, recordings: &[PathBuf]) -> (i32, String, String) {
    let out = Command::new("node").arg(dir.join("check.mjs")).arg(layout).args(recordings).output().expect("node starts");
    (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stdout).into_owned(), String::from_utf8_lossy(&out.stderr).into_owned())
}

fn mcaps(dir: &Path, prefix: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "mcap") && p.file_name().unwrap().to_string_lossy().starts_with(prefix))
        .collect();
    v.sort();
    v
}

/// The six default runs (0.2 s each): both scenes' layouts pass with their recordings; the
/// layout `analyze layout` writes for one recording passes; a layout with a misspelt plot path
/// or a topic the recording lacks fails, naming it.
#[test]
fn layouts_and_scene_entities_pass_foxglove_checks() {
    let Some(node_dir) = checker_or_skip("foxglove_layout::layouts_and_scene_entities_pass_foxglove_checks") else { return };
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path();
    let o = run_sim(&["--duration", "0.2", "-q", "-f", "csv", "-o", out.to_str().unwrap()]);
    assert!(o.status.success(), "sim: {}", String::from_utf8_lossy(&o.stderr));

    let paper = mcaps(out, "paper-").into_iter().filter(|p| !p.to_string_lossy().contains("unilateral")).collect::<Vec<_>>();
    let unilateral = mcaps(out, "paper-unilateral-");
    assert_eq!((paper.len(), unilateral.len()), (3, 3));
    for rec in paper.iter().chain(&unilateral) {
        let layout = rec.with_extension("foxglove-layout.json");
        let (code, stdout, stderr) = check(&node_dir, &layout, std::slice::from_ref(rec));
        assert_eq!(code, 0, "{}: {stderr}\n{stdout}", layout.display());
        let summary: serde_json::Value = serde_json::from_str(&stdout).unwrap();
        assert_eq!(summary["failures"], 0);
        // every contact of every sample had its arrow checked, or was separated and not drawn
        // (its deletions checked)
        for r in summary["recordings"].as_array().unwrap() {
            let samples = r["contact_marker_messages"].as_u64().unwrap();
            assert_eq!(samples, 201, "{r}");
            let separated = r["separated_checked"].as_u64().unwrap();
            assert_eq!(r["arrows_checked"].as_u64().unwrap() + separated, samples * r["contacts"].as_u64().unwrap(), "{r}");
            if rec.to_string_lossy().contains("whole-table") {
                // seven of its nine candidates never touch: each deleted once, at the first sample
                assert!(separated >= 7 * samples && r["deletions_checked"].as_u64().unwrap() >= 14, "{r}");
            }
        }
    }

    // analyze layout, for one recording
    let two = out.join("paper-two-elbow.mcap");
    let dir = out.join("layouts");
    let o = run_analyze(&[OsStr("layout"), two.as_os_str().into(), OsStr("-o"), dir.as_os_str().into()]);
    assert!(o.status.success(), "analyze layout: {}", String::from_utf8_lossy(&o.stderr));
    let written = dir.join("paper.foxglove-layout.json");
    let (code, stdout, stderr) = check(&node_dir, &written, std::slice::from_ref(&two));
    assert_eq!(code, 0, "{stderr}\n{stdout}");

    // the checker fails on a bad path and on a missing topic
    let text = std::fs::read_to_string(&written).unwrap();
    for (from, to, says) in [("/motors.current[3]", "/motors.curent[3]", "no field curent"), ("/energy.balance_residual", "/energies.balance_residual", "/energies")] {
        assert!(text.contains(from));
        let bad = out.join("bad.json");
        std::fs::write(&bad, text.replace(from, to)).unwrap();
        let (code, _, stderr) = check(&node_dir, &bad, std::slice::from_ref(&two));
        assert_eq!(code, 1, "{to}: {stderr}");
        assert!(stderr.contains(says), "{to}: {stderr}");
    }
}

#[allow(non_snake_case)]
fn OsStr(s: &str) -> std::ffi::OsString {
    s.into()
}

/// The value at message path `path` (`field`, `field.sub`, `field[k]`) of `msg`, if any.
fn at<'a>(msg: &'a schemas::Value, path: &str) -> Option<&'a schemas::Value> {
    let mut v = msg;
    for part in path.split('.') {
        let (name, index) = match part.split_once('[') {
            Some((n, k)) => (n, Some(k.trim_end_matches(']').parse::<usize>().ok()?)),
            None => (part, None),
        };
        v = v.get(name)?;
        if let Some(k) = index {
            v = v.as_list()?.get(k)?;
        }
    }
    Some(v)
}

/// Layouts with only the series the recording has (issue 27 item 4): `sim` writes one layout
/// per recording, and every plot path of each resolves to a value in every message of its
/// topic in that recording (no series left empty), while every contact of the run has its
/// normal force plotted. Measured here: the series per layout (the scene-wide layouts of
/// before had 80 for the unilateral scene, 28 of them empty for the two-elbow run).
#[test]
fn each_recording_gets_a_layout_with_only_its_series() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path();
    let o = run_sim(&["--duration", "0.05", "-q", "-f", "csv", "-o", out.to_str().unwrap()]);
    assert!(o.status.success(), "sim: {}", String::from_utf8_lossy(&o.stderr));
    let recs = mcaps(out, "paper-");
    assert_eq!(recs.len(), 6);
    let mut counts = Vec::new();
    for rec in &recs {
        let layout_path = rec.with_extension("foxglove-layout.json");
        let layout: serde_json::Value = serde_json::from_slice(&std::fs::read(&layout_path).unwrap()).unwrap_or_else(|e| panic!("{}: {e}", layout_path.display()));
        let r = schemas::read_recording(rec).unwrap();
        let contacts = r.run().unwrap().contacts.clone();
        let mut series = 0;
        let mut normal_forces = std::collections::BTreeSet::new();
        for c in layout["configById"].as_object().unwrap().values() {
            for p in c["paths"].as_array().into_iter().flatten() {
                let value = p["value"].as_str().unwrap();
                if !value.starts_with('/') {
                    continue; // a reference line
                }
                series += 1;
                let (topic, field) = value.split_once('.').unwrap();
                let msgs = r.messages(topic).unwrap_or_else(|| panic!("{}: {value}: no topic {topic} in the recording", layout_path.display()));
                assert!(!msgs.is_empty(), "{value}");
                for (k, (_, m)) in msgs.iter().enumerate() {
                    assert!(at(m, field).is_some(), "{}: {value} has no value in message #{k}", layout_path.display());
                }
                if field.starts_with("normal_force[") {
                    normal_forces.insert(field.to_string());
                }
                if let Some(label) = p["label"].as_str().filter(|_| field.contains("force[") || field.contains("velocity_") || field.starts_with("mode[")) {
                    assert!(contacts.iter().any(|c| label.starts_with(c.as_str())), "{value}: label {label:?} names no contact of {contacts:?}");
                }
            }
        }
        assert_eq!(normal_forces.len(), contacts.len(), "{}: {normal_forces:?} for {contacts:?}", layout_path.display());
        counts.push((rec.file_name().unwrap().to_string_lossy().into_owned(), series));
    }
    eprintln!("series per layout: {counts:?}");
    assert!(!out.join("paper.foxglove-layout.json").exists() && !out.join("paper-unilateral.foxglove-layout.json").exists());
}
