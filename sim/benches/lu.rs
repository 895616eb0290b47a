//! The Rosenbrock stepper's dense LU (`src/integrate/lu.rs`, compiled here from its source:
//! it is private to the crate) against nalgebra 0.35's, factor + one solve, for the state
//! dimensions of small arms up to a 100-joint chain.
//!
//! `cargo bench -p sim --bench lu`; the measured ratios are in the `//!` docs of `lu.rs`.
//!
//! Groups (criterion ids, also the directories under `target/criterion/`), each
//! `lu/<variant>/<n>` for n = 13, 53, 153, 503, on `I/(h gamma) - J` with a random dense `J`
//! (entries uniform in [-1, 1], `1/(h gamma) = 1`, so partial pivoting swaps rows), copied into
//! the working storage, factored and solved for one right-hand side in every iteration:
//! - `hand`: `lu_factor` + `lu_solve` (row-major, in place; allocates nothing);
//! - `nalgebra`: `LU::new` on a copy of the `DMatrix` + `solve_mut` (allocates the copy and the
//!   permutation in every factorisation: `LU::new` takes the matrix by value);
//! - `nalgebra-inplace`: nalgebra's own elimination steps (`linalg::gauss_step`,
//!   `gauss_step_swap`, `#[doc(hidden)]` in 0.35) on a preallocated column-major `DMatrix`
//!   with our pivot vector, solved with `solve_lower_triangular_with_diag_mut` and
//!   `solve_upper_triangular_mut`: the allocation-free way to use nalgebra's kernels.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use nalgebra::{DMatrix, DVector};

// the stepper's own source; `unused`: its unit tests are compiled but not run here
#[allow(unused)]
#[path = "../src/integrate/lu.rs"]
mod lu;

const DIMS: [usize; 4] = [13, 53, 153, 503];

/// `n` numbers uniform in [-1, 1) from SplitMix64 (Steele, Lea & Flood 2014) seeded with
/// `seed` (kept here so the bench depends on nothing else in the crate).
fn uniform(seed: &mut u64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|_| {
            *seed = seed.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = *seed;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^= z >> 31;
            2.0 * (z >> 11) as f64 / (1u64 << 53) as f64 - 1.0
        })
        .collect()
}

/// nalgebra's partial-pivoting elimination (the loop of `LU::new`) in place; `false` if a
/// column has no nonzero pivot.
fn na_factor(m: &mut DMatrix<f64>, piv: &mut [usize]) -> bool {
    for i in 0..m.nrows() {
        let p = m.view_range(i.., i).icamax() + i;
        let diag = m[(p, i)];
        if diag == 0.0 {
            return false;
        }
        piv[i] = p;
        if p != i {
            m.columns_range_mut(..i).swap_rows(i, p);
            nalgebra::linalg::gauss_step_swap(m, diag, i, p);
        } else {
            nalgebra::linalg::gauss_step(m, diag, i);
        }
    }
    true
}

/// Solves with the factors of [`na_factor`] in place.
fn na_solve(m: &DMatrix<f64>, piv: &[usize], b: &mut DVector<f64>) {
    for (i, &p) in piv.iter().enumerate() {
        b.swap_rows(i, p);
    }
    m.solve_lower_triangular_with_diag_mut(b, 1.0);
    m.solve_upper_triangular_mut(b);
}

fn lu(c: &mut Criterion) {
    let mut g = c.benchmark_group("lu");
    for n in DIMS {
        let mut seed = n as u64;
        let jac = uniform(&mut seed, n * n);
        let rhs = uniform(&mut seed, n);
        // W = I/(h gamma) - J, row-major, and the same as a column-major DMatrix
        let mut w = jac.iter().map(|j| -j).collect::<Vec<f64>>();
        for i in 0..n {
            w[i * n + i] += 1.0;
        }
        let wm = DMatrix::from_row_slice(n, n, &w);
        let b = DVector::from_column_slice(&rhs);

        // the three agree on the solution (to 1e-8 relative; the matrices are well enough
        // conditioned)
        let (mut a, mut piv, mut x) = (w.clone(), vec![0; n], rhs.clone());
        lu::lu_factor(&mut a, n, &mut piv, 1.0 + 1.0).expect("regular");
        lu::lu_solve(&a, n, &piv, &mut x);
        let x_na = nalgebra::LU::new(wm.clone()).solve(&b).expect("regular");
        let (mut m, mut x_in) = (wm.clone(), b.clone());
        assert!(na_factor(&mut m, &mut piv));
        na_solve(&m, &piv, &mut x_in);
        let scale = x_na.amax();
        for i in 0..n {
            assert!(
                (x[i] - x_na[i]).abs() <= 1e-8 * scale && (x_in[i] - x_na[i]).abs() <= 1e-8 * scale
            );
        }

        g.bench_function(BenchmarkId::new("hand", n), |bench| {
            bench.iter(|| {
                a.copy_from_slice(&w);
                x.copy_from_slice(&rhs);
                lu::lu_factor(&mut a, n, &mut piv, 2.0).expect("regular");
                lu::lu_solve(&a, n, &piv, &mut x);
                black_box(x[0])
            })
        });
        g.bench_function(BenchmarkId::new("nalgebra", n), |bench| {
            let mut x = b.clone();
            bench.iter(|| {
                let f = nalgebra::LU::new(black_box(&wm).clone());
                x.copy_from(&b);
                assert!(f.solve_mut(&mut x));
                black_box(x[0])
            })
        });
        g.bench_function(BenchmarkId::new("nalgebra-inplace", n), |bench| {
            bench.iter(|| {
                m.copy_from(black_box(&wm));
                x_in.copy_from(&b);
                assert!(na_factor(&mut m, &mut piv));
                na_solve(&m, &piv, &mut x_in);
                black_box(x_in[0])
            })
        });
    }
    g.finish();
}

fn config() -> Criterion {
    Criterion::default()
        .sample_size(15)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(2))
}

criterion_group! {
    name = benches;
    config = config();
    targets = lu
}
criterion_main!(benches);
