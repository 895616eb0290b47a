//! What a crash leaves is usable (issue 29, item 7): a `sim` run killed mid-run (the hidden
//! `.NAME.<pid>-<n>.partial` it leaves) and a complete recording cut at 90 % and at 50 % of its
//! bytes give `analyze metrics --recover` the metrics of the intact run restricted to the
//! recovered interval `[0, t_end]`, exactly: the same samples, summed in the same order (the
//! reference streams the intact file through the same reductions, dropping every message after
//! `t_end`). Before the writer's flush groups, `/hand` reached the file only at the end of a
//! run, and every one of these refused with "no topic /hand" (exit 2).

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use analyze::metrics::METRIC_TOPICS;
use analyze::{Reductions, RunMetrics};

use super::run_analyze;

/// Simulated time of the runs, s (the paper's path is timed by the scene, not by the duration).
const DURATION: &str = "10";

/// The paper's two-elbow run, `DURATION` s, into `dir`; its recording.
fn intact_run(dir: &Path) -> PathBuf {
    let out = super::run_sim(&["run", "--run", "two-elbow", "-o", dir.to_str().unwrap(), "-j", "1", "--quiet", "-f", "csv", "--duration", DURATION]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    dir.join("paper-two-elbow.mcap")
}

/// Metrics of `intact` restricted to the messages logged at or before `t_end_ns`.
fn restricted(intact: &Path, t_end_ns: u64) -> RunMetrics {
    struct Upto(Reductions, u64);
    impl schemas::Visitor for Upto {
        fn message(&mut self, m: schemas::DecodedMessage<'_>) -> Result<(), schemas::Error> {
            if m.log_time_ns <= self.1 {
                self.0.message(m)?;
            }
            Ok(())
        }
        fn typed(&self) -> bool {
            self.0.typed()
        }
        fn metadata(&mut self, name: &str, entries: &std::collections::BTreeMap<String, String>) {
            self.0.metadata(name, entries);
        }
    }
    let mut v = Upto(Reductions::default(), t_end_ns);
    let rec = schemas::stream_recording(intact, Some(&METRIC_TOPICS), &mut v).unwrap();
    v.0.finish(&rec, Some("restricted".into())).unwrap()
}

/// `analyze metrics --recover damaged -f json`: incomplete (exit 1), every topic up to one time
/// (the warning says so), and equal to the intact run's metrics over `[0, t_end]` but for the
/// file name and the reason. The recovered end, s.
fn check_recovered(damaged: &Path, intact: &Path) -> f64 {
    let out = run_analyze(&["metrics".as_ref(), "--recover".as_ref(), damaged.as_os_str(), "-f".as_ref(), "json".as_ref()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{}: {stderr}", damaged.display());
    assert!(stderr.contains("damaged recording") && stderr.contains("every topic up to it"), "{stderr}");
    let got: Vec<RunMetrics> = serde_json::from_slice(&out.stdout).unwrap();
    let got = &got[0];
    assert_eq!(got.status, analyze::Status::Incomplete, "{stderr}");
    assert!(got.samples > 100, "{stderr}");
    // the end of the recovered interval, as the reader saw it (the JSON rounds nothing: it is
    // the last /hand sample's own log time)
    let (_, report) = analyze::read_run_metrics_recover(damaged).unwrap();
    let t_end_ns = report.t_end_ns.unwrap();
    assert!(report.aligned && !report.complete, "{report}");
    let t_end_s = got.t_end_s.expect("a recovered run with samples has an end time");
    assert_eq!(schemas::to_log_time(t_end_s), t_end_ns, "{report}");
    let want = restricted(intact, t_end_ns);
    let strip = |m: &RunMetrics| {
        let mut v = serde_json::to_value(m).unwrap();
        let o = v.as_object_mut().unwrap();
        for k in ["file", "status", "error", "error_time_s"] {
            o.remove(k);
        }
        v
    };
    assert_eq!(strip(got), strip(&want), "{}: recovered metrics differ from the intact run's over [0, {} s]", damaged.display(), t_end_s);
    t_end_s
}

/// A complete recording cut at 90 % and at 50 % of its bytes: the metrics up to the last flush
/// group before the cut, which loses at most ~1 s of log time (groups close every simulated
/// second, and earlier when a topic's chunk is full) beyond the share of the bytes.
#[test]
fn a_recording_cut_at_90_and_50_percent_gives_the_metrics_of_its_intact_part() {
    let dir = tempfile::tempdir().unwrap();
    let intact = intact_run(&dir.path().join("intact"));
    let bytes = std::fs::read(&intact).unwrap();
    let duration: f64 = DURATION.parse().unwrap();
    for percent in [90, 50] {
        let cut = dir.path().join(format!("cut{percent}.mcap"));
        std::fs::write(&cut, &bytes[..bytes.len() * percent / 100]).unwrap();
        let t_end = check_recovered(&cut, &intact);
        let share = duration * f64::from(percent as u32) / 100.0;
        assert!(t_end > share - 1.5 && t_end < share, "cut at {percent} %: recovered to {t_end} s");
    }
}

/// A `sim` process SIGKILLed mid-run (once its hidden `.partial` holds 3 MB, ~2 s of the 10):
/// the `.partial` it leaves gives the metrics up to its last complete flush group.
#[test]
fn a_killed_sim_leaves_a_partial_file_that_recovers() {
    let dir = tempfile::tempdir().unwrap();
    let intact = intact_run(&dir.path().join("intact"));
    let killed_dir = dir.path().join("killed");
    let mut child = Command::new(env!("CARGO_BIN_EXE_sim"))
        .args(["run", "--run", "two-elbow", "-o", killed_dir.to_str().unwrap(), "-j", "1", "--quiet", "-f", "csv", "--duration", DURATION])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let partial = |d: &Path| -> Option<PathBuf> {
        std::fs::read_dir(d).ok()?.flatten().map(|e| e.path()).find(|p| p.extension().is_some_and(|x| x == "partial"))
    };
    let start = Instant::now();
    let file = loop {
        if let Some(p) = partial(&killed_dir).filter(|p| std::fs::metadata(p).is_ok_and(|m| m.len() > 3_000_000)) {
            break p;
        }
        assert!(child.try_wait().unwrap().is_none(), "sim finished before it could be killed");
        assert!(start.elapsed() < Duration::from_secs(120), "no .partial of 3 MB after 120 s");
        std::thread::sleep(Duration::from_millis(2));
    };
    child.kill().unwrap(); // SIGKILL
    assert!(!child.wait().unwrap().success());
    // the kill left the hidden file, never the final name
    assert!(!killed_dir.join("paper-two-elbow.mcap").exists());
    let name = file.file_name().unwrap().to_str().unwrap().to_string();
    assert!(name.starts_with(".paper-two-elbow.mcap.") && name.ends_with(".partial"), "{name}");
    let t_end = check_recovered(&file, &intact);
    assert!((0.5..10.0).contains(&t_end), "recovered to {t_end} s");
}
