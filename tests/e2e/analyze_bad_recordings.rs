//! Damaged and foreign recordings through the `analyze` binary and library: a clear error
//! naming the file and no panic; `--recover` reads the intact part of a truncated file.

use crate::run_analyze;
use std::path::Path;

use schemas::synth::Synth;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A valid small recording: 2 joints, 1 contact, 400 samples at 1 kHz, chunks of 4 KiB.
fn small() -> Synth {
    let mut s = Synth::new("one-elbow", &["elbow4"], 2);
    (s.dt, s.n, s.chunk_size) = (1e-3, 399, Some(4096));
    s
}

/// Truncated, bit-flipped, empty, non-MCAP, wrong-schema and metadata-less files: bad input,
/// exit status 2, the file and what is wrong with it on stderr, nothing on stdout, no panic.
#[test]
fn damaged_and_foreign_files_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let good = small().write(&dir.path().join("good.mcap"));
    let bytes = std::fs::read(&good).unwrap();
    let put = |name: &str, b: &[u8]| {
        let p = dir.path().join(name);
        std::fs::write(&p, b).unwrap();
        p
    };
    let truncated = put("truncated.mcap", &bytes[..bytes.len() * 2 / 3]);
    let mut flipped = bytes.clone();
    flipped[bytes.len() / 3] ^= 0x10;
    let flipped = put("flipped.mcap", &flipped);
    let empty = put("empty.mcap", b"");
    let text = put("text.mcap", b"{\"not\": \"mcap\"}");
    let magic_only = put("magic.mcap", b"\x89MCAP0\r\n");
    // a HandState on /motors: a schema without `current`
    let wrong_schema = dir.path().join("wrong-schema.mcap");
    let mut w = schemas::RecordingWriter::create(&wrong_schema).unwrap();
    w.write_record(small().names.as_ref().unwrap()).unwrap();
    w.write_record(&schemas::RunResult::complete(0, 0, 0)).unwrap();
    w.write(schemas::topics::HAND, 0, &schemas::HandState::default()).unwrap();
    w.write(schemas::topics::MOTORS, 0, &schemas::HandState::default()).unwrap();
    w.finish().unwrap();
    let mut synth = small();
    synth.names = None;
    let no_run = synth.write(&dir.path().join("no-run.mcap"));
    let mut synth = small();
    synth.result = None;
    let no_result = synth.write(&dir.path().join("no-result.mcap"));
    let mut synth = small();
    (synth.hand, synth.motors, synth.constraints, synth.energy) = (None, None, None, None);
    let no_samples = synth.write(&dir.path().join("no-samples.mcap"));
    let cases: [(&Path, &str); 9] = [
        (
            &truncated,
            "unreadable MCAP: MCAP file ended in the middle of a record",
        ),
        (&flipped, "unreadable MCAP"),
        (&empty, "not an MCAP file (0 bytes"),
        (&text, "not an MCAP file"),
        (&magic_only, "MCAP"),
        (&wrong_schema, "topic /motors: message #0 (log_time 0 ns): missing field `current`"),
        (&no_run, "metadata record `run`: the recording has no such record"),
        (&no_result, "metadata record `result`: the recording has no such record"),
        (&no_samples, "/hand"),
    ];
    for (path, want) in cases {
        for cmd in ["metrics", "compare"] {
            let out = run_analyze(&[cmd, s(path)]);
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{cmd} {}: {stderr}", path.display());
            assert!(stderr.starts_with("analyze: error: "), "{stderr}");
            assert!(stderr.contains(s(path)), "{stderr}");
            assert!(stderr.contains(want), "{want:?} not in {stderr}");
            assert!(
                !stderr.contains("panicked") && out.stdout.is_empty(),
                "{stderr}"
            );
            // each cause once
            assert!(
                !stderr.contains("record: MCAP file ended in the middle of a record"),
                "{stderr}"
            );
        }
    }
    // --recover does not make a foreign or empty file readable
    for path in [&empty, &text] {
        let out = run_analyze(&["metrics", "--recover", s(path)]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert!(
            stderr.contains(s(path)) && stderr.contains("not an MCAP file"),
            "{stderr}"
        );
    }
    // ... nor one whose damage starts before the metadata
    let out = run_analyze(&["metrics", "--recover", s(&magic_only)]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("damaged recording") && stderr.contains("recovered 0 messages") && stderr.contains("no such record"),
        "{stderr}"
    );
}

fn metrics_json(args: &[&str], code: i32) -> (serde_json::Value, String) {
    let out = run_analyze(args);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(code), "{args:?}: {stderr}");
    (serde_json::from_slice(&out.stdout).unwrap(), stderr)
}

/// `metrics --recover` on a truncated file: the metrics of what survived with exit 1 (numbers
/// from a damaged file are never a plain success), a warning naming the file and the byte
/// offset, status `incomplete`, fewer samples ending at the last recovered one; an intact file
/// gives exactly what it gives without `--recover`, without a warning, exit 0; `compare
/// --recover` works with a mix of intact and damaged files (exit 1).
#[test]
fn recover_reads_the_intact_part() {
    let dir = tempfile::tempdir().unwrap();
    let good = small().write(&dir.path().join("good.mcap"));
    let bytes = std::fs::read(&good).unwrap();
    let (plain, _) = metrics_json(&["metrics", s(&good), "-f", "json"], 0);
    let (recovered, stderr) = metrics_json(&["metrics", "--recover", s(&good), "-f", "json"], 0);
    assert_eq!(plain, recovered);
    assert!(stderr.is_empty(), "{stderr}");

    let cut = dir.path().join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let (m, stderr) = metrics_json(&["metrics", "--recover", s(&cut), "-f", "json"], 1);
    assert!(
        stderr.starts_with(&format!(
            "analyze: warning: {}: damaged recording: stopped at byte ",
            cut.display()
        )),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"));
    let run = &m[0];
    assert_eq!(run["status"], "incomplete");
    assert!(
        run["error"]
            .as_str()
            .unwrap()
            .starts_with("recording damaged, stops at byte "),
        "{run}"
    );
    let samples = run["samples"].as_u64().unwrap();
    assert!(samples > 10 && samples < 400, "{samples}");
    assert_eq!(
        run["t_end_s"].as_f64().unwrap(),
        (samples - 1) as f64 * 1e-3
    );
    // W_1 = t at the last /energy sample recovered
    let w1 = run["links"][0]["work_j"].as_f64().unwrap();
    assert!(
        w1 > 0.0 && w1 <= run["t_end_s"].as_f64().unwrap() + 1e-12,
        "{w1}"
    );

    let out = run_analyze(&["compare", "--recover", s(&good), s(&cut)]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("is incomplete (recovered from a damaged recording)"),
        "{stdout}"
    );
    // without --recover the cut file is an error
    let out = run_analyze(&["compare", s(&good), s(&cut)]);
    assert_eq!(out.status.code(), Some(2));
}

/// The library: metrics of the recovered part equal the metrics of a recording holding only
/// the recovered messages (same values), for cuts at many offsets.
#[test]
fn recovered_metrics_are_the_metrics_of_the_prefix() {
    let dir = tempfile::tempdir().unwrap();
    let good = small().write(&dir.path().join("good.mcap"));
    let bytes = std::fs::read(&good).unwrap();
    let full = schemas::read_recording_bytes(&bytes, "full").unwrap();
    let mut ok = 0;
    for k in 1..40 {
        let cut = k * bytes.len() / 40;
        let (rec, report) =
            schemas::read_recording_recover_bytes(&bytes[..cut], "cut.mcap").unwrap();
        let Ok(m) = analyze::run_metrics_recovered(&rec, &report) else {
            continue; // too little survived (e.g. no /energy message yet)
        };
        ok += 1;
        // the same metrics from the full recording with every topic cut to the recovered count
        let prefix = schemas::synth::prefix_like(&full, &rec);
        if rec.result().unwrap().is_none() {
            assert_eq!(m.status, analyze::Status::Incomplete);
        }
        let mut expect = analyze::run_metrics_recovered(&prefix, &report).unwrap();
        expect.file = m.file.clone();
        assert_eq!(m, expect, "cut at {cut}");
        assert_eq!(m.samples, rec.read::<schemas::HandState>().unwrap().len());
    }
    assert!(ok > 25, "{ok} cuts gave metrics");
}

/// A run that failed at t = 0 (nine rigid contacts closed, over the limit of 8): the recording
/// has its `run` and `result` records and no samples. `view`, `export`, `figures` and `layout`
/// read it (issue 29: before, every command refused it with "no topic /hand"), name the file,
/// the status and the reason on stderr, write what there is, and exit 1 (a failed run is a
/// result to see); a directory with it and a good run does both, exit 1.
#[test]
fn a_run_that_failed_at_t0_reads_with_its_status_and_reason() {
    let dir = tempfile::tempdir().unwrap();
    let runs = dir.path().join("runs");
    std::fs::create_dir(&runs).unwrap();
    let reason = "9 rigid contacts closed at once, more than the limit of 8";
    let mut synth = small();
    (synth.hand, synth.motors, synth.constraints, synth.energy) = (None, None, None, None);
    synth.result = Some(schemas::RunResult::failed(reason.into(), Some(0.0)));
    let failed = synth.write(&runs.join("failed.mcap"));
    small().write(&runs.join("good.mcap"));
    let out = dir.path().join("out");
    let (f, o) = (s(&failed), out.to_str().unwrap());
    for (args, made) in [
        (vec!["export", f, "-o", o, "-f", "csv"], out.join("failed").join("metadata.json")),
        (vec!["figures", f, "-o", o], out.join("index.html")),
        (vec!["layout", f, "-o", o], out.clone()),
        (vec!["view", f], runs.join("failed.rrd")),
    ] {
        let res = run_analyze(&args);
        let stderr = String::from_utf8_lossy(&res.stderr);
        assert_eq!(res.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(stderr.contains(f) && stderr.contains("failed") && stderr.contains(reason), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked") && !stderr.contains("error:"), "{args:?}: {stderr}");
        assert!(made.exists(), "{args:?}: {} not written", made.display());
    }
    let res = run_analyze(&["figures", runs.to_str().unwrap(), "-o", out.join("both").to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&res.stderr);
    assert_eq!(res.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains(reason) && out.join("both").join("index.html").is_file(), "{stderr}");
}
