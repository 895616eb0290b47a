//! Spatial (6D) vector algebra in the Plücker form of Featherstone, *Rigid Body Dynamics
//! Algorithms* (RBDA, Springer 2008), ch. 2, written with 3D parts so that no 6x6 matrix is formed.
//!
//! Conventions:
//! - A motion vector is `(w, v)`: angular velocity and the linear velocity of the body-fixed point
//!   that coincides with the frame origin (RBDA §2.3). A force vector is `(n, f)`: moment about
//!   the frame origin and force (RBDA §2.4).
//! - A placement `x_parent_child: Isometry3` maps child coordinates to parent coordinates,
//!   `p_parent = R p_child + t` (the pinocchio `liMi` convention).
//! - A rigid-body inertia is stored as `(m, h = m c, I_o)`: mass, first moment and rotational
//!   inertia about the frame origin (RBDA §2.13, eq 2.63), which adds linearly.

use nalgebra::{Isometry3, Matrix3, Vector3};

/// A placement `x_parent_child` as a rotation matrix and a translation: the form the
/// recursive algorithms apply (a 3x3 product is cheaper than a quaternion rotation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Xform {
    pub rot: Matrix3<f64>,
    pub trans: Vector3<f64>,
}

impl Xform {
    pub fn identity() -> Self {
        Self { rot: Matrix3::identity(), trans: Vector3::zeros() }
    }
}

impl From<&Isometry3<f64>> for Xform {
    fn from(x: &Isometry3<f64>) -> Self {
        Self { rot: *x.rotation.to_rotation_matrix().matrix(), trans: x.translation.vector }
    }
}

/// Spatial motion vector (angular, linear), rad/s and m/s (or their rates).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Motion {
    pub w: Vector3<f64>,
    pub v: Vector3<f64>,
}

/// Spatial force vector (moment about the origin, force), N m and N.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Force {
    pub n: Vector3<f64>,
    pub f: Vector3<f64>,
}

/// Rigid-body inertia about a frame's origin (RBDA eq 2.63), kg, kg m, kg m^2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inertia {
    pub mass: f64,
    /// First moment of mass `m c`, with `c` the centre of mass in this frame.
    pub h: Vector3<f64>,
    /// Rotational inertia about the frame origin.
    pub i_o: Matrix3<f64>,
}

impl Default for Inertia {
    fn default() -> Self {
        Self::zero()
    }
}

#[inline]
fn skew(a: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

impl Motion {
    pub const ZERO: Motion = Motion { w: Vector3::new(0.0, 0.0, 0.0), v: Vector3::new(0.0, 0.0, 0.0) };

    pub fn new(w: Vector3<f64>, v: Vector3<f64>) -> Self {
        Self { w, v }
    }

    /// Express a parent-frame motion in the child frame: `X_child_parent * m` (RBDA eq 2.24).
    #[inline]
    pub fn to_child(&self, x_parent_child: &Isometry3<f64>) -> Motion {
        let r = x_parent_child.rotation;
        let t = x_parent_child.translation.vector;
        Motion { w: r.inverse_transform_vector(&self.w), v: r.inverse_transform_vector(&(self.v + self.w.cross(&t))) }
    }

    /// [`Motion::to_child`] with a matrix placement.
    #[inline]
    pub fn to_child_x(&self, x: &Xform) -> Motion {
        Motion { w: x.rot.tr_mul(&self.w), v: x.rot.tr_mul(&(self.v + self.w.cross(&x.trans))) }
    }

    /// Express a child-frame motion in the parent frame.
    #[inline]
    pub fn to_parent(&self, x_parent_child: &Isometry3<f64>) -> Motion {
        let r = x_parent_child.rotation;
        let t = x_parent_child.translation.vector;
        let w = r.transform_vector(&self.w);
        Motion { w, v: r.transform_vector(&self.v) - w.cross(&t) }
    }

    /// Spatial cross product for motions, `self x m` (RBDA eq 2.31).
    #[inline]
    pub fn cross_motion(&self, m: &Motion) -> Motion {
        Motion { w: self.w.cross(&m.w), v: self.w.cross(&m.v) + self.v.cross(&m.w) }
    }

    /// Spatial cross product for forces, `self x* f` (RBDA eq 2.32).
    #[inline]
    pub fn cross_force(&self, f: &Force) -> Force {
        Force { n: self.w.cross(&f.n) + self.v.cross(&f.f), f: self.w.cross(&f.f) }
    }

    #[inline]
    pub fn add(&self, o: &Motion) -> Motion {
        Motion { w: self.w + o.w, v: self.v + o.v }
    }

    #[inline]
    pub fn scale(&self, s: f64) -> Motion {
        Motion { w: self.w * s, v: self.v * s }
    }
}

impl Force {
    pub const ZERO: Force = Force { n: Vector3::new(0.0, 0.0, 0.0), f: Vector3::new(0.0, 0.0, 0.0) };

    /// Express a child-frame force in the parent frame: `X_child_parent^T f` (RBDA eq 2.25).
    #[inline]
    pub fn to_parent(&self, x_parent_child: &Isometry3<f64>) -> Force {
        let r = x_parent_child.rotation;
        let t = x_parent_child.translation.vector;
        let f = r.transform_vector(&self.f);
        Force { n: r.transform_vector(&self.n) + t.cross(&f), f }
    }

    /// [`Force::to_parent`] with a matrix placement.
    #[inline]
    pub fn to_parent_x(&self, x: &Xform) -> Force {
        let f = x.rot * self.f;
        Force { n: x.rot * self.n + x.trans.cross(&f), f }
    }

    #[inline]
    pub fn add(&self, o: &Force) -> Force {
        Force { n: self.n + o.n, f: self.f + o.f }
    }

    /// Power `m . f` of a force on a motion.
    #[inline]
    pub fn dot(&self, m: &Motion) -> f64 {
        self.n.dot(&m.w) + self.f.dot(&m.v)
    }
}

impl Inertia {
    pub fn zero() -> Self {
        Self { mass: 0.0, h: Vector3::zeros(), i_o: Matrix3::zeros() }
    }

    /// From mass, centre of mass `c` and rotational inertia about the centre of mass, all in
    /// this frame (parallel-axis theorem, RBDA eq 2.63).
    pub fn from_com(mass: f64, c: Vector3<f64>, i_com: Matrix3<f64>) -> Self {
        let sc = skew(&c);
        Self { mass, h: c * mass, i_o: i_com - sc * sc * mass }
    }

    /// Centre of mass in this frame (origin for a massless body).
    pub fn com(&self) -> Vector3<f64> {
        if self.mass > 0.0 {
            self.h / self.mass
        } else {
            Vector3::zeros()
        }
    }

    /// Rotational inertia about the centre of mass.
    pub fn i_com(&self) -> Matrix3<f64> {
        let c = self.com();
        let sc = skew(&c);
        self.i_o + sc * sc * self.mass
    }

    /// Momentum `I m` (RBDA eq 2.63 applied to a motion).
    #[inline]
    pub fn mul(&self, m: &Motion) -> Force {
        Force { n: self.i_o * m.w + self.h.cross(&m.v), f: m.v * self.mass - self.h.cross(&m.w) }
    }

    /// Express a child-frame inertia in the parent frame, `X^T I X` (RBDA eq 2.66).
    pub fn to_parent(&self, x_parent_child: &Isometry3<f64>) -> Inertia {
        let r = x_parent_child.rotation.to_rotation_matrix();
        let p = x_parent_child.translation.vector;
        let rh = r * self.h;
        let sp = skew(&p);
        let srh = skew(&rh);
        Inertia {
            mass: self.mass,
            h: rh + p * self.mass,
            i_o: r * self.i_o * r.transpose() - srh * sp - sp * srh - sp * sp * self.mass,
        }
    }

    /// [`Inertia::to_parent`] with a matrix placement, the skew products of RBDA eq 2.66 written
    /// out with `[a]×[b]× = b aᵀ − (a·b) 1`: with `R h` and the translation `p`,
    /// `I_o' = R I_o Rᵀ + (2 (R h)·p + m p·p) 1 − p (R h)ᵀ − (R h) pᵀ − m p pᵀ`
    /// (two 3x3 products instead of five; the CRBA's composite inertias use it).
    #[inline]
    pub fn to_parent_x(&self, x: &Xform) -> Inertia {
        let r = &x.rot;
        let p = x.trans;
        let m = self.mass;
        let rh = r * self.h;
        let mut i_o = r * self.i_o * r.transpose();
        let s = 2.0 * rh.dot(&p) + m * p.dot(&p);
        for c in 0..3 {
            for k in 0..3 {
                i_o[(k, c)] -= p[k] * rh[c] + rh[k] * p[c] + m * p[k] * p[c];
            }
            i_o[(c, c)] += s;
        }
        Inertia { mass: m, h: rh + p * m, i_o }
    }

    /// [`Inertia::to_parent_x`] with a pure rotation `R` (the origin kept): `h' = R h`,
    /// `I_o' = R I_o Rᵀ`.
    #[inline]
    pub fn rotated(&self, r: &Matrix3<f64>) -> Inertia {
        Inertia { mass: self.mass, h: r * self.h, i_o: r * self.i_o * r.transpose() }
    }

    /// [`Inertia::to_parent_x`] with a pure translation: the same inertia about a point `p`
    /// away, axes kept (`p` is this frame's origin in the new one; RBDA eq 2.66 with R = 1):
    /// `h' = h + m p`, `I_o' = I_o + (2 h·p + m p·p) 1 − p hᵀ − h pᵀ − m p pᵀ`.
    #[inline]
    pub fn translated(&self, p: &Vector3<f64>) -> Inertia {
        let (m, h) = (self.mass, self.h);
        let mut i_o = self.i_o;
        let s = 2.0 * h.dot(p) + m * p.dot(p);
        for c in 0..3 {
            for k in 0..3 {
                i_o[(k, c)] -= p[k] * h[c] + h[k] * p[c] + m * p[k] * p[c];
            }
            i_o[(c, c)] += s;
        }
        Inertia { mass: m, h: h + p * m, i_o }
    }

    #[inline]
    pub fn add(&self, o: &Inertia) -> Inertia {
        Inertia { mass: self.mass + o.mass, h: self.h + o.h, i_o: self.i_o + o.i_o }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion};

    fn placement() -> Isometry3<f64> {
        Isometry3::from_parts(
            Translation3::new(0.3, -0.2, 0.5),
            UnitQuaternion::from_euler_angles(0.3, -1.1, 0.7),
        )
    }

    /// Power is frame invariant: (X f) . (X m) = f . m  (RBDA eq 2.26), to 1e-14.
    #[test]
    fn power_is_invariant_under_change_of_frame() {
        let x = placement();
        let m = Motion::new(Vector3::new(0.1, 2.0, -0.3), Vector3::new(1.0, -0.5, 0.25));
        let f = Force { n: Vector3::new(0.4, 0.2, -1.0), f: Vector3::new(-2.0, 0.3, 0.9) };
        let m_parent = m.to_parent(&x);
        let f_parent = f.to_parent(&x);
        assert!((f_parent.dot(&m_parent) - f.dot(&m)).abs() < 1e-14);
        let back = m_parent.to_child(&x);
        assert!((back.w - m.w).norm() < 1e-15 && (back.v - m.v).norm() < 1e-15);
    }

    /// The matrix-placement forms equal the isometry forms (1e-15).
    #[test]
    fn matrix_placements_match_isometries() {
        let x = placement();
        let xm = Xform::from(&x);
        let m = Motion::new(Vector3::new(0.1, 2.0, -0.3), Vector3::new(1.0, -0.5, 0.25));
        let f = Force { n: Vector3::new(0.4, 0.2, -1.0), f: Vector3::new(-2.0, 0.3, 0.9) };
        let i = Inertia::from_com(0.7, Vector3::new(0.01, 0.02, 0.15), Matrix3::new(0.003, 0.0001, 0.0, 0.0001, 0.002, 0.0, 0.0, 0.0, 0.001));
        let (a, b) = (m.to_child(&x), m.to_child_x(&xm));
        assert!((a.w - b.w).norm() < 1e-15 && (a.v - b.v).norm() < 1e-15);
        let (a, b) = (f.to_parent(&x), f.to_parent_x(&xm));
        assert!((a.n - b.n).norm() < 1e-15 && (a.f - b.f).norm() < 1e-15);
        let (a, b) = (i.to_parent(&x), i.to_parent_x(&xm));
        assert!((a.i_o - b.i_o).norm() < 1e-15 && (a.h - b.h).norm() < 1e-15);
    }

    /// A rotation then a translation equals the whole placement (1e-15): the world-aligned
    /// CRBA's two steps are `to_parent_x` split in two.
    #[test]
    fn rotation_then_translation_is_the_placement() {
        let x = placement();
        let xm = Xform::from(&x);
        let i = Inertia::from_com(0.7, Vector3::new(0.01, 0.02, 0.15), Matrix3::new(0.003, 0.0001, 0.0, 0.0001, 0.002, 0.0, 0.0, 0.0, 0.001));
        let whole = i.to_parent_x(&xm);
        let split = i.rotated(&xm.rot).translated(&xm.trans);
        assert!((whole.i_o - split.i_o).norm() < 1e-15 && (whole.h - split.h).norm() < 1e-15 && whole.mass == split.mass);
        let rot_only = i.to_parent_x(&Xform { rot: xm.rot, trans: Vector3::zeros() });
        assert!((rot_only.i_o - i.rotated(&xm.rot).i_o).norm() < 1e-15);
        // the translated inertia about the new origin has the same I_com and a moved centre
        let moved = i.translated(&xm.trans);
        assert!((moved.com() - (i.com() + xm.trans)).norm() < 1e-15);
        assert!((moved.i_com() - i.i_com()).norm() < 1e-15);
    }

    /// Inertia transform agrees with transforming momentum: X^T I X m = X^T (I (X m)), to 1e-14.
    #[test]
    fn inertia_transform_matches_momentum_transform() {
        let x = placement();
        let i_child = Inertia::from_com(
            0.7,
            Vector3::new(0.01, 0.02, 0.15),
            Matrix3::new(0.003, 0.0001, 0.0, 0.0001, 0.002, 0.0, 0.0, 0.0, 0.001),
        );
        let m_parent = Motion::new(Vector3::new(0.3, -0.1, 0.8), Vector3::new(0.5, 0.4, -0.6));
        let direct = i_child.to_parent(&x).mul(&m_parent);
        let via_child = i_child.mul(&m_parent.to_child(&x)).to_parent(&x);
        assert!((direct.n - via_child.n).norm() < 1e-14);
        assert!((direct.f - via_child.f).norm() < 1e-14);
        // the centre of mass goes with the placement and I_com turns with the rotation
        let moved = i_child.to_parent(&x);
        assert!((moved.com() - x.transform_point(&i_child.com().into()).coords).norm() < 1e-15);
        let r = x.rotation.to_rotation_matrix();
        assert!((moved.i_com() - r * i_child.i_com() * r.transpose()).norm() < 1e-15);
    }
}
