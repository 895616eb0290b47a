//! One command-line voice across `sim` and `analyze`, as a user meets it: the version with its
//! commit, the shared flags, strict subcommands with a suggestion, `-f json` wherever it is
//! offered, shell completions and man pages, and the exit statuses (0 done, 1 a failure to see,
//! 2 bad input).

use std::process::Output;

fn tool(name: &str, args: &[&str]) -> Output {
    if name == "sim" {
        crate::run_sim(args)
    } else {
        crate::run_analyze(args)
    }
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn both_tools_print_their_version_with_the_commit() {
    for name in ["sim", "analyze"] {
        let o = tool(name, &["--version"]);
        assert!(o.status.success());
        let v = stdout(&o);
        assert!(v.starts_with(&format!("{name} {} (commit ", env!("CARGO_PKG_VERSION"))), "{v}");
    }
}

#[test]
fn a_mistyped_command_is_bad_input_with_a_suggestion() {
    for (name, typo, meant) in [("sim", "chek", "check"), ("analyze", "comapre", "compare")] {
        let o = tool(name, &[typo, "x.json"]);
        assert_eq!(o.status.code(), Some(2), "{name} {typo}");
        assert!(stderr(&o).contains(meant), "{}", stderr(&o));
        assert!(o.stdout.is_empty());
    }
    // a scene is given by `run SCENE` or `--scene`, never read from a stray word
    let o = tool("sim", &["my-scene.json"]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn shared_flags_mean_the_same_in_both_tools() {
    for (name, cmd) in [("sim", "run"), ("sim", "sweep"), ("analyze", "compare"), ("analyze", "summary")] {
        let help = stdout(&tool(name, &[cmd, "--help"]));
        for flag in ["-f, --format <FORMAT>", "[possible values: table, json, csv]", "-q, --quiet", "-v, --verbose..."] {
            assert!(help.contains(flag), "{name} {cmd}: {flag:?} not in\n{help}");
        }
    }
    for (name, cmd) in [("sim", "run"), ("sim", "sweep"), ("analyze", "summary")] {
        assert!(stdout(&tool(name, &[cmd, "--help"])).contains("-j, --jobs <N>"), "{name} {cmd}");
    }
    for (name, cmd) in [("sim", "run"), ("sim", "replay"), ("sim", "precision"), ("analyze", "report"), ("analyze", "figures"), ("analyze", "export"), ("analyze", "layout")] {
        assert!(stdout(&tool(name, &[cmd, "--help"])).contains("-o, --out <DIR>"), "{name} {cmd}");
    }
    // every command's help says what it outputs and gives examples
    for (name, cmds) in [
        ("sim", &["run", "check", "replay", "sweep", "precision", "export-scene", "schema"][..]),
        ("analyze", &["compare", "metrics", "summary", "diff", "report", "figures", "export", "layout"][..]),
    ] {
        for cmd in cmds {
            let help = stdout(&tool(name, &[cmd, "--help"]));
            assert!(help.contains("Output:") && help.contains("Example"), "{name} {cmd}:\n{help}");
        }
    }
}

#[test]
fn json_is_honoured_where_it_is_offered() {
    let o = tool("sim", &["check", "-f", "json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let d: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(d["scene"], "paper");
    assert_eq!(d["joints"].as_array().unwrap().len(), 10);
    assert_eq!(d["integrator"]["method"], "dopri45");
    let sweep = concat!(env!("CARGO_MANIFEST_DIR"), "/sim/scenes/sweeps/paper-gains.json");
    let o = tool("sim", &["sweep", sweep, "--dry-run", "-f", "json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let d: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(d["variants"].as_array().unwrap().len(), d["grid_size"].as_u64().unwrap() as usize);
    // sim check for people: no Rust debug output
    let text = stdout(&tool("sim", &["check"]));
    assert!(text.contains("is valid") && text.contains("dopri45 rtol 1e-8") && !text.contains("Dopri45(") && !text.contains("{ "), "{text}");
}

#[test]
fn completions_and_man_pages_come_from_the_command_definitions() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["sim", "analyze"] {
        let o = tool(name, &["completions", "bash"]);
        assert!(o.status.success());
        let script = stdout(&o);
        assert!(script.contains(&format!("_{name}")) && script.contains("completions"), "{name}");
        let out = dir.path().join(name);
        let o = tool(name, &["man", "-o", out.to_str().unwrap(), "-q"]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(out.join(format!("{name}.1")).is_file());
        let sub = if name == "sim" { "sim-run.1" } else { "analyze-compare.1" };
        let page = std::fs::read_to_string(out.join(sub)).unwrap();
        assert!(page.contains(".TH") && page.contains("\\-\\-format"), "{sub}");
    }
    let o = tool("sim", &["completions", "tcsh"]);
    assert_eq!(o.status.code(), Some(2), "an unknown shell is a usage error");
}
