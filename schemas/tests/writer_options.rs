//! The writer's settings (compression, chunks per topic, background thread) change the bytes,
//! never what a reader reads; the tap hands a visitor what a read of the finished file hands it.

// the visitor closures return schemas::Error, whose size is the library's choice
#![allow(clippy::result_large_err)]


use std::sync::{Arc, Mutex};

use crate::common::{content, write_all_with};
use schemas::{read_recording, stream_recording, Compression, DecodedMessage, RecordingWriter, Tap, Value, WriterOptions};

fn settings() -> Vec<(&'static str, WriterOptions)> {
    let d = WriterOptions::default();
    vec![
        ("default", d),
        ("inline mixed zstd 3", WriterOptions::INLINE_MIXED_ZSTD3),
        ("lz4", WriterOptions { compression: Compression::Lz4, ..d }),
        ("none", WriterOptions { compression: Compression::None, ..d }),
        ("zstd 9, small chunks, queue of 1", WriterOptions { compression: Compression::Zstd { level: 9 }, chunk_size: 4096, queue: 1, ..d }),
        ("inline per topic", WriterOptions { background: false, ..d }),
    ]
}

/// Every setting reads back the same metadata, channels and messages (exactly: `Value`
/// equality of every field), and each is deterministic.
#[test]
fn every_setting_reads_back_the_same_recording() {
    let dir = tempfile::tempdir().unwrap();
    let c = content(3000); // > 1 MiB: several chunks per setting
    let mut reference = None;
    for (k, (name, options)) in settings().into_iter().enumerate() {
        let path = dir.path().join(format!("{k}.mcap"));
        write_all_with(&path, &c, RecordingWriter::create_with(&path, options).unwrap());
        let again = dir.path().join(format!("{k}-again.mcap"));
        write_all_with(&again, &c, RecordingWriter::create_with(&again, options).unwrap());
        assert!(std::fs::read(&path).unwrap() == std::fs::read(&again).unwrap(), "{name}: not deterministic");
        let r = read_recording(&path).unwrap();
        let mut channels = r.channels.clone();
        channels.sort_by(|a, b| a.topic.cmp(&b.topic));
        for ch in &mut channels {
            ch.channel_id = 0; // numbered by first use, but compared by topic
        }
        let got = (r.metadata_records().clone(), channels, r.message_map().clone());
        assert_eq!(got.2.values().map(Vec::len).sum::<usize>(), 1 + 7 * 3000, "{name}");
        match &reference {
            None => reference = Some(got),
            Some(want) => {
                assert_eq!(got.0, want.0, "{name}: metadata");
                assert_eq!(got.1, want.1, "{name}: channels");
                // (Debug text: the content has NaNs, and tells -0.0 from 0.0)
                assert!(format!("{:?}", got.2) == format!("{:?}", want.2), "{name}: messages");
            }
        }
    }
}

/// The same calls on the caller's thread or on the writer's give the same bytes.
#[test]
fn background_and_inline_writers_give_identical_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let c = content(2000);
    for per_topic in [false, true] {
        let options = WriterOptions { chunk_per_topic: per_topic, ..WriterOptions::default() };
        let a = dir.path().join(format!("bg-{per_topic}.mcap"));
        write_all_with(&a, &c, RecordingWriter::create_with(&a, WriterOptions { background: true, queue: 3, ..options }).unwrap());
        let b = dir.path().join(format!("inline-{per_topic}.mcap"));
        write_all_with(&b, &c, RecordingWriter::create_with(&b, WriterOptions { background: false, ..options }).unwrap());
        assert!(std::fs::read(&a).unwrap() == std::fs::read(&b).unwrap(), "per topic {per_topic}");
    }
}

/// With chunks per topic every chunk's message index names one channel (what lets a reader
/// skip chunks); interleaved chunks name several.
#[test]
fn chunks_per_topic_hold_one_channel_each() {
    let dir = tempfile::tempdir().unwrap();
    let c = content(3000);
    for per_topic in [true, false] {
        let path = dir.path().join(format!("{per_topic}.mcap"));
        let options = WriterOptions { chunk_per_topic: per_topic, chunk_size: 64 << 10, ..WriterOptions::default() };
        write_all_with(&path, &c, RecordingWriter::create_with(&path, options).unwrap());
        let bytes = std::fs::read(&path).unwrap();
        let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
        let per_chunk: Vec<usize> = summary.chunk_indexes.iter().map(|ci| ci.message_index_offsets.len()).collect();
        assert!(per_chunk.len() > 7, "{per_chunk:?}");
        if per_topic {
            assert!(per_chunk.iter().all(|&n| n == 1), "{per_chunk:?}");
            // and the chunk of a channel lies within the time range of its messages
            for ci in &summary.chunk_indexes {
                assert!(ci.message_start_time <= ci.message_end_time);
            }
        } else {
            assert!(per_chunk.iter().any(|&n| n > 1), "{per_chunk:?}");
        }
    }
}

type Seen = Arc<Mutex<Vec<(String, usize, u64, Value, Option<String>)>>>;

fn collector(seen: &Seen) -> impl FnMut(DecodedMessage<'_>) -> Result<(), schemas::Error> + Send + 'static {
    let seen = seen.clone();
    move |m: DecodedMessage<'_>| {
        let run = m.run.map(|r| r.run.clone());
        seen.lock().unwrap().push((m.topic.to_string(), m.index, m.log_time_ns, m.value().into_owned(), run));
        Ok(())
    }
}

/// What the tap hands its visitor is what a streamed read of the file hands it: the same
/// messages (in the same order per topic), the same `run` record, and the same recording.
#[test]
fn the_tap_sees_what_a_reader_of_the_file_sees() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = schemas::synth::Synth::new("two-elbow", &["elbow4", "elbow7"], 3);
    s.n = 2500;
    let topics = [schemas::topics::HAND, schemas::topics::ENERGY, schemas::topics::CONSTRAINTS];
    let path = dir.path().join("t.mcap");
    let tapped_seen: Seen = Seen::default();
    let tap = Tap::new(path.display().to_string(), Some(&topics), Box::new(collector(&tapped_seen)));
    let w = RecordingWriter::create_tapped(&path, WriterOptions::default(), Some(tap)).unwrap();
    let (written, tapped) = s.write_with(w);
    assert_eq!(written, path);
    let tapped = tapped.expect("a tap was given");
    let from_tap = tapped.recording.unwrap();

    let read_seen: Seen = Seen::default();
    let from_file = stream_recording(&path, Some(&topics), &mut collector(&read_seen)).unwrap();
    let by_topic = |seen: &Seen| {
        let mut v = seen.lock().unwrap().clone();
        v.sort_by(|a, b| (&a.0, a.1).cmp(&(&b.0, b.1))); // per topic, in index order
        v
    };
    let (a, b) = (by_topic(&tapped_seen), by_topic(&read_seen));
    assert_eq!(a.len(), 3 * 2501);
    assert!(a == b, "the tap and the reader saw different messages");
    assert!(a.iter().all(|m| m.4.as_deref() == Some("two-elbow")), "every message carries the run record");
    assert_eq!(from_tap.source, from_file.source);
    assert_eq!(from_tap.metadata_records(), from_file.metadata_records());
    let sorted = |r: &schemas::Recording| {
        let mut c = r.channels.clone();
        c.sort_by(|a, b| a.topic.cmp(&b.topic));
        c
    };
    assert_eq!(sorted(&from_tap), sorted(&from_file));
    assert_eq!(from_tap.run().unwrap(), from_file.run().unwrap());
}
