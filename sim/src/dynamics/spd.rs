//! Solving the small symmetric positive semi-definite systems of the contacts — the Schur
//! complement `J M⁻¹ Jᵀ` of the force solve, `J Jᵀ` of the projection — in one place, so that
//! redundant contacts are treated alike everywhere: Cholesky of A; when A is singular, or
//! numerically so (a pivot ratio below 1e-6, i.e. a condition number above 1e12), Cholesky of
//! `A + ε I` with `ε = 1e-10 max diag(A)` (Tikhonov; Golub & Van Loan, *Matrix Computations*,
//! §6.1.4), which splits the solution among the redundant rows.

use nalgebra::{Cholesky, DMatrix, Dim, Dyn, Matrix, StorageMut};

/// Solve `A X = B` in place of `B` for symmetric positive semi-definite `A` (n x n). `work` is
/// n x n scratch (its storage moves through the factorisation: no allocation on success).
/// Returns `Some(regularized)`, or `None` when even `A + ε I` cannot be factored.
pub fn solve_regularized<C: Dim, S: StorageMut<f64, Dyn, C>>(
    a: &DMatrix<f64>,
    work: &mut DMatrix<f64>,
    b: &mut Matrix<f64, Dyn, C, S>,
) -> Option<bool> {
    let n = a.nrows();
    let max_diag = (0..n).fold(0.0f64, |m, k| m.max(a[(k, k)].abs()));
    for eps in [0.0, 1e-10 * max_diag] {
        work.copy_from(a);
        for k in 0..n {
            work[(k, k)] += eps;
        }
        let m = std::mem::replace(work, DMatrix::zeros(0, 0));
        match Cholesky::new(m) {
            Some(chol) => {
                let l = chol.l_dirty();
                let min_pivot = (0..n).fold(f64::INFINITY, |m, k| m.min(l[(k, k)].abs()));
                let max_pivot = (0..n).fold(0.0f64, |m, k| m.max(l[(k, k)].abs()));
                // pivots are square roots: a ratio of 1e-6 is a condition number of 1e12
                let well_posed = eps > 0.0 || min_pivot > 1e-6 * max_pivot;
                if well_posed {
                    chol.solve_mut(b);
                }
                *work = chol.unpack_dirty();
                if well_posed {
                    return Some(eps > 0.0);
                }
            }
            None => *work = DMatrix::zeros(n, n),
        }
    }
    None
}
