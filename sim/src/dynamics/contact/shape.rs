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

use nalgebra::Vector3;

use super::Contact;
use crate::dynamics::{Data, Model};

/// The shape of a contact on its link.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum ContactShape {
    /// The contact's point itself touches the plane (the paper's elbows).
    #[default]
    Point,
    /// A sphere of `radius` (m, > 0) centred on the contact's point: a pad, or one end of a
    /// capsule.
    Sphere { radius: f64 },
}

impl ContactShape {
    /// Its name in scenes and recordings: `point`, `sphere`.
    pub fn name(&self) -> &'static str {
        match self {
            ContactShape::Point => "point",
            ContactShape::Sphere { .. } => "sphere",
        }
    }

    /// The radius of the shape, m (0 for a point).
    pub fn radius(&self) -> f64 {
        match self {
            ContactShape::Point => 0.0,
            ContactShape::Sphere { radius } => *radius,
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
        }
    }

    /// The touching point, world frame, m. Needs `forward_kinematics`.
    pub fn touch_point(&self, data: &Data) -> Vector3<f64> {
        let c = self.plane.point.position(data);
        match self.shape {
            ContactShape::Point => c,
            ContactShape::Sphere { radius } => c - radius * self.plane.normal_world.into_inner(),
        }
    }

    /// The velocity of the body's material point at the touching point, world frame, m/s.
    /// Needs `forward_kinematics` and `forward_velocities`.
    pub fn touch_velocity(&self, data: &Data) -> Vector3<f64> {
        match (self.shape, self.plane.point.body) {
            (ContactShape::Sphere { .. }, Some(b)) => {
                let r = self.touch_point(data) - data.x_world_body[b].translation.vector;
                data.v_world[b] + data.w_world[b].cross(&r)
            }
            _ => self.plane.point.velocity(data),
        }
    }

    /// The touching point, gap, velocity and `J̇ q̇` at once. Needs `forward_kinematics` and
    /// `forward_velocities`.
    pub fn touch(&self, data: &Data) -> Touch {
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
                    bias: data.a_bias_world[b] + data.alpha_bias_world[b].cross(&(p - o)) + w.cross(&w.cross(&(c - o))),
                }
            }
            _ => Touch { point: point.position(data), gap: self.plane.position(data), velocity: point.velocity(data), bias: point.bias_acceleration(data) },
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
        let n = 4;
        let model = random_chain(n, 7);
        let plane = PointOnPlane {
            name: "pad".into(),
            point: BodyPoint { body: Some(n - 1), p_body: Vector3::new(0.1, -0.05, 0.2) },
            normal_world: Unit::new_normalize(Vector3::new(0.2, -0.1, 1.0)),
            offset: -0.3,
        };
        let c = Contact::new(plane, ContactModel::Unilateral { restitution: 0.0, friction: 0.5 }).with_shape(ContactShape::Sphere { radius: 0.07 });
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
        // the material point's own bias differs by r ω × (ω × n): far above the tolerance
        // here, so the test tells the two apart
        let _ = at(0.0, &mut data);
        let w = data.w_world[n - 1];
        let extra = 0.07 * w.cross(&w.cross(&dirs[0]));
        assert!(dirs.iter().map(|d| d.dot(&extra).abs()).fold(0.0, f64::max) > 1e-3, "the case distinguishes the two biases: {extra}");
    }
}
