//! `sim`'s table comes from what each run wrote (the writer's tap feeds `analyze`'s reductions,
//! no file is read back): it must equal `analyze compare` on the files `sim` wrote, field by
//! field, exactly (issue 14, item 3).

use std::path::Path;
use std::process::Command;

fn run(cmd: &mut Command) -> String {
    let o = cmd.output().unwrap();
    assert!(o.status.success(), "{:?}: {}", cmd, String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stdout).unwrap()
}

/// `sim run SCENE --duration D -f FORMAT` into `dir`, and `analyze compare -f FORMAT` on the
/// files it names, in its order: the two outputs.
fn both(scene: Option<&Path>, duration: &str, format: &str, dir: &Path) -> (String, String, Vec<String>) {
    let mut sim = Command::new(env!("CARGO_BIN_EXE_sim"));
    sim.arg("run");
    if let Some(s) = scene {
        sim.arg(s);
    }
    sim.args(["--duration", duration, "--quiet", "-f", "csv", "-o"]).arg(dir);
    let csv = run(&mut sim);
    // the files, in the table's order (column `file`)
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = header.iter().position(|c| *c == "file").expect("a file column");
    let files: Vec<String> = lines.map(|l| l.split(',').nth(col).unwrap().to_string()).collect();
    assert!(!files.is_empty());
    let sim_out = if format == "csv" {
        csv
    } else {
        let mut sim = Command::new(env!("CARGO_BIN_EXE_sim"));
        sim.arg("run");
        if let Some(s) = scene {
            sim.arg(s);
        }
        sim.args(["--duration", duration, "--quiet", "-f", format, "-o"]).arg(dir);
        run(&mut sim)
    };
    let analyze = run(Command::new(env!("CARGO_BIN_EXE_analyze")).args(["compare", "--quiet", "-f", format]).args(&files));
    (sim_out, analyze, files)
}

#[test]
fn sim_table_equals_analyze_compare_on_the_files_it_wrote() {
    let dir = tempfile::tempdir().unwrap();
    // the paper scene: three runs, no, one and two elbows (every metric has values)
    let (sim_json, analyze_json, files) = both(None, "0.3", "json", dir.path());
    assert_eq!(files.len(), 3);
    let a: serde_json::Value = serde_json::from_str(&sim_json).unwrap();
    let b: serde_json::Value = serde_json::from_str(&analyze_json).unwrap();
    // field by field (JSON numbers are printed round-trip exact), then the text itself
    assert_eq!(a, b);
    assert_eq!(sim_json, analyze_json);
    assert!(sim_json.contains("elbow4"), "{sim_json}");

    let (sim_csv, analyze_csv, _) = both(None, "0.3", "csv", dir.path());
    assert_eq!(sim_csv, analyze_csv);

    // another scene
    let small = Path::new(env!("CARGO_MANIFEST_DIR")).join("sim/scenes/small/small.json");
    let dir = tempfile::tempdir().unwrap();
    let (sim_table, analyze_table, _) = both(Some(&small), "0.2", "table", dir.path());
    assert_eq!(sim_table, analyze_table);
}
