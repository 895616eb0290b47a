//! The null space of a small symmetric positive semi-definite matrix (row-major, n ≲ 10): the
//! rank by Cholesky with diagonal pivoting (Higham, *Accuracy and Stability of Numerical
//! Algorithms*, 2nd ed., SIAM 2002, §10.3: the largest remaining diagonal is the next pivot,
//! and the factorisation stops when it is below a tolerance), a basis of the null space from
//! the factor (`G = Pᵀ [L₁₁; L₂₁] [L₁₁ᵀ L₂₁ᵀ] P`: the vectors `P [−L₁₁⁻ᵀ L₂₁ᵀ e_c; e_c]`), and
//! its orthonormalisation by modified Gram–Schmidt, twice (ibid. §19.8: "twice is enough").
//!
//! Used by the redundant sticking contacts of a group (`contact/dependent.rs`) and by the
//! holding torques of sticking gears in a closed chain (`ode/gear_hold.rs`). Allocates nothing.

/// Cholesky with diagonal pivoting of the n x n symmetric PSD `a` in place (row-major; L in
/// its lower triangle, in pivot order `perm`, with the trailing block left as the Schur
/// complement): returns the rank k, where the largest remaining pivot is ≤ `tol` or NaN.
pub fn pivoted_cholesky(a: &mut [f64], n: usize, perm: &mut [usize], tol: f64) -> usize {
    for (i, p) in perm.iter_mut().enumerate().take(n) {
        *p = i;
    }
    for k in 0..n {
        let j = (k..n).max_by(|&p, &q| a[p * n + p].total_cmp(&a[q * n + q])).unwrap_or(k);
        if a[j * n + j].is_nan() || a[j * n + j] <= tol {
            return k;
        }
        if j != k {
            perm.swap(j, k);
            for c in 0..n {
                a.swap(k * n + c, j * n + c);
            }
            for row in 0..n {
                a.swap(row * n + k, row * n + j);
            }
        }
        let d = a[k * n + k].sqrt();
        a[k * n + k] = d;
        for i in k + 1..n {
            a[i * n + k] /= d;
        }
        for i in k + 1..n {
            for c in k + 1..=i {
                let v = a[i * n + k] * a[c * n + k];
                a[i * n + c] -= v;
                a[c * n + i] = a[i * n + c];
            }
        }
    }
    n
}

/// The null basis of `a` factored by [`pivoted_cholesky`] to rank k: column c (at
/// `z[c n..(c + 1) n]`) has x2 = e_c and `x1 = −L₁₁⁻ᵀ l` (l the first k entries of L's row
/// k + c), scattered to the original order, then orthonormalised ([`orthonormalise`]).
/// Returns its dimension: n − k less any column lost to the orthonormalisation.
pub fn null_basis(a: &[f64], n: usize, k: usize, perm: &[usize], z: &mut [f64]) -> usize {
    let d = n - k;
    for c in 0..d {
        let col = &mut z[c * n..(c + 1) * n];
        col.fill(0.0);
        for i in (0..k).rev() {
            let mut v = -a[(k + c) * n + i];
            for q in i + 1..k {
                v -= a[q * n + i] * col[perm[q]];
            }
            col[perm[i]] = v / a[i * n + i];
        }
        col[perm[k + c]] = 1.0;
    }
    orthonormalise(z, n, d)
}

/// Modified Gram–Schmidt, twice, on the `d` columns of length `n` in `z` (column c at
/// `z[c n..]`); a column whose norm falls to 1e-8 of its own first norm or below (or is not
/// finite) is dropped. Returns the count kept, packed first.
pub fn orthonormalise(z: &mut [f64], n: usize, d: usize) -> usize {
    let mut kept = 0;
    for c in 0..d {
        if c != kept {
            for i in 0..n {
                z[kept * n + i] = z[c * n + i];
            }
        }
        let n0 = (0..n).map(|i| z[kept * n + i] * z[kept * n + i]).sum::<f64>().sqrt();
        if n0.is_nan() || n0 <= 0.0 {
            continue;
        }
        for _ in 0..2 {
            for prev in 0..kept {
                let dot: f64 = (0..n).map(|i| z[prev * n + i] * z[kept * n + i]).sum();
                for i in 0..n {
                    z[kept * n + i] -= dot * z[prev * n + i];
                }
            }
        }
        let norm = (0..n).map(|i| z[kept * n + i] * z[kept * n + i]).sum::<f64>().sqrt();
        if norm.is_finite() && norm > 1e-8 * n0 {
            for i in 0..n {
                z[kept * n + i] /= norm;
            }
            kept += 1;
        }
    }
    kept
}

#[cfg(test)]
mod tests {
    use super::*;

    /// G = B Bᵀ with B 4 x 2 (rank 2): the null space has dimension 2, G z = 0 to rounding,
    /// and the basis is orthonormal and orthogonal to B's columns.
    #[test]
    fn the_null_space_of_a_rank_two_gram_matrix() {
        let b = [[1.0, 0.5], [2.0, -1.0], [0.0, 3.0], [-1.0, 0.25]];
        let n = 4;
        let mut g = [0.0; 16];
        for i in 0..n {
            for j in 0..n {
                g[i * n + j] = b[i][0] * b[j][0] + b[i][1] * b[j][1];
            }
        }
        let orig = g;
        let (mut perm, mut z) = ([0usize; 4], [0.0; 16]);
        let k = pivoted_cholesky(&mut g, n, &mut perm, 1e-10 * 14.0);
        assert_eq!(k, 2);
        let d = null_basis(&g, n, k, &perm, &mut z);
        assert_eq!(d, 2);
        for c in 0..d {
            let col = &z[c * n..(c + 1) * n];
            for i in 0..n {
                let gz: f64 = (0..n).map(|j| orig[i * n + j] * col[j]).sum();
                assert!(gz.abs() < 1e-13, "G z[{c}] row {i}: {gz}");
            }
            for other in 0..d {
                let dot: f64 = (0..n).map(|i| col[i] * z[other * n + i]).sum();
                assert!((dot - f64::from(u8::from(c == other))).abs() < 1e-14, "zᵀz [{c}, {other}] = {dot}");
            }
        }
    }
}
