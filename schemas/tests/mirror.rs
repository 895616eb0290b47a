//! A [`Mirror`] is handed exactly the records the writer writes (the schemas, channels with their
//! metadata, metadata records and message bytes of the finished file, read back with the `mcap`
//! crate), and the file does not depend on it (byte-identical to one written without), even
//! when it panics (issue 29: a failure in the live view never loses the recording).


use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};

use crate::common::{content, write_all_with};
use schemas::{Mirror, RecordingWriter, WriterOptions};

#[derive(Default)]
struct Seen {
    schemas: BTreeMap<u16, (String, String, Vec<u8>)>,
    /// id → (schema id, topic, message encoding, metadata)
    channels: BTreeMap<u16, (u16, String, String, BTreeMap<String, String>)>,
    metadata: Vec<(String, BTreeMap<String, String>)>,
    /// (channel id, sequence, log time, bytes), in the order handed over
    messages: Vec<(u16, u32, u64, Vec<u8>)>,
    finished: usize,
}

struct Recorder(Arc<Mutex<Seen>>);

impl Mirror for Recorder {
    fn schema(&mut self, id: u16, name: &str, encoding: &str, data: &[u8]) {
        let old = self.0.lock().unwrap().schemas.insert(id, (name.into(), encoding.into(), data.into()));
        assert!(old.is_none(), "schema {id} handed twice");
    }
    fn channel(&mut self, id: u16, schema_id: u16, topic: &str, message_encoding: &str, metadata: &BTreeMap<String, String>) {
        let mut s = self.0.lock().unwrap();
        assert!(s.schemas.contains_key(&schema_id), "channel {topic} before its schema");
        s.channels.insert(id, (schema_id, topic.into(), message_encoding.into(), metadata.clone()));
    }
    fn metadata(&mut self, name: &str, entries: &BTreeMap<String, String>) {
        self.0.lock().unwrap().metadata.push((name.into(), entries.clone()));
    }
    fn message(&mut self, channel_id: u16, sequence: u32, log_time_ns: u64, data: &[u8]) {
        let mut s = self.0.lock().unwrap();
        assert!(s.channels.contains_key(&channel_id), "message before its channel {channel_id}");
        s.messages.push((channel_id, sequence, log_time_ns, data.to_vec()));
    }
    fn finish(&mut self) {
        self.0.lock().unwrap().finished += 1;
    }
}

#[test]
fn a_mirror_is_handed_the_records_of_the_file_and_changes_no_byte() {
    let dir = tempfile::tempdir().unwrap();
    let c = content(300);
    for options in [WriterOptions::default(), WriterOptions::INLINE_MIXED_ZSTD3] {
        let (with, without) = (dir.path().join("with.mcap"), dir.path().join("without.mcap"));
        let seen = Arc::new(Mutex::new(Seen::default()));
        let w = RecordingWriter::create_mirrored(&with, options, None, Some(Box::new(Recorder(seen.clone())))).unwrap();
        write_all_with(&with, &c, w);
        write_all_with(&without, &c, RecordingWriter::create_with(&without, options).unwrap());
        assert_eq!(std::fs::read(&with).unwrap(), std::fs::read(&without).unwrap(), "the mirror changed the file ({options:?})");

        let seen = std::mem::take(&mut *seen.lock().unwrap());
        assert_eq!(seen.finished, 1);
        let bytes = std::fs::read(&with).unwrap();
        let summary = mcap::Summary::read(&bytes).unwrap().expect("a summary");
        // channels and schemas as in the file
        assert_eq!(seen.channels.len(), summary.channels.len());
        for (id, ch) in &summary.channels {
            let (schema_id, topic, encoding, metadata) = &seen.channels[id];
            assert_eq!((topic, encoding, metadata), (&ch.topic, &ch.message_encoding, &ch.metadata));
            let s = ch.schema.as_ref().expect("every channel has a schema");
            assert_eq!(*schema_id, s.id);
            assert_eq!(seen.schemas[schema_id], (s.name.clone(), s.encoding.clone(), s.data.to_vec()));
        }
        assert!(seen.channels.values().any(|c| !c.3.is_empty()), "the units metadata reached the mirror");
        // every message, with its bytes; per channel in the file's order
        let mut file: Vec<(u16, u32, u64, Vec<u8>)> = mcap::MessageStream::new(&bytes)
            .unwrap()
            .map(|m| {
                let m = m.unwrap();
                (m.channel.id, m.sequence, m.log_time, m.data.to_vec())
            })
            .collect();
        let mut mirrored = seen.messages.clone();
        assert_eq!(mirrored.len(), file.len());
        let key = |m: &(u16, u32, u64, Vec<u8>)| (m.0, m.1);
        file.sort_by_key(key);
        mirrored.sort_by_key(key);
        assert!(mirrored == file, "the mirror saw other messages than the file holds");
        // metadata records as in the file
        let mut records = Vec::new();
        for idx in &summary.metadata_indexes {
            let m = mcap::read::metadata(&bytes, idx).unwrap();
            records.push((m.name, m.metadata));
        }
        let mut from_mirror = seen.metadata.clone();
        from_mirror.sort();
        records.sort();
        assert_eq!(from_mirror, records);
    }
}

/// Panics on the `n`-th message (or, `n` = 0, on the first channel); counts finish calls.
struct Panics {
    n: usize,
    seen: usize,
    finished: Arc<Mutex<usize>>,
}

impl Mirror for Panics {
    fn channel(&mut self, _id: u16, _schema_id: u16, topic: &str, _enc: &str, _metadata: &BTreeMap<String, String>) {
        assert!(self.n != 0, "a deliberate panic on channel {topic}");
    }
    fn message(&mut self, _channel_id: u16, _sequence: u32, _log_time_ns: u64, _data: &[u8]) {
        self.seen += 1;
        assert!(self.seen != self.n, "a deliberate panic on message {}", self.n);
    }
    fn finish(&mut self) {
        *self.finished.lock().unwrap() += 1;
    }
}

/// A mirror that panics (on a channel, on the first message, mid-run) does not lose the
/// recording: the file is written, finished and byte-identical to one written without a
/// mirror, with the writer on its background thread and inline; the mirror gets nothing after
/// its panic (no finish). Before issue 29 the panic unwound the writer's thread and the file
/// was never finished.
#[test]
fn a_mirror_that_panics_loses_no_record() {
    let dir = tempfile::tempdir().unwrap();
    let c = content(300);
    for options in [WriterOptions::default(), WriterOptions::INLINE_MIXED_ZSTD3] {
        let without = dir.path().join("without.mcap");
        write_all_with(&without, &c, RecordingWriter::create_with(&without, options).unwrap());
        for n in [0, 1, 150] {
            let with = dir.path().join(format!("with{n}.mcap"));
            let finished = Arc::new(Mutex::new(0));
            let mirror = Panics { n, seen: 0, finished: finished.clone() };
            let w = RecordingWriter::create_mirrored(&with, options, None, Some(Box::new(mirror))).unwrap();
            write_all_with(&with, &c, w);
            assert_eq!(std::fs::read(&with).unwrap(), std::fs::read(&without).unwrap(), "panic at {n} ({options:?})");
            assert_eq!(*finished.lock().unwrap(), 0, "a mirror that panicked is not called again");
        }
    }
}
