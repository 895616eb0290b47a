//! The visual geometry of a URDF: per link, its `<visual>` elements (origin, primitive shape,
//! colour), read with `quick-xml` (the parser `sim` uses).
//!
//! URDF conventions (<http://wiki.ros.org/urdf/XML/link>): a visual's `origin` is `xyz` (m) and
//! `rpy` (rad, fixed axes X-Y-Z: `R = Rz(y) Ry(p) Rx(r)`) in the link frame; a cylinder's axis is
//! its local z (Rerun's `Cylinders3D` too); `material` is an inline `<color rgba>` or a name
//! defined at the top level of the robot. Meshes are left out (the viewer draws primitives).

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

/// One `<visual>` of a link.
#[derive(Debug, Clone, PartialEq)]
pub struct Visual {
    /// Pose of the shape in the link frame.
    pub origin: Pose,
    pub shape: Shape,
    /// RGBA in [0, 1], when the URDF gives a colour.
    pub rgba: Option<[f64; 4]>,
}

/// The visuals of every link, by link name (links without primitives are absent).
pub type Visuals = BTreeMap<String, Vec<Visual>>;

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

/// The visuals of `xml` (a URDF). An error names the element and the value that does not parse.
pub fn visuals(xml: &str) -> Result<Visuals, String> {
    let mut reader = Reader::from_str(xml);
    let mut out = Visuals::new();
    let mut named_colors: BTreeMap<String, [f64; 4]> = BTreeMap::new();
    let mut link: Option<String> = None;
    let mut visual: Option<(Pose, Option<Shape>, Option<[f64; 4]>, Option<String>)> = None;
    let mut material: Option<String> = None; // a top-level material being defined
    let mut depth_in_visual_geometry = false;
    loop {
        let ev = reader.read_event().map_err(|e| format!("at byte {}: {e}", reader.error_position()))?;
        let (e, empty) = match &ev {
            Event::Start(e) => (e, false),
            Event::Empty(e) => (e, true),
            Event::End(e) => {
                match e.name().as_ref() {
                    b"link" => link = None,
                    b"visual" => {
                        if let (Some(name), Some((origin, Some(shape), rgba, mat))) = (&link, visual.take()) {
                            let rgba = rgba.or_else(|| mat.and_then(|m| named_colors.get(&m).copied()));
                            out.entry(name.clone()).or_default().push(Visual { origin, shape, rgba });
                        }
                        visual = None;
                    }
                    b"geometry" => depth_in_visual_geometry = false,
                    b"material" => material = None,
                    _ => {}
                }
                continue;
            }
            Event::Eof => break,
            _ => continue,
        };
        match e.name().as_ref() {
            b"link" if !empty => link = attr(e, b"name"),
            b"visual" if !empty && link.is_some() => visual = Some((Pose::IDENTITY, None, None, None)),
            b"origin" => {
                if let Some(v) = visual.as_mut().filter(|_| !depth_in_visual_geometry) {
                    let xyz = attr(e, b"xyz").map(|t| numbers::<3>(&t, "origin xyz")).transpose()?.unwrap_or([0.0; 3]);
                    let rpy = attr(e, b"rpy").map(|t| numbers::<3>(&t, "origin rpy")).transpose()?.unwrap_or([0.0; 3]);
                    v.0 = Pose { translation: xyz, rotation: quat_from_rpy(rpy) };
                }
            }
            b"geometry" if visual.is_some() && !empty => depth_in_visual_geometry = true,
            b"box" if depth_in_visual_geometry => {
                let size_m = numbers::<3>(&attr(e, b"size").unwrap_or_default(), "box size")?;
                visual.as_mut().map(|v| v.1 = Some(Shape::Box { size_m }));
            }
            b"cylinder" if depth_in_visual_geometry => {
                let [radius_m] = numbers::<1>(&attr(e, b"radius").unwrap_or_default(), "cylinder radius")?;
                let [length_m] = numbers::<1>(&attr(e, b"length").unwrap_or_default(), "cylinder length")?;
                visual.as_mut().map(|v| v.1 = Some(Shape::Cylinder { radius_m, length_m }));
            }
            b"sphere" if depth_in_visual_geometry => {
                let [radius_m] = numbers::<1>(&attr(e, b"radius").unwrap_or_default(), "sphere radius")?;
                visual.as_mut().map(|v| v.1 = Some(Shape::Sphere { radius_m }));
            }
            b"material" => {
                let name = attr(e, b"name");
                match visual.as_mut() {
                    Some(v) => v.3 = name,
                    None if link.is_none() && !empty => material = name,
                    None => {}
                }
            }
            b"color" => {
                let rgba = numbers::<4>(&attr(e, b"rgba").unwrap_or_default(), "color rgba")?;
                match (visual.as_mut(), &material) {
                    (Some(v), _) => v.2 = Some(rgba),
                    (None, Some(m)) => {
                        named_colors.insert(m.clone(), rgba);
                    }
                    _ => {}
                }
            }
            _ => {}
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
        assert!(visuals("<robot><link name='a'><visual><geometry><box size='1 x 1'/></geometry></visual></link></robot>")
            .unwrap_err()
            .contains("box size"));
    }
}
