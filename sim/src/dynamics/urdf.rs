//! A line-aware reader of URDF text (ROS URDF specification, <http://wiki.ros.org/urdf/XML>):
//! the elements the dynamics needs, each with the line it starts on, so that every error says
//! `file:line: <element name="...">: what is wrong; what to do`.
//!
//! Read: `<robot name>`; `<link name>` with `<inertial>` (`<origin xyz rpy>`, `<mass value>`,
//! `<inertia ixx ixy ixz iyy iyz izz>`), the `<mesh filename>` of its `<visual>` and
//! `<collision>`, and each `<collision>`'s `<origin>` and `<sphere>`, `<cylinder>`, `<box>` or
//! `<capsule>` geometry (the table's candidate contacts, `scene/contacts.rs`); `<joint name type>` with `<origin>`, `<parent link>`, `<child link>`,
//! `<axis xyz>` (default `1 0 0`), `<limit>`, `<dynamics>` and `<mimic joint multiplier offset>`.
//! Everything else (materials, textures, `<transmission>`, `<gazebo>`, `<ros2_control>`,
//! `<calibration>`, `<safety_controller>`, vendor tags) is skipped without a word: it does not
//! enter the dynamics. A file that still holds xacro macros is refused with the command that
//! expands it. The XML itself is read by quick-xml (no recursion: depth is bounded before, in
//! [`crate::limits::xml_shape`]).

use std::ops::Range;

use quick_xml::events::{BytesStart, Event};
use quick_xml::Reader;

use crate::error::ModelError;

/// A joint type of the URDF specification.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UrdfJointType {
    Revolute,
    Continuous,
    Prismatic,
    Fixed,
    Floating,
    Planar,
}

impl UrdfJointType {
    pub fn as_str(self) -> &'static str {
        match self {
            UrdfJointType::Revolute => "revolute",
            UrdfJointType::Continuous => "continuous",
            UrdfJointType::Prismatic => "prismatic",
            UrdfJointType::Fixed => "fixed",
            UrdfJointType::Floating => "floating",
            UrdfJointType::Planar => "planar",
        }
    }
}

/// `<origin xyz rpy>` as written (m, rad); zeros when absent.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct UrdfPose {
    pub xyz: [f64; 3],
    pub rpy: [f64; 3],
}

/// A link's `<inertial>`.
#[derive(Clone, Debug, PartialEq)]
pub struct UrdfInertial {
    pub line: usize,
    pub origin: UrdfPose,
    /// kg
    pub mass: f64,
    /// `[ixx, ixy, ixz, iyy, iyz, izz]`, kg m^2, about the centre of mass in the inertial frame.
    pub inertia: [f64; 6],
}

#[derive(Clone, Debug, PartialEq)]
pub struct UrdfLink {
    pub name: String,
    pub line: usize,
    /// `None` when the link has no `<inertial>` (a massless frame).
    pub inertial: Option<UrdfInertial>,
}

/// `<limit>`: what is written; absent attributes are `None`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct UrdfLimit {
    pub lower: Option<f64>,
    pub upper: Option<f64>,
    pub effort: Option<f64>,
    pub velocity: Option<f64>,
}

/// `<mimic joint multiplier offset>`: q_follower = multiplier q_leader + offset.
#[derive(Clone, Debug, PartialEq)]
pub struct UrdfMimic {
    pub line: usize,
    pub leader: String,
    pub multiplier: f64,
    pub offset: f64,
}

#[derive(Clone, Debug, PartialEq)]
pub struct UrdfJointElem {
    pub name: String,
    pub line: usize,
    pub kind: UrdfJointType,
    pub origin: UrdfPose,
    pub parent: String,
    pub child: String,
    /// As written (not normalized); `1 0 0` when absent (the specification's default).
    pub axis: [f64; 3],
    pub limit: Option<UrdfLimit>,
    /// `<dynamics damping friction>`, zeros when absent.
    pub damping: f64,
    pub friction: f64,
    pub mimic: Option<UrdfMimic>,
}

/// A `<mesh filename>` reference, with the byte range of the attribute value in the text.
#[derive(Clone, Debug, PartialEq)]
pub struct UrdfMesh {
    pub link: String,
    pub line: usize,
    pub filename: String,
    /// Byte range of the value in the URDF text (`None` when it held XML escapes).
    pub span: Option<Range<usize>>,
}

/// The geometry of a `<collision>` (ROS URDF specification, `<geometry>`; `<capsule>` is not
/// in the specification but read by Gazebo/SDF-derived tools): lengths in m, in the collision's
/// `<origin>` frame (a cylinder's and a capsule's axis is its z axis, centred at the origin).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum UrdfGeometry {
    Sphere { radius: f64 },
    Cylinder { radius: f64, length: f64 },
    Capsule { radius: f64, length: f64 },
    /// `size`: the full edge lengths along x, y, z.
    Box { size: [f64; 3] },
    Mesh,
}

/// A link's `<collision>`: its `<origin>` in the link frame and its geometry (`None` when the
/// `<geometry>` is missing or holds nothing read).
#[derive(Clone, Debug, PartialEq)]
pub struct UrdfCollision {
    pub link: String,
    pub line: usize,
    pub origin: UrdfPose,
    pub geometry: Option<UrdfGeometry>,
}

/// The parsed document.
#[derive(Clone, Debug, PartialEq)]
pub struct UrdfDoc {
    pub name: String,
    pub links: Vec<UrdfLink>,
    pub joints: Vec<UrdfJointElem>,
    pub meshes: Vec<UrdfMesh>,
    /// Every `<collision>` of every link, in file order.
    pub collisions: Vec<UrdfCollision>,
}

/// What to do with a xacro file.
pub const XACRO_HINT: &str = "this is a xacro file, not a URDF: run `xacro FILE > robot.urdf` first (ROS: `ros2 run xacro xacro FILE > robot.urdf`) and name robot.urdf in the scene";

fn is_xacro(s: &str) -> bool {
    s.contains("${") || s.contains("$(")
}

/// Line numbers (1-based) of byte offsets.
struct Lines(Vec<usize>);

impl Lines {
    fn new(text: &str) -> Self {
        Lines(std::iter::once(0).chain(text.match_indices('\n').map(|(i, _)| i + 1)).collect())
    }
    fn of(&self, offset: usize) -> usize {
        match self.0.binary_search(&offset) {
            Ok(i) => i + 1,
            Err(i) => i,
        }
    }
}

/// `<tag name="...">` for messages.
pub fn element(tag: &str, name: Option<&str>) -> String {
    match name {
        Some(n) => format!("<{tag} name=\"{n}\">"),
        None => format!("<{tag}>"),
    }
}

struct Ctx<'a> {
    file: &'a str,
    line: usize,
    /// The enclosing `<link name="...">` or `<joint name="...">` (empty at the top level).
    within: String,
}

impl Ctx<'_> {
    fn err(&self, element: String, why: impl Into<String>) -> ModelError {
        ModelError::At { file: self.file.to_string(), line: self.line, element: format!("{}{element}", self.within), why: why.into() }
    }
}

/// The attributes of one start tag, unescaped, with the byte range of each raw value.
struct Attrs {
    tag: String,
    items: Vec<(String, String, Option<Range<usize>>)>,
}

impl Attrs {
    fn read(e: &BytesStart, text: &str, c: &Ctx) -> Result<Attrs, ModelError> {
        let tag = String::from_utf8_lossy(e.name().as_ref()).into_owned();
        let mut items = Vec::new();
        for a in e.attributes() {
            let a = a.map_err(|err| c.err(format!("<{tag}>"), format!("malformed attribute: {err}; write attributes as name=\"value\"")))?;
            let key = String::from_utf8_lossy(a.key.as_ref()).into_owned();
            let span = match &a.value {
                // a value borrowed from `text`: its byte range there (for rewriting mesh URIs)
                std::borrow::Cow::Borrowed(v) => (v.as_ptr() as usize)
                    .checked_sub(text.as_ptr() as usize)
                    .filter(|&start| start + v.len() <= text.len())
                    .map(|start| start..start + v.len()),
                _ => None,
            };
            let raw_has_escape = a.value.contains(&b'&');
            let value = a
                .unescape_value()
                .map_err(|err| c.err(format!("<{tag}>"), format!("attribute `{key}`: {err}")))?
                .into_owned();
            items.push((key, value, if raw_has_escape { None } else { span }));
        }
        Ok(Attrs { tag, items })
    }
    fn get(&self, key: &str) -> Option<&str> {
        self.items.iter().find(|(k, _, _)| k == key).map(|(_, v, _)| v.as_str())
    }
    fn span(&self, key: &str) -> Option<Range<usize>> {
        self.items.iter().find(|(k, _, _)| k == key).and_then(|(_, _, s)| s.clone())
    }
    fn elem(&self) -> String {
        element(&self.tag, self.get("name"))
    }
    fn required(&self, key: &str, c: &Ctx) -> Result<&str, ModelError> {
        self.get(key).ok_or_else(|| c.err(self.elem(), format!("the attribute `{key}` is missing; the URDF specification requires it")))
    }
    fn number(&self, key: &str, c: &Ctx) -> Result<Option<f64>, ModelError> {
        match self.get(key) {
            None => Ok(None),
            Some(s) if is_xacro(s) => Err(c.err(self.elem(), format!("{key}=\"{s}\" is a xacro expression; {XACRO_HINT}"))),
            Some(s) => s.trim().parse::<f64>().map(Some).map_err(|_| {
                c.err(self.elem(), format!("{key}=\"{s}\" is not a number; write a decimal number such as 0.25 or 1e-3"))
            }),
        }
    }
    fn vec3(&self, key: &str, c: &Ctx) -> Result<Option<[f64; 3]>, ModelError> {
        let Some(s) = self.get(key) else { return Ok(None) };
        if is_xacro(s) {
            return Err(c.err(self.elem(), format!("{key}=\"{s}\" is a xacro expression; {XACRO_HINT}")));
        }
        let parts: Vec<&str> = s.split_whitespace().collect();
        let bad = || c.err(self.elem(), format!("{key}=\"{s}\" must be three numbers separated by spaces, such as \"0 0 1\""));
        if parts.len() != 3 {
            return Err(bad());
        }
        let mut v = [0.0; 3];
        for (x, p) in v.iter_mut().zip(&parts) {
            *x = p.parse::<f64>().map_err(|_| bad())?;
        }
        Ok(Some(v))
    }
    fn pose(&self, c: &Ctx) -> Result<UrdfPose, ModelError> {
        Ok(UrdfPose { xyz: self.vec3("xyz", c)?.unwrap_or_default(), rpy: self.vec3("rpy", c)?.unwrap_or_default() })
    }
}

/// What the reader is inside of.
enum Open {
    Link(usize),
    Inertial(usize, Option<f64>, Option<[f64; 6]>, UrdfPose, usize),
    Joint(usize),
    /// A `<collision>` (its index in `doc.collisions`) and its `<geometry>`.
    Collision(usize),
    Geometry(usize),
    Other,
}

/// Parse URDF text. `file` names the file in errors.
pub fn parse(text: &str, file: &str) -> Result<UrdfDoc, ModelError> {
    let lines = Lines::new(text);
    let at = |line: usize| Ctx { file, line, within: String::new() };
    if file.ends_with(".xacro") {
        return Err(ModelError::Xacro { file: file.to_string(), line: 1 });
    }
    let mut reader = Reader::from_str(text);
    reader.config_mut().check_end_names = true;
    let mut doc = UrdfDoc { name: String::new(), links: Vec::new(), joints: Vec::new(), meshes: Vec::new(), collisions: Vec::new() };
    // the names of the open elements, outermost first, and what each is
    let mut stack: Vec<(String, Open)> = Vec::new();
    let mut seen_root = false;
    loop {
        let start = reader.buffer_position() as usize;
        let ev = reader.read_event().map_err(|e| {
            let pos = reader.error_position() as usize;
            ModelError::Parse { file: file.to_string(), line: lines.of(pos.min(text.len())), message: format!("{e}") }
        })?;
        // the line of the tag's `<` (skip the whitespace before it)
        let tag_at = start + text.get(start..).map_or(0, |s| s.len() - s.trim_start().len());
        let line = lines.of(tag_at.min(text.len()));
        // the enclosing link or joint, named in messages about its inner elements
        let within = stack
            .iter()
            .rev()
            .find_map(|(_, o)| match o {
                Open::Link(l) => Some(element("link", Some(&doc.links[*l].name))),
                Open::Inertial(l, ..) => Some(format!("{}<inertial>", element("link", Some(&doc.links[*l].name)))),
                Open::Joint(j) => Some(element("joint", Some(&doc.joints[*j].name))),
                Open::Collision(k) | Open::Geometry(k) => Some(format!("{}<collision>", element("link", Some(&doc.collisions[*k].link)))),
                Open::Other => None,
            })
            .unwrap_or_default();
        let c = Ctx { file, line, within };
        let (e, empty) = match &ev {
            Event::Start(e) => (e, false),
            Event::Empty(e) => (e, true),
            Event::End(_) => {
                if let Some((_, open)) = stack.pop() {
                    close(&mut doc, open, &c)?;
                }
                continue;
            }
            Event::Eof => break,
            _ => continue,
        };
        let attrs = Attrs::read(e, text, &c)?;
        let tag = attrs.tag.clone();
        if tag.starts_with("xacro:") || attrs.items.iter().any(|(k, _, _)| k == "xmlns:xacro") && tag != "robot" {
            return Err(ModelError::Xacro { file: file.to_string(), line });
        }
        let parent = stack.last().map(|(t, _)| t.as_str());
        let open = match (stack.len(), parent, tag.as_str()) {
            (0, None, "robot") => {
                if seen_root {
                    return Err(c.err(attrs.elem(), "a second <robot> element; a URDF holds one"));
                }
                seen_root = true;
                // a generated URDF often keeps `xmlns:xacro`: only a xacro element (or a `${…}`
                // in a value) marks an unexpanded file
                doc.name = attrs.get("name").unwrap_or_default().to_string();
                Open::Other
            }
            (0, None, other) => {
                return Err(c.err(format!("<{other}>"), "the root element must be <robot>: is this a URDF?"));
            }
            (1, Some("robot"), "link") => {
                let name = attrs.required("name", &c)?.to_string();
                doc.links.push(UrdfLink { name, line, inertial: None });
                Open::Link(doc.links.len() - 1)
            }
            (1, Some("robot"), "joint") => {
                let name = attrs.required("name", &c)?.to_string();
                let ty = attrs.required("type", &c)?;
                let kind = match ty {
                    "revolute" => UrdfJointType::Revolute,
                    "continuous" => UrdfJointType::Continuous,
                    "prismatic" => UrdfJointType::Prismatic,
                    "fixed" => UrdfJointType::Fixed,
                    "floating" => UrdfJointType::Floating,
                    "planar" => UrdfJointType::Planar,
                    other => {
                        return Err(c.err(
                            attrs.elem(),
                            format!("unknown joint type `{other}`; the URDF types are revolute, continuous, prismatic, fixed, floating and planar"),
                        ))
                    }
                };
                doc.joints.push(UrdfJointElem {
                    name,
                    line,
                    kind,
                    origin: UrdfPose::default(),
                    parent: String::new(),
                    child: String::new(),
                    axis: [1.0, 0.0, 0.0],
                    limit: None,
                    damping: 0.0,
                    friction: 0.0,
                    mimic: None,
                });
                Open::Joint(doc.joints.len() - 1)
            }
            (_, _, _) => {
                match stack.last_mut().map(|(_, o)| o) {
                    Some(Open::Link(l)) if tag == "inertial" => Open::Inertial(*l, None, None, UrdfPose::default(), line),
                    Some(Open::Link(l)) if tag == "collision" => {
                        doc.collisions.push(UrdfCollision { link: doc.links[*l].name.clone(), line, origin: UrdfPose::default(), geometry: None });
                        Open::Collision(doc.collisions.len() - 1)
                    }
                    Some(Open::Collision(k)) if tag == "origin" => {
                        doc.collisions[*k].origin = attrs.pose(&c)?;
                        Open::Other
                    }
                    Some(Open::Collision(k)) if tag == "geometry" => Open::Geometry(*k),
                    Some(Open::Geometry(k)) if tag != "mesh" => {
                        let k = *k;
                        let len = |key: &str, what: &str| -> Result<f64, ModelError> {
                            match attrs.number(key, &c)? {
                                Some(x) if x.is_finite() && x > 0.0 => Ok(x),
                                Some(x) => Err(c.err(attrs.elem(), format!("{key}=\"{x}\" must be a positive length (m) for {what}"))),
                                None => Err(c.err(attrs.elem(), format!("the attribute `{key}` (m) is missing; the URDF specification requires it for {what}"))),
                            }
                        };
                        let g = match tag.as_str() {
                            "sphere" => Some(UrdfGeometry::Sphere { radius: len("radius", "a sphere")? }),
                            "cylinder" => Some(UrdfGeometry::Cylinder { radius: len("radius", "a cylinder")?, length: len("length", "a cylinder")? }),
                            "capsule" => Some(UrdfGeometry::Capsule { radius: len("radius", "a capsule")?, length: len("length", "a capsule")? }),
                            "box" => {
                                let size = attrs.vec3("size", &c)?.ok_or_else(|| c.err(attrs.elem(), "the attribute `size` (m, three edge lengths) is missing"))?;
                                if !size.iter().all(|x| x.is_finite() && *x > 0.0) {
                                    return Err(c.err(attrs.elem(), format!("size=\"{} {} {}\" must be three positive lengths (m)", size[0], size[1], size[2])));
                                }
                                Some(UrdfGeometry::Box { size })
                            }
                            _ => None,
                        };
                        if g.is_some() {
                            doc.collisions[k].geometry = g;
                        }
                        Open::Other
                    }
                    Some(Open::Inertial(_, mass, inertia, origin, _)) => {
                        match tag.as_str() {
                            "origin" => *origin = attrs.pose(&c)?,
                            "mass" => {
                                *mass = Some(attrs.number("value", &c)?.ok_or_else(|| {
                                    c.err(attrs.elem(), "the attribute `value` (kg) is missing")
                                })?)
                            }
                            "inertia" => {
                                let mut v = [0.0; 6];
                                for (x, k) in v.iter_mut().zip(["ixx", "ixy", "ixz", "iyy", "iyz", "izz"]) {
                                    *x = attrs.number(k, &c)?.ok_or_else(|| {
                                        c.err(attrs.elem(), format!("the attribute `{k}` (kg m^2) is missing; write all six of ixx ixy ixz iyy iyz izz"))
                                    })?;
                                }
                                *inertia = Some(v);
                            }
                            _ => {}
                        }
                        Open::Other
                    }
                    Some(Open::Joint(j)) => {
                        let j = *j;
                        let joint = &mut doc.joints[j];
                        match tag.as_str() {
                            "origin" => joint.origin = attrs.pose(&c)?,
                            "parent" => joint.parent = attrs.required("link", &c)?.to_string(),
                            "child" => joint.child = attrs.required("link", &c)?.to_string(),
                            "axis" => joint.axis = attrs.vec3("xyz", &c)?.unwrap_or([1.0, 0.0, 0.0]),
                            "limit" => {
                                joint.limit = Some(UrdfLimit {
                                    lower: attrs.number("lower", &c)?,
                                    upper: attrs.number("upper", &c)?,
                                    effort: attrs.number("effort", &c)?,
                                    velocity: attrs.number("velocity", &c)?,
                                })
                            }
                            "dynamics" => {
                                joint.damping = attrs.number("damping", &c)?.unwrap_or(0.0);
                                joint.friction = attrs.number("friction", &c)?.unwrap_or(0.0);
                            }
                            "mimic" => {
                                let (multiplier, offset) = (attrs.number("multiplier", &c)?.unwrap_or(1.0), attrs.number("offset", &c)?.unwrap_or(0.0));
                                if !(multiplier.is_finite() && offset.is_finite()) {
                                    return Err(c.err(attrs.elem(), format!("multiplier=\"{multiplier}\" offset=\"{offset}\" must be finite numbers")));
                                }
                                joint.mimic = Some(UrdfMimic { line, leader: attrs.required("joint", &c)?.to_string(), multiplier, offset })
                            }
                            _ => {}
                        }
                        Open::Other
                    }
                    _ => {
                        // a mesh anywhere inside a link's visual or collision geometry
                        if tag == "mesh" {
                            if let Some(Open::Geometry(k)) = stack.last().map(|(_, o)| o) {
                                doc.collisions[*k].geometry = Some(UrdfGeometry::Mesh);
                            }
                            let link = stack.iter().find_map(|(_, o)| match o {
                                Open::Link(l) => Some(*l),
                                _ => None,
                            });
                            if let (Some(l), Some(f)) = (link, attrs.get("filename")) {
                                doc.meshes.push(UrdfMesh {
                                    link: doc.links[l].name.clone(),
                                    line,
                                    filename: f.to_string(),
                                    span: attrs.span("filename"),
                                });
                            }
                        }
                        Open::Other
                    }
                }
            }
        };
        if empty {
            close(&mut doc, open, &c)?;
        } else {
            stack.push((tag, open));
        }
    }
    if !seen_root {
        return Err(ModelError::Parse { file: file.to_string(), line: 1, message: "no <robot> element (an empty file?)".into() });
    }
    if let Some((tag, _)) = stack.last() {
        return Err(ModelError::Parse { file: file.to_string(), line: lines.0.len(), message: format!("<{tag}> is not closed (a truncated file?)") });
    }
    // every joint names its parent and child
    for j in &doc.joints {
        let c = at(j.line);
        if j.parent.is_empty() {
            return Err(c.err(element("joint", Some(&j.name)), "has no <parent link=\"...\"/>; the URDF specification requires one"));
        }
        if j.child.is_empty() {
            return Err(c.err(element("joint", Some(&j.name)), "has no <child link=\"...\"/>; the URDF specification requires one"));
        }
    }
    Ok(doc)
}

fn close(doc: &mut UrdfDoc, open: Open, c: &Ctx) -> Result<(), ModelError> {
    if let Open::Inertial(l, mass, inertia, origin, line) = open {
        let link = &doc.links[l];
        let here = Ctx { file: c.file, line, within: String::new() };
        let elem = format!("<link name=\"{}\"><inertial>", link.name);
        let mass = mass.ok_or_else(|| here.err(elem.clone(), "has no <mass value=\"...\"/> (kg); the URDF specification requires one"))?;
        let inertia = inertia.ok_or_else(|| here.err(elem, "has no <inertia .../> (kg m^2); the URDF specification requires one"))?;
        doc.links[l].inertial = Some(UrdfInertial { line, origin, mass, inertia });
    }
    Ok(())
}

/// What became of one `<mesh filename>` of the URDF ([`resolve_meshes`]).
#[derive(Clone, Debug, PartialEq)]
pub struct MeshInfo {
    pub link: String,
    pub line: usize,
    /// As written in the URDF.
    pub filename: String,
    /// The absolute `file://` URI written into the stored URDF text, when resolved.
    pub uri: Option<String>,
    /// Whether the resolved file exists (false when unresolved).
    pub exists: bool,
    /// Why it was not resolved, or why the file is missing; empty when resolved and present.
    pub note: String,
}

/// Resolve the `<mesh filename>` references of URDF `text` (which must parse): a
/// `package://PKG/rest` against `package_dirs[PKG]` (absolute directories), a relative path
/// against `urdf_dir`, a `file://` URI kept. Returns the text with every resolved reference
/// rewritten as an absolute `file://` URI (byte for byte the same text when nothing is
/// rewritten) and what became of each reference, so that a recording can say whether its
/// meshes can be found.
pub fn resolve_meshes(
    text: &str,
    file: &str,
    package_dirs: &std::collections::BTreeMap<String, std::path::PathBuf>,
    urdf_dir: Option<&std::path::Path>,
) -> Result<(String, Vec<MeshInfo>), ModelError> {
    let doc = parse(text, file)?;
    let mut out = String::with_capacity(text.len());
    let mut last = 0;
    let mut infos = Vec::with_capacity(doc.meshes.len());
    for m in &doc.meshes {
        let path: Result<std::path::PathBuf, String> = if let Some(rest) = m.filename.strip_prefix("package://") {
            let (pkg, sub) = rest.split_once('/').unwrap_or((rest, ""));
            match package_dirs.get(pkg) {
                Some(d) => Ok(d.join(sub)),
                None => Err(format!("package `{pkg}` is not in the scene's robot.package_paths: meshes not embedded")),
            }
        } else if let Some(abs) = m.filename.strip_prefix("file://") {
            Ok(std::path::PathBuf::from(abs))
        } else if m.filename.contains("://") {
            Err("not a package:// or file:// URI: left as written".to_string())
        } else {
            match urdf_dir {
                Some(d) => Ok(d.join(&m.filename)),
                None => Err("a relative path, left as written (meshes are resolved when the scene gives robot.package_paths)".to_string()),
            }
        };
        let info = match path {
            Ok(p) => {
                let exists = p.is_file();
                let uri = format!("file://{}", p.display());
                if let (Some(span), true) = (&m.span, uri != m.filename) {
                    out.push_str(&text[last..span.start]);
                    out.push_str(&xml_escape(&uri));
                    last = span.end;
                }
                let note = if exists { String::new() } else { format!("no file {}", p.display()) };
                MeshInfo { link: m.link.clone(), line: m.line, filename: m.filename.clone(), uri: Some(uri), exists, note }
            }
            Err(note) => MeshInfo { link: m.link.clone(), line: m.line, filename: m.filename.clone(), uri: None, exists: false, note },
        };
        infos.push(info);
    }
    out.push_str(&text[last..]);
    Ok((out, infos))
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('"', "&quot;").replace('<', "&lt;")
}

/// One sentence on the meshes for the recording's metadata; `None` when there are none.
pub fn mesh_summary(meshes: &[MeshInfo]) -> Option<String> {
    if meshes.is_empty() {
        return None;
    }
    let present = meshes.iter().filter(|m| m.exists).count();
    if present == meshes.len() {
        return Some(format!("all {} mesh references resolved to file:// URIs of files present when recorded", meshes.len()));
    }
    let missing: Vec<String> = meshes.iter().filter(|m| !m.exists).map(|m| format!("{} (link {}): {}", m.filename, m.link, m.note)).collect();
    // the remedy for what is missing: a package (or the URDF's directory) the scene did not
    // give, or files that are not where the given paths lead
    let unplaced = meshes.iter().any(|m| !m.exists && m.uri.is_none());
    let remedy = if unplaced { "give robot.package_paths in the scene" } else { "the package paths were given: the files named are not there" };
    Some(format!(
        "meshes not embedded: {} of {} mesh references do not resolve to a present file ({remedy}): {}",
        missing.len(),
        meshes.len(),
        missing.join("; ")
    ))
}
