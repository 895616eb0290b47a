//! Contact geometry: where a contact touches its plane, its gap, and the Jacobian and `J̇ q̇`
//! of the touching point, for each shape a contact may have ([`ContactShape`]): a point of a
//! link (the paper's elbows), or a sphere of radius r centred on a point of a link (a pad; a
//! capsule is its two end spheres, `scene/contacts.rs`).
//!
//! A sphere of centre c and radius r over the plane `n · x = d` touches it at the point of the
//! sphere farthest along −n, `p = c − r n`, with gap `g = n · c − d − r` (the signed distance of
//! the sphere from the plane; Ericson, *Real-Time Collision Detection*, 2005, §5.2.2). As the
//! sphere rolls, p moves over the body: the contact's velocity is that of the body's material
//! point at p, `v_p = v_o + ω × (p − o)` (o the body origin), so `J(q)` is the material
//! point's Jacobian at p, and `ġ = n · v_p = n · v_c` (the support point's envelope
//! property). Its bias is the derivative of that Jacobian along the motion,
//! `J̇ q̇ = a_o + α × (p − o) + ω × (ṗ − v_o)` at q̈ = 0 with the touching point's own velocity
//! `ṗ = v_c` (the plane is fixed): `a_o + α × (p − o) + ω × (ω × (c − o))` — not the
//! material point's `… + ω × (ω × (p − o))`, which differs by `r ω × (ω × n)` and would add
//! `r |ω_t|²` to g̈ (Featherstone, RBDA, 2008, §2.7 for the body-point kinematics; Pfeiffer &
//! Glocker, *Multibody Dynamics with Unilateral Contacts*, 1996, §4.2 for contact kinematics
//! on a moving contact point; Montana, "The kinematics of contact and grasp", IJRR 7(3), 1988,
//! for rolling contact). A point is the sphere with r = 0, computed by the point's own
//! formulas (so point contacts give the same bits as before shapes existed).
//!
//! A cylinder's rim is a circle of radius r about the centre c of an end face, in the plane
//! normal to the cylinder's axis a (world `a = R_b a_b`). Its point farthest along −n is
//! `p = c + r u` with `u = −m/|m|`, `m = n − (n·a) a` (n projected on the rim's plane), and the
//! gap is `g = n·c − d − r |m|` (the support point of a disk, Ericson §3.9 / van den Bergen,
//! *Collision Detection in Interactive 3D Environments*, 2004, §4.3.4). The point moves along
//! the rim as the link turns, `ṗ = v_c + r u̇` with `u̇ = −(I − û ûᵀ) ṁ / |m|`,
//! `ṁ = −(n·ȧ) a − (n·a) ȧ`, `ȧ = ω × a`; so `J̇ q̇ = a_o + α × (p − o) + ω × (ω × (c − o))
//! + r ω × u̇`, and again `ġ = n · v_p` (p minimises n·x over the rim). When the axis is
//! within [`RIM_MIN_ANGLE`] of the normal (a cylinder standing on its face) every rim point is
//! nearly lowest and u is not defined: a run refuses that state when the rim is within its
//! radius of the plane ([`check_rims`]), with the time and the angle.

use nalgebra::Vector3;

use super::Contact;
use crate::dynamics::{Data, Model};
use crate::error::DynamicsError;

/// The smallest angle, rad, between a rim's axis and the plane normal for which its lowest
/// point is taken as unique (0.5°: at that tilt the rim's lowest point is 1 % of r × 0.87
/// below the next point a quarter turn away; nearer, u turns by 1/|m| per radian of tilt).
pub const RIM_MIN_ANGLE: f64 = 0.5 * std::f64::consts::PI / 180.0;

/// The shape of a contact on its link.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum ContactShape {
    /// The contact's point itself touches the plane (the paper's elbows).
    #[default]
    Point,
    /// A sphere of `radius` (m, > 0) centred on the contact's point: a pad, or one end of a
    /// capsule.
    Sphere { radius: f64 },
    /// The rim of a cylinder's end face: a circle of `radius` (m, > 0) centred on the contact's
    /// point, normal to `axis` (a unit vector, body frame).
    Rim { radius: f64, axis: Vector3<f64> },
}

impl ContactShape {
    /// Its name in scenes and recordings: `point`, `sphere`, `rim`.
    pub fn name(&self) -> &'static str {
        match self {
            ContactShape::Point => "point",
            ContactShape::Sphere { .. } => "sphere",
            ContactShape::Rim { .. } => "rim",
        }
    }

    /// The radius of the shape, m (0 for a point).
    pub fn radius(&self) -> f64 {
        match self {
            ContactShape::Point => 0.0,
            ContactShape::Sphere { radius } | ContactShape::Rim { radius, .. } => *radius,
        }
    }
}

/// Where a contact touches its plane at a state, world frame: the touching point `p`, the gap
/// g (m), the velocity of the body's material point at p (m/s) and `J̇ q̇` of the contact
/// (m/s^2, see the module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Touch {
    pub point: Vector3<f64>,
    pub gap: f64,
    pub velocity: Vector3<f64>,
    pub bias: Vector3<f64>,
}

impl Contact {
    /// The gap g, m. Needs `forward_kinematics`.
    pub fn gap(&self, data: &Data) -> f64 {
        match self.shape {
            ContactShape::Point => self.plane.position(data),
            ContactShape::Sphere { radius } => self.plane.position(data) - radius,
            ContactShape::Rim { radius, .. } => {
                let (_, m, _) = self.rim(data);
                self.plane.position(data) - radius * m.norm()
            }
        }
    }

    /// The touching point, world frame, m. Needs `forward_kinematics`.
    pub fn touch_point(&self, data: &Data) -> Vector3<f64> {
        let c = self.plane.point.position(data);
        match self.shape {
            ContactShape::Point => c,
            ContactShape::Sphere { radius } => c - radius * self.plane.normal_world.into_inner(),
            ContactShape::Rim { radius, .. } => c + radius * self.rim(data).2,
        }
    }

    /// The velocity of the body's material point at the touching point, world frame, m/s.
    /// Needs `forward_kinematics` and `forward_velocities`.
    pub fn touch_velocity(&self, data: &Data) -> Vector3<f64> {
        match (self.shape, self.plane.point.body) {
            (ContactShape::Sphere { .. } | ContactShape::Rim { .. }, Some(b)) => {
                let r = self.touch_point(data) - data.x_world_body[b].translation.vector;
                data.v_world[b] + data.w_world[b].cross(&r)
            }
            _ => self.plane.point.velocity(data),
        }
    }

    /// A rim's axis `a` (world), `m = n − (n·a) a` and its direction `u` to the lowest point
    /// (zeros for other shapes). Needs `forward_kinematics`.
    fn rim(&self, data: &Data) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
        match (self.shape, self.plane.point.body) {
            (ContactShape::Rim { axis, .. }, Some(b)) => {
                let a = data.x_world_body[b].rotation * axis;
                let (m, u) = rim_direction(&self.plane.normal_world.into_inner(), &a);
                (a, m, u)
            }
            _ => (Vector3::zeros(), Vector3::zeros(), Vector3::zeros()),
        }
    }

    /// The touching point, gap, velocity and `J̇ q̇` at once. Needs `forward_kinematics` and
    /// `forward_velocities`.
    pub fn touch(&self, data: &Data) -> Touch {
        self.touch_with::<true>(data)
    }

    /// [`Contact::touch`] without `J̇ q̇` (`bias` zero): the point, gap and velocity by the
    /// same operations, so the same values bit for bit. For what reads only the gap and the
    /// velocities (a separated candidate's event function, `rows::contact_gaps_where`; issue 24
    /// item 2). Needs `forward_kinematics` and `forward_velocities`.
    pub fn touch_moving(&self, data: &Data) -> Touch {
        self.touch_with::<false>(data)
    }

    fn touch_with<const BIAS: bool>(&self, data: &Data) -> Touch {
        let point = &self.plane.point;
        match (self.shape, point.body) {
            (ContactShape::Sphere { radius }, Some(b)) => {
                let o = data.x_world_body[b].translation.vector;
                let c = point.position(data);
                let p = c - radius * self.plane.normal_world.into_inner();
                let w = data.w_world[b];
                Touch {
                    point: p,
                    gap: self.plane.normal_world.dot(&c) - self.plane.offset - radius,
                    velocity: data.v_world[b] + w.cross(&(p - o)),
                    bias: if BIAS { data.a_bias_world[b] + data.alpha_bias_world[b].cross(&(p - o)) + w.cross(&w.cross(&(c - o))) } else { Vector3::zeros() },
                }
            }
            (ContactShape::Rim { radius, .. }, Some(b)) => {
                let o = data.x_world_body[b].translation.vector;
                let c = point.position(data);
                let n = self.plane.normal_world.into_inner();
                let w = data.w_world[b];
                let (a, m, u) = self.rim(data);
                let s = m.norm();
                let p = c + radius * u;
                let bias = if BIAS {
                    // u̇ = −(I − û ûᵀ) ṁ / |m| = −(ṁ − u (u·ṁ)) / |m|, û = −u (zero when degenerate: refused by check_rims)
                    let ad = w.cross(&a);
                    let md = -n.dot(&ad) * a - n.dot(&a) * ad;
                    let ud = if s > 0.0 { -(md - u * u.dot(&md)) / s } else { Vector3::zeros() };
                    data.a_bias_world[b] + data.alpha_bias_world[b].cross(&(p - o)) + w.cross(&w.cross(&(c - o))) + radius * w.cross(&ud)
                } else {
                    Vector3::zeros()
                };
                Touch { point: p, gap: n.dot(&c) - self.plane.offset - radius * s, velocity: data.v_world[b] + w.cross(&(p - o)), bias }
            }
            _ => Touch {
                point: point.position(data),
                gap: self.plane.position(data),
                velocity: point.velocity(data),
                bias: if BIAS { point.bias_acceleration(data) } else { Vector3::zeros() },
            },
        }
    }

    /// `dir · J` of the contact (the material point at the touching point `p`, from
    /// [`Contact::touch`]) into the entries of `row` of the contact body's ancestor joints.
    pub fn jacobian_along<R>(&self, model: &Model, data: &Data, p: &Vector3<f64>, dir: &Vector3<f64>, row: &mut R)
    where
        R: std::ops::IndexMut<usize, Output = f64> + ?Sized,
    {
        self.plane.point.jacobian_along_at(model, data, p, dir, row);
    }
}

/// `m = n − (n·a) a` (n in the rim's plane) and the rim's direction to its lowest point,
/// `u = −m/|m|`; at |m| = 0 (the axis along n) any direction in the plane: one normal to a.
fn rim_direction(n: &Vector3<f64>, a: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let m = n - n.dot(a) * a;
    let s = m.norm();
    if s > 0.0 {
        (m, -m / s)
    } else {
        (m, a.cross(&if a.x.abs() < 0.9 { Vector3::x() } else { Vector3::y() }).normalize())
    }
}

/// Refuse a cylinder's rim that stands on its face (axis within [`RIM_MIN_ANGLE`] of the plane
/// normal) while it is within its radius of the plane: its lowest point is not unique there.
/// Needs `forward_kinematics`.
pub fn check_rims(contacts: &[Contact], data: &Data, t: f64) -> Result<(), DynamicsError> {
    for c in contacts {
        if let (ContactShape::Rim { radius, axis }, Some(b)) = (c.shape, c.plane.point.body) {
            let a = data.x_world_body[b].rotation * axis;
            let n = c.plane.normal_world.into_inner();
            let s = (n - n.dot(&a) * a).norm();
            if s < RIM_MIN_ANGLE.sin() && c.plane.position(data) - radius * s < radius {
                let angle = s.min(1.0).asin().to_degrees();
                return Err(DynamicsError::InconsistentContact {
                    t,
                    contact: c.plane.name.clone(),
                    why: format!(
                        "the cylinder rim stands on its face: its axis is {angle:.3}° from the plane's normal (under {:.1}°), so its lowest point is not unique; give the face as sphere pads or box corners, or start the cylinder tilted",
                        RIM_MIN_ANGLE.to_degrees()
                    ),
                });
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    //! The sphere's rows against finite differences along a trajectory: `ġ = J_n q̇`,
    //! `d/dt (J q̇) = J q̈ + J̇ q̇` (the touching point moving over the body), on a random
    //! chain.
    use nalgebra::{Unit, Vector3};

    use super::*;
    use crate::dynamics::constraints::PointOnPlane;
    use crate::dynamics::contact::ContactModel;
    use crate::dynamics::kinematics::{forward_kinematics, forward_velocities, BodyPoint};
    use crate::dynamics::samples::random_chain;

    #[test]
    fn a_spheres_gap_rate_and_bias_are_the_derivatives_of_its_gap_and_velocity() {
        rows_are_the_derivatives(ContactShape::Sphere { radius: 0.07 });
    }

    /// The rim's touching point moves along the rim: the same identities, and its bias differs
    /// from the material point's and from the sphere's formula (checked below).
    #[test]
    fn a_rims_gap_rate_and_bias_are_the_derivatives_of_its_gap_and_velocity() {
        rows_are_the_derivatives(ContactShape::Rim { radius: 0.07, axis: Vector3::new(0.3, -0.8, 0.5).normalize() });
    }

    fn rows_are_the_derivatives(shape: ContactShape) {
        let n = 4;
        let model = random_chain(n, 7);
        let plane = PointOnPlane {
            name: "pad".into(),
            point: BodyPoint { body: Some(n - 1), p_body: Vector3::new(0.1, -0.05, 0.2) },
            normal_world: Unit::new_normalize(Vector3::new(0.2, -0.1, 1.0)),
            offset: -0.3,
        };
        let c = Contact::new(plane, ContactModel::Unilateral { restitution: 0.0, friction: 0.5 }).with_shape(shape);
        let q0: Vec<f64> = (0..n).map(|i| 0.3 + 0.4 * i as f64).collect();
        let qd: Vec<f64> = (0..n).map(|i| 1.1 - 0.7 * i as f64).collect();
        let qdd: Vec<f64> = (0..n).map(|i| -0.5 + 0.9 * i as f64).collect();
        let mut data = Data::new(&model);
        // q(t) = q0 + qd t + ½ qdd t², q̇(t) = qd + qdd t
        let at = |t: f64, data: &mut Data| -> Touch {
            let q: Vec<f64> = (0..n).map(|i| q0[i] + qd[i] * t + 0.5 * qdd[i] * t * t).collect();
            let v: Vec<f64> = (0..n).map(|i| qd[i] + qdd[i] * t).collect();
            forward_kinematics(&model, data, &q);
            forward_velocities(&model, data, &v);
            c.touch(data)
        };
        let t0 = at(0.0, &mut data);
        let mut rows = vec![[0.0; 3]; n];
        let dirs = [c.plane.normal_world.into_inner(), c.t1, c.t2];
        for (a, dir) in dirs.iter().enumerate() {
            let mut row = vec![0.0; n];
            c.jacobian_along(&model, &data, &t0.point, dir, &mut row[..]);
            for j in 0..n {
                rows[j][a] = row[j];
            }
        }
        let h = 1e-5;
        let (tp, tm) = (at(h, &mut data), at(-h, &mut data));
        let gd = (tp.gap - tm.gap) / (2.0 * h);
        let jqd: f64 = (0..n).map(|j| rows[j][0] * qd[j]).sum();
        assert!((gd - jqd).abs() < 1e-8, "ġ = {gd} by differences, J_n q̇ = {jqd}");
        assert!((jqd - dirs[0].dot(&t0.velocity)).abs() < 1e-12);
        for (a, dir) in dirs.iter().enumerate() {
            let vd = (dir.dot(&tp.velocity) - dir.dot(&tm.velocity)) / (2.0 * h);
            let want: f64 = (0..n).map(|j| rows[j][a] * qdd[j]).sum::<f64>() + dir.dot(&t0.bias);
            assert!((vd - want).abs() < 1e-7 * (1.0 + want.abs()), "axis {a}: d/dt(J q̇) = {vd} by differences, J q̈ + J̇ q̇ = {want}");
        }
        // the material point's own bias (and for a rim, the bias without its r ω × u̇ term)
        // differs far above the tolerance here, so the test tells them apart
        let _ = at(0.0, &mut data);
        let w = data.w_world[n - 1];
        let o = data.x_world_body[n - 1].translation.vector;
        let material = data.a_bias_world[n - 1] + data.alpha_bias_world[n - 1].cross(&(t0.point - o)) + w.cross(&w.cross(&(t0.point - o)));
        let extra = t0.bias - material;
        assert!(dirs.iter().map(|d| d.dot(&extra).abs()).fold(0.0, f64::max) > 1e-3, "the case distinguishes the biases: {extra}");
        if let ContactShape::Rim { radius, .. } = shape {
            let c0 = c.plane.point.position(&data);
            let fixed = data.a_bias_world[n - 1] + data.alpha_bias_world[n - 1].cross(&(t0.point - o)) + w.cross(&w.cross(&(c0 - o)));
            assert!(dirs.iter().map(|d| d.dot(&(t0.bias - fixed)).abs()).fold(0.0, f64::max) > 1e-3, "the rim's r ω × u̇ term matters here");
            // the touching point is on the rim, lowest along −n
            assert!(((t0.point - c0).norm() - radius).abs() < 1e-12);
            assert!((c.gap(&data) - t0.gap).abs() < 1e-15 && (c.touch_point(&data) - t0.point).norm() < 1e-15);
        }
    }
}
