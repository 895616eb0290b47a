//! The forces of sticking contacts whose rows are dependent ACROSS contacts: two or more
//! coincident or kinematically dependent contacts (two elbows at one point; a point moved only
//! by the joints that move another touching point). The generalisation of
//! [`super::indeterminate`] (one contact whose own three rows have rank 2) to a group.
//!
//! Theory (Pfeiffer & Glocker, *Multibody Dynamics with Unilateral Contacts*, 1996, §5.3 on
//! redundant constraints; Trinkle, Pang, Sudarsky & Lo, "On dynamic multi-rigid-body contact
//! problems with Coulomb friction", ZAMM 77 (1997), on the non-uniqueness of the contact forces;
//! Glocker, *Set-Valued Force Laws*, 2001, §7 for the cone law of each contact). With the
//! sticking contacts' rows stacked, `W = [W_1; …; W_n]` (3n x nv), the forces `λ` enter the
//! dynamics only through `Wᵀ λ`: every `λ + Z α`, `Z` a basis of the null space of
//! `G = W M_J⁻¹ Wᵀ` (equivalently of `Wᵀ`, M_J being positive definite), gives the same q̈. The
//! active-row solve (`solve.rs`, Tikhonov-regularised) returns one of them, blind to the
//! cones. Coulomb's law holds with all these contacts sticking if SOME distribution lies in
//! every cone `|f_t,k| ≤ μ_k f_n,k`. The group's stick margin is therefore
//!
//! ```text
//! m*(λ) = max_α min_k m_k(α),   m_k(α) = μ_k f_n,k(α) − |f_t,k(α)|,
//! ```
//!
//! a concave maximisation (each `m_k` is concave in α: a linear function minus a norm of an
//! affine one), a second-order cone program (Boyd & Vandenberghe, *Convex Optimization*, 2004,
//! §4.4.2). The stick of the group holds while `m* ≥ 0`; its stick → slip event function is `m*`
//! for every contact of the group (they fire together and the mode problem decides the group's
//! slip at once: `modes.rs`), and the recorded forces are the maximising distribution (inside
//! every cone whenever the stick holds). `m*` is the optimal value of a parametric convex
//! program, continuous in the data, so the event function is continuous in time.
//!
//! For n coincident contacts with the same μ (identical rows), `m*` = `m(F)/n` with `F` the
//! summed force and `m` one contact's margin (the equal split is optimal: `m` is concave and
//! positively homogeneous), so the pair sticks and slips exactly as one contact carrying the
//! sum (`sim/tests/contacts_pair.rs`).
//!
//! Algorithm, allocation-free on scratch sized once for nc contacts:
//! 1. `G` of the sticking contacts' rows and its null space by Cholesky with diagonal pivoting
//!    (Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed., 2002, §10.3): a
//!    remaining pivot ≤ `1e-10 max G_ii` ends the factorisation (the threshold of
//!    [`super::indeterminate::null_direction`]); the basis `[−L₁₁⁻ᵀ L₂₁ᵀ; I]`, orthonormalised
//!    (modified Gram–Schmidt, twice).
//! 2. When the null space is spanned by the contacts' own null directions (its dimension is
//!    the count of contacts with a rank-2 block) there is no dependence across contacts and
//!    nothing changes (the per-contact rule of `indeterminate.rs` stands).
//! 3. Otherwise the contacts coupled by it: the connected components of the block pattern of
//!    the orthogonal projector `P = Z Zᵀ` (a subspace splits into pieces supported on disjoint
//!    sets of contacts exactly when P is block diagonal along them), each component with two or
//!    more contacts a group, its null basis Z restricted to its rows.
//! 4. Each group's program by the barrier method (Boyd & Vandenberghe §11.3, with the
//!    second-order cone's logarithmic barrier `−log(u² − |v|²)`, §11.6): variables (α, t),
//!    minimise `−τ t + Σ_k −log(u_k² − |v_k|²) − log(R² − |α|²)` with `u_k = μ_k f_n,k(α) − t`,
//!    `v_k = f_t,k(α)`, Newton steps with backtracking, τ raised ×20 until the duality gap bound
//!    `ν/τ` (ν = 2n + 2) is below 1e-14 of the force scale. The ball `|α| ≤ R` (R = 1e4 times
//!    the force scale) bounds the program when the group is jammed (a null direction inside
//!    every cone: any tangential load is carried): an optimum at the ball reports `+∞`, as a
//!    jammed single contact does. The margin reported is `min_k m_k(α*)` at the optimum found
//!    (a value the distribution attains, within the gap bound of the maximum).

use crate::dynamics::psd_null::{null_basis, orthonormalise, pivoted_cholesky};

/// Scratch of [`group_margins`], sized once for nc contacts (no allocation in the step loop).
#[derive(Clone, Debug)]
pub struct DependentScratch {
    /// The sticking contacts considered (contact index, active index of its normal row).
    idx: Vec<usize>,
    pos: Vec<usize>,
    /// Their friction coefficients.
    mus: Vec<f64>,
    /// Whether each has a rank-2 block of its own.
    local: Vec<bool>,
    /// Group label of each (index into idx).
    comp: Vec<usize>,
    /// `G` (p x p row-major), its pivoting permutation, the null basis (d columns of length p).
    g: Vec<f64>,
    perm: Vec<usize>,
    z: Vec<f64>,
    /// A group's basis (columns of length p) and the barrier method's vectors and matrix.
    basis: Vec<f64>,
    x: Vec<f64>,
    xt: Vec<f64>,
    grad: Vec<f64>,
    step: Vec<f64>,
    hess: Vec<f64>,
    inv: Vec<f64>,
    /// Per contact: a member of a group of the last [`group_margins`] (its force is the
    /// group's distribution, not unique where the program's maximiser is not).
    grouped: Vec<bool>,
}

impl DependentScratch {
    pub fn new(nc: usize) -> Self {
        let p = 3 * nc;
        DependentScratch {
            idx: Vec::with_capacity(nc),
            pos: Vec::with_capacity(nc),
            mus: Vec::with_capacity(nc),
            local: Vec::with_capacity(nc),
            comp: vec![0; nc],
            g: vec![0.0; p * p],
            perm: vec![0; p],
            z: vec![0.0; p * p],
            basis: vec![0.0; p * p],
            x: vec![0.0; p + 1],
            xt: vec![0.0; p + 1],
            grad: vec![0.0; p + 1],
            step: vec![0.0; p + 1],
            hess: vec![0.0; (p + 1) * (p + 1)],
            inv: vec![0.0; p + 1],
            grouped: vec![false; nc],
        }
    }

    /// Whether contact k was a member of a group (rows dependent across contacts) in the last
    /// [`group_margins`] (false after [`DependentScratch::clear_groups`]).
    pub fn in_group(&self, k: usize) -> bool {
        self.grouped.get(k).copied().unwrap_or(false)
    }

    /// No contact in a group (a solve with fewer than two sticking contacts).
    pub fn clear_groups(&mut self) {
        self.grouped.fill(false);
    }
}

/// One sticking contact of a group, as the program reads it: friction, force (normal,
/// tangential) and the rows of the group basis at its three coordinates.
struct Member<'a> {
    mu: f64,
    f: [f64; 3],
    rows: [&'a [f64]; 3],
}

/// The null space of the p x p PSD matrix `g` (row-major, overwritten) by Cholesky with
/// diagonal pivoting: its dimension d and an orthonormal basis in `z` (column c at
/// `z[c p..(c + 1) p]`).
fn null_space(g: &mut [f64], p: usize, perm: &mut [usize], z: &mut [f64]) -> usize {
    let scale = (0..p).map(|i| g[i * p + i].abs()).fold(0.0, f64::max);
    if scale.is_nan() || scale <= 0.0 || !scale.is_finite() {
        return 0;
    }
    let r = pivoted_cholesky(g, p, perm, 1e-10 * scale);
    null_basis(g, p, r, perm, z)
}

/// The rows and forces the group program reads, and what it writes back.
pub struct GroupInput<'a> {
    /// Per contact: friction μ (0 for a contact that does not take part).
    pub mu: &'a dyn Fn(usize) -> f64,
    /// Whether contact k sticks with its three rows active, and the active index of its normal
    /// row (the two tangential rows follow it).
    pub sticking: &'a dyn Fn(usize) -> Option<usize>,
    /// `G_ij` of active rows i, j (`W_i M_J⁻¹ W_jᵀ`).
    pub gram: &'a dyn Fn(usize, usize) -> f64,
    /// Whether contact k's own 3 x 3 block has rank 2 (`indeterminate::null_direction`).
    pub local: &'a dyn Fn(usize) -> bool,
}

/// The groups of sticking contacts with rows dependent across contacts (module doc): their
/// forces `f_n`, `f_t` replaced by the distribution of the largest common margin and `margin`
/// set to that margin for every member (`+∞` when the group is jammed). Contacts outside such
/// groups are left as they are. No allocation (`s` sized for `f_n.len()` contacts).
pub fn group_margins(input: &GroupInput, s: &mut DependentScratch, f_n: &mut [f64], f_t: &mut [[f64; 2]], margin: &mut [f64]) {
    let nc = f_n.len();
    s.grouped.fill(false);
    s.idx.clear();
    s.pos.clear();
    s.local.clear();
    s.mus.clear();
    for k in 0..nc {
        let mu = (input.mu)(k);
        if mu > 0.0 {
            if let Some(i) = (input.sticking)(k) {
                s.idx.push(k);
                s.pos.push(i);
                s.mus.push(mu);
                s.local.push((input.local)(k));
            }
        }
    }
    let n = s.idx.len();
    if n < 2 {
        return;
    }
    let p = 3 * n;
    for a in 0..p {
        for b in 0..p {
            s.g[a * p + b] = (input.gram)(s.pos[a / 3] + a % 3, s.pos[b / 3] + b % 3);
        }
    }
    // symmetrise (the Gram of the same rows: equal up to rounding)
    for a in 0..p {
        for b in 0..a {
            let v = 0.5 * (s.g[a * p + b] + s.g[b * p + a]);
            s.g[a * p + b] = v;
            s.g[b * p + a] = v;
        }
    }
    let d = null_space(&mut s.g, p, &mut s.perm, &mut s.z);
    let n_local = s.local.iter().filter(|&&l| l).count();
    if d <= n_local {
        return;
    }
    // components of the projector's block pattern (union by relabelling; n ≤ 8)
    for i in 0..n {
        s.comp[i] = i;
    }
    for i in 0..n {
        for j in i + 1..n {
            let mut w = 0.0f64;
            for a in 0..3 {
                for b in 0..3 {
                    let pa = (0..d).map(|c| s.z[c * p + 3 * i + a] * s.z[c * p + 3 * j + b]).sum::<f64>();
                    w = w.max(pa.abs());
                }
            }
            if w > 1e-9 {
                let (from, to) = (s.comp[j], s.comp[i]);
                if from != to {
                    for c in 0..n {
                        if s.comp[c] == from {
                            s.comp[c] = to;
                        }
                    }
                }
            }
        }
    }
    for label in 0..n {
        let members = (0..n).filter(|&i| s.comp[i] == label).count();
        if members < 2 {
            continue;
        }
        // the group's basis: Z restricted to its coordinates, orthonormalised
        for c in 0..d {
            for a in 0..p {
                s.basis[c * p + a] = if s.comp[a / 3] == label { s.z[c * p + a] } else { 0.0 };
            }
        }
        let dg = orthonormalise(&mut s.basis, p, d);
        if dg == 0 {
            continue;
        }
        for i in (0..n).filter(|&i| s.comp[i] == label) {
            s.grouped[s.idx[i]] = true;
        }
        solve_group(s, label, p, dg, f_n, f_t, margin);
    }
}

/// The barrier method of the module doc for the group `label` with basis `s.basis[..dg p]`.
#[allow(clippy::too_many_arguments)]
fn solve_group(s: &mut DependentScratch, label: usize, p: usize, dg: usize, f_n: &mut [f64], f_t: &mut [[f64; 2]], margin: &mut [f64]) {
    let n = s.idx.len();
    let scale = (0..n).filter(|&i| s.comp[i] == label).map(|i| {
        let k = s.idx[i];
        f_n[k].abs() + f_t[k][0].hypot(f_t[k][1])
    });
    let scale = 1.0 + scale.fold(0.0, f64::max);
    let nx = dg + 1;
    let radius = 1e4;
    let nu = 2.0 * n as f64 + 2.0;
    let basis = &s.basis[..dg * p];
    let member = |i: usize| -> Member {
        let k = s.idx[i];
        Member {
            mu: s.mus[i],
            f: [f_n[k] / scale, f_t[k][0] / scale, f_t[k][1] / scale],
            rows: [0, 1, 2].map(|a| &basis[3 * i + a..]),
        }
    };
    // w_k(x) = (u, v1, v2): u = μ (f_n + Σ α_c Z_c,n) − t, v = f_t + Σ α_c Z_c,t
    let w_of = |m: &Member, x: &[f64]| -> [f64; 3] {
        let mut w = m.f;
        for (c, xc) in x.iter().enumerate().take(dg) {
            for (a, wa) in w.iter_mut().enumerate() {
                *wa += xc * m.rows[a][c * p];
            }
        }
        [m.mu * w[0] - x[dg], w[1], w[2]]
    };
    let margin_at = |x: &[f64]| -> f64 {
        (0..n).filter(|&i| s.comp[i] == label).map(|i| {
            let m = member(i);
            let w = w_of(&m, x);
            w[0] + x[dg] - w[1].hypot(w[2])
        })
        .fold(f64::INFINITY, f64::min)
    };
    // objective −τ t + barrier; None outside the domain
    let objective = |x: &[f64], tau: f64| -> Option<f64> {
        let a2: f64 = x[..dg].iter().map(|v| v * v).sum();
        if a2.is_nan() || a2 >= radius * radius {
            return None;
        }
        let mut phi = -tau * x[dg] - (radius * radius - a2).ln();
        for i in (0..n).filter(|&i| s.comp[i] == label) {
            let w = w_of(&member(i), x);
            let delta = w[0] * w[0] - w[1] * w[1] - w[2] * w[2];
            if !(w[0] > 0.0 && delta > 0.0) {
                return None;
            }
            phi -= delta.ln();
        }
        Some(phi)
    };
    let x = &mut s.x[..nx];
    x.fill(0.0);
    x[dg] = margin_at(x) - 1.0;
    let mut tau = 1.0;
    let mut fx = objective(x, tau);
    if fx.is_none() {
        return;
    }
    loop {
        for _newton in 0..60 {
            // gradient and Hessian
            let (grad, hess) = (&mut s.grad[..nx], &mut s.hess[..nx * nx]);
            grad.fill(0.0);
            hess.fill(0.0);
            grad[dg] = -tau;
            let a2: f64 = x[..dg].iter().map(|v| v * v).sum();
            let rb = radius * radius - a2;
            for c in 0..dg {
                grad[c] += 2.0 * x[c] / rb;
                hess[c * nx + c] += 2.0 / rb;
                for e in 0..dg {
                    hess[c * nx + e] += 4.0 * x[c] * x[e] / (rb * rb);
                }
            }
            for i in (0..n).filter(|&i| s.comp[i] == label) {
                let m = member(i);
                let w = w_of(&m, x);
                let delta = w[0] * w[0] - w[1] * w[1] - w[2] * w[2];
                let jw = [w[0], -w[1], -w[2]];
                // E (3 x nx): ∂w/∂α_c, ∂w/∂t
                let e_col = |a: usize, c: usize| -> f64 {
                    if c == dg {
                        if a == 0 { -1.0 } else { 0.0 }
                    } else if a == 0 {
                        m.mu * m.rows[0][c * p]
                    } else {
                        m.rows[a][c * p]
                    }
                };
                let jsign = [1.0, -1.0, -1.0];
                for c in 0..nx {
                    let ejc: f64 = (0..3).map(|a| jw[a] * e_col(a, c)).sum();
                    grad[c] -= 2.0 * ejc / delta;
                    for e in 0..=c {
                        let eje: f64 = (0..3).map(|a| jw[a] * e_col(a, e)).sum();
                        let ee: f64 = (0..3).map(|a| jsign[a] * e_col(a, c) * e_col(a, e)).sum();
                        let h = -2.0 * ee / delta + 4.0 * ejc * eje / (delta * delta);
                        hess[c * nx + e] += h;
                        if e != c {
                            hess[e * nx + c] += h;
                        }
                    }
                }
            }
            // Newton step: H Δ = −g (Cholesky)
            let step = &mut s.step[..nx];
            for (st, g) in step.iter_mut().zip(grad.iter()) {
                *st = -g;
            }
            if !crate::dynamics::cholesky::factor_in_place(hess, nx, &mut s.inv[..nx]) {
                break;
            }
            crate::dynamics::cholesky::solve_lower(hess, &s.inv[..nx], nx, step);
            crate::dynamics::cholesky::solve_upper_transposed(hess, &s.inv[..nx], nx, step);
            let decrement: f64 = -grad.iter().zip(step.iter()).map(|(g, d)| g * d).sum::<f64>();
            if decrement.is_nan() || decrement <= 1e-20 {
                break;
            }
            // backtracking (Armijo, α = 0.25, β = 0.5)
            let f0 = fx.unwrap_or(f64::INFINITY);
            let mut h = 1.0;
            let mut moved = false;
            for _ in 0..60 {
                let xt = &mut s.xt[..nx];
                for j in 0..nx {
                    xt[j] = x[j] + h * s.step[j];
                }
                if let Some(ft) = objective(xt, tau) {
                    if ft <= f0 - 0.25 * h * decrement {
                        x.copy_from_slice(xt);
                        fx = Some(ft);
                        moved = true;
                        break;
                    }
                }
                h *= 0.5;
            }
            if !moved || decrement < 1e-18 {
                break;
            }
        }
        if nu / tau <= 1e-14 {
            break;
        }
        tau *= 20.0;
        fx = objective(x, tau);
        if fx.is_none() {
            break;
        }
    }
    let a2: f64 = x[..dg].iter().map(|v| v * v).sum();
    let jammed = a2.sqrt() >= 0.5 * radius;
    let best = margin_at(x);
    // the distribution at the optimum, back in newtons
    for i in (0..n).filter(|&i| s.comp[i] == label) {
        let k = s.idx[i];
        let mut f = [f_n[k], f_t[k][0], f_t[k][1]];
        for c in 0..dg {
            for (a, fa) in f.iter_mut().enumerate() {
                *fa += scale * x[c] * basis[c * p + 3 * i + a];
            }
        }
        f_n[k] = f[0];
        f_t[k] = [f[1], f[2]];
        margin[k] = if jammed { f64::INFINITY } else { scale * best };
    }
}

/// The twins among the `closed` contacts (positions in `closed`): `Some(j)` for a contact of
/// the same model (friction, restitution) whose three rows and biases equal (to 1e-12 of their largest entry) those of the earlier
/// closed contact `closed[j]` — two contacts at one point on one plane. They move as one point,
/// so they stick or slide together (a split of their modes is the same motion with one of them
/// carrying nothing, and a slide from rest of one beside a stick of the other has no
/// consistent normal forces: the two sliding force columns differ by the rounding of their
/// directions). For the mode problem (`modes.rs`, at events only: allocates).
pub fn twins(contacts: &[super::Contact], rows: &super::rows::ContactRows, closed: &[usize]) -> Vec<Option<usize>> {
    let same = |a: usize, b: usize| {
        if contacts[a].model != contacts[b].model {
            return false;
        }
        let (mut diff, mut big) = (0.0f64, 0.0f64);
        for axis in 0..3 {
            for (x, y) in rows.row(3 * a + axis).iter().zip(rows.row(3 * b + axis)) {
                diff = diff.max((x - y).abs());
                big = big.max(x.abs()).max(y.abs());
            }
            let (x, y) = (rows.bias[3 * a + axis], rows.bias[3 * b + axis]);
            diff = diff.max((x - y).abs());
            big = big.max(x.abs()).max(y.abs());
        }
        diff <= 1e-12 * (1.0 + big)
    };
    closed.iter().enumerate().map(|(i, &k)| (0..i).find(|&j| same(closed[j], k))).collect()
}

/// Whether the combination `idx` of the candidates `cands` gives two twins different modes.
pub fn twins_differ<T: PartialEq>(twins: &[Option<usize>], cands: &[Vec<T>], idx: &[usize]) -> bool {
    twins.iter().enumerate().any(|(i, t)| t.is_some_and(|j| cands[i][idx[i]] != cands[j][idx[j]]))
}

/// Each twin's entry of `v` (per contact) set to its original's: the slip direction and the
/// onset a slide from rest of the pair chose once, as for one contact.
pub fn copy_to_twins<T: Copy>(twins: &[Option<usize>], closed: &[usize], v: &mut [T]) {
    for (i, t) in twins.iter().enumerate() {
        if let Some(j) = *t {
            v[closed[i]] = v[closed[j]];
        }
    }
}

/// The next combination of `idx` (odometer order); false after the last.
pub fn next_combination<T>(idx: &mut [usize], cands: &[Vec<T>]) -> bool {
    for i in 0..idx.len() {
        idx[i] += 1;
        if idx[i] < cands[i].len() {
            return true;
        }
        idx[i] = 0;
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(w: &[Vec<f64>], mu: &[f64], f_n: &mut [f64], f_t: &mut [[f64; 2]]) -> Vec<f64> {
        // M = I: G = W Wᵀ
        let g: Vec<Vec<f64>> = w.iter().map(|a| w.iter().map(|b| a.iter().zip(b).map(|(x, y)| x * y).sum()).collect()).collect();
        let nc = mu.len();
        let mut s = DependentScratch::new(nc);
        let mut margin: Vec<f64> = (0..nc).map(|k| mu[k] * f_n[k] - f_t[k][0].hypot(f_t[k][1])).collect();
        let sticking = |k: usize| Some(3 * k);
        let gram = |i: usize, j: usize| g[i][j];
        let local = |_k: usize| false;
        let mu_of = |k: usize| mu[k];
        group_margins(&GroupInput { mu: &mu_of, sticking: &sticking, gram: &gram, local: &local }, &mut s, f_n, f_t, &mut margin);
        margin
    }

    fn unit(nv: usize, i: usize) -> Vec<f64> {
        (0..nv).map(|j| if i == j { 1.0 } else { 0.0 }).collect()
    }

    /// Two coincident contacts (identical rows of a free point, nv = 4 with a coordinate the
    /// rows do not see) with the same μ, the solve's split skewed on purpose: the group margin
    /// is the summed force's margin halved (the equal split, module doc) to 1e-12 of the force,
    /// inside the cone and outside it; the sum of the forces is unchanged.
    #[test]
    fn coincident_contacts_share_the_summed_force_equally() {
        let w: Vec<Vec<f64>> = (0..6).map(|r| unit(4, r % 3)).collect();
        let mu = [0.5, 0.5];
        for (total_n, total_t) in [(10.0, [3.0, -1.5]), (10.0, [6.0, 0.0])] {
            let single = 0.5 * total_n - f64::hypot(total_t[0], total_t[1]);
            let mut f_n = [6.0, 4.0];
            let mut f_t = [total_t, [0.0, 0.0]];
            let m = run(&w, &mu, &mut f_n, &mut f_t);
            for k in 0..2 {
                assert!((m[k] - single / 2.0).abs() <= 1e-12 * total_n, "margin {} vs m(F)/2 = {}", m[k], single / 2.0);
                assert!(mu[k] * f_n[k] - f_t[k][0].hypot(f_t[k][1]) >= single / 2.0 - 1e-12 * total_n);
            }
            assert!((f_n[0] + f_n[1] - total_n).abs() <= 1e-12 * total_n);
            assert!((f_t[0][0] + f_t[1][0] - total_t[0]).abs() <= 1e-12 * total_n && (f_t[0][1] + f_t[1][1] - total_t[1]).abs() <= 1e-12 * total_n);
        }
    }

    /// Different μ at one point (0.2 and 0.8): some split is inside both cones exactly when the
    /// sum is inside the wider one's; the largest common margin is a brute-force scan's best
    /// (the split along the tangential force, the normal share: a 2-D scan by 1e-3 N) to 1e-4 N.
    #[test]
    fn coincident_contacts_with_different_friction_take_the_best_split() {
        let w: Vec<Vec<f64>> = (0..6).map(|r| unit(3, r % 3)).collect();
        let mu = [0.2, 0.8];
        let (total_n, total_t) = (10.0, 5.0);
        let mut f_n = [5.0, 5.0];
        let mut f_t = [[2.5, 0.0], [2.5, 0.0]];
        let m = run(&w, &mu, &mut f_n, &mut f_t);
        let mut best = f64::NEG_INFINITY;
        for i in 0..=1000 {
            for j in 0..=1000 {
                let (n0, t0) = (total_n * i as f64 * 1e-3, total_t * j as f64 * 1e-3);
                best = best.max((mu[0] * n0 - t0).min(mu[1] * (total_n - n0) - (total_t - t0)));
            }
        }
        assert!((m[0] - best).abs() <= 1e-4 * total_n && m[0] == m[1], "margin {m:?}, scan {best}");
        assert!(m[0] > 0.0 && (0..2).all(|k| mu[k] * f_n[k] - f_t[k][0].hypot(f_t[k][1]) >= m[0] - 1e-9));
    }

    /// Independent contacts (two free points in disjoint coordinates, nv = 6: full-rank stacked
    /// rows) are left as they are.
    #[test]
    fn independent_contacts_are_not_touched() {
        let w: Vec<Vec<f64>> = (0..6).map(|r| unit(6, r)).collect();
        let mu = [0.5, 0.5];
        let mut f_n = [1.0, 2.0];
        let mut f_t = [[2.0, 0.0], [0.0, 0.5]];
        let m = run(&w, &mu, &mut f_n, &mut f_t);
        assert_eq!((f_n, f_t, m), ([1.0, 2.0], [[2.0, 0.0], [0.0, 0.5]], vec![0.5 - 2.0, 1.0 - 0.5]));
    }
}

#[cfg(test)]
#[path = "dependent_tests.rs"]
mod onset_tests;
