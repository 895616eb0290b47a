//! The message of [`topics::SCENE`] (once, t = 0): the table planes as boxes, the target path
//! of the hand, the force scale bar with its legend and the contact shapes; and what a reader
//! (`analyze view`) takes back from it ([`SceneRead`]) so that Rerun draws the same tables,
//! scale and bar as Foxglove. Foxglove's `SceneUpdate` and its primitives, as in the parent
//! module's doc.

use super::*;

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::markers::TABLE_THICKNESS_M;

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
