//! The geometry of a URDF: per link, its `<visual>` and `<collision>` elements (origin,
//! primitive shape or mesh, colour), read with `quick-xml` (the parser `sim` uses).
//!
//! URDF conventions (<http://wiki.ros.org/urdf/XML/link>): a visual's `origin` is `xyz` (m) and
//! `rpy` (rad, fixed axes X-Y-Z: `R = Rz(y) Ry(p) Rx(r)`) in the link frame; a cylinder's axis is
//! its local z (Rerun's `Cylinders3D` too); `material` is an inline `<color rgba>` or a name
//! defined at the top level of the robot (before or after its use); a `<mesh>` has a
//! `filename` and a `scale` (default `1 1 1`). [`visuals`] are the primitives `entities` draws;
//! [`links`] every visual and collision, meshes too, which [`super::mesh`] draws.

use std::collections::BTreeMap;

use quick_xml::events::{BytesStart, Event};
use quick_xml::Reader;

use super::pose::{quat_from_rpy, Pose};

/// A primitive shape, SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    Box { size_m: [f64; 3] },
    Cylinder { radius_m: f64, length_m: f64 },
    Sphere { radius_m: f64 },
}

/// One `<visual>` primitive of a link.
#[derive(Debug, Clone, PartialEq)]
pub struct Visual {
    /// Pose of the shape in the link frame.
    pub origin: Pose,
    pub shape: Shape,
    /// RGBA in [0, 1], when the URDF gives a colour.
    pub rgba: Option<[f64; 4]>,
}

/// The primitive visuals of every link, by link name (links without primitives are absent).
pub type Visuals = BTreeMap<String, Vec<Visual>>;

/// A `<mesh filename scale>`: the file as the recorded URDF names it (a `file://` URI when
/// `sim` resolved the scene's `robot.package_paths`; empty when it names none) and the scale
/// per axis of the mesh frame (NaN when the attribute does not read as three numbers).
#[derive(Debug, Clone, PartialEq)]
pub struct MeshRef {
    pub filename: String,
    pub scale: [f64; 3],
}

/// The geometry of a `<visual>` or `<collision>`.
#[derive(Debug, Clone, PartialEq)]
pub enum Geometry {
    Primitive(Shape),
    Mesh(MeshRef),
}

/// One `<visual>` or `<collision>` of a link: its pose in the link frame, its geometry and (for
/// a visual) its colour.
#[derive(Debug, Clone, PartialEq)]
pub struct Element {
    pub origin: Pose,
    pub geometry: Geometry,
    pub rgba: Option<[f64; 4]>,
}

/// Everything a link draws with: its visuals and its collisions, in document order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LinkGeometry {
    pub visuals: Vec<Element>,
    pub collisions: Vec<Element>,
}

/// The geometry of every link that has a visual or a collision, by link name.
pub type Links = BTreeMap<String, LinkGeometry>;

/// The child link of every joint, by joint name (`<joint name><child link/></joint>`).
pub fn joint_children(xml: &str) -> Result<BTreeMap<String, String>, String> {
    let mut reader = Reader::from_str(xml);
    let mut out = BTreeMap::new();
    let mut joint: Option<String> = None;
    loop {
        match reader.read_event().map_err(|e| format!("at byte {}: {e}", reader.error_position()))? {
            Event::Start(e) if e.name().as_ref() == b"joint" => joint = attr(&e, b"name"),
            Event::End(e) if e.name().as_ref() == b"joint" => joint = None,
            Event::Empty(e) | Event::Start(e) if e.name().as_ref() == b"child" => {
                if let (Some(j), Some(link)) = (&joint, attr(&e, b"link")) {
                    out.insert(j.clone(), link);
                }
            }
            Event::Eof => break,
            _ => {}
        }
    }
    Ok(out)
}

fn attr(e: &BytesStart, name: &[u8]) -> Option<String> {
    e.attributes().flatten().find(|a| a.key.as_ref() == name).and_then(|a| a.unescape_value().ok()).map(|v| v.into_owned())
}

fn numbers<const N: usize>(text: &str, what: &str) -> Result<[f64; N], String> {
    let v: Vec<f64> = text.split_whitespace().map(str::parse).collect::<Result<_, _>>().map_err(|e| format!("{what} = {text:?}: {e}"))?;
    v.try_into().map_err(|v: Vec<f64>| format!("{what} = {text:?}: {} numbers, expected {N}", v.len()))
}

/// The primitive visuals of `xml` (a URDF), from [`links`].
pub fn visuals(xml: &str) -> Result<Visuals, String> {
    Ok(primitive_visuals(&links(xml)?))
}

/// The primitive visuals of `links`.
pub fn primitive_visuals(links: &Links) -> Visuals {
    let mut out = Visuals::new();
    for (name, link) in links {
        let prims: Vec<Visual> = link
            .visuals
            .iter()
            .filter_map(|e| match e.geometry {
                Geometry::Primitive(shape) => Some(Visual { origin: e.origin, shape, rgba: e.rgba }),
                Geometry::Mesh(_) => None,
            })
            .collect();
        if !prims.is_empty() {
            out.insert(name.clone(), prims);
        }
    }
    out
}

/// Which element of a link is being read.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Visual,
    Collision,
}

/// An element being read: kind, origin, geometry, inline colour, material name.
type Partial = (Kind, Pose, Option<Geometry>, Option<[f64; 4]>, Option<String>);

/// The visuals and collisions of every link of `xml` (a URDF). An error names the element and
/// the value that does not parse; an element without a geometry is left out.
pub fn links(xml: &str) -> Result<Links, String> {
    let mut reader = Reader::from_str(xml);
    let mut out = Links::new();
    let mut named_colors: BTreeMap<String, [f64; 4]> = BTreeMap::new();
    let mut link: Option<String> = None;
    let mut elem: Option<Partial> = None;
    let mut material: Option<String> = None; // a top-level material being defined
    let mut in_geometry = false;
    // the named materials of visuals, resolved at the end (a material may be defined after use)
    let mut pending: Vec<(String, usize, String)> = Vec::new();
    loop {
        let ev = reader.read_event().map_err(|e| format!("at byte {}: {e}", reader.error_position()))?;
        let (e, empty) = match &ev {
            Event::Start(e) => (e, false),
            Event::Empty(e) => (e, true),
            Event::End(e) => {
                match e.name().as_ref() {
                    b"link" => link = None,
                    b"visual" | b"collision" => {
                        if let (Some(name), Some((kind, origin, Some(geometry), rgba, mat))) = (&link, elem.take()) {
                            let entry = out.entry(name.clone()).or_default();
                            let list = if kind == Kind::Visual { &mut entry.visuals } else { &mut entry.collisions };
                            if let (None, Some(m), Kind::Visual) = (rgba, mat, kind) {
                                pending.push((name.clone(), list.len(), m));
                            }
                            list.push(Element { origin, geometry, rgba });
                        }
                        elem = None;
                    }
                    b"geometry" => in_geometry = false,
                    b"material" => material = None,
                    _ => {}
                }
                continue;
            }
            Event::Eof => break,
            _ => continue,
        };
        let set = |elem: &mut Option<Partial>, g: Geometry| {
            if let Some(v) = elem.as_mut() {
                v.2 = Some(g);
            }
        };
        match e.name().as_ref() {
            b"link" if !empty => link = attr(e, b"name"),
            b"visual" if !empty && link.is_some() => elem = Some((Kind::Visual, Pose::IDENTITY, None, None, None)),
            b"collision" if !empty && link.is_some() => elem = Some((Kind::Collision, Pose::IDENTITY, None, None, None)),
            b"origin" => {
                if let Some(v) = elem.as_mut().filter(|_| !in_geometry) {
                    let xyz = attr(e, b"xyz").map(|t| numbers::<3>(&t, "origin xyz")).transpose()?.unwrap_or([0.0; 3]);
                    let rpy = attr(e, b"rpy").map(|t| numbers::<3>(&t, "origin rpy")).transpose()?.unwrap_or([0.0; 3]);
                    v.1 = Pose { translation: xyz, rotation: quat_from_rpy(rpy) };
                }
            }
            b"geometry" if elem.is_some() && !empty => in_geometry = true,
            b"box" if in_geometry => {
                let size_m = numbers::<3>(&attr(e, b"size").unwrap_or_default(), "box size")?;
                set(&mut elem, Geometry::Primitive(Shape::Box { size_m }));
            }
            b"cylinder" if in_geometry => {
                let [radius_m] = numbers::<1>(&attr(e, b"radius").unwrap_or_default(), "cylinder radius")?;
                let [length_m] = numbers::<1>(&attr(e, b"length").unwrap_or_default(), "cylinder length")?;
                set(&mut elem, Geometry::Primitive(Shape::Cylinder { radius_m, length_m }));
            }
            b"sphere" if in_geometry => {
                let [radius_m] = numbers::<1>(&attr(e, b"radius").unwrap_or_default(), "sphere radius")?;
                set(&mut elem, Geometry::Primitive(Shape::Sphere { radius_m }));
            }
            b"mesh" if in_geometry => {
                // a mesh that cannot be drawn (no filename, a bad scale) is the viewer's note,
                // not an error of the whole recording: `mesh::load` says why
                let filename = attr(e, b"filename").unwrap_or_default();
                let scale = attr(e, b"scale").map_or(Ok([1.0; 3]), |t| numbers::<3>(&t, "mesh scale")).unwrap_or([f64::NAN; 3]);
                set(&mut elem, Geometry::Mesh(MeshRef { filename, scale }));
            }
            b"material" => {
                let name = attr(e, b"name");
                match elem.as_mut() {
                    Some(v) => v.4 = name,
                    None if link.is_none() && !empty => material = name,
                    None => {}
                }
            }
            b"color" => {
                let rgba = numbers::<4>(&attr(e, b"rgba").unwrap_or_default(), "color rgba")?;
                match (elem.as_mut(), &material) {
                    (Some(v), _) => v.3 = Some(rgba),
                    (None, Some(m)) => {
                        named_colors.insert(m.clone(), rgba);
                    }
                    _ => {}
                }
            }
            _ => {}
        }
    }
    for (name, k, m) in pending {
        if let (Some(c), Some(l)) = (named_colors.get(&m), out.get_mut(&name)) {
            l.visuals[k].rgba = Some(*c);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn visuals_are_read_with_their_origins_and_colours() {
        let xml = r#"<robot name="r">
          <material name="blue"><color rgba="0 0 1 1"/></material>
          <link name="a"><visual><origin xyz="0 0 0.1" rpy="0 0 0"/><geometry><cylinder radius="0.02" length="0.2"/></geometry>
            <material name="blue"/></visual>
            <collision><origin xyz="9 9 9"/><geometry><box size="1 1 1"/></geometry></collision></link>
          <link name="b"><visual><geometry><sphere radius="0.03"/></geometry><material name="x"><color rgba="1 0 0 0.5"/></material></visual></link>
          <link name="c"/>
        </robot>"#;
        let v = visuals(xml).unwrap();
        assert_eq!(v.len(), 2);
        assert_eq!(v["a"][0].shape, Shape::Cylinder { radius_m: 0.02, length_m: 0.2 });
        assert_eq!(v["a"][0].origin.translation, [0.0, 0.0, 0.1]);
        assert_eq!(v["a"][0].rgba, Some([0.0, 0.0, 1.0, 1.0]));
        assert_eq!(v["b"][0].rgba, Some([1.0, 0.0, 0.0, 0.5]));
        let j = joint_children(r#"<robot><joint name="j1" type="revolute"><parent link="a"/><child link="b"/></joint></robot>"#).unwrap();
        assert_eq!(j["j1"], "b");
        // meshes (with their scale, default 1 1 1) and collisions; a material defined after use
        let l = links(
            r#"<robot name="r">
          <link name="m"><visual><origin xyz="0 0 0.1"/><geometry><mesh filename="file:///a.dae" scale="0.001 0.001 0.002"/></geometry>
            <material name="late"/></visual>
            <collision><geometry><mesh filename="file:///a.stl"/></geometry></collision>
            <collision><geometry><sphere radius="0.1"/></geometry></collision></link>
          <material name="late"><color rgba="0 1 0 1"/></material>
        </robot>"#,
        )
        .unwrap();
        let m = &l["m"];
        assert_eq!(m.visuals[0].geometry, Geometry::Mesh(MeshRef { filename: "file:///a.dae".into(), scale: [0.001, 0.001, 0.002] }));
        assert_eq!(m.visuals[0].origin.translation, [0.0, 0.0, 0.1]);
        assert_eq!(m.visuals[0].rgba, Some([0.0, 1.0, 0.0, 1.0]));
        assert_eq!(m.collisions.len(), 2);
        assert_eq!(m.collisions[0].geometry, Geometry::Mesh(MeshRef { filename: "file:///a.stl".into(), scale: [1.0; 3] }));
        assert_eq!(m.collisions[1].geometry, Geometry::Primitive(Shape::Sphere { radius_m: 0.1 }));
        assert!(visuals(&format!("<robot><link name='m'>{}</link></robot>", "<visual><geometry><mesh filename='x'/></geometry></visual>")).unwrap().is_empty());
        let bad = links("<robot><link name='a'><visual><geometry><mesh filename='x' scale='1 y 1'/></geometry></visual></link></robot>").unwrap();
        assert!(matches!(&bad["a"].visuals[0].geometry, Geometry::Mesh(m) if m.scale.iter().all(|s| s.is_nan())));
        assert!(visuals("<robot><link name='a'><visual><geometry><box size='1 x 1'/></geometry></visual></link></robot>")
            .unwrap_err()
            .contains("box size"));
    }
}
