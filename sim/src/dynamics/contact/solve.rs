//! The constrained dynamics with a chosen set of active contact rows (Pfeiffer & Glocker 1996,
//! §5; Featherstone RBDA §8.1 for the Schur complement):
//!
//! ```text
//! M_J q̈ = b + Ŵᵀ λ,     W q̈ + w = 0
//! ```
//!
//! W holds the active rows (normal rows of bilateral and closed contacts, tangential rows of
//! sticking ones) and w their biases `J̇ q̇` (plus a Baumgarte term when asked). Ŵ is W except for
//! a sliding contact, whose force column is `J_n − μ sᵀ J_t` (Coulomb friction `−μ f_n s`
//! along the slip direction s) while its constraint row stays `J_n`. With `X = M_J⁻¹ Ŵᵀ` and
//! `u = M_J⁻¹ b`: `A λ = −w − W u` with `A = W X`, then `q̈ = u + X λ`. A is symmetric positive
//! definite without sliding friction (Cholesky), nonsymmetric with it (LU with partial
//! pivoting, Golub & Van Loan, *Matrix Computations*, 4th ed., Alg. 3.4.1). Nothing allocates:
//! the scratch is sized for all 3 nc rows.

use super::rows::ContactRows;
use crate::dynamics::cholesky;

/// The force column of an active row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RowForce {
    /// The row itself (a constraint force).
    Same,
    /// A sliding contact's normal row: force column `J_n − μ (s1 J_t1 + s2 J_t2)`.
    Sliding { mu: f64, s: [f64; 2] },
}

/// One active row: `row` indexes [`ContactRows`] (`3k + axis`); `extra` is added to its bias.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ActiveRow {
    pub row: usize,
    pub force: RowForce,
    pub extra: f64,
}

/// Scratch of [`solve_active`], for at most `3 nc` rows.
#[derive(Clone, Debug)]
pub struct ActiveScratch {
    x: Vec<f64>,
    a: Vec<f64>,
    a2: Vec<f64>,
    rhs: Vec<f64>,
    inv: Vec<f64>,
    piv: Vec<usize>,
    /// The residual of an iterative refinement.
    res: Vec<f64>,
    u: Vec<f64>,
    /// The multipliers λ of the active rows (N), in their order.
    pub lambda: Vec<f64>,
}

impl ActiveScratch {
    pub fn new(nv: usize, nc: usize) -> Self {
        let m = 3 * nc;
        ActiveScratch {
            x: vec![0.0; m * nv],
            a: vec![0.0; m * m],
            a2: vec![0.0; m * m],
            rhs: vec![0.0; m],
            inv: vec![0.0; m],
            piv: vec![0; m],
            res: vec![0.0; m],
            u: vec![0.0; nv],
            lambda: vec![0.0; m],
        }
    }
}

impl ActiveScratch {
    /// `W_i · M_J⁻¹ Ŵ_jᵀ` of active rows `i` and `j` of the last [`solve_active`] (for rows with
    /// their own force column, the Gram matrix `W M_J⁻¹ Wᵀ`), N⁻¹ kg⁻¹ in SI.
    pub fn gram(&self, rows: &ContactRows, active: &[ActiveRow], i: usize, j: usize) -> f64 {
        let nv = rows.nv;
        rows.dot(active[i].row, &self.x[j * nv..(j + 1) * nv])
    }
}

/// The active rows' system is singular (redundant rows, or a sliding combination with no
/// solution).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Singular;

/// `x = M_J⁻¹ x` with the Cholesky factor `l` (column-major, lower) and its reciprocal diagonal.
pub fn solve_mj(l: &[f64], inv: &[f64], nv: usize, x: &mut [f64]) {
    cholesky::solve_lower(l, inv, nv, x);
    cholesky::solve_upper_transposed(l, inv, nv, x);
}

/// Solve the system of the module docs: `q̈` into `qdd`, λ into `s.lambda[..active.len()]`.
pub fn solve_active(
    l: &[f64],
    inv: &[f64],
    b: &[f64],
    rows: &ContactRows,
    active: &[ActiveRow],
    s: &mut ActiveScratch,
    qdd: &mut [f64],
) -> Result<(), Singular> {
    let nv = rows.nv;
    let m = active.len();
    s.u.copy_from_slice(b);
    solve_mj(l, inv, nv, &mut s.u);
    let mut symmetric = true;
    for (k, ar) in active.iter().enumerate() {
        let xk = &mut s.x[k * nv..(k + 1) * nv];
        xk.copy_from_slice(rows.row(ar.row));
        if let RowForce::Sliding { mu, s: dir } = ar.force {
            if mu != 0.0 {
                symmetric = false;
                let c = ar.row / 3;
                for j in 0..nv {
                    xk[j] -= mu * (dir[0] * rows.row(3 * c + 1)[j] + dir[1] * rows.row(3 * c + 2)[j]);
                }
            }
        }
        solve_mj(l, inv, nv, xk);
    }
    // A (row-major m x m) and the right-hand side
    for (i, ai) in active.iter().enumerate() {
        for k in 0..m {
            s.a[i * m + k] = rows.dot(ai.row, &s.x[k * nv..(k + 1) * nv]);
        }
        s.lambda[i] = -rows.bias[ai.row] - ai.extra - rows.dot(ai.row, &s.u);
    }
    // a redundant set (two welded points of a planar chain, two contacts at one point:
    // statically indeterminate forces) has a singular A: as in the bilateral path
    // (dynamics/spd.rs), a pivot ratio below 1e-6 (condition above 1e12) retries with
    // A + ε I, ε = 1e-10 max diag(A) (Tikhonov), which splits the forces among the redundant
    // rows, then refines λ ← λ + (A + ε I)⁻¹ (r − A λ) (iterated Tikhonov: the consistent
    // system's error falls by ε/(σ + ε) ≤ 1e-4 per sweep on each range direction σ of A, so
    // three sweeps leave q̈ exact to rounding instead of O(ε); Engl, Hanke & Neubauer,
    // *Regularization of Inverse Problems*, 1996, §5.1). Without it two coincident contacts
    // accelerated the arm ~5e-11 relative differently from one carrying their sum.
    let max_diag = (0..m).map(|i| s.a[i * m + i].abs()).fold(0.0, f64::max);
    s.a2[..m * m].copy_from_slice(&s.a[..m * m]);
    s.rhs[..m].copy_from_slice(&s.lambda[..m]);
    let mut solved = false;
    for eps in [0.0, 1e-10 * max_diag] {
        let a = &mut s.a[..m * m];
        a.copy_from_slice(&s.a2[..m * m]);
        for i in 0..m {
            a[i * m + i] += eps;
        }
        let lam = &mut s.lambda[..m];
        lam.copy_from_slice(&s.rhs[..m]);
        if symmetric {
            // A is symmetric (column-major = row-major): the Cholesky of dynamics/cholesky.rs
            if !cholesky::factor_in_place(a, m, &mut s.inv[..m]) {
                continue;
            }
            let (lo, hi) = (0..m).fold((f64::INFINITY, 0.0f64), |(lo, hi), i| (lo.min(a[i * m + i]), hi.max(a[i * m + i])));
            if eps == 0.0 && !(lo > 1e-6 * hi) {
                continue;
            }
            cholesky::solve_lower(a, &s.inv[..m], m, lam);
            cholesky::solve_upper_transposed(a, &s.inv[..m], m, lam);
            if eps > 0.0 {
                for _ in 0..3 {
                    residual(&s.a2[..m * m], &s.rhs[..m], lam, &mut s.res[..m]);
                    cholesky::solve_lower(a, &s.inv[..m], m, &mut s.res[..m]);
                    cholesky::solve_upper_transposed(a, &s.inv[..m], m, &mut s.res[..m]);
                    for (l, r) in lam.iter_mut().zip(&s.res[..m]) {
                        *l += r;
                    }
                }
            }
            solved = true;
            break;
        } else {
            let mut u_min = f64::INFINITY;
            let mut u_max = 0.0f64;
            if lu_solve_in_place(a, m, &mut s.piv[..m], lam, 1e-14 * max_diag).is_err() {
                continue;
            }
            for i in 0..m {
                u_min = u_min.min(a[i * m + i].abs());
                u_max = u_max.max(a[i * m + i].abs());
            }
            if eps == 0.0 && !(u_min > 1e-12 * u_max) {
                continue;
            }
            if eps > 0.0 {
                for _ in 0..3 {
                    residual(&s.a2[..m * m], &s.rhs[..m], lam, &mut s.res[..m]);
                    lu_resolve(a, m, &s.piv[..m], &mut s.res[..m]);
                    for (l, r) in lam.iter_mut().zip(&s.res[..m]) {
                        *l += r;
                    }
                }
            }
            solved = true;
            break;
        }
    }
    if !solved {
        return Err(Singular);
    }
    let lam = &s.lambda[..m];
    qdd.copy_from_slice(&s.u);
    for k in 0..m {
        let f = lam[k];
        for (x, y) in qdd.iter_mut().zip(&s.x[k * nv..(k + 1) * nv]) {
            *x += y * f;
        }
    }
    if lam.iter().any(|x| !x.is_finite()) {
        return Err(Singular);
    }
    Ok(())
}

/// `res = rhs − A x` (A row-major m x m).
fn residual(a: &[f64], rhs: &[f64], x: &[f64], res: &mut [f64]) {
    let m = x.len();
    for i in 0..m {
        res[i] = rhs[i] - (0..m).map(|j| a[i * m + j] * x[j]).sum::<f64>();
    }
}

/// Solve with the factors [`lu_solve_in_place`] left in `a` and `piv` (the multipliers below the
/// diagonal, permuted with the rows as LAPACK's getrf keeps them): the row swaps in order,
/// then L's and U's substitutions (Golub & Van Loan §3.4.4).
pub fn lu_resolve(a: &[f64], m: usize, piv: &[usize], rhs: &mut [f64]) {
    for (k, &p) in piv.iter().enumerate().take(m) {
        rhs.swap(k, p);
    }
    for k in 0..m {
        for i in k + 1..m {
            rhs[i] -= a[i * m + k] * rhs[k];
        }
    }
    for k in (0..m).rev() {
        let mut x = rhs[k];
        for j in k + 1..m {
            x -= a[k * m + j] * rhs[j];
        }
        rhs[k] = x / a[k * m + k];
    }
}

/// Gaussian elimination with partial pivoting of the row-major `m x m` matrix `a`, solving
/// `a x = rhs` in place (Golub & Van Loan Alg. 3.4.1, 3.1.1–3.1.2); a pivot not above `tiny`
/// is singular.
pub fn lu_solve_in_place(a: &mut [f64], m: usize, piv: &mut [usize], rhs: &mut [f64], tiny: f64) -> Result<(), Singular> {
    for k in 0..m {
        let mut p = k;
        for i in k + 1..m {
            if a[i * m + k].abs() > a[p * m + k].abs() {
                p = i;
            }
        }
        if !(a[p * m + k].abs() > tiny) {
            return Err(Singular);
        }
        piv[k] = p;
        if p != k {
            for j in 0..m {
                a.swap(k * m + j, p * m + j);
            }
            rhs.swap(k, p);
        }
        for i in k + 1..m {
            let l = a[i * m + k] / a[k * m + k];
            a[i * m + k] = l;
            for j in k + 1..m {
                a[i * m + j] -= l * a[k * m + j];
            }
            rhs[i] -= l * rhs[k];
        }
    }
    for k in (0..m).rev() {
        let mut x = rhs[k];
        for j in k + 1..m {
            x -= a[k * m + j] * rhs[j];
        }
        rhs[k] = x / a[k * m + k];
    }
    Ok(())
}
