//! `sim sweep`: the shards of a job array together give exactly the unsharded sweep (the same
//! files, byte for byte, and the same merged metrics), and bad input exits with 2 naming it.

use crate::run_sim;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use sim::sweep::{Shard, Sweep};


fn sweep_file() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("sim/scenes/sweeps/small-kp-integrator.json")
}

/// File name -> bytes of every recording in `dir`.
fn recordings(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "mcap"))
        .map(|p| (p.file_name().unwrap().to_string_lossy().into_owned(), std::fs::read(&p).unwrap()))
        .collect()
}

/// Metrics of every recording of `dirs`, by file name (the `file` field made relative).
fn merged_metrics(dirs: &[&Path]) -> BTreeMap<String, analyze::RunMetrics> {
    let mut out = BTreeMap::new();
    for d in dirs {
        for name in recordings(d).into_keys() {
            let mut m = analyze::read_run_metrics(&d.join(&name)).unwrap();
            m.file = name.clone();
            assert!(out.insert(name, m).is_none(), "a file in two shards");
        }
    }
    out
}

#[test]
fn shards_together_equal_the_unsharded_sweep() {
    let sweep = Sweep::load(&sweep_file()).unwrap();
    assert_eq!(sweep.grid_size, 4);
    let tmp = tempfile::tempdir().unwrap();
    let file = sweep_file();
    let file = file.to_str().unwrap();

    let a = tmp.path().join("A");
    let o = run_sim(&["sweep", file, "-o", a.to_str().unwrap(), "-j", "2", "--quiet", "--format", "csv"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = String::from_utf8(o.stdout).unwrap();
    assert_eq!(csv.lines().count(), 1 + 4 * 2, "{csv}");
    assert!(csv.lines().next().unwrap().starts_with("index,variant,run,controller.kp,integrator,status,"));
    let unsharded = recordings(&a);
    let expected: Vec<String> = (0..4)
        .flat_map(|k| ["elbow", "free"].map(|r| format!("small-grid-{k:03}-{r}.mcap")))
        .collect();
    assert_eq!(unsharded.keys().cloned().collect::<Vec<_>>(), { let mut e = expected.clone(); e.sort(); e });
    assert!(a.join("sweep-manifest.json").is_file());

    let mut shard_dirs = Vec::new();
    let mut union = BTreeMap::new();
    for i in 0..3 {
        let b = tmp.path().join(format!("B{i}"));
        let shard = format!("{i}/3");
        let o = run_sim(&["sweep", file, "--shard", &shard, "-o", b.to_str().unwrap(), "-j", "1", "--quiet", "--format", "json"]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let rows: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let files = recordings(&b);
        assert_eq!(rows.as_array().unwrap().len(), files.len());
        // the shard holds exactly the grid points k with k % 3 == i
        let sh: Shard = shard.parse().unwrap();
        for name in files.keys() {
            let k: usize = name["small-grid-".len()..][..3].parse().unwrap();
            assert!(sh.contains(k), "{name} in shard {shard}");
        }
        let manifest: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(b.join(format!("sweep-manifest.shard-{i}-of-3.json"))).unwrap()).unwrap();
        assert_eq!(manifest["shard"]["index"], i);
        assert_eq!(manifest["variants"].as_array().unwrap().len(), sh.indices(4).len());
        for (name, bytes) in files {
            assert!(union.insert(name.clone(), bytes).is_none(), "{name} written by two shards");
        }
        shard_dirs.push(b);
    }
    // the same set of files, each byte-identical to its unsharded twin
    assert_eq!(union.keys().collect::<Vec<_>>(), unsharded.keys().collect::<Vec<_>>());
    for (name, bytes) in &unsharded {
        assert!(union[name] == *bytes, "{name} differs between the sharded and the unsharded sweep");
    }
    // merged metrics (what `analyze metrics B0 B1 B2` reads) equal the unsharded ones
    let merged = merged_metrics(&shard_dirs.iter().map(PathBuf::as_path).collect::<Vec<_>>());
    let whole = merged_metrics(&[&a]);
    assert_eq!(merged, whole);
    // and the variants really differ: kp changes the tracking
    assert_ne!(whole["small-grid-000-free.mcap"].hand_error.as_ref().unwrap().norm.rms_m, whole["small-grid-002-free.mcap"].hand_error.as_ref().unwrap().norm.rms_m);
    assert_eq!(whole["small-grid-003-elbow.mcap"].scene, "small-grid-003");
}

#[test]
fn bad_input_exits_2_naming_it() {
    let file = sweep_file();
    let file = file.to_str().unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("x");
    let out = out.to_str().unwrap();
    for (args, needle) in [
        (vec!["sweep", file, "--shard", "3/3", "-o", out], "3/3"),
        (vec!["sweep", file, "--shard", "1/0", "-o", out], "1/0"),
        (vec!["sweep", "/nonexistent/sweep.json", "-o", out], "/nonexistent/sweep.json"),
    ] {
        let o = run_sim(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
    // a bad field path and a bad value, from a sweep file next to the small scene
    let small = Path::new(env!("CARGO_MANIFEST_DIR")).join("sim/scenes/small/small.json");
    for (axes, needles) in [
        (r#"[{"field": "controller.kq", "values": [1]}]"#, vec!["axes[0].field", "controller.kq", "unknown field"]),
        (r#"[{"field": "motor.resistance", "values": [1.1, -2]}]"#, vec!["bad-001", "motor.resistance = -2", "must be > 0"]),
    ] {
        let p = tmp.path().join("bad.json");
        std::fs::write(&p, format!(r#"{{"name": "bad", "scene": {:?}, "duration": 0.1, "axes": {axes}}}"#, small.to_str().unwrap())).unwrap();
        let o = run_sim(&["sweep", p.to_str().unwrap(), "-o", out, "--quiet"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        for n in needles {
            assert!(err.contains(n), "missing {n:?} in: {err}");
        }
        // nothing ran
        assert!(!Path::new(out).join("bad-000-elbow.mcap").exists());
    }
}

/// A variant that fails numerically (RK4 with a step beyond its stability limit) makes the sweep
/// exit with 1, while the other variants still complete: the manifest says which failed and
/// why, and the failed run's recording says so too.
#[test]
fn a_failed_run_exits_1_and_the_others_complete() {
    let tmp = tempfile::tempdir().unwrap();
    let small = Path::new(env!("CARGO_MANIFEST_DIR")).join("sim/scenes/small/small.json");
    let sweep = tmp.path().join("mixed.json");
    let axes = r#"[{"field": "integrator", "values": [{"method": "rk4", "step": 5e-3}, {"method": "dopri45", "rtol": 1e-8, "atol": 1e-10}]}]"#;
    std::fs::write(&sweep, format!(r#"{{"name": "mixed", "scene": {:?}, "runs": ["free"], "duration": 0.5, "axes": {axes}}}"#, small.to_str().unwrap())).unwrap();
    let out = tmp.path().join("out");
    let o = run_sim(&["sweep", sweep.to_str().unwrap(), "-o", out.to_str().unwrap(), "--quiet"]);
    assert_eq!(o.status.code(), Some(1), "{}", String::from_utf8_lossy(&o.stderr));
    let manifest: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("sweep-manifest.json")).unwrap()).unwrap();
    let status = |k: usize| manifest["variants"][k]["files"][0]["status"].as_str().unwrap().to_string();
    assert_eq!((status(0), status(1)), ("failed".to_string(), "complete".to_string()), "{manifest}");
    assert!(manifest["variants"][0]["files"][0]["error"].as_str().unwrap().contains("t = "), "{manifest}");
    let result = |k: usize| schemas::read_recording(&out.join(format!("mixed-{k:03}-free.mcap"))).unwrap().result().unwrap().unwrap().status;
    assert_eq!((result(0), result(1)), (schemas::RunStatus::Failed, schemas::RunStatus::Complete));
}

#[test]
fn the_example_sweeps_are_valid() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("sim/scenes/sweeps");
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        let s = Sweep::load(&p).unwrap_or_else(|e| panic!("{e}"));
        // the first and last grid points validate into scenes
        s.scene(&s.variant(0)).unwrap();
        s.scene(&s.variant(s.grid_size - 1)).unwrap();
    }
    let o = run_sim(&["sweep", dir.join("paper-gains.json").to_str().unwrap(), "--dry-run", "--shard", "1/4"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8(o.stdout).unwrap();
    assert!(text.contains("paper-gains-001: controller.kp = 250, controller.kd = 20"), "{text}");
    assert!(!text.contains("paper-gains-002"), "{text}");
}
