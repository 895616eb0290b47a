//! The holding torques of the sticking gears when they are not unique: several joints of a
//! closed chain stick at once (an elbow on the table and two or more sticking joints of the
//! loop), and the constraint forces and the gears share the load.
//!
//! A sticking joint is held by the torque λ_a that makes `q̈_a = 0` (`drive_forces.rs`): with
//! the sticking joints S, `G λ = b`, `G = G_SS` the change of `q̈_S` per unit torque at each
//! sticking joint, `b = −q̈_S(τ)`. With the constrained dynamics `q̈ = A τ + c`, `A = M⁻¹ −
//! M⁻¹ Jᵀ (J M⁻¹ Jᵀ)⁻¹ J M⁻¹` symmetric positive semi-definite, `G = E_Sᵀ A E_S` is PSD, and a
//! λ with `λᵀ G λ = 0` has `A E_S λ = 0`: it changes no joint's acceleration, only the
//! constraint forces (the torques are carried by the table). So the holding torques are the
//! affine set `λ_p + Z z` (Z a basis of the null space of G) and the motion is the same for
//! every one of them: the law of the stuck gears is set-valued (Glocker, *Set-Valued Force
//! Laws*, Springer 2001, ch. 7; Pfeiffer & Glocker, *Multibody Dynamics with Unilateral
//! Contacts*, Wiley 1996, §5.3 on redundant constraints and their indeterminate forces). The
//! stick of all of them is consistent when SOME λ of the set lies in every joint's band
//! `lo_a ≤ λ_a ≤ hi_a` (`dynamics/gear_friction.rs`, "The stick band at rest"): a linear
//! feasibility problem in z.
//!
//! Which λ: the **analytic centre** of the feasible polytope `P = {z : s_k(z) ≥ 0}`, the 2m
//! slacks `s_k` being `λ_a − lo_a` and `hi_a − λ_a` of the m joints the null space moves,
//!
//! ```text
//! z* = argmin_z  −Σ_k log s_k(z)
//! ```
//!
//! (Boyd & Vandenberghe, *Convex Optimization*, Cambridge 2004, §8.5.3). It is unique (the
//! barrier is strictly convex on P: Z has full column rank), independent of where the search
//! starts (a pure function of (t, y)), smooth in the data while P has an interior (implicit
//! function theorem on `∇φ = 0`, with `∇²φ` positive definite), and strictly inside every band
//! while P has an interior: a joint's margin reaches 0 only when P shrinks to nothing, i.e.
//! exactly when no distribution of the load holds every joint any more, which is the stick →
//! slide condition of a set-valued law. The choice of minimal norm (standard for an
//! indeterminate friction set, Pfeiffer & Glocker 1996) is not taken: it lies on the band edges
//! as soon as its unconstrained point is outside them, so a joint's margin would be 0 while the
//! others could still take its load, and its event would fire with stick still consistent.
//!
//! When P is empty or has no interior (a band of zero width: an efficiency-only gear at
//! i = 0), the choice is the **max–min** distribution, `max_z min_k s_k(z)` (the largest common
//! margin, the Phase I problem of §11.4.1 in Boyd & Vandenberghe), whose value m* < 0 says by
//! how much the best distribution leaves a band; its margins are the event functions the
//! driver locates where m* crosses 0 (m* is the optimal value of a parametric LP, continuous
//! in the data; the analytic centre's smallest margin tends to 0 as P shrinks to a point, so
//! the joints whose margins vanish are the same from both sides). The same value is the
//! contacts' group stick margin for redundant sticking contacts (`dynamics/contact/dependent.rs`).
//!
//! **The scale of G.** G is formed from differences of q̈ (one solve per sticking joint), so a
//! direction the chain fixes has G = rounding of either sign (~1e-14 rad/s² per N m), not 0.
//! Its pivots are judged against an absolute scale, not against G's own largest diagonal:
//! `free = max_a 1/(M_J)_aa` over the sticking joints, a lower bound of each joint's free
//! mobility (`(M_J⁻¹)_aa ≥ 1/(M_J)_aa` for SPD `M_J = M + J_m`, Cauchy–Schwarz), which bounds
//! G_aa from above (`G_aa ≤ (M_J⁻¹)_aa`: a constraint only takes mobility away). The scale is
//! `max(free, largest diagonal of G)`. Relative to G alone, one sticking joint whose motion the
//! chain fixes (an elbow on the table and the shoulder that lifts it) had G = ±1e-14 as its own
//! scale, was judged regular, and got λ = b/G = rounding/rounding: any torque, out of its band
//! (the small arm, bilateral elbow, all gear features, dopri45 rtol 1e-12 stopped with no
//! consistent gear mode at 0.2227 s).
//!
//! Algorithm (allocation-free on scratch sized once for nv joints):
//! 0. Gaussian elimination of `G λ = b` as before this choice existed: when no pivot falls
//!    below 1e-12 of the scale, G is regular, λ is unique, and it is taken (bit for
//!    bit the earlier solve: the open chains' runs are unchanged).
//! 1. Otherwise G symmetrised and factored by Cholesky with diagonal pivoting (Higham, *Accuracy and
//!    Stability of Numerical Algorithms*, 2nd ed., SIAM 2002, §10.3): a remaining pivot
//!    ≤ 1e-10 of the scale ends it at rank k; the particular solution `λ_p` has the
//!    trailing n − k unknowns (in pivot order) 0 (the basic solution), the null basis
//!    `[−L₁₁⁻ᵀ L₂₁ᵀ; I]`, orthonormalised (modified Gram–Schmidt, twice). Rank n: λ = λ_p, done.
//! 2. The joints the null space moves (a row of Z longer than 1e-9): the others keep `λ_p`.
//! 3. Phase I, `max t` s.t. `s_k(z) ≥ t`, by the barrier method (§11.3): minimise
//!    `−τ t − Σ log(s_k(z) − t)` by Newton's method with backtracking from z = 0 and
//!    t = min s_k − 1 (strictly feasible), τ raised ×20 from `1/scale` until the gap bound
//!    `2m/τ` is below 1e-13 of the torque scale (1 N m + the largest |λ_p|, |lo|, |hi|); stopped
//!    early as soon as t > 1e-9 of the scale (P has an interior, and the point is inside it).
//! 4. Phase II, from that point: Newton's method with backtracking on `−Σ log s_k(z)` until the
//!    Newton decrement² is below 1e-24 (it is dimensionless; the convergence is quadratic, so
//!    the centre is found to rounding and λ is a function of (t, y) to rounding).
//!
//! Cost: at most a few hundred Newton steps of size r + 1 ≤ n + 1 (r the null dimension) per
//! evaluation with a redundant sticking set; none without one (an open chain: r = 0).

use crate::dynamics::psd_null::{null_basis, pivoted_cholesky};

/// Scratch of [`hold_torques`], sized once for n joints.
#[derive(Clone, Debug)]
pub(crate) struct HoldScratch {
    /// G (n x n, overwritten by its factor), the pivot order, the null basis (r columns of n).
    a: Vec<f64>,
    perm: Vec<usize>,
    z: Vec<f64>,
    /// The moved joints (indices into S) and their rows of Z, packed (m x r).
    moved: Vec<usize>,
    zm: Vec<f64>,
    /// The Newton iterate (r + 1), gradient, step, Hessian ((r + 1)²), trial point.
    x: Vec<f64>,
    grad: Vec<f64>,
    step: Vec<f64>,
    hess: Vec<f64>,
    trial: Vec<f64>,
    /// The slacks' constants `c_k` (2m): `λ_p − lo`, `hi − λ_p` of each moved joint.
    c: Vec<f64>,
}

impl HoldScratch {
    pub(crate) fn new(n: usize) -> Self {
        HoldScratch {
            a: vec![0.0; n * n],
            perm: vec![0; n],
            z: vec![0.0; n * n],
            moved: Vec::with_capacity(n),
            zm: vec![0.0; n * n],
            x: vec![0.0; n + 1],
            grad: vec![0.0; n + 1],
            step: vec![0.0; n + 1],
            hess: vec![0.0; (n + 1) * (n + 1)],
            trial: vec![0.0; n + 1],
            c: vec![0.0; 2 * n],
        }
    }
}

/// The holding torques λ (n) of n sticking joints (module docs): `g` is G (n x n row-major,
/// read), `lambda` holds b on entry and λ on return, `lo`/`hi` the bands, `free` the largest
/// free mobility bound `max_a 1/(M_J)_aa` of the sticking joints (rad/s² per N m; the
/// absolute scale of G's pivots, module docs). Returns the null dimension r (0: λ was unique),
/// or `None` on a non-finite entry.
pub(crate) fn hold_torques(s: &mut HoldScratch, g: &[f64], lambda: &mut [f64], lo: &[f64], hi: &[f64], n: usize, free: f64) -> Option<usize> {
    // 0. a unique λ (G regular: every pivot of the elimination above 1e-12 of the largest
    // diagonal) as before this choice existed, bit for bit
    s.a[..n * n].copy_from_slice(&g[..n * n]);
    s.x[..n].copy_from_slice(&lambda[..n]);
    if !solve_psd(&mut s.a, &mut s.x, n, free)? {
        lambda[..n].copy_from_slice(&s.x[..n]);
        return Some(0);
    }
    // 1. the pivoted Cholesky factor of the symmetrised G
    for i in 0..n {
        for j in 0..n {
            s.a[i * n + j] = 0.5 * (g[i * n + j] + g[j * n + i]);
        }
    }
    let k = factor(&mut s.a, n, &mut s.perm, free)?;
    // the basic solution: L11 L11ᵀ x1 = (P b)_1, x2 = 0, scattered back
    {
        let (a, perm, x) = (&s.a, &s.perm, &mut s.x);
        for i in 0..k {
            let mut v = lambda[perm[i]];
            for c in 0..i {
                v -= a[i * n + c] * x[c];
            }
            x[i] = v / a[i * n + i];
        }
        for i in (0..k).rev() {
            let mut v = x[i];
            for c in i + 1..k {
                v -= a[c * n + i] * x[c];
            }
            x[i] = v / a[i * n + i];
        }
        lambda[..n].fill(0.0);
        for i in 0..k {
            lambda[perm[i]] = x[i];
        }
    }
    if !lambda[..n].iter().all(|v| v.is_finite()) {
        return None;
    }
    let r = null_basis(&s.a, n, k, &s.perm, &mut s.z);
    if r == 0 {
        return Some(0);
    }
    // 2. the joints the null space moves
    s.moved.clear();
    for a in 0..n {
        let norm2: f64 = (0..r).map(|c| s.z[c * n + a] * s.z[c * n + a]).sum();
        if norm2 > 1e-18 {
            s.moved.push(a);
        }
    }
    let m = s.moved.len();
    let mut scale: f64 = 1.0;
    for (p, &a) in s.moved.iter().enumerate() {
        for c in 0..r {
            s.zm[p * r + c] = s.z[c * n + a];
        }
        s.c[2 * p] = lambda[a] - lo[a];
        s.c[2 * p + 1] = hi[a] - lambda[a];
        scale = scale.max(lambda[a].abs()).max(lo[a].abs()).max(hi[a].abs());
    }
    if !scale.is_finite() {
        return None;
    }
    let prob = Slacks { zm: &s.zm[..m * r], c: &s.c[..2 * m], r };
    // 3. Phase I: the largest common margin (x = (z, t))
    s.x[..r].fill(0.0);
    s.x[r] = prob.min_slack(&s.x[..r]) - scale;
    let mut tau = 1.0 / scale;
    let nu = (2 * m) as f64;
    let interior = loop {
        let inside = newton(&prob, true, tau, &mut s.x, &mut s.grad, &mut s.step, &mut s.hess, &mut s.trial, Some(1e-9 * scale));
        if inside || nu / tau < 1e-13 * scale {
            break inside;
        }
        tau *= 20.0;
    };
    // 4. Phase II: the analytic centre, when P has an interior
    if interior {
        newton(&prob, false, 1.0, &mut s.x, &mut s.grad, &mut s.step, &mut s.hess, &mut s.trial, None);
    }
    for (p, &a) in s.moved.iter().enumerate() {
        let dz: f64 = (0..r).map(|c| s.zm[p * r + c] * s.x[c]).sum();
        lambda[a] += dz;
    }
    lambda[..n].iter().all(|v| v.is_finite()).then_some(r)
}

/// Solve `a x = b` for the n x n symmetric positive semi-definite `a` (row-major; `b`
/// overwritten by x) by Gaussian elimination without pivoting, skipping (x = 0) the
/// directions whose pivot is below 1e-12 of the scale (the largest diagonal, or `free` if
/// larger: module docs). Returns whether it skipped
/// one (then G is singular to rounding and the caller chooses among the solutions), `None` on
/// a non-finite entry. (The solve of `drive_forces.rs` before the choice, kept for regular G.)
fn solve_psd(a: &mut [f64], b: &mut [f64], n: usize, free: f64) -> Option<bool> {
    let scale = (0..n).map(|k| a[k * n + k].abs()).fold(free, f64::max);
    if !scale.is_finite() {
        return None;
    }
    let tol = 1e-12 * scale;
    let mut skipped = false;
    for k in 0..n {
        if a[k * n + k] <= tol {
            for c in 0..n {
                a[k * n + c] = 0.0;
                a[c * n + k] = 0.0;
            }
            b[k] = 0.0;
            skipped = true;
            continue;
        }
        for r in k + 1..n {
            let f = a[r * n + k] / a[k * n + k];
            for c in k..n {
                a[r * n + c] -= f * a[k * n + c];
            }
            b[r] -= f * b[k];
        }
    }
    for k in (0..n).rev() {
        if a[k * n + k] == 0.0 {
            b[k] = 0.0;
            continue;
        }
        let mut s = b[k];
        for c in k + 1..n {
            s -= a[k * n + c] * b[c];
        }
        b[k] = s / a[k * n + k];
    }
    b[..n].iter().all(|x| x.is_finite()).then_some(skipped)
}

/// The rank of the symmetrised G in `a`, factored in place by [`pivoted_cholesky`] (L in its
/// lower triangle, in pivot order `perm`), a remaining pivot ≤ 1e-10 of the scale (the largest
/// diagonal, or `free` if larger) ending it. `None` on a non-finite diagonal.
fn factor(a: &mut [f64], n: usize, perm: &mut [usize], free: f64) -> Option<usize> {
    let scale = (0..n).map(|i| a[i * n + i]).fold(free, f64::max);
    if !scale.is_finite() || (0..n).any(|i| a[i * n + i].is_nan()) {
        return None;
    }
    if scale <= 0.0 {
        for (i, p) in perm.iter_mut().enumerate().take(n) {
            *p = i;
        }
        return Some(0);
    }
    Some(pivoted_cholesky(a, n, perm, 1e-10 * scale))
}

/// The slacks `s_{2p}(z) = c_{2p} + Zm_p z`, `s_{2p+1}(z) = c_{2p+1} − Zm_p z` of the moved
/// joints p (Zm packed m x r).
struct Slacks<'a> {
    zm: &'a [f64],
    c: &'a [f64],
    r: usize,
}

impl Slacks<'_> {
    /// `Zm_p z`.
    fn row(&self, p: usize, z: &[f64]) -> f64 {
        (0..self.r).map(|c| self.zm[p * self.r + c] * z[c]).sum()
    }

    fn min_slack(&self, z: &[f64]) -> f64 {
        (0..self.c.len() / 2).map(|p| {
            let v = self.row(p, z);
            (self.c[2 * p] + v).min(self.c[2 * p + 1] - v)
        }).fold(f64::INFINITY, f64::min)
    }

    /// The barrier objective at x: Phase I (`x = (z, t)`) `−τ t − Σ log(s_k − t)`, Phase II
    /// `−Σ log s_k`; +∞ outside.
    fn objective(&self, phase1: bool, tau: f64, x: &[f64]) -> f64 {
        let t = if phase1 { x[self.r] } else { 0.0 };
        let mut f = if phase1 { -tau * t } else { 0.0 };
        for p in 0..self.c.len() / 2 {
            let v = self.row(p, x);
            for u in [self.c[2 * p] + v - t, self.c[2 * p + 1] - v - t] {
                if u <= 0.0 || u.is_nan() {
                    return f64::INFINITY;
                }
                f -= u.ln();
            }
        }
        f
    }
}

/// Newton's method with backtracking (Armijo 0.25, halving) on the barrier objective of
/// [`Slacks::objective`] from the strictly feasible x, to a decrement² of 1e-24 or 100
/// steps. Phase I with `stop_at`: returns true as soon as t exceeds it. Phase II: returns true.
#[allow(clippy::too_many_arguments)]
fn newton(pb: &Slacks, phase1: bool, tau: f64, x: &mut [f64], grad: &mut [f64], step: &mut [f64], hess: &mut [f64], trial: &mut [f64], stop_at: Option<f64>) -> bool {
    let r = pb.r;
    let d = if phase1 { r + 1 } else { r };
    let m = pb.c.len() / 2;
    let mut f = pb.objective(phase1, tau, x);
    for _ in 0..100 {
        if let Some(stop) = stop_at {
            if x[r] > stop {
                return true;
            }
        }
        grad[..d].fill(0.0);
        hess[..d * d].fill(0.0);
        if phase1 {
            grad[r] = -tau;
        }
        let t = if phase1 { x[r] } else { 0.0 };
        for p in 0..m {
            let v = pb.row(p, x);
            // d s_k/dz = ±Zm_p, d s_k/dt = −1 (Phase I)
            for (sign, ck) in [(1.0, pb.c[2 * p]), (-1.0, pb.c[2 * p + 1])] {
                let u = ck + sign * v - t;
                let w = 1.0 / u;
                let coef = |c: usize| if c < r { sign * pb.zm[p * r + c] } else { -1.0 };
                for i in 0..d {
                    let ai = coef(i);
                    grad[i] -= ai * w;
                    for j in 0..=i {
                        hess[i * d + j] += ai * coef(j) * w * w;
                    }
                }
            }
        }
        for i in 0..d {
            for j in 0..i {
                hess[j * d + i] = hess[i * d + j];
            }
        }
        // the Newton step −H⁻¹ g by Cholesky (H is positive definite on a bounded P)
        if !cholesky_solve(hess, grad, step, d) {
            return false;
        }
        let dec2: f64 = -(0..d).map(|i| grad[i] * step[i]).sum::<f64>();
        // NaN or below the threshold: done
        if dec2.is_nan() || dec2 < 1e-24 {
            break;
        }
        let mut h = 1.0;
        let mut moved = false;
        for _ in 0..60 {
            for i in 0..d {
                trial[i] = x[i] + h * step[i];
            }
            let ft = pb.objective(phase1, tau, trial);
            if ft <= f - 0.25 * h * dec2 {
                x[..d].copy_from_slice(&trial[..d]);
                f = ft;
                moved = true;
                break;
            }
            h *= 0.5;
        }
        if !moved {
            break;
        }
    }
    match stop_at {
        Some(stop) => x[r] > stop,
        None => true,
    }
}

/// Solve `h x = −g` for the d x d positive definite `h` (row-major, overwritten by its
/// Cholesky factor) into `x`. False when a pivot is not positive.
fn cholesky_solve(h: &mut [f64], g: &[f64], x: &mut [f64], d: usize) -> bool {
    for k in 0..d {
        let mut v = h[k * d + k];
        for c in 0..k {
            v -= h[k * d + c] * h[k * d + c];
        }
        if v.is_nan() || v <= 0.0 {
            return false;
        }
        let l = v.sqrt();
        h[k * d + k] = l;
        for i in k + 1..d {
            let mut w = h[i * d + k];
            for c in 0..k {
                w -= h[i * d + c] * h[k * d + c];
            }
            h[i * d + k] = w / l;
        }
    }
    for i in 0..d {
        let mut v = -g[i];
        for c in 0..i {
            v -= h[i * d + c] * x[c];
        }
        x[i] = v / h[i * d + i];
    }
    for i in (0..d).rev() {
        let mut v = x[i];
        for c in i + 1..d {
            v -= h[c * d + i] * x[c];
        }
        x[i] = v / h[i * d + i];
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two joints of a loop whose torques the table can exchange (G = [[1, 1], [1, 1]]: a
    /// torque pair (1, −1) moves nothing), load b = 2 split as λ₁ + λ₂ = 2: the centre of the
    /// feasible segment of λ₁ ∈ [lo₁, hi₁], λ₂ = 2 − λ₁ ∈ [lo₂, hi₂], and the max–min point
    /// (common margin m* < 0) when the bands cannot take it.
    #[test]
    fn a_shared_load_is_split_inside_both_bands() {
        let g = [1.0, 1.0, 1.0, 1.0];
        let mut s = HoldScratch::new(2);
        // bands [−0.5, 1.5] and [−0.2, 0.9]: λ₁ ∈ [1.1, 1.5] (λ₂ ∈ [0.5, 0.9]); the analytic
        // centre of the four slacks λ₁ + 0.5, 1.5 − λ₁, λ₂ + 0.2, 0.9 − λ₂ along λ₂ = 2 − λ₁
        let (lo, hi) = ([-0.5, -0.2], [1.5, 0.9]);
        let mut lam = [2.0, 2.0];
        assert_eq!(hold_torques(&mut s, &g, &mut lam, &lo, &hi, 2, 0.0), Some(1));
        assert!((lam[0] + lam[1] - 2.0).abs() < 1e-13, "{lam:?}");
        // ∂/∂λ₁ of −log(λ₁+0.5) − log(1.5−λ₁) − log(2.2−λ₁) − log(λ₁−1.1) = 0
        let d = |x: f64| -1.0 / (x + 0.5) + 1.0 / (1.5 - x) + 1.0 / (2.2 - x) - 1.0 / (x - 1.1);
        assert!(d(lam[0]).abs() < 1e-9, "{lam:?}: {}", d(lam[0]));
        assert!(lam[0] > 1.1 && lam[0] < 1.5, "{lam:?}");
        // bands that together take at most 1.8: the best split leaves each by 0.1
        let (lo, hi) = ([-0.5, -0.2], [1.0, 0.8]);
        let mut lam = [2.0, 2.0];
        hold_torques(&mut s, &g, &mut lam, &lo, &hi, 2, 0.0).unwrap();
        assert!((lam[0] - 1.1).abs() < 1e-10 && (lam[1] - 0.9).abs() < 1e-10, "{lam:?}");
    }

    /// A unique λ (G regular) is G⁻¹ b, bands or not; a joint the constraints hold alone
    /// (G = 0) sits at its band's centre.
    #[test]
    fn a_unique_solution_is_kept_and_a_free_one_centred() {
        let g = [2.0, 0.5, 0.5, 1.0];
        let mut s = HoldScratch::new(2);
        let mut lam = [1.0, 2.0];
        assert_eq!(hold_torques(&mut s, &g, &mut lam, &[-1.0, -1.0], &[0.1, 0.1], 2, 0.0), Some(0));
        let det = 2.0 - 0.25;
        assert!((lam[0] - (1.0 - 1.0) / det).abs() < 1e-15 && (lam[1] - (2.0 * 2.0 - 0.5) / det).abs() < 1e-14, "{lam:?}");
        let mut lam = [0.0];
        assert_eq!(hold_torques(&mut s, &[0.0], &mut lam, &[-0.3], &[0.7], 1, 0.0), Some(1));
        assert!((lam[0] - 0.2).abs() < 1e-12, "{lam:?}");
    }

    /// One sticking joint whose motion the chain fixes: G is rounding of either sign (the
    /// values of the small arm's shoulder under a bilateral elbow, 0.2226 s), judged against
    /// the free mobility bound, not against itself: λ is the band's centre, not b/G (which
    /// is 0.45 N m and 1.2 N m here, far outside the ±0.08 N m band). A regular G of the same
    /// size as `free` keeps b/G.
    #[test]
    fn a_joint_the_chain_fixes_is_judged_against_its_free_mobility() {
        let mut s = HoldScratch::new(1);
        for (g, b) in [(-1.9064087466909004e-14, -8.607632496982761e-15), (4.606985029875766e-15, -9.00180627548094e-15 + 1.44e-14)] {
            let mut lam = [b];
            assert_eq!(hold_torques(&mut s, &[g], &mut lam, &[-0.08], &[0.08], 1, 3.0), Some(1), "G = {g}");
            assert!(lam[0].abs() < 1e-12, "G = {g}: {lam:?}");
        }
        let mut lam = [0.06];
        assert_eq!(hold_torques(&mut s, &[2.0], &mut lam, &[-0.08], &[0.08], 1, 3.0), Some(0));
        assert_eq!(lam[0], 0.03);
    }
}
