//! `sim optimize`: on the small arm's study (`sim/scenes/studies/small-kd.json`, 0.2-s runs),
//! the optimum lies within one spacing of a dense grid's best (the grid run by `sim sweep`),
//! within the study's budget of 40 evaluations; the same seed gives byte-identical outputs; three
//! shards of a generation merge to the unsharded generation; `--seeds` runs one study per seed
//! and states their optima's spread; a study stopped (by
//! `--generations` and by a kill) and resumed gives the uninterrupted study's outputs.

use crate::run_sim;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn study_file() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("sim/scenes/studies/small-kd.json")
}

/// The study's text outputs (no figures: plotters' SVG text is checked by its own tests), by name.
fn outputs(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    ["study-state.json", "best.csv", "evaluations.csv", "pareto.csv", "optimum.json", "report.md", "map.svg", "convergence.svg"]
        .iter()
        .map(|n| (n.to_string(), std::fs::read(dir.join(n)).unwrap_or_else(|e| panic!("{n}: {e}"))))
        .collect()
}

fn optimize(dir: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec!["optimize".to_string(), study_file().display().to_string(), "-o".into(), dir.display().to_string(), "-j".into(), "2".into()];
    args.extend(extra.iter().map(|s| s.to_string()));
    let out = run_sim(&args);
    assert_eq!(out.status.code(), Some(0), "sim {args:?}: {}", String::from_utf8_lossy(&out.stderr));
    out
}

fn state(dir: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(dir.join("study-state.json")).unwrap()).unwrap()
}

#[test]
fn the_optimum_is_the_dense_grids_best_within_one_spacing() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("study");
    optimize(&out, &[]);
    let st = state(&out);
    let evals = st["evaluations"].as_array().unwrap();
    assert!(evals.len() <= 40, "{} evaluations: the budget is 40", evals.len());
    // the optimum: the best evaluation
    let best = evals.iter().filter(|e| e["objective"].is_f64()).min_by(|a, b| a["objective"].as_f64().unwrap().total_cmp(&b["objective"].as_f64().unwrap())).unwrap();
    let kd_opt = best["values"][0][1].as_f64().unwrap();
    let e_opt = best["objective"].as_f64().unwrap();
    // the dense grid: kd = 2, 2.25, ..., 20 (73 points) at the evaluations' tolerance (rtol 1e-4)
    let spacing = 0.25;
    let values: Vec<f64> = (0..=72).map(|k| 2.0 + spacing * k as f64).collect();
    let sweep = serde_json::json!({
        "name": "grid", "scene": Path::new(env!("CARGO_MANIFEST_DIR")).join("sim/scenes/small/small.json"),
        "runs": ["elbow"], "duration": 0.2,
        "axes": [{"field": "controller.kd", "values": values}, {"field": "integrator.rtol", "values": [1e-4]}, {"field": "integrator.atol", "values": [1e-6]}]
    });
    let sweep_file = tmp.path().join("grid.json");
    std::fs::write(&sweep_file, sweep.to_string()).unwrap();
    let g = run_sim(&["sweep", sweep_file.to_str().unwrap(), "-o", tmp.path().join("grid").to_str().unwrap(), "-j", "2", "-q", "-f", "json"]);
    assert_eq!(g.status.code(), Some(0), "{}", String::from_utf8_lossy(&g.stderr));
    let rows: Vec<serde_json::Value> = serde_json::from_slice(&g.stdout).unwrap();
    let (kd_grid, e_grid) = rows
        .iter()
        .map(|r| (r["values"]["controller.kd"].as_f64().unwrap(), r["E_total_j"].as_f64().unwrap()))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap();
    // an interior minimum (not at a bound): the grid has a best point to find
    assert!(kd_grid > 2.0 + spacing && kd_grid < 20.0 - spacing, "grid best at kd = {kd_grid}");
    assert!((kd_opt - kd_grid).abs() <= spacing, "optimum kd = {kd_opt}, grid best kd = {kd_grid} (spacing {spacing})");
    // and at least as good as the grid's best, up to the evaluations' error (the report's error
    // bar, below 1e-5 J here)
    assert!(e_opt <= e_grid + 1e-5, "optimum {e_opt} J, grid best {e_grid} J");
    // the report states the error bar and the optimum's scene runs
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("Error bar:"), "{report}");
    // the error bar is measured at the baseline, the centre and both ends of kd's range (each at
    // the loose and the tight rtol), and stated as 2 × the largest difference; the optimum's
    // own loose − tight lies within it
    let cal = &st["calibration"];
    let designs = cal["designs"].as_array().expect("the calibration designs");
    assert_eq!(designs.len(), 4, "{cal}");
    let largest = designs.iter().map(|d| (d["loose"].as_f64().unwrap() - d["tight"].as_f64().unwrap()).abs()).fold(0.0, f64::max);
    assert!(largest > 0.0, "{cal}");
    assert_eq!(cal["error_j"].as_f64().unwrap(), 2.0 * largest, "{cal}");
    let tight_opt: f64 = report
        .lines()
        .find_map(|l| l.strip_prefix("| optimum (tight) | "))
        .and_then(|l| l.split(" | ").next())
        .and_then(|x| x.parse().ok())
        .unwrap_or_else(|| panic!("no tight optimum in {report}"));
    // the report prints 5 decimals: the optimum's loose − tight within the bar, up to that rounding
    assert!((e_opt - tight_opt).abs() <= 2.0 * largest + 5e-6, "loose {e_opt} J, tight {tight_opt} J, error bar {} J", 2.0 * largest);
    assert!(report.contains("matches its tight re-run within the stated error bar"), "{report}");
    let r = run_sim(&["run", out.join("optimum.json").to_str().unwrap(), "-o", tmp.path().join("rerun").to_str().unwrap(), "-q"]);
    assert_eq!(r.status.code(), Some(0), "{}", String::from_utf8_lossy(&r.stderr));
    for f in ["small-kd-optimum-elbow.mcap", "small-kd-baseline-elbow.mcap", "map.png", "pareto.svg", "convergence.png"] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    // the candidates' recordings are not kept
    assert_eq!(std::fs::read_dir(out.join("candidates")).unwrap().count(), 0);
}

#[test]
fn the_same_seed_gives_byte_identical_outputs_and_a_resumed_study_the_same() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b, c) = (tmp.path().join("a"), tmp.path().join("b"), tmp.path().join("c"));
    optimize(&a, &[]);
    optimize(&b, &[]);
    assert_eq!(outputs(&a), outputs(&b), "two runs of one study");
    // stopped after 3 generations (as a kill between two generations), then resumed
    let stop = optimize(&c, &["--generations", "3"]);
    assert!(!c.join("report.md").exists(), "a stopped study has no report yet");
    assert!(String::from_utf8_lossy(&stop.stderr).contains("run again to go on"));
    assert_eq!(state(&c)["optimizer"]["generation"], 3);
    optimize(&c, &[]);
    assert_eq!(outputs(&a), outputs(&c), "stopped and resumed");
}

/// `--seeds 2`: `seed-1/` holds the study run alone (the same bytes), `seed-2/` the study with
/// seed 2, and seeds.csv / seeds.md give each seed's best objective (the least feasible one of
/// its evaluations.csv), the best over the two and their spread (max − min).
#[test]
fn seeds_run_one_study_per_seed_and_state_the_spread_of_their_optima() {
    let tmp = tempfile::tempdir().unwrap();
    let (many, one) = (tmp.path().join("many"), tmp.path().join("one"));
    let printed = optimize(&many, &["--seeds", "2"]);
    optimize(&one, &[]);
    assert_eq!(outputs(&one), outputs(&many.join("seed-1")), "seed 1 of two against the study alone");
    let state2 = state(&many.join("seed-2"));
    assert_eq!(state2["spec"]["method"]["seed"], 2);
    assert_ne!(state(&one)["evaluations"], state2["evaluations"], "another seed, other candidates");
    // each seed's best from its own table
    let best_of = |dir: &Path| -> f64 {
        let mut r = csv::Reader::from_path(dir.join("evaluations.csv")).unwrap();
        let h = r.headers().unwrap().clone();
        let col = h.iter().position(|c| c == "objective_j").unwrap();
        r.records().filter_map(|x| x.unwrap()[col].parse::<f64>().ok()).fold(f64::INFINITY, f64::min)
    };
    let (b1, b2) = (best_of(&many.join("seed-1")), best_of(&many.join("seed-2")));
    let mut r = csv::Reader::from_path(many.join("seeds.csv")).unwrap();
    let rows: Vec<(String, f64)> = r.records().map(|x| x.unwrap()).map(|x| (x[1].to_string(), x[2].parse().unwrap())).collect();
    assert_eq!(rows, vec![("1".to_string(), b1), ("2".to_string(), b2)]);
    let md = std::fs::read_to_string(many.join("seeds.md")).unwrap();
    let spread = format!("{:.2e}", (b1 - b2).abs());
    assert!(md.contains(&format!("| {:.4} |", b1.min(b2))) && md.contains(&spread), "best {} and spread {spread} not in:\n{md}", b1.min(b2));
    assert!(String::from_utf8_lossy(&printed.stdout).contains(&spread), "seeds.md is printed");
    // --seeds with --shard or --generations is refused
    let bad = run_sim(&["optimize", study_file().to_str().unwrap(), "--seeds", "2", "--generations", "1"]);
    assert_eq!(bad.status.code(), Some(2));
}

#[test]
fn a_killed_study_resumes_to_the_same_result() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, k) = (tmp.path().join("a"), tmp.path().join("k"));
    optimize(&a, &[]);
    // a real kill: as soon as the first state is written, SIGKILL (the study may be between
    // generations or inside one; the state file is whole either way: written under a temporary
    // name, then renamed)
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_sim"))
        .args(["optimize", study_file().to_str().unwrap(), "-o", k.to_str().unwrap(), "-j", "2", "-q"])
        .spawn()
        .unwrap();
    let t0 = std::time::Instant::now();
    while !k.join("study-state.json").exists() && t0.elapsed().as_secs() < 120 {
        assert!(child.try_wait().unwrap().is_none(), "the study ended before its first state was written");
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    // the kill must interrupt the study: it is still running when killed, dies of the signal,
    // and leaves a state with fewer evaluations than the whole study and no report (a kill that
    // lands after the study finished would test nothing)
    assert!(child.try_wait().unwrap().is_none(), "the study finished before the kill");
    child.kill().unwrap();
    let status = child.wait().unwrap();
    {
        use std::os::unix::process::ExitStatusExt;
        assert_eq!(status.signal(), Some(9), "the study was not killed by SIGKILL: {status}");
    }
    let (killed_at, whole) = (state(&k)["evaluations"].as_array().unwrap().len(), state(&a)["evaluations"].as_array().unwrap().len());
    assert!(killed_at < whole, "the kill left {killed_at} of the study's {whole} evaluations: it did not interrupt the study");
    assert!(!k.join("report.md").exists() && !k.join("optimum.json").exists(), "the killed study wrote its outputs");
    optimize(&k, &[]);
    assert_eq!(outputs(&a), outputs(&k), "killed and resumed");
}

#[test]
fn three_shards_of_a_generation_merge_to_the_unsharded_generation() {
    let tmp = tempfile::tempdir().unwrap();
    let (u, s) = (tmp.path().join("u"), tmp.path().join("s"));
    for g in 1..=2 {
        optimize(&u, &["--generations", "1"]);
        for i in 0..3 {
            let out = optimize(&s, &["--shard", &format!("{i}/3")]);
            assert!(s.join(format!("gen-{:04}.shard-{i}-of-3.json", g - 1)).is_file(), "{}", String::from_utf8_lossy(&out.stderr));
        }
        // the merge: every candidate from the shards, none evaluated again
        let m = optimize(&s, &["--generations", "1"]);
        assert!(!String::from_utf8_lossy(&m.stderr).contains("evaluation(s) in"), "the merge evaluated: {}", String::from_utf8_lossy(&m.stderr));
        assert_eq!(std::fs::read(u.join("study-state.json")).unwrap(), std::fs::read(s.join("study-state.json")).unwrap(), "generation {g}");
    }
    // and the rest of the study, unsharded, ends where the unsharded study ends
    optimize(&u, &[]);
    optimize(&s, &[]);
    assert_eq!(outputs(&u), outputs(&s));
}

#[test]
fn bad_study_files_exit_2_naming_the_file_the_field_and_the_value() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("sim/scenes/small/small.json");
    let cases = [
        (serde_json::json!([{"kind": "continuous", "field": "controller.kq", "min": 1, "max": 2}]), "variables[0].field", "controller.kq"),
        (serde_json::json!([{"kind": "continuous", "field": "controller.kd", "min": 3, "max": 2}]), "variables[0].max", "2"),
        (serde_json::json!([{"kind": "categorical", "field": "controller.kd", "values": ["x"]}]), "variables[0].values[0]", "\"x\""),
        (serde_json::json!([{"kind": "continuous", "field": "controller.kd", "min": -5, "max": 2}]), "controller.kd", "-5"),
        // on-link variables: the contact, the links and the ranges, each named
        (serde_json::json!([{"kind": "on-link", "contact": "elbow9", "links": ["link2"]}]), "variables[0].contact", "elbow9"),
        (serde_json::json!([{"kind": "on-link", "contact": "elbow3", "links": ["link2", "link9"]}]), "variables[0].links[1]", "link9"),
        (serde_json::json!([{"kind": "on-link", "contact": "elbow3", "links": ["hand"]}]), "variables[0].links[0]", "hand"),
        (serde_json::json!([{"kind": "on-link", "contact": "elbow3", "links": ["link2"], "along": [0, 2]}]), "variables[0].along[1]", "2"),
        (serde_json::json!([{"kind": "on-link", "contact": "elbow3", "links": ["link2"], "around": [1, -1]}]), "variables[0].around[1]", "-1"),
        // the hand load: its validation names the field and the value
        (serde_json::json!([{"kind": "categorical", "field": "hand_load.mass", "values": [0.5, -1.0]}]), "hand_load.mass", "-1"),
    ];
    // the method: a start design names a dimension of the study and lies in its range
    let kd = serde_json::json!([{"kind": "continuous", "field": "controller.kd", "min": 2, "max": 20}]);
    let methods = [
        (serde_json::json!({"start": {"controller.kp": 3}}), "method.start.controller.kp", "3"),
        (serde_json::json!({"start": {"controller.kd": 25}}), "method.start.controller.kd", "25"),
        (serde_json::json!({"sigma0": 0}), "method.sigma0", "0"),
    ];
    let cases: Vec<_> = cases.iter().map(|(v, f, x)| (v.clone(), serde_json::json!({}), *f, *x)).chain(methods.iter().map(|(m, f, x)| (kd.clone(), m.clone(), *f, *x))).collect();
    for (k, (vars, method, field, value)) in cases.iter().enumerate() {
        let f = tmp.path().join(format!("bad{k}.json"));
        let doc = serde_json::json!({"name": "bad", "scene": scene, "duration": 0.1, "variables": vars, "method": method});
        std::fs::write(&f, doc.to_string()).unwrap();
        let out = run_sim(&["optimize", f.to_str().unwrap(), "-o", tmp.path().join("o").to_str().unwrap()]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "case {k}: {err}");
        for s in [f.to_str().unwrap(), field, value] {
            assert!(err.contains(s), "case {k}: `{s}` not in: {err}");
        }
    }
}

/// An `on-link` variable on the small arm whose links 2 and 3 have collision cylinders (radius
/// 2 cm, along the link from 0 to 0.3 m), with the hand load as a second variable: every
/// candidate's contact point lies on the cylinder's surface at its position along the chain
/// and its angle around (to 1e-12 m, 1e-9 rad), the brace under it holds the bilateral
/// contact at q0 (no candidate is infeasible), and the optimum's scene runs.
#[test]
fn on_link_points_lie_on_the_collision_cylinder_and_the_brace_holds_them() {
    let tmp = tempfile::tempdir().unwrap();
    let small = Path::new(env!("CARGO_MANIFEST_DIR")).join("sim/scenes/small");
    let cyl = r#"<collision><origin xyz="0 0 0.15" rpy="0 0 0"/><geometry><cylinder radius="0.02" length="0.3"/></geometry></collision>"#;
    let urdf = std::fs::read_to_string(small.join("small_arm.urdf")).unwrap();
    let urdf = urdf.replace("<link name=\"link2\">", &format!("<link name=\"link2\">{cyl}")).replace("<link name=\"link3\">", &format!("<link name=\"link3\">{cyl}"));
    assert_eq!(urdf.matches("<collision>").count(), 2);
    std::fs::write(tmp.path().join("small_arm.urdf"), urdf).unwrap();
    std::fs::copy(small.join("small.json"), tmp.path().join("small.json")).unwrap();
    let study = serde_json::json!({
        "name": "on-cyl", "scene": "small.json", "runs": ["elbow"], "duration": 0.1,
        "variables": [
            {"kind": "categorical", "field": "hand_load.mass", "values": [0.0, 0.2]},
            {"kind": "on-link", "contact": "elbow3", "links": ["link2", "link3"], "along": [0.2, 1.8], "around": [-3.0, 3.0]}
        ],
        "method": {"seed": 4, "evaluations": 24, "local_fraction": 0.0}
    });
    let f = tmp.path().join("on-cyl.json");
    std::fs::write(&f, study.to_string()).unwrap();
    let out = tmp.path().join("o");
    let r = run_sim(&["optimize", f.to_str().unwrap(), "-o", out.to_str().unwrap(), "-j", "2", "-q"]);
    assert_eq!(r.status.code(), Some(0), "{}", String::from_utf8_lossy(&r.stderr));
    let st = state(&out);
    let evals = st["evaluations"].as_array().unwrap();
    assert_eq!(evals.len(), 24);
    for e in evals {
        assert!(e["objective"].is_f64(), "infeasible: {}", e["infeasible"]);
        let u: Vec<f64> = e["point"]["u"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
        let (t, theta) = (0.2 + 1.6 * u[0], -3.0 + 6.0 * u[1]);
        let values = e["values"].as_array().unwrap();
        let point = values.iter().find(|v| v[0] == "contacts.0.point").unwrap_or_else(|| panic!("no point in {values:?}"))[1].clone();
        assert!(values.iter().any(|v| v[0] == "contacts.0.plane.offset"), "no brace in {values:?}");
        let link = if t < 1.0 { "link2" } else { "link3" };
        assert_eq!(point["link"], link, "t = {t}");
        let p: Vec<f64> = point["offset"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
        let s = t - t.floor();
        assert!((p[2] - 0.3 * s).abs() < 1e-12, "t = {t}: z = {}", p[2]);
        assert!((p[0].hypot(p[1]) - 0.02).abs() < 1e-12, "off the surface: {p:?}");
        let d = (p[1].atan2(p[0]) - theta).rem_euclid(std::f64::consts::TAU);
        assert!(d.min(std::f64::consts::TAU - d) < 1e-9, "θ = {theta}: {p:?}");
    }
    // both loads were searched, and the load is in the optimum's scene when it is the best
    assert!(evals.iter().any(|e| e["point"]["combo"] == 1) && evals.iter().any(|e| e["point"]["combo"] == 0));
    let opt: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("optimum.json")).unwrap()).unwrap();
    assert!(opt["hand_load"]["mass"].is_f64(), "{}", opt["hand_load"]);
    let r = run_sim(&["run", out.join("optimum.json").to_str().unwrap(), "-o", tmp.path().join("rerun").to_str().unwrap(), "-q"]);
    assert_eq!(r.status.code(), Some(0), "{}", String::from_utf8_lossy(&r.stderr));
}

/// A calibration that cannot state its error bar is a failed run, not bad input: the small
/// study with a hand-error bound that nothing keeps (the baseline included) stops before the
/// search with status 1, naming the study, the baseline and every design that could replace
/// it with their reasons, and writes no state.
#[test]
fn a_calibration_that_cannot_state_its_error_bar_exits_1_saying_why() {
    let tmp = tempfile::tempdir().unwrap();
    let mut spec: serde_json::Value = serde_json::from_slice(&std::fs::read(study_file()).unwrap()).unwrap();
    spec["scene"] = serde_json::Value::from(Path::new(env!("CARGO_MANIFEST_DIR")).join("sim/scenes/small/small.json").display().to_string());
    spec["constraints"] = serde_json::json!({ "hand_error_max": 1e-9 });
    let f = tmp.path().join("strict.json");
    std::fs::write(&f, spec.to_string()).unwrap();
    let out = tmp.path().join("o");
    let r = run_sim(&["optimize", f.to_str().unwrap(), "-o", out.to_str().unwrap(), "-j", "2", "-q"]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(1), "{err}");
    assert!(err.contains("study `small-kd`") && err.contains("strict.json") && err.contains("the baseline is infeasible (at rtol 1e-4: hand error") && err.contains("> the bound 0.000 mm") && err.contains("and so is every calibration design"), "{err}");
    assert!(!out.join("study-state.json").exists(), "no state for a study that did not start");
}
