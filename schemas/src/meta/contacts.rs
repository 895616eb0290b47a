//! Record `contacts` (format 2+, see the parent module; only runs with a non-bilateral contact): each contact's model
//! and parameters, its plane and tangent basis, and the event settings of the run. The models
//! are those of issue 11 (Pfeiffer & Glocker 1996 for the rigid unilateral contact with Newton
//! restitution and Coulomb friction; a spring-damper for the compliant one).

use serde::{Deserialize, Serialize};

use super::MetadataRecord;

/// One contact of the run, as it ran.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactInfo {
    /// The contact's name (as in `run.contacts`).
    pub name: String,
    /// `bilateral`, `unilateral` or `compliant`.
    pub model: String,
    /// Newton's coefficient of restitution e ∈ [0, 1] (unilateral).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub restitution: Option<f64>,
    /// Coulomb friction coefficient μ ≥ 0 (unilateral, compliant).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<f64>,
    /// Normal stiffness k, N/m (compliant).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness: Option<f64>,
    /// Normal damping c, N·s/m (compliant).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping: Option<f64>,
    /// Regularisation speed v_s of the friction law, m/s (compliant).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slip_velocity: Option<f64>,
    /// The plane's unit normal n, world frame.
    pub normal: [f64; 3],
    /// The plane's offset d (the plane is n · x = d), m.
    pub offset: f64,
    /// The tangent basis of `/contacts`' `*_t1`, `*_t2` fields, world frame.
    pub t1: [f64; 3],
    pub t2: [f64; 3],
    /// Where the contact is on the arm and its shape there (issue 27; absent in recordings
    /// made before it, whose readers take the point from the scene).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<ContactShapeInfo>,
}

/// A contact's shape on its link, in that link's frame (a `/tf` frame), as it ran
/// (`sim::dynamics::contact::shape`): a `point` of the link, a `sphere` of `radius` centred on
/// `center` (a pad, or one end sphere of a capsule: a capsule is the two contacts
/// `<name>/0` and `<name>/1`), or the `rim` of a cylinder's end face, the circle of `radius`
/// about `center` normal to `axis`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactShapeInfo {
    /// `point`, `sphere` or `rim`.
    pub kind: String,
    /// m (0 for a point).
    pub radius: f64,
    /// The link (a frame of `/tf`) the geometry is fixed to.
    pub link: String,
    /// The contact's point (the sphere's or rim's centre), link frame, m.
    pub center: [f64; 3],
    /// A rim's unit axis, link frame.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<[f64; 3]>,
}

/// The kinds of [`ContactShapeInfo::kind`].
pub mod shape_kind {
    pub const POINT: &str = "point";
    pub const SPHERE: &str = "sphere";
    pub const RIM: &str = "rim";
}

impl ContactShapeInfo {
    /// The point of the shape farthest along `−normal` (unit, world frame), world frame, m,
    /// given its centre `center_w` and (a rim) its axis `axis_w` in the world frame: the point
    /// itself; `c − r n` for a sphere; `c + r u`, `u = −m/|m|`, `m = n − (n·a) a`, for a rim
    /// (Ericson, *Real-Time Collision Detection*, 2005, §3.9; the formulas of
    /// `sim::dynamics::contact::shape`, which the simulation touches the plane with). A rim
    /// standing on its face (|m| = 0, refused by the run near the plane) gives its centre.
    pub fn lowest_point(&self, center_w: [f64; 3], axis_w: [f64; 3], normal: [f64; 3]) -> [f64; 3] {
        let n = normal;
        match self.kind.as_str() {
            shape_kind::SPHERE => [0, 1, 2].map(|i| center_w[i] - self.radius * n[i]),
            shape_kind::RIM => {
                let a = axis_w;
                let na = n[0] * a[0] + n[1] * a[1] + n[2] * a[2];
                let m = [0, 1, 2].map(|i| n[i] - na * a[i]);
                let s = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
                if s > 0.0 {
                    [0, 1, 2].map(|i| center_w[i] - self.radius * m[i] / s)
                } else {
                    center_w
                }
            }
            _ => center_w,
        }
    }
}

impl ContactInfo {
    /// A `model` contact on the plane z = 0 (normal +z, tangents +x and +y) with no law
    /// parameter set: the base the synthetic recordings and the tests fill in.
    pub fn on_floor(name: &str, model: &str) -> Self {
        ContactInfo {
            name: name.into(),
            model: model.into(),
            restitution: None,
            friction: None,
            stiffness: None,
            damping: None,
            slip_velocity: None,
            normal: [0.0, 0.0, 1.0],
            offset: 0.0,
            t1: [1.0, 0.0, 0.0],
            t2: [0.0, 1.0, 0.0],
            shape: None,
        }
    }
}

/// Record `contacts`: every contact of the run (all of them, bilateral ones too, in
/// `run.contacts` order) and the settings of the event-driven integration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactsRecord {
    /// A JSON array of [`ContactInfo`].
    #[serde(with = "json_contacts")]
    pub contacts: Vec<ContactInfo>,
    /// Width of the bracket an event time is located to, s.
    #[serde(with = "super::sci")]
    pub time_tolerance: f64,
    /// A contact is closed when `|g| ≤ gap_tolerance`, m …
    #[serde(with = "super::sci")]
    pub gap_tolerance: f64,
    /// … and `|dg/dt| ≤ velocity_tolerance`, m/s.
    #[serde(with = "super::sci")]
    pub velocity_tolerance: f64,
    /// Impacts slower than this are plastic and end a bouncing sequence (the Zeno rule), m/s.
    #[serde(with = "super::sci")]
    pub rest_velocity: f64,
    /// Most events in a run.
    #[serde(with = "super::text")]
    pub max_events: u64,
    /// The largest slip speed below which the run regularised a sliding contact's friction
    /// direction, m/s: a stick → slip onset's friction blends towards the direction the sticking
    /// force leaves its cone below `max(v_s, min(K · slip resolution, this))` (`sim`'s
    /// `ode/hybrid.rs`, `onset_speed`), so below this speed the friction's direction is
    /// resolved only to the integrator's resolution of the slip. Absent: `v_s` = 1e-6 m/s
    /// (every recording made before it, and every run whose tolerances resolve the slip
    /// below `v_s`, as the paper's rtol 1e-8). The contact audit does not judge the direction
    /// of slips at or below it ([`super::AuditBounds::of`]).
    #[serde(default, skip_serializing_if = "Option::is_none", with = "super::sci_opt")]
    pub onset_slip_speed: Option<f64>,
}

impl MetadataRecord for ContactsRecord {
    const NAME: &'static str = "contacts";
}

impl ContactsRecord {
    /// The contact named `name`.
    pub fn contact(&self, name: &str) -> Option<&ContactInfo> {
        self.contacts.iter().find(|c| c.name == name)
    }
}

/// [`ContactsRecord::contacts`] as JSON text.
mod json_contacts {
    use serde::{Deserialize, Deserializer, Serializer};

    use super::ContactInfo;

    pub fn serialize<S: Serializer>(v: &[ContactInfo], s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&serde_json::to_string(v).map_err(serde::ser::Error::custom)?)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<ContactInfo>, D::Error> {
        let s = String::deserialize(d)?;
        serde_json::from_str(&s).map_err(|e| serde::de::Error::custom(format!("{s:?} is not a JSON array of contacts: {e}")))
    }
}

#[cfg(test)]
mod tests {
    use super::super::{from_entries, to_entries};
    use super::*;

    pub(crate) fn sample() -> ContactsRecord {
        let plane = ContactInfo::on_floor;
        let elbow4 = ContactInfo { restitution: Some(0.5), friction: Some(0.6), ..plane("elbow4", "unilateral") };
        let pad = ContactInfo { stiffness: Some(1e5), damping: Some(300.0), friction: Some(0.6), slip_velocity: Some(1e-3), ..plane("pad", "compliant") };
        ContactsRecord {
            contacts: vec![elbow4, pad, plane("elbow7", "bilateral")],
            time_tolerance: 1e-12,
            gap_tolerance: 1e-9,
            velocity_tolerance: 1e-9,
            rest_velocity: 1e-4,
            max_events: 100_000,
            onset_slip_speed: None,
        }
    }

    /// Every key is text, numbers in `{:e}` form; the record reads back equal, and a bad
    /// contacts list is named.
    #[test]
    fn the_contacts_record_round_trips() {
        let r = sample();
        let e = to_entries(&r).unwrap();
        let keys: Vec<&str> = e.keys().map(String::as_str).collect();
        assert_eq!(keys, ["contacts", "gap_tolerance", "max_events", "rest_velocity", "time_tolerance", "velocity_tolerance"]);
        assert_eq!(e["time_tolerance"], "1e-12");
        assert_eq!(e["max_events"], "100000");
        // the bilateral contact has no model parameters in the text
        assert!(e["contacts"].contains(r#"{"name":"elbow7","model":"bilateral","normal""#), "{}", e["contacts"]);
        assert_eq!(from_entries::<ContactsRecord>(&e).unwrap(), r);
        assert_eq!(r.contact("pad").and_then(|c| c.stiffness), Some(1e5));
        // the onset's declared speed: a key only when set, read back equal
        let loose = ContactsRecord { onset_slip_speed: Some(3e-3), ..sample() };
        let el = to_entries(&loose).unwrap();
        assert_eq!(el["onset_slip_speed"], "3e-3");
        assert_eq!(from_entries::<ContactsRecord>(&el).unwrap(), loose);
        let mut bad = e.clone();
        bad.insert("contacts".into(), "[1]".into());
        assert!(from_entries::<ContactsRecord>(&bad).unwrap_err().contains("not a JSON array of contacts"));
    }
}
