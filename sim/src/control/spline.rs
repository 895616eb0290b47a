//! Interpolating splines in time with exact derivatives, several channels sharing one knot
//! vector (a joint-space trajectory: one channel per joint).
//!
//! - [`CubicSpline`]: the C² cubic spline through `(t_k, y_k)` with clamped ends (C² between
//!   the first and the last knot; outside them the end value is held, so where the run goes on
//!   past the last waypoint q̈_d steps from the end curvature to 0: use `quintic` for a target
//!   that comes to rest smoothly)
//!   `S'(t_0) = v_0`, `S'(t_n) = v_n` (Burden & Faires, *Numerical Analysis*, 9th ed., §3.5,
//!   Alg. 3.5; de Boor, *A Practical Guide to Splines*, ch. IV). The unknowns are the second
//!   derivatives M_k at the knots, from the tridiagonal system
//!   `h_{k−1} M_{k−1} + 2 (h_{k−1} + h_k) M_k + h_k M_{k+1} = 6 (Δ_k − Δ_{k−1})`,
//!   `2 h_0 M_0 + h_0 M_1 = 6 (Δ_0 − v_0)`, `h_{n−1} M_{n−1} + 2 h_{n−1} M_n = 6 (v_n − Δ_{n−1})`,
//!   Δ_k = (y_{k+1} − y_k) / h_k, solved by the Thomas algorithm (the matrix is strictly
//!   diagonally dominant). On `[t_k, t_{k+1}]`, with a = (t_{k+1} − t)/h, b = 1 − a:
//!   `S = a y_k + b y_{k+1} + ((a³ − a) M_k + (b³ − b) M_{k+1}) h²/6`,
//!   `S' = Δ_k − (3a² − 1) h M_k / 6 + (3b² − 1) h M_{k+1} / 6`, `S'' = a M_k + b M_{k+1}`.
//!   A cubic polynomial with its own end slopes is reproduced exactly; for smooth f the error
//!   is ≤ 5/384 h⁴ max|f⁗| (Hall & Meyer 1976), O(h³) in S', O(h²) in S''.
//! - [`MinJerk`]: one quintic per interval, rest to rest (zero velocity and acceleration at
//!   every waypoint): `y = y_k + (y_{k+1} − y_k) s(τ)`, `s = 10τ³ − 15τ⁴ + 6τ⁵`, τ = (t − t_k)/h
//!   (Flash & Hogan 1985, the minimum-jerk profile), C² everywhere.
//!
//! Before the first knot and after the last, both hold the end value (zero derivatives).
//! Evaluation finds the interval by bisection and allocates nothing.

/// Where `t` falls: `None` before the first or after the last knot, else the interval k with
/// `t_k <= t <= t_{k+1}`.
fn interval(t_knots: &[f64], t: f64) -> Option<usize> {
    let n = t_knots.len();
    if n < 2 || !(t >= t_knots[0] && t <= t_knots[n - 1]) {
        return None;
    }
    // the first knot strictly after t, minus one, kept within 0..n-1
    let k = t_knots.partition_point(|&tk| tk <= t);
    Some(k.saturating_sub(1).min(n - 2))
}

/// The knots must be finite and strictly increasing; at least one.
pub fn check_knots(t: &[f64]) -> Result<(), String> {
    if t.is_empty() {
        return Err("needs at least one knot".into());
    }
    for (k, w) in t.windows(2).enumerate() {
        if !(w[1] > w[0]) {
            return Err(format!("times must increase strictly: t[{}] = {} is not after t[{k}] = {}", k + 1, w[1], w[0]));
        }
    }
    if let Some(x) = t.iter().find(|x| !x.is_finite()) {
        return Err(format!("time {x} is not finite"));
    }
    Ok(())
}

/// The minimum-jerk profile s(τ) and its first two derivatives in τ, τ ∈ [0, 1].
#[inline]
pub fn min_jerk(tau: f64) -> (f64, f64, f64) {
    let (t2, t3) = (tau * tau, tau * tau * tau);
    (t3 * (10.0 - 15.0 * tau + 6.0 * t2), 30.0 * t2 * (1.0 - 2.0 * tau + t2), 60.0 * tau * (1.0 - 3.0 * tau + 2.0 * t2))
}

/// A clamped C² cubic spline with `m` channels.
#[derive(Clone, Debug, PartialEq)]
pub struct CubicSpline {
    t: Vec<f64>,
    /// y[k * m + j]: channel j at knot k.
    y: Vec<f64>,
    /// Second derivatives at the knots, same layout.
    m2: Vec<f64>,
    m: usize,
}

impl CubicSpline {
    /// The spline through `y` (knot-major, `t.len() * m` values) with end slopes `v0`, `vn` (m each).
    pub fn clamped(t: Vec<f64>, y: Vec<f64>, m: usize, v0: &[f64], vn: &[f64]) -> Result<Self, String> {
        check_knots(&t)?;
        let n = t.len();
        assert!(y.len() == n * m && v0.len() == m && vn.len() == m, "spline sizes");
        let mut m2 = vec![0.0; n * m];
        if n >= 2 {
            let h: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
            // the tridiagonal matrix (sub a, diag b, super c), forward-eliminated once
            let mut b = vec![0.0; n];
            let mut c = vec![0.0; n];
            let mut a = vec![0.0; n];
            b[0] = 2.0 * h[0];
            c[0] = h[0];
            for k in 1..n - 1 {
                a[k] = h[k - 1];
                b[k] = 2.0 * (h[k - 1] + h[k]);
                c[k] = h[k];
            }
            a[n - 1] = h[n - 2];
            b[n - 1] = 2.0 * h[n - 2];
            // Thomas: c'_k = c_k / (b_k − a_k c'_{k−1})
            let mut cp = vec![0.0; n];
            let mut den = vec![0.0; n];
            den[0] = b[0];
            cp[0] = c[0] / den[0];
            for k in 1..n {
                den[k] = b[k] - a[k] * cp[k - 1];
                cp[k] = c[k] / den[k];
            }
            let mut d = vec![0.0; n];
            for j in 0..m {
                let yy = |k: usize| y[k * m + j];
                let delta = |k: usize| (yy(k + 1) - yy(k)) / h[k];
                d[0] = 6.0 * (delta(0) - v0[j]);
                for k in 1..n - 1 {
                    d[k] = 6.0 * (delta(k) - delta(k - 1));
                }
                d[n - 1] = 6.0 * (vn[j] - delta(n - 2));
                // forward sweep, then back substitution
                d[0] /= den[0];
                for k in 1..n {
                    d[k] = (d[k] - a[k] * d[k - 1]) / den[k];
                }
                m2[(n - 1) * m + j] = d[n - 1];
                for k in (0..n - 1).rev() {
                    m2[k * m + j] = d[k] - cp[k] * m2[(k + 1) * m + j];
                }
            }
        }
        Ok(Self { t, y, m2, m })
    }

    /// Clamped with zero end slopes: starts and ends at rest.
    pub fn at_rest(t: Vec<f64>, y: Vec<f64>, m: usize) -> Result<Self, String> {
        let z = vec![0.0; m];
        Self::clamped(t, y, m, &z, &z)
    }

    /// Clamped with the end slopes of the cubic through the first (last) four knots of a uniform
    /// grid, `(−11 y_0 + 18 y_1 − 9 y_2 + 2 y_3) / (6h)` (an O(h³) slope, which keeps the
    /// spline's O(h⁴)): for sampled smooth functions whose end slopes are not known.
    pub fn uniform_sampled(t: Vec<f64>, y: Vec<f64>, m: usize) -> Result<Self, String> {
        let n = t.len();
        if n < 4 {
            return Err(format!("needs at least 4 samples, has {n}"));
        }
        let (h0, hn) = (t[1] - t[0], t[n - 1] - t[n - 2]);
        let mut v0 = vec![0.0; m];
        let mut vn = vec![0.0; m];
        for j in 0..m {
            let yy = |k: usize| y[k * m + j];
            v0[j] = (-11.0 * yy(0) + 18.0 * yy(1) - 9.0 * yy(2) + 2.0 * yy(3)) / (6.0 * h0);
            vn[j] = (11.0 * yy(n - 1) - 18.0 * yy(n - 2) + 9.0 * yy(n - 3) - 2.0 * yy(n - 4)) / (6.0 * hn);
        }
        Self::clamped(t, y, m, &v0, &vn)
    }

    /// Number of channels.
    pub fn channels(&self) -> usize {
        self.m
    }

    /// The knots, s.
    pub fn knots(&self) -> &[f64] {
        &self.t
    }

    /// S, S', S'' at `t` into `y`, `yd`, `ydd` (m each).
    pub fn eval(&self, t: f64, y: &mut [f64], yd: &mut [f64], ydd: &mut [f64]) {
        let m = self.m;
        let Some(k) = interval_or_hold(&self.t, &self.y, m, t, y, yd, ydd) else { return };
        let h = self.t[k + 1] - self.t[k];
        let a = (self.t[k + 1] - t) / h;
        let b = (t - self.t[k]) / h;
        let (y0, y1) = (&self.y[k * m..(k + 1) * m], &self.y[(k + 1) * m..(k + 2) * m]);
        let (m0, m1) = (&self.m2[k * m..(k + 1) * m], &self.m2[(k + 1) * m..(k + 2) * m]);
        let (ca, cb) = ((a * a * a - a) * h * h / 6.0, (b * b * b - b) * h * h / 6.0);
        let (da, db) = ((3.0 * a * a - 1.0) * h / 6.0, (3.0 * b * b - 1.0) * h / 6.0);
        for j in 0..m {
            y[j] = a * y0[j] + b * y1[j] + ca * m0[j] + cb * m1[j];
            yd[j] = (y1[j] - y0[j]) / h - da * m0[j] + db * m1[j];
            ydd[j] = a * m0[j] + b * m1[j];
        }
    }
}

/// The interval of the knots `knots` that holds `t`; outside them (`None`), the end value of
/// `values` (m channels per knot) held, with zero derivatives, written into `y`, `yd`, `ydd`.
fn interval_or_hold(knots: &[f64], values: &[f64], m: usize, t: f64, y: &mut [f64], yd: &mut [f64], ydd: &mut [f64]) -> Option<usize> {
    let k = interval(knots, t);
    if k.is_none() {
        let n = knots.len();
        let end = if n > 1 && t > knots[n - 1] { n - 1 } else { 0 };
        y.copy_from_slice(&values[end * m..(end + 1) * m]);
        yd.fill(0.0);
        ydd.fill(0.0);
    }
    k
}

/// Minimum-jerk quintic segments through waypoints, rest at each, with `m` channels.
#[derive(Clone, Debug, PartialEq)]
pub struct MinJerk {
    t: Vec<f64>,
    y: Vec<f64>,
    m: usize,
}

impl MinJerk {
    pub fn new(t: Vec<f64>, y: Vec<f64>, m: usize) -> Result<Self, String> {
        check_knots(&t)?;
        assert_eq!(y.len(), t.len() * m, "spline sizes");
        Ok(Self { t, y, m })
    }

    /// y, y', y'' at `t` (m each).
    pub fn eval(&self, t: f64, y: &mut [f64], yd: &mut [f64], ydd: &mut [f64]) {
        let m = self.m;
        let Some(k) = interval_or_hold(&self.t, &self.y, m, t, y, yd, ydd) else { return };
        let h = self.t[k + 1] - self.t[k];
        let (s, sd, sdd) = min_jerk((t - self.t[k]) / h);
        for j in 0..m {
            let (y0, dy) = (self.y[k * m + j], self.y[(k + 1) * m + j] - self.y[k * m + j]);
            y[j] = y0 + dy * s;
            yd[j] = dy * sd / h;
            ydd[j] = dy * sdd / (h * h);
        }
    }
}

/// A joint-space interpolant chosen by name.
#[derive(Clone, Debug, PartialEq)]
pub enum JointSpline {
    Cubic(CubicSpline),
    Quintic(MinJerk),
}

impl JointSpline {
    pub fn eval(&self, t: f64, y: &mut [f64], yd: &mut [f64], ydd: &mut [f64]) {
        match self {
            JointSpline::Cubic(s) => s.eval(t, y, yd, ydd),
            JointSpline::Quintic(s) => s.eval(t, y, yd, ydd),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ev(s: &CubicSpline, t: f64) -> (f64, f64, f64) {
        let (mut y, mut yd, mut ydd) = ([0.0], [0.0], [0.0]);
        s.eval(t, &mut y, &mut yd, &mut ydd);
        (y[0], yd[0], ydd[0])
    }

    /// A cubic polynomial p(t) = 1 − 2t + 0.5t² + 0.3t³ on non-uniform knots, clamped with its
    /// own end slopes, is reproduced exactly: S, S', S'' = p, p', p'' to 1e-12 everywhere.
    #[test]
    fn cubic_reproduces_a_cubic_exactly() {
        let p = |t: f64| (1.0 - 2.0 * t + 0.5 * t * t + 0.3 * t * t * t, -2.0 + t + 0.9 * t * t, 1.0 + 1.8 * t);
        let t = vec![0.0, 0.3, 0.7, 1.6, 2.0, 3.1];
        let y: Vec<f64> = t.iter().map(|&x| p(x).0).collect();
        let s = CubicSpline::clamped(t, y, 1, &[p(0.0).1], &[p(3.1).1]).unwrap();
        for i in 0..=310 {
            let x = i as f64 * 0.01;
            let (a, b) = (ev(&s, x), p(x));
            assert!((a.0 - b.0).abs() < 1e-12 && (a.1 - b.1).abs() < 1e-12 && (a.2 - b.2).abs() < 1e-11, "t = {x}: {a:?} vs {b:?}");
        }
    }

    /// sin on [0, 2] with exact end slopes: halving h divides the max error by ~16 (O(h⁴)) in
    /// S, ~8 (O(h³)) in S' and ~4 (O(h²)) in S'' (ratios within [0.75, 1.3] of the theory), and
    /// the S error is within the 5/384 h⁴ bound.
    #[test]
    fn cubic_error_orders_on_sine() {
        let err = |n: usize| {
            let t: Vec<f64> = (0..=n).map(|k| 2.0 * k as f64 / n as f64).collect();
            let y: Vec<f64> = t.iter().map(|x| x.sin()).collect();
            let s = CubicSpline::clamped(t, y, 1, &[1.0], &[2f64.cos()]).unwrap();
            let mut e = [0.0f64; 3];
            for i in 0..=4000 {
                let x = 2.0 * i as f64 / 4000.0;
                let (a, b, c) = ev(&s, x);
                e[0] = e[0].max((a - x.sin()).abs());
                e[1] = e[1].max((b - x.cos()).abs());
                e[2] = e[2].max((c + x.sin()).abs());
            }
            e
        };
        let (e1, e2) = (err(20), err(40));
        assert!(e1[0] <= 5.0 / 384.0 * 0.1f64.powi(4));
        for (i, order) in [4, 3, 2].iter().enumerate() {
            let ratio = e1[i] / e2[i] / 2f64.powi(*order);
            assert!((0.75..1.3).contains(&ratio), "derivative {i}: ratio {ratio}, errors {e1:?} {e2:?}");
        }
    }

    /// C² at the knots: value, slope and curvature from the left and right agree to 1e-9
    /// (1e-9 s either side of each knot, times the next derivative's bound); holds outside.
    #[test]
    fn cubic_is_c2_at_knots_and_holds_outside() {
        let t = vec![0.0, 1.0, 1.5, 3.0, 4.0];
        let y = vec![0.0, 1.0, -0.5, 2.0, 2.0];
        let s = CubicSpline::at_rest(t.clone(), y, 1).unwrap();
        for &k in &t[1..4] {
            let (l, r) = (ev(&s, k - 1e-10), ev(&s, k + 1e-10));
            assert!((l.0 - r.0).abs() < 1e-8 && (l.1 - r.1).abs() < 1e-7 && (l.2 - r.2).abs() < 1e-7, "{l:?} {r:?}");
        }
        assert_eq!(ev(&s, -1.0), (0.0, 0.0, 0.0));
        assert_eq!(ev(&s, 5.0), (2.0, 0.0, 0.0));
        assert!(ev(&s, 0.0).1.abs() < 1e-14 && ev(&s, 4.0).1.abs() < 1e-14);
        assert_eq!(ev(&s, 1.5).0, -0.5);
    }

    /// Minimum jerk: s(0) = 0, s(1) = 1, s', s'' vanish at both ends, and the derivatives are
    /// exact (central differences, h = 1e-5, tolerances 1e-8 and 1e-6 as a cross-check).
    #[test]
    fn min_jerk_profile() {
        assert_eq!(min_jerk(0.0), (0.0, 0.0, 0.0));
        let (s, sd, sdd) = min_jerk(1.0);
        assert!((s - 1.0).abs() < 1e-15 && sd.abs() < 1e-14 && sdd.abs() < 1e-13);
        let seg = MinJerk::new(vec![0.0, 2.0, 3.0], vec![0.0, 1.0, 4.0, -1.0, 0.0, 0.0], 2).unwrap();
        let h = 1e-5;
        // off the knots (q‴ jumps there, which a central difference of q̇ straddling one sees)
        for i in 1..30 {
            let t = i as f64 * 0.1 + 0.013;
            let mut v = [[0.0; 2]; 9];
            let [y, yd, ydd, yp, ydp, yddp, ym, ydm, yddm] = &mut v;
            seg.eval(t, y, yd, ydd);
            seg.eval(t + h, yp, ydp, yddp);
            seg.eval(t - h, ym, ydm, yddm);
            for j in 0..2 {
                assert!(((yp[j] - ym[j]) / (2.0 * h) - yd[j]).abs() < 1e-8);
                assert!(((ydp[j] - ydm[j]) / (2.0 * h) - ydd[j]).abs() < 1e-6);
            }
        }
    }
}
