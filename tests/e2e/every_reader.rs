//! One guard for every reader (issue 29): every `analyze` command that opens a recording,
//! enumerated from `analyze --help` so that a new command cannot be forgotten, refuses the
//! adversarial inputs promptly, in bounded memory, with exit status 2 and the file named: a
//! 200 MB and a 20 GB sparse file without the MCAP magic (as `.mcap` and, for `diff`'s tables,
//! as `.csv`), a `.mcap` link to `/dev/zero`, a FIFO without a writer, a directory and a
//! truncated recording. Before the fix `view` and `diff` read the whole input first (212 MB and
//! 1.4 GB for the 200 MB file, until memory ran out for `/dev/zero`) and blocked forever on the
//! FIFO.
//!
//! Directory commands report every input they leave out (a dangling or looping `*.mcap` link, a
//! file that does not read), go on with the others and exit 1; an export directory is
//! marked `INCOMPLETE` until it is finished, also on a full disk.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use schemas::synth::Synth;

use crate::run_analyze;

/// Address-space limit of every adversarial run (as `bounded_memory.rs`): 200 MB.
const LIMIT_KB: u64 = 200_000;
/// A refusal must come within this (a blocked or memory-bound reader is killed at it).
const PROMPT: Duration = Duration::from_secs(20);
/// Commands that open no recording (each must say so in its help).
const NOT_READERS: [&str; 3] = ["completions", "man", "help"];

/// The commands of `analyze --help`, in order.
fn commands() -> Vec<String> {
    let out = run_analyze(&["--help"]);
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    let list = text.split("Commands:\n").nth(1).expect("a Commands section");
    list.lines().take_while(|l| !l.trim().is_empty()).filter_map(|l| l.split_whitespace().next().map(str::to_string)).collect()
}

/// `analyze CMD --help`.
fn help(cmd: &str) -> String {
    String::from_utf8_lossy(&run_analyze(&[cmd, "--help"]).stdout).into_owned()
}

/// Runs `analyze args…` under the address-space limit, killed after [`PROMPT`]: the output and
/// how long it took.
fn limited(args: &[String]) -> (std::process::Output, Duration) {
    let started = Instant::now();
    let out = Command::new("timeout")
        .args(["-s", "KILL", &PROMPT.as_secs().to_string(), "sh", "-c", &format!("ulimit -v {LIMIT_KB} && exec \"$0\" \"$@\"")])
        .arg(env!("CARGO_BIN_EXE_analyze"))
        .args(args)
        .output()
        .expect("timeout and sh start");
    (out, started.elapsed())
}

/// A valid small recording: 2 joints, 1 contact, 400 samples at 1 kHz.
fn small(name: &str) -> Synth {
    let mut s = Synth::new(name, &["elbow4"], 2);
    (s.dt, s.n, s.chunk_size) = (1e-3, 399, Some(4096));
    s
}

/// The adversarial inputs, made in `dir`: `(path, what it is)`.
fn adversarial(dir: &Path) -> Vec<(PathBuf, &'static str)> {
    let sparse = |name: &str, len: u64| {
        let p = dir.join(name);
        std::fs::File::create(&p).unwrap().set_len(len).unwrap();
        p
    };
    let good = small("good").write(&dir.join("intact.mcap"));
    let bytes = std::fs::read(&good).unwrap();
    let truncated = dir.join("truncated.mcap");
    std::fs::write(&truncated, &bytes[..bytes.len() * 2 / 3]).unwrap();
    let zero = dir.join("zero.mcap");
    std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
    let fifo = dir.join("fifo.mcap");
    let made = Command::new("mkfifo").arg(&fifo).status().expect("mkfifo starts");
    assert!(made.success());
    let directory = dir.join("empty-dir.mcap");
    std::fs::create_dir(&directory).unwrap();
    vec![
        (sparse("sparse-200mb.mcap", 200_000_000), "a 200 MB sparse file without the MCAP magic"),
        (sparse("sparse-20gb.mcap", 20_000_000_000), "a 20 GB sparse file without the MCAP magic"),
        (sparse("sparse-200mb.csv", 200_000_000), "a 200 MB sparse file named as a table"),
        (zero, "a .mcap link to /dev/zero"),
        (fifo, "a FIFO without a writer"),
        (directory, "a directory"),
        (truncated, "a truncated recording"),
    ]
}

/// Every command that reads recordings, given each adversarial input (for `diff` as A and as
/// B, the other side a good recording): exit 2 within [`PROMPT`] under 200 MB, the file named
/// on stderr, nothing on stdout, no panic.
#[test]
fn every_command_that_reads_recordings_refuses_adversarial_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = adversarial(dir.path());
    let good = small("good").write(&dir.path().join("good.mcap"));
    let cmds = commands();
    assert!(cmds.len() >= 11, "{cmds:?}");
    let mut tried = 0;
    for cmd in &cmds {
        let h = help(cmd);
        let arguments = h.split("Arguments:").nth(1).map(|a| a.split("Options:").next().unwrap_or(a)).unwrap_or("");
        let reads = arguments.to_lowercase().contains("recording");
        assert_eq!(
            reads,
            !NOT_READERS.contains(&cmd.as_str()),
            "`analyze {cmd}`: its arguments {} recordings, but NOT_READERS says otherwise: {arguments}",
            if reads { "name" } else { "do not name" }
        );
        if !reads {
            continue;
        }
        let out_dir = dir.path().join(format!("out-{cmd}.rrd"));
        let mut variants: Vec<Vec<String>> = vec![vec![]];
        if h.contains("--recover") {
            variants.push(vec!["--recover".into()]);
        }
        for (bad, what) in &inputs {
            let b = bad.display().to_string();
            let g = good.display().to_string();
            let positions: Vec<Vec<String>> =
                if cmd == "diff" { vec![vec![b.clone(), g.clone()], vec![g.clone(), b.clone()]] } else { vec![vec![b.clone()]] };
            for flags in &variants {
                if flags.iter().any(|f| f == "--recover") && *what == "a truncated recording" {
                    continue; // --recover reads its intact part (exit 1): analyze_bad_recordings.rs
                }
                for pos in &positions {
                    let mut args = vec![cmd.clone()];
                    args.extend(flags.iter().cloned());
                    args.extend(pos.iter().cloned());
                    if h.contains("--out") {
                        args.extend(["-o".to_string(), out_dir.display().to_string()]);
                    }
                    let (out, took) = limited(&args);
                    let stderr = String::from_utf8_lossy(&out.stderr);
                    assert_eq!(out.status.code(), Some(2), "analyze {args:?} on {what}: took {took:?}, stderr: {stderr}");
                    assert!(took < PROMPT, "analyze {args:?} on {what}: {took:?}");
                    assert!(stderr.contains(&b), "analyze {args:?} on {what}: the file is not named: {stderr}");
                    assert!(!stderr.contains("panicked") && out.stdout.is_empty(), "analyze {args:?} on {what}: {stderr}");
                    tried += 1;
                }
            }
        }
    }
    assert!(tried >= 9 * 7, "{tried} runs");
}

/// A directory with a good recording, a dangling and a looping `*.mcap` link and a file that is
/// not a recording: `export`, `figures`, `layout` and `view` name each input they leave out and
/// why, do the good one, and exit 1 (not 2 for the lot).
#[test]
fn directory_commands_name_what_they_leave_out_and_go_on() {
    let dir = tempfile::tempdir().unwrap();
    let runs = dir.path().join("runs");
    std::fs::create_dir(&runs).unwrap();
    small("good").write(&runs.join("good.mcap"));
    std::fs::write(runs.join("text.mcap"), "not a recording").unwrap();
    std::os::unix::fs::symlink(runs.join("gone.mcap"), runs.join("dangling.mcap")).unwrap();
    std::os::unix::fs::symlink(runs.join("loop-b.mcap"), runs.join("loop-a.mcap")).unwrap();
    std::os::unix::fs::symlink(runs.join("loop-a.mcap"), runs.join("loop-b.mcap")).unwrap();
    let r = runs.display().to_string();
    let out = dir.path().join("out");
    let o = out.display().to_string();
    for (args, made) in [
        (vec!["export", &r, "-o", &o, "-f", "csv"], out.join("good").join("metadata.json")),
        (vec!["export", &r, "-o", &o, "-f", "parquet"], out.join("good").join("hand.parquet")),
        (vec!["figures", &r, "-o", &o], out.join("index.html")),
        (vec!["layout", &r, "-o", &o], out.join("layouts")),
        (vec!["view", &r], runs.join("good.rrd")),
    ] {
        let res = run_analyze(&args);
        let stderr = String::from_utf8_lossy(&res.stderr);
        assert_eq!(res.status.code(), Some(1), "{args:?}: {stderr}");
        for name in ["dangling.mcap", "loop-a.mcap", "loop-b.mcap", "text.mcap"] {
            assert!(stderr.contains(&runs.join(name).display().to_string()), "{args:?}: {name} not named: {stderr}");
        }
        assert!(stderr.contains("skipped: a link to") && stderr.contains("not an MCAP file"), "{args:?}: {stderr}");
        let written = match made.file_name().and_then(|n| n.to_str()) {
            // the layout's name is the scene's: any one
            Some("layouts") => std::fs::read_dir(&out).unwrap().any(|e| e.unwrap().file_name().to_string_lossy().ends_with(".foxglove-layout.json")),
            _ => made.is_file(),
        };
        assert!(written, "{args:?}: {} not written: {stderr}", made.display());
        assert!(!out.join("good").join("INCOMPLETE").exists(), "{args:?}: a finished export is marked incomplete");
    }
}

/// A full disk during `analyze export`: exit 2 naming the file and "No space left on device",
/// and the directory `OUT/<name>` marked `INCOMPLETE` (before the fix the tables written before
/// the disk filled stayed, without `metadata.json` and unmarked). The disk is a tmpfs half the size
/// of the export, mounted in a private namespace (`unshare -rm`); where that is not available
/// the test says so and checks nothing.
#[test]
fn an_export_directory_on_a_full_disk_is_marked_incomplete() {
    let probe = Command::new("unshare").args(["-rm", "sh", "-c", "mount -t tmpfs -o size=64k tmpfs /tmp && echo ok"]).output();
    if !probe.is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "ok") {
        eprintln!("skipped: `unshare -rm` with a tmpfs mount is not available here");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let mut s = small("long");
    s.n = 20_000;
    let rec = s.write(&dir.path().join("long.mcap"));
    // the size of the whole export, on a disk with room
    let room = dir.path().join("room");
    let res = run_analyze(&["export", rec.to_str().unwrap(), "-o", room.to_str().unwrap(), "-f", "csv", "-q"]);
    assert_eq!(res.status.code(), Some(0), "{}", String::from_utf8_lossy(&res.stderr));
    let total: u64 = std::fs::read_dir(room.join("long")).unwrap().map(|e| e.unwrap().metadata().unwrap().len()).sum();
    assert!(total > 200_000, "{total} bytes");
    let full = dir.path().join("full");
    std::fs::create_dir(&full).unwrap();
    let d = full.display();
    let script = format!(
        "mount -t tmpfs -o size={kb}k tmpfs '{d}' && '{analyze}' export '{rec}' -o '{d}' -f csv -q; echo \"exit=$?\"; ls -A '{d}'; ls -A '{d}/long' 2>/dev/null",
        kb = total / 2 / 1024,
        analyze = env!("CARGO_BIN_EXE_analyze"),
        rec = rec.display()
    );
    let o = Command::new("unshare").args(["-rm", "sh", "-c", &script]).output().unwrap();
    let (out, err) = (String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    let mut lines = out.lines();
    assert_eq!(lines.next(), Some("exit=2"), "stdout {out}, stderr {err}");
    let left: Vec<&str> = lines.collect();
    assert!(left.contains(&"long") && left.contains(&"INCOMPLETE"), "a partial export was left unmarked: {left:?}; stderr {err}");
    assert!(err.contains("No space left on device") && err.contains(&rec.display().to_string()), "{err}");
}
