//! The contact topics and records (issue 11) through the writer and the reader: the synthetic
//! unilateral recording reads back exactly (lossless encoding: tolerance 0), its arrays are
//! indexed by contact, and the topics are absent from a recording without them.

use schemas::synth::{unilateral, Synth};
use schemas::{read_recording, topics, ArraySizes, ContactEventMsg, ContactState, ContactsRecord, EnergyTermsRecord, CONTACT_EVENT_KINDS};

#[test]
fn the_unilateral_synth_reads_back_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let (s, _) = unilateral();
    let path = s.write_in(dir.path());
    let rec = read_recording(&path).unwrap();
    let sizes = ArraySizes { joints: 3, contacts: 2 };
    let states = rec.read_sized::<ContactState>(sizes).unwrap();
    assert_eq!(states.len(), 101);
    let f = s.contacts.as_ref().unwrap();
    for (k, (t, m)) in states.iter().enumerate() {
        let tk = k as f64 * 0.01;
        assert_eq!(*t, schemas::from_log_time(schemas::to_log_time(tk)));
        assert_eq!(*m, ContactState { time: tk, ..f(tk) }, "sample {k}");
    }
    assert_eq!(states[50].1.mode, [0, 1]);
    assert_eq!(states[75].1.mode, [2, 1]);
    let events = rec.read::<ContactEventMsg>().unwrap();
    let got: Vec<(f64, &ContactEventMsg)> = events.iter().map(|(t, e)| (*t, e)).collect();
    assert_eq!(got.len(), 4);
    for ((t, e), want) in got.iter().zip(&s.contact_events) {
        assert_eq!(*e, want);
        assert_eq!(*t, schemas::from_log_time(schemas::to_log_time(want.time)));
        assert!(CONTACT_EVENT_KINDS.contains(&e.kind.as_str()));
    }
    assert_eq!(rec.record::<ContactsRecord>().unwrap(), *s.contacts_record.as_ref().unwrap());
    let terms = rec.record::<EnergyTermsRecord>().unwrap();
    assert_eq!((terms.impact_loss, terms.friction_work, terms.emf_conversion), (Some(0.06), Some(0.006), None));
    // events come before the sample that follows them, in file order too: the channel's
    // message count and times are what `sim` writes
    assert_eq!(rec.channel(topics::CONTACT_EVENTS).unwrap().message_count, 4);
    // an array of the wrong length is refused, naming the topic and the field
    let err = rec.read_sized::<ContactState>(ArraySizes { joints: 3, contacts: 3 }).unwrap_err().to_string();
    assert!(err.contains(topics::CONTACTS) && err.contains("name"), "{err}");
}

#[test]
fn a_bilateral_recording_has_no_contact_topics_or_record() {
    let dir = tempfile::tempdir().unwrap();
    let path = Synth::new("two-elbow", &["elbow4", "elbow7"], 3).write_in(dir.path());
    let rec = read_recording(&path).unwrap();
    for topic in topics::CONTACT_TOPICS {
        assert!(rec.channel(topic).is_none(), "{topic}");
        assert!(!topics::ALL.contains(&topic), "{topic}");
    }
    assert!(rec.record_opt::<ContactsRecord>().unwrap().is_none());
    assert!(rec.read::<ContactState>().is_err());
}
