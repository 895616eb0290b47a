//! In-place Cholesky factorisation `A = L Lᵀ` of a small dense symmetric positive definite
//! matrix and the two triangular solves with its factor, on column-major storage (a
//! `DMatrix`'s slice), for the joint-space inertia of the force solve (nv ≈ 10).
//!
//! The outer-product (right-looking) Cholesky of Golub & Van Loan, *Matrix Computations*,
//! 4th ed., Algorithm 4.2.2 (§4.2.5), and column-oriented forward and back substitution
//! (ibid. §3.1.2–3.1.3, Algorithms 3.1.3 and 3.1.4 with `Lᵀ`). Every inner loop runs down a
//! contiguous column. Written here rather than calling `nalgebra::Cholesky` because the
//! two-contact solve wants `L⁻¹ [b Jᵀ]` in one forward substitution and `L⁻ᵀ` once, and
//! nalgebra's generic dynamic-size routines (`Cholesky::new`, `solve_mut`) were a fifth of the
//! two-elbow right-hand side at this size (`cargo bench -p sim --bench dynamics`).

/// Factor the n x n column-major `a` in place: its lower triangle becomes L (the strict upper
/// triangle is left as it was, unread), and `inv_diag` (length n) the reciprocals `1 / L_jj`,
/// so that the solves multiply instead of divide (a division's latency is on the critical path
/// of a substitution). Returns false, with `a` partly overwritten, when a pivot is not
/// positive (not positive definite, or NaN).
pub fn factor_in_place(a: &mut [f64], n: usize, inv_diag: &mut [f64]) -> bool {
    debug_assert_eq!(a.len(), n * n);
    debug_assert_eq!(inv_diag.len(), n);
    for j in 0..n {
        let d = a[j + j * n];
        if d.is_nan() || d <= 0.0 {
            return false;
        }
        let l_jj = d.sqrt();
        a[j + j * n] = l_jj;
        let inv = 1.0 / l_jj;
        inv_diag[j] = inv;
        for x in &mut a[j + 1 + j * n..(j + 1) * n] {
            *x *= inv;
        }
        // the trailing submatrix (lower triangle) minus the outer product of column j
        let (done, rest) = a.split_at_mut((j + 1) * n);
        let col_j = &done[j * n..(j + 1) * n];
        for k in j + 1..n {
            let l_kj = col_j[k];
            let col_k = &mut rest[(k - j - 1) * n..(k - j) * n];
            for i in k..n {
                col_k[i] -= col_j[i] * l_kj;
            }
        }
    }
    true
}

/// Solve `L X = B` in place of `B`: `cols` holds the columns of B one after another (length a
/// multiple of n), L the lower triangle of `l` (n x n, column-major), `inv_diag` its
/// reciprocal diagonal from [`factor_in_place`]. The columns advance together, row by row, so
/// that their independent chains overlap.
pub fn solve_lower(l: &[f64], inv_diag: &[f64], n: usize, cols: &mut [f64]) {
    debug_assert_eq!(cols.len() % n.max(1), 0);
    let m = cols.len().checked_div(n).unwrap_or(0);
    for j in 0..n {
        let col = &l[j * n..(j + 1) * n];
        for c in 0..m {
            let b = &mut cols[c * n..(c + 1) * n];
            let x = b[j] * inv_diag[j];
            b[j] = x;
            for i in j + 1..n {
                b[i] -= col[i] * x;
            }
        }
    }
}

/// Solve `Lᵀ x = b` in place of `b` (length n), L and `inv_diag` as in [`solve_lower`].
pub fn solve_upper_transposed(l: &[f64], inv_diag: &[f64], n: usize, b: &mut [f64]) {
    debug_assert_eq!(b.len(), n);
    for j in (0..n).rev() {
        let col = &l[j * n..(j + 1) * n];
        let mut s = b[j];
        for i in j + 1..n {
            s -= col[i] * b[i];
        }
        b[j] = s * inv_diag[j];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::samples::SplitMix64;
    use nalgebra::DMatrix;

    /// A random SPD matrix `B Bᵀ + n 1` (condition number of order 10).
    fn spd(n: usize, rng: &mut SplitMix64) -> DMatrix<f64> {
        let b = DMatrix::from_fn(n, n, |_, _| rng.range(-1.0, 1.0));
        &b * b.transpose() + DMatrix::identity(n, n) * n as f64
    }

    /// L Lᵀ reproduces A, and the two solves give A⁻¹ b with a residual at rounding
    /// (|A x − b| ≤ 1e-13 |b|), against nalgebra's Cholesky to 1e-13, for n = 1..12.
    #[test]
    fn factor_and_solves_match_the_definition_and_nalgebra() {
        let mut rng = SplitMix64(11);
        for n in 1..=12 {
            let a = spd(n, &mut rng);
            let mut l = a.clone();
            let mut inv = vec![0.0; n];
            assert!(factor_in_place(l.as_mut_slice(), n, &mut inv));
            let lower = l.lower_triangle();
            assert!((&lower * lower.transpose() - &a).norm() <= 1e-13 * a.norm(), "n = {n}: L Lᵀ ≠ A");
            // three right-hand sides at once, then each through Lᵀ
            let b = DMatrix::from_fn(n, 3, |_, _| rng.range(-1.0, 1.0));
            let mut x = b.clone();
            solve_lower(l.as_slice(), &inv, n, x.as_mut_slice());
            for col in x.as_mut_slice().chunks_exact_mut(n) {
                solve_upper_transposed(l.as_slice(), &inv, n, col);
            }
            assert!((&a * &x - &b).norm() <= 1e-13 * b.norm(), "n = {n}: residual");
            let reference = a.clone().cholesky().expect("SPD").solve(&b);
            assert!((x - reference).norm() <= 1e-13, "n = {n}: differs from nalgebra");
        }
    }

    /// Not positive definite (a zero, a negative or a NaN pivot) is refused, not factored.
    #[test]
    fn indefinite_and_nan_are_refused() {
        let mut inv = [0.0; 3];
        let mut a = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
        assert!(!factor_in_place(a.as_mut_slice(), 2, &mut inv[..2]));
        let mut z = DMatrix::<f64>::zeros(3, 3);
        assert!(!factor_in_place(z.as_mut_slice(), 3, &mut inv));
        let mut nan = DMatrix::from_row_slice(2, 2, &[f64::NAN, 0.0, 0.0, 1.0]);
        assert!(!factor_in_place(nan.as_mut_slice(), 2, &mut inv[..2]));
    }
}
