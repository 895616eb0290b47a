//! `sim list` and the built-in scenes by name, as a user runs them: the listing in its three
//! formats, `sim NAME` running a built-in scene (the paper, by name, writes the same recordings'
//! names as `sim` alone), `sim export-scene NAME` writing a scene and its URDF that `sim check`
//! then reads, and an unknown name refused with exit status 2 and a suggestion.

use crate::run_sim;

fn stdout(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn list_shows_every_builtin_scene_with_its_dof_and_runs_in_each_format() {
    let o = run_sim(&["list", "-f", "json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let rows: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let rows = rows.as_array().unwrap();
    let got: Vec<(&str, u64)> = rows.iter().map(|r| (r["name"].as_str().unwrap(), r["dof"].as_u64().unwrap())).collect();
    // the paper (10 joints), the paper arm over a real table, and the three real arms:
    // UR5e-like 6, Panda-like 7, SO-100-like 6
    assert_eq!(got, [("paper", 10), ("paper-unilateral", 10), ("ur5e-like", 6), ("panda-like", 7), ("hobby-arm", 6)]);
    assert_eq!(rows[0]["runs"], serde_json::json!(["two-elbow", "one-elbow", "no-elbow"]));
    assert_eq!(rows[1]["runs"], serde_json::json!(["two-elbow-unilateral", "one-elbow-unilateral", "whole-table"]));
    for r in &rows[2..] {
        let runs = r["runs"].as_array().unwrap();
        assert_eq!(runs.len(), 2, "each arm: the task with its contact and without");
        assert_eq!(runs[1], "free");
        assert!(r["description"].as_str().unwrap().contains("SOURCES.md"), "{r}");
    }
    let table = stdout(&run_sim(&["list"]));
    for name in ["paper", "paper-unilateral", "ur5e-like", "panda-like", "hobby-arm"] {
        assert!(table.lines().any(|l| l.starts_with(&format!("{name} "))), "{name} missing from\n{table}");
    }
    let csv = stdout(&run_sim(&["list", "-f", "csv"]));
    assert_eq!(csv.lines().next(), Some("name,dof,robot,urdf,runs,description"));
    assert_eq!(csv::Reader::from_reader(csv.as_bytes()).records().count(), 5);
}

#[test]
fn a_builtin_scene_runs_by_name_and_exports_to_files_sim_checks() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    // `sim paper …` is `sim run paper …`: the paper's recording, under the paper's name
    let o = run_sim(&["paper".as_ref(), "--run".as_ref(), "no-elbow".as_ref(), "--duration".as_ref(), "0.01".as_ref(), "-q".as_ref(), "-o".as_ref(), out.as_os_str()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.join("paper-no-elbow.mcap").is_file());
    let exported = dir.path().join("exported");
    let o = run_sim(&["export-scene".as_ref(), "hobby-arm".as_ref(), "-o".as_ref(), exported.as_os_str(), "-q".as_ref()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let scene: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(exported.join("hobby_arm.json")).unwrap()).unwrap();
    assert_eq!(scene["name"], "hobby-arm");
    let urdf = std::fs::read_to_string(exported.join(scene["urdf"].as_str().unwrap())).unwrap();
    assert_eq!(urdf, sim::scene::builtin::find("hobby-arm").unwrap().files[0].1);
    // the default export is still the paper
    let paper = dir.path().join("paper");
    assert!(run_sim(&["export-scene".as_ref(), "-o".as_ref(), paper.as_os_str(), "-q".as_ref()]).status.success());
    assert!(run_sim(&["check".as_ref(), paper.join("paper.json").as_os_str()]).status.success());
    // an exported arm scene: `sim check` reads it from the files
    let o = run_sim(&["check".as_ref(), exported.join("hobby_arm.json").as_os_str()]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn an_unknown_scene_name_is_an_unknown_command_with_a_suggestion() {
    let o = run_sim(&["pand-like"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("unrecognized subcommand"), "{}", stderr(&o));
    let o = run_sim(&["export-scene", "no-such-arm"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("no built-in scene `no-such-arm`") && stderr(&o).contains("ur5e-like"), "{}", stderr(&o));
}
