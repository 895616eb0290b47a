//! The long-run memory check: `analyze metrics`, `summary` and `metrics --recover` read a long
//! recording in bounded memory. The recording is synthetic (`schemas::synth`, 300 000 samples of
//! the four metric topics, 300 s at 1 kHz) and the commands run under an address-space limit
//! (`ulimit -v`) of 200 MB: a reader that holds the decoded messages needs several GB for it and
//! is killed by the limit (the reader before issue 12 took 2 GB on a 60 s run); the streamed
//! reader needs about 10 MB of heap (BENCHMARKS.md, "Peak memory"). The metrics must still be
//! right: the sample count and the peak current of the known signal.

use schemas::synth::Synth;

/// Runs `analyze args…` with an address-space limit of `limit_kb`.
fn analyze_limited(limit_kb: u64, args: &[&str]) -> std::process::Output {
    let cmd = format!("ulimit -v {limit_kb} && exec \"$0\" \"$@\"");
    std::process::Command::new("sh")
        .arg("-c")
        .arg(cmd)
        .arg(env!("CARGO_BIN_EXE_analyze"))
        .args(args)
        .output()
        .expect("sh starts")
}

#[test]
fn long_recordings_are_read_in_bounded_memory() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = Synth::new("long", &["elbow"], 3);
    (s.dt, s.n) = (1e-3, 300_000);
    let s = s.with_setup();
    let path = s.write_in(dir.path());
    let bytes = std::fs::metadata(&path).unwrap().len();
    let p = path.to_str().unwrap();
    for args in [vec!["metrics", p, "-f", "json"], vec!["metrics", "--recover", p, "-f", "json"], vec!["summary", p, "-f", "json"]] {
        let out = analyze_limited(200_000, &args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{args:?} ({bytes} bytes) within 200 MB: {stderr}");
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let text = v.to_string();
        assert!(text.contains("\"samples\":300001"), "{args:?}: {text:.300}");
    }
    // the metrics themselves: currents (j+1) sin(2 pi t), peak 3 A on joint 3
    let out = analyze_limited(200_000, &["metrics", p, "-f", "json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let peak = v[0]["peak_current"]["current_a"].as_f64().unwrap();
    assert!((peak - 3.0).abs() < 1e-9, "{peak}");
}

/// The long recording of [`long_recordings_are_read_in_bounded_memory`], in `dir`.
fn long_recording(dir: &std::path::Path) -> std::path::PathBuf {
    let mut s = Synth::new("long", &["elbow"], 3);
    (s.dt, s.n) = (1e-3, 300_000);
    s.with_setup().write_in(dir)
}

/// `figures` and `layout` on the 300 s recording within 200 MB (issue 29): `layout` keeps only
/// the box of the hand's target positions, `figures` at most `analyze::figures::MAX_ROWS` rows
/// per series (min-max decimated as read). The layout's camera is the one of the whole series
/// (the target circles the synthetic arm's base: focus on it), and every figure is written.
#[test]
fn long_recordings_are_drawn_and_laid_out_in_bounded_memory() {
    let dir = tempfile::tempdir().unwrap();
    let path = long_recording(dir.path());
    let p = path.to_str().unwrap();
    let figs = dir.path().join("figures");
    let out = analyze_limited(200_000, &["figures", p, "-o", figs.to_str().unwrap(), "-q"]);
    assert_eq!(out.status.code(), Some(0), "figures within 200 MB: {}", String::from_utf8_lossy(&out.stderr));
    let index = std::fs::read_to_string(figs.join("index.md")).unwrap();
    assert!(index.contains("fig05_electric_total"), "{index:.300}");
    let out = analyze_limited(200_000, &["layout", p]);
    assert_eq!(out.status.code(), Some(0), "layout within 200 MB: {}", String::from_utf8_lossy(&out.stderr));
    let streamed: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    // the same layout as from the recording read whole
    let rec = schemas::read_recording_topics(&path, Some(&[schemas::topics::HAND])).unwrap();
    let whole = schemas::layout::foxglove(&schemas::layout::LayoutInput::from_recording(&rec).unwrap());
    assert_eq!(streamed, whole);
}

/// `export` on the 300 s recording within 200 MB, as Parquet and CSV, wide and long (issue 29:
/// 1.79 GB peak on main): each topic's table is written batch by batch as the file is read
/// (`analyze::frames::streamed`). The tables hold every sample: 300 001 rows of `/motors`, its
/// peak current 3 A on joint 3 and its last time 300 s, read back from the CSV.
#[test]
fn long_recordings_are_exported_in_bounded_memory() {
    let dir = tempfile::tempdir().unwrap();
    let path = long_recording(dir.path());
    let p = path.to_str().unwrap();
    for (format, layout) in [("parquet", "wide"), ("csv", "wide"), ("csv", "long")] {
        let out_dir = dir.path().join(format!("{format}-{layout}"));
        let o = out_dir.to_str().unwrap();
        let out = analyze_limited(200_000, &["export", p, "-f", format, "--layout", layout, "-o", o, "-q"]);
        assert_eq!(out.status.code(), Some(0), "export {format} {layout} within 200 MB: {}", String::from_utf8_lossy(&out.stderr));
        let tables = out_dir.join("long");
        assert!(!tables.join(analyze::export::INCOMPLETE).exists());
        let meta: serde_json::Value = serde_json::from_slice(&std::fs::read(tables.join("metadata.json")).unwrap()).unwrap();
        let motors = meta["topics"].as_array().unwrap().iter().find(|t| t["topic"] == "/motors").unwrap().clone();
        if layout == "wide" {
            assert_eq!(motors["rows"], 300_001, "{motors}");
        }
        if format == "csv" && layout == "wide" {
            let text = std::fs::read_to_string(tables.join("motors.csv")).unwrap();
            let mut lines = text.lines();
            let header: Vec<&str> = lines.next().unwrap().split(',').collect();
            let col = header.iter().position(|h| h.starts_with("current.") && h.contains('3')).expect("a current column of joint 3");
            let (mut n, mut peak, mut last) = (0, 0.0f64, 0.0f64);
            for line in lines {
                let cells: Vec<&str> = line.split(',').collect();
                peak = peak.max(cells[col].parse::<f64>().unwrap().abs());
                last = cells[0].parse().unwrap();
                n += 1;
            }
            assert_eq!(n, 300_001);
            assert!((peak - 3.0).abs() < 1e-9, "{peak}");
            assert!((last - 300.0).abs() < 1e-9, "{last}");
        }
    }
}

/// `view` on the 300 s recording within 200 MB (issue 29: 1.84 GB on main, where the whole
/// recording was decoded before the `.rrd` was encoded): the recording is surveyed in a
/// streamed pass, then drawn in time windows as it is read again (`analyze::view::window`).
/// The `.rrd` holds every sample: read back frame by frame (the RRD framing, each chunk an
/// Arrow IPC stream), each joint's current has 300 001 rows from 0 to 300 s in several
/// chunks, and the largest is the known peak, 3 A on joint 3.
#[test]
fn long_recordings_are_viewed_in_bounded_memory() {
    use analyze::view::rrd::{ArrowMsg, KIND_ARROW_MSG};
    use arrow_array::cast::AsArray;
    use prost::Message;
    let dir = tempfile::tempdir().unwrap();
    let path = long_recording(dir.path());
    let rrd = dir.path().join("long.rrd");
    let out = analyze_limited(200_000, &["view", path.to_str().unwrap(), "-o", rrd.to_str().unwrap(), "-q"]);
    assert_eq!(out.status.code(), Some(0), "view within 200 MB: {}", String::from_utf8_lossy(&out.stderr));
    let bytes = std::fs::read(&rrd).unwrap();
    // per current entity: rows, chunks, first and last time, largest |value|
    let mut currents: std::collections::BTreeMap<String, (usize, usize, i64, i64, f64)> = Default::default();
    let mut i = 12;
    while i < bytes.len() {
        let kind = u64::from_le_bytes(bytes[i..i + 8].try_into().unwrap());
        let len = u64::from_le_bytes(bytes[i + 8..i + 16].try_into().unwrap()) as usize;
        let payload = &bytes[i + 16..i + 16 + len];
        i += 16 + len;
        if kind == analyze::view::rrd::KIND_END {
            break;
        }
        if kind != KIND_ARROW_MSG {
            continue;
        }
        let m = ArrowMsg::decode(payload).unwrap();
        let batch = analyze::view::rrd::payload_batch(&m).unwrap();
        let entity = batch.schema().metadata()["rerun:entity_path"].clone();
        let Some(t) = batch.column_by_name("sim_time") else { continue };
        if !entity.starts_with("/current_A/") {
            continue;
        }
        let t = t.as_primitive::<arrow_array::types::DurationNanosecondType>();
        let v = batch.column_by_name("Scalars:scalars").unwrap().as_list::<i32>().values().as_primitive::<arrow_array::types::Float64Type>().clone();
        let e = currents.entry(entity).or_insert((0, 0, i64::MAX, i64::MIN, 0.0));
        e.0 += batch.num_rows();
        e.1 += 1;
        e.2 = e.2.min(t.value(0));
        e.3 = e.3.max(t.value(t.len() - 1));
        e.4 = v.values().iter().fold(e.4, |a, x| a.max(x.abs()));
    }
    assert_eq!(currents.len(), 3, "{currents:?}");
    for (entity, &(rows, chunks, t0, t1, _)) in &currents {
        assert_eq!((rows, t0, t1), (300_001, 0, 300_000_000_000), "{entity}");
        assert!(chunks > 1, "{entity}: drawn in windows, {chunks} chunk");
    }
    let peak = currents.values().map(|c| c.4).fold(0.0, f64::max);
    assert!((peak - 3.0).abs() < 1e-9, "{peak}");
}

/// A recording whose messages carry 5 002-entry arrays while its `run` record declares 3
/// joints (issue 29: `export` took 530–610 MB on such a 343 KB file): refused as damage under
/// 200 MB, naming the file, the topic, the field and the time, exit 2, no table left.
#[test]
fn arrays_longer_than_the_run_declares_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = Synth::new("wide", &["elbow"], 5_002);
    (s.dt, s.n) = (1e-3, 50);
    s.names.as_mut().unwrap().joint_names = Some(vec!["joint1".into(), "joint2".into(), "joint3".into()]);
    let path = s.with_setup().write_in(dir.path());
    let out_dir = dir.path().join("tables");
    let out = analyze_limited(200_000, &["export", path.to_str().unwrap(), "-o", out_dir.to_str().unwrap(), "-q"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    let file = path.display().to_string();
    assert!(err.contains(&file) && err.contains("topic /") && err.contains("field ") && err.contains("5002 entries, expected 3"), "{err}");
    assert!(!out_dir.join("wide").join("metadata.json").exists());
}
