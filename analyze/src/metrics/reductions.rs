//! [`Reductions`]: the metrics of [`super::RunMetrics`] as running reductions, fed one message at
//! a time while a recording is streamed (the formulas are in the parent module's docs), and
//! the checks each message passes before it counts.

use schemas::topics::ArrayIndex;
use schemas::{topics, ConstraintState, ContactEventMsg, ContactState, DecodedMessage, EnergyState, HandState, MotorState, Recording, RunResult, RunStatus};

use super::signal::negative_time;
use super::contacts::ContactReductions;
use super::{AxisError, ContactMetrics, EnergyAudit, HandError, LinkMetrics, PeakCurrent, RunMetrics, Status, REQUIRED_METRIC_TOPICS};
use crate::Error;

/// `max_k |v_k|` and the time of its first occurrence.
#[derive(Debug, Clone, Copy)]
struct Peak {
    abs: f64,
    t: f64,
}

impl Default for Peak {
    fn default() -> Self {
        Peak { abs: f64::NAN, t: f64::NAN }
    }
}

impl Peak {
    fn add(&mut self, t: f64, v: f64) {
        if self.abs.is_nan() || v.abs() > self.abs {
            *self = Peak { abs: v.abs(), t };
        }
    }
}

/// `min_k v_k` and the time of its first occurrence.
#[derive(Debug, Clone, Copy)]
struct Min {
    v: f64,
    t: f64,
}

impl Default for Min {
    fn default() -> Self {
        Min { v: f64::NAN, t: f64::NAN }
    }
}

impl Min {
    fn add(&mut self, t: f64, v: f64) {
        if self.v.is_nan() || v < self.v {
            *self = Min { v, t };
        }
    }
}

/// One error component: `Σ e²` and the peak.
#[derive(Debug, Default, Clone, Copy)]
struct Axis {
    sum_sq: f64,
    peak: Peak,
}

impl Axis {
    fn add(&mut self, t: f64, e: f64) {
        self.sum_sq += e * e;
        self.peak.add(t, e);
    }

    fn of(&self, n: usize) -> AxisError {
        AxisError { rms_m: (self.sum_sq / n as f64).sqrt(), max_abs_m: self.peak.abs, t_max_s: self.peak.t }
    }
}

/// One contact over the run.
#[derive(Debug, Default, Clone)]
struct Contact {
    min_force: Min,
    /// The previous sample `(t, f_n)`, for the trapezoid rule on `1[f_n < 0]`.
    previous: Option<(f64, f64)>,
    pull_time: f64,
    first_pull: Option<f64>,
    position: Peak,
    velocity: Peak,
}

/// Where the samples of one topic should lie: `t_k = k Δt` (`sim`'s output grid, from
/// `run.setup.output_rate_hz`), and the samples seen.
#[derive(Debug, Default, Clone, Copy)]
struct Samples {
    count: usize,
    last_t: f64,
}

/// The running reductions behind [`RunMetrics`], fed one message at a time ([`schemas::Visitor`]):
/// memory is a few numbers per joint and contact, whatever the length of the run.
///
/// Each message is checked as it comes: its arrays have one entry per joint or contact of the
/// `run` record, its values are finite (a NaN or an infinity is an error naming the topic, the
/// field and the time: it would make every peak and sum meaningless), and its time lies on the
/// recorded output grid `t_k = k / output_rate` (to 1e-6 of the interval plus 2 ns of
/// rounding; a file whose time was scaled, shifted or has a gap is refused).
#[derive(Debug, Default)]
pub struct Reductions {
    hand: [Axis; 4],
    hand_samples: Samples,
    motor_peaks: Vec<Peak>,
    motor_samples: Samples,
    contacts: Vec<Contact>,
    contact_samples: Samples,
    energy_first: Option<EnergyState>,
    energy_last: Option<EnergyState>,
    residual: Peak,
    energy_samples: Samples,
    /// Joints and contacts of the arrays seen (every message must have the first's).
    joints: Option<usize>,
    n_contacts: Option<usize>,
    /// Why the last message was refused (see the `Visitor` impl).
    error: Option<Error>,
    /// `/contacts` and `/contact_events` (runs with contact models).
    contact_states: ContactReductions,
    contact_state_samples: Samples,
    /// The contact audit of `/contacts` ([`schemas::ContactAuditor`]), from the `contacts`
    /// record on (it comes before the samples in every recording `sim` writes).
    audit: Option<schemas::ContactAuditor>,
}

/// An array of `len` entries (one per `per`) where the first message of the run had `*seen`.
fn fit(seen: &mut Option<usize>, m: &DecodedMessage<'_>, field: &str, len: usize, per: &'static str) -> Result<(), Error> {
    match *seen {
        None => {
            *seen = Some(len);
            Ok(())
        }
        Some(expected) if expected == len => Ok(()),
        Some(expected) => Err(Error::WrongLength {
            file: m.file.to_string(),
            topic: m.topic.to_string(),
            field: field.to_string(),
            index: m.index,
            t_s: m.t_s(),
            found: len,
            expected,
            per,
        }),
    }
}

/// Every number of the message is finite, and its per-joint and per-contact arrays have the
/// lengths of the first message's; the error names the first that is not.
fn check(m: &DecodedMessage<'_>, joints: &mut Option<usize>, contacts: &mut Option<usize>) -> Result<(), Error> {
    if let Some((field, value)) = m.non_finite() {
        return Err(Error::NonFinite { file: m.file.to_string(), topic: m.topic.to_string(), field, value, index: m.index, t_s: m.t_s() });
    }
    m.try_for_each_array(|field, kind, len| match kind {
        ArrayIndex::Joint => fit(joints, m, field, len, "joint"),
        ArrayIndex::Contact => fit(contacts, m, field, len, "contact"),
    })
}

impl Reductions {
    /// The error that stopped the reader: the one kept by the visitor, or the reader's own.
    pub fn take_error(&mut self, e: schemas::Error) -> Error {
        self.error.take().unwrap_or_else(|| e.into())
    }

    /// The message's time against the output grid of its `run` record; counts it.
    fn sample(samples: &mut Samples, m: &DecodedMessage<'_>) -> Result<f64, Error> {
        let t = m.t_s();
        if let Some(rate) = m.run.and_then(|r| r.setup.as_ref()).map(|s| s.output_rate_hz).filter(|r| r.is_finite() && *r > 0.0) {
            let dt = 1.0 / rate;
            let expected = samples.count as f64 * dt;
            if (t - expected).abs() > 1e-6 * dt + 2e-9 {
                return Err(Error::OffGrid {
                    file: m.file.to_string(),
                    topic: m.topic.to_string(),
                    index: m.index,
                    t_s: t,
                    expected_s: expected,
                    rate_hz: rate,
                });
            }
        }
        samples.count += 1;
        samples.last_t = t;
        Ok(t)
    }

    /// The metrics, once every message went through; `rec` holds the metadata read.
    pub fn finish(self, rec: &Recording, incomplete: Option<String>) -> Result<RunMetrics, Error> {
        let file = || rec.source.clone();
        let run = rec.run()?;
        for (what, names) in [("joint names", &run.joint_names), ("contact names", &run.contacts)] {
            if let Some(dup) = names.iter().enumerate().find_map(|(k, n)| names[..k].contains(n).then_some(n)) {
                return Err(Error::BadMetadata {
                    file: file(),
                    record: "run".into(),
                    key: what.into(),
                    value: dup.clone(),
                    detail: "named twice: every joint and contact needs its own name".into(),
                });
            }
        }
        let (status, error, error_time_s) = match &incomplete {
            Some(why) => (Status::Incomplete, Some(why.clone()), None),
            None => {
                let r = rec.record::<RunResult>()?;
                let status = match r.status {
                    RunStatus::Complete => Status::Complete,
                    RunStatus::Failed => Status::Failed,
                };
                (status, r.error, r.error_time_s)
            }
        };
        // a run that failed before its first sample (t = 0: a start the solver refuses, NaN in
        // the initial state) has its metadata and no messages: its row says so, without numbers
        let no_samples = [&self.hand_samples, &self.motor_samples, &self.contact_samples, &self.energy_samples].iter().all(|s| s.count == 0);
        if status == Status::Failed && no_samples {
            return Ok(RunMetrics::without_samples(rec.source.clone(), run, status, error, error_time_s));
        }
        for topic in REQUIRED_METRIC_TOPICS {
            rec.check_topic(topic)?;
        }
        let non_empty = |topic: &str, s: &Samples| if s.count == 0 { Err(Error::NoSamples { file: file(), topic: topic.into() }) } else { Ok(()) };
        non_empty(topics::HAND, &self.hand_samples)?;
        non_empty(topics::MOTORS, &self.motor_samples)?;
        non_empty(topics::CONSTRAINTS, &self.contact_samples)?;
        non_empty(topics::ENERGY, &self.energy_samples)?;
        // a complete run has every sample of its grid: [0, duration] at the output rate
        if let (Status::Complete, Some(setup)) = (status, &run.setup) {
            let dt = 1.0 / setup.output_rate_hz;
            for (topic, s) in [(topics::HAND, &self.hand_samples), (topics::MOTORS, &self.motor_samples), (topics::CONSTRAINTS, &self.contact_samples), (topics::ENERGY, &self.energy_samples)] {
                if s.last_t < setup.duration_s - dt * (1.0 + 1e-6) {
                    return Err(Error::ShortRun {
                        file: file(),
                        topic: topic.into(),
                        samples: s.count,
                        t_end_s: s.last_t,
                        duration_s: setup.duration_s,
                    });
                }
            }
        }
        // arrays read before the `run` record (or without it) must match it now
        for (seen, names, per) in [(self.joints, &run.joint_names, "joint"), (self.n_contacts, &run.contacts, "contact")] {
            if let Some(n) = seen.filter(|&n| n != names.len()) {
                return Err(Error::BadMetadata {
                    file: file(),
                    record: "run".into(),
                    key: format!("{per} names"),
                    value: names.join(", "),
                    detail: format!("{} names, but the messages have {n} entries per {per}", names.len()),
                });
            }
        }
        if self.contact_state_samples.count > 0 {
            if let (Status::Complete, Some(setup)) = (status, &run.setup) {
                let (dt, s) = (1.0 / setup.output_rate_hz, &self.contact_state_samples);
                if s.last_t < setup.duration_s - dt * (1.0 + 1e-6) {
                    return Err(Error::ShortRun { file: file(), topic: topics::CONTACTS.into(), samples: s.count, t_end_s: s.last_t, duration_s: setup.duration_s });
                }
            }
        }
        let contact_states = match self.contact_state_samples.count {
            0 => Vec::new(),
            _ => self.contact_states.finish(&rec.source, &run.contacts, rec.record_opt::<schemas::ContactsRecord>()?.as_ref())?,
        };
        let recorded_breaches = rec.result()?.and_then(|r| r.contact_law_breaches);
        let contact_audit = match (self.audit, self.contact_state_samples.count) {
            (Some(audit), n) if n > 0 => Some(super::ContactAuditMetrics { audit: audit.finish(), recorded_breaches }),
            _ => None,
        };
        let joint_names = run.joint_names;
        let contacts = run.contacts;
        let n = self.hand_samples.count;
        let hand_error = HandError { x: self.hand[0].of(n), y: self.hand[1].of(n), z: self.hand[2].of(n), norm: self.hand[3].of(n) };
        let peak_current = (0..self.motor_peaks.len())
            .fold(None::<usize>, |best, j| match best {
                Some(b) if self.motor_peaks[b].abs >= self.motor_peaks[j].abs => Some(b),
                _ => Some(j),
            })
            .map(|j| PeakCurrent { joint: joint_names[j].clone(), current_a: self.motor_peaks[j].abs, t_s: self.motor_peaks[j].t });
        let (Some(first), Some(last)) = (self.energy_first, self.energy_last) else {
            return Err(Error::NoSamples { file: file(), topic: topics::ENERGY.into() });
        };
        let links = (0..joint_names.len())
            .map(|j| LinkMetrics {
                joint: joint_names[j].clone(),
                work_j: last.link_work[j],
                electric_energy_j: last.electric_energy[j],
                peak_current_a: self.motor_peaks[j].abs,
                t_peak_current_s: self.motor_peaks[j].t,
            })
            .collect();
        let contact_forces = self
            .contacts
            .iter()
            .zip(&contacts)
            .map(|(c, name)| ContactMetrics {
                contact: name.clone(),
                min_normal_force_n: c.min_force.v,
                t_min_normal_force_s: c.min_force.t,
                pull_time_s: c.pull_time,
                first_pull_s: c.first_pull,
                max_abs_position_m: c.position.abs,
                max_abs_velocity_m_s: c.velocity.abs,
            })
            .collect();
        let electric_j = last.electric_energy_total;
        let energy_audit = EnergyAudit {
            electric_j,
            kinetic_change_j: last.kinetic - first.kinetic,
            potential_change_j: last.potential - first.potential,
            magnetic_change_j: last.magnetic - first.magnetic,
            resistive_loss_j: last.resistive_loss,
            friction_loss_j: last.friction_loss,
            gear_friction_loss_j: rec.has_gear_friction_loss().then_some(last.gear_friction_loss),
            residual_j: last.balance_residual,
            max_abs_residual_j: self.residual.abs,
            t_max_abs_residual_s: self.residual.t,
            max_abs_residual_rel: Some(self.residual.abs / electric_j.abs()).filter(|x| electric_j != 0.0 && x.is_finite()),
        };
        Ok(RunMetrics {
            file: file(),
            scene: run.scene,
            run: run.run,
            contacts,
            joint_names,
            samples: n,
            t_end_s: Some(self.hand_samples.last_t),
            status,
            error,
            error_time_s,
            hand_error: Some(hand_error),
            links,
            link_work_total_j: Some(last.link_work_total),
            electric_energy_total_j: Some(electric_j),
            peak_current,
            contact_forces,
            energy: Some(energy_audit),
            limits: match rec.record_opt::<schemas::LimitsRecord>()? {
                Some(l) => Some(super::LimitsMetrics { exceeded: l.exceeded, saturations: l.saturations, resolution_s: l.resolution, events: l.events }),
                None => None,
            },
            energy_terms: rec.record_opt::<schemas::EnergyTermsRecord>()?,
            contact_states,
            contact_audit,
        })
    }
}

/// An error of [`Reductions::add`] stops the reader ([`schemas::Error::Stopped`]) and is kept
/// in [`Reductions::error`], to be returned as it is.
impl schemas::Visitor for Reductions {
    /// The metric messages typed when their schema is `schemas`' own (the same numbers, no
    /// generic tree).
    fn typed(&self) -> bool {
        true
    }

    /// The `contacts` record starts the contact audit (a record that does not parse is left
    /// to the typed reading at the end, which names it).
    fn metadata(&mut self, name: &str, entries: &std::collections::BTreeMap<String, String>) {
        use schemas::MetadataRecord;
        if name == schemas::ContactsRecord::NAME {
            self.audit = schemas::ContactsRecord::from_metadata(entries).ok().map(|r| schemas::ContactAuditor::new(&r));
        }
    }

    /// Nothing of a message is kept past [`Reductions::add`] (the energies are copied).
    fn by_ref(&self) -> bool {
        true
    }

    fn message(&mut self, m: DecodedMessage<'_>) -> Result<(), schemas::Error> {
        self.message_ref(&m)
    }

    fn message_ref(&mut self, m: &DecodedMessage<'_>) -> Result<(), schemas::Error> {
        match self.add(m) {
            Ok(()) => Ok(()),
            Err(Error::Read(e)) => Err(*e),
            Err(e) => {
                self.error = Some(e);
                Err(schemas::Error::Stopped { file: m.file.to_string() })
            }
        }
    }
}

impl Reductions {
    /// One message. When the `run` record came first (`sim` writes it first), its arrays are
    /// checked against the run's joints and contacts as they come; otherwise (another producer,
    /// or a record written late) every message must have the arrays of the first, and
    /// [`Reductions::finish`] checks them against the run.
    fn add(&mut self, m: &DecodedMessage<'_>) -> Result<(), Error> {
        let sizes = m.sizes();
        check(m, &mut self.joints, &mut self.n_contacts)?;
        match m.topic {
            topics::HAND => {
                let h = m.decode_ref::<HandState>(sizes)?;
                let e = [h.error.x, h.error.y, h.error.z, h.error_norm];
                let t = Self::sample(&mut self.hand_samples, m)?;
                for (axis, e) in self.hand.iter_mut().zip(e) {
                    axis.add(t, e);
                }
            }
            topics::MOTORS => {
                let motor = m.decode_ref::<MotorState>(sizes)?;
                let t = Self::sample(&mut self.motor_samples, m)?;
                self.motor_peaks.resize(motor.current.len(), Peak::default());
                for (p, &i) in self.motor_peaks.iter_mut().zip(&motor.current) {
                    p.add(t, i);
                }
            }
            topics::CONSTRAINTS => {
                let c = m.decode_ref::<ConstraintState>(sizes)?;
                let t = Self::sample(&mut self.contact_samples, m)?;
                self.contacts.resize(c.normal_force.len(), Contact::default());
                for (k, acc) in self.contacts.iter_mut().enumerate() {
                    let f = c.normal_force[k];
                    acc.min_force.add(t, f);
                    if let Some((t0, f0)) = acc.previous {
                        acc.pull_time += negative_time(&[t0, t], &[f0, f]);
                    }
                    acc.previous = Some((t, f));
                    if f < 0.0 && acc.first_pull.is_none() {
                        acc.first_pull = Some(t);
                    }
                    acc.position.add(t, c.position[k]);
                    acc.velocity.add(t, c.velocity[k]);
                }
            }
            topics::ENERGY => {
                let e = m.decode_ref::<EnergyState>(sizes)?;
                let t = Self::sample(&mut self.energy_samples, m)?;
                self.residual.add(t, e.balance_residual);
                if self.energy_first.is_none() {
                    self.energy_first = Some(e.clone().into_owned());
                }
                match self.energy_last.as_mut() {
                    Some(last) => copy_energy(last, &e),
                    None => self.energy_last = Some(e.into_owned()),
                }
            }
            topics::CONTACTS => {
                let c = m.decode_ref::<ContactState>(sizes)?;
                let t = Self::sample(&mut self.contact_state_samples, m)?;
                self.contact_states.state(t, &c);
                if let Some(audit) = self.audit.as_mut() {
                    audit.sample(t, &c);
                }
            }
            topics::CONTACT_EVENTS => {
                let e = m.decode::<ContactEventMsg>(sizes)?;
                self.contact_states.event(m, e)?;
            }
            _ => {}
        }
        Ok(())
    }
}

/// `*to = from.clone()`, reusing `to`'s arrays and names (no allocation per `/energy` message).
fn copy_energy(to: &mut EnergyState, from: &EnergyState) {
    let EnergyState {
        time,
        link_work,
        electric_energy,
        link_work_total,
        electric_energy_total,
        kinetic,
        potential,
        magnetic,
        resistive_loss,
        friction_loss,
        balance_residual,
        gear_friction_loss,
        name,
    } = from;
    to.time = *time;
    to.link_work.clone_from(link_work);
    to.electric_energy.clone_from(electric_energy);
    to.link_work_total = *link_work_total;
    to.electric_energy_total = *electric_energy_total;
    to.kinetic = *kinetic;
    to.potential = *potential;
    to.magnetic = *magnetic;
    to.resistive_loss = *resistive_loss;
    to.friction_loss = *friction_loss;
    to.balance_residual = *balance_residual;
    to.gear_friction_loss = *gear_friction_loss;
    to.name.clone_from(name);
}
