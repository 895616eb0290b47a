//! The writer's guarantees: byte-identical output for identical input, no file at `path`
//! unless `finish` succeeded, no leftover temporary file, one writer per path at a time, I/O
//! errors and misuse reported with the file named (and the OS reason).


use std::collections::BTreeMap;

use crate::common::{content, write_all};
use schemas::{read_recording, topics, EnergyState, HandState, MotorState, RecordingWriter};

#[test]
fn identical_runs_give_identical_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let c = content(3000); // > 1 MiB uncompressed: several zstd chunks
    let a = write_all(&dir.path().join("a.mcap"), &c);
    let b = write_all(&dir.path().join("b.mcap"), &c);
    let (a, b) = (std::fs::read(a).unwrap(), std::fs::read(b).unwrap());
    let summary = mcap::Summary::read(&a).unwrap().unwrap();
    assert!(
        summary.chunk_indexes.len() >= 2,
        "{} chunks",
        summary.chunk_indexes.len()
    );
    assert!(summary
        .chunk_indexes
        .iter()
        .all(|c| c.compression == "zstd"));
    assert!(a == b, "recordings differ");
    // and the header names our library, not the mcap crate version
    let library = format!("elbow-sim schemas {}", schemas::FORMAT_VERSION);
    assert!(a.windows(library.len()).any(|w| w == library.as_bytes()));
}

#[test]
fn dropped_writer_leaves_nothing_and_finish_leaves_only_path() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.mcap");
    let listing = || {
        let mut v: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    };

    // dropped mid-run: the temp file existed while writing, afterwards nothing remains
    {
        let mut w = RecordingWriter::create(&path).unwrap();
        w.write(topics::MOTORS, 0, &MotorState::default()).unwrap();
        // its own temporary name, and the lock of the final name (schemas::atomic)
        let temp = w.temp_path().file_name().unwrap().to_string_lossy().into_owned();
        let expected = format!(".run.mcap.{}-", std::process::id());
        assert!(temp.starts_with(&expected) && temp.ends_with(".partial"), "{temp}");
        assert_eq!(listing(), [temp, ".run.mcap.lock".to_string()]);
        assert!(!path.exists());
    }
    assert!(listing().is_empty(), "{:?}", listing());

    // panicking mid-run: same
    let p2 = path.clone();
    let result = std::panic::catch_unwind(move || {
        let mut w = RecordingWriter::create(&p2).unwrap();
        w.write(topics::HAND, 5, &HandState::default()).unwrap();
        panic!("simulated failure");
    });
    assert!(result.is_err());
    assert!(listing().is_empty(), "{:?}", listing());

    // stale temp files from killed runs (this version's names and the older fixed one) and a
    // stale lock file are removed, and finish leaves only `path`
    for stale in [".run.mcap.partial", ".run.mcap.4242-0.partial", ".run.mcap.lock"] {
        std::fs::write(dir.path().join(stale), b"garbage from a killed run").unwrap();
    }
    let mut w = RecordingWriter::create(&path).unwrap();
    w.write(topics::MOTORS, 0, &MotorState::default()).unwrap();
    assert_eq!(w.finish().unwrap(), path);
    assert_eq!(listing(), ["run.mcap"]);
    assert_eq!(read_recording(&path).unwrap().messages("/motors").unwrap().len(), 1);

    // an abandoned second run never touches the finished recording
    let before = std::fs::read(&path).unwrap();
    {
        let mut w = RecordingWriter::create(&path).unwrap();
        w.write(
            topics::MOTORS,
            0,
            &MotorState {
                time: 1.0,
                ..Default::default()
            },
        )
        .unwrap();
    }
    assert_eq!(std::fs::read(&path).unwrap(), before);
    assert_eq!(listing(), ["run.mcap"]);
}

#[test]
fn writer_rejects_misuse_with_errors_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.mcap");
    let mut w = RecordingWriter::create(&path).unwrap();
    w.write(topics::MOTORS, 0, &MotorState::default()).unwrap();
    let e = w
        .write(topics::MOTORS, 1, &HandState::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("m.mcap") && e.contains("/motors") && e.contains("HandState"),
        "{e}"
    );
    let mut bad = BTreeMap::new();
    bad.insert("format_version".to_string(), "99".to_string());
    let e = w.write_metadata_raw("recording", &bad).unwrap_err().to_string();
    assert!(e.contains("format_version") && e.contains("99"), "{e}");
    drop(w);
    let e = RecordingWriter::create(&dir.path().join("no_such_dir/x.mcap"))
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("no_such_dir"), "{e}");
}

#[test]
fn format_version_is_written_even_without_a_recording_record() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("v.mcap");
    let mut w = RecordingWriter::create(&path).unwrap();
    w.write(topics::ENERGY, 0, &EnergyState::default()).unwrap();
    w.finish().unwrap();
    let r = read_recording(&path).unwrap();
    assert_eq!(r.metadata_records().get("recording").and_then(|m| m.get("format_version")).map(String::as_str), Some(schemas::FORMAT_VERSION.to_string().as_str()));
    assert_eq!(r.metadata_records().len(), 1);
}
