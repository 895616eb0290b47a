//! The acceptance test of `analyze view`: a paper recording and a unilateral one converted by
//! the binary, then read by Rerun itself (the 0.41 Python SDK's reader, `rerun_facts.py`): the
//! blueprint's views exist (3D arm and hand close-up, plots of currents, voltages, contact
//! forces, energies, residual), the typed scalar entities exist under the names of the joints
//! and contacts of the recording, with one row per recorded sample, on a duration timeline.
//!
//! The Python is `ELBOW_RERUN_PYTHON` (default `~/.cache/elbow-sim/venv-check/bin/python`, the
//! venv of `.ci/run`); without it the test fails under CI and is skipped otherwise with a
//! visible `SKIPPED` line (`skip.rs`).

use std::path::{Path, PathBuf};
use std::process::Command;

use serde::Deserialize;

use crate::{run_analyze, run_sim};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Store {
    kind: String,
    application_id: String,
    recording_id: String,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ViewFact {
    class: String,
    name: String,
    origin: String,
    query: Vec<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Container {
    kind: u8,
    contents: Vec<String>,
}

/// What `rerun_facts.py` prints.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Facts {
    stores: Vec<Store>,
    views: Vec<ViewFact>,
    containers: Vec<Container>,
    entities: std::collections::BTreeMap<String, Vec<String>>,
    timelines: std::collections::BTreeMap<String, String>,
    series_names: std::collections::BTreeMap<String, Vec<String>>,
    rows: std::collections::BTreeMap<String, usize>,
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The Python with rerun-sdk 0.41, or `None` when it is missing (the policy of `skip.rs`).
fn rerun_python(test: &str) -> Option<PathBuf> {
    let p = std::env::var_os("ELBOW_RERUN_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(std::env::var_os("HOME").unwrap_or_default()).join(".cache/elbow-sim/venv-check/bin/python"));
    let works = Command::new(&p).args(["-c", "import rerun.chunk"]).output().is_ok_and(|o| o.status.success());
    if works {
        return Some(p);
    }
    crate::skip::skip(test, &format!("{} has no rerun-sdk 0.41 (set ELBOW_RERUN_PYTHON, or make the venv as .ci/run does)", p.display()));
    None
}

fn facts(python: &Path, rrd: &Path) -> Facts {
    let o = Command::new(python).arg(root().join("tests/e2e/rerun_facts.py")).arg(rrd).output().expect("python starts");
    assert!(o.status.success(), "rerun_facts.py {}: {}", rrd.display(), String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&o.stdout)))
}

fn view(f: &Facts, class: &str, origin: &str) -> bool {
    f.views.iter().any(|v| v.class == class && v.origin == origin)
}

/// Converts `mcap` to `rrd` with the binary and checks what Rerun reads against the recording.
fn check(python: &Path, mcap: &Path, rrd: &Path) -> Facts {
    let o = run_analyze(&[Path::new("view"), mcap, Path::new("-o"), rrd]);
    assert!(o.status.success(), "analyze view: {}", String::from_utf8_lossy(&o.stderr));
    let f = facts(python, rrd);
    let rec = schemas::read_recording(mcap).unwrap();
    let run = rec.run().unwrap();
    let samples = rec.read::<schemas::MotorState>().unwrap().len();
    let stem = rrd.file_stem().unwrap().to_string_lossy().into_owned();

    // one recording and one blueprint, both of the file stem's application id
    assert_eq!(f.stores.len(), 2, "{:?}", f.stores);
    assert!(f.stores.iter().all(|s| s.application_id == stem), "{:?}", f.stores);
    assert!(f.stores.iter().any(|s| s.kind == "blueprint") && f.stores.iter().any(|s| s.kind == "recording"));
    assert!(f.stores.iter().all(|s| !s.recording_id.is_empty()));
    // the simulated time as a duration, not a 1970 timestamp
    assert_eq!(f.timelines.get("sim_time").map(String::as_str), Some("duration[ns]"), "{:?}", f.timelines);

    // the blueprint: the arm and the hand in 3D, the plots of the experiment, laid out
    assert_eq!(f.views.iter().filter(|v| v.class == "3D" && v.origin == "/world").count(), 2, "{:?}", f.views);
    assert!(f.views.iter().any(|v| v.class == "3D" && v.name.starts_with("arm (")), "{:?}", f.views);
    assert!(f.views.iter().any(|v| v.class == "3D" && v.name.contains("hand")));
    for origin in ["/current_A", "/voltage_V", "/normal_force_N", "/electric_energy_J", "/link_work_J", "/energy_J", "/energy_residual_J"] {
        assert!(view(&f, "TimeSeries", origin), "no time series of {origin}: {:?}", f.views);
    }
    assert!(f.views.iter().all(|v| !v.query.is_empty()));
    assert!(!f.containers.is_empty() && f.containers.iter().all(|c| (1..=4).contains(&c.kind) && !c.contents.is_empty()));

    // typed scalars named by joint and contact, one row per sample, their series named
    for j in &run.joint_names {
        for (signal, unit) in [("current_A", "A"), ("voltage_V", "V"), ("electric_energy_J", "J"), ("link_work_J", "J")] {
            let e = format!("/{signal}/{j}");
            assert_eq!(f.entities.get(&e).map(|c| c.contains(&"Scalars:scalars".to_string())), Some(true), "{e}: {:?}", f.entities.get(&e));
            assert_eq!(f.rows.get(&e), Some(&samples), "{e}");
            let name = &f.series_names[&e];
            assert!(name.len() == 1 && name[0].contains(j.as_str()) && name[0].contains(&format!("[{unit}]")), "{e}: {name:?}");
        }
    }
    for c in &run.contacts {
        let e = format!("/normal_force_N/{c}");
        assert!(f.rows.get(&e).is_some_and(|&n| n == samples), "{e}: {:?}", f.rows.get(&e));
        assert!(f.series_names[&e][0].contains(c.as_str()));
        // the contact in 3D: a marker and a force arrow
        assert!(f.entities.contains_key(&format!("/world/contacts/{c}")), "{c}");
        assert!(f.entities[&format!("/world/contacts/{c}/force")].contains(&"Arrows3D:vectors".to_string()));
    }
    for e in ["/energy_J/electric-in", "/energy_J/link-work", "/energy_residual_J"] {
        assert_eq!(f.rows.get(e), Some(&samples), "{e}");
    }
    // the scene in 3D: the arm from the URDF, the table, the target path, the hand points
    assert!(f.entities.keys().any(|e| e.starts_with("/world/") && f.entities[e].iter().any(|c| c.starts_with("Cylinders3D:") || c.starts_with("Boxes3D:"))));
    assert!(f.entities.get("/world/table0").is_some_and(|c| c.contains(&"Boxes3D:half_sizes".to_string())));
    assert!(f.entities.get("/world/target_path").is_some_and(|c| c.contains(&"LineStrips3D:strips".to_string())));
    for e in ["/world/hand/actual", "/world/hand/desired"] {
        assert!(f.entities.get(e).is_some_and(|c| c.contains(&"Points3D:positions".to_string()) && c.contains(&"Points3D:colors".to_string())), "{e}");
    }
    f
}

#[test]
fn rerun_reads_the_blueprint_and_named_scalars_of_a_paper_and_a_unilateral_recording() {
    let Some(python) = rerun_python("rerun_view::rerun_reads_the_blueprint_and_named_scalars_of_a_paper_and_a_unilateral_recording") else { return };
    let dir = tempfile::tempdir().unwrap();

    // the paper's two-elbow run (bilateral: /constraints)
    let paper = root().join("recordings/paper-archive-two-elbow.mcap");
    let f = check(&python, &paper, &dir.path().join("paper-two-elbow.rrd"));
    assert!(!view(&f, "TimeSeries", "/contact_mode"), "a bilateral run has no modes");

    // a unilateral run, short (its modes, friction and events)
    let o = run_sim(&[
        "run",
        &root().join("sim/scenes/paper_unilateral.json").to_string_lossy(),
        "--run",
        "two-elbow-unilateral",
        "--duration",
        "0.2",
        "-q",
        "-o",
        &dir.path().to_string_lossy(),
    ]);
    assert!(o.status.success(), "sim: {}", String::from_utf8_lossy(&o.stderr));
    let uni = dir.path().join("paper-unilateral-two-elbow-unilateral.mcap");
    let f = check(&python, &uni, &dir.path().join("unilateral.rrd"));
    for origin in ["/contact_mode", "/friction_force_N"] {
        assert!(view(&f, "TimeSeries", origin), "no time series of {origin}: {:?}", f.views);
    }
    assert!(f.entities.contains_key("/contact_mode/elbow4") && f.entities.contains_key("/friction_force_N/elbow7"));
}

/// `rerun rrd verify` (Rerun's own checker, the CLI of the venv's rerun-sdk 0.41: every chunk
/// decoded against Rerun's reflection, the footer present, each manifest decoded and its
/// chunks found at their offsets) passes on every kind of file `analyze view` writes: one run,
/// several runs in one file (`-o`), a run that failed at t = 0 (no samples), a run drawn in
/// several windows (a 30 s synthetic run) and one whose URDF root link is named `world`.
/// Before issue 27 item 5 it failed on each with "Missing RRD footer / no RRD manifests".
#[test]
fn rerun_rrd_verify_passes_on_every_kind_of_file_view_writes() {
    let Some(python) = rerun_python("rerun_view::rerun_rrd_verify_passes_on_every_kind_of_file_view_writes") else { return };
    let rerun = python.parent().unwrap().join("rerun");
    let dir = tempfile::tempdir().unwrap();
    let archive = |run: &str| root().join(format!("recordings/paper-archive-{run}.mcap"));
    let mut failed = schemas::synth::Synth::new("failed", &["elbow4"], 3);
    (failed.hand, failed.motors, failed.constraints, failed.energy) = (None, None, None, None);
    failed.result = Some(schemas::RunResult::failed("9 rigid contacts closed at once".into(), Some(0.0)));
    let failed = failed.write(&dir.path().join("failed.mcap"));
    let mut long = schemas::synth::Synth::new("long", &["elbow"], 3);
    (long.dt, long.n) = (1e-3, 30_000);
    let long = long.with_setup().write_in(dir.path());
    let world = world_root_recording(dir.path());
    let jobs: Vec<(Vec<PathBuf>, &str, i32)> = vec![
        (vec![archive("two-elbow")], "single.rrd", 0),
        (vec![archive("no-elbow"), archive("one-elbow"), archive("two-elbow")], "several.rrd", 0),
        (vec![failed], "failed.rrd", 1),
        (vec![long], "windows.rrd", 0),
        (vec![world], "world-root.rrd", 0),
    ];
    for (inputs, out, code) in jobs {
        let rrd = dir.path().join(out);
        let mut args: Vec<&Path> = vec![Path::new("view")];
        args.extend(inputs.iter().map(PathBuf::as_path));
        args.extend([Path::new("-o"), rrd.as_path()]);
        let o = run_analyze(&args);
        assert_eq!(o.status.code(), Some(code), "analyze view -> {out}: {}", String::from_utf8_lossy(&o.stderr));
        let v = Command::new(&rerun).args(["rrd", "verify"]).arg(&rrd).output().expect("rerun starts");
        let said = format!("{}{}", String::from_utf8_lossy(&v.stdout), String::from_utf8_lossy(&v.stderr));
        assert!(v.status.success() && said.contains("verified without error"), "rerun rrd verify {out}: {said}");
        // and the SDK's reader takes it as a current file (no "legacy" warning)
        let read = Command::new(&python)
            .args(["-W", "error", "-c", "import sys; from rerun.chunk import RrdReader; r = RrdReader(sys.argv[1]); [c for s in r.recordings() for c in r.stream(store=s)]"])
            .arg(&rrd)
            .output()
            .expect("python starts");
        let said = String::from_utf8_lossy(&read.stderr);
        assert!(read.status.success() && !said.to_lowercase().contains("legacy"), "RrdReader {out}: {said}");
    }
}

/// A recording of the UR5e-like arm whose URDF has a root link named `world` (as UR5's and Z1's
/// of example-robot-data: `world` → `base_link` by a fixed joint), 50 ms of a `sim` run.
fn world_root_recording(dir: &Path) -> PathBuf {
    let arms = root().join("sim/scenes/arms");
    let urdf = std::fs::read_to_string(arms.join("ur5e_like.urdf")).unwrap();
    let at = urdf.find("<link name=\"base_link\"").expect("the UR5e-like URDF has a base_link");
    let world = "<link name=\"world\"/>\n  <joint name=\"world_joint\" type=\"fixed\">\n    <parent link=\"world\"/>\n    <child link=\"base_link\"/>\n    <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>\n  </joint>\n  ";
    let urdf = format!("{}{world}{}", &urdf[..at], &urdf[at..]);
    std::fs::write(dir.join("ur5e_world.urdf"), urdf).unwrap();
    let mut scene: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(arms.join("ur5e_like.json")).unwrap()).unwrap();
    scene["urdf"] = "ur5e_world.urdf".into();
    scene["name"] = "ur5e-world".into();
    scene.as_object_mut().unwrap().remove("$schema");
    let scene_path = dir.join("ur5e_world.json");
    std::fs::write(&scene_path, serde_json::to_string_pretty(&scene).unwrap()).unwrap();
    let o = run_sim(&["run", scene_path.to_str().unwrap(), "--run", "with-elbow", "--duration", "0.05", "-q", "-o", dir.to_str().unwrap()]);
    assert!(o.status.success(), "sim: {}", String::from_utf8_lossy(&o.stderr));
    dir.join("ur5e-world-with-elbow.mcap")
}

/// A URDF whose root link is named `world` (issue 27 item 1): the recording's `/tf` has no
/// `world` → `world` transform (a frame is not its own parent), and `analyze view` draws the
/// arm below `/world` (before: "/tf: every frame has a parent in /tf (a cycle, no root
/// frame)"), its links nested from `base_link`.
#[test]
fn a_urdf_whose_root_link_is_world_is_drawn() {
    let dir = tempfile::tempdir().unwrap();
    let mcap = world_root_recording(dir.path());
    let rec = schemas::read_recording(&mcap).unwrap();
    let tf = rec.read::<schemas::Transforms>().unwrap();
    assert!(!tf.is_empty());
    for (t, m) in &tf {
        assert!(m.transforms.iter().all(|e| e.parent_frame_id != e.child_frame_id), "t = {t}: a self-transform");
        assert_eq!(m.transforms.iter().filter(|e| e.child_frame_id == "base_link" && e.parent_frame_id == "world").count(), 1, "t = {t}");
    }
    let rrd = dir.path().join("world.rrd");
    let o = run_analyze(&[Path::new("view"), mcap.as_path(), Path::new("-o"), rrd.as_path()]);
    assert!(o.status.success(), "analyze view: {}", String::from_utf8_lossy(&o.stderr));
    // the arm's frames nested below /world, each with its transforms (read back chunk by chunk)
    let entities = entities(&std::fs::read(&rrd).unwrap());
    for e in ["/world/base_link", "/world/base_link/shoulder_link", "/world/base_link/shoulder_link/upper_arm_link"] {
        assert!(entities.get(e).is_some_and(|c| c.contains("Transform3D:translation")), "{e}: {:?}", entities.get(e));
    }
    assert!(!entities.contains_key("/world/world"));
}

/// The entities of an `.rrd` and their component columns (the chunks of
/// [`crate::rerun_meshes::batches`]).
fn entities(bytes: &[u8]) -> std::collections::BTreeMap<String, std::collections::BTreeSet<String>> {
    let mut out: std::collections::BTreeMap<String, std::collections::BTreeSet<String>> = Default::default();
    for batch in crate::rerun_meshes::batches(bytes) {
        let e = out.entry(batch.schema().metadata()["rerun:entity_path"].clone()).or_default();
        e.extend(batch.schema().fields().iter().map(|f| f.name().clone()));
    }
    out
}
