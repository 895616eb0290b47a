//! The contact shapes of a run as drawn in both viewers (issue 27 item 2): what touches the
//! table, fixed to its link, from each contact's [`ContactShapeInfo`] (record `contacts`).
//!
//! A sphere pad is a sphere; a capsule (the contacts `<name>/0` and `<name>/1`: two spheres of
//! one radius on one link) is the cylinder between its end centres and the two end spheres;
//! a cylinder's rim is the circle of its radius about its centre, normal to its axis; the two
//! rims `<name>/0` and `<name>/1` of one cylinder (one link, one radius, both axes along the
//! segment between the centres, as `table.from_collisions` makes them) are that cylinder and
//! its two rims. A point contact has no shape: it is drawn by its marker alone, as before.
//!
//! On [`crate::topics::SCENE`] each shape is one entity `shape/<name>` (the capsule's or the
//! cylinder's base name), in its link's frame with `frame_locked` (Foxglove moves it with
//! `/tf`: <https://docs.foxglove.dev/docs/visualization/message-schemas/scene-entity>), with
//! Foxglove's sphere, cylinder (flat faces normal to its z axis, `size` the bounding box) and
//! line-loop primitives; metadata: `kind`, `contacts`, `link`, `radius_m`, `centers_m`,
//! `axis`. A run without shaped contacts writes no such entity (the paper's `/scene` is as it
//! was). `analyze view` draws the same [`ShapeGlyph`]s under the link's Rerun entity.

use foxglove::messages::{line_primitive, CylinderPrimitive, LinePrimitive, Point3, SceneEntity, SpherePrimitive, Vector3};

use super::{colors, identity, kv, pose, quat, rotation_between, CONTACT_RING_POINTS, RING_LINE_WIDTH_M};
use crate::messages::timestamp;
use crate::meta::{shape_kind, ContactShapeInfo};

/// Opacity of a drawn contact shape (translucent, so that the link and the marker inside show).
pub const SHAPE_ALPHA: f64 = 0.45;
/// Prefix of the shape entities' ids.
pub const SHAPE_ID: &str = "shape/";

/// One drawn contact shape, link frame (m).
#[derive(Debug, Clone, PartialEq)]
pub enum ShapeGlyph {
    /// A sphere pad.
    Sphere { name: String, link: String, center: [f64; 3], radius: f64 },
    /// A capsule: the segment between `ends` swept by a sphere of `radius`.
    Capsule { name: String, link: String, ends: [[f64; 3]; 2], radius: f64 },
    /// One cylinder rim: the circle of `radius` about `center` normal to the unit `axis`.
    Rim { name: String, link: String, center: [f64; 3], axis: [f64; 3], radius: f64 },
    /// A cylinder from its two rims: its axis is the segment between `ends` (the rims' centres).
    Cylinder { name: String, link: String, ends: [[f64; 3]; 2], radius: f64 },
}

impl ShapeGlyph {
    /// `sphere`, `capsule`, `rim` or `cylinder`.
    pub fn kind(&self) -> &'static str {
        match self {
            ShapeGlyph::Sphere { .. } => "sphere",
            ShapeGlyph::Capsule { .. } => "capsule",
            ShapeGlyph::Rim { .. } => "rim",
            ShapeGlyph::Cylinder { .. } => "cylinder",
        }
    }

    /// The shape's name (a contact's, or a capsule's or cylinder's base name).
    pub fn name(&self) -> &str {
        match self {
            ShapeGlyph::Sphere { name, .. } | ShapeGlyph::Capsule { name, .. } | ShapeGlyph::Rim { name, .. } | ShapeGlyph::Cylinder { name, .. } => name,
        }
    }

    /// The link it is fixed to.
    pub fn link(&self) -> &str {
        match self {
            ShapeGlyph::Sphere { link, .. } | ShapeGlyph::Capsule { link, .. } | ShapeGlyph::Rim { link, .. } | ShapeGlyph::Cylinder { link, .. } => link,
        }
    }

    /// Its radius, m.
    pub fn radius(&self) -> f64 {
        match self {
            ShapeGlyph::Sphere { radius, .. } | ShapeGlyph::Capsule { radius, .. } | ShapeGlyph::Rim { radius, .. } | ShapeGlyph::Cylinder { radius, .. } => *radius,
        }
    }

    /// The rim circles it draws: `(centre, unit axis)` each, link frame.
    pub fn rims(&self) -> Vec<([f64; 3], [f64; 3])> {
        match self {
            ShapeGlyph::Rim { center, axis, .. } => vec![(*center, *axis)],
            ShapeGlyph::Cylinder { ends, .. } => {
                let a = unit(sub(ends[1], ends[0]));
                vec![(ends[0], a), (ends[1], a)]
            }
            _ => Vec::new(),
        }
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let l = norm(a);
    if l > 0.0 {
        a.map(|x| x / l)
    } else {
        [0.0, 0.0, 1.0]
    }
}

/// Whether unit `a` is parallel (or antiparallel) to `d` within 1e-9 rad.
fn parallel(a: [f64; 3], d: [f64; 3]) -> bool {
    let d = unit(d);
    let c = [a[1] * d[2] - a[2] * d[1], a[2] * d[0] - a[0] * d[2], a[0] * d[1] - a[1] * d[0]];
    norm(c) <= 1e-9
}

/// The shapes of a run's contacts (`(name, shape)`, in the run's order; point contacts and
/// contacts without a shape are skipped), capsules and cylinders joined from their two ends.
pub fn shape_glyphs<'a>(contacts: impl IntoIterator<Item = (&'a str, &'a ContactShapeInfo)>) -> Vec<ShapeGlyph> {
    let shaped: Vec<(&str, &ContactShapeInfo)> = contacts.into_iter().filter(|(_, s)| s.kind != shape_kind::POINT && s.radius > 0.0).collect();
    let mut used = vec![false; shaped.len()];
    let mut out = Vec::new();
    for i in 0..shaped.len() {
        if used[i] {
            continue;
        }
        let (name, s) = shaped[i];
        // `<base>/0` with its `<base>/1`: one capsule or one cylinder
        let pair = name.strip_suffix("/0").and_then(|base| {
            let other = format!("{base}/1");
            let j = (0..shaped.len()).find(|&j| !used[j] && j != i && shaped[j].0 == other)?;
            let t = shaped[j].1;
            let same = t.kind == s.kind && t.link == s.link && t.radius == s.radius && t.center != s.center;
            let fits = match s.kind.as_str() {
                shape_kind::SPHERE => true,
                shape_kind::RIM => {
                    let d = sub(t.center, s.center);
                    s.axis.zip(t.axis).is_some_and(|(a, b)| parallel(a, d) && parallel(b, d))
                }
                _ => false,
            };
            (same && fits).then(|| (j, base.to_string(), [s.center, t.center]))
        });
        if let Some((j, base, ends)) = pair {
            used[i] = true;
            used[j] = true;
            let (link, radius) = (s.link.clone(), s.radius);
            out.push(if s.kind == shape_kind::SPHERE {
                ShapeGlyph::Capsule { name: base, link, ends, radius }
            } else {
                ShapeGlyph::Cylinder { name: base, link, ends, radius }
            });
            continue;
        }
        used[i] = true;
        let (name, link, center, radius) = (name.to_string(), s.link.clone(), s.center, s.radius);
        match s.kind.as_str() {
            shape_kind::SPHERE => out.push(ShapeGlyph::Sphere { name, link, center, radius }),
            shape_kind::RIM => out.push(ShapeGlyph::Rim { name, link, center, axis: unit(s.axis.unwrap_or([0.0, 0.0, 1.0])), radius }),
            _ => {}
        }
    }
    out
}

/// The closed circle of `radius` about `center` normal to unit `axis` ([`CONTACT_RING_POINTS`]
/// points, the first not repeated), in the frame of `center`.
pub fn circle(center: [f64; 3], axis: [f64; 3], radius: f64) -> Vec<[f64; 3]> {
    let q = rotation_between([0.0, 0.0, 1.0], axis);
    (0..CONTACT_RING_POINTS)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / CONTACT_RING_POINTS as f64;
            let v = super::rotate(q, [radius * a.cos(), radius * a.sin(), 0.0]);
            [center[0] + v[0], center[1] + v[1], center[2] + v[2]]
        })
        .collect()
}

/// A cylinder primitive between `ends` of `radius` (flat faces normal to the segment).
fn cylinder(ends: [[f64; 3]; 2], radius: f64, alpha: f64) -> CylinderPrimitive {
    let d = sub(ends[1], ends[0]);
    let mid = [0, 1, 2].map(|i| 0.5 * (ends[0][i] + ends[1][i]));
    CylinderPrimitive {
        pose: Some(pose(mid, quat(rotation_between([0.0, 0.0, 1.0], unit(d))))),
        size: Some(Vector3 { x: 2.0 * radius, y: 2.0 * radius, z: norm(d) }),
        bottom_scale: 1.0,
        top_scale: 1.0,
        color: Some(colors::color(colors::CONTACT_SHAPE, alpha)),
    }
}

fn sphere(center: [f64; 3], radius: f64) -> SpherePrimitive {
    SpherePrimitive {
        pose: Some(pose(center, identity())),
        size: Some(Vector3 { x: 2.0 * radius, y: 2.0 * radius, z: 2.0 * radius }),
        color: Some(colors::color(colors::CONTACT_SHAPE, SHAPE_ALPHA)),
    }
}

fn rim_line(center: [f64; 3], axis: [f64; 3], radius: f64) -> LinePrimitive {
    LinePrimitive {
        r#type: line_primitive::Type::LineLoop as i32,
        pose: Some(pose([0.0; 3], identity())),
        thickness: RING_LINE_WIDTH_M,
        scale_invariant: false,
        points: circle(center, axis, radius).into_iter().map(|p| Point3 { x: p[0], y: p[1], z: p[2] }).collect(),
        color: Some(colors::color(colors::CONTACT_SHAPE, 1.0)),
        colors: Vec::new(),
        indices: Vec::new(),
    }
}

fn fmt3(p: [f64; 3]) -> String {
    format!("[{}, {}, {}]", p[0], p[1], p[2])
}

/// The [`crate::topics::SCENE`] entities of `glyphs` (see the module doc), at t = 0.
pub fn shape_entities(glyphs: &[ShapeGlyph]) -> Vec<SceneEntity> {
    glyphs
        .iter()
        .map(|g| {
            let (contacts, centers) = match g {
                ShapeGlyph::Sphere { name, center, .. } | ShapeGlyph::Rim { name, center, .. } => (name.clone(), fmt3(*center)),
                ShapeGlyph::Capsule { name, ends, .. } | ShapeGlyph::Cylinder { name, ends, .. } => {
                    (format!("{name}/0, {name}/1"), format!("[{}, {}]", fmt3(ends[0]), fmt3(ends[1])))
                }
            };
            let mut metadata = vec![
                kv("what", format!("the contact shape of {contacts} on link {}, in its frame", g.link())),
                kv("kind", g.kind()),
                kv("contacts", contacts),
                kv("link", g.link()),
                kv("radius_m", g.radius().to_string()),
                kv("centers_m", centers),
            ];
            if let ShapeGlyph::Rim { axis, .. } = g {
                metadata.push(kv("axis", fmt3(*axis)));
            }
            metadata.push(kv("units", "m"));
            let mut e = SceneEntity {
                timestamp: Some(timestamp(0)),
                frame_id: g.link().into(),
                id: format!("{SHAPE_ID}{}", g.name()),
                frame_locked: true,
                metadata,
                ..Default::default()
            };
            match g {
                ShapeGlyph::Sphere { center, radius, .. } => e.spheres.push(sphere(*center, *radius)),
                ShapeGlyph::Capsule { ends, radius, .. } => {
                    e.cylinders.push(cylinder(*ends, *radius, SHAPE_ALPHA));
                    e.spheres.extend(ends.iter().map(|c| sphere(*c, *radius)));
                }
                ShapeGlyph::Cylinder { ends, radius, .. } => e.cylinders.push(cylinder(*ends, *radius, 0.25)),
                ShapeGlyph::Rim { .. } => {}
            }
            e.lines.extend(g.rims().into_iter().map(|(c, a)| rim_line(c, a, g.radius())));
            e
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn info(kind: &str, link: &str, center: [f64; 3], radius: f64, axis: Option<[f64; 3]>) -> ContactShapeInfo {
        ContactShapeInfo { kind: kind.into(), radius, link: link.into(), center, axis }
    }

    /// A pad stays a sphere, a capsule's two ends become one capsule, a cylinder's two rims one
    /// cylinder, a lone rim a rim, points nothing; two ends on different links or of different
    /// radii stay apart.
    #[test]
    fn contacts_are_joined_into_the_shapes_they_came_from() {
        let x = Some([1.0, 0.0, 0.0]);
        let shapes = [
            ("elbow", info("point", "l1", [0.0; 3], 0.0, None)),
            ("pad", info("sphere", "ball", [0.0, 0.0, 0.1], 0.05, None)),
            ("rod/0", info("sphere", "rod", [-0.3, 0.0, 0.0], 0.04, None)),
            ("rod/1", info("sphere", "rod", [0.3, 0.0, 0.0], 0.04, None)),
            ("drum/c0/0", info("rim", "drum", [-0.2, 0.0, 0.0], 0.05, x)),
            ("drum/c0/1", info("rim", "drum", [0.2, 0.0, 0.0], 0.05, x)),
            ("odd/0", info("sphere", "a", [0.0; 3], 0.01, None)),
            ("odd/1", info("sphere", "b", [0.1, 0.0, 0.0], 0.01, None)),
            ("wheel", info("rim", "w", [0.0; 3], 0.1, Some([0.0, 2.0, 0.0]))),
        ];
        let g = shape_glyphs(shapes.iter().map(|(n, s)| (*n, s)));
        let kinds: Vec<(&str, &str)> = g.iter().map(|g| (g.kind(), g.name())).collect();
        assert_eq!(kinds, [("sphere", "pad"), ("capsule", "rod"), ("cylinder", "drum/c0"), ("sphere", "odd/0"), ("sphere", "odd/1"), ("rim", "wheel")]);
        assert_eq!(g[1], ShapeGlyph::Capsule { name: "rod".into(), link: "rod".into(), ends: [[-0.3, 0.0, 0.0], [0.3, 0.0, 0.0]], radius: 0.04 });
        // the lone rim's axis is made unit
        assert_eq!(g[5].rims(), [([0.0; 3], [0.0, 1.0, 0.0])]);
    }

    /// The entities: in the link frame, frame-locked; a capsule's cylinder spans its ends (its
    /// z axis along the segment, 2r wide), its spheres sit at the ends; every rim point is at
    /// the radius from its centre in the plane normal to its axis (1e-12).
    #[test]
    fn shape_entities_are_the_shapes_in_their_link_frames() {
        let g = vec![
            ShapeGlyph::Capsule { name: "rod".into(), link: "rod".into(), ends: [[-0.3, 0.0, 0.0], [0.3, 0.0, 0.0]], radius: 0.04 },
            ShapeGlyph::Rim { name: "w".into(), link: "wheel".into(), center: [0.1, 0.2, 0.3], axis: [0.0, 0.6, 0.8], radius: 0.1 },
        ];
        let e = shape_entities(&g);
        assert_eq!((e[0].id.as_str(), e[0].frame_id.as_str(), e[0].frame_locked), ("shape/rod", "rod", true));
        let c = e[0].cylinders[0];
        let p = c.pose.unwrap();
        let pos = p.position.unwrap();
        assert!(pos.x.abs() < 1e-15 && pos.y.abs() < 1e-15 && pos.z.abs() < 1e-15);
        let o = p.orientation.unwrap();
        let z = super::super::rotate([o.x, o.y, o.z, o.w], [0.0, 0.0, 1.0]);
        assert!((z[0].abs() - 1.0).abs() < 1e-12, "{z:?}");
        let s = c.size.unwrap();
        assert_eq!((s.x, s.y, s.z), (0.08, 0.08, 0.6));
        let ends: Vec<f64> = e[0].spheres.iter().map(|s| s.pose.unwrap().position.unwrap().x).collect();
        assert_eq!(ends, [-0.3, 0.3]);
        assert_eq!((e[1].frame_id.as_str(), e[1].lines.len(), e[1].spheres.len()), ("wheel", 1, 0));
        for q in &e[1].lines[0].points {
            let d = [q.x - 0.1, q.y - 0.2, q.z - 0.3];
            assert!((norm(d) - 0.1).abs() < 1e-12 && (0.6 * d[1] + 0.8 * d[2]).abs() < 1e-12, "{d:?}");
        }
        let meta = |k: &str| e[1].metadata.iter().find(|kv| kv.key == k).map(|kv| kv.value.clone());
        assert_eq!(meta("kind").as_deref(), Some("rim"));
        assert_eq!(meta("axis").as_deref(), Some("[0, 0.6, 0.8]"));
    }

    /// The lowest point of each shape over the plane z = 0: a point is itself, a sphere's is
    /// r below its centre, a rim tilted by θ about x (axis (0, sin θ, cos θ)·…) is at
    /// `c + r u` with u the in-plane direction most opposed to the normal, r cos θ below c.
    #[test]
    fn the_lowest_point_of_each_shape() {
        let n = [0.0, 0.0, 1.0];
        let c = [0.1, 0.2, 0.3];
        assert_eq!(info("point", "l", c, 0.0, None).lowest_point(c, [0.0; 3], n), c);
        assert_eq!(info("sphere", "l", c, 0.05, None).lowest_point(c, [0.0; 3], n), [0.1, 0.2, 0.25]);
        let th: f64 = 0.3;
        // axis tilted from the horizontal x axis: a = (cos θ, 0, sin θ)
        let a = [th.cos(), 0.0, th.sin()];
        let p = info("rim", "l", c, 0.1, Some([1.0, 0.0, 0.0])).lowest_point(c, a, n);
        let want = [0.1 + 0.1 * th.sin(), 0.2, 0.3 - 0.1 * th.cos()];
        for k in 0..3 {
            assert!((p[k] - want[k]).abs() < 1e-14, "{p:?} {want:?}");
        }
    }
}
