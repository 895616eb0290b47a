//! Dense in-place LU factorisation with partial pivoting, for the `dim x dim` iteration
//! matrices of the implicit steppers.
//!
//! Algorithm: Gaussian elimination with row interchanges (`PA = LU`, unit lower `L`), right-
//! looking (outer-product) form, Golub & Van Loan, *Matrix Computations*, 4th ed., 2013,
//! Algorithm 3.4.1; forward and back substitution, Algorithms 3.1.1–3.1.2. Row-major storage;
//! `L` (without its unit diagonal) and `U` overwrite the matrix. Nothing allocates.
//!
//! Singularity is judged numerically, not only by an exact zero: a pivot whose magnitude is not
//! above `4 n eps scale` counts as zero, where `scale` is the caller's bound on the size of the
//! terms that formed the matrix (for `I/(h gamma) - J`: `1/(h gamma) + max |J_ij|`). A matrix
//! that only cancels to such a pivot through rounding (e.g. `1/(h gamma)` equal to an eigenvalue
//! of `J`) is reported instead of producing a solution amplified by `1/eps`. A NaN pivot is
//! reported the same way.
//!
//! Measured against nalgebra 0.35's `LU` (`cargo bench -p sim --bench lu`, `sim/benches/lu.rs`):
//! factor + one solve of a dense `I/(h gamma) - J`, copied into the working storage each time,
//! ratio of criterion medians in the same run (hand-written / nalgebra), three runs on a
//! 2-core KVM guest shared with other builds (load ~3, so +-10 % between runs):
//!
//! | n | vs `LU::new` + `solve_mut` | vs nalgebra's elimination in place |
//! |---|---|---|
//! | 13 | 0.79, 0.80, 0.80 (0.75 µs) | 0.77, 0.82, 0.86 |
//! | 53 | 0.99, 1.06, 0.86 (18.5 µs) | 0.95, 1.04, 1.01 |
//! | 153 | 1.09, 0.93, 1.01 (0.37 ms) | 1.04, 1.02, 0.97 |
//! | 503 | 0.99, 0.90, 0.88 (12-16 ms) | 0.99, 1.01, 1.08 |
//!
//! (Before the rank-1 update ran over row slices, which lets the compiler drop the bounds
//! checks and vectorise, the ratios to `LU::new` were 1.30, 1.26, 1.16, 1.02.) So this LU is
//! as fast as nalgebra's and stays: `LU::new` takes the matrix by value and allocates it and
//! its permutation at every factorisation (the step loop must not allocate), nalgebra's
//! allocation-free path goes through its `#[doc(hidden)]` `gauss_step` functions, its storage
//! is column-major while `OdeJacobian` writes row-major, and it has no numerical
//! singularity test (exact zero pivots only). faer was not measured.

/// Factorises the row-major `n x n` matrix `a` in place (`PA = LU`); `piv[k]` is the row swapped
/// with row `k` at step `k`.
///
/// # Errors
/// `Err(k)`: the pivot of column `k` is not above `4 n eps scale` in magnitude (or is NaN);
/// `a` and `piv` are then partially overwritten and must not be used with [`lu_solve`].
#[allow(dead_code)] // the steppers use lu_factor_within; this is for the tests and benches/lu.rs
pub(super) fn lu_factor(
    a: &mut [f64],
    n: usize,
    piv: &mut [usize],
    scale: f64,
) -> Result<(), usize> {
    lu_factor_within(a, n, piv, scale, || false).map_err(|stop| match stop {
        LuStop::Singular(k) | LuStop::OutOfTime(k) => k,
    })
}

/// Why [`lu_factor_within`] stopped: a (numerically) zero pivot in column `k`, or the
/// deadline, seen before column `k` (0-based).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum LuStop {
    Singular(usize),
    OutOfTime(usize),
}

/// [`lu_factor`] that asks `out_of_time` (the steppers: their `Watch`, a read of the clock)
/// before every column after the first (a column costs `(n - k)^2` multiply-adds: 9e6 for the
/// 3000 coupled states of a 1000-joint arm, some milliseconds, against tens of nanoseconds for
/// the clock).
///
/// # Errors
/// [`LuStop::Singular`] as [`lu_factor`]'s `Err(k)`; [`LuStop::OutOfTime`] past the deadline
/// (the matrix then partially overwritten).
pub(super) fn lu_factor_within(
    a: &mut [f64],
    n: usize,
    piv: &mut [usize],
    scale: f64,
    out_of_time: impl Fn() -> bool,
) -> Result<(), LuStop> {
    assert_eq!(a.len(), n * n, "lu_factor: matrix length vs n^2");
    assert_eq!(piv.len(), n, "lu_factor: pivot length vs n");
    let tiny = 4.0 * n as f64 * f64::EPSILON * scale;
    for k in 0..n {
        if k > 0 && out_of_time() {
            return Err(LuStop::OutOfTime(k));
        }
        // pivot: largest magnitude in column k at or below the diagonal
        let mut p = k;
        let mut best = a[k * n + k].abs();
        for i in k + 1..n {
            let v = a[i * n + k].abs();
            if v > best {
                best = v;
                p = i;
            }
        }
        let regular = best > tiny; // false for NaN too
        if !regular {
            return Err(LuStop::Singular(k));
        }
        piv[k] = p;
        if p != k {
            let (upper, lower) = a.split_at_mut(p * n);
            upper[k * n..(k + 1) * n].swap_with_slice(&mut lower[..n]);
        }
        let inv = 1.0 / a[k * n + k];
        // rank-1 update of the rows below k, as slices (no bounds checks in the inner loop,
        // which the compiler then vectorises; the same operations in the same order)
        let (upper, lower) = a.split_at_mut((k + 1) * n);
        let pivot_row = &upper[k * n + k + 1..];
        for row in lower.chunks_exact_mut(n) {
            let l = row[k] * inv;
            row[k] = l;
            if l != 0.0 {
                for (x, u) in row[k + 1..].iter_mut().zip(pivot_row) {
                    *x -= l * u;
                }
            }
        }
    }
    Ok(())
}

/// Solves `A x = b` in place (`b` becomes `x`) with the factors from [`lu_factor`].
pub(super) fn lu_solve(lu: &[f64], n: usize, piv: &[usize], b: &mut [f64]) {
    debug_assert_eq!(lu.len(), n * n);
    debug_assert_eq!(b.len(), n);
    // apply the row interchanges in order, then L y = P b (unit diagonal)
    for (k, &p) in piv.iter().enumerate() {
        if p != k {
            b.swap(k, p);
        }
    }
    for i in 1..n {
        let row = &lu[i * n..i * n + i];
        let s: f64 = row.iter().zip(&b[..i]).map(|(l, x)| l * x).sum();
        b[i] -= s;
    }
    // U x = y
    for i in (0..n).rev() {
        let row = &lu[i * n + i + 1..(i + 1) * n];
        let s: f64 = row.iter().zip(&b[i + 1..]).map(|(u, x)| u * x).sum();
        b[i] = (b[i] - s) / lu[i * n + i];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// max_i |(A x - b)_i| for row-major A.
    fn residual(a: &[f64], n: usize, x: &[f64], b: &[f64]) -> f64 {
        (0..n)
            .map(|i| {
                let ax: f64 = (0..n).map(|j| a[i * n + j] * x[j]).sum();
                (ax - b[i]).abs()
            })
            .fold(0.0, f64::max)
    }

    // A matrix that needs pivoting (zero leading entry) and a nonsymmetric 5x5 with a known
    // solution: residual <= 1e-13 (entries O(10), condition O(100)), solution error <= 1e-12.
    #[test]
    fn lu_solves_pivoting_and_general_systems() {
        let a0 = [0.0, 2.0, 1.0, 1.0, 1.0, 1.0, 4.0, -3.0, 2.0];
        let x_true = [1.0, -2.0, 0.5];
        let b0: Vec<f64> = (0..3)
            .map(|i| (0..3).map(|j| a0[i * 3 + j] * x_true[j]).sum())
            .collect();
        let (mut a, mut piv, mut x) = (a0, [0; 3], b0.clone());
        lu_factor(&mut a, 3, &mut piv, 4.0).expect("nonsingular");
        lu_solve(&a, 3, &piv, &mut x);
        assert!(residual(&a0, 3, &x, &b0) <= 1e-13);
        for (xi, ti) in x.iter().zip(&x_true) {
            assert!((xi - ti).abs() <= 1e-12, "{x:?}");
        }

        let n = 5;
        let mut a5 = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                a5[i * n + j] =
                    ((i * 7 + j * 3) % 11) as f64 - 5.0 + if i == j { 12.0 } else { 0.0 };
            }
        }
        let x_true: Vec<f64> = (0..n).map(|i| (i as f64).sin() + 0.3).collect();
        let b: Vec<f64> = (0..n)
            .map(|i| (0..n).map(|j| a5[i * n + j] * x_true[j]).sum())
            .collect();
        let (mut lu, mut piv, mut x) = (a5.clone(), vec![0; n], b.clone());
        lu_factor(&mut lu, n, &mut piv, 20.0).expect("nonsingular");
        lu_solve(&lu, n, &piv, &mut x);
        assert!(residual(&a5, n, &x, &b) <= 1e-13);
        for (xi, ti) in x.iter().zip(&x_true) {
            assert!((xi - ti).abs() <= 1e-12, "{x:?} vs {x_true:?}");
        }
    }

    #[test]
    fn lu_reports_exact_and_numerical_singularity() {
        // rank 2: third row = first + second
        let mut a = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 5.0, 7.0, 9.0];
        let mut piv = [0; 3];
        assert!(lu_factor(&mut a, 3, &mut piv, 9.0).is_err());
        // 1/(h g) - j with h g = 1/j up to rounding: cancels to O(eps), which is singular at
        // the scale 1/(h g) + |j| of the terms
        let j = 3.0;
        let hg = 1.0 / j;
        let mut w: [f64; 1] = [1.0 / hg - j];
        assert!(w[0].abs() < 1e-14);
        assert_eq!(lu_factor(&mut w, 1, &mut [0], 1.0 / hg + j), Err(0));
        // NaN entries
        let mut a = [f64::NAN, 1.0, 1.0, 1.0];
        assert!(lu_factor(&mut a, 2, &mut [0; 2], 1.0).is_err());
        // a small but well-conditioned matrix at a small scale is fine
        let mut a = [1e-200, 0.0, 0.0, 1e-200];
        assert!(lu_factor(&mut a, 2, &mut [0; 2], 1e-200).is_ok());
    }
}
