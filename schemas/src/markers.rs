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
//! Force arrows: the force of the table on the arm at the contact point, `f_n n + f_t1 t1 +
//! f_t2 t2` (N, world frame; sign conventions of the contact modules: `f_n > 0` pushes the point
//! away from the plane), drawn from the contact point with length `|F| ·`
//! [`FORCE_SCALE_M_PER_N`]; the same scale is in each arrow entity's metadata
//! (`scale_m_per_n`).
//!
//! [`ContactMarkers`] builds its message once and only overwrites numbers (and the `mode`
//! metadata value, within its capacity) per sample: recording it allocates nothing per sample.

use foxglove::messages::{
    line_primitive, ArrowPrimitive, Color, CubePrimitive, KeyValuePair, LinePrimitive, Point3, Pose, Quaternion, SceneEntity,
    SceneUpdate, SpherePrimitive, Vector3,
};

use crate::messages::timestamp;
#[cfg(doc)]
use crate::topics;

/// The world frame of `/tf`, the frame of every entity (`sim` records `world -> root link`).
pub const WORLD_FRAME: &str = "world";

/// Length of a force arrow per newton of contact force, m/N: 5 mm per newton, so the paper's
/// elbow forces (|f_n| ≤ 32 N) draw arrows up to 0.16 m, half a link (0.3 m).
pub const FORCE_SCALE_M_PER_N: f64 = 5e-3;
/// Radius of a contact marker sphere, m (the paper arm's elbow spheres are 0.02 m).
pub const CONTACT_MARKER_RADIUS_M: f64 = 0.025;
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
/// Shaft and head diameters of a force arrow, m.
pub const ARROW_SHAFT_DIAMETER_M: f64 = 0.006;
pub const ARROW_HEAD_DIAMETER_M: f64 = 0.015;
/// Share of an arrow's length taken by its head.
pub const ARROW_HEAD_SHARE: f64 = 0.25;

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

/// The message of [`topics::SCENE`]: entity `table/<k>` per plane (a box, metadata: normal,
/// offset, contacts, units) and `target_path` (a line strip of the hand's target, metadata:
/// points, dt, units), all at t = 0 in `frame_id`.
pub fn scene_update(d: &SceneDescription<'_>) -> SceneUpdate {
    let mut entities = Vec::with_capacity(d.planes.len() + 1);
    for (k, p) in d.planes.iter().enumerate() {
        let n = p.normal;
        // centre: the base's projection on the plane, moved half a thickness below it
        let c = [n[0] * (p.offset - TABLE_THICKNESS_M / 2.0), n[1] * (p.offset - TABLE_THICKNESS_M / 2.0), n[2] * (p.offset - TABLE_THICKNESS_M / 2.0)];
        let [x, y, z, w] = rotation_between([0.0, 0.0, 1.0], n);
        let in_run = !p.contacts.is_empty();
        let side = 2.0 * d.half_size_m;
        entities.push(SceneEntity {
            timestamp: Some(timestamp(0)),
            frame_id: d.frame_id.into(),
            id: format!("table/{k}"),
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
                pose: Some(pose(c, Quaternion { x, y, z, w })),
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
            id: "target_path".into(),
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
    SceneUpdate { deletions: Vec::new(), entities }
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

/// The message of [`topics::CONTACT_MARKERS`], built once for a run's contacts and updated in
/// place every sample. Entities, in this order: per contact `contact/<name>` (a sphere at the
/// contact point coloured by mode) and `force/<name>` (the force arrow), then `hand/actual`
/// and `hand/desired`.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactMarkers {
    msg: SceneUpdate,
    n: usize,
}

/// Index of the metadata entry `mode` of a contact entity.
const MODE_KEY: usize = 1;

impl ContactMarkers {
    /// The message for contacts `names` in frame `frame_id`.
    pub fn new(frame_id: &str, names: &[String]) -> Self {
        let mut entities = Vec::with_capacity(2 * names.len() + 2);
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
        for name in names {
            let mut mode = String::with_capacity(longest);
            mode.push_str(MarkerMode::Separated.name());
            let mut e = entity(
                format!("contact/{name}"),
                vec![kv("what", format!("contact point of {name}, coloured by mode")), KeyValuePair { key: "mode".into(), value: mode }, kv("units", "m")],
            );
            e.spheres.push(sphere(CONTACT_MARKER_RADIUS_M, colors::color(colors::SEPARATED, 0.9)));
            entities.push(e);
            let mut a = entity(
                format!("force/{name}"),
                vec![
                    kv("what", format!("force of the table on the arm at {name} (normal + friction), length = |F| x scale")),
                    kv("scale_m_per_n", FORCE_SCALE_M_PER_N.to_string()),
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
            entities.push(a);
        }
        let mut actual = entity("hand/actual".into(), vec![kv("what", "the hand, actual position"), kv("units", "m")]);
        actual.spheres.push(sphere(HAND_ACTUAL_RADIUS_M, colors::color(colors::HAND_ACTUAL, 0.7)));
        entities.push(actual);
        let mut desired = entity("hand/desired".into(), vec![kv("what", "the hand, desired position (target)"), kv("units", "m")]);
        desired.spheres.push(sphere(HAND_DESIRED_RADIUS_M, colors::color(colors::HAND_DESIRED, 0.35)));
        entities.push(desired);
        ContactMarkers { msg: SceneUpdate { deletions: Vec::new(), entities }, n: names.len() }
    }

    /// The message at `t_ns` for `contacts` (in the order of `new`'s names; missing ones keep
    /// their last state) and the hand `actual` and `desired` (world frame, m).
    pub fn update(&mut self, t_ns: u64, contacts: impl IntoIterator<Item = ContactSample>, actual: [f64; 3], desired: [f64; 3]) -> &SceneUpdate {
        let stamp = Some(timestamp(t_ns));
        for e in &mut self.msg.entities {
            e.timestamp = stamp;
        }
        let (contact_entities, hand) = self.msg.entities.split_at_mut(2 * self.n);
        for (pair, c) in contact_entities.chunks_exact_mut(2).zip(contacts) {
            let (marker, arrow) = pair.split_at_mut(1);
            let (marker, arrow) = (&mut marker[0], &mut arrow[0]);
            let mode = &mut marker.metadata[MODE_KEY].value;
            mode.clear();
            mode.push_str(c.mode.name());
            let color = colors::color(c.mode.hex(), 0.9);
            if let Some(s) = marker.spheres.first_mut() {
                s.pose = Some(pose(c.point, identity()));
                s.color = Some(color);
            }
            let f = c.force;
            let norm = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
            let length = norm * FORCE_SCALE_M_PER_N;
            let [x, y, z, w] = if norm > 0.0 { rotation_between([1.0, 0.0, 0.0], [f[0] / norm, f[1] / norm, f[2] / norm]) } else { [0.0, 0.0, 0.0, 1.0] };
            if let Some(a) = arrow.arrows.first_mut() {
                a.pose = Some(pose(c.point, Quaternion { x, y, z, w }));
                a.head_length = ARROW_HEAD_SHARE * length;
                a.shaft_length = length - a.head_length;
                a.color = Some(colors::color(c.mode.hex(), 1.0));
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

    fn rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
        let [x, y, z, w] = q;
        // v' = v + 2w (u × v) + 2 u × (u × v), u = (x, y, z)
        let u = [x, y, z];
        let cross = |a: [f64; 3], b: [f64; 3]| [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
        let t = cross(u, v);
        let t2 = cross(u, t);
        [v[0] + 2.0 * w * t[0] + 2.0 * t2[0], v[1] + 2.0 * w * t[1] + 2.0 * t2[1], v[2] + 2.0 * w * t[2] + 2.0 * t2[2]]
    }

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

    /// Arrow length = |F| × scale (1e-12 relative: one product), along F; colours by mode;
    /// pulling red, pushing blue; hands at their positions.
    #[test]
    fn markers_show_force_mode_and_hand() {
        let names = ["elbow4".to_string(), "elbow7".to_string()];
        let mut m = ContactMarkers::new("world", &names);
        let samples = [
            ContactSample { point: [0.1, 0.2, 0.0], force: [0.0, 0.0, -40.0], mode: MarkerMode::bilateral(-40.0) },
            ContactSample { point: [0.3, 0.0, 0.0], force: [3.0, 0.0, 4.0], mode: MarkerMode::from_code(2, 4.0) },
        ];
        let msg = m.update(5_000_000, samples, [1.0, 2.0, 3.0], [1.0, 2.0, 3.5]).clone();
        assert_eq!(msg.entities.len(), 6);
        let a = &msg.entities[1].arrows[0];
        assert!((a.shaft_length + a.head_length - 40.0 * FORCE_SCALE_M_PER_N).abs() < 1e-12);
        let q = a.pose.as_ref().unwrap().orientation.as_ref().unwrap();
        let d = rotate([q.x, q.y, q.z, q.w], [1.0, 0.0, 0.0]);
        assert!((d[2] + 1.0).abs() < 1e-12, "{d:?}");
        assert_eq!(msg.entities[0].spheres[0].color, Some(colors::color(colors::PULLING, 0.9)));
        assert_eq!(msg.entities[0].metadata[MODE_KEY].value, "bilateral pulling");
        let a2 = &msg.entities[3].arrows[0];
        assert!((a2.shaft_length + a2.head_length - 5.0 * FORCE_SCALE_M_PER_N).abs() < 1e-15);
        assert_eq!(msg.entities[2].spheres[0].color, Some(colors::color(colors::SLIDING, 0.9)));
        let hd = msg.entities[5].spheres[0].pose.as_ref().unwrap().position.as_ref().unwrap();
        assert_eq!((hd.x, hd.y, hd.z), (1.0, 2.0, 3.5));
        assert_eq!(msg.entities[4].timestamp, Some(timestamp(5_000_000)));
        assert!(HAND_ACTUAL_RADIUS_M > 0.015 && HAND_DESIRED_RADIUS_M > HAND_ACTUAL_RADIUS_M);
    }

    /// A table box's top face lies on its plane (within rounding) and the path keeps its points.
    #[test]
    fn scene_draws_planes_and_path() {
        let planes = [TablePlane { normal: [0.0, 0.0, 1.0], offset: 0.0, contacts: vec!["elbow4".into()] }];
        let path = [[0.0, 0.0, 0.1], [0.1, 0.0, 0.1]];
        let s = scene_update(&SceneDescription { frame_id: "world", planes: &planes, half_size_m: 2.0, target_path: &path, target_dt_s: 0.001 });
        assert_eq!(s.entities.len(), 2);
        let cube = &s.entities[0].cubes[0];
        let top = cube.pose.as_ref().unwrap().position.as_ref().unwrap().z + cube.size.as_ref().unwrap().z / 2.0;
        assert!(top.abs() < 1e-15);
        assert_eq!(s.entities[1].lines[0].points.len(), 2);
        assert_eq!(s.entities[1].id, "target_path");
    }
}
