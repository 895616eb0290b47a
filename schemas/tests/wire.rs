//! The hand-written protobuf walk of the metric messages (`schemas/src/reader/wire.rs`) against
//! `prost-reflect`'s generic decoding of the same bytes through the schema stored in the file
//! (the reference), on hand-made messages that `sim` never writes: fields missing, unknown
//! fields of every wire type (groups too), repeated scalars packed, unpacked and both, a scalar
//! or a nested message given twice, names apart from each other or changing from one message to
//! the next, a `uint32` past 32 bits; and bytes that do not decode (a field of the wrong wire
//! type, a packed `double` of 12 bytes, a truncated record, a name that is not UTF-8, field 0),
//! which must be refused by both. Each message is read three ways in one file: the generic tree,
//! the typed struct, and the typed struct decoded into kept storage (`Visitor::by_ref`); the
//! trees must be equal bit for bit, and an error must come from the same message.

use prost::encoding::{encode_key, encode_varint, WireType};
use schemas::{topics, Body, ConstraintState, ContactState, DecodedMessage, EnergyState, Error, HandState, Message, MotorState, Value, Visitor};

/// A protobuf message built record by record.
#[derive(Default, Clone)]
struct Pb(Vec<u8>);

impl Pb {
    fn f64(mut self, tag: u32, x: f64) -> Self {
        encode_key(tag, WireType::SixtyFourBit, &mut self.0);
        self.0.extend_from_slice(&x.to_le_bytes());
        self
    }
    fn packed(mut self, tag: u32, xs: &[f64]) -> Self {
        encode_key(tag, WireType::LengthDelimited, &mut self.0);
        encode_varint(8 * xs.len() as u64, &mut self.0);
        for x in xs {
            self.0.extend_from_slice(&x.to_le_bytes());
        }
        self
    }
    fn varint(mut self, tag: u32, v: u64) -> Self {
        encode_key(tag, WireType::Varint, &mut self.0);
        encode_varint(v, &mut self.0);
        self
    }
    fn packed_varints(self, tag: u32, vs: &[u64]) -> Self {
        let mut body = Vec::new();
        for &v in vs {
            encode_varint(v, &mut body);
        }
        self.bytes(tag, &body)
    }
    fn bytes(mut self, tag: u32, b: &[u8]) -> Self {
        encode_key(tag, WireType::LengthDelimited, &mut self.0);
        encode_varint(b.len() as u64, &mut self.0);
        self.0.extend_from_slice(b);
        self
    }
    fn fixed32(mut self, tag: u32, v: u32) -> Self {
        encode_key(tag, WireType::ThirtyTwoBit, &mut self.0);
        self.0.extend_from_slice(&v.to_le_bytes());
        self
    }
    fn group(mut self, tag: u32, inner: &Pb) -> Self {
        encode_key(tag, WireType::StartGroup, &mut self.0);
        self.0.extend_from_slice(&inner.0);
        encode_key(tag, WireType::EndGroup, &mut self.0);
        self
    }
    fn raw(mut self, b: &[u8]) -> Self {
        self.0.extend_from_slice(b);
        self
    }
}

fn vec3(x: f64, y: f64, z: f64) -> Vec<u8> {
    Pb::default().f64(1, x).f64(2, y).f64(3, z).0
}

/// What one read of a message gave: its tree and whether it was typed.
#[derive(Debug)]
struct Seen {
    topic: String,
    index: usize,
    known: bool,
    value: Value,
}

struct Keep {
    typed: bool,
    by_ref: bool,
    seen: Vec<Seen>,
}

impl Visitor for Keep {
    fn message(&mut self, m: DecodedMessage<'_>) -> Result<(), Error> {
        self.message_ref(&m)
    }
    fn message_ref(&mut self, m: &DecodedMessage<'_>) -> Result<(), Error> {
        self.seen.push(Seen { topic: m.topic.to_string(), index: m.index, known: matches!(m.body, Body::Known(_)), value: m.value().into_owned() });
        Ok(())
    }
    fn typed(&self) -> bool {
        self.typed
    }
    fn by_ref(&self) -> bool {
        self.by_ref
    }
}

/// One file with a channel per kind (this crate's own schema) holding `messages` (topic,
/// bytes), in order, 1 ms apart.
fn file(messages: &[(&str, Vec<u8>)]) -> Vec<u8> {
    let mut w = mcap::Writer::new(std::io::Cursor::new(Vec::new())).unwrap();
    let mut channel = |topic: &str, name: String, data: Vec<u8>| {
        let s = w.add_schema(&name, "protobuf", &data).unwrap();
        (topic.to_string(), w.add_channel(s, topic, "protobuf", &Default::default()).unwrap())
    };
    let channels = [
        channel(topics::HAND, HandState::schema_name(), HandState::schema_data()),
        channel(topics::MOTORS, MotorState::schema_name(), MotorState::schema_data()),
        channel(topics::CONSTRAINTS, ConstraintState::schema_name(), ConstraintState::schema_data()),
        channel(topics::ENERGY, EnergyState::schema_name(), EnergyState::schema_data()),
        channel(topics::CONTACTS, ContactState::schema_name(), ContactState::schema_data()),
    ];
    for (k, (topic, data)) in messages.iter().enumerate() {
        let id = channels.iter().find(|(t, _)| t == topic).unwrap().1;
        let t = 1_000_000 * k as u64;
        let header = mcap::records::MessageHeader { channel_id: id, sequence: k as u32, log_time: t, publish_time: t };
        w.write_to_known_channel(&header, data).unwrap();
    }
    w.finish().unwrap();
    w.into_inner().into_inner()
}

/// Reads `bytes` three ways: generic, typed, typed by reference.
fn three_ways(bytes: &[u8]) -> [Result<Vec<Seen>, String>; 3] {
    [(false, false), (true, false), (true, true)].map(|(typed, by_ref)| {
        let path = tempfile::NamedTempFile::new().unwrap();
        std::fs::write(path.path(), bytes).unwrap();
        let mut keep = Keep { typed, by_ref, seen: Vec::new() };
        schemas::stream_recording(path.path(), None, &mut keep).map(|_| keep.seen).map_err(|e| e.to_string())
    })
}

/// The three reads of `messages` agree, message by message; the typed ones are typed.
fn agree(messages: &[(&str, Vec<u8>)]) {
    let [generic, typed, by_ref] = three_ways(&file(messages));
    let generic = generic.unwrap();
    for (how, seen) in [("typed", typed.unwrap()), ("by reference", by_ref.unwrap())] {
        assert_eq!(seen.len(), generic.len(), "{how}");
        for (g, t) in generic.iter().zip(&seen) {
            let at = format!("{how}: {} #{}", g.topic, g.index);
            assert!(!g.known && t.known, "{at}");
            assert!(g.value.same_bits(&t.value), "{at}:\ngeneric {:?}\n  typed {:?}", g.value, t.value);
        }
    }
}

/// All three reads refuse `bad` (after `before`), at the same message.
fn refused(before: &[(&str, Vec<u8>)], bad: (&str, Vec<u8>)) {
    let mut messages = before.to_vec();
    messages.push(bad);
    let [generic, typed, by_ref] = three_ways(&file(&messages));
    let generic = generic.expect_err("the generic reader refuses it");
    // "topic /motors: message #0 (log_time 1000000 ns, protobuf)": where, not why
    let at = |e: &str| e.find("topic ").zip(e.find("):")).map(|(a, b)| e[a..b].to_string());
    for (how, r) in [("typed", typed), ("by reference", by_ref)] {
        let e = r.expect_err(how);
        assert!(at(&e).is_some() && at(&e) == at(&generic), "{how}: {e}\ngeneric: {generic}");
    }
}

fn names(tag: u32, names: &[&str]) -> Pb {
    names.iter().fold(Pb::default(), |p, n| p.bytes(tag, n.as_bytes()))
}

#[test]
fn missing_and_unknown_fields_read_as_prost_reflect_reads_them() {
    let unknown = |p: Pb| p.varint(99, 7).f64(100, 1.5).bytes(101, b"xyz").fixed32(102, 3).group(103, &Pb::default().varint(1, 2));
    agree(&[
        // empty messages: every field its default
        (topics::HAND, Vec::new()),
        (topics::MOTORS, Vec::new()),
        (topics::CONSTRAINTS, Vec::new()),
        (topics::ENERGY, Vec::new()),
        (topics::CONTACTS, Vec::new()),
        // some fields only, unknown ones among them (a group too: the walk leaves it to prost)
        (topics::HAND, unknown(Pb::default().f64(1, 0.25)).bytes(3, &vec3(1.0, -0.0, f64::NAN)).0),
        (topics::ENERGY, unknown(Pb::default().f64(6, 2.0)).f64(12, -1e-300).0),
        (topics::CONTACTS, Pb::default().f64(1, 0.5).varint(99, 1).packed(6, &[1.0, 2.0]).fixed32(98, 1).0),
    ]);
}

#[test]
fn repeated_fields_packed_unpacked_and_mixed_append_and_scalars_given_twice_keep_the_last() {
    agree(&[
        (topics::MOTORS, Pb::default().f64(2, 1.0).f64(2, 2.0).packed(2, &[3.0, 4.0]).f64(2, 5.0).f64(1, 0.1).f64(1, 0.2).0),
        (topics::CONSTRAINTS, names(5, &["a", "b"]).packed(2, &[1.0]).f64(3, 7.0).packed(3, &[]).packed(4, &[f64::INFINITY, -2.0]).0),
        // mode: packed and unpacked codes, one past 32 bits (a uint32 keeps its low 32 bits)
        (topics::CONTACTS, Pb::default().varint(3, 1).packed_varints(3, &[2, 0, (1 << 33) + 3]).varint(3, u64::MAX).0),
        // a nested message given twice is merged field by field
        (topics::HAND, Pb::default().bytes(2, &vec3(1.0, 2.0, 3.0)).bytes(2, &Pb::default().f64(2, 9.0).0).f64(5, 1.0).f64(5, 2.0).0),
    ]);
}

#[test]
fn names_apart_or_changing_between_messages_are_read_again() {
    let contact = |names: Pb| names.f64(1, 0.0).packed(4, &[0.1, 0.2]).0;
    agree(&[
        (topics::CONTACTS, contact(names(2, &["left", "right"]))),
        (topics::CONTACTS, contact(names(2, &["left", "right"]))), // the same bytes: kept
        (topics::CONTACTS, contact(names(2, &["left", "rite"]))), // one changed
        (topics::CONTACTS, contact(names(2, &["left"]))), // one fewer
        // apart: another field between the two entries
        (topics::CONTACTS, Pb::default().bytes(2, b"left").f64(1, 1.0).bytes(2, b"right").0),
        (topics::CONTACTS, contact(names(2, &["left", "right", "third"]))),
        (topics::ENERGY, names(13, &["j1", "j2"]).f64(1, 0.0).raw(&names(13, &["j3"]).0).0),
        (topics::ENERGY, names(13, &["j1", "j2"]).f64(1, 0.0).raw(&names(13, &["j3"]).0).0),
        (topics::MOTORS, names(7, &["é", ""]).0),
    ]);
}

#[test]
fn bytes_that_do_not_decode_are_refused_by_every_path() {
    let good = vec![(topics::CONTACTS, names(2, &["a"]).packed(4, &[1.0]).0)];
    // time as a varint (a double has wire type 1)
    refused(&good, (topics::CONTACTS, Pb::default().varint(1, 5).0));
    // a packed double of 12 bytes
    refused(&good, (topics::MOTORS, Pb::default().bytes(2, &[0; 12]).0));
    // truncated: a double cut short, a length past the end
    refused(&good, (topics::ENERGY, Pb::default().f64(6, 1.0).0[..5].to_vec()));
    refused(&good, (topics::CONSTRAINTS, Pb::default().raw(&[0x12, 0x10, 0, 0]).0));
    // a name that is not UTF-8, after a good one (the by-reference path keeps the good one's bytes)
    refused(&good, (topics::CONTACTS, Pb::default().bytes(2, &[0xff, 0xfe]).0));
    // field number 0
    refused(&good, (topics::HAND, Pb::default().raw(&[0x01, 0, 0, 0, 0, 0, 0, 0, 0]).0));
    // a mode code of fixed64 wire type
    refused(&good, (topics::CONTACTS, Pb::default().f64(3, 1.0).0));
}
