//! The contact channels through the recorder and back (write → read → equal, tolerance 0: the
//! encoding is lossless), on hand-made outputs of the paper arm with its elbows declared
//! unilateral and compliant; and a bilateral run writes none of them.

use schemas::{read_recording, topics, ArraySizes, ContactEventMsg, ContactState, ContactsRecord, EnergyTermsRecord};

use super::*;
use crate::dynamics::contact::{ContactEventKind, ContactMode};
use crate::ode::ArmSystem;

fn out(mode: ContactMode, k: f64) -> ContactOutput {
    ContactOutput {
        mode,
        gap: 1e-3 * k,
        gap_rate: -0.01 * k,
        normal_force: 10.0 + k,
        friction_force: [-2.0 * k, 0.5],
        slip_velocity: [1e-3 * k, -2e-4],
        impact_loss: 0.1 * k,
        friction_work: 0.01 * k,
        damping_loss: 0.001 * k,
    }
}

fn event(t: f64, contact: usize, kind: ContactEventKind) -> ContactEvent {
    ContactEvent { t, contact, kind, impulse: 0.25, energy_lost: 0.125, gap_rate_before: -0.5, gap_rate_after: 0.25 }
}

/// Three samples of the two-elbow run at 1 ms: outputs at the initial state, contacts and events
/// made up (elbow4 unilateral, elbow7 compliant); events at 0.4 ms and 0.7 ms (before the
/// second sample) and exactly at 2 ms (the third).
fn samples(scene: &Scene, run: &Run) -> Vec<Outputs> {
    let mut sys = ArmSystem::new(scene, run);
    let y0 = sys.initial_state();
    let mut o = Outputs::default();
    sys.outputs(0.0, &y0, &mut o).expect("outputs at the initial state");
    let modes = [[ContactMode::Sticking, ContactMode::Sliding], [ContactMode::Separated, ContactMode::Sliding], [ContactMode::Sliding, ContactMode::Separated]];
    (0..3)
        .map(|k| {
            let mut s = o.clone();
            s.t = k as f64 * 1e-3;
            s.contacts = modes[k].iter().enumerate().map(|(c, &m)| out(m, (2 * k + c) as f64)).collect();
            s.events = match k {
                1 => vec![event(4e-4, 0, ContactEventKind::LiftOff), event(7e-4, 1, ContactEventKind::Impact)],
                2 => vec![event(2e-3, 0, ContactEventKind::SlipToStick)],
                _ => vec![],
            };
            s
        })
        .collect()
}

fn two_elbow(scene: &Scene) -> Run {
    scene.runs().iter().find(|r| r.name == "two-elbow").expect("the paper's two-elbow run").clone()
}

#[test]
fn contact_states_events_and_records_read_back_equal() {
    let scene = Scene::paper().expect("the built-in scene");
    let run = two_elbow(&scene);
    let mut contacts = run_contacts(&scene, &run);
    contacts[0].model = ContactModel::Unilateral { restitution: 0.5, friction: 0.6 };
    contacts[1].model = ContactModel::Compliant { stiffness: 1e5, damping: 300.0, friction: 0.6, slip_velocity: 1e-3 };
    let settings = ContactSettings { rest_velocity: 2e-4, ..Default::default() };
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("unilateral.mcap");
    let mut rec = Recorder::create_described(&path, &scene, &run, WriterOptions::default(), None, None, &contacts, &settings).unwrap();
    let outs = samples(&scene, &run);
    for o in &outs {
        rec.record(o).unwrap();
    }
    // an event after the last sample (a run that then failed): written by `record_events`
    let late = event(2.5e-3, 1, ContactEventKind::Rest);
    rec.record_events(&[late]).unwrap();
    rec.finish(Ok(&crate::integrate::Stats::default())).unwrap();

    let r = read_recording(&path).unwrap();
    let names = vec!["elbow4".to_string(), "elbow7".to_string()];
    assert_eq!(r.run().unwrap().contacts, names);
    let states = r.read_sized::<ContactState>(ArraySizes { joints: outs[0].q.len(), contacts: 2 }).unwrap();
    assert_eq!(states.len(), 3);
    for ((t, s), o) in states.iter().zip(&outs) {
        assert_eq!(*t, o.t);
        let col = |f: fn(&ContactOutput) -> f64| o.contacts.iter().map(f).collect::<Vec<_>>();
        let want = ContactState {
            time: o.t,
            name: names.clone(),
            mode: o.contacts.iter().map(|c| c.mode.code()).collect(),
            gap: col(|c| c.gap),
            gap_rate: col(|c| c.gap_rate),
            normal_force: col(|c| c.normal_force),
            friction_force_t1: col(|c| c.friction_force[0]),
            friction_force_t2: col(|c| c.friction_force[1]),
            slip_velocity_t1: col(|c| c.slip_velocity[0]),
            slip_velocity_t2: col(|c| c.slip_velocity[1]),
            impact_loss: col(|c| c.impact_loss),
            friction_work: col(|c| c.friction_work),
            damping_loss: col(|c| c.damping_loss),
        };
        assert_eq!(*s, want);
    }
    let events = r.read::<ContactEventMsg>().unwrap();
    let want: Vec<&ContactEvent> = outs.iter().flat_map(|o| &o.events).chain([&late]).collect();
    assert_eq!(events.len(), want.len());
    for ((t, e), w) in events.iter().zip(want) {
        assert_eq!(*t, w.t, "log time = event time");
        assert_eq!((e.time, e.contact.as_str(), e.kind.as_str()), (w.t, names[w.contact].as_str(), w.kind.name()));
        assert_eq!((e.impulse, e.energy_lost, e.gap_rate_before, e.gap_rate_after), (w.impulse, w.energy_lost, w.gap_rate_before, w.gap_rate_after));
    }
    // every event is in the file before the sample that follows it: the reader keeps file
    // order per topic, so check through the joint states' and events' log times
    assert!(events.windows(2).all(|w| w[0].0 <= w[1].0));
    let got = r.record::<ContactsRecord>().unwrap();
    assert_eq!(got, contacts_record_with_shapes(&scene.model, &contacts, &settings));
    // the paper's elbows are points of their links
    assert!(got.contacts.iter().all(|c| c.shape.as_ref().is_some_and(|s| s.kind == "point" && s.radius == 0.0)), "{:?}", got.contacts);
    let e4 = got.contact("elbow4").unwrap();
    assert_eq!((e4.model.as_str(), e4.restitution, e4.friction, e4.stiffness), ("unilateral", Some(0.5), Some(0.6), None));
    let e7 = got.contact("elbow7").unwrap();
    assert_eq!((e7.model.as_str(), e7.stiffness, e7.damping, e7.slip_velocity), ("compliant", Some(1e5), Some(300.0), Some(1e-3)));
    assert_eq!((e7.normal, e7.t1, e7.t2), ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]));
    assert_eq!(got.rest_velocity, 2e-4);
    let terms = r.record::<EnergyTermsRecord>().unwrap();
    let last = &outs[2].contacts;
    assert_eq!(terms.impact_loss, Some(last[0].impact_loss + last[1].impact_loss));
    assert_eq!(terms.friction_work, Some(last[0].friction_work + last[1].friction_work));
    assert_eq!(terms.damping_loss, Some(last[0].damping_loss + last[1].damping_loss));
    // `/constraints` is written as for every run
    assert_eq!(r.channel(topics::CONSTRAINTS).unwrap().message_count, 3);
}

/// A run whose contacts are all bilateral writes no contact topic and no `contacts` record,
/// whatever its outputs carry, and no contact totals in `energy_terms`.
#[test]
fn a_bilateral_run_writes_no_contact_channels() {
    let scene = Scene::paper().expect("the built-in scene");
    let run = two_elbow(&scene);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bilateral.mcap");
    let mut rec = Recorder::create(&path, &scene, &run).unwrap();
    for o in &samples(&scene, &run) {
        rec.record(o).unwrap();
    }
    rec.finish(Ok(&crate::integrate::Stats::default())).unwrap();
    let r = read_recording(&path).unwrap();
    for topic in topics::CONTACT_TOPICS.iter().chain(&topics::FRICTION_TOPICS) {
        assert!(r.channel(topic).is_none(), "{topic}");
    }
    assert!(r.record_opt::<ContactsRecord>().unwrap().is_none());
    assert!(r.record_opt::<EnergyTermsRecord>().unwrap().is_none());
}

/// The event kinds and mode codes of the simulator are the recording format's.
#[test]
fn event_kinds_and_mode_codes_are_the_formats() {
    use ContactEventKind::*;
    let kinds: Vec<&str> = [LiftOff, TouchDown, Impact, Rest, StickToSlip, SlipToStick].iter().map(|k| k.name()).collect();
    assert_eq!(kinds, schemas::CONTACT_EVENT_KINDS);
    for m in [ContactMode::Separated, ContactMode::Sticking, ContactMode::Sliding, ContactMode::Bilateral] {
        assert_eq!(schemas::contact_mode::name(m.code()), Some(m.name()));
    }
}
