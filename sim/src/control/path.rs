//! Hand paths in the world frame (m, s) with their exact first and second time derivatives.
//!
//! - [`CirclePath`]: a circle in any plane, `r(t) = c + ρ (cos φ u + sin φ v)`,
//!   `φ(t) = φ_0 + σ 2π t / T`, with n the plane's unit normal, u the in-plane zero-angle axis
//!   and v = n × u; σ = +1 turns counter-clockwise about n (right-hand rule), −1 clockwise.
//!   u is the given `zero_axis` projected onto the plane, else world +x projected onto the
//!   plane, or world +y when n is along ±x (|n × x| < 1e-6). For n = +z, u = +x
//!   and v = +y: the paper's horizontal circle. `ṙ = ρ φ̇ (−sin φ u + cos φ v)`,
//!   `r̈ = −ρ φ̇² (cos φ u + sin φ v)`.
//! - Line segments through points p_k at times t_k, each run rest to rest with the minimum-jerk
//!   time scaling `p_k + (p_{k+1} − p_k) s(τ)` ([`super::spline::min_jerk`]; Flash & Hogan 1985).
//! - Waypoints: a clamped C² cubic spline per coordinate, at rest at the first and last point
//!   ([`super::spline::CubicSpline`]).
//!
//! Before the first and after the last time, the line and waypoint paths hold their end point.

use nalgebra::Vector3;

use super::spline::{CubicSpline, MinJerk};

#[derive(Clone, Debug, PartialEq)]
pub struct CirclePath {
    /// m, world frame.
    pub center: Vector3<f64>,
    /// Unit normal n, world frame.
    pub normal: Vector3<f64>,
    /// In-plane unit axis u at φ = 0; v = n × u.
    pub u: Vector3<f64>,
    pub v: Vector3<f64>,
    /// m.
    pub radius: f64,
    /// s per turn.
    pub period: f64,
    /// φ_0, rad.
    pub phase: f64,
    /// +1 counter-clockwise about n, −1 clockwise.
    pub direction: f64,
}

impl CirclePath {
    /// The circle of `center`, unit-normalised `normal` (non-zero), optional zero-angle axis
    /// (must not be parallel to the normal). `Err` says which is degenerate.
    pub fn new(
        center: Vector3<f64>,
        normal: Vector3<f64>,
        zero_axis: Option<Vector3<f64>>,
        radius: f64,
        period: f64,
        phase: f64,
        direction: f64,
    ) -> Result<Self, String> {
        let nn = normal.norm();
        if !(nn > 1e-12) {
            return Err("normal: must be non-zero".into());
        }
        let n = normal / nn;
        let e = match zero_axis {
            Some(a) => a,
            None if n.cross(&Vector3::x()).norm() < 1e-6 => Vector3::y(),
            None => Vector3::x(),
        };
        let u = e - n * n.dot(&e);
        if !(u.norm() > 1e-9 * e.norm().max(1e-300)) {
            return Err("zero_axis: must not be parallel to the normal".into());
        }
        let u = u.normalize();
        Ok(Self { center, normal: n, u, v: n.cross(&u), radius, period, phase, direction })
    }

    fn rate(&self) -> f64 {
        self.direction * 2.0 * std::f64::consts::PI / self.period
    }

    /// r, ṙ, r̈ at t.
    pub fn eval(&self, t: f64) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
        let w = self.rate();
        let (s, c) = (self.phase + w * t).sin_cos();
        let radial = self.u * c + self.v * s;
        let tangent = self.v * c - self.u * s;
        (self.center + radial * self.radius, tangent * (self.radius * w), -radial * (self.radius * w * w))
    }
}

/// A hand path.
#[derive(Clone, Debug, PartialEq)]
pub enum CartesianPath {
    Circle(CirclePath),
    Lines(MinJerk),
    Waypoints(CubicSpline),
}

impl CartesianPath {
    /// Line segments through `points` at `times` (strictly increasing), rest to rest.
    pub fn lines(points: &[[f64; 3]], times: &[f64]) -> Result<Self, String> {
        Ok(CartesianPath::Lines(MinJerk::new(times.to_vec(), points.iter().flatten().copied().collect(), 3)?))
    }

    /// The C² cubic spline through `points` at `times`, at rest at both ends.
    pub fn waypoints(points: &[[f64; 3]], times: &[f64]) -> Result<Self, String> {
        Ok(CartesianPath::Waypoints(CubicSpline::at_rest(times.to_vec(), points.iter().flatten().copied().collect(), 3)?))
    }

    /// r, ṙ, r̈ at t (m, m/s, m/s²), world frame.
    pub fn eval(&self, t: f64) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
        let (mut y, mut yd, mut ydd) = ([0.0; 3], [0.0; 3], [0.0; 3]);
        match self {
            CartesianPath::Circle(c) => return c.eval(t),
            CartesianPath::Lines(s) => s.eval(t, &mut y, &mut yd, &mut ydd),
            CartesianPath::Waypoints(s) => s.eval(t, &mut y, &mut yd, &mut ydd),
        }
        (Vector3::from(y), Vector3::from(yd), Vector3::from(ydd))
    }

    /// r(t), m.
    pub fn position(&self, t: f64) -> Vector3<f64> {
        self.eval(t).0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Central-difference cross-check of ṙ and r̈ (h = 1e-5 s; tolerances 1e-8 m/s, 1e-5 m/s²).
    fn check_derivatives(p: &CartesianPath, ts: &[f64]) {
        let h = 1e-5;
        for &t in ts {
            let (_, v, a) = p.eval(t);
            let (rp, vp, _) = p.eval(t + h);
            let (rm, vm, _) = p.eval(t - h);
            assert!(((rp - rm) / (2.0 * h) - v).norm() < 1e-8, "t = {t}: v");
            assert!(((vp - vm) / (2.0 * h) - a).norm() < 1e-5, "t = {t}: a");
        }
    }

    /// A circle in the tilted plane n ∝ (1, 1, 1): every point is at distance ρ from c and in
    /// the plane (1e-15 m scale), φ = 0 lies along x projected onto the plane, it turns
    /// counter-clockwise about n, closes after one period, and ṙ, r̈ are the exact derivatives.
    #[test]
    fn circle_in_a_tilted_plane() {
        let n = Vector3::new(1.0, 1.0, 1.0);
        let c = CirclePath::new(Vector3::new(0.3, -0.2, 0.5), n, None, 0.15, 2.0, 0.0, 1.0).unwrap();
        let nu = n.normalize();
        let ux = (Vector3::x() - nu * nu.x).normalize();
        assert!((c.eval(0.0).0 - (c.center + ux * 0.15)).norm() < 1e-15);
        for k in 0..40 {
            let t = k as f64 * 0.05;
            let (r, v, a) = c.eval(t);
            assert!(((r - c.center).norm() - 0.15).abs() < 1e-15);
            assert!((r - c.center).dot(&nu).abs() < 1e-15);
            assert!((r - c.center).cross(&v).dot(&nu) > 0.0);
            // centripetal: r̈ = −(2π/T)² (r − c)
            assert!((a + (r - c.center) * (std::f64::consts::PI).powi(2)).norm() < 1e-13);
        }
        assert!((c.eval(2.0).0 - c.eval(0.0).0).norm() < 1e-15);
        check_derivatives(&CartesianPath::Circle(c), &[0.0, 0.37, 1.2, 1.99]);
        // the horizontal circle: u = x, v = y (the paper's convention)
        let h = CirclePath::new(Vector3::zeros(), Vector3::z(), None, 1.0, 1.0, 0.0, 1.0).unwrap();
        assert_eq!((h.u, h.v), (Vector3::x(), Vector3::y()));
        // normal along x: u = y; a zero axis along the normal is refused
        let x = CirclePath::new(Vector3::zeros(), -Vector3::x(), None, 1.0, 1.0, 0.0, -1.0).unwrap();
        assert_eq!(x.u, Vector3::y());
        assert!(CirclePath::new(Vector3::zeros(), Vector3::z(), Some(Vector3::z() * 2.0), 1.0, 1.0, 0.0, 1.0).is_err());
    }

    /// Lines: through each point at its time, at rest there, straight between, derivatives exact.
    #[test]
    fn lines_and_waypoints() {
        let pts = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 2.0, 0.5]];
        let l = CartesianPath::lines(&pts, &[0.0, 1.0, 3.0]).unwrap();
        for (p, t) in pts.iter().zip([0.0, 1.0, 3.0]) {
            let (r, v, a) = l.eval(t);
            assert!((r - Vector3::from(*p)).norm() < 1e-15 && v.norm() < 1e-14 && a.norm() < 1e-12);
        }
        // on the second segment the point stays on the line from p1 to p2
        let (r, _, _) = l.eval(2.2);
        let d = Vector3::new(0.0, 2.0, 0.5);
        assert!((r - Vector3::x()).cross(&d).norm() < 1e-15);
        check_derivatives(&l, &[0.3, 1.5, 2.9]);
        let w = CartesianPath::waypoints(&pts, &[0.0, 1.0, 3.0]).unwrap();
        assert!((w.position(1.0) - Vector3::x()).norm() < 1e-15);
        check_derivatives(&w, &[0.3, 1.5, 2.9]);
        assert!(CartesianPath::lines(&pts, &[0.0, 1.0, 1.0]).is_err());
    }
}
