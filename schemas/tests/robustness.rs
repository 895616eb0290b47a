//! The reader on hostile or foreign input: every malformed file is an `Err` naming the source,
//! never a panic; channels from other writers decode from their own schemas or are skipped
//! with a reason.

use std::collections::BTreeMap;

use schemas::{
    read_recording, read_recording_bytes, topics, Error, HandState, MotorState, RecordingWriter,
    Value,
};

/// A small valid recording from our writer.
fn valid_file() -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let mut w = RecordingWriter::create(&dir.path().join("v.mcap")).unwrap();
    for k in 0..20u32 {
        let t = u64::from(k) * 1_000_000;
        let m = MotorState {
            time: f64::from(k),
            current: vec![1.0, 2.0],
            ..Default::default()
        };
        w.write(topics::MOTORS, t, &m).unwrap();
        w.write(
            topics::HAND,
            t,
            &HandState {
                time: f64::from(k),
                ..Default::default()
            },
        )
        .unwrap();
    }
    std::fs::read(w.finish().unwrap()).unwrap()
}

/// Deterministic pseudo-random bytes (xorshift64*), so failures reproduce.
fn noise(seed: u64, n: usize) -> Vec<u8> {
    let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    (0..n)
        .map(|_| {
            x ^= x >> 12;
            x ^= x << 25;
            x ^= x >> 27;
            (x.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 56) as u8
        })
        .collect()
}

#[test]
fn empty_and_random_bytes_are_errors() {
    let e = read_recording_bytes(&[], "empty.mcap").unwrap_err();
    assert!(
        matches!(e, Error::NotMcap { .. }) && e.to_string().contains("empty.mcap"),
        "{e}"
    );
    for seed in 0..200 {
        let junk = noise(seed, (seed as usize * 37) % 5000);
        assert!(read_recording_bytes(&junk, "junk").is_err());
        // junk behind a valid magic gets past the first check
        let mut j = mcap::MAGIC.to_vec();
        j.extend(&junk);
        let e = read_recording_bytes(&j, "junk-with-magic").unwrap_err();
        assert!(e.to_string().contains("junk-with-magic"), "{e}");
    }
}

#[test]
fn every_truncation_is_an_error() {
    let full = valid_file();
    assert!(read_recording_bytes(&full, "full").is_ok());
    for n in 0..full.len() {
        let r = read_recording_bytes(&full[..n], "cut.mcap");
        assert!(
            r.is_err(),
            "prefix of {n}/{} bytes was accepted",
            full.len()
        );
    }
}

/// Our files carry chunk, data-section and summary CRCs, all checked: any flipped byte fails.
#[test]
fn every_single_byte_corruption_is_an_error() {
    let full = valid_file();
    let mut rejected = 0;
    for i in 0..full.len() {
        for flip in [0x01u8, 0x80, 0xff] {
            let mut b = full.clone();
            b[i] ^= flip;
            if read_recording_bytes(&b, "flipped").is_err() {
                rejected += 1;
            }
        }
    }
    assert_eq!(
        rejected,
        full.len() * 3,
        "{} of {} corruptions went undetected",
        full.len() * 3 - rejected,
        full.len() * 3
    );
}

#[test]
fn read_recording_names_a_missing_file() {
    let e = read_recording(std::path::Path::new("/nonexistent/x.mcap"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("/nonexistent/x.mcap"), "{e}");
}

/// A file written with the raw mcap crate, as some other program would.
fn foreign(build: impl FnOnce(&mut mcap::Writer<std::io::Cursor<Vec<u8>>>)) -> Vec<u8> {
    let mut w = mcap::WriteOptions::new()
        .create(std::io::Cursor::new(Vec::new()))
        .unwrap();
    build(&mut w);
    w.finish().unwrap();
    w.into_inner().into_inner()
}

fn put(w: &mut mcap::Writer<std::io::Cursor<Vec<u8>>>, ch: u16, seq: u32, data: &[u8]) {
    let h = mcap::records::MessageHeader {
        channel_id: ch,
        sequence: seq,
        log_time: 7,
        publish_time: 7,
    };
    w.write_to_known_channel(&h, data).unwrap();
}

#[test]
fn foreign_json_big_endian_cdr_and_unknown_encodings() {
    let none = BTreeMap::new();
    let bytes = foreign(|w| {
        let s = w
            .add_schema("Pt", "jsonschema", br#"{"type":"object"}"#)
            .unwrap();
        let c = w.add_channel(s, "/json", "json", &none).unwrap();
        put(w, c, 0, br#"{"x": 1.5, "v": [1, -2, 3.25]}"#);
        let s = w
            .add_schema(
                "geometry_msgs/msg/Point",
                "ros2msg",
                b"float64 x\nfloat64 y\nfloat64 z",
            )
            .unwrap();
        let c = w.add_channel(s, "/be", "cdr", &none).unwrap();
        let mut be = vec![0u8, 0, 0, 0];
        for x in [1.0f64, -2.0, 0.5] {
            be.extend(x.to_be_bytes());
        }
        put(w, c, 0, &be);
        let s = w.add_schema("pkg/Thing", "ros1msg", b"float64 x").unwrap();
        let c = w.add_channel(s, "/ros1", "ros1", &none).unwrap();
        put(w, c, 0, &[1, 2, 3]);
    });
    let r = read_recording_bytes(&bytes, "foreign.mcap").unwrap();
    let json = &r.messages("/json").unwrap()[0].1;
    assert_eq!(json.get("x"), Some(&Value::F64(1.5)));
    assert_eq!(
        json.get("v").and_then(Value::as_f64_vec),
        Some(vec![1.0, -2.0, 3.25])
    );
    let be = &r.messages("/be").unwrap()[0].1;
    assert_eq!(be.get("y"), Some(&Value::F64(-2.0)));
    assert_eq!(be.get("z"), Some(&Value::F64(0.5)));

    // the ros1 channel is listed with a reason and its messages are counted but not decoded
    let ros1 = r.channels.iter().find(|c| c.topic == "/ros1").unwrap();
    assert_eq!(ros1.message_count, 1);
    assert!(ros1.undecoded.as_deref().unwrap().contains("ros1"));
    assert!(r.messages("/ros1").is_none());
    #[derive(serde::Deserialize)]
    struct Ros1Thing {
        #[allow(dead_code)]
        x: f64,
    }
    impl schemas::TopicMessage for Ros1Thing {
        const TOPIC: &'static str = "/ros1";
    }
    let e = r.read::<Ros1Thing>().err().unwrap();
    assert!(matches!(e, Error::UndecodedTopic { .. }), "{e}");
}

#[test]
fn undecodable_payloads_and_schemas_are_errors_naming_the_topic() {
    let none = BTreeMap::new();
    // CDR payload too short for its schema
    let bytes = foreign(|w| {
        let s = w
            .add_schema(
                "geometry_msgs/msg/Point",
                "ros2msg",
                b"float64 x\nfloat64 y",
            )
            .unwrap();
        let c = w.add_channel(s, "/short", "cdr", &none).unwrap();
        put(w, c, 0, &[0, 1, 0, 0, 1, 2, 3]);
    });
    let e = read_recording_bytes(&bytes, "f.mcap")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("f.mcap") && e.contains("/short") && e.contains("field x"),
        "{e}"
    );

    // protobuf schema that is not a FileDescriptorSet
    let bytes = foreign(|w| {
        let s = w
            .add_schema("a.B", "protobuf", &[0xff, 0xff, 0xff])
            .unwrap();
        let c = w.add_channel(s, "/pb", "protobuf", &none).unwrap();
        put(w, c, 0, &[8, 1]);
    });
    let e = read_recording_bytes(&bytes, "g.mcap").unwrap_err();
    assert!(
        matches!(e, Error::BadSchema { .. }) && e.to_string().contains("/pb"),
        "{e}"
    );

    // a real descriptor set, but a payload that is not that message
    let bytes = foreign(|w| {
        let s = w
            .add_schema(
                "handstate.HandState",
                "protobuf",
                &<HandState as schemas::Message>::schema_data(),
            )
            .unwrap();
        let c = w.add_channel(s, "/hand", "protobuf", &none).unwrap();
        put(w, c, 0, &[0x0a, 0x50, 1]);
    });
    let e = read_recording_bytes(&bytes, "h.mcap").unwrap_err();
    assert!(
        matches!(e, Error::Decode { .. }) && e.to_string().contains("/hand"),
        "{e}"
    );

    // bad JSON
    let bytes = foreign(|w| {
        let c = w.add_channel(0, "/j", "json", &none).unwrap();
        put(w, c, 0, b"{not json");
    });
    let e = read_recording_bytes(&bytes, "j.mcap")
        .unwrap_err()
        .to_string();
    assert!(e.contains("/j") && e.contains("message #0"), "{e}");
}

/// Without CRCs (other writers may omit them) corruption reaches the record parsers and the
/// message decoders: results may be Ok or Err, but no panic may escape (the two dependency
/// panics this finds are caught in `read_recording_bytes`; stderr shows them).
#[test]
fn corruption_without_crcs_never_panics() {
    let none = BTreeMap::new();
    let options = mcap::WriteOptions::new()
        .compression(None)
        .calculate_chunk_crcs(false)
        .calculate_data_section_crc(false)
        .calculate_summary_section_crc(false);
    let mut w = options.create(std::io::Cursor::new(Vec::new())).unwrap();
    let hand = <HandState as schemas::Message>::schema_data();
    let s = w
        .add_schema("handstate.HandState", "protobuf", &hand)
        .unwrap();
    let c = w.add_channel(s, "/hand", "protobuf", &none).unwrap();
    let mut buf = Vec::new();
    schemas::Message::encode_into(
        &HandState {
            time: 1.0,
            ..Default::default()
        },
        &mut buf,
    );
    put(&mut w, c, 0, &buf);
    let s = w
        .add_schema(
            "sensor_msgs/msg/JointState",
            "ros2msg",
            schemas::cdr::JOINT_STATE_MSG.as_bytes(),
        )
        .unwrap();
    let c = w.add_channel(s, "/js", "cdr", &none).unwrap();
    let mut buf = Vec::new();
    let js = schemas::JointState {
        name: vec!["a".into()],
        position: vec![1.0],
        ..Default::default()
    };
    schemas::Message::encode_into(&js, &mut buf);
    put(&mut w, c, 0, &buf);
    let c = w.add_channel(0, "/j", "json", &none).unwrap();
    put(&mut w, c, 0, br#"{"a":[1,2,{"b":null}]}"#);
    w.finish().unwrap();
    let full = w.into_inner().into_inner();
    assert!(read_recording_bytes(&full, "nocrc").is_ok());
    let mut ok = 0;
    for i in 0..full.len() {
        for flip in [0x01u8, 0x10, 0x80, 0xff] {
            let mut b = full.clone();
            b[i] ^= flip;
            ok += usize::from(read_recording_bytes(&b, "nocrc").is_ok());
        }
    }
    // some flips land in data that stays decodable (a float, a string byte); most do not
    assert!(
        ok > 0 && ok < full.len() * 4,
        "{ok} of {} accepted",
        full.len() * 4
    );
}

/// Paths that are not regular files are refused before any byte is read (`/dev/zero` would
/// never end), and a huge file without the MCAP magic after its first 8 bytes: a 20 GB sparse
/// file is refused as fast as an empty one.
#[test]
fn not_a_file_and_huge_non_mcap_files_are_refused_before_reading() {
    let dir = tempfile::tempdir().unwrap();
    for (path, kind) in [(std::path::Path::new("/dev/zero"), "character device"), (dir.path(), "directory")] {
        let e = schemas::read_recording(path).unwrap_err();
        assert!(matches!(e, Error::NotAFile { .. }) && e.to_string().contains(kind), "{e}");
        let e = schemas::read_recording_recover(path).unwrap_err();
        assert!(matches!(e, Error::NotAFile { .. }), "{e}");
    }
    let big = dir.path().join("big.mcap");
    std::fs::File::create(&big).unwrap().set_len(20 << 30).unwrap();
    let e = schemas::read_recording(&big).unwrap_err();
    assert!(matches!(e, Error::NotMcap { len, .. } if len == 20 << 30), "{e}");
    // the magic, then zeros: opcode 0x00 is no MCAP record, refused at once
    let zeros = dir.path().join("zeros.mcap");
    let mut f = std::fs::File::create(&zeros).unwrap();
    std::io::Write::write_all(&mut f, mcap::MAGIC).unwrap();
    f.set_len(20 << 30).unwrap();
    let e = schemas::read_recording(&zeros).unwrap_err();
    assert!(e.to_string().contains("opcode 0x00"), "{e}");
    let (_, report) = schemas::read_recording_recover(&zeros).unwrap();
    assert!(report.reason.as_deref().unwrap().contains("opcode 0x00") && report.messages == 0, "{report}");
    // a valid recording followed by gigabytes of zeros
    let tail = dir.path().join("tail.mcap");
    std::fs::write(&tail, valid_file()).unwrap();
    std::fs::OpenOptions::new().write(true).open(&tail).unwrap().set_len(20 << 30).unwrap();
    assert!(schemas::read_recording(&tail).is_err());
}

/// A file that says it is of a format version newer than this reader's is refused, naming the
/// record and the version; older versions read.
#[test]
fn an_unknown_format_version_is_refused() {
    for (version, ok) in [("0", true), ("2", true), ("3", true), ("4", false), ("99", false), ("two", false)] {
        let b = foreign(|w| {
            let mut m = std::collections::BTreeMap::new();
            m.insert("format_version".to_string(), version.to_string());
            w.write_metadata(&mcap::records::Metadata { name: "recording".into(), metadata: m }).unwrap();
        });
        match read_recording_bytes(&b, "v.mcap") {
            Ok(_) => assert!(ok, "version {version} read"),
            Err(e) => {
                assert!(!ok, "version {version}: {e}");
                assert!(matches!(e, Error::UnsupportedFormat { .. }) && e.to_string().contains(&format!("format_version = {version}")), "{e}");
            }
        }
    }
}
