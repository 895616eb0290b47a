//! Per-contact metrics of runs with contact models (issue 11: rigid unilateral contacts after
//! Pfeiffer & Glocker, *Multibody Dynamics with Unilateral Contacts*, 1996, and compliant ones),
//! from `/contacts` (one sample per output time) and `/contact_events` (one message per event,
//! at its time): [`ContactStateMetrics`]. Bilateral contacts (the paper's) are covered by
//! [`super::ContactMetrics`] from `/constraints` (the time the table pulls).
//!
//! - **Time in contact**: the time with mode ≠ separated. Between two samples of the same status
//!   the whole interval counts or not; an interval where the status changes counts from (closing)
//!   or up to (opening) the event that changed it, when the recording has it in that interval
//!   (a lift-off opens; a touch-down, an impact or a rest closes): exact to the event times.
//!   Without such an event the change is put at the midpoint (error ≤ dt/2 per change).
//! - **Events** counted per kind; **impact energy lost** = Σ `energy_lost` of the impacts and
//!   rests of the contact (J); the recorded cumulative impact loss, friction work and damping
//!   loss at the last sample (J).
//! - **Friction needed to stick**: `max |f_t| / f_n` over the sticking samples (mode 1) with
//!   `f_n > 0`, and over every sample in contact (modes 1, 2, 3) with `f_n > 0` (a sliding
//!   contact gives `μ`): the smallest μ that would have held.
//! - **Normal force** min and max over the samples in contact, N.
//!
//! Memory: a few numbers per contact, plus the status changes and the events (bounded by the
//! run's `max_events`).

use schemas::contact_event_kind as kind;
use schemas::{contact_mode, ContactEventMsg, ContactState, DecodedMessage, CONTACT_EVENT_KINDS};
use serde::{Deserialize, Serialize};

use crate::Error;

/// Events of one contact, per kind.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EventCounts {
    pub lift_offs: u64,
    pub touch_downs: u64,
    pub impacts: u64,
    /// Bouncing sequences ended by the Zeno rule (a plastic last impact).
    pub rests: u64,
    pub stick_to_slip: u64,
    pub slip_to_stick: u64,
}

/// One contact of a run with `/contacts`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactStateMetrics {
    /// Contact name (metadata `run.contacts`).
    pub contact: String,
    /// `bilateral`, `unilateral`, `compliant` (record `contacts`; `None` without it).
    pub model: Option<String>,
    /// Coulomb μ of the model, when it has one.
    pub friction: Option<f64>,
    /// Time with mode ≠ separated, s (see the module docs).
    pub time_in_contact_s: f64,
    pub events: EventCounts,
    /// Σ `energy_lost` over the impact and rest events, J.
    pub impact_energy_lost_j: f64,
    /// Recorded cumulative impact loss at the last sample, J.
    pub impact_loss_j: f64,
    /// Recorded cumulative friction work at the last sample, J.
    pub friction_work_j: f64,
    /// Recorded cumulative damping loss at the last sample (compliant), J.
    pub damping_loss_j: f64,
    /// `max |f_t| / f_n` over the sticking samples with `f_n > 0`; `None` if it never sticks.
    pub stick_friction_needed: Option<f64>,
    /// `max |f_t| / f_n` over every sample in contact with `f_n > 0`.
    pub contact_friction_needed: Option<f64>,
    /// `min f_n` and `max f_n` over the samples in contact, N; `None` if never in contact.
    pub min_normal_force_in_contact_n: Option<f64>,
    pub max_normal_force_in_contact_n: Option<f64>,
}

/// The running reduction of one contact.
#[derive(Debug, Default, Clone)]
struct Acc {
    /// The previous sample `(t, in contact)`.
    previous: Option<(f64, bool)>,
    time_in_contact: f64,
    /// Intervals `(t0, t1, closing)` where the status changed (refined with the events).
    changes: Vec<(f64, f64, bool)>,
    stick_ratio: Option<f64>,
    contact_ratio: Option<f64>,
    fn_min: Option<f64>,
    fn_max: Option<f64>,
    /// The last sample's cumulative impact loss, friction work, damping loss.
    last: [f64; 3],
}

fn max_opt(a: Option<f64>, b: f64) -> Option<f64> {
    Some(a.map_or(b, |a| a.max(b)))
}

fn min_opt(a: Option<f64>, b: f64) -> Option<f64> {
    Some(a.map_or(b, |a| a.min(b)))
}

/// `/contacts` and `/contact_events`, reduced.
#[derive(Debug, Default)]
pub(super) struct ContactReductions {
    contacts: Vec<Acc>,
    /// `(index, log time in s, event)` of every event, in file order.
    events: Vec<(usize, f64, ContactEventMsg)>,
}

impl ContactReductions {
    /// One `/contacts` sample at `t` (its arrays were checked against the run's contacts).
    pub(super) fn state(&mut self, t: f64, s: &ContactState) {
        self.contacts.resize(s.mode.len(), Acc::default());
        let at = |v: &[f64], k: usize| v.get(k).copied().unwrap_or(0.0);
        for (k, acc) in self.contacts.iter_mut().enumerate() {
            let mode = s.mode[k];
            let in_contact = mode != contact_mode::SEPARATED;
            if let Some((t0, was)) = acc.previous {
                match (was, in_contact) {
                    (true, true) => acc.time_in_contact += t - t0,
                    (false, false) => {}
                    (_, closing) => acc.changes.push((t0, t, closing)),
                }
            }
            acc.previous = Some((t, in_contact));
            if in_contact {
                let f_n = at(&s.normal_force, k);
                acc.fn_min = min_opt(acc.fn_min, f_n);
                acc.fn_max = max_opt(acc.fn_max, f_n);
                if f_n > 0.0 {
                    let ratio = at(&s.friction_force_t1, k).hypot(at(&s.friction_force_t2, k)) / f_n;
                    acc.contact_ratio = max_opt(acc.contact_ratio, ratio);
                    if mode == contact_mode::STICKING {
                        acc.stick_ratio = max_opt(acc.stick_ratio, ratio);
                    }
                }
            }
            acc.last = [at(&s.impact_loss, k), at(&s.friction_work, k), at(&s.damping_loss, k)];
        }
    }

    /// One `/contact_events` message.
    pub(super) fn event(&mut self, m: &DecodedMessage<'_>, e: ContactEventMsg) -> Result<(), Error> {
        if !CONTACT_EVENT_KINDS.contains(&e.kind.as_str()) {
            return Err(Error::BadEvent {
                file: m.file.to_string(),
                index: m.index,
                t_s: m.t_s(),
                field: "kind",
                value: e.kind,
                detail: format!("not a contact event kind (one of {})", CONTACT_EVENT_KINDS.join(", ")),
            });
        }
        self.events.push((m.index, m.t_s(), e));
        Ok(())
    }

    /// The metrics per contact of `names` (the run's), with the models of the `contacts` record.
    pub(super) fn finish(self, file: &str, names: &[String], record: Option<&schemas::ContactsRecord>) -> Result<Vec<ContactStateMetrics>, Error> {
        let mut out: Vec<ContactStateMetrics> = names
            .iter()
            .enumerate()
            .map(|(k, name)| {
                let info = record.and_then(|r| r.contact(name));
                let acc = self.contacts.get(k).cloned().unwrap_or_default();
                ContactStateMetrics {
                    contact: name.clone(),
                    model: info.map(|i| i.model.clone()),
                    friction: info.and_then(|i| i.friction),
                    time_in_contact_s: acc.time_in_contact,
                    events: EventCounts::default(),
                    impact_energy_lost_j: 0.0,
                    impact_loss_j: acc.last[0],
                    friction_work_j: acc.last[1],
                    damping_loss_j: acc.last[2],
                    stick_friction_needed: acc.stick_ratio,
                    contact_friction_needed: acc.contact_ratio,
                    min_normal_force_in_contact_n: acc.fn_min,
                    max_normal_force_in_contact_n: acc.fn_max,
                }
            })
            .collect();
        let mut per_contact: Vec<Vec<(f64, &ContactEventMsg)>> = vec![Vec::new(); names.len()];
        for (index, t, e) in &self.events {
            let Some(k) = names.iter().position(|n| *n == e.contact) else {
                return Err(Error::BadEvent {
                    file: file.to_string(),
                    index: *index,
                    t_s: *t,
                    field: "contact",
                    value: e.contact.clone(),
                    detail: format!("the run's contacts are {}", names.join(", ")),
                });
            };
            per_contact[k].push((*t, e));
            let m = &mut out[k];
            let c = &mut m.events;
            match e.kind.as_str() {
                kind::LIFT_OFF => c.lift_offs += 1,
                kind::TOUCH_DOWN => c.touch_downs += 1,
                kind::IMPACT => c.impacts += 1,
                kind::REST => c.rests += 1,
                kind::STICK_TO_SLIP => c.stick_to_slip += 1,
                _ => c.slip_to_stick += 1, // the kinds were checked as they came
            }
            if matches!(e.kind.as_str(), kind::IMPACT | kind::REST) {
                m.impact_energy_lost_j += e.energy_lost;
            }
        }
        // the intervals where the status changed: from or up to the event that changed it
        for (k, m) in out.iter_mut().enumerate() {
            let Some(acc) = self.contacts.get(k) else { continue };
            for &(t0, t1, closing) in &acc.changes {
                let mut inside = per_contact[k].iter().filter(|(t, _)| *t > t0 && *t <= t1);
                let part = if closing {
                    let closer = inside.rfind(|(_, e)| matches!(e.kind.as_str(), kind::TOUCH_DOWN | kind::IMPACT | kind::REST));
                    closer.map_or(0.5 * (t1 - t0), |(t, _)| t1 - t)
                } else {
                    let opener = inside.find(|(_, e)| e.kind == kind::LIFT_OFF);
                    opener.map_or(0.5 * (t1 - t0), |(t, _)| t - t0)
                };
                m.time_in_contact_s += part;
            }
        }
        Ok(out)
    }
}
