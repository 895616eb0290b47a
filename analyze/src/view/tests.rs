//! `analyze view` read back without Rerun: the RRD framing and protobuf messages decoded with
//! this module's own structs, every chunk with arrow's IPC reader (an independent decoder), and
//! the values compared with the recording (exact: f64 scalars are stored as f64). The check
//! against Rerun itself is the e2e acceptance test (`tests/e2e/rerun_view.rs`).

use std::collections::BTreeMap;

use arrow_array::cast::AsArray;
use arrow_array::types::{DurationNanosecondType, Float64Type};
use arrow_array::{Array, RecordBatch};
use arrow_schema::{DataType, TimeUnit};
use prost::Message;

use super::rrd::{self, ArrowMsg, BlueprintActivationCommand, SetStoreInfo};
use super::{encode, read_input, Input};

/// Frames of an RRD stream: `(kind, offset of the payload, payload)`, after checking the stream
/// header, up to the `End` message; then the stream footer, which must point at the `End`
/// message's payload with its xxh32 and end the file.
fn frames(bytes: &[u8]) -> Vec<(u64, usize, &[u8])> {
    assert_eq!(&bytes[..4], b"RRF2");
    assert_eq!(bytes[4..8], [0, 41, 0, 0], "written as Rerun 0.41.0");
    assert_eq!(bytes[8..12], [1, 2, 0, 0], "LZ4, protobuf");
    let mut out = Vec::new();
    let mut i = 12;
    loop {
        let kind = u64::from_le_bytes(bytes[i..i + 8].try_into().unwrap());
        let len = u64::from_le_bytes(bytes[i + 8..i + 16].try_into().unwrap()) as usize;
        out.push((kind, i + 16, &bytes[i + 16..i + 16 + len]));
        i += 16 + len;
        if kind == rrd::KIND_END {
            break;
        }
    }
    let (_, start, footer) = *out.last().unwrap();
    assert_eq!(bytes.len(), i + 32, "the stream footer ends the file");
    let tail = &bytes[i..];
    assert_eq!(u64::from_le_bytes(tail[..8].try_into().unwrap()) as usize, start);
    assert_eq!(u64::from_le_bytes(tail[8..16].try_into().unwrap()) as usize, footer.len());
    assert_eq!(u32::from_le_bytes(tail[16..20].try_into().unwrap()), xxhash_rust::xxh32::xxh32(footer, super::manifest::CRC_SEED));
    assert_eq!(&tail[20..], b"RRF2FOOT\x01\x00\x00\x00");
    out
}

struct Decoded {
    stores: Vec<SetStoreInfo>,
    activations: Vec<BlueprintActivationCommand>,
    /// Per store kind (1 recording, 2 blueprint): entity path -> batches.
    chunks: BTreeMap<(i32, String), Vec<RecordBatch>>,
}

fn decode(bytes: &[u8]) -> Decoded {
    let mut d = Decoded { stores: Vec::new(), activations: Vec::new(), chunks: BTreeMap::new() };
    for (kind, _, payload) in frames(bytes) {
        match kind {
            rrd::KIND_END => {}
            rrd::KIND_SET_STORE_INFO => d.stores.push(SetStoreInfo::decode(payload).unwrap()),
            rrd::KIND_BLUEPRINT_ACTIVATION => d.activations.push(BlueprintActivationCommand::decode(payload).unwrap()),
            rrd::KIND_ARROW_MSG => {
                let m = ArrowMsg::decode(payload).unwrap();
                assert_eq!((m.compression, m.encoding), (rrd::COMPRESSION_LZ4, 1));
                let batch = rrd::payload_batch(&m).unwrap();
                let meta = batch.schema().metadata().clone();
                assert_eq!(meta["rerun:id"], m.chunk_id.unwrap().chunk_name());
                assert_eq!(meta["sorbet:version"], "0.1.4");
                assert_eq!(m.is_static, Some(!batch.schema().fields().iter().any(|f| f.metadata().get("rerun:kind").is_some_and(|k| k == "index"))));
                let store = m.store_id.unwrap().kind;
                d.chunks.entry((store, meta["rerun:entity_path"].clone())).or_default().push(batch);
            }
            k => panic!("unexpected frame kind {k}"),
        }
    }
    d
}

fn synth_input(dir: &std::path::Path) -> Input {
    let (s, _) = schemas::synth::unilateral();
    read_input(&s.write_in(dir)).unwrap()
}

/// The scalars of `entity` (its temporal chunk) and their `sim_time`, ns.
fn series(d: &Decoded, entity: &str) -> (Vec<i64>, Vec<f64>) {
    let batches = d.chunks.get(&(1, entity.to_string())).unwrap_or_else(|| panic!("no entity {entity}"));
    let b = batches.iter().find(|b| b.schema().column_with_name("sim_time").is_some()).unwrap();
    let (_, field) = b.schema().column_with_name("sim_time").map(|(i, f)| (i, f.clone())).unwrap();
    assert_eq!(field.data_type(), &DataType::Duration(TimeUnit::Nanosecond), "a duration timeline, not a 1970 date");
    assert_eq!(field.metadata()["rerun:kind"], "index");
    let t = b.column_by_name("sim_time").unwrap().as_primitive::<DurationNanosecondType>().values().to_vec();
    let list = b.column_by_name("Scalars:scalars").unwrap().as_list::<i32>();
    let v = list.values().as_primitive::<Float64Type>().values().to_vec();
    assert_eq!(list.len(), t.len());
    assert_eq!(v.len(), t.len(), "one scalar per row");
    (t, v)
}

#[test]
fn the_stream_decodes_and_holds_the_recorded_signals_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let input = synth_input(dir.path());
    let path = dir.path().join(format!("{}.mcap", input.run.name));
    let rec = schemas::read_recording(&path).unwrap();
    let bytes = encode(std::slice::from_ref(&input), "my-run").unwrap();
    let d = decode(&bytes);

    // a blueprint store made the default, then the recording, both of application id "my-run"
    assert_eq!(d.stores.len(), 2);
    let ids: Vec<_> = d.stores.iter().map(|s| s.info.as_ref().unwrap().store_id.clone().unwrap()).collect();
    assert_eq!(ids.iter().map(|i| i.kind).collect::<Vec<_>>(), [2, 1]);
    assert!(ids.iter().all(|i| i.application_id.as_ref().unwrap().id == "my-run"));
    assert_eq!(d.activations.len(), 1);
    assert!(d.activations[0].make_default);
    assert_eq!(d.activations[0].blueprint_id.as_ref(), Some(&ids[0]));

    // every current, by joint name, with the recorded values at the recorded times
    let motors = rec.read::<schemas::MotorState>().unwrap();
    let joints = rec.run().unwrap().joint_names;
    assert!(joints.len() >= 2);
    for (j, name) in joints.iter().enumerate() {
        let (t, v) = series(&d, &format!("/current_A/{name}"));
        assert_eq!(t, motors.iter().map(|(t, _)| (t * 1e9).round() as i64).collect::<Vec<_>>());
        assert_eq!(v, motors.iter().map(|(_, m)| m.current[j]).collect::<Vec<_>>());
        let style = &d.chunks[&(1, format!("/current_A/{name}"))].iter().find(|b| b.schema().column_with_name("sim_time").is_none()).unwrap();
        let names = style.column_by_name("SeriesLines:names").unwrap().as_list::<i32>();
        assert_eq!(names.values().as_string::<i32>().value(0), format!("{name} [A]"));
    }
    // contact forces and modes by contact name; energy totals and the residual
    let contacts = rec.read::<schemas::ContactState>().unwrap();
    for (c, name) in rec.run().unwrap().contacts.iter().enumerate() {
        let (_, f) = series(&d, &format!("/normal_force_N/{name}"));
        assert_eq!(f, contacts.iter().map(|(_, s)| s.normal_force[c]).collect::<Vec<_>>());
        let (_, m) = series(&d, &format!("/contact_mode/{name}"));
        assert_eq!(m, contacts.iter().map(|(_, s)| f64::from(s.mode[c])).collect::<Vec<_>>());
    }
    let energy = rec.read::<schemas::EnergyState>().unwrap();
    assert_eq!(series(&d, "/energy_J/electric-in").1, energy.iter().map(|(_, e)| e.electric_energy_total).collect::<Vec<_>>());
    assert_eq!(series(&d, "/energy_residual_J").1, energy.iter().map(|(_, e)| e.balance_residual).collect::<Vec<_>>());

    // the blueprint names the views of the signals
    let origins: Vec<String> = d
        .chunks
        .iter()
        .filter(|((store, _), _)| *store == 2)
        .flat_map(|(_, bs)| bs.iter())
        .filter_map(|b| b.column_by_name("ViewBlueprint:space_origin").map(|c| c.as_list::<i32>().values().as_string::<i32>().value(0).to_string()))
        .collect();
    for o in ["/world", "/current_A", "/normal_force_N", "/contact_mode", "/electric_energy_J", "/energy_J", "/energy_residual_J"] {
        assert!(origins.iter().any(|x| x == o), "no view of {o}: {origins:?}");
    }
    // row ids are unique over the whole stream
    let mut rows = std::collections::BTreeSet::new();
    for b in d.chunks.values().flatten() {
        let ids = b.column_by_name("rerun.controls.RowId").unwrap().as_fixed_size_binary();
        for k in 0..ids.len() {
            assert!(rows.insert(ids.value(k).to_vec()), "row id used twice");
        }
    }
}

#[test]
fn the_same_input_gives_the_same_bytes_and_another_input_another_recording_id() {
    let dir = tempfile::tempdir().unwrap();
    let a = encode(&[synth_input(dir.path())], "x").unwrap();
    let b = encode(&[synth_input(dir.path())], "x").unwrap();
    assert!(a == b, "two conversions of one recording differ");
    let mut s = schemas::synth::Synth::new("other", &["elbow4"], 3);
    s.n = 50;
    let other = read_input(&s.write_in(dir.path())).unwrap();
    let c = encode(&[other], "x").unwrap();
    let rec_id = |bytes: &[u8]| decode(bytes).stores[1].info.as_ref().unwrap().store_id.as_ref().unwrap().recording_id.clone();
    assert_ne!(rec_id(&a), rec_id(&c));
}

#[test]
fn several_runs_go_side_by_side_under_their_names() {
    let dir = tempfile::tempdir().unwrap();
    let one = read_input(&schemas::synth::Synth::new("one-elbow", &["elbow4"], 3).write_in(dir.path())).unwrap();
    let two = read_input(&schemas::synth::Synth::new("two-elbow", &["elbow4", "elbow7"], 3).write_in(dir.path())).unwrap();
    let d = decode(&encode(&[one, two], "cmp").unwrap());
    for e in ["/current_A/one-elbow/joint1", "/current_A/two-elbow/joint3", "/normal_force_N/two-elbow/elbow7", "/energy_J/electric-in/one-elbow", "/energy_residual_J/two-elbow"] {
        assert!(d.chunks.contains_key(&(1, e.to_string())), "no entity {e}");
    }
    assert!(!d.chunks.contains_key(&(1, "/normal_force_N/one-elbow/elbow7".to_string())));
}

/// Every entity's rows, whatever chunks they are in: per entity of the recording store, its
/// static cells and its temporal rows (time, then every data column's cell), in time order.
#[allow(clippy::type_complexity)]
fn rows_by_entity(d: &Decoded) -> BTreeMap<String, (Vec<(String, arrow_array::ArrayRef)>, Vec<(i64, Vec<(String, arrow_array::ArrayRef)>)>)> {
    let mut out = BTreeMap::new();
    for ((store, entity), batches) in &d.chunks {
        if *store != 1 {
            continue;
        }
        let (statics, temporal): (&mut Vec<_>, &mut Vec<_>) = {
            let e = out.entry(entity.clone()).or_insert_with(|| (Vec::new(), Vec::new()));
            (&mut e.0, &mut e.1)
        };
        for b in batches {
            let data: Vec<(String, &arrow_array::ListArray)> = b
                .schema()
                .fields()
                .iter()
                .zip(b.columns())
                .filter(|(f, _)| f.metadata().get("rerun:kind").is_some_and(|k| k == "data"))
                .map(|(f, c)| (f.name().clone(), c.as_list::<i32>()))
                .collect();
            match b.column_by_name("sim_time") {
                None => statics.extend(data.iter().map(|(n, c)| (n.clone(), c.value(0)))),
                Some(t) => {
                    let t = t.as_primitive::<DurationNanosecondType>();
                    for k in 0..b.num_rows() {
                        temporal.push((t.value(k), data.iter().map(|(n, c)| (n.clone(), c.value(k))).collect()));
                    }
                }
            }
        }
        statics.sort_by(|a, b| a.0.cmp(&b.0));
        temporal.sort_by_key(|(t, _)| *t);
    }
    out
}

/// The windowed encoder (issue 29): a recording drawn in windows of 7 samples holds, entity by
/// entity, exactly the rows and the static cells of the same recording drawn in one window
/// (times and values, each cell compared as Arrow data), with each static chunk once, and no
/// chunk larger than the cut by size allows.
#[test]
fn windows_hold_the_rows_of_the_whole_run() {
    let dir = tempfile::tempdir().unwrap();
    let input = synth_input(dir.path());
    let n = input.run.whole.counts[schemas::topics::MOTORS];
    assert!(n > 50, "{n} samples: several windows of 7");
    let encode_rows = |rows: usize| super::encode_to(std::slice::from_ref(&input), "w", Vec::new(), "w.rrd", rows).unwrap().0;
    let one = decode(&encode_rows(super::window::WINDOW_ROWS));
    let many = decode(&encode_rows(7));
    let (a, b) = (rows_by_entity(&one), rows_by_entity(&many));
    assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>());
    for (entity, (sa, ta)) in &a {
        let (sb, tb) = &b[entity];
        assert!(sa == sb, "{entity}: static cells differ");
        assert_eq!(ta.len(), tb.len(), "{entity}: rows");
        for (ra, rb) in ta.iter().zip(tb) {
            assert!(ra == rb, "{entity}: the row at {} ns differs", ra.0);
        }
    }
    // one window is one temporal chunk per entity; seven samples, several
    let chunks = |d: &Decoded, e: &str| d.chunks[&(1, e.to_string())].iter().filter(|b| b.column_by_name("sim_time").is_some()).count();
    assert_eq!(chunks(&one, "/energy_residual_J"), 1);
    assert!(chunks(&many, "/energy_residual_J") >= n / (8 * 7), "{} chunks of {n} samples", chunks(&many, "/energy_residual_J"));
    // no window holds more than 8 times the window's rows (the cut by size of a file whose
    // topics do not interleave)
    for ((_, e), batches) in &many.chunks {
        assert!(batches.iter().all(|b| b.num_rows() <= 8 * 7), "{e}: a chunk of more than 56 rows");
    }
    let statics = |d: &Decoded, e: &str| d.chunks[&(1, e.to_string())].iter().filter(|b| b.column_by_name("sim_time").is_none()).count();
    assert_eq!(statics(&many, "/energy_residual_J"), 1);
    assert_eq!(statics(&many, "/world/target_path"), 1);
}

/// A `/tf` whose URDF root link is named like the world (`world` → `world`, then `world` →
/// `base_link`, as UR5 and Z1 of example-robot-data recorded before the recorder left the
/// self-transform out): the tree's root is `world` and the self-transform is no frame; a real
/// cycle is still refused.
#[test]
fn a_root_link_named_world_is_the_root_not_a_cycle() {
    use schemas::{Quat, TransformEntry, Transforms, Vec3};
    let entry = |parent: &str, child: &str, x: f64| TransformEntry {
        parent_frame_id: parent.into(),
        child_frame_id: child.into(),
        translation: Vec3 { x, y: 0.0, z: 0.0 },
        rotation: Quat { x: 0.0, y: 0.0, z: 0.0, w: 1.0 },
    };
    let msg = Transforms { transforms: vec![entry("world", "world", 0.0), entry("world", "base_link", 0.5), entry("base_link", "link1", 0.25)] };
    let mut tree = super::run::FrameTree::default();
    tree.take("ur5.mcap", &msg).unwrap();
    tree.take("ur5.mcap", &msg).unwrap();
    assert_eq!(tree.root("ur5.mcap").unwrap(), "world");
    assert_eq!(tree.frames.iter().map(|(n, _)| n.as_str()).collect::<Vec<_>>(), ["base_link", "link1"]);
    let latest = &tree.latest;
    let poses = super::run::world_poses("world", &tree.frames, |i| latest[i]);
    assert_eq!(poses["link1"].translation, [0.75, 0.0, 0.0]);
    let cycle = Transforms { transforms: vec![entry("a", "b", 0.0), entry("b", "a", 0.0)] };
    let mut tree = super::run::FrameTree::default();
    tree.take("c.mcap", &cycle).unwrap();
    let err = tree.root("c.mcap").unwrap_err().to_string();
    assert!(err.contains("c.mcap") && err.contains("no root frame"), "{err}");
}

/// The RRD footer (issue 27 item 5): one manifest per store, one row per chunk of that store,
/// each row pointing at its chunk's message (the chunk id in the message at that offset and
/// length), with the chunk's entity, static flag, rows and first and last `sim_time`; the
/// sorbet schema names every entity's component.
#[test]
fn the_footer_lists_every_chunk_where_it_lies() {
    use arrow_array::{BooleanArray, DurationNanosecondArray, FixedSizeBinaryArray, StringArray, UInt64Array};
    let dir = tempfile::tempdir().unwrap();
    let input = synth_input(dir.path());
    let bytes = super::encode_to(std::slice::from_ref(&input), "f", Vec::new(), "f.rrd", 7).unwrap().0;
    let all = frames(&bytes);
    let footer = super::manifest::RrdFooter::decode(all.last().unwrap().2).unwrap();
    assert_eq!(footer.manifests.len(), 2);
    let mut seen = 0;
    for m in &footer.manifests {
        let store = m.store_id.clone().unwrap();
        let part = m.data.as_ref().unwrap();
        assert_eq!((part.encoder_version, part.compression), (1, 1));
        let mut r = arrow_ipc::reader::StreamReader::try_new(part.payload.as_deref().unwrap(), None).unwrap();
        let data = r.next().unwrap().unwrap();
        let col = |name: &str| data.column_by_name(name).unwrap_or_else(|| panic!("no column {name}")).clone();
        let (entity, ids, statics) = (col("chunk_entity_path"), col("chunk_id"), col("chunk_is_static"));
        let entity = entity.as_any().downcast_ref::<StringArray>().unwrap();
        let ids = ids.as_any().downcast_ref::<FixedSizeBinaryArray>().unwrap();
        let statics = statics.as_any().downcast_ref::<BooleanArray>().unwrap();
        let u64s = |name: &str| col(name).as_any().downcast_ref::<UInt64Array>().unwrap().values().to_vec();
        let (rows, offsets, sizes) = (u64s("chunk_num_rows"), u64s("chunk_byte_offset"), u64s("chunk_byte_size"));
        let chunks_of_store = all.iter().filter(|(k, _, p)| *k == rrd::KIND_ARROW_MSG && ArrowMsg::decode(*p).unwrap().store_id.as_ref() == Some(&store)).count();
        assert_eq!(data.num_rows(), chunks_of_store, "one row per chunk of the store");
        for k in 0..data.num_rows() {
            let (o, n) = (offsets[k] as usize, sizes[k] as usize);
            assert!(all.iter().any(|(kind, at, p)| *kind == rrd::KIND_ARROW_MSG && *at == o && p.len() == n), "row {k}: no message at {o}+{n}");
            let msg = ArrowMsg::decode(&bytes[o..o + n]).unwrap();
            assert_eq!(msg.chunk_id.unwrap().bytes(), ids.value(k));
            assert_eq!(msg.is_static, Some(statics.value(k)));
            let batch = rrd::payload_batch(&msg).unwrap();
            assert_eq!(batch.schema().metadata()["rerun:entity_path"], entity.value(k));
            assert_eq!(batch.num_rows() as u64, rows[k]);
            if let Some(t) = batch.column_by_name("sim_time") {
                let t = t.as_primitive::<DurationNanosecondType>();
                let start = col("sim_time:start");
                let end = col("sim_time:end");
                let (start, end) = (start.as_any().downcast_ref::<DurationNanosecondArray>().unwrap(), end.as_any().downcast_ref::<DurationNanosecondArray>().unwrap());
                assert_eq!((start.value(k), end.value(k)), (t.value(0), t.value(t.len() - 1)), "row {k}");
            }
            seen += 1;
        }
        let schema = arrow_ipc::reader::StreamReader::try_new(m.sorbet_schema.as_ref().unwrap().arrow_schema.as_deref().unwrap(), None).unwrap().schema();
        if store.kind == 1 {
            assert!(schema.field_with_name("/energy_residual_J:Scalars:scalars").is_ok());
            assert!(schema.field_with_name("property:RecordingInfo:name").is_ok());
            assert_eq!(schema.field_with_name("sim_time").unwrap().data_type(), &DataType::Duration(TimeUnit::Nanosecond));
        }
        assert_eq!(m.sorbet_schema_sha256.as_ref().map(Vec::len), Some(32));
    }
    assert_eq!(seen, all.iter().filter(|(k, _, _)| *k == rrd::KIND_ARROW_MSG).count());
}
