//! The force of a sticking contact whose three rows are dependent: a statically indeterminate
//! contact (Pfeiffer & Glocker, *Multibody Dynamics with Unilateral Contacts*, 1996, §5.3 on
//! redundant constraints; Trinkle, Pang, Sudarsky & Lo, "On dynamic multi-rigid-body contact
//! problems with Coulomb friction", ZAMM 77 (1997), on the non-uniqueness of the contact forces).
//!
//! A point whose motion the arm allows in only two directions (an elbow's axis point: it sits
//! on the upper arm, which the shoulder's two joints move over a sphere around the shoulder)
//! has rows `W_k = [J_n; J_t1; J_t2]` of rank 2: there is a unit `z = (z_n, z_t1, z_t2)` with
//! `W_kᵀ z = 0`, the direction of the link it sits on expressed in the contact's frame. A force
//! `α z` on the point is carried by the arm's structure (the shoulder's bearings) and
//! accelerates nothing, so the sticking forces form the line `λ + α z` (the active-row solve's
//! regularisation, `solve.rs`, returns one of them: the smallest, blind to the cone). Coulomb's
//! law holds if SOME force of the line lies in the cone `|f_t| ≤ μ f_n`. Judging the stick by
//! the smallest force declared it broken while the contact could hold (issue 23 item 6: UR5,
//! Z1 and the UR5e-like elbows, which then slid at zero speed and chattered).
//!
//! The rule: among the line, the force of the largest margin `m(α) = μ f_n(α) − |f_t(α)|` (a
//! concave function of α). With `f_n(α) = a + α b`, `f_t(α) = c + α d` (b = z_n, d = the
//! tangential part of z, `D = |d|`, `h` the distance of the line `c + α d` from the origin,
//! `k = μ b / D`), for `|k| < 1` the maximum is at `D β = k h / sqrt(1 − k²)` with
//! `β = α + c·d/D²`, and is `m* = μ (a − b c·d/D²) − h sqrt(1 − k²)`: the stick holds while
//! `m* ≥ 0`, the stick → slip event is the zero of `m*` (`ode/hybrid.rs`), and the recorded
//! force is the maximising one (inside the cone whenever the stick holds). For `|k| ≥ 1` the
//! arm's own direction `z` lies inside the cone: the contact is jammed (wedged; any tangential
//! load is carried), `m*` is unbounded, the recorded force is the smallest shift of the line
//! into the cone and the margin is reported as `+∞`.

/// A dependent-row test for the 3 x 3 Gram block `B = W_k M_J⁻¹ W_kᵀ` (symmetric positive
/// semidefinite, N⁻¹ kg⁻¹ units): its null direction `z` (unit) when `|B z| ≤ 1e-10 max B_ii`,
/// else `None`. `z` is the largest of the cross products of two of B's rows (for rank 2 the
/// rows span the plane orthogonal to the null direction); a full-rank B has no such z and fails
/// the residual test.
pub fn null_direction(b: &[[f64; 3]; 3]) -> Option<[f64; 3]> {
    let cross = |u: &[f64; 3], v: &[f64; 3]| [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
    let norm = |u: &[f64; 3]| (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
    let scale = b[0][0].abs().max(b[1][1].abs()).max(b[2][2].abs());
    if scale.is_nan() || scale <= 0.0 {
        return None;
    }
    let mut z = [0.0; 3];
    let mut best = 0.0;
    for (i, j) in [(0, 1), (0, 2), (1, 2)] {
        let c = cross(&b[i], &b[j]);
        let n = norm(&c);
        if n > best {
            best = n;
            z = [c[0] / n, c[1] / n, c[2] / n];
        }
    }
    if best.is_nan() || best <= 0.0 {
        return None;
    }
    let r = [0, 1, 2].map(|i| b[i][0] * z[0] + b[i][1] * z[1] + b[i][2] * z[2]);
    (norm(&r) <= 1e-10 * scale).then_some(z)
}

/// The shift `α` along the null direction `z` of a sticking contact with force (`f_n`, `f_t`)
/// and friction `mu` > 0 that gives the force of the largest margin `μ f_n − |f_t|` (module
/// doc), and that margin (N). Jammed (`μ |z_n| ≥ |z_t|`): the smallest `|α|` that brings the
/// force into the cone (0 when it is inside), and a margin of `+∞`.
pub fn most_admissible(mu: f64, f_n: f64, f_t: [f64; 2], z: [f64; 3]) -> (f64, f64) {
    let (a, b, c, d) = (f_n, z[0], f_t, [z[1], z[2]]);
    let dd = d[0] * d[0] + d[1] * d[1];
    let margin = |alpha: f64| mu * (a + alpha * b) - (c[0] + alpha * d[0]).hypot(c[1] + alpha * d[1]);
    if mu * b.abs() < dd.sqrt() {
        let big_d = dd.sqrt();
        let k = mu * b / big_d;
        let cd = c[0] * d[0] + c[1] * d[1];
        let h = (c[0] * d[1] - c[1] * d[0]).abs() / big_d;
        let s = (1.0 - k * k).sqrt();
        let beta = k * h / (big_d * s);
        let alpha = beta - cd / dd;
        (alpha, margin(alpha))
    } else {
        if margin(0.0) >= 0.0 {
            return (0.0, f64::INFINITY);
        }
        // μ² (a + α b)² = |c + α d|², the root with the smallest |α| and f_n(α) ≥ 0
        let qa = mu * mu * b * b - dd;
        let qb = 2.0 * (mu * mu * a * b - (c[0] * d[0] + c[1] * d[1]));
        let qc = mu * mu * a * a - (c[0] * c[0] + c[1] * c[1]);
        let roots: [f64; 2] = if qa.abs() <= 1e-15 * (mu * mu * b * b + dd) {
            [-qc / qb, f64::NAN]
        } else {
            let disc = (qb * qb - 4.0 * qa * qc).max(0.0).sqrt();
            [(-qb + disc) / (2.0 * qa), (-qb - disc) / (2.0 * qa)]
        };
        let alpha = roots
            .into_iter()
            .filter(|r| r.is_finite() && a + r * b >= 0.0)
            .min_by(|x, y| x.abs().total_cmp(&y.abs()))
            .unwrap_or(0.0);
        (alpha, f64::INFINITY)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Gram block of the rows of a point that moves only in the plane spanned by `e1`,
    /// `e2` (a 2-DoF point): `W = [n; t1; t2] [e1 e2]` (3 x 2), `B = W Wᵀ` (M = I): rank 2, its
    /// null direction `(e1 × e2)` in the contact frame, up to sign.
    #[test]
    fn a_rank_two_block_has_the_normal_of_its_motion_plane_as_null_direction() {
        let e1 = [0.2f64, 0.9, -0.1];
        let e2 = [-0.5f64, 0.1, 0.7];
        let b: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| e1[i] * e1[j] + e2[i] * e2[j]));
        let z = null_direction(&b).expect("rank 2");
        let w = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
        let wn = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
        let dot = (z[0] * w[0] + z[1] * w[1] + z[2] * w[2]) / wn;
        assert!((dot.abs() - 1.0).abs() <= 1e-12, "z = {z:?}, e1 × e2 = {w:?}");
        // full rank: none
        let mut full = b;
        full[0][0] += 0.3;
        full[2][2] += 0.1;
        assert!(null_direction(&full).is_none());
    }

    /// The largest margin against a brute-force scan of the line `λ + α z`, α in ±200 N by
    /// 1e-4 N (the margin is concave: the scan's best is within 1e-6 N of the maximum), for
    /// a bounded case; a jammed case reports +∞ and a force in the cone.
    #[test]
    fn the_most_admissible_force_is_the_largest_margin_on_the_line() {
        let mu = 0.5;
        let z = {
            let v = [-0.21f64, 0.95, 0.23];
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            [v[0] / n, v[1] / n, v[2] / n]
        };
        let (f_n, f_t) = (107.0, [20.1, -55.0]);
        let (alpha, m) = most_admissible(mu, f_n, f_t, z);
        let margin = |a: f64| mu * (f_n + a * z[0]) - (f_t[0] + a * z[1]).hypot(f_t[1] + a * z[2]);
        let best = (-2_000_000..=2_000_000).map(|i| margin(i as f64 * 1e-4)).fold(f64::NEG_INFINITY, f64::max);
        assert!((m - best).abs() <= 1e-6 && (m - margin(alpha)).abs() <= 1e-12, "closed form {m} at α = {alpha}, scan {best}");
        assert!(m > mu * f_n - f_t[0].hypot(f_t[1]), "the smallest force's margin is not the largest");
        // jammed: z within the cone (|z_t| < μ |z_n|)
        let zj = [0.95f64, 0.3, 0.0];
        let n = (zj[0] * zj[0] + zj[1] * zj[1]).sqrt();
        let zj = [zj[0] / n, zj[1] / n, 0.0];
        let (aj, mj) = most_admissible(mu, 10.0, [30.0, 0.0], zj);
        assert!(mj.is_infinite());
        let (fn_j, ft_j) = (10.0 + aj * zj[0], [30.0 + aj * zj[1], aj * zj[2]]);
        assert!(fn_j >= 0.0 && (mu * fn_j - ft_j[0].hypot(ft_j[1])).abs() <= 1e-9 * fn_j, "on the cone: f_n {fn_j}, f_t {ft_j:?}");
    }
}
