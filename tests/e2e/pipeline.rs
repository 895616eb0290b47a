//! End to end, as a user runs it: the `sim` binary on a scene writes recordings, the `analyze`
//! binary reads them back; bad input gets a clear error and an exit status, never a panic.
//!

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin(name: &str) -> PathBuf {
    PathBuf::from(match name {
        "sim" => env!("CARGO_BIN_EXE_sim"),
        _ => env!("CARGO_BIN_EXE_analyze"),
    })
}

fn small_scene() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("sim/scenes/small/small.json")
}

fn run(cmd: &mut Command) -> Output {
    let out = cmd.output().expect("the binary starts");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "a panic: {stderr}");
    out
}

#[test]
fn sim_then_analyze_on_the_small_scene() {
    let dir = tempfile::tempdir().unwrap();
    let out = run(Command::new(bin("sim")).arg("run").arg(small_scene()).arg("-o").arg(dir.path()).args(["--format", "json", "--quiet"]));
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let table: serde_json::Value = serde_json::from_slice(&out.stdout).expect("sim prints JSON with --format json");
    assert!(table.is_object(), "{table}");
    for run in ["elbow", "free"] {
        assert!(dir.path().join(format!("small-{run}.mcap")).exists());
    }
    // analyze reads the directory and prints one CSV row per run
    let out = run(Command::new(bin("analyze")).arg("compare").arg(dir.path()).args(["--format", "csv"]));
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let csv = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = csv.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 3, "{csv}");
    let header: Vec<&str> = lines[0].split(',').collect();
    for row in &lines[1..] {
        assert_eq!(row.split(',').count(), header.len(), "{row}");
    }
    // the people's table names both runs
    let out = run(Command::new(bin("analyze")).arg("compare").arg(dir.path()));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("elbow") && text.contains("free"), "{text}");
}

#[test]
fn a_bad_scene_names_file_field_and_value() {
    let dir = tempfile::tempdir().unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(small_scene()).unwrap()).unwrap();
    v["motor"]["resistance"] = serde_json::json!(-2.5);
    let scene = dir.path().join("bad.json");
    std::fs::write(&scene, v.to_string()).unwrap();
    std::fs::copy(small_scene().with_file_name("small_arm.urdf"), dir.path().join("small_arm.urdf")).unwrap();
    let out = run(Command::new(bin("sim")).arg("run").arg(&scene).arg("-o").arg(dir.path().join("o")).arg("--quiet"));
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bad.json") && err.contains("motor.resistance") && err.contains("-2.5"), "{err}");
    assert!(!dir.path().join("o").join("small-elbow.mcap").exists());
}

#[test]
fn analyze_rejects_files_that_are_not_recordings() {
    let dir = tempfile::tempdir().unwrap();
    let junk = dir.path().join("junk.mcap");
    std::fs::write(&junk, b"not an mcap file at all").unwrap();
    let out = run(Command::new(bin("analyze")).arg("compare").arg(&junk));
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("junk.mcap"));
}

#[test]
fn precision_writes_its_table_and_plots() {
    let dir = tempfile::tempdir().unwrap();
    let out = run(Command::new(bin("sim"))
        .args(["precision"])
        .arg(small_scene())
        .args(["--run", "elbow", "--duration", "0.1", "--repeats", "1", "--quiet", "-o"])
        .arg(dir.path()));
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let table = String::from_utf8(out.stdout).unwrap();
    for series in ["dopri45", "rosenbrock", "imex", "rk4", "paper baseline", "rodas5p (exact J)", "rodas4"] {
        assert!(table.contains(series), "{series} missing from\n{table}");
    }
    // the recommendation for the default --accuracy (1e-6 m), which the tight runs reach
    assert!(table.contains("Recommended for max hand error <= 1e-6 m: "), "{table}");
    let rows: serde_json::Value = serde_json::from_slice(&std::fs::read(dir.path().join("precision.json")).unwrap()).unwrap();
    let rows = rows.as_array().unwrap();
    assert!(rows.len() >= 20);
    // the tightest Dormand-Prince rung is within 1e-9 m of the reference
    let tight = rows.iter().find(|r| r["series"] == "dopri45" && r["setting"] == "rtol 1e-10").unwrap();
    assert!(tight["max_hand_error_m"].as_f64().unwrap() < 1e-9, "{tight}");
    // the plots are real images: PNG signature and size, SVG with the axes' labels
    let png = std::fs::read(dir.path().join("work-precision.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    assert!(png.len() > 10_000, "{} bytes", png.len());
    let svg = std::fs::read_to_string(dir.path().join("work-precision.svg")).unwrap();
    assert!(svg.contains("max hand error") && svg.contains("wall time"));
}

fn same_bytes(a: &Path, b: &Path) -> bool {
    std::fs::read(a).unwrap() == std::fs::read(b).unwrap()
}

/// The main command twice, on one thread and on every core: byte-identical recordings.
#[test]
fn the_main_command_is_deterministic_whatever_the_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    for (out, jobs) in [(&a, "1"), (&b, "3")] {
        let o = run(Command::new(bin("sim")).arg("-o").arg(out).args(["-j", jobs, "--quiet", "--format", "csv"]));
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    for r in ["two-elbow", "one-elbow", "no-elbow"] {
        let f = format!("paper-{r}.mcap");
        assert!(same_bytes(&a.join(&f), &b.join(&f)), "{f} differs between -j 1 and -j 3");
    }
}

/// Replaying each archived recording from its own metadata reproduces it exactly.
#[test]
fn replaying_the_archive_reproduces_it_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let archive = Path::new(env!("CARGO_MANIFEST_DIR")).join("recordings");
    for r in ["two-elbow", "one-elbow", "no-elbow"] {
        let f = archive.join(format!("paper-archive-{r}.mcap"));
        let o = run(Command::new(bin("sim")).arg("replay").arg(&f).arg("-o").arg(dir.path()).arg("--quiet"));
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(same_bytes(&f, &dir.path().join(f.file_name().unwrap())), "{r}: the replay differs from the archive");
    }
}

/// A `sim` killed mid-run leaves no file at its destination (only its hidden partial file).
#[test]
fn a_killed_run_leaves_no_file_at_the_destination() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("sim/scenes/hard/long-60s-plain.json");
    let mut child = Command::new(bin("sim"))
        .arg("run")
        .arg(&scene)
        .arg("-o")
        .arg(dir.path())
        .arg("--quiet")
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    // wait until it has started writing (the hidden partial file appears), then kill it
    let t0 = std::time::Instant::now();
    while std::fs::read_dir(dir.path()).unwrap().count() == 0 && t0.elapsed().as_secs() < 30 {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    std::thread::sleep(std::time::Duration::from_millis(300));
    child.kill().unwrap();
    child.wait().unwrap();
    let names: Vec<String> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert!(!names.is_empty(), "the run never started writing");
    assert!(!names.iter().any(|n| n.ends_with(".mcap")), "a finished-looking file after a kill: {names:?}");
}

/// A run that fails numerically exits with status 1 and leaves a valid recording that says
/// when and why.
#[test]
fn a_numerical_failure_exits_1_with_a_valid_recording() {
    let dir = tempfile::tempdir().unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(small_scene()).unwrap()).unwrap();
    v["integrator"] = serde_json::json!({"method": "rk4", "step": 5e-3});
    v["runs"] = serde_json::json!([{"name": "free", "contacts": []}]);
    let scene = dir.path().join("unstable.json");
    std::fs::write(&scene, v.to_string()).unwrap();
    std::fs::copy(small_scene().with_file_name("small_arm.urdf"), dir.path().join("small_arm.urdf")).unwrap();
    let out = run(Command::new(bin("sim")).arg("run").arg(&scene).arg("-o").arg(dir.path()).arg("--quiet"));
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stderr));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("t = "), "{err}");
    let rec = schemas::read_recording(&dir.path().join("small-free.mcap")).unwrap();
    assert_eq!(rec.result().unwrap().unwrap().status, schemas::RunStatus::Failed);
}
