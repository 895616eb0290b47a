//! The scene entities of a recording for Foxglove's 3D panel: [`topics::SCENE`] (once, t = 0: the
//! table planes and the target path of the hand) and [`topics::CONTACT_MARKERS`] (every sample:
//! one marker per contact coloured by its mode, an arrow of the contact force on the arm, and the
//! actual and desired hand as spheres coloured apart).
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

use foxglove::messages::{
    line_primitive, ArrowPrimitive, Color, CubePrimitive, KeyValuePair, LinePrimitive, Point3, Pose, Quaternion, SceneEntity,
    SceneUpdate, SpherePrimitive, TextPrimitive, Vector3,
};

use crate::messages::timestamp;
#[cfg(doc)]
use crate::topics;

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

/// The largest `m × 10^k` (m in 1, 2, 5) not above `x > 0` (`x` itself when it is not a
/// positive finite number).
pub fn round_125_down(x: f64) -> f64 {
    if !(x.is_finite() && x > 0.0) {
        return x;
    }
    let p = 10f64.powf(x.log10().floor());
    let m = [5.0, 2.0, 1.0].into_iter().find(|m| m * p <= x * (1.0 + 1e-12)).unwrap_or(1.0);
    m * p
}

/// The length scale of the contact force arrows: one per scene, the same in every run and in
/// both viewers (Foxglove's `/contact_markers`, `analyze view`'s Rerun arrows), written on
/// [`topics::SCENE`] (entity `legend/force_scale`) and in each arrow entity's metadata.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForceScale {
    /// Arrow length per newton, m/N.
    pub m_per_n: f64,
    /// The force the scale was chosen from (the arm's weight under standard gravity), N.
    pub reference_force_n: f64,
}

impl ForceScale {
    /// The scale of an arm of `mass_kg` (every link) whose `links` moving links reach
    /// `reach_m`: its weight under standard gravity is drawn a third of a mean link long,
    /// rounded down to 1, 2 or 5 × 10^k m/N (the paper arm: 1.0 kg, ten 0.3 m links: 9.8 N
    /// would be 0.1 m, so 10 mm per newton; its elbow forces, up to 32 N, up to 0.32 m). An arm
    /// without mass or length gets [`LEGACY_FORCE_SCALE_M_PER_N`].
    pub fn for_arm(mass_kg: f64, reach_m: f64, links: usize) -> Self {
        let weight = mass_kg * STANDARD_GRAVITY_M_PER_S2;
        let link = reach_m / links.max(1) as f64;
        let raw = link / 3.0 / weight;
        let m_per_n = if raw.is_finite() && raw > 0.0 { round_125_down(raw) } else { LEGACY_FORCE_SCALE_M_PER_N };
        ForceScale { m_per_n, reference_force_n: weight }
    }

    /// The scale of a recording written before the scale came from the scene.
    pub fn legacy() -> Self {
        ForceScale { m_per_n: LEGACY_FORCE_SCALE_M_PER_N, reference_force_n: 0.0 }
    }

    /// Drawn length of a force of magnitude `force_n` ≥ 0, m: `|F| × scale`, at least
    /// [`MIN_ARROW_LENGTH_M`] for a nonzero force, 0 for none.
    pub fn length_m(&self, force_n: f64) -> f64 {
        if force_n > 0.0 {
            (force_n * self.m_per_n).max(MIN_ARROW_LENGTH_M)
        } else {
            0.0
        }
    }

    /// A round force whose arrow is about 0.1 m long (the scale bar's), N.
    pub fn bar_force_n(&self) -> f64 {
        round_125_down(0.1 / self.m_per_n)
    }

    /// The legend, e.g. "force arrows: 10 N = 0.100 m (10 mm per N); shorter than 0.060 m
    /// drawn 0.060 m, value in the label".
    pub fn legend(&self) -> String {
        let f = self.bar_force_n();
        format!(
            "force arrows: {} N = {:.3} m ({} mm per N); shorter than {:.3} m drawn {:.3} m, value in the label",
            fmt_num(f),
            f * self.m_per_n,
            fmt_num(self.m_per_n * 1e3),
            MIN_ARROW_LENGTH_M,
            MIN_ARROW_LENGTH_M
        )
    }
}

/// A number without trailing zeros (`10`, `0.5`, `2.5e-5`).
fn fmt_num(x: f64) -> String {
    if x != 0.0 && (x.abs() < 1e-3 || x.abs() >= 1e6) {
        format!("{x:e}")
    } else {
        let s = format!("{x:.6}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

/// How a contact force is drawn: an arrow from the contact point's projection on its plane
/// (the point on the table's surface) along the force, [`ForceScale::length_m`] long.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForceGlyph {
    /// Where the arrow starts: the contact point projected on its plane, world frame, m.
    pub tail: [f64; 3],
    /// Unit direction of the force (+x when there is none), world frame.
    pub direction: [f64; 3],
    /// Drawn length, m (0: no force).
    pub length_m: f64,
    /// `|F|`, N.
    pub magnitude_n: f64,
}

impl ForceGlyph {
    /// The glyph of `force` (N, world frame) at contact `point` (m) on the plane `normal · x =
    /// offset` (unit normal), drawn at `scale`.
    pub fn new(point: [f64; 3], normal: [f64; 3], offset: f64, force: [f64; 3], scale: &ForceScale) -> Self {
        let gap = normal[0] * point[0] + normal[1] * point[1] + normal[2] * point[2] - offset;
        let tail = [0, 1, 2].map(|i| point[i] - gap * normal[i]);
        let magnitude_n = (force[0] * force[0] + force[1] * force[1] + force[2] * force[2]).sqrt();
        let direction = if magnitude_n > 0.0 { force.map(|f| f / magnitude_n) } else { [1.0, 0.0, 0.0] };
        ForceGlyph { tail, direction, length_m: scale.length_m(magnitude_n), magnitude_n }
    }

    /// The arrow's tip, world frame, m.
    pub fn tip(&self) -> [f64; 3] {
        [0, 1, 2].map(|i| self.tail[i] + self.length_m * self.direction[i])
    }
}

/// Writes the label of a contact's force into `out` (cleared first): `<name> <|F|> N <mode>`,
/// e.g. `elbow4 1.4 N bilateral pulling`. Allocates nothing when `out` has room for
/// [`label_capacity`]`(name)`.
pub fn write_label(out: &mut String, name: &str, magnitude_n: f64, mode: MarkerMode) {
    use std::fmt::Write;
    out.clear();
    out.push_str(name);
    // bounded width: at most 8 characters before the unit
    let _ = if magnitude_n.is_finite() && magnitude_n < 99_999.95 { write!(out, " {magnitude_n:.1} N ") } else { write!(out, " {magnitude_n:.2e} N ") };
    out.push_str(mode.name());
}

/// Room a label of contact `name` needs ([`write_label`]).
pub fn label_capacity(name: &str) -> usize {
    name.len() + 48
}

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

/// A contact plane `n · p = d` (world frame, unit normal), as drawn on [`topics::SCENE`].
#[derive(Debug, Clone, PartialEq)]
pub struct TablePlane {
    /// Unit normal, world frame.
    pub normal: [f64; 3],
    /// Offset d, m.
    pub offset: f64,
    /// The contacts on it (names), in this run; empty when the run has none on it (the plane
    /// of the scene's other runs, drawn fainter).
    pub contacts: Vec<String>,
}

/// What [`scene_update`] draws.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneDescription<'a> {
    /// The frame of every entity (the world frame of `/tf`).
    pub frame_id: &'a str,
    /// Distinct planes, each drawn as a thin square box centred on the projection of the world
    /// origin (the arm's base), its top face on the plane.
    pub planes: &'a [TablePlane],
    /// Half the side of each table box, m (the arm's reach).
    pub half_size_m: f64,
    /// The hand's target path, world frame, m (one point per sample taken, in time order).
    pub target_path: &'a [[f64; 3]],
    /// The time between two points of `target_path`, s (metadata).
    pub target_dt_s: f64,
    /// The scale of the force arrows (the scale bar `legend/force_scale`, drawn when there is
    /// a plane).
    pub force_scale: ForceScale,
    /// The run's contact shapes ([`shape_glyphs`]; none for point contacts), each an entity
    /// `shape/<name>` in its link's frame.
    pub shapes: &'a [ShapeGlyph],
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

/// Where the scale bar stands on plane `p`: the projection of (0, −0.25 m, 0) (in front of
/// the base, seen from the −y side view of both viewers), pointing along the normal.
fn scale_bar_tail(p: &TablePlane) -> [f64; 3] {
    let n = p.normal;
    let q = [0.0, -0.25, 0.0];
    let gap = n[0] * q[0] + n[1] * q[1] + n[2] * q[2] - p.offset;
    [0, 1, 2].map(|i| q[i] - gap * n[i])
}

/// The ids of the [`topics::SCENE`] entities.
pub mod ids {
    /// Prefix of the table boxes (`table/<k>`).
    pub const TABLE: &str = "table/";
    /// The target path.
    pub const TARGET_PATH: &str = "target_path";
    /// The force scale bar and its legend.
    pub const FORCE_SCALE: &str = "legend/force_scale";
}

/// The message of [`topics::SCENE`]: entity `table/<k>` per plane (a box, metadata: normal,
/// offset, contacts, units), `target_path` (a line strip of the hand's target, metadata:
/// points, dt, units) and, when there is a plane, `legend/force_scale` (an arrow of a round
/// force at the arrows' scale standing on the first plane, with its text; metadata: the
/// scale, its reference force, the bar's force, the shortest arrow), all at t = 0 in
/// `frame_id`; then one entity per contact shape (`shape/<name>`, in its link's frame,
/// [`shape_entities`]).
pub fn scene_update(d: &SceneDescription<'_>) -> SceneUpdate {
    let mut entities = Vec::with_capacity(d.planes.len() + 2);
    for (k, p) in d.planes.iter().enumerate() {
        let n = p.normal;
        // centre: the base's projection on the plane, moved half a thickness below it
        let c = [n[0] * (p.offset - TABLE_THICKNESS_M / 2.0), n[1] * (p.offset - TABLE_THICKNESS_M / 2.0), n[2] * (p.offset - TABLE_THICKNESS_M / 2.0)];
        let in_run = !p.contacts.is_empty();
        let side = 2.0 * d.half_size_m;
        entities.push(SceneEntity {
            timestamp: Some(timestamp(0)),
            frame_id: d.frame_id.into(),
            id: format!("{}{k}", ids::TABLE),
            lifetime: None,
            frame_locked: false,
            metadata: vec![
                kv("what", "contact plane n·p = d (the table); top face of the box"),
                kv("normal", format!("[{}, {}, {}]", n[0], n[1], n[2])),
                kv("offset_m", p.offset.to_string()),
                kv("contacts", if in_run { p.contacts.join(", ") } else { "none in this run (the scene's other runs touch it)".into() }),
                kv("size_m", format!("{side} x {side} x {TABLE_THICKNESS_M}")),
                kv("units", "m"),
            ],
            cubes: vec![CubePrimitive {
                pose: Some(pose(c, quat(rotation_between([0.0, 0.0, 1.0], n)))),
                size: Some(Vector3 { x: side, y: side, z: TABLE_THICKNESS_M }),
                color: Some(colors::color(colors::TABLE, if in_run { 0.35 } else { 0.15 })),
            }],
            ..Default::default()
        });
    }
    if !d.target_path.is_empty() {
        entities.push(SceneEntity {
            timestamp: Some(timestamp(0)),
            frame_id: d.frame_id.into(),
            id: ids::TARGET_PATH.into(),
            metadata: vec![
                kv("what", "the hand's target path (desired position), world frame"),
                kv("points", d.target_path.len().to_string()),
                kv("dt_s", d.target_dt_s.to_string()),
                kv("units", "m"),
            ],
            lines: vec![LinePrimitive {
                r#type: line_primitive::Type::LineStrip as i32,
                pose: Some(pose([0.0; 3], identity())),
                thickness: TARGET_LINE_WIDTH_M,
                scale_invariant: false,
                points: d.target_path.iter().map(|p| Point3 { x: p[0], y: p[1], z: p[2] }).collect(),
                color: Some(colors::color(colors::HAND_DESIRED, 0.8)),
                colors: Vec::new(),
                indices: Vec::new(),
            }],
            ..Default::default()
        });
    }
    if let Some(plane) = d.planes.iter().find(|p| !p.contacts.is_empty()).or(d.planes.first()) {
        let s = d.force_scale;
        let f = s.bar_force_n();
        let len = f * s.m_per_n;
        let tail = scale_bar_tail(plane);
        let n = plane.normal;
        let legend = s.legend();
        entities.push(SceneEntity {
            timestamp: Some(timestamp(0)),
            frame_id: d.frame_id.into(),
            id: ids::FORCE_SCALE.into(),
            metadata: vec![
                kv("what", "the scale of the contact force arrows (the same in every run of the scene and in analyze view)"),
                kv("scale_m_per_n", s.m_per_n.to_string()),
                kv("reference_force_n", s.reference_force_n.to_string()),
                kv("bar_force_n", f.to_string()),
                kv("min_arrow_length_m", MIN_ARROW_LENGTH_M.to_string()),
                kv("legend", legend.clone()),
                kv("units", "m per N"),
            ],
            arrows: vec![ArrowPrimitive {
                pose: Some(pose(tail, quat(rotation_between([1.0, 0.0, 0.0], n)))),
                shaft_length: (1.0 - ARROW_HEAD_SHARE) * len,
                shaft_diameter: ARROW_SHAFT_DIAMETER_M,
                head_length: ARROW_HEAD_SHARE * len,
                head_diameter: ARROW_HEAD_DIAMETER_M,
                color: Some(colors::color(colors::SCALE_BAR, 1.0)),
            }],
            texts: vec![TextPrimitive {
                pose: Some(pose([0, 1, 2].map(|i| tail[i] + (len + 0.03) * n[i]), identity())),
                billboard: true,
                font_size: LABEL_FONT_PX,
                scale_invariant: true,
                color: Some(colors::color(colors::SCALE_BAR, 1.0)),
                text: format!("{} N = {:.3} m", fmt_num(f), len),
            }],
            ..Default::default()
        });
    }
    entities.extend(shape_entities(d.shapes));
    SceneUpdate { deletions: Vec::new(), entities }
}

/// A table box of [`topics::SCENE`], as read back.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableBox {
    /// Centre, world frame, m.
    pub center: [f64; 3],
    /// Orientation `[x, y, z, w]` (its z axis is the plane's normal).
    pub rotation: [f64; 4],
    /// Full extents, m.
    pub size: [f64; 3],
    /// Opacity in [0, 1] (fainter: a plane no contact of this run is on).
    pub alpha: f64,
}

/// The scale bar of [`topics::SCENE`], as read back.
#[derive(Debug, Clone, PartialEq)]
pub struct ScaleBar {
    pub tail: [f64; 3],
    /// The bar's vector (direction × length), world frame, m.
    pub vector: [f64; 3],
    /// Its text (`10 N = 0.100 m`).
    pub text: String,
}

/// What a reader of a recording (`analyze view`) takes from [`topics::SCENE`] so that it draws
/// what Foxglove draws: the force scale, the tables, the scale bar.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneRead {
    /// [`ForceScale::legacy`] for a recording without `legend/force_scale`.
    pub force_scale: ForceScale,
    /// Whether the scale came from the recording (else the legacy one).
    pub scale_recorded: bool,
    pub tables: Vec<TableBox>,
    pub scale_bar: Option<ScaleBar>,
}

impl Default for SceneRead {
    fn default() -> Self {
        SceneRead { force_scale: ForceScale::legacy(), scale_recorded: false, tables: Vec::new(), scale_bar: None }
    }
}

impl SceneRead {
    /// Reads a decoded [`topics::SCENE`] message (a `foxglove.SceneUpdate`); what it lacks
    /// keeps its default (a message of another producer, or of an older version).
    pub fn from_message(msg: &crate::Value) -> SceneRead {
        use crate::Value;
        let mut out = SceneRead::default();
        let num = |v: &Value, path: &str| v.get(path).and_then(Value::as_f64).unwrap_or(0.0);
        let xyz = |v: &Value, path: &str| [num(v, &format!("{path}.x")), num(v, &format!("{path}.y")), num(v, &format!("{path}.z"))];
        let quat4 = |v: &Value, path: &str| {
            let q = [num(v, &format!("{path}.x")), num(v, &format!("{path}.y")), num(v, &format!("{path}.z")), num(v, &format!("{path}.w"))];
            if q == [0.0; 4] {
                [0.0, 0.0, 0.0, 1.0]
            } else {
                q
            }
        };
        let list = |v: &Value, path: &str| -> Vec<Value> {
            match v.get(path) {
                Some(Value::List(l)) => l.clone(),
                _ => Vec::new(),
            }
        };
        for e in list(msg, "entities") {
            let id = e.get("id").and_then(Value::as_str).unwrap_or("");
            let meta = |key: &str| list(&e, "metadata").into_iter().find(|kv| kv.get("key").and_then(Value::as_str) == Some(key)).and_then(|kv| kv.get("value").and_then(Value::as_str).map(str::to_string));
            if id.starts_with(ids::TABLE) {
                for c in list(&e, "cubes") {
                    out.tables.push(TableBox { center: xyz(&c, "pose.position"), rotation: quat4(&c, "pose.orientation"), size: xyz(&c, "size"), alpha: num(&c, "color.a") });
                }
            } else if id == ids::FORCE_SCALE {
                let scale = meta("scale_m_per_n").and_then(|s| s.parse::<f64>().ok()).filter(|s| s.is_finite() && *s > 0.0);
                if let Some(m_per_n) = scale {
                    let reference_force_n = meta("reference_force_n").and_then(|s| s.parse().ok()).unwrap_or(0.0);
                    out.force_scale = ForceScale { m_per_n, reference_force_n };
                    out.scale_recorded = true;
                }
                if let (Some(a), Some(t)) = (list(&e, "arrows").first(), list(&e, "texts").first()) {
                    let q = quat4(a, "pose.orientation");
                    let len = num(a, "shaft_length") + num(a, "head_length");
                    let dir = rotate(q, [1.0, 0.0, 0.0]);
                    out.scale_bar = Some(ScaleBar {
                        tail: xyz(a, "pose.position"),
                        vector: dir.map(|x| x * len),
                        text: t.get("text").and_then(Value::as_str).unwrap_or("").to_string(),
                    });
                }
            }
        }
        out
    }
}

impl SceneRead {
    /// What `rec`'s [`topics::SCENE`] says (its first message); the defaults when it has none
    /// or did not decode it.
    pub fn from_recording(rec: &crate::Recording) -> SceneRead {
        rec.messages(crate::topics::SCENE).and_then(|m| m.first()).map(|(_, v)| SceneRead::from_message(v)).unwrap_or_default()
    }

    /// What a [`topics::SCENE`] message handed to a [`crate::Visitor`] says (a streamed read:
    /// `analyze view`'s survey takes the first).
    pub fn from_decoded(m: &crate::DecodedMessage<'_>) -> SceneRead {
        SceneRead::from_message(&m.value())
    }
}

/// The `scale_m_per_n` of the first force arrow of `rec`'s first [`topics::CONTACT_MARKERS`]
/// message (what Foxglove draws the run's arrows at), when it has one.
pub fn recorded_arrow_scale(rec: &crate::Recording) -> Option<f64> {
    use crate::Value;
    let (_, msg) = rec.messages(crate::topics::CONTACT_MARKERS)?.first()?;
    let entities = msg.get("entities")?.as_list()?;
    let force = entities.iter().find(|e| e.get("id").and_then(Value::as_str).is_some_and(|id| id.starts_with("force/")))?;
    let meta = force.get("metadata")?.as_list()?;
    meta.iter().find(|kv| kv.get("key").and_then(Value::as_str) == Some("scale_m_per_n"))?.get("value")?.as_str()?.parse().ok()
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

/// The message of [`topics::CONTACT_MARKERS`], built once for a run's contacts and updated in
/// place every sample. Entities, in this order: per contact `contact/<name>` (a translucent
/// sphere at the contact point, larger than the link there, and a ring on the table around
/// the point's projection, both coloured by mode) and `force/<name>` (the force arrow from the
/// point on the surface, [`ForceGlyph`], and its label, [`write_label`]), then `hand/actual`
/// and `hand/desired`.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactMarkers {
    msg: SceneUpdate,
    contacts: Vec<MarkerContact>,
    scale: ForceScale,
}

/// Index of the metadata entry `mode` of a contact entity.
const MODE_KEY: usize = 1;

impl ContactMarkers {
    /// The message for `contacts` in frame `frame_id`, arrows at `scale`.
    pub fn new(frame_id: &str, contacts: &[MarkerContact], scale: ForceScale) -> Self {
        let mut entities = Vec::with_capacity(2 * contacts.len() + 2);
        let entity = |id: String, metadata: Vec<KeyValuePair>| SceneEntity {
            timestamp: Some(timestamp(0)),
            frame_id: frame_id.into(),
            id,
            metadata,
            ..Default::default()
        };
        let sphere = |r: f64, c: Color| SpherePrimitive {
            pose: Some(pose([0.0; 3], identity())),
            size: Some(Vector3 { x: 2.0 * r, y: 2.0 * r, z: 2.0 * r }),
            color: Some(c),
        };
        // the longest mode name, so that writing any mode later needs no allocation
        let longest = [MarkerMode::Separated, MarkerMode::Sticking, MarkerMode::Sliding, MarkerMode::Pushing, MarkerMode::Pulling]
            .iter()
            .map(|m| m.name().len())
            .max()
            .unwrap_or(0);
        // a ring in the xy plane of its pose (turned onto the contact's plane)
        let ring: Vec<Point3> = (0..CONTACT_RING_POINTS)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / CONTACT_RING_POINTS as f64;
                Point3 { x: CONTACT_RING_RADIUS_M * a.cos(), y: CONTACT_RING_RADIUS_M * a.sin(), z: 0.0 }
            })
            .collect();
        for c in contacts {
            let name = &c.name;
            let mut mode = String::with_capacity(longest);
            mode.push_str(MarkerMode::Separated.name());
            let mut e = entity(
                format!("contact/{name}"),
                vec![
                    kv("what", format!("contact point of {name} (sphere) and its point on the table (ring), coloured by mode")),
                    KeyValuePair { key: "mode".into(), value: mode },
                    kv("sphere_radius_m", CONTACT_MARKER_RADIUS_M.to_string()),
                    kv("ring_radius_m", CONTACT_RING_RADIUS_M.to_string()),
                    kv("units", "m"),
                ],
            );
            e.spheres.push(sphere(CONTACT_MARKER_RADIUS_M, colors::color(colors::SEPARATED, 0.45)));
            e.lines.push(LinePrimitive {
                r#type: line_primitive::Type::LineLoop as i32,
                pose: Some(pose([0.0; 3], quat(rotation_between([0.0, 0.0, 1.0], c.normal)))),
                thickness: RING_LINE_WIDTH_M,
                scale_invariant: false,
                points: ring.clone(),
                color: Some(colors::color(colors::SEPARATED, 1.0)),
                colors: Vec::new(),
                indices: Vec::new(),
            });
            entities.push(e);
            let mut a = entity(
                format!("force/{name}"),
                vec![
                    kv("what", format!("force of the table on the arm at {name} (normal + friction), from the point on the table, length = max(|F| x scale, min_length_m)")),
                    kv("scale_m_per_n", scale.m_per_n.to_string()),
                    kv("min_length_m", MIN_ARROW_LENGTH_M.to_string()),
                    kv("units", "m per N"),
                ],
            );
            a.arrows.push(ArrowPrimitive {
                pose: Some(pose([0.0; 3], identity())),
                shaft_length: 0.0,
                shaft_diameter: ARROW_SHAFT_DIAMETER_M,
                head_length: 0.0,
                head_diameter: ARROW_HEAD_DIAMETER_M,
                color: Some(colors::color(colors::SEPARATED, 1.0)),
            });
            let mut text = String::with_capacity(label_capacity(name));
            write_label(&mut text, name, 0.0, MarkerMode::Separated);
            a.texts.push(TextPrimitive {
                pose: Some(pose([0.0; 3], identity())),
                billboard: true,
                font_size: LABEL_FONT_PX,
                scale_invariant: true,
                color: Some(colors::color(colors::SEPARATED, 1.0)),
                text,
            });
            entities.push(a);
        }
        let mut actual = entity("hand/actual".into(), vec![kv("what", "the hand, actual position"), kv("units", "m")]);
        actual.spheres.push(sphere(HAND_ACTUAL_RADIUS_M, colors::color(colors::HAND_ACTUAL, 0.7)));
        entities.push(actual);
        let mut desired = entity("hand/desired".into(), vec![kv("what", "the hand, desired position (target)"), kv("units", "m")]);
        desired.spheres.push(sphere(HAND_DESIRED_RADIUS_M, colors::color(colors::HAND_DESIRED, 0.35)));
        entities.push(desired);
        ContactMarkers { msg: SceneUpdate { deletions: Vec::new(), entities }, contacts: contacts.to_vec(), scale }
    }

    /// The scale of the arrows.
    pub fn scale(&self) -> ForceScale {
        self.scale
    }

    /// The message at `t_ns` for `contacts` (in the order of `new`'s contacts; missing ones
    /// keep their last state) and the hand `actual` and `desired` (world frame, m).
    pub fn update(&mut self, t_ns: u64, contacts: impl IntoIterator<Item = ContactSample>, actual: [f64; 3], desired: [f64; 3]) -> &SceneUpdate {
        let stamp = Some(timestamp(t_ns));
        for e in &mut self.msg.entities {
            e.timestamp = stamp;
        }
        let (contact_entities, hand) = self.msg.entities.split_at_mut(2 * self.contacts.len());
        for ((pair, c), info) in contact_entities.chunks_exact_mut(2).zip(contacts).zip(&self.contacts) {
            let (marker, arrow) = pair.split_at_mut(1);
            let (marker, arrow) = (&mut marker[0], &mut arrow[0]);
            let mode = &mut marker.metadata[MODE_KEY].value;
            mode.clear();
            mode.push_str(c.mode.name());
            let glyph = ForceGlyph::new(c.point, info.normal, info.offset, c.force, &self.scale);
            if let Some(s) = marker.spheres.first_mut() {
                s.pose = Some(pose(c.point, identity()));
                s.color = Some(colors::color(c.mode.hex(), 0.45));
            }
            if let Some(l) = marker.lines.first_mut() {
                if let Some(p) = l.pose.as_mut() {
                    p.position = Some(Vector3 { x: glyph.tail[0], y: glyph.tail[1], z: glyph.tail[2] });
                }
                l.color = Some(colors::color(c.mode.hex(), 1.0));
            }
            let color = colors::color(c.mode.hex(), 1.0);
            if let Some(a) = arrow.arrows.first_mut() {
                a.pose = Some(pose(glyph.tail, quat(rotation_between([1.0, 0.0, 0.0], glyph.direction))));
                a.head_length = ARROW_HEAD_SHARE * glyph.length_m;
                a.shaft_length = glyph.length_m - a.head_length;
                a.color = Some(color);
            }
            if let Some(t) = arrow.texts.first_mut() {
                // beside the tip (at the marker when there is no force)
                let at = if glyph.length_m > 0.0 { glyph.tip() } else { c.point };
                let n = info.normal;
                t.pose = Some(pose([0, 1, 2].map(|i| at[i] + 0.02 * n[i]), identity()));
                t.color = Some(color);
                write_label(&mut t.text, &info.name, glyph.magnitude_n, c.mode);
            }
        }
        for (e, p) in hand.iter_mut().zip([actual, desired]) {
            if let Some(s) = e.spheres.first_mut() {
                if let Some(ps) = s.pose.as_mut() {
                    ps.position = Some(Vector3 { x: p[0], y: p[1], z: p[2] });
                }
            }
        }
        &self.msg
    }

    /// The message as last updated.
    pub fn message(&self) -> &SceneUpdate {
        &self.msg
    }
}

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
        // no force: no arrow
        let none = [ContactSample { point: [0.0; 3], force: [0.0; 3], mode: MarkerMode::Separated }; 2];
        let msg = m.update(6_000_000, none, [0.0; 3], [0.0; 3]);
        assert_eq!(msg.entities[1].arrows[0].shaft_length + msg.entities[1].arrows[0].head_length, 0.0);
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

    /// The paper arm (1.0 kg, ten 0.3 m links) gets 10 mm per N; scales are 1-2-5 rounded
    /// down; a massless arm gets the legacy scale; the bar is a round force about 0.1 m long.
    #[test]
    fn the_scale_comes_from_the_arm() {
        let s = ForceScale::for_arm(1.0, 3.0, 10);
        assert_eq!(s.m_per_n, 0.01);
        assert!((s.reference_force_n - 9.80665).abs() < 1e-12);
        assert_eq!(s.bar_force_n(), 10.0);
        assert_eq!(ForceScale::for_arm(0.0, 3.0, 10), ForceScale { m_per_n: LEGACY_FORCE_SCALE_M_PER_N, reference_force_n: 0.0 });
        for (x, want) in [(0.0102, 0.01), (0.0099, 0.005), (0.03, 0.02), (7.0, 5.0), (1.0, 1.0), (2e-4, 2e-4)] {
            assert!((round_125_down(x) - want).abs() < 1e-15 * want.max(1.0), "{x}: {}", round_125_down(x));
        }
        assert!(s.legend().starts_with("force arrows: 10 N = 0.100 m (10 mm per N)"), "{}", s.legend());
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

    /// A table box's top face lies on its plane (within rounding) and the path keeps its points.
    #[test]
    fn scene_draws_planes_and_path() {
        let planes = [TablePlane { normal: [0.0, 0.0, 1.0], offset: 0.0, contacts: vec!["elbow4".into()] }];
        let path = [[0.0, 0.0, 0.1], [0.1, 0.0, 0.1]];
        let scale = ForceScale::for_arm(1.0, 3.0, 10);
        let s = scene_update(&SceneDescription { frame_id: "world", planes: &planes, half_size_m: 2.0, target_path: &path, target_dt_s: 0.001, force_scale: scale, shapes: &[] });
        assert_eq!(s.entities.len(), 3);
        let cube = &s.entities[0].cubes[0];
        let top = cube.pose.as_ref().unwrap().position.as_ref().unwrap().z + cube.size.as_ref().unwrap().z / 2.0;
        assert!(top.abs() < 1e-15);
        assert_eq!(s.entities[1].lines[0].points.len(), 2);
        assert_eq!(s.entities[1].id, "target_path");
        // the scale bar: 10 N at 10 mm per N, standing on the table
        let bar = &s.entities[2];
        assert_eq!(bar.id, ids::FORCE_SCALE);
        let a = &bar.arrows[0];
        assert!((a.shaft_length + a.head_length - 0.1).abs() < 1e-15);
        assert_eq!(bar.texts[0].text, "10 N = 0.100 m");
    }

    /// What analyze view reads back from /scene is what was written: the scale, the tables,
    /// the bar (through the recording's own encoding and decoding).
    #[test]
    fn scene_reads_back() {
        let planes = [TablePlane { normal: [0.0, 0.6, 0.8], offset: 0.1, contacts: vec!["elbow4".into()] }];
        let scale = ForceScale { m_per_n: 0.02, reference_force_n: 4.9 };
        let s = scene_update(&SceneDescription { frame_id: "world", planes: &planes, half_size_m: 1.5, target_path: &[], target_dt_s: 0.0, force_scale: scale, shapes: &[] });
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("scene.mcap");
        let mut w = crate::RecordingWriter::create(&path).unwrap();
        w.write(crate::topics::SCENE, 0, &s).unwrap();
        w.finish().unwrap();
        let rec = crate::read_recording(&path).unwrap();
        let r = SceneRead::from_message(&rec.messages(crate::topics::SCENE).unwrap()[0].1);
        assert!(r.scale_recorded);
        assert_eq!(r.force_scale, scale);
        assert_eq!(r.tables.len(), 1);
        assert_eq!(r.tables[0].size, [3.0, 3.0, TABLE_THICKNESS_M]);
        let bar = r.scale_bar.unwrap();
        let len = (bar.vector.iter().map(|x| x * x).sum::<f64>()).sqrt();
        assert!((len - 0.1).abs() < 1e-12 && (bar.vector[1] / len - 0.6).abs() < 1e-12, "{bar:?}");
        assert_eq!(SceneRead::from_message(&crate::Value::Struct(Vec::new())), SceneRead::default());
    }
}
