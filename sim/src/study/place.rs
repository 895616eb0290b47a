//! Where a contact sits on the arm, as a study variable (`"kind": "on-link"`): a position `t`
//! along a chain of links (link `k = ⌊t⌋` of the list, `s = t − k ∈ [0, 1]` along it) and an
//! angle `θ` around the link's axis, mapped to a point of the link:
//!
//! - a link with a `<collision>` cylinder or capsule (its first one, in file order): the point
//!   on the cylinder's surface, `p = a + s (b − a) + r (cos θ x̂_c + sin θ ŷ_c)`, with `a`, `b`
//!   the ends of its axis (`a` the one nearer the link's origin), `r` its radius and `x̂_c`,
//!   `ŷ_c` the collision frame's axes (a capsule: its cylindrical part; the end caps are not
//!   reached);
//! - without one: the point on the segment from the link's origin (its joint) to its first
//!   child joint's origin, `p = a + s (b − a)` (a line has no "around": θ changes nothing).
//!
//! Without an `around` range the angle is the side of the surface that faces the contact's
//! plane at the initial state (`θ = atan2(−n·ŷ_c, −n·x̂_c)`, n the plane's normal in the link's
//! axes). With `support` (the default) the contact's plane is moved to pass through the point
//! at the initial state (`plane.offset = n · p_world(q0)`): a brace placed under the point, so
//! that the point rests from the start wherever it is (a bilateral contact must hold at q0; a
//! unilateral one must not start inside its plane). Only that point touches the brace: the
//! rest of the arm is not a contact (as everywhere in the paper's model).
//!
//! The geometry is read once from the base scene (its URDF and initial state); the mapping
//! gives each candidate's replacements of `contacts.<k>.point` and `contacts.<k>.plane.offset`.

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use serde_json::{json, Value};

use crate::dynamics::kinematics::forward_kinematics;
use crate::dynamics::urdf::{self, UrdfGeometry};
use crate::dynamics::Data;
use crate::scene::Scene;

/// One link of the chain: the line (or cylinder) a point is placed on, in the link's frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Segment {
    pub link: String,
    /// The axis' ends, link frame, m (`a` nearer the link's origin).
    pub a: Vector3<f64>,
    pub b: Vector3<f64>,
    /// The surface's radius, m (0: the segment itself).
    pub radius: f64,
    /// Unit vectors across the axis, link frame (θ = 0 along `e1`, π/2 along `e2`).
    pub e1: Vector3<f64>,
    pub e2: Vector3<f64>,
    /// The link frame in the world at the base scene's initial state.
    pub x_world_link: Isometry3<f64>,
    /// What the point is placed on, for messages and the book ("collision cylinder 0", ...).
    pub on: String,
}

/// A contact placed along a chain of links.
#[derive(Clone, Debug, PartialEq)]
pub struct Placement {
    /// The contact's index in the scene's `contacts`.
    pub contact: usize,
    pub links: Vec<Segment>,
    /// The contact plane's unit normal, world frame.
    pub normal: Vector3<f64>,
    /// Move the plane through the point at q0.
    pub support: bool,
}

fn pose(xyz: [f64; 3], rpy: [f64; 3]) -> Isometry3<f64> {
    Isometry3::from_parts(Translation3::new(xyz[0], xyz[1], xyz[2]), UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]))
}

/// Two unit vectors across `u` (any, for a line).
fn across(u: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let t = if u.x.abs() < 0.9 { Vector3::x() } else { Vector3::y() };
    let e1 = (t - u * u.dot(&t)).normalize();
    (e1, u.cross(&e1).normalize())
}

impl Placement {
    /// The placement of contact `contact` (index into the scene's `contacts`, with plane
    /// normal `normal`) along `links`, from the base `scene`; `Err((j, why))` names the link
    /// `links[j]` that cannot carry a point.
    pub fn new(scene: &Scene, contact: usize, normal: [f64; 3], links: &[String], support: bool) -> Result<Placement, (usize, String)> {
        let model = scene.model();
        let doc = urdf::parse(scene.urdf_xml(), "the URDF").map_err(|e| (0, e.to_string()))?;
        let mut data = Data::new(model);
        forward_kinematics(model, &mut data, scene.q0());
        let mut out = Vec::with_capacity(links.len());
        for (j, link) in links.iter().enumerate() {
            let Some(frame) = model.frame(link) else {
                return Err((j, format!("no such link in the URDF (links: {})", model.frames.iter().map(|f| f.name.as_str()).collect::<Vec<_>>().join(", "))));
            };
            let Some(body) = frame.body else {
                return Err((j, "is fixed to the base: a contact there never moves".into()));
            };
            let x_world_link = data.x_world_body[body] * frame.x_body_frame;
            let shape = doc.collisions.iter().filter(|c| &c.link == link).enumerate().find_map(|(k, c)| match c.geometry {
                Some(UrdfGeometry::Cylinder { radius, length }) => Some((k, "cylinder", radius, length, pose(c.origin.xyz, c.origin.rpy))),
                Some(UrdfGeometry::Capsule { radius, length }) => Some((k, "capsule", radius, length, pose(c.origin.xyz, c.origin.rpy))),
                _ => None,
            });
            let seg = match shape {
                Some((k, kind, radius, length, x)) => {
                    let (mut a, mut b) = ((x * Point3::new(0.0, 0.0, -0.5 * length)).coords, (x * Point3::new(0.0, 0.0, 0.5 * length)).coords);
                    if b.norm() < a.norm() {
                        std::mem::swap(&mut a, &mut b);
                    }
                    Segment { link: link.clone(), a, b, radius, e1: x.rotation * Vector3::x(), e2: x.rotation * Vector3::y(), x_world_link, on: format!("its collision {kind} {k} (radius {radius} m, length {length} m)") }
                }
                None => {
                    let Some(child) = model.urdf_joints.iter().find(|u| &u.parent_link == link) else {
                        return Err((j, "has no <collision> cylinder or capsule and no child joint: there is no segment to place a point on".into()));
                    };
                    let b = child.origin.translation.vector;
                    if b.norm() < 1e-9 {
                        return Err((j, format!("has no <collision> cylinder or capsule and its child joint `{}` sits at its origin: a segment of length 0", child.name)));
                    }
                    let (e1, e2) = across(&b.normalize());
                    Segment { link: link.clone(), a: Vector3::zeros(), b, radius: 0.0, e1, e2, x_world_link, on: format!("the segment from its origin to joint `{}` (no collision cylinder or capsule)", child.name) }
                }
            };
            out.push(seg);
        }
        Ok(Placement { contact, links: out, normal: Vector3::from(normal).normalize(), support })
    }

    /// The link and the point (link frame, m) at position `t ∈ [0, links]` along the chain and
    /// angle `theta` (rad; `None`: the side facing the plane at q0).
    pub fn point(&self, t: f64, theta: Option<f64>) -> (&Segment, Vector3<f64>) {
        let n = self.links.len();
        let t = t.clamp(0.0, n as f64);
        let k = (t.floor() as usize).min(n - 1);
        let s = (t - k as f64).clamp(0.0, 1.0);
        let seg = &self.links[k];
        let theta = theta.unwrap_or_else(|| {
            // the plane's normal in the link's axes: the side facing it is along −n
            let d = seg.x_world_link.rotation.inverse() * (-self.normal);
            d.dot(&seg.e2).atan2(d.dot(&seg.e1))
        });
        (seg, seg.a + (seg.b - seg.a) * s + (seg.e1 * theta.cos() + seg.e2 * theta.sin()) * seg.radius)
    }

    /// The replacements of the scene JSON that put the contact at (`t`, `theta`).
    pub fn replacements(&self, t: f64, theta: Option<f64>) -> Vec<(String, Value)> {
        let (seg, p) = self.point(t, theta);
        let k = self.contact;
        let mut out = vec![(format!("contacts.{k}.point"), json!({"link": seg.link, "offset": [p.x, p.y, p.z]}))];
        if self.support {
            let p_world = seg.x_world_link * Point3::from(p);
            out.push((format!("contacts.{k}.plane.offset"), Value::from(self.normal.dot(&p_world.coords))));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn segment(radius: f64) -> Segment {
        Segment {
            link: "l".into(),
            a: Vector3::new(0.0, 0.0, 0.1),
            b: Vector3::new(0.0, 0.0, 0.5),
            radius,
            e1: Vector3::x(),
            e2: Vector3::y(),
            x_world_link: Isometry3::translation(1.0, 2.0, 3.0),
            on: String::new(),
        }
    }

    #[test]
    fn a_point_on_a_cylinder_lies_on_its_surface_at_its_place_along_and_around() {
        // every (s, θ) on a grid: distance from the axis = r, the projection on the axis at
        // a + s (b − a), the direction across at angle θ from e1
        let p = Placement { contact: 3, links: vec![segment(0.02)], normal: Vector3::z(), support: true };
        for i in 0..=10 {
            for j in -8..=8 {
                let (s, th) = (i as f64 / 10.0, j as f64 * 0.4);
                let (_, x) = p.point(s, Some(th));
                let along = (x.z - 0.1) / 0.4;
                assert!((along - s).abs() < 1e-12, "s = {s}: {along}");
                let radial = Vector3::new(x.x, x.y, 0.0);
                assert!((radial.norm() - 0.02).abs() < 1e-15);
                assert!((radial.y.atan2(radial.x) - th.sin().atan2(th.cos())).abs() < 1e-12, "θ = {th}");
            }
        }
        // out of range: clamped to the ends
        assert_eq!(p.point(-1.0, Some(0.0)).1, p.point(0.0, Some(0.0)).1);
        assert_eq!(p.point(7.0, Some(0.0)).1, p.point(1.0, Some(0.0)).1);
    }

    #[test]
    fn without_an_angle_the_point_faces_the_plane_and_the_plane_passes_through_it() {
        // the link frame turned by 90° about x: its +y axis points down (world −z); the plane
        // z = const below it is faced by the side θ = π/2
        let mut seg = segment(0.05);
        seg.x_world_link = Isometry3::from_parts(Translation3::new(0.0, 0.0, 1.0), UnitQuaternion::from_euler_angles(-std::f64::consts::FRAC_PI_2, 0.0, 0.0));
        let p = Placement { contact: 1, links: vec![seg.clone()], normal: Vector3::z(), support: true };
        let (_, x) = p.point(0.5, None);
        assert!((x - Vector3::new(0.0, 0.05, 0.3)).norm() < 1e-12, "{x}");
        let r = p.replacements(0.5, None);
        assert_eq!(r[0].0, "contacts.1.point");
        assert_eq!(r[1].0, "contacts.1.plane.offset");
        // the lowest point of the cylinder's circle at s = 0.5: world z of the axis − r
        let axis_z = (seg.x_world_link * Point3::new(0.0, 0.0, 0.3)).z;
        assert!((r[1].1.as_f64().unwrap() - (axis_z - 0.05)).abs() < 1e-12, "{:?}", r[1]);
    }

    #[test]
    fn a_chain_of_links_is_walked_link_by_link() {
        let (mut l0, mut l1) = (segment(0.0), segment(0.0));
        l0.link = "l0".into();
        l1.link = "l1".into();
        let p = Placement { contact: 0, links: vec![l0, l1], normal: Vector3::z(), support: false };
        assert_eq!(p.point(0.25, None).0.link, "l0");
        assert_eq!(p.point(1.25, None).0.link, "l1");
        assert!((p.point(1.25, None).1 - Vector3::new(0.0, 0.0, 0.2)).norm() < 1e-12);
        // t = 2 (the end) is the last link's s = 1
        assert!((p.point(2.0, None).1 - Vector3::new(0.0, 0.0, 0.5)).norm() < 1e-12);
        assert_eq!(p.replacements(0.5, None).len(), 1, "no support: the plane is kept");
    }
}
