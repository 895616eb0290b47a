//! The scene entities of a recording for Foxglove's 3D panel: [`topics::SCENE`] (once, t = 0: the
//! table planes and the target path of the hand) and [`topics::CONTACT_MARKERS`] (every sample:
//! one marker per contact that touches coloured by its mode, an arrow of the contact force on
//! the arm, and the actual and desired hand as spheres coloured apart; a contact that separates
//! is deleted).
//!
//! Message types and conventions are Foxglove's `foxglove.SceneUpdate` and its primitives
//! (<https://docs.foxglove.dev/docs/visualization/message-schemas/scene-update>,
//! `.../scene-entity`, `.../arrow-primitive`, `.../cube-primitive`, `.../line-primitive`,
//! `.../sphere-primitive`): an entity is identified by `id` within its topic, a later entity with
//! the same id replaces it, `lifetime` 0 keeps it until replaced; an arrow points along its pose's
//! +x axis, total length `shaft_length + head_length`; a cube and a sphere are centred on their
//! pose, `size` is the full extent (diameter for a sphere); colours are RGBA in [0, 1].
//!
//! Colours (issue 13, the lead's decisions): contact mode separated = grey `#9e9e9e`, sticking =
//! green `#2ca02c`, sliding = orange `#ff7f0e`, bilateral pushing (`f_n ≥ 0`) = blue `#1f77b4`,
//! bilateral pulling (`f_n < 0`: the table holds the arm down) = red `#d62728`; hand actual =
//! purple `#9467bd` (a colour no link of the built-in arms has: the paper arm's links are blue),
//! desired/target = orange `#ff7f0e`.
//!
//! Contacts (issue 27): a translucent sphere at the contact point, larger than the link there
//! ([`CONTACT_MARKER_RADIUS_M`]), and a ring on the table around the point's projection on its
//! plane ([`CONTACT_RING_RADIUS_M`]), both coloured by mode; the force of the table on the arm,
//! `f_n n + f_t1 t1 + f_t2 t2` (N, world frame; sign conventions of the contact modules: `f_n >
//! 0` pushes the point away from the plane), drawn as an arrow from that point on the table's
//! surface along the force ([`ForceGlyph`]), `|F| ×` the scene's [`ForceScale`] long and at
//! least [`MIN_ARROW_LENGTH_M`] (so a small force, the paper's elbow4 pulling at about 1.4 N,
//! still leaves its marker), with a text label giving the contact, `|F|` and the mode. The
//! scale is chosen from the scene (the arm's weight), not from the run, so every run of a scene
//! draws a newton the same length; it is on [`topics::SCENE`] as a scale bar with its legend
//! (entity `legend/force_scale`), where `analyze view` reads it ([`SceneRead`]) so that Rerun
//! draws the same arrows, tables and bar.
//!
//! [`ContactMarkers`] builds its message once and only overwrites numbers (and the `mode`
//! metadata value, within its capacity) per sample: recording it allocates nothing per sample.
//! A contact that does not touch is not drawn: its entities are deleted when it separates
//! (`markers/contact_markers.rs`).

use foxglove::messages::{
    line_primitive, ArrowPrimitive, Color, CubePrimitive, KeyValuePair, LinePrimitive, Point3, Pose, Quaternion, SceneEntity,
    SceneUpdate, SpherePrimitive, TextPrimitive, Vector3,
};

use crate::messages::timestamp;
#[cfg(doc)]
use crate::topics;

mod labels;
mod scale;
mod scene;
pub use scale::{round_125_down, ForceGlyph, ForceScale};
use scale::fmt_num;
pub use scene::{ids, recorded_arrow_scale, scene_update, ScaleBar, SceneDescription, SceneRead, TableBox, TablePlane};
pub use labels::{default_anchor, label_capacity, place_labels, write_label, LabelBox, LABEL_CHAR_WIDTH_M, LABEL_GAP_M, LABEL_LIFT_M, LABEL_ROW_M};
mod contact_markers;
pub use contact_markers::ContactMarkers;
mod shapes;
pub use shapes::{circle, shape_entities, shape_glyphs, ShapeGlyph, SHAPE_ALPHA, SHAPE_ID};

/// The world frame of `/tf`, the frame of every entity (`sim` records `world -> root link`).
pub const WORLD_FRAME: &str = "world";

/// The force scale of recordings made before the scale came from the scene (format 3 as first
/// written): 5 mm per newton for every run. A reader of such a file (no `legend/force_scale`
/// on [`topics::SCENE`]) draws with it, as their `/contact_markers` did.
pub const LEGACY_FORCE_SCALE_M_PER_N: f64 = 5e-3;
/// Standard gravity, m/s² (the arm's weight that sets [`ForceScale::for_arm`], whatever the
/// scene's gravity).
pub const STANDARD_GRAVITY_M_PER_S2: f64 = 9.80665;
/// Radius of a contact marker sphere, m: larger than the link geometry at a contact (the paper
/// arm's elbow spheres are 0.02 m, its links 0.01 m), translucent so that the link shows inside.
pub const CONTACT_MARKER_RADIUS_M: f64 = 0.035;
/// Radius of the ring drawn on the table around a contact's point on the surface, m.
pub const CONTACT_RING_RADIUS_M: f64 = 0.06;
/// Points of that ring (a closed loop).
pub const CONTACT_RING_POINTS: usize = 48;
/// Shortest drawn force arrow, m: a nonzero force whose `|F| × scale` is shorter is drawn this
/// long (its value is in the arrow's label), so that it leaves the marker sphere by at least
/// 25 mm.
pub const MIN_ARROW_LENGTH_M: f64 = CONTACT_MARKER_RADIUS_M + 0.025;
/// Radius of the actual hand's sphere, m (the URDF's hand sphere is 0.015 m: this one shows
/// around it).
pub const HAND_ACTUAL_RADIUS_M: f64 = 0.022;
/// Radius of the desired hand's sphere, m (larger and more transparent than the actual one, so
/// both stay visible when they nearly coincide).
pub const HAND_DESIRED_RADIUS_M: f64 = 0.03;
/// Thickness of a table box, m (its top face is the contact plane).
pub const TABLE_THICKNESS_M: f64 = 0.005;
/// Width of the target path's line, m.
pub const TARGET_LINE_WIDTH_M: f64 = 0.002;
/// Width of a contact ring's line, m.
pub const RING_LINE_WIDTH_M: f64 = 0.004;
/// Shaft and head diameters of a force arrow, m.
pub const ARROW_SHAFT_DIAMETER_M: f64 = 0.006;
pub const ARROW_HEAD_DIAMETER_M: f64 = 0.015;
/// Share of an arrow's length taken by its head.
pub const ARROW_HEAD_SHARE: f64 = 0.25;
/// Font size of the labels, screen pixels (scale invariant).
pub const LABEL_FONT_PX: f64 = 14.0;

/// The colours of the views (`#rrggbb` and RGBA in [0, 1]).
pub mod colors {
    /// Contact separated.
    pub const SEPARATED: &str = "#9e9e9e";
    /// Contact sticking.
    pub const STICKING: &str = "#2ca02c";
    /// Contact sliding.
    pub const SLIDING: &str = "#ff7f0e";
    /// Bilateral contact, the table pushes (`f_n ≥ 0`).
    pub const PUSHING: &str = "#1f77b4";
    /// Bilateral contact, the table pulls (`f_n < 0`).
    pub const PULLING: &str = "#d62728";
    /// The hand, actual.
    pub const HAND_ACTUAL: &str = "#9467bd";
    /// The hand, desired (and the target path).
    pub const HAND_DESIRED: &str = "#ff7f0e";
    /// The table.
    pub const TABLE: &str = "#8c6d46";
    /// The force scale bar.
    pub const SCALE_BAR: &str = "#404040";
    /// A contact's shape (sphere pad, capsule, cylinder rim), fixed to its link.
    pub const CONTACT_SHAPE: &str = "#17becf";

    /// `#rrggbb` as RGBA bytes with `alpha` (0 for a malformed string: the constants above are not).
    pub fn rgba8(hex: &str, alpha: u8) -> [u8; 4] {
        let h = hex.trim_start_matches('#');
        let byte = |k: usize| h.get(k..k + 2).and_then(|s| u8::from_str_radix(s, 16).ok()).unwrap_or(0);
        [byte(0), byte(2), byte(4), alpha]
    }

    /// `#rrggbb` as a Foxglove colour (channels in [0, 1]) with opacity `alpha`.
    pub fn color(hex: &str, alpha: f64) -> foxglove::messages::Color {
        let [r, g, b, _] = rgba8(hex, 255);
        foxglove::messages::Color { r: r as f64 / 255.0, g: g as f64 / 255.0, b: b as f64 / 255.0, a: alpha }
    }
}

/// What a contact marker shows: the mode of a unilateral or compliant contact, or the sign of
/// a bilateral contact's force.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MarkerMode {
    Separated,
    Sticking,
    Sliding,
    /// Bilateral, `f_n ≥ 0`.
    Pushing,
    /// Bilateral, `f_n < 0`.
    Pulling,
}

impl MarkerMode {
    /// The mode of a contact from its `/contacts` mode code ([`crate::contact_mode`]) and
    /// normal force (a bilateral contact, code 3, is pushing or pulling by the sign of `f_n`).
    pub fn from_code(code: u32, normal_force_n: f64) -> Self {
        match code {
            crate::contact_mode::SEPARATED => MarkerMode::Separated,
            crate::contact_mode::STICKING => MarkerMode::Sticking,
            crate::contact_mode::SLIDING => MarkerMode::Sliding,
            _ => Self::bilateral(normal_force_n),
        }
    }

    /// A bilateral contact with normal force `f_n`.
    pub fn bilateral(normal_force_n: f64) -> Self {
        if normal_force_n < 0.0 {
            MarkerMode::Pulling
        } else {
            MarkerMode::Pushing
        }
    }

    /// Its name in the entity metadata.
    pub fn name(self) -> &'static str {
        match self {
            MarkerMode::Separated => "separated",
            MarkerMode::Sticking => "sticking",
            MarkerMode::Sliding => "sliding",
            MarkerMode::Pushing => "bilateral pushing",
            MarkerMode::Pulling => "bilateral pulling",
        }
    }

    /// Its colour, `#rrggbb` ([`colors`]).
    pub fn hex(self) -> &'static str {
        match self {
            MarkerMode::Separated => colors::SEPARATED,
            MarkerMode::Sticking => colors::STICKING,
            MarkerMode::Sliding => colors::SLIDING,
            MarkerMode::Pushing => colors::PUSHING,
            MarkerMode::Pulling => colors::PULLING,
        }
    }
}

fn kv(key: &str, value: impl Into<String>) -> KeyValuePair {
    KeyValuePair { key: key.into(), value: value.into() }
}

fn identity() -> Quaternion {
    Quaternion { x: 0.0, y: 0.0, z: 0.0, w: 1.0 }
}

fn pose(p: [f64; 3], q: Quaternion) -> Pose {
    Pose { position: Some(Vector3 { x: p[0], y: p[1], z: p[2] }), orientation: Some(q) }
}

fn quat(q: [f64; 4]) -> Quaternion {
    Quaternion { x: q[0], y: q[1], z: q[2], w: q[3] }
}

/// The unit quaternion that turns `a` (unit) onto `b` (unit), `[x, y, z, w]`; a half turn about
/// an axis normal to `a` when they are opposite.
pub fn rotation_between(a: [f64; 3], b: [f64; 3]) -> [f64; 4] {
    let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let c = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    if dot < -1.0 + 1e-12 {
        // opposite: any axis normal to a
        let axis = if a[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
        let n = [a[1] * axis[2] - a[2] * axis[1], a[2] * axis[0] - a[0] * axis[2], a[0] * axis[1] - a[1] * axis[0]];
        let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        return [n[0] / l, n[1] / l, n[2] / l, 0.0];
    }
    // q = (a × b, 1 + a·b), normalised (half-angle form)
    let w = 1.0 + dot;
    let l = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2] + w * w).sqrt();
    [c[0] / l, c[1] / l, c[2] / l, w / l]
}

/// `v` turned by the unit quaternion `q = [x, y, z, w]`.
pub fn rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    let [x, y, z, w] = q;
    // v' = v + 2w (u × v) + 2 u × (u × v), u = (x, y, z)
    let u = [x, y, z];
    let cross = |a: [f64; 3], b: [f64; 3]| [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    let t = cross(u, v);
    let t2 = cross(u, t);
    [v[0] + 2.0 * w * t[0] + 2.0 * t2[0], v[1] + 2.0 * w * t[1] + 2.0 * t2[1], v[2] + 2.0 * w * t[2] + 2.0 * t2[2]]
}

/// One contact at one sample, as [`ContactMarkers::update`] draws it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactSample {
    /// The contact point, world frame, m.
    pub point: [f64; 3],
    /// The force of the table on the arm at the point, world frame, N.
    pub force: [f64; 3],
    pub mode: MarkerMode,
}

/// A contact as [`ContactMarkers`] draws it: its name and plane `normal · x = offset` (world
/// frame, unit normal).
#[derive(Debug, Clone, PartialEq)]
pub struct MarkerContact {
    pub name: String,
    pub normal: [f64; 3],
    pub offset: f64,
}

/// Index of the metadata entry `mode` of a contact entity.
const MODE_KEY: usize = 1;

#[cfg(test)]
mod tests {
    use super::*;


    /// The quaternion turns a onto b within 1e-12 (unit vectors: rounding only), opposite ones too.
    #[test]
    fn rotation_between_turns_a_onto_b() {
        let cases = [([1.0, 0.0, 0.0], [0.0, 0.0, 1.0]), ([1.0, 0.0, 0.0], [0.0, 0.0, -1.0]), ([1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]), ([0.0, 0.0, 1.0], [0.6, 0.0, 0.8])];
        for (a, b) in cases {
            let r = rotate(rotation_between(a, b), a);
            for k in 0..3 {
                assert!((r[k] - b[k]).abs() < 1e-12, "{a:?} -> {b:?}: {r:?}");
            }
        }
    }

    fn two_contacts() -> Vec<MarkerContact> {
        ["elbow4", "elbow7"].iter().map(|n| MarkerContact { name: n.to_string(), normal: [0.0, 0.0, 1.0], offset: 0.0 }).collect()
    }

    /// Arrow length = |F| × scale (1e-12 relative: one product) above the shortest length,
    /// along F, from the point's projection on the plane; colours by mode; pulling red, pushing
    /// blue; labels with name, |F| and mode; hands at their positions.
    #[test]
    fn markers_show_force_mode_and_hand() {
        let scale = ForceScale { m_per_n: 0.01, reference_force_n: 9.8 };
        let mut m = ContactMarkers::new("world", &two_contacts(), scale);
        let samples = [
            ContactSample { point: [0.1, 0.2, 0.001], force: [0.0, 0.0, -40.0], mode: MarkerMode::bilateral(-40.0) },
            ContactSample { point: [0.3, 0.0, 0.0], force: [0.3, 0.0, 0.4], mode: MarkerMode::from_code(2, 0.4) },
        ];
        let msg = m.update(5_000_000, samples, [1.0, 2.0, 3.0], [1.0, 2.0, 3.5]).clone();
        assert_eq!(msg.entities.len(), 6);
        let a = &msg.entities[1].arrows[0];
        assert!((a.shaft_length + a.head_length - 40.0 * 0.01).abs() < 1e-12);
        let q = a.pose.as_ref().unwrap().orientation.as_ref().unwrap();
        let d = rotate([q.x, q.y, q.z, q.w], [1.0, 0.0, 0.0]);
        assert!((d[2] + 1.0).abs() < 1e-12, "{d:?}");
        // the tail is on the table (z = 0), below the point (z = 1 mm)
        let tail = a.pose.as_ref().unwrap().position.as_ref().unwrap();
        assert_eq!((tail.x, tail.y, tail.z), (0.1, 0.2, 0.0));
        assert_eq!(msg.entities[0].spheres[0].color, Some(colors::color(colors::PULLING, 0.45)));
        assert_eq!(msg.entities[0].lines[0].color, Some(colors::color(colors::PULLING, 1.0)));
        assert_eq!(msg.entities[0].metadata[MODE_KEY].value, "bilateral pulling");
        assert_eq!(msg.entities[1].texts[0].text, "elbow4 40.0 N bilateral pulling");
        // 0.5 N x 0.01 m/N = 5 mm: drawn at the shortest length, the value in the label
        let a2 = &msg.entities[3].arrows[0];
        assert_eq!(a2.shaft_length + a2.head_length, MIN_ARROW_LENGTH_M);
        assert_eq!(msg.entities[3].texts[0].text, "elbow7 0.5 N sliding");
        assert_eq!(msg.entities[2].spheres[0].color, Some(colors::color(colors::SLIDING, 0.45)));
        let hd = msg.entities[5].spheres[0].pose.as_ref().unwrap().position.as_ref().unwrap();
        assert_eq!((hd.x, hd.y, hd.z), (1.0, 2.0, 3.5));
        assert_eq!(msg.entities[4].timestamp, Some(timestamp(5_000_000)));
        const { assert!(HAND_ACTUAL_RADIUS_M > 0.015 && HAND_DESIRED_RADIUS_M > HAND_ACTUAL_RADIUS_M) };
        // touching with no force: no arrow
        let none = [ContactSample { point: [0.0; 3], force: [0.0; 3], mode: MarkerMode::Sticking }; 2];
        let msg = m.update(6_000_000, none, [0.0; 3], [0.0; 3]);
        assert_eq!(msg.entities[1].arrows[0].shaft_length + msg.entities[1].arrows[0].head_length, 0.0);
    }

    /// The ids a viewer shows after each message, applying it as Foxglove does (deletions of
    /// the entities stamped before them, then the entities added or replaced), with each
    /// contact entity's mode.
    fn replay(shown: &mut std::collections::BTreeMap<String, (u64, String)>, msg: &SceneUpdate) {
        let ns = |t: &Option<foxglove::messages::Timestamp>| t.map_or(0, |t| t.total_nanos());
        for d in &msg.deletions {
            assert_eq!(d.r#type, foxglove::messages::scene_entity_deletion::Type::MatchingId as i32);
            if shown.get(&d.id).is_some_and(|(t, _)| *t < ns(&d.timestamp)) {
                shown.remove(&d.id);
            }
        }
        for e in &msg.entities {
            let mode = e.metadata.get(MODE_KEY).map(|kv| kv.value.clone()).unwrap_or_default();
            shown.insert(e.id.clone(), (ns(&e.timestamp), mode));
        }
    }

    /// A contact that separates is deleted in the message of that sample and absent while it
    /// stays separated (its deletions once per separation, its entities in every message while
    /// it touches); a viewer replaying the messages from the start, or only the last one (a
    /// seek), shows at every sample exactly the touching contacts in their modes; the labels
    /// are placed apart among the drawn contacts only. Fails on the old rule (every contact
    /// drawn every sample, a separated one grey).
    #[test]
    fn a_separated_contact_is_deleted_once_and_not_drawn() {
        let contacts: Vec<MarkerContact> = ["a", "b", "c"].iter().map(|n| MarkerContact { name: n.to_string(), normal: [0.0, 0.0, 1.0], offset: 0.0 }).collect();
        let mut m = ContactMarkers::new("world", &contacts, ForceScale::for_arm(1.0, 3.0, 10));
        use MarkerMode::{Separated as Sep, Sliding as Sli, Sticking as Sti};
        // per sample, the three contacts' modes: c starts separated, a separates twice, b never
        let modes = [[Sti, Sti, Sep], [Sep, Sli, Sep], [Sep, Sli, Sep], [Sli, Sti, Sep], [Sep, Sti, Sti], [Sep, Sti, Sti], [Sti, Sti, Sti]];
        let mut shown = std::collections::BTreeMap::new();
        let mut deletions = [0; 3];
        for (i, row) in modes.iter().enumerate() {
            let t = (i as u64 + 1) * 1_000_000;
            let samples = row.iter().enumerate().map(|(k, &mode)| ContactSample { point: [0.0, 0.01 * k as f64, 0.0], force: [0.0, 0.0, if mode == Sep { 0.0 } else { 5.0 }], mode });
            let msg = m.update(t, samples, [0.0; 3], [0.0; 3]).clone();
            for (k, name) in ["a", "b", "c"].iter().enumerate() {
                let separates = row[k] == Sep && (i == 0 || modes[i - 1][k] != Sep);
                let ids = [format!("contact/{name}"), format!("force/{name}")];
                let deleted = msg.deletions.iter().filter(|d| ids.contains(&d.id)).count();
                assert_eq!(deleted, if separates { 2 } else { 0 }, "sample {i}, {name}: {deleted} deletions");
                deletions[k] += deleted;
                let written = msg.entities.iter().filter(|e| ids.contains(&e.id)).count();
                assert_eq!(written, if row[k] == Sep { 0 } else { 2 }, "sample {i}, {name}: {written} entities");
                assert_eq!(m.drawn(k), row[k] != Sep);
            }
            replay(&mut shown, &msg);
            // the last message alone (a seek) shows the same
            let mut seek = std::collections::BTreeMap::new();
            replay(&mut seek, &msg);
            for view in [&shown, &seek] {
                for (k, name) in ["a", "b", "c"].iter().enumerate() {
                    let marker = view.get(&format!("contact/{name}"));
                    match row[k] {
                        Sep => assert!(marker.is_none() && !view.contains_key(&format!("force/{name}")), "sample {i}: separated {name} shown"),
                        mode => {
                            assert_eq!(marker.map(|(t, s)| (*t, s.as_str())), Some((t, mode.name())), "sample {i}, {name}");
                            assert_eq!(view.get(&format!("force/{name}")).map(|(t, _)| *t), Some(t));
                        }
                    }
                }
                assert!(view.contains_key("hand/actual") && view.contains_key("hand/desired"));
                assert_eq!(view.len(), 2 + 2 * row.iter().filter(|&&x| x != Sep).count(), "sample {i}");
            }
            // the drawn labels apart; a lone drawn contact's label at its default place
            let texts: Vec<LabelBox> = msg
                .entities
                .iter()
                .filter(|e| e.id.starts_with("force/"))
                .map(|e| {
                    let p = e.texts[0].pose.as_ref().unwrap().position.as_ref().unwrap();
                    LabelBox::new([p.x, p.y, p.z], e.texts[0].text.chars().count())
                })
                .collect();
            for a in 0..texts.len() {
                for b in 0..a {
                    assert!(texts[a].clearance_m(&texts[b]) >= -1e-9, "sample {i}: labels clash");
                }
            }
        }
        assert_eq!(deletions, [4, 0, 2], "a separates twice, c once (at the first sample)");
    }

    /// Every nonzero force leaves the marker sphere by at least 25 mm - 1e-12 m, whatever its
    /// size and direction, with the point on the table (bilateral) or up to 1 mm off it.
    #[test]
    fn every_nonzero_force_leaves_its_marker() {
        let scale = ForceScale::for_arm(1.0, 3.0, 10);
        let normal = [0.0, 0.0, 1.0];
        for f in [1e-9, 0.01, 1.4, 5.9, 6.0, 32.0, 1e4] {
            for dir in [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [0.6, 0.0, 0.8], [0.0, -0.6, -0.8], [1.0, 0.0, 0.0]] {
                for gap in [-1e-3, 0.0, 1e-3] {
                    let p = [0.2, -0.1, gap];
                    let g = ForceGlyph::new(p, normal, 0.0, dir.map(|x| x * f), &scale);
                    let outside = length_outside_sphere(g.tail, g.tip(), p, CONTACT_MARKER_RADIUS_M);
                    assert!(outside >= 0.025 - 1e-3 - 1e-12, "f = {f} N along {dir:?}, gap {gap}: {outside} m outside");
                    assert!((g.length_m - (f * scale.m_per_n).max(MIN_ARROW_LENGTH_M)).abs() < 1e-15);
                }
            }
        }
    }

    /// Length of the segment a-b outside the ball (c, r), m.
    fn length_outside_sphere(a: [f64; 3], b: [f64; 3], c: [f64; 3], r: f64) -> f64 {
        let d = [0, 1, 2].map(|i| b[i] - a[i]);
        let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let u = d.map(|x| x / len);
        let m = [0, 1, 2].map(|i| a[i] - c[i]);
        let bq = u[0] * m[0] + u[1] * m[1] + u[2] * m[2];
        let cq = m[0] * m[0] + m[1] * m[1] + m[2] * m[2] - r * r;
        let disc = bq * bq - cq;
        if disc <= 0.0 {
            return len;
        }
        let (t0, t1) = ((-bq - disc.sqrt()).clamp(0.0, len), (-bq + disc.sqrt()).clamp(0.0, len));
        len - (t1 - t0)
    }

    /// Foxglove's labels of close contacts never clash (`LabelBox::clearance_m` ≥ −1e-9 m, the
    /// text primitives' poses and texts as recorded): nine contacts 0.3 m apart on a line (the
    /// whole-table run) and two at one point, over 100 samples of forces that change size, sign
    /// and mode; at their default places (above the tips) they clash; a contact far from the
    /// others keeps its default place exactly (the paper runs' bytes do not move).
    #[test]
    fn labels_of_close_contacts_never_clash() {
        let mut contacts: Vec<MarkerContact> = (0..9).map(|i| MarkerContact { name: format!("joint{}", i + 3), normal: [0.0, 0.0, 1.0], offset: 0.0 }).collect();
        contacts.push(MarkerContact { name: "pad/0".into(), normal: [0.0, 0.0, 1.0], offset: 0.0 });
        contacts.push(MarkerContact { name: "pad/1".into(), normal: [0.0, 0.0, 1.0], offset: 0.0 });
        contacts.push(MarkerContact { name: "far".into(), normal: [0.0, 0.0, 1.0], offset: 0.0 });
        let point = |i: usize| match i {
            0..=8 => [0.3 * i as f64, 0.0, 0.0],
            9 | 10 => [1.0, 1.0, 0.0],
            _ => [10.0, 10.0, 0.0],
        };
        let scale = ForceScale::for_arm(1.0, 3.0, 10);
        let mut m = ContactMarkers::new("world", &contacts, scale);
        let mut clashed_by_default = 0;
        for k in 0..100 {
            let samples: Vec<ContactSample> = (0..contacts.len())
                .map(|i| {
                    let f_n = if (k + i) % 7 == 0 { 0.0 } else { 30.0 * ((0.1 * k as f64 + i as f64).sin()) };
                    ContactSample { point: point(i), force: [0.2 * f_n, 0.0, f_n], mode: MarkerMode::bilateral(f_n) }
                })
                .collect();
            let msg = m.update(k as u64 * 1_000_000, samples.iter().copied(), [0.0; 3], [0.0; 3]).clone();
            let boxes: Vec<LabelBox> = (0..contacts.len())
                .map(|i| {
                    let t = &msg.entities[2 * i + 1].texts[0];
                    let p = t.pose.as_ref().unwrap().position.as_ref().unwrap();
                    LabelBox::new([p.x, p.y, p.z], t.text.chars().count())
                })
                .collect();
            let defaults: Vec<LabelBox> = (0..contacts.len())
                .map(|i| {
                    let g = ForceGlyph::new(samples[i].point, [0.0, 0.0, 1.0], 0.0, samples[i].force, &scale);
                    LabelBox::new(default_anchor(&g, samples[i].point, [0.0, 0.0, 1.0]), boxes[i].half_width_m as usize)
                })
                .collect();
            let mut clash = false;
            for i in 0..boxes.len() {
                for j in 0..i {
                    let c = boxes[i].clearance_m(&boxes[j]);
                    assert!(c >= -1e-9, "sample {k}: {} and {} clash by {} m", contacts[i].name, contacts[j].name, -c);
                    clash |= LabelBox { half_width_m: boxes[i].half_width_m, ..defaults[i] }.clearance_m(&LabelBox { half_width_m: boxes[j].half_width_m, ..defaults[j] }) < 0.0;
                }
            }
            clashed_by_default += usize::from(clash);
            assert_eq!(boxes[11].anchor, defaults[11].anchor, "sample {k}: the far label moved");
        }
        assert!(clashed_by_default > 25, "{clashed_by_default}");
    }

    /// A label never outgrows the room it was given (no allocation per sample), whatever the
    /// number.
    #[test]
    fn labels_fit_their_capacity() {
        let mut s = String::with_capacity(label_capacity("elbow4"));
        let cap = s.capacity();
        for f in [0.0, 1.44, 99_999.94, 99_999.96, 1e300, f64::INFINITY, f64::NAN, f64::MAX] {
            write_label(&mut s, "elbow4", f, MarkerMode::Pulling);
            assert_eq!(s.capacity(), cap, "{f}: {s}");
        }
        write_label(&mut s, "elbow4", 1.44, MarkerMode::Pulling);
        assert_eq!(s, "elbow4 1.4 N bilateral pulling");
    }
}
