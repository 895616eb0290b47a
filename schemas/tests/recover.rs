//! `read_recording_recover`: the intact part of a damaged recording, written by our own writer
//! with small chunks so that a cut leaves several complete chunks before it.

use std::collections::BTreeMap;

use schemas::{
    read_recording_bytes, read_recording_recover, read_recording_recover_bytes, topics, Error,
    HandState, MotorState, Recording, RecordingWriter, Value, Vec3,
};

const SAMPLES: u32 = 600;

/// 600 samples of /motors and /hand (1 ms apart), `run` metadata first, `result` last;
/// chunks of at most ~4 KiB uncompressed.
fn recording() -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let mut w = RecordingWriter::create_with_chunk_size(&dir.path().join("r.mcap"), 4096).unwrap();
    let mut run = BTreeMap::new();
    run.insert("run".to_string(), "two-elbow".to_string());
    w.write_metadata_raw("run", &run).unwrap();
    for k in 0..SAMPLES {
        let t = f64::from(k) * 1e-3;
        let ns = schemas::to_log_time(t);
        let m = MotorState {
            time: t,
            current: vec![t.sin(), 2.0 * t.cos(), -t / 3.0],
            voltage: vec![1.0 / (1.0 + t), 0.5, f64::from(k)],
            ..Default::default()
        };
        w.write(topics::MOTORS, ns, &m).unwrap();
        let h = HandState {
            time: t,
            error: Vec3 {
                x: t,
                y: -t,
                z: t * t,
            },
            error_norm: t * 2.0,
            ..Default::default()
        };
        w.write(topics::HAND, ns, &h).unwrap();
    }
    let mut result = BTreeMap::new();
    result.insert("status".to_string(), "complete".to_string());
    w.write_metadata_raw("result", &result).unwrap();
    std::fs::read(w.finish().unwrap()).unwrap()
}

fn assert_prefix(part: &Recording, full: &Recording, what: &str) {
    for (topic, list) in part.message_map() {
        let all = &full.messages(topic).unwrap();
        assert!(list.len() <= all.len(), "{what}: {topic}");
        assert_eq!(
            list[..],
            all[..list.len()],
            "{what}: {topic} is not a prefix"
        );
    }
}

fn count(rec: &Recording) -> u64 {
    rec.message_map().values().map(|l| l.len() as u64).sum()
}

/// An intact file: the recovered recording is the normal reader's, and the report says complete.
#[test]
fn an_intact_file_reads_as_with_the_normal_reader() {
    let full = recording();
    let normal = read_recording_bytes(&full, "r.mcap").unwrap();
    let (rec, report) = read_recording_recover_bytes(&full, "r.mcap").unwrap();
    assert!(report.complete && report.reason.is_none(), "{report}");
    assert_eq!(rec.message_map(), normal.message_map());
    assert_eq!(rec.metadata_records(), normal.metadata_records());
    assert_eq!(rec.channels, normal.channels);
    assert_eq!(report.messages, u64::from(SAMPLES) * 2);
    assert_eq!(
        report.t_end_ns,
        Some(schemas::to_log_time(f64::from(SAMPLES - 1) * 1e-3))
    );
    assert_eq!(report.stopped_at, full.len() as u64);
    assert!(report.chunks >= 5, "only {} chunks", report.chunks);
    assert!(report.metadata.contains(&"result".to_string()));
}

/// Cut at many offsets: always Ok, a prefix of the original messages (same values), never
/// fewer messages for a longer prefix, the `run` metadata (written first) once its record is
/// whole, the warning text naming the file and the offset; the stop offset is a record start
/// at or before the cut.
#[test]
fn truncated_files_give_a_prefix_of_the_messages() {
    let full = recording();
    let normal = read_recording_bytes(&full, "r.mcap").unwrap();
    let (_, intact) = read_recording_recover_bytes(&full, "r.mcap").unwrap();
    let mut last = 0;
    let mut cuts: Vec<usize> = (0..60).map(|k| 8 + k * (full.len() - 8) / 60).collect();
    cuts.push(full.len() - 1);
    let mut partial_seen = 0;
    for &cut in &cuts {
        let (rec, report) = read_recording_recover_bytes(&full[..cut], "cut.mcap").unwrap();
        assert!(!report.complete, "cut at {cut}");
        assert!(
            report.stopped_at <= cut as u64 && report.file_len == cut as u64,
            "{report}"
        );
        assert_prefix(&rec, &normal, &format!("cut at {cut}"));
        let n = count(&rec);
        assert_eq!(n, report.messages, "{report}");
        assert!(n >= last, "cut at {cut}: {n} < {last} messages");
        last = n;
        assert!(report.chunks <= intact.chunks);
        let text = report.to_string();
        assert!(
            text.starts_with("cut.mcap: damaged recording: stopped at byte ")
                && text.contains(&format!(" of {cut}: ")),
            "{text}"
        );
        if n > 0 {
            assert_eq!(rec.metadata_records().get("run").and_then(|m| m.get("run")).map(String::as_str), Some("two-elbow"));
            assert_eq!(
                report.t_end_ns,
                rec.message_map()
                    .values()
                    .flat_map(|l| l.last())
                    .map(|(t, _)| *t)
                    .max()
            );
            partial_seen += usize::from(n < u64::from(SAMPLES) * 2);
        }
    }
    // the whole data section survives when only the summary is cut
    assert_eq!(last, u64::from(SAMPLES) * 2);
    assert!(partial_seen > 40, "{partial_seen} partial recoveries");
}

/// A flipped byte inside a middle chunk: reading stops at that chunk (its CRC fails), keeping
/// every chunk before it and nothing of it.
#[test]
fn a_corrupt_chunk_stops_recovery_before_it() {
    let full = recording();
    let normal = read_recording_bytes(&full, "r.mcap").unwrap();
    // top-level records: opcode, u64 length, body; chunks are opcode 0x06
    let mut chunks = Vec::new();
    let mut at = 8;
    while at + 9 <= full.len() {
        let len = u64::from_le_bytes(full[at + 1..at + 9].try_into().unwrap()) as usize;
        if full[at] == 0x06 {
            chunks.push((at, len));
        }
        at += 9 + len;
    }
    let (start, len) = chunks[chunks.len() / 2];
    let mid = start + 9 + len - 5; // in the compressed records
    let mut b = full.clone();
    b[mid] ^= 0x40;
    assert!(read_recording_bytes(&b, "x").is_err());
    let (rec, report) = read_recording_recover_bytes(&b, "flip.mcap").unwrap();
    assert!(!report.complete);
    assert_eq!(report.stopped_at, start as u64, "{report}");
    assert!(
        report.reason.as_deref().unwrap().contains("unreadable"),
        "{report}"
    );
    assert_prefix(&rec, &normal, "flip");
    let n = count(&rec);
    assert!(n > 0 && n < u64::from(SAMPLES) * 2, "{n}");
    // the prefix ends where the damage starts: recovery of the file cut there gives the same
    let (rec2, _) =
        read_recording_recover_bytes(&full[..report.stopped_at as usize], "cut").unwrap();
    assert_eq!(rec2.message_map(), rec.message_map());
}

#[test]
fn nothing_to_recover_is_an_error_or_empty() {
    let e = read_recording_recover_bytes(b"hello", "t.mcap").unwrap_err();
    assert!(
        matches!(e, Error::NotMcap { .. }) && e.to_string().contains("t.mcap"),
        "{e}"
    );
    let e = read_recording_recover(std::path::Path::new("/nonexistent/y.mcap")).unwrap_err();
    assert!(e.to_string().contains("/nonexistent/y.mcap"), "{e}");
    let (rec, report) = read_recording_recover_bytes(mcap::MAGIC, "m.mcap").unwrap();
    assert!(rec.message_map().is_empty() && rec.metadata_records().is_empty() && report.messages == 0);
    assert_eq!(report.stopped_at, 8);
    assert!(report.to_string().contains("no messages"), "{report}");
}

/// The writer's default output is unchanged by the chunk-size option: `create` writes one
/// chunk for a small file; a small chunk size writes several, and both read the same.
#[test]
fn chunk_size_option_reads_the_same() {
    let dir = tempfile::tempdir().unwrap();
    let write = |w: &mut RecordingWriter| {
        for k in 0..200u32 {
            let m = MotorState {
                time: f64::from(k),
                current: vec![f64::from(k); 4],
                ..Default::default()
            };
            w.write(topics::MOTORS, u64::from(k), &m).unwrap();
        }
    };
    let mut a = RecordingWriter::create(&dir.path().join("a.mcap")).unwrap();
    write(&mut a);
    let a = std::fs::read(a.finish().unwrap()).unwrap();
    let mut b = RecordingWriter::create_with_chunk_size(&dir.path().join("b.mcap"), 1024).unwrap();
    write(&mut b);
    let b = std::fs::read(b.finish().unwrap()).unwrap();
    let (ra, pa) = read_recording_recover_bytes(&a, "a").unwrap();
    let (rb, pb) = read_recording_recover_bytes(&b, "b").unwrap();
    assert_eq!((pa.chunks, pb.chunks > 3), (1, true), "{pa} / {pb}");
    assert_eq!(ra.message_map(), rb.message_map());
    let v: &Value = &ra.message_map()[topics::MOTORS][7].1;
    assert_eq!(
        v.get("current").and_then(Value::as_f64_vec),
        Some(vec![7.0; 4])
    );
}

/// Top-level records of an intact file: (start, opcode, length of the body).
fn records(b: &[u8]) -> Vec<(usize, u8, usize)> {
    let mut out = Vec::new();
    let mut at = 8;
    while at + 9 <= b.len() - 8 {
        let len = u64::from_le_bytes(b[at + 1..at + 9].try_into().unwrap()) as usize;
        out.push((at, b[at], len));
        at += 9 + len;
    }
    out
}

/// A metadata record changed in place (same length: "two-elbow" -> "two-elbox") passes the
/// MCAP parser but not the data section's CRC. Recovery keeps every message (the chunks pass
/// their own CRCs) and leaves out every metadata record, saying why: no label from bytes that
/// failed a CRC.
#[test]
fn metadata_that_fails_the_data_section_crc_is_left_out() {
    let full = recording();
    let at = full.windows(9).position(|w| w == b"two-elbow").unwrap();
    let mut b = full.clone();
    b[at + 8] = b'x';
    let e = read_recording_bytes(&b, "x").unwrap_err();
    assert!(e.to_string().to_lowercase().contains("crc"), "{e}");
    let (rec, report) = read_recording_recover_bytes(&b, "meta.mcap").unwrap();
    assert!(!report.complete && !report.metadata_verified, "{report}");
    assert!(rec.metadata_records().is_empty(), "{:?}", rec.metadata_records());
    let reason = report.reason.as_deref().unwrap();
    assert!(reason.contains("data section's CRC does not match") && reason.contains("run"), "{reason}");
    assert_eq!(count(&rec), u64::from(SAMPLES) * 2);
    // the intact file's metadata is verified
    let (_, intact) = read_recording_recover_bytes(&full, "r.mcap").unwrap();
    assert!(intact.metadata_verified);
}

/// A chunk copied twice in a row (a copy that went wrong): the normal reader refuses the file,
/// recovery reads every message once, counts the repeat, and (the repeat left out) verifies the
/// metadata by the data section's CRC.
#[test]
fn a_repeated_chunk_is_read_once() {
    let full = recording();
    let (start, _, len) = *records(&full).iter().filter(|r| r.1 == 0x06).nth(2).unwrap();
    let chunk = &full[start..start + 9 + len];
    let mut b = full[..start + 9 + len].to_vec();
    b.extend_from_slice(chunk);
    b.extend_from_slice(&full[start + 9 + len..]);
    assert!(read_recording_bytes(&b, "x").is_err());
    let (rec, report) = read_recording_recover_bytes(&b, "dup.mcap").unwrap();
    assert_eq!(report.duplicate_chunks, 1, "{report}");
    assert!(report.to_string().contains("1 repeated chunks skipped"), "{report}");
    let normal = read_recording_bytes(&full, "r.mcap").unwrap();
    assert_eq!(rec.message_map(), normal.message_map());
    assert_eq!(count(&rec), u64::from(SAMPLES) * 2);
    // the repeat is the only damage: without it the data section's CRC matches
    assert!(report.metadata_verified, "{report}");
    assert_eq!(rec.metadata_records(), normal.metadata_records());
}

/// Two chunks swapped: time goes backwards on their channels. The normal reader names the topic
/// and the message; recovery stops at the first message whose time goes backwards, keeping
/// what came before it (chunks 0 and 2: time in order, with a gap that `analyze` finds
/// against the output grid).
#[test]
fn chunks_out_of_time_order_are_refused() {
    let full = recording();
    let chunks: Vec<_> = records(&full).into_iter().filter(|r| r.1 == 0x06).collect();
    // chunk 1 and chunk 2, each with the message-index records after it, swapped
    let (a, b0, c0) = (chunks[1].0, chunks[2].0, chunks[3].0);
    let mut b = full[..a].to_vec();
    b.extend_from_slice(&full[b0..c0]);
    b.extend_from_slice(&full[a..b0]);
    b.extend_from_slice(&full[c0..]);
    let e = read_recording_bytes(&b, "swap.mcap").unwrap_err();
    assert!(matches!(e, Error::TimeBackwards { .. }) && e.to_string().contains("time goes backwards"), "{e}");
    let (rec, report) = read_recording_recover_bytes(&b, "swap.mcap").unwrap();
    assert!(report.reason.as_deref().unwrap().contains("time goes backwards"), "{report}");
    assert_eq!(report.stopped_at, (a + (c0 - b0)) as u64, "{report}");
    for list in rec.message_map().values() {
        assert!(list.windows(2).all(|w| w[0].0 < w[1].0));
    }
}


/// 10 s of /motors and /hand every 10 ms and a sparse topic (/contact_events, every 0.37 s,
/// between samples, written before the next sample as `sim` does), with the default writer.
fn recording_default() -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let mut w = RecordingWriter::create(&dir.path().join("d.mcap")).unwrap();
    let mut run = BTreeMap::new();
    run.insert("run".to_string(), "two-elbow".to_string());
    w.write_metadata_raw("run", &run).unwrap();
    let mut next_event = 0.37;
    for k in 0..1000u32 {
        let t = f64::from(k) * 1e-2;
        while next_event <= t {
            let e = schemas::ContactEventMsg { time: next_event, contact: "elbow".into(), kind: "impact".into(), impulse: next_event, ..Default::default() };
            w.write(topics::CONTACT_EVENTS, schemas::to_log_time(next_event), &e).unwrap();
            next_event += 0.37;
        }
        let ns = schemas::to_log_time(t);
        let m = MotorState { time: t, current: vec![t.sin(); 3], voltage: vec![f64::from(k); 3], ..Default::default() };
        w.write(topics::MOTORS, ns, &m).unwrap();
        let h = HandState { time: t, error: Vec3 { x: t, y: -t, z: t * t }, error_norm: t * 2.0, ..Default::default() };
        w.write(topics::HAND, ns, &h).unwrap();
    }
    let mut result = BTreeMap::new();
    result.insert("status".to_string(), "complete".to_string());
    w.write_metadata_raw("result", &result).unwrap();
    std::fs::read(w.finish().unwrap()).unwrap()
}

/// What a crash leaves (issue 29, item 7): the default writer writes every topic's chunk
/// together at least every second of log time, so a file cut anywhere gives, by recovery, every
/// topic up to the same time and nothing after: exactly the intact recording restricted to
/// `[0, t_end]` (the sparse topic too), losing at most the flush group the cut falls into
/// (≤ 1 s of log time here, at most one chunk per topic). On the writer that wrote a topic's
/// chunk only when it held 1 MiB, every cut before the end recovered no message at all.
#[test]
fn a_cut_file_of_the_default_writer_keeps_every_topic_up_to_the_same_time() {
    let full = recording_default();
    let normal = read_recording_bytes(&full, "d.mcap").unwrap();
    assert_eq!(normal.messages(topics::CONTACT_EVENTS).unwrap().len(), 27);
    let mut last = 0;
    let mut recovered = 0;
    for k in 1..40 {
        let cut = k * full.len() / 40;
        let (rec, report) = read_recording_recover_bytes(&full[..cut], "cut.mcap").unwrap();
        assert!(!report.complete && report.aligned, "cut at {cut}: {report}");
        let t_end = report.t_end_ns.unwrap_or(0);
        // the intact recording restricted to [0, t_end]: every topic, exactly
        for (topic, list) in normal.message_map() {
            let expected: Vec<_> = list.iter().filter(|(t, _)| report.t_end_ns.is_some_and(|end| *t <= end)).cloned().collect();
            let got = rec.message_map().get(topic).cloned().unwrap_or_default();
            assert_eq!(got, expected, "cut at {cut}: {topic} is not the intact one up to {t_end} ns: {report}");
        }
        assert!(t_end >= last, "cut at {cut}: {t_end} < {last}");
        last = t_end;
        assert!(report.held_back_chunks <= 3, "cut at {cut}: more than one group lost: {report}");
        // the part lost: at most the group the cut falls into (≤ 1 s), whose chunks follow
        // the data in proportion to the bytes (10 s in all; 0.5 s of slack for the metadata)
        let t_cut = 10.0 * cut as f64 / full.len() as f64;
        let t = schemas::from_log_time(t_end);
        assert!(report.t_end_ns.is_none() && t_cut < 1.5 || t > t_cut - 1.5, "cut at {cut} (~{t_cut} s): recovered to {t} s: {report}");
        recovered += usize::from(report.messages > 0);
        assert!(report.to_string().contains("every topic up to it") || report.messages == 0, "{report}");
    }
    assert!(recovered >= 34, "{recovered} of 39 cuts recovered messages");
}
