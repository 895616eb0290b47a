//! The `analyze` binary as a process: exit codes and messages on bad input, `--help`.

use crate::run_analyze;

/// Empty, non-MCAP and missing files: bad input, exit status 2, the file named on stderr, no
/// panic, nothing on stdout.
#[test]
fn bad_files_exit_non_zero_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let empty = dir.path().join("empty.mcap");
    let text = dir.path().join("text.mcap");
    std::fs::write(&empty, "").unwrap();
    std::fs::write(&text, "hello").unwrap();
    let missing = dir.path().join("missing.mcap");
    for path in [&empty, &text, &missing] {
        for cmd in ["compare", "metrics"] {
            let out = run_analyze(&[cmd, path.to_str().unwrap()]);
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{cmd} {}: {stderr}", path.display());
            assert!(stderr.contains(&path.display().to_string()), "{stderr}");
            assert!(
                !stderr.contains("panicked") && out.stdout.is_empty(),
                "{stderr}"
            );
        }
    }
    let out = run_analyze(&[
        "compare",
        dir.path().join("nothing-here").to_str().unwrap(),
        "-f",
        "xml",
    ]);
    assert_eq!(out.status.code(), Some(2)); // clap: bad command line
}

#[test]
fn help_shows_commands_and_examples() {
    let out = run_analyze(&["--help"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    for want in ["compare", "metrics", "Examples:", "analyze compare out/"] {
        assert!(text.contains(want), "{want:?} not in\n{text}");
    }
}

/// The small scene (4 joints) as `dir/nine.json`, `duration` s: run `nine` has nine unilateral
/// contacts closed at t = 0 on the same elbow, over the limit of 8 simultaneous rigid contacts
/// (`MAX_CLOSED_CONTACTS`), so it fails at t = 0 before its first sample; run `free` has none
/// and completes (issue 29).
pub(crate) fn nine_contacts_scene(dir: &std::path::Path, duration: f64) -> std::path::PathBuf {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut s: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(root.join("sim/scenes/small/small.json")).unwrap()).unwrap();
    s.as_object_mut().unwrap().remove("$schema");
    s["urdf"] = root.join("sim/scenes/small/small_arm.urdf").display().to_string().into();
    s["duration"] = duration.into();
    let names: Vec<String> = "abcdefghi".chars().map(|c| format!("elbow3{c}")).collect();
    s["contacts"] = names
        .iter()
        .map(|n| serde_json::json!({"name": n, "point": {"joint": "joint3"}, "plane": {"normal": [0.0, 0.0, 1.0], "offset": 0.0}, "model": "unilateral", "restitution": 0.0, "friction": 0.5}))
        .collect();
    s["runs"] = serde_json::json!([{"name": "nine", "contacts": names}, {"name": "free", "contacts": []}]);
    let path = dir.join("nine.json");
    std::fs::write(&path, serde_json::to_string_pretty(&s).unwrap()).unwrap();
    path
}

/// No `inf`, `NaN` or `Infinity` in a text, and no number longer than 24 characters (the
/// longest shortest-round-trip form of an f64 in scientific notation).
fn no_wrong_number(what: &str, text: &str) {
    for bad in ["inf", "NaN", "Infinity"] {
        assert!(!text.split(|c: char| !c.is_alphanumeric()).any(|w| w == bad), "{what} prints {bad}:\n{text}");
    }
    let numbers = text.split(|c: char| !(c.is_ascii_digit() || matches!(c, '.' | '-' | '+' | 'e')));
    let widest = numbers.filter(|w| w.chars().any(|c| c.is_ascii_digit())).map(str::len).max().unwrap_or(0);
    assert!(widest <= 24, "{what}: a {widest}-character number:\n{text}");
}

/// A run that failed at t = 0 (nine closed rigid contacts, over the limit of 8) leaves a
/// recording with no message: `metrics`, `compare`, `summary` and `report` read it (on main:
/// exit 2, "no topic /hand", and `compare out/` failed for the whole directory). Its row has its
/// status, reason and time (`result` record), and no numbers: null in JSON, empty in CSV, `—`
/// in text; the complete run beside it keeps all of its numbers; exit status 1.
#[test]
fn a_run_that_failed_at_t0_is_a_row_with_its_status_and_no_numbers() {
    let dir = tempfile::tempdir().unwrap();
    let scene = nine_contacts_scene(dir.path(), 0.1);
    let out = dir.path().join("out");
    let sim = crate::run_sim(&[std::ffi::OsStr::new("run"), scene.as_os_str(), "-q".as_ref(), "-o".as_ref(), out.as_os_str()]);
    assert_eq!(sim.status.code(), Some(1), "{}", String::from_utf8_lossy(&sim.stderr));
    let nine = out.join("small-nine.mcap");
    assert!(nine.is_file(), "the failed run's recording");
    let s = |p: &std::path::Path| p.to_str().unwrap().to_string();

    // metrics: JSON with the status, the reason, the time, and null numbers
    let o = run_analyze(&["metrics", &s(&nine), "-f", "json"]);
    assert_eq!(o.status.code(), Some(1), "{}", String::from_utf8_lossy(&o.stderr));
    let m: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let r = &m[0];
    assert_eq!(r["status"], "failed");
    assert_eq!(r["run"], "nine");
    assert!(r["error"].as_str().unwrap().contains("more than 8 simultaneous rigid contacts"), "{r}");
    assert_eq!(r["error_time_s"].as_f64(), Some(0.0));
    assert_eq!(r["samples"], 0);
    for key in ["t_end_s", "hand_error", "electric_energy_total_j", "link_work_total_j", "energy", "peak_current"] {
        assert!(r[key].is_null(), "{key}: {}", r[key]);
    }
    // the reason on stderr too
    assert!(String::from_utf8_lossy(&o.stderr).contains("run nine failed at t = 0.000 s"), "{}", String::from_utf8_lossy(&o.stderr));

    // compare the directory: both runs, the failed one with its status and `—`, exit 1
    let o = run_analyze(&["compare", &s(&out)]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{}", String::from_utf8_lossy(&o.stderr));
    let row = text.lines().find(|l| l.starts_with("nine") && l.contains("failed at 0.000 s")).unwrap_or_else(|| panic!("{text}"));
    assert!(row.contains('—'), "{row}");
    let e_row = text.lines().skip_while(|l| !l.starts_with("Energy totals")).find(|l| l.starts_with("nine")).unwrap();
    assert_eq!(e_row.split_whitespace().skip(2).collect::<Vec<_>>(), ["—", "—", "-", "-"], "{e_row}");
    assert!(text.contains("more than 8 simultaneous rigid contacts"), "{text}");
    let free = text.lines().skip_while(|l| !l.starts_with("Energy totals")).find(|l| l.starts_with("free *")).unwrap();
    let e_free: f64 = free.split_whitespace().nth(2).unwrap().parse().unwrap();
    assert!(e_free > 0.1, "{free}");
    no_wrong_number("compare", &text);

    // CSV: empty cells, the status and the reason
    let o = run_analyze(&["compare", &s(&out), "-f", "csv"]);
    assert_eq!(o.status.code(), Some(1));
    let csv = String::from_utf8_lossy(&o.stdout).to_string();
    let mut rd = csv::Reader::from_reader(csv.as_bytes());
    let head = rd.headers().unwrap().clone();
    let rows: Vec<csv::StringRecord> = rd.records().map(Result::unwrap).collect();
    let col = |name: &str| head.iter().position(|h| h == name).unwrap_or_else(|| panic!("{name}: {head:?}"));
    let nine_row = rows.iter().find(|r| &r[col("run")] == "nine").unwrap();
    assert_eq!(&nine_row[col("status")], "failed");
    for c in ["t_end_s", "E_total_j", "err_z_rms_m", "E_total_ratio", "residual_max_rel"] {
        assert_eq!(&nine_row[col(c)], "", "{c}");
    }
    assert!(nine_row[col("not_compared")].contains("no sample"), "{nine_row:?}");

    // summary and report: every run, the failed one with its status; exit 1
    let o = run_analyze(&["summary", &s(&out), "-f", "json"]);
    assert_eq!(o.status.code(), Some(1), "{}", String::from_utf8_lossy(&o.stderr));
    let rows: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let rows = rows.as_array().unwrap();
    assert_eq!(rows.len(), 2, "{rows:?}");
    let nine_row = rows.iter().find(|r| r["run"] == "nine").unwrap();
    assert!(nine_row["status"].as_str().unwrap().starts_with("failed"), "{nine_row}");
    assert!(nine_row["E_total_j"].is_null() && nine_row["t_end_s"].is_null(), "{nine_row}");
    let report = dir.path().join("report");
    let o = run_analyze(&["report", &s(&out), "--no-figures", "-o", &s(&report)]);
    assert_eq!(o.status.code(), Some(1), "{}", String::from_utf8_lossy(&o.stderr));
    let md = std::fs::read_to_string(report.join("report.md")).unwrap();
    assert!(md.contains("nine did not complete: failed at t = 0.000 s"), "{md}");
    no_wrong_number("report", &md);
}

/// Runs over different durations are never ranked or divided (issue 29, item 3): a 0.1-s run
/// beside 0.2-s runs of the same scene gets no ratio (on main: "0.472 × baseline" against the
/// 0.2-s baseline), is marked `†` with the reason, is left out of the rankings, and says why in
/// every format; `summary` says the runs end at different times.
#[test]
fn runs_over_different_durations_are_not_ranked_or_divided() {
    let dir = tempfile::tempdir().unwrap();
    let small = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("sim/scenes/small/small.json");
    let (long, short) = (dir.path().join("long"), dir.path().join("short"));
    for (d, duration) in [(&long, "0.2"), (&short, "0.1")] {
        let o = crate::run_sim(&[std::ffi::OsStr::new("run"), small.as_os_str(), "--duration".as_ref(), duration.as_ref(), "-q".as_ref(), "-o".as_ref(), d.as_os_str()]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let files = [long.join("small-free.mcap"), long.join("small-elbow.mcap"), short.join("small-elbow.mcap")];
    let args = |f: &str| -> Vec<String> { ["compare".to_string()].into_iter().chain(files.iter().map(|p| p.display().to_string())).chain(["-f".into(), f.into()]).collect() };
    let o = run_analyze(&args("json"));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let c: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let runs = c["runs"].as_array().unwrap();
    // the 0.2-s elbow run is compared, the 0.1-s one is not
    assert!(runs[1]["to_baseline"]["electric_energy"].as_f64().is_some_and(|x| x > 0.0 && x < 1.0), "{}", runs[1]);
    assert!(runs[1].get("not_compared").is_none(), "{}", runs[1]);
    for k in ["electric_energy", "link_work", "error_z_rms", "error_norm_rms"] {
        assert!(runs[2]["to_baseline"][k].is_null(), "{k}: {}", runs[2]);
    }
    let why = runs[2]["not_compared"].as_str().unwrap();
    assert!(why.contains("t = 0.1 s") && why.contains("different durations"), "{why}");
    let findings: Vec<&str> = c["findings"].as_array().unwrap().iter().map(|f| f.as_str().unwrap()).collect();
    let least = findings.iter().find(|f| f.starts_with("Least total electric energy")).unwrap();
    // the short run has the least energy (half the time), but is not ranked
    let e_short = runs[2]["metrics"]["electric_energy_total_j"].as_f64().unwrap();
    let e_long = runs[1]["metrics"]["electric_energy_total_j"].as_f64().unwrap();
    assert!(e_short < e_long);
    assert!(least.contains(&format!("{e_long:.3} J")), "{least}");
    assert!(findings.iter().any(|f| f.contains("is not compared with the baseline")), "{findings:#?}");

    // text: the row marked, no ratio, the reason under the brief table and in the findings
    let o = run_analyze(&args("table"));
    let text = String::from_utf8_lossy(&o.stdout);
    let row = text.lines().skip_while(|l| !l.starts_with("Energy totals")).filter(|l| l.starts_with("elbow")).nth(1).unwrap();
    assert!(row.contains('†') && row.split_whitespace().rev().take(2).all(|c| c == "-"), "{row}");
    // CSV: the reason in its column, no ratio
    let o = run_analyze(&args("csv"));
    let csv = String::from_utf8_lossy(&o.stdout).to_string();
    let mut rd = csv::Reader::from_reader(csv.as_bytes());
    let head = rd.headers().unwrap().clone();
    let rows: Vec<csv::StringRecord> = rd.records().map(Result::unwrap).collect();
    let col = |name: &str| head.iter().position(|h| h == name).unwrap();
    assert_eq!(&rows[2][col("E_total_ratio")], "");
    assert!(rows[2][col("not_compared")].contains("different durations"));
    assert_eq!(&rows[1][col("not_compared")], "");

    // summary: the note
    let o = run_analyze(&["summary".to_string(), long.display().to_string(), short.display().to_string()]);
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("the runs end at different times (0.1 to 0.2 s"), "{text}");
}

/// A relative residual over ~0 J (5e-324 J drawn: on main `inf` in the table, `null` in JSON)
/// and a total of 4e302 J (on main a 307-character cell) print as numbers a person can read:
/// the relative residual is absent (`-`, the absolute one is there), the total in scientific
/// notation; no `inf` or `NaN` in any format (issue 29, item 3).
#[test]
fn no_table_prints_inf_nan_or_a_300_digit_number() {
    use schemas::synth::{energy, Synth};
    let dir = tempfile::tempdir().unwrap();
    let mut tiny = Synth::new("tiny", &[], 2).with_setup();
    tiny.energy = Some(Box::new(|t| schemas::EnergyState { balance_residual: 1e-3 * t, ..energy(vec![0.0, 0.0], vec![5e-324, 0.0]) }));
    let mut huge = Synth::new("huge", &[], 2).with_setup();
    huge.energy = Some(Box::new(|t| schemas::EnergyState { balance_residual: 4e302 * t, ..energy(vec![1.0, 1.0], vec![2e302 * t, 2e302 * t]) }));
    let files = [tiny.write_in(dir.path()), huge.write_in(dir.path())];
    let s: Vec<String> = files.iter().map(|p| p.display().to_string()).collect();
    for cmd in ["metrics", "compare"] {
        for f in ["table", "csv", "json"] {
            let o = run_analyze(&[cmd, &s[0], &s[1], "-f", f]);
            let text = String::from_utf8_lossy(&o.stdout);
            assert!(o.status.success(), "{cmd} -f {f}: {}", String::from_utf8_lossy(&o.stderr));
            no_wrong_number(&format!("{cmd} -f {f}"), &text);
            if f == "table" && cmd == "metrics" {
                assert!(text.contains("4.0000e302"), "{text}");
            }
        }
    }
    let o = run_analyze(&["summary", &s[0], &s[1], "--columns", "run,E_total_j,residual_max_rel"]);
    no_wrong_number("summary", &String::from_utf8_lossy(&o.stdout));
}
