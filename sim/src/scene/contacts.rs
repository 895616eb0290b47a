//! The scene's contacts: each `contacts[i]` with its model (absent = the paper's bilateral
//! constraint), the `table` construct (a plane under named points, each a unilateral contact by
//! default that belongs to every run), and the `events` settings. Errors name
//! `contacts[i].field` (or `table.field`) and the value.

use nalgebra::{Isometry3, Point3, Translation3, Unit, UnitQuaternion, Vector3};

use super::ctx::{non_negative, positive, Ctx};
use super::spec::{LawKeys, PlaneSpec, PointSpec, SceneSpec, ShapeSpec, TableSpec};
use super::INITIAL_CONSTRAINT_TOL;
use crate::dynamics::constraints::PointOnPlane;
use crate::dynamics::kinematics::BodyPoint;
use crate::dynamics::urdf::{self, UrdfGeometry};
use crate::dynamics::contact::{Contact, ContactModel, ContactSettings, ContactShape};
use crate::dynamics::{Data, Model};
use crate::error::{short, SceneError};

/// The model of a contact from its keys; `default` when `model` is absent.
fn contact_model(c: &Ctx, f: &str, k: LawKeys, default: &str) -> Result<ContactModel, SceneError> {
    let model = k.model.unwrap_or(default);
    let given = [
        ("restitution", k.restitution),
        ("friction", k.friction),
        ("stiffness", k.stiffness),
        ("damping", k.damping),
        ("slip_velocity", k.slip_velocity),
    ];
    let allowed: &[&str] = match model {
        "bilateral" => &[],
        "unilateral" => &["restitution", "friction"],
        "compliant" => &["friction", "stiffness", "damping", "slip_velocity"],
        other => {
            return Err(c.err(format!("{f}.model"), other, "unknown contact model: use \"bilateral\", \"unilateral\" or \"compliant\""));
        }
    };
    for (key, v) in given {
        if let Some(v) = v {
            if !allowed.contains(&key) {
                return Err(c.err(format!("{f}.{key}"), short(v), format!("does not belong to the {model} model (its keys: {})", if allowed.is_empty() { "none".into() } else { allowed.join(", ") })));
            }
        }
    }
    let friction = c.number(&format!("{f}.friction"), k.friction.unwrap_or(0.0), non_negative, "must be >= 0")?;
    Ok(match model {
        "bilateral" => ContactModel::Bilateral,
        "unilateral" => {
            let restitution = c.number(&format!("{f}.restitution"), k.restitution.unwrap_or(0.0), |x| (0.0..=1.0).contains(&x), "must be in [0, 1]")?;
            ContactModel::Unilateral { restitution, friction }
        }
        _ => {
            let Some(stiffness) = k.stiffness else {
                return Err(c.err(format!("{f}.stiffness"), "(absent)", "a compliant contact needs a stiffness, N/m (> 0)"));
            };
            let stiffness = c.number(&format!("{f}.stiffness"), stiffness, positive, "must be > 0 N/m")?;
            let damping = c.number(&format!("{f}.damping"), k.damping.unwrap_or(0.0), non_negative, "must be >= 0 N s/m")?;
            let slip_velocity = c.number(&format!("{f}.slip_velocity"), k.slip_velocity.unwrap_or(1e-3), positive, "must be > 0 m/s")?;
            ContactModel::Compliant { stiffness, damping, friction, slip_velocity }
        }
    })
}

fn plane(c: &Ctx, f: &str, name: &str, model: &Model, point: &PointSpec, plane: &PlaneSpec) -> Result<PointOnPlane, SceneError> {
    let point = c.point(&format!("{f}.point"), model, point)?;
    let n = c.vec3(&format!("{f}.plane.normal"), plane.normal)?;
    if n.norm() < 1e-12 {
        return Err(c.err(format!("{f}.plane.normal"), format!("{:?}", plane.normal), "must be non-zero"));
    }
    let offset = c.number(&format!("{f}.plane.offset"), plane.offset, |_| true, "")?;
    if point.body.is_none() {
        return Err(c.err(format!("{f}.point"), name, "is fixed to the base: it cannot be constrained"));
    }
    Ok(PointOnPlane { name: name.to_string(), point, normal_world: Unit::new_normalize(n), offset })
}

/// The contacts one spec'd contact becomes, each `(name, centre on its plane, shape)`: one
/// (a point, or a sphere centred on it), or two spheres for a capsule (`<name>/0` at the point,
/// `<name>/1` at `to`; `capsule_ok` only for the table's points). Errors name `{f}.shape.*`.
fn shaped(c: &Ctx, f: &str, model: &Model, p: PointOnPlane, m: ContactModel, shape: Option<&ShapeSpec>, capsule_ok: bool) -> Result<Vec<(PointOnPlane, ContactShape)>, SceneError> {
    let Some(shape) = shape else { return Ok(vec![(p, ContactShape::Point)]) };
    let kind = match shape {
        ShapeSpec::Sphere { .. } => "sphere",
        ShapeSpec::Capsule { .. } => "capsule",
    };
    if m == ContactModel::Bilateral {
        return Err(c.err(
            format!("{f}.shape.kind"),
            kind,
            "a bilateral contact holds its point on the plane without friction, so a shape changes nothing but the offset: give the sphere's centre as the point and move plane.offset by the radius, or make the contact unilateral or compliant",
        ));
    }
    let radius = |r: f64| c.number(&format!("{f}.shape.radius"), r, |x| x > 0.0 && x <= 10.0, "must be in (0, 10] m");
    match shape {
        ShapeSpec::Sphere { radius: r } => Ok(vec![(p, ContactShape::Sphere { radius: radius(*r)? })]),
        ShapeSpec::Capsule { radius: r, to } => {
            if !capsule_ok {
                return Err(c.err(format!("{f}.shape.kind"), kind, "a capsule is two contacts (its end spheres): give it under table.points, or write two sphere contacts"));
            }
            let r = radius(*r)?;
            let end = c.point(&format!("{f}.shape.to"), model, to)?;
            if end.body != p.point.body {
                return Err(c.err(format!("{f}.shape.to"), to.link.as_deref().or(to.joint.as_deref()).unwrap_or(""), "must be a point of the same link as the contact's point (a capsule is rigid)"));
            }
            if (end.p_body - p.point.p_body).norm() < 1e-9 {
                return Err(c.err(format!("{f}.shape.to"), format!("{:?}", to.offset), "is the contact's point itself: a capsule of zero length is a sphere (kind \"sphere\")"));
            }
            let a = PointOnPlane { name: format!("{}/0", p.name), ..p.clone() };
            let b = PointOnPlane { name: format!("{}/1", p.name), point: end, ..p };
            Ok(vec![(a, ContactShape::Sphere { radius: r }), (b, ContactShape::Sphere { radius: r })])
        }
    }
}

/// The initial state against a contact: bilateral ones must hold (C = 0, Ċ = 0, the paper's
/// check); a unilateral one must not start inside the plane (g0 ≥ −gap_tol).
fn check_initial(c: &Ctx, f: &str, contact: &Contact, data: &Data, gap_tol: f64) -> Result<(), SceneError> {
    let p = &contact.plane;
    let (pos, vel) = (contact.gap(data), p.velocity(data));
    match contact.model {
        ContactModel::Bilateral => {
            if pos.abs() > INITIAL_CONSTRAINT_TOL || vel.abs() > INITIAL_CONSTRAINT_TOL {
                return Err(c.err(
                    f.to_string(),
                    &p.name,
                    format!(
                        "the initial state violates this contact: C(q0) = {pos:.3e} m, C'(q0, qd0) = {vel:.3e} m/s (tolerance {INITIAL_CONSTRAINT_TOL:e}); move initial.q onto the plane or drop the contact"
                    ),
                ));
            }
        }
        ContactModel::Unilateral { .. } => {
            if pos < -gap_tol {
                return Err(c.err(
                    f.to_string(),
                    &p.name,
                    format!("the {} starts inside the plane: gap g(q0) = {pos:.3e} m < -{gap_tol:e} m; move initial.q or the plane", contact.shape.name()),
                ));
            }
        }
        ContactModel::Compliant { .. } => {}
    }
    crate::dynamics::contact::shape::check_rims(std::slice::from_ref(contact), data, 0.0).map_err(|e| c.err(f.to_string(), &p.name, format!("at the initial state: {e}")))?;
    Ok(())
}

/// The table's candidate contacts from the URDF `<collision>` shapes of the links named in
/// `table.from_collisions` (see its doc in `spec_contacts.rs`), each `(centre on the table's
/// plane, shape)`. Errors name `table.from_collisions[i]`, `table.cylinders` and the links that
/// have no usable shape.
fn collision_contacts(c: &Ctx, t: &TableSpec, model: &Model, urdf_xml: &str, m: ContactModel, normal: Unit<Vector3<f64>>, offset: f64) -> Result<Vec<(PointOnPlane, ContactShape)>, SceneError> {
    if t.from_collisions.is_empty() {
        if let Some(v) = &t.cylinders {
            return Err(c.err("table.cylinders", v, "applies to the cylinders of table.from_collisions, which names no link"));
        }
        return Ok(Vec::new());
    }
    let capsules = match t.cylinders.as_deref() {
        None | Some("rims") => false,
        Some("capsule") => true,
        Some(other) => return Err(c.err("table.cylinders", other, "unknown: use \"rims\" (the cylinder's two rim circles) or \"capsule\" (two end spheres of its radius)")),
    };
    if m == ContactModel::Bilateral {
        return Err(c.err("table.from_collisions", t.from_collisions.join(", "), "a bilateral table holds each contact on the plane: collision shapes give several candidate contacts, of which only some touch; make the table unilateral or compliant"));
    }
    let doc = urdf::parse(urdf_xml, "the URDF").map_err(|e| c.err("urdf", "", e.to_string()))?;
    let mut out = Vec::new();
    let mut bare = Vec::new();
    for (i, link) in t.from_collisions.iter().enumerate() {
        let f = format!("table.from_collisions[{i}]");
        let Some(frame) = model.frame(link) else {
            return Err(c.err(f, link, format!("no such link in the URDF (links: {})", super::ctx::names(model.frames.iter().map(|f| &f.name)))));
        };
        if t.from_collisions[..i].contains(link) {
            return Err(c.err(f, link, "is named twice"));
        }
        let Some(body) = frame.body else {
            return Err(c.err(f, link, "is fixed to the base: its shapes cannot move onto the table"));
        };
        let cols: Vec<_> = doc.collisions.iter().filter(|k| &k.link == link).collect();
        let mut any = false;
        for (k, col) in cols.iter().enumerate() {
            let (xyz, rpy) = (col.origin.xyz, col.origin.rpy);
            // the collision frame in the body frame
            let x = frame.x_body_frame * Isometry3::from_parts(Translation3::new(xyz[0], xyz[1], xyz[2]), UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]));
            let at = |p: Vector3<f64>| BodyPoint { body: Some(body), p_body: (x * Point3::from(p)).coords };
            let plane = |name: String, p: Vector3<f64>| PointOnPlane { name, point: at(p), normal_world: normal, offset };
            let name = format!("{link}/c{k}");
            match col.geometry {
                Some(UrdfGeometry::Sphere { radius }) => out.push((plane(name, Vector3::zeros()), ContactShape::Sphere { radius })),
                Some(UrdfGeometry::Box { size }) => {
                    for j in 0..8 {
                        let s = |b: usize, e: f64| if j >> b & 1 == 1 { 0.5 * e } else { -0.5 * e };
                        out.push((plane(format!("{name}/{j}"), Vector3::new(s(0, size[0]), s(1, size[1]), s(2, size[2]))), ContactShape::Point));
                    }
                }
                Some(UrdfGeometry::Cylinder { radius, length }) if !capsules => {
                    let axis = x.rotation * Vector3::z();
                    for (j, z) in [-0.5 * length, 0.5 * length].into_iter().enumerate() {
                        out.push((plane(format!("{name}/{j}"), Vector3::new(0.0, 0.0, z)), ContactShape::Rim { radius, axis }));
                    }
                }
                Some(UrdfGeometry::Cylinder { radius, length } | UrdfGeometry::Capsule { radius, length }) => {
                    for (j, z) in [-0.5 * length, 0.5 * length].into_iter().enumerate() {
                        out.push((plane(format!("{name}/{j}"), Vector3::new(0.0, 0.0, z)), ContactShape::Sphere { radius }));
                    }
                }
                Some(UrdfGeometry::Mesh) | None => continue,
            }
            any = true;
        }
        if !any {
            bare.push(if cols.is_empty() { format!("{link} (no <collision>)") } else { format!("{link} ({} <collision> of meshes only)", cols.len()) });
        }
    }
    if !bare.is_empty() {
        return Err(c.err(
            "table.from_collisions",
            t.from_collisions.join(", "),
            format!("these links have no <collision> sphere, cylinder, capsule or box to put on the table: {}; name other links, or give their points under table.points", bare.join(", ")),
        ));
    }
    Ok(out)
}

/// Every contact of the scene (the `contacts`, then the table's points) as planes and as
/// contacts with their models, the indices of the table's contacts (part of every run), and
/// the event settings. `data` holds the kinematics and velocities at (q0, q̇0).
pub(super) fn build_contacts(
    c: &Ctx,
    spec: &SceneSpec,
    model: &Model,
    data: &Data,
    urdf_xml: &str,
) -> Result<(Vec<PointOnPlane>, Vec<Contact>, Vec<usize>, ContactSettings), SceneError> {
    let mut settings = ContactSettings::default();
    if let Some(ev) = &spec.events {
        if let Some(x) = ev.time_tolerance {
            settings.time_tol = c.number("events.time_tolerance", x, |x| x > 0.0 && x <= 1e-3, "must be in (0, 1e-3] s")?;
        }
        if let Some(x) = ev.rest_velocity {
            settings.rest_velocity = c.number("events.rest_velocity", x, non_negative, "must be >= 0 m/s")?;
        }
        if let Some(x) = ev.max_events {
            if x == 0 {
                return Err(c.err("events.max_events", x, "must be >= 1"));
            }
            settings.max_events = x;
        }
        if let Some(x) = ev.max_events_at_one_time {
            let (lo, hi) = (2, crate::dynamics::contact::MAX_EVENTS_AT_ONE_TIME_LIMIT);
            if !(lo..=hi).contains(&x) {
                return Err(c.err("events.max_events_at_one_time", x, format!("must be in [{lo}, {hi}]")));
            }
            settings.max_events_at_one_time = x;
        }
    }
    let mut planes: Vec<PointOnPlane> = Vec::new();
    let mut contacts: Vec<Contact> = Vec::new();
    let mut table_idx = Vec::new();
    let mut push = |f: &str, p: PointOnPlane, m: ContactModel, shape: ContactShape| -> Result<(), SceneError> {
        if planes.iter().any(|x| x.name == p.name) {
            return Err(c.err(format!("{f}.name"), &p.name, "is used twice"));
        }
        let contact = Contact::new(p.clone(), m).with_shape(shape);
        check_initial(c, f, &contact, data, settings.gap_tol)?;
        planes.push(p);
        contacts.push(contact);
        Ok(())
    };
    for (i, cs) in spec.contacts.iter().enumerate() {
        let f = format!("contacts[{i}]");
        let m = contact_model(c, &f, cs.law(), "bilateral")?;
        let p = plane(c, &f, &cs.name, model, &cs.point, &cs.plane)?;
        for (p, shape) in shaped(c, &f, model, p, m, cs.shape.as_ref(), false)? {
            push(&f, p, m, shape)?;
        }
    }
    if let Some(t) = &spec.table {
        let m = contact_model(c, "table", t.law(), "unilateral")?;
        if t.points.is_empty() && t.from_collisions.is_empty() {
            return Err(c.err("table.points", "[]", "needs at least one point (or links under table.from_collisions)"));
        }
        // one contact per `contacts[i]` (a capsule is refused there)
        let mut n_contacts = spec.contacts.len();
        for (i, tp) in t.points.iter().enumerate() {
            let f = format!("table.points[{i}]");
            let p = plane(c, &f, &tp.name, model, &tp.point, &t.plane)?;
            for (p, shape) in shaped(c, &f, model, p, m, tp.shape.as_ref(), true)? {
                push(&f, p, m, shape)?;
                table_idx.push(n_contacts);
                n_contacts += 1;
            }
        }
        let n = c.vec3("table.plane.normal", t.plane.normal)?;
        if n.norm() < 1e-12 {
            return Err(c.err("table.plane.normal", format!("{:?}", t.plane.normal), "must be non-zero"));
        }
        for (p, shape) in collision_contacts(c, t, model, urdf_xml, m, Unit::new_normalize(n), t.plane.offset)? {
            let link = p.name.split('/').next().unwrap_or_default().to_string();
            let i = t.from_collisions.iter().position(|l| *l == link).unwrap_or(0);
            push(&format!("table.from_collisions[{i}]"), p, m, shape)?;
            table_idx.push(n_contacts);
            n_contacts += 1;
        }
    }
    Ok((planes, contacts, table_idx, settings))
}
