//! The scene file's contact additions (issue 11), as written: the `table` construct, the
//! `events` settings, and the model keys of a contact or of the table ([`LawKeys`]). Part of
//! [`super::spec`] (re-exported there); validated in `scene/contacts.rs`.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::spec::{ContactSpec, PlaneSpec, PointSpec};

/// `"table"`: one plane under named points; each point becomes a contact (unilateral unless
/// `model` says otherwise) that is part of every run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TableSpec {
    /// The table's plane, world frame.
    pub plane: PlaneSpec,
    /// The points of the arm over the table, each a contact of every run (may be empty when
    /// `from_collisions` names links).
    #[serde(default)]
    pub points: Vec<TablePointSpec>,
    /// The contact model of every point: `unilateral`, `bilateral` or `compliant` (default:
    /// unilateral).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(with = "Option<ContactModelName>")]
    pub model: Option<String>,
    /// Newton's coefficient of restitution e in [0, 1] (unilateral; default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub restitution: Option<f64>,
    /// Coulomb friction coefficient mu >= 0 (unilateral, compliant; default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<f64>,
    /// Normal stiffness k, N/m (compliant; required).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness: Option<f64>,
    /// Normal damping c, N s/m (compliant; default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping: Option<f64>,
    /// Regularisation speed v_s of the compliant friction, m/s (default 1e-3).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slip_velocity: Option<f64>,
    /// Links of the URDF whose `<collision>` shapes become candidate contacts on the table
    /// (each link needs at least one sphere, cylinder, capsule or box; meshes are skipped): a
    /// sphere → a sphere contact `<link>/c<k>` at its centre; a box → its 8 corners as point
    /// contacts `<link>/c<k>/0`…`/7`; a cylinder → its two rims `<link>/c<k>/0` (−z end) and
    /// `/1` (+z end), or a capsule (see `cylinders`); a capsule → its two end spheres. k counts
    /// the link's `<collision>` elements from 0 in file order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub from_collisions: Vec<String>,
    /// How a collision `<cylinder>` touches the table: `rims` (default: the two rim circles, the
    /// cylinder's true shape) or `capsule` (two end spheres of the cylinder's radius: a capsule
    /// of the cylinder's radius and length, as many URDFs mean a cylinder with rounded ends).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(with = "Option<CylinderContacts>")]
    pub cylinders: Option<String>,
}

/// How a collision `<cylinder>` becomes contacts (`table.cylinders`).
// (for the schema only: the spec keeps the string, validated in `contacts.rs` with its message)
#[derive(JsonSchema)]
#[schemars(rename_all = "kebab-case")]
#[allow(dead_code)]
pub(super) enum CylinderContacts {
    /// The two rim circles, each touching at its lowest point.
    Rims,
    /// Two spheres of the cylinder's radius at the ends of its axis.
    Capsule,
}

/// One point of the table construct.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TablePointSpec {
    /// The contact's name (as a contact's `name`).
    pub name: String,
    /// The point of the arm.
    pub point: PointSpec,
    /// What touches the table at the point (default: the point itself).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<ShapeSpec>,
}

/// `"shape"` of a contact or a table point: what of the link touches the plane, tagged by
/// `kind` (book: explanation/contacts.md, "Contact shapes"). Absent: the point itself.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum ShapeSpec {
    /// A sphere centred on the contact's point (a pad): it touches the plane at its lowest
    /// point, centre − radius × normal, and rolls.
    Sphere {
        /// The sphere's radius, m (> 0).
        radius: f64,
    },
    /// A capsule (table points only): the segment from the contact's point to `to` (on the
    /// same link) swept by a sphere of `radius`; it becomes two sphere contacts, `<name>/0` at
    /// the point and `<name>/1` at `to`, each lifting off and touching down on its own (a
    /// capsule on a plane touches at its lower end, or at both when it lies flat).
    Capsule {
        /// The capsule's radius, m (> 0).
        radius: f64,
        /// The other end of the capsule's segment, a point of the same link.
        to: PointSpec,
    },
}

/// `"events"`: settings of the event-driven integration (every key optional).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct EventsSpec {
    /// Width of the bracket an event time is located to, s (default 1e-12).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_tolerance: Option<f64>,
    /// Impacts slower than this are plastic and end a bouncing sequence (the Zeno rule), m/s
    /// (default 1e-4).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rest_velocity: Option<f64>,
    /// Most contact events in a run (default 100000).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_events: Option<u64>,
    /// Most contact events in a row at one instant (each within 10 time_tolerance of the
    /// previous) before the run stops as chattering, in [2, 10000] (default 32). Raise it for a
    /// cascade of events through many contacts that does settle.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_events_at_one_time: Option<u32>,
}

/// A contact model (README, "A table that only pushes: contacts").
// (for the schema only: the spec keeps the string, validated in `contacts.rs` with its message)
#[derive(JsonSchema)]
#[schemars(rename_all = "kebab-case")]
#[allow(dead_code)]
pub(super) enum ContactModelName {
    /// The paper's: the point stays on the plane, f_n of either sign, no friction.
    Bilateral,
    /// Rigid, event-driven: g >= 0, f_n >= 0; Newton restitution at impacts; Coulomb friction.
    Unilateral,
    /// A spring-damper: f_n = max(0, k δ + c δ̇) for a penetration δ; regularised friction.
    Compliant,
}

/// The model keys of a contact or of the table, as written.
#[derive(Clone, Copy, Debug)]
pub struct LawKeys<'a> {
    pub model: Option<&'a str>,
    pub restitution: Option<f64>,
    pub friction: Option<f64>,
    pub stiffness: Option<f64>,
    pub damping: Option<f64>,
    pub slip_velocity: Option<f64>,
}

impl ContactSpec {
    pub fn law(&self) -> LawKeys<'_> {
        LawKeys {
            model: self.model.as_deref(),
            restitution: self.restitution,
            friction: self.friction,
            stiffness: self.stiffness,
            damping: self.damping,
            slip_velocity: self.slip_velocity,
        }
    }
}

impl TableSpec {
    pub fn law(&self) -> LawKeys<'_> {
        LawKeys {
            model: self.model.as_deref(),
            restitution: self.restitution,
            friction: self.friction,
            stiffness: self.stiffness,
            damping: self.damping,
            slip_velocity: self.slip_velocity,
        }
    }
}
