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

/// Frames of an RRD stream: `(kind, payload)`, after checking the stream header.
fn frames(bytes: &[u8]) -> Vec<(u64, &[u8])> {
    assert_eq!(&bytes[..4], b"RRF2");
    assert_eq!(bytes[4..8], [0, 41, 0, 0], "written as Rerun 0.41.0");
    assert_eq!(bytes[8..12], [0, 2, 0, 0], "uncompressed, protobuf");
    let mut out = Vec::new();
    let mut i = 12;
    while i < bytes.len() {
        let kind = u64::from_le_bytes(bytes[i..i + 8].try_into().unwrap());
        let len = u64::from_le_bytes(bytes[i + 8..i + 16].try_into().unwrap()) as usize;
        out.push((kind, &bytes[i + 16..i + 16 + len]));
        i += 16 + len;
    }
    assert_eq!(i, bytes.len(), "the last frame ends at the end of the file");
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
    for (kind, payload) in frames(bytes) {
        match kind {
            rrd::KIND_SET_STORE_INFO => d.stores.push(SetStoreInfo::decode(payload).unwrap()),
            rrd::KIND_BLUEPRINT_ACTIVATION => d.activations.push(BlueprintActivationCommand::decode(payload).unwrap()),
            rrd::KIND_ARROW_MSG => {
                let m = ArrowMsg::decode(payload).unwrap();
                assert_eq!((m.compression, m.encoding, m.uncompressed_size), (1, 1, m.payload.len() as u64));
                let mut r = arrow_ipc::reader::StreamReader::try_new(m.payload.as_slice(), None).unwrap();
                let batch = r.next().unwrap().unwrap();
                assert!(r.next().is_none(), "one batch per chunk");
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
