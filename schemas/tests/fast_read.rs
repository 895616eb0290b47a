//! The fast paths of the reader give what the generic reader gives: typed decoding of the
//! metric messages (`Visitor::typed`) against the generic tree, message by message and field
//! by field (bit for bit), and reading only the chunks that hold the wanted topics against
//! reading every chunk, with the file's checks still made on the chunks skipped.

use crate::common;

use schemas::{regroup_chunks, topics, Body, DecodedMessage, Error, Value, Visitor};

const METRICS: [&str; 4] = [topics::HAND, topics::MOTORS, topics::CONSTRAINTS, topics::ENERGY];
/// Everything but the metric topics: one group of chunks; the metric topics another.
const BULK: [&str; 4] = [topics::TF, topics::HAND_POINTS, topics::JOINT_STATES, topics::ROBOT_DESCRIPTION];

/// What a visitor sees of one message, comparable between the two paths.
struct Seen {
    topic: String,
    index: usize,
    log_time_ns: u64,
    known: bool,
    value: Value,
    non_finite: Option<(String, u64)>,
    arrays: Vec<(String, usize)>,
    typed: String,
}

struct Keep {
    typed: bool,
    seen: Vec<Seen>,
}

fn typed_debug(m: &DecodedMessage<'_>) -> String {
    // the struct each topic reads as, with the array checks (sizes of the fixture: 2 joints, 2 contacts)
    let sizes = Some(schemas::ArraySizes { joints: 2, contacts: 2 });
    let bits = |r: Result<String, Error>| r.unwrap_or_else(|e| format!("error: {e}"));
    match m.topic {
        topics::HAND => bits(m.decode::<schemas::HandState>(sizes).map(|x| format!("{x:?}"))),
        topics::MOTORS => bits(m.decode::<schemas::MotorState>(sizes).map(|x| format!("{x:?}"))),
        topics::CONSTRAINTS => bits(m.decode::<schemas::ConstraintState>(sizes).map(|x| format!("{x:?}"))),
        topics::ENERGY => bits(m.decode::<schemas::EnergyState>(sizes).map(|x| format!("{x:?}"))),
        _ => String::new(),
    }
}

impl Visitor for Keep {
    fn message(&mut self, m: DecodedMessage<'_>) -> Result<(), Error> {
        self.seen.push(Seen {
            topic: m.topic.to_string(),
            index: m.index,
            log_time_ns: m.log_time_ns,
            known: matches!(m.body, Body::Known(_)),
            value: m.value().into_owned(),
            non_finite: m.non_finite().map(|(f, x)| (f, x.to_bits())),
            arrays: m.arrays().map(|(f, _, n)| (f.to_string(), n)).collect(),
            typed: typed_debug(&m),
        });
        Ok(())
    }

    fn typed(&self) -> bool {
        self.typed
    }
}

#[test]
fn typed_decoding_gives_the_generic_tree_on_every_message() {
    let dir = tempfile::tempdir().unwrap();
    let c = common::content(300);
    let path = common::write_all(&dir.path().join("all.mcap"), &c);
    let read = |typed| {
        let mut keep = Keep { typed, seen: Vec::new() };
        schemas::stream_recording(&path, Some(&METRICS), &mut keep).unwrap();
        keep.seen
    };
    let (generic, typed) = (read(false), read(true));
    assert_eq!(generic.len(), 4 * 300);
    assert_eq!(typed.len(), generic.len());
    let mut non_finite = 0;
    for (g, t) in generic.iter().zip(&typed) {
        let at = format!("{} #{}", g.topic, g.index);
        assert!(!g.known && t.known, "{at}: the generic path gives trees, the typed path structs");
        assert_eq!((&g.topic, g.index, g.log_time_ns), (&t.topic, t.index, t.log_time_ns), "{at}");
        assert!(g.value.same_bits(&t.value), "{at}:\n{:?}\n{:?}", g.value, t.value);
        assert_eq!(g.non_finite, t.non_finite, "{at}");
        assert_eq!(g.arrays, t.arrays, "{at}");
        assert_eq!(g.typed, t.typed, "{at}");
        non_finite += usize::from(g.non_finite.is_some());
    }
    // the fixture's awkward values (NaN among them) reach every topic
    assert!(non_finite > 100, "{non_finite}");
}

/// `chunk_bytes`: small, so that each group spans several chunks.
fn regrouped(bytes: &[u8], summary: bool) -> Vec<u8> {
    regroup_chunks(bytes, &[&BULK], 16 << 10, summary).unwrap()
}

fn fixture() -> (tempfile::TempDir, Vec<u8>) {
    let dir = tempfile::tempdir().unwrap();
    // every topic in every chunk (the writer's old layout; its default is now one topic per chunk)
    let path = dir.path().join("all.mcap");
    let w = schemas::RecordingWriter::create_with(&path, schemas::WriterOptions::INLINE_MIXED_ZSTD3).unwrap();
    let path = common::write_all_with(&path, &common::content(400), w);
    let bytes = std::fs::read(path).unwrap();
    (dir, bytes)
}

#[test]
fn only_the_chunks_of_the_wanted_topics_are_read_and_they_read_the_same() {
    let (_dir, mixed) = fixture();
    let full = schemas::read_recording_bytes(&mixed, "mixed").unwrap();
    let grouped = regrouped(&mixed, true);
    let unsummarised = regrouped(&mixed, false);
    for (name, bytes, skips) in [("mixed", &mixed, false), ("grouped", &grouped, true), ("grouped, no summary", &unsummarised, false)] {
        for typed in [false, true] {
            let mut keep = Keep { typed, seen: Vec::new() };
            let rec = match name {
                // the bytes reader and the file reader take the same path
                "grouped" if typed => {
                    let dir = tempfile::tempdir().unwrap();
                    let path = dir.path().join("g.mcap");
                    std::fs::write(&path, bytes).unwrap();
                    schemas::stream_recording(&path, Some(&METRICS), &mut keep).unwrap()
                }
                _ => {
                    let rec = schemas::read_recording_bytes_topics(bytes, name, Some(&METRICS)).unwrap();
                    rec.replay(&METRICS, &mut keep).unwrap();
                    rec
                }
            };
            assert_eq!(rec.chunks_skipped() > 0, skips, "{name}: {} chunks skipped", rec.chunks_skipped());
            // every channel counted, as when every chunk is read
            let counts = |r: &schemas::Recording| r.channels.iter().map(|c| (c.topic.clone(), c.message_count)).collect::<Vec<_>>();
            assert_eq!(counts(&rec), counts(&full), "{name}");
            assert_eq!(rec.metadata_records(), full.metadata_records(), "{name}");
            let mut seen = keep.seen.iter();
            for topic in METRICS {
                for (k, (t, v)) in full.messages(topic).unwrap().iter().enumerate() {
                    let s = seen.find(|s| s.topic == topic && s.index == k).unwrap_or_else(|| panic!("{name}: {topic} #{k} missing"));
                    assert!(s.log_time_ns == *t && s.value.same_bits(v), "{name}: {topic} #{k}");
                }
                seen = keep.seen.iter();
            }
            assert_eq!(keep.seen.len(), METRICS.iter().map(|t| full.messages(t).unwrap().len()).sum::<usize>(), "{name}");
        }
    }
    // the grouped file skipped the bulk chunks only: the metric messages were all read
    let rec = schemas::read_recording_bytes_topics(&grouped, "grouped", Some(&[topics::TF])).unwrap();
    assert!(rec.chunks_skipped() > 0);
    assert_eq!(rec.messages(topics::TF).unwrap().len(), full.messages(topics::TF).unwrap().len());
}

#[test]
fn a_skipped_chunk_is_still_checked() {
    let (_dir, mixed) = fixture();
    let grouped = regrouped(&mixed, true);
    let summary = mcap::Summary::read(&grouped).unwrap().unwrap();
    let bulk: Vec<u16> = summary.channels.values().filter(|c| BULK.contains(&c.topic.as_str())).map(|c| c.id).collect();
    let chunk = summary.chunk_indexes.iter().find(|c| c.message_index_offsets.keys().all(|ch| bulk.contains(ch))).expect("a chunk of the bulk topics only");
    // a byte of its compressed data: the data section's CRC covers it
    let mut bad = grouped.clone();
    bad[(chunk.chunk_start_offset + chunk.chunk_length - 1) as usize] ^= 0x40;
    let e = schemas::read_recording_bytes_topics(&bad, "bad", Some(&METRICS)).unwrap_err();
    assert!(e.to_string().contains("CRC") || e.to_string().contains("crc"), "{e}");
    assert!(schemas::read_recording_bytes(&bad, "bad").is_err());
}

#[test]
fn time_going_backwards_in_a_skipped_chunk_is_found() {
    // /tf goes back in time once; its chunks are skipped when the metric topics are read
    let dir = tempfile::tempdir().unwrap();
    let c = common::content(400);
    let mut w = schemas::RecordingWriter::create(&dir.path().join("back.mcap")).unwrap();
    for (k, &t) in c.times.iter().enumerate() {
        let t_tf = match k {
            200 => c.times[201],
            201 => c.times[200],
            _ => t,
        };
        w.write(topics::TF, t_tf, &common::tf(t_tf, k)).unwrap();
        w.write(topics::HAND, t, &c.hands[k]).unwrap();
    }
    let path = w.finish().unwrap();
    let grouped = regrouped(&std::fs::read(path).unwrap(), true);
    match schemas::read_recording_bytes_topics(&grouped, "back", Some(&[topics::HAND])) {
        Err(Error::TimeBackwards { topic, index, .. }) => assert_eq!((topic.as_str(), index), (topics::TF, 201)),
        other => panic!("{other:?}"),
    }
}
