//! The contact audit: the laws of each contact model checked at every sample of `/contacts`,
//! the way the energy audit checks the balance. `sim` computes it as it records and writes the
//! record `contact_audit`; `analyze` computes it again from the samples (so a recording whose
//! samples break a law is caught even if its record says otherwise) and checks it
//! (`analyze metrics --check`). One definition, here, for both.
//!
//! The laws (Pfeiffer & Glocker, *Multibody Dynamics with Unilateral Contacts*, 1996, §§ 4–5:
//! Signorini's condition and Coulomb's law as complementarity conditions; Brogliato,
//! *Nonsmooth Mechanics*, 3rd ed., 2016, § 5.2), for a contact with gap g, gap rate ġ, normal
//! force f_n, friction force f_t and slip velocity v_t, sample by sample:
//!
//! | law | measured | unilateral (rigid) | compliant |
//! |---|---|---|---|
//! | a closed contact sits on its plane | `max |g|` while closed | ≤ [`AuditBounds::gap_m`] | — (it penetrates by design) |
//! | … and moves along it | `max |ġ|` while closed | ≤ [`AuditBounds::gap_rate_m_s`] | — |
//! | a separated contact is not inside the table | `max (−g)` while separated | ≤ [`AuditBounds::penetration_m`] | — (it is in touch when g < 0) |
//! | the table only pushes | `max (−f_n)` | ≤ [`AuditBounds::force_n`] | ≤ [`AuditBounds::force_n`] |
//! | a separated contact carries no force | `max |f|` while separated | ≤ [`AuditBounds::force_n`] | ≤ [`AuditBounds::force_n`] |
//! | friction stays in its cone | `max (|f_t| − μ max(f_n, 0))` | ≤ [`AuditBounds::force_n`] + [`AuditBounds::cone_rel`] μ f_n | same |
//! | sliding friction opposes the slip | `max ∠(−f_t, v_t)` while sliding with `|v_t| > slip_m_s`, `|f_t| > force_n` | ≤ [`AuditBounds::angle_rad`] | same (in touch) |
//!
//! `slip_m_s` is the larger of the gap-rate bound and the speed the run declares its friction
//! direction regularised below (`ContactsRecord::onset_slip_speed`, absent: `v_s` = 1e-6 m/s,
//! which the gap-rate bound's floor covers): below it Coulomb's direction `−v_t/|v_t|` is not
//! the model's. At tight tolerances (the integrator's resolution of a slip below `v_s`, as at
//! the paper's rtol 1e-8) nothing changes; at loose ones a stick → slip onset's friction
//! direction is resolved only to the integrator's slip resolution (`sim`'s
//! `ode/hybrid.rs::onset_speed`, K = 30 times it: 2.9e-3 m/s at rtol 1e-4 on the paper's
//! unilateral scene), so slips slower than that are not judged there.
//! | complementarity | `max |f_n g|` | reported (≤ `max |f_n|` · `gap_m` when the rows above hold) | — |
//!
//! Bilateral contacts (the paper's) have no law to break here: the table may pull, and their
//! drift is the constraint stabilisation's (`/constraints`); they are listed with no checks.
//!
//! **The bounds** come from the run's event settings (record `contacts`) and are stated in the
//! record: a contact closes when `|g| ≤ gap_tolerance` and `|ġ| ≤ velocity_tolerance`, and the
//! closed phase holds `g = 0` at the acceleration level with the integrator's error on top; an
//! event is located to `time_tolerance`, so a sample just past a touch-down may be inside by
//! `|ġ| · time_tolerance`. The bounds are those tolerances times [`SLACK`] (the integrator's
//! drift over a closed phase: measured on every built-in contact run at ≤ 1e-2 of the bound,
//! see `TESTING.md`), and absolute floors of a nanometre, a micrometre per second, a micronewton
//! and a thousandth of a radian, far below any physical effect and far above rounding: a wrong
//! model (a contact held open above the table, friction outside its cone) breaks them by
//! orders of magnitude. Each law's worst value and its first breach are kept per contact.
//!
//! Memory: a fixed number of values per contact; no allocation per sample.

use serde::{Deserialize, Serialize};

use super::{ContactInfo, ContactsRecord, MetadataRecord};
use crate::messages::{contact_mode, ContactState};

/// The factor between the event settings and the bounds (see the module docs).
pub const SLACK: f64 = 1e3;

/// What each law is held to (see the module docs), SI units.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AuditBounds {
    /// `|g|` of a closed rigid contact, m.
    pub gap_m: f64,
    /// `|ġ|` of a closed rigid contact, m/s.
    pub gap_rate_m_s: f64,
    /// `−g` of a separated rigid contact, m.
    pub penetration_m: f64,
    /// A force that should be zero or non-negative, N (absolute).
    pub force_n: f64,
    /// The cone's relative slack (of μ f_n).
    pub cone_rel: f64,
    /// Slip speeds at or below this have no direction to oppose, m/s: the gap-rate bound, or
    /// the run's declared regularisation speed (`ContactsRecord::onset_slip_speed`) if larger.
    pub slip_m_s: f64,
    /// The angle between −f_t and v_t while sliding, rad.
    pub angle_rad: f64,
}

impl AuditBounds {
    /// The bounds of a run with these event settings (see the module docs).
    pub fn of(record: &ContactsRecord) -> Self {
        let gap_m = (SLACK * record.gap_tolerance).max(1e-9);
        let gap_rate_m_s = (SLACK * record.velocity_tolerance).max(1e-6);
        AuditBounds {
            gap_m,
            gap_rate_m_s,
            penetration_m: gap_m,
            force_n: 1e-6,
            cone_rel: 1e-9,
            slip_m_s: gap_rate_m_s.max(record.onset_slip_speed.unwrap_or(0.0)),
            angle_rad: 1e-3,
        }
    }
}

/// One law's worst value over the run and the first sample that broke its bound.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Worst {
    /// The worst value (0 when the law never applied).
    pub value: f64,
    /// The time of the worst value, s.
    pub t: f64,
    /// Samples beyond the bound.
    pub breaches: u64,
    /// The first of them, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub first_breach_t: Option<f64>,
}

impl Worst {
    fn add(&mut self, t: f64, value: f64, bound: f64) {
        if value > self.value {
            self.value = value;
            self.t = t;
        }
        // a value that is not a number breaks the law (and is not kept: JSON has no NaN)
        if value > bound || value.is_nan() {
            self.breaches += 1;
            self.first_breach_t.get_or_insert(t);
        }
    }
}

/// The laws of one contact over a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactLaws {
    pub contact: String,
    /// `unilateral`, `compliant` or `bilateral` (no checks).
    pub model: String,
    /// `max |g|` while closed, m.
    pub closed_gap_m: Worst,
    /// `max |ġ|` while closed, m/s.
    pub closed_gap_rate_m_s: Worst,
    /// `max (−g)` while separated, m.
    pub penetration_m: Worst,
    /// `max (−f_n)`, N.
    pub pull_n: Worst,
    /// `max |f|` while separated, N.
    pub separated_force_n: Worst,
    /// `max (|f_t| − (1 + cone_rel) μ max(f_n, 0))`, N.
    pub cone_excess_n: Worst,
    /// `max ∠(−f_t, v_t)` while sliding, rad.
    pub slip_angle_rad: Worst,
    /// `max |f_n g|`, N m (reported, not bounded).
    pub complementarity_n_m: f64,
    /// Samples in a mode this model does not have (bilateral or an unknown code on a
    /// unilateral or compliant contact): each breaks the law of its model.
    pub foreign_mode: u64,
}

impl ContactLaws {
    fn new(info: &ContactInfo) -> Self {
        ContactLaws {
            contact: info.name.clone(),
            model: info.model.clone(),
            closed_gap_m: Worst::default(),
            closed_gap_rate_m_s: Worst::default(),
            penetration_m: Worst::default(),
            pull_n: Worst::default(),
            separated_force_n: Worst::default(),
            cone_excess_n: Worst::default(),
            slip_angle_rad: Worst::default(),
            complementarity_n_m: 0.0,
            foreign_mode: 0,
        }
    }

    /// Every law: `(name, unit, worst, its bound in `b`)`.
    pub fn laws(&self, b: &AuditBounds) -> [(&'static str, &'static str, &Worst, f64); 7] {
        [
            ("closed gap", "m", &self.closed_gap_m, b.gap_m),
            ("closed gap rate", "m/s", &self.closed_gap_rate_m_s, b.gap_rate_m_s),
            ("penetration while separated", "m", &self.penetration_m, b.penetration_m),
            ("pull", "N", &self.pull_n, b.force_n),
            ("force while separated", "N", &self.separated_force_n, b.force_n),
            ("friction outside its cone", "N", &self.cone_excess_n, b.force_n),
            ("friction not opposing the slip", "rad", &self.slip_angle_rad, b.angle_rad),
        ]
    }

    /// Samples that broke a law, over the laws.
    pub fn breaches(&self) -> u64 {
        let w = [&self.closed_gap_m, &self.closed_gap_rate_m_s, &self.penetration_m, &self.pull_n, &self.separated_force_n, &self.cone_excess_n, &self.slip_angle_rad];
        w.iter().map(|w| w.breaches).sum::<u64>() + self.foreign_mode
    }
}

/// The contact audit of a run: the bounds and each contact's laws.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactAudit {
    pub bounds: AuditBounds,
    /// In `run.contacts` order.
    pub contacts: Vec<ContactLaws>,
    /// Samples audited.
    pub samples: u64,
    /// Samples × laws broken, over the contacts (0: every law held at every sample).
    pub breaches: u64,
}

/// Record `contact_audit` (runs with a non-bilateral contact): [`ContactAudit`] as metadata
/// text.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactAuditRecord {
    /// The bounds, a JSON object of [`AuditBounds`].
    #[serde(with = "json_value")]
    pub bounds: AuditBounds,
    /// A JSON array of [`ContactLaws`], in `run.contacts` order.
    #[serde(with = "json_value")]
    pub contacts: Vec<ContactLaws>,
    /// Samples audited.
    #[serde(with = "super::text")]
    pub samples: u64,
    /// Samples × laws broken, over the contacts (0: every law held at every sample).
    #[serde(with = "super::text")]
    pub breaches: u64,
}

impl MetadataRecord for ContactAuditRecord {
    const NAME: &'static str = "contact_audit";
}

impl From<ContactAudit> for ContactAuditRecord {
    fn from(a: ContactAudit) -> Self {
        ContactAuditRecord { bounds: a.bounds, contacts: a.contacts, samples: a.samples, breaches: a.breaches }
    }
}

impl From<ContactAuditRecord> for ContactAudit {
    fn from(r: ContactAuditRecord) -> Self {
        ContactAudit { bounds: r.bounds, contacts: r.contacts, samples: r.samples, breaches: r.breaches }
    }
}

impl ContactAudit {
    /// "elbow7: closed gap 1.5e-2 m (bound 1e-6) first at t = 0.0739 s; …" for each broken
    /// law, or `None` when every law held.
    pub fn verdict(&self) -> Option<String> {
        let b = &self.bounds;
        let mut parts = Vec::new();
        for c in &self.contacts {
            for (name, unit, w, bound) in c.laws(b) {
                if w.breaches > 0 {
                    let first = w.first_breach_t.map_or(String::new(), |t| format!(" first at t = {t} s,"));
                    let n = w.breaches;
                    parts.push(format!(
                        "{}: {name} {:.3e} {unit} (bound {bound:.1e}),{first} worst at t = {} s, {n} sample{}",
                        c.contact,
                        w.value,
                        w.t,
                        if n == 1 { "" } else { "s" }
                    ));
                }
            }
            if c.foreign_mode > 0 {
                parts.push(format!("{}: {} samples in a mode a {} contact does not have", c.contact, c.foreign_mode, c.model));
            }
        }
        (!parts.is_empty()).then(|| parts.join("; "))
    }
}

/// The running audit of one run's `/contacts` samples.
#[derive(Debug, Clone)]
pub struct ContactAuditor {
    bounds: AuditBounds,
    /// μ per contact (0 without friction).
    mu: Vec<f64>,
    laws: Vec<ContactLaws>,
    samples: u64,
}

impl ContactAuditor {
    /// For the contacts of `record`, in its order (the order of `/contacts`' arrays).
    pub fn new(record: &ContactsRecord) -> Self {
        ContactAuditor {
            bounds: AuditBounds::of(record),
            mu: record.contacts.iter().map(|c| c.friction.unwrap_or(0.0)).collect(),
            laws: record.contacts.iter().map(ContactLaws::new).collect(),
            samples: 0,
        }
    }

    /// One `/contacts` sample at `t` (arrays shorter than the contacts count as absent).
    pub fn sample(&mut self, t: f64, s: &ContactState) {
        self.samples += 1;
        let b = self.bounds;
        let at = |v: &[f64], k: usize| v.get(k).copied().unwrap_or(0.0);
        for (k, (law, &mu)) in self.laws.iter_mut().zip(&self.mu).enumerate() {
            let rigid = match law.model.as_str() {
                "unilateral" => true,
                "compliant" => false,
                _ => continue,
            };
            let Some(&mode) = s.mode.get(k) else { continue };
            let (g, gd, f_n) = (at(&s.gap, k), at(&s.gap_rate, k), at(&s.normal_force, k));
            let f_t = [at(&s.friction_force_t1, k), at(&s.friction_force_t2, k)];
            let v_t = [at(&s.slip_velocity_t1, k), at(&s.slip_velocity_t2, k)];
            let ft = f_t[0].hypot(f_t[1]);
            let closed = mode == contact_mode::STICKING || mode == contact_mode::SLIDING;
            if mode == contact_mode::SEPARATED {
                law.separated_force_n.add(t, f_n.hypot(ft), b.force_n);
                if rigid {
                    law.penetration_m.add(t, -g, b.penetration_m);
                }
            } else if rigid && closed {
                law.closed_gap_m.add(t, g.abs(), b.gap_m);
                law.closed_gap_rate_m_s.add(t, gd.abs(), b.gap_rate_m_s);
            } else if !closed {
                // a mode this model does not have (bilateral code on a unilateral contact, or
                // an unknown code)
                law.foreign_mode += 1;
                continue;
            }
            law.pull_n.add(t, -f_n, b.force_n);
            // (a pull is its own law: the cone of a pulling contact is the point f_t = 0)
            law.cone_excess_n.add(t, ft - mu * f_n.max(0.0) * (1.0 + b.cone_rel), b.force_n);
            let v = v_t[0].hypot(v_t[1]);
            if mode == contact_mode::SLIDING && v > b.slip_m_s && ft > b.force_n {
                // the angle between −f_t and v_t, from atan2 (accurate at small angles)
                let cross = -(f_t[0] * v_t[1] - f_t[1] * v_t[0]);
                let dot = -(f_t[0] * v_t[0] + f_t[1] * v_t[1]);
                law.slip_angle_rad.add(t, cross.abs().atan2(dot), b.angle_rad);
            }
            law.complementarity_n_m = law.complementarity_n_m.max((f_n * g).abs());
        }
    }

    /// The audit.
    pub fn finish(self) -> ContactAudit {
        let breaches = self.laws.iter().map(ContactLaws::breaches).sum();
        ContactAudit { bounds: self.bounds, contacts: self.laws, samples: self.samples, breaches }
    }
}

/// A value as JSON text (a metadata value is text).
mod json_value {
    use serde::de::DeserializeOwned;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<T: Serialize, S: Serializer>(v: &T, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&serde_json::to_string(v).map_err(serde::ser::Error::custom)?)
    }

    pub fn deserialize<'de, T: DeserializeOwned, D: Deserializer<'de>>(d: D) -> Result<T, D::Error> {
        let s = String::deserialize(d)?;
        serde_json::from_str(&s).map_err(|e| serde::de::Error::custom(format!("{s:?} is not the JSON the contact audit writes: {e}")))
    }
}

#[cfg(test)]
mod tests {
    use super::super::{from_entries, to_entries};
    use super::*;

    fn info(name: &str, model: &str, mu: f64) -> ContactInfo {
        ContactInfo { friction: Some(mu), ..ContactInfo::on_floor(name, model) }
    }

    /// Contacts `rigid` (unilateral, μ = 0.5), `soft` (compliant, μ = 0.5) and `paper`
    /// (bilateral); tolerances 1e-9 m and 1e-9 m/s, so the bounds are 1e-6 m and 1e-6 m/s.
    fn record() -> ContactsRecord {
        ContactsRecord {
            contacts: vec![info("rigid", "unilateral", 0.5), info("soft", "compliant", 0.5), info("paper", "bilateral", 0.0)],
            time_tolerance: 1e-12,
            gap_tolerance: 1e-9,
            velocity_tolerance: 1e-9,
            rest_velocity: 1e-4,
            max_events: 1000,
            onset_slip_speed: None,
        }
    }

    /// One contact in one sample: `(mode, g, ġ, f_n, f_t, v_t)`.
    type Row = (u32, f64, f64, f64, [f64; 2], [f64; 2]);

    /// One sample of the three contacts.
    fn state(c: [Row; 3]) -> ContactState {
        ContactState {
            time: 0.0,
            name: vec!["rigid".into(), "soft".into(), "paper".into()],
            mode: c.iter().map(|c| c.0).collect(),
            gap: c.iter().map(|c| c.1).collect(),
            gap_rate: c.iter().map(|c| c.2).collect(),
            normal_force: c.iter().map(|c| c.3).collect(),
            friction_force_t1: c.iter().map(|c| c.4[0]).collect(),
            friction_force_t2: c.iter().map(|c| c.4[1]).collect(),
            slip_velocity_t1: c.iter().map(|c| c.5[0]).collect(),
            slip_velocity_t2: c.iter().map(|c| c.5[1]).collect(),
            impact_loss: vec![0.0; 3],
            friction_work: vec![0.0; 3],
            damping_loss: vec![0.0; 3],
        }
    }

    const SEP: u32 = contact_mode::SEPARATED;
    const STICK: u32 = contact_mode::STICKING;
    const SLIDE: u32 = contact_mode::SLIDING;
    const BIL: u32 = contact_mode::BILATERAL;

    /// A lawful history: the rigid contact sticks inside its cone, slides with friction on its
    /// cone's edge against the slip, lifts off; the compliant one is pressed in by 1 mm (its
    /// model) and slides; the bilateral one pulls (allowed).
    fn lawful() -> Vec<ContactState> {
        let paper = (BIL, 0.0, 0.0, -5.0, [0.0, 0.0], [0.0, 0.0]);
        vec![
            state([(STICK, 1e-12, -1e-11, 10.0, [3.0, 4.0], [0.0, 0.0]), (STICK, -1e-3, 0.0, 100.0, [1.0, 0.0], [1e-4, 0.0]), paper]),
            // |f_t| = μ f_n exactly, along −v_t
            state([(SLIDE, 0.0, 0.0, 10.0, [-3.0, -4.0], [0.3, 0.4]), (SLIDE, -1e-3, 0.0, 100.0, [0.0, -50.0], [0.0, 0.2]), paper]),
            state([(SEP, 0.02, 0.1, 0.0, [0.0, 0.0], [0.0, 0.0]), (SEP, 0.01, 0.1, 0.0, [0.0, 0.0], [0.0, 0.0]), paper]),
        ]
    }

    fn audit(samples: &[ContactState]) -> ContactAudit {
        let mut a = ContactAuditor::new(&record());
        for (k, s) in samples.iter().enumerate() {
            a.sample(k as f64 * 0.01, s);
        }
        a.finish()
    }

    #[test]
    fn a_lawful_history_breaks_nothing_and_the_worst_values_are_exact() {
        let a = audit(&lawful());
        assert_eq!((a.samples, a.breaches), (3, 0), "{:?}", a.verdict());
        assert_eq!(a.verdict(), None);
        let rigid = &a.contacts[0];
        assert_eq!((rigid.closed_gap_m.value, rigid.closed_gap_m.t), (1e-12, 0.0));
        assert_eq!(rigid.closed_gap_rate_m_s.value, 1e-11);
        assert_eq!(rigid.cone_excess_n.value, 0.0, "on the cone's edge is inside it");
        assert!(rigid.slip_angle_rad.value < 1e-15, "{}", rigid.slip_angle_rad.value);
        assert_eq!(rigid.complementarity_n_m, 1e-11);
        // the compliant contact's penetration is its model, not a breach; the bilateral
        // contact's pull is the paper's table
        assert_eq!(a.contacts[1].closed_gap_m.value, 0.0);
        assert_eq!(a.contacts[2].pull_n.value, 0.0);
    }

    /// Each law broken at one sample (the second) is counted once, with its time and value,
    /// and named by the verdict; nothing else is.
    #[test]
    fn each_broken_law_is_found_at_its_sample_and_named() {
        let base = lawful();
        type Doctor = Box<dyn Fn(&mut ContactState)>;
        let cases: Vec<(&str, Doctor, f64)> = vec![
            ("closed gap", Box::new(|s| s.gap[0] = 2e-6), 2e-6),
            ("closed gap rate", Box::new(|s| s.gap_rate[0] = -3e-6), 3e-6),
            // (without friction: with a pull no friction force is inside the cone)
            ("pull", Box::new(|s| {
                s.normal_force[0] = -1e-3;
                s.friction_force_t1[0] = 0.0;
                s.friction_force_t2[0] = 0.0;
            }), 1e-3),
            ("friction outside its cone", Box::new(|s| s.friction_force_t1[0] = -3.001), 0.0),
            ("friction not opposing the slip", Box::new(|s| s.friction_force_t1[0] = 3.0), 0.0),
            ("force while separated", Box::new(|s| {
                s.mode[0] = SEP;
                s.gap[0] = 0.01;
                s.friction_force_t1[0] = 0.0;
                s.friction_force_t2[0] = 0.0;
            }), 10.0),
            ("penetration while separated", Box::new(|s| {
                s.mode[0] = SEP;
                s.gap[0] = -2e-6;
                s.normal_force[0] = 0.0;
                s.friction_force_t1[0] = 0.0;
                s.friction_force_t2[0] = 0.0;
            }), 2e-6),
        ];
        for (law, doctor, value) in cases {
            let mut samples = base.clone();
            doctor(&mut samples[1]);
            let a = audit(&samples);
            let rigid = &a.contacts[0];
            let broken: Vec<&str> = rigid.laws(&a.bounds).iter().filter(|l| l.2.breaches > 0).map(|l| l.0).collect();
            assert_eq!(broken, [law], "{law}");
            let w = rigid.laws(&a.bounds).into_iter().find(|l| l.0 == law).unwrap().2;
            assert_eq!((w.breaches, w.first_breach_t, w.t), (1, Some(0.01), 0.01), "{law}");
            if value > 0.0 {
                assert!((w.value - value).abs() <= 1e-12 * value, "{law}: {} vs {value}", w.value);
            }
            assert_eq!(a.breaches, 1, "{law}");
            let v = a.verdict().expect("named");
            assert!(v.starts_with(&format!("rigid: {law} ")) && v.contains("first at t = 0.01 s"), "{v}");
        }
    }

    /// Friction along the slip is π from where it should be; at 1e-3 rad (the bound) it is not
    /// a breach, at 2e-3 it is.
    #[test]
    fn the_slip_angle_is_the_angle_between_the_friction_and_minus_the_slip() {
        let mut s = lawful();
        s[1].friction_force_t1[0] = 3.0;
        s[1].friction_force_t2[0] = 4.0;
        let a = audit(&s);
        assert!((a.contacts[0].slip_angle_rad.value - std::f64::consts::PI).abs() < 1e-15);
        for (angle, breaches) in [(0.999e-3, 0), (2e-3, 1)] {
            let mut s = lawful();
            // −f_t rotated by `angle` from v_t = (0.3, 0.4)
            let (c, sn) = (f64::cos(angle), f64::sin(angle));
            let (vx, vy) = (0.6, 0.8);
            s[1].friction_force_t1[0] = -5.0 * (c * vx - sn * vy);
            s[1].friction_force_t2[0] = -5.0 * (sn * vx + c * vy);
            let a = audit(&s);
            assert!((a.contacts[0].slip_angle_rad.value - angle).abs() < 1e-12, "{angle}");
            assert_eq!(a.contacts[0].slip_angle_rad.breaches, breaches, "{angle}");
        }
    }

    /// A mode the model does not have and a value that is not a number are breaches; the
    /// compliant contact is held to the force laws (it may not pull).
    #[test]
    fn foreign_modes_nan_and_a_pulling_compliant_contact_are_breaches() {
        let mut s = lawful();
        s[0].mode[0] = BIL;
        s[1].gap[0] = f64::NAN;
        s[2].mode[1] = STICK;
        s[2].gap[1] = -1e-3;
        s[2].normal_force[1] = -2.0;
        let a = audit(&s);
        assert_eq!(a.contacts[0].foreign_mode, 1);
        assert_eq!(a.contacts[0].closed_gap_m.breaches, 1, "NaN breaks the law");
        assert_eq!(a.contacts[1].pull_n.breaches, 1);
        assert_eq!(a.contacts[1].pull_n.value, 2.0);
        // a pulling contact's cone is the point f_t = 0: without friction it is not outside
        assert_eq!(a.contacts[1].cone_excess_n.breaches, 0);
        assert_eq!(a.breaches, 3);
        let v = a.verdict().unwrap();
        assert!(v.contains("rigid: 1 samples in a mode a unilateral contact does not have") && v.contains("soft: pull 2.000e0 N"), "{v}");
        // JSON has no NaN: the record still round-trips
        let r = ContactAuditRecord::from(a.clone());
        let back: ContactAuditRecord = from_entries(&to_entries(&r).unwrap()).unwrap();
        assert_eq!(ContactAudit::from(back), a);
    }

    /// The bounds follow the event settings, with their floors.
    #[test]
    fn the_bounds_are_the_event_tolerances_times_the_slack() {
        let b = AuditBounds::of(&record());
        assert_eq!((b.gap_m, b.gap_rate_m_s, b.penetration_m), (SLACK * 1e-9, SLACK * 1e-9, SLACK * 1e-9));
        let tight = ContactsRecord { gap_tolerance: 1e-15, velocity_tolerance: 1e-15, ..record() };
        let b = AuditBounds::of(&tight);
        assert_eq!((b.gap_m, b.gap_rate_m_s), (1e-9, 1e-6));
    }

    /// A run that declares its friction direction regularised below 3e-3 m/s
    /// (`onset_slip_speed`): a slip of 2e-3 m/s with the friction at 0.5 rad off is not
    /// judged, one of 4e-3 m/s is; the bound is the declared speed. A record without the field
    /// (every recording before it) audits as before: both slips judged, `slip_m_s` the
    /// gap-rate bound.
    #[test]
    fn a_declared_regularisation_speed_is_not_judged_below_and_judged_above() {
        let off = |speed: f64| {
            let mut s = lawful();
            // v_t along (0.6, 0.8) at `speed`, −f_t rotated from it by 0.5 rad, |f_t| = μ f_n
            let (c, sn) = (f64::cos(0.5), f64::sin(0.5));
            s[1].slip_velocity_t1[0] = 0.6 * speed;
            s[1].slip_velocity_t2[0] = 0.8 * speed;
            s[1].friction_force_t1[0] = -5.0 * (c * 0.6 - sn * 0.8);
            s[1].friction_force_t2[0] = -5.0 * (sn * 0.6 + c * 0.8);
            s
        };
        let run = |record: &ContactsRecord, samples: &[ContactState]| {
            let mut a = ContactAuditor::new(record);
            for (k, s) in samples.iter().enumerate() {
                a.sample(k as f64 * 0.01, s);
            }
            a.finish()
        };
        let declared = ContactsRecord { onset_slip_speed: Some(3e-3), ..record() };
        assert_eq!(AuditBounds::of(&declared).slip_m_s, 3e-3);
        let below = run(&declared, &off(2e-3));
        assert_eq!((below.breaches, below.contacts[0].slip_angle_rad.value), (0, 0.0), "{:?}", below.verdict());
        let above = run(&declared, &off(4e-3));
        let w = above.contacts[0].slip_angle_rad;
        assert_eq!((above.breaches, w.breaches, w.first_breach_t), (1, 1, Some(0.01)));
        assert!((w.value - 0.5).abs() < 1e-12, "{}", w.value);
        // the old record: the bounds of before (slip_m_s = the gap-rate bound, SLACK × 1e-9
        // m/s), the slip below the declared speed judged
        let b = AuditBounds::of(&record());
        assert_eq!(b, AuditBounds { slip_m_s: b.gap_rate_m_s, ..AuditBounds::of(&declared) });
        assert_eq!(b.slip_m_s, SLACK * 1e-9);
        let old = run(&record(), &off(2e-3));
        assert_eq!((old.breaches, old.contacts[0].slip_angle_rad.breaches), (1, 1));
        // a declared speed below the gap-rate bound changes nothing
        assert_eq!(AuditBounds::of(&ContactsRecord { onset_slip_speed: Some(1e-7), ..record() }), AuditBounds::of(&record()));
    }
}
