//! The ROS34PW2 coefficients of Rang & Angermann, BIT 45 (2005) 761–787, in the
//! `(alpha_ij, gamma_ij, b, b_hat)` form of HNW II §IV.7 (7.4), as printed in the paper to 17
//! significant digits (hence `excessive_precision` is allowed), and the coefficients of the
//! transformed scheme HNW II (7.25) derived from them.
#![allow(clippy::excessive_precision)]

/// `gamma_ii` of ROS34PW2 (Rang & Angermann 2005).
pub(crate) const GAMMA: f64 = 4.358_665_215_084_590_0e-1;
/// `alpha_ij` (strictly lower).
pub(crate) const ALPHA: [[f64; 4]; 4] = [
    [0.0, 0.0, 0.0, 0.0],
    [8.717_330_430_169_180_1e-1, 0.0, 0.0, 0.0],
    [
        8.445_706_001_536_942_3e-1,
        -1.129_906_423_648_418_5e-1,
        0.0,
        0.0,
    ],
    [0.0, 0.0, 1.0, 0.0],
];
/// `gamma_ij` (lower, diagonal `GAMMA`).
pub(crate) const GAMMA_IJ: [[f64; 4]; 4] = [
    [GAMMA, 0.0, 0.0, 0.0],
    [-8.717_330_430_169_180_1e-1, GAMMA, 0.0, 0.0],
    [
        -9.033_805_701_304_408_2e-1,
        5.418_067_238_809_532_6e-2,
        GAMMA,
        0.0,
    ],
    [
        2.421_238_070_609_534_6e-1,
        -1.223_250_583_904_514_7,
        5.452_602_553_351_021_4e-1,
        GAMMA,
    ],
];
/// Weights of the order-3 solution.
pub(crate) const B: [f64; 4] = [
    2.421_238_070_609_534_6e-1,
    -1.223_250_583_904_514_7,
    1.545_260_255_335_102_0,
    4.358_665_215_084_590_0e-1,
];
/// Weights of the embedded order-2 solution.
pub(crate) const B_HAT: [f64; 4] = [
    3.781_090_314_581_936_9e-1,
    -9.604_229_221_242_317_8e-2,
    0.5,
    2.179_332_607_542_295_0e-1,
];

/// Coefficients of the transformed scheme, derived from the paper's.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Tableau {
    /// `(alpha_ij) Gamma^-1` (strictly lower).
    pub a: [[f64; 4]; 4],
    /// `-(Gamma^-1)_ij` for `j < i`.
    pub c: [[f64; 4]; 4],
    /// `b Gamma^-1` and `(b - b_hat) Gamma^-1`.
    pub m: [f64; 4],
    pub e: [f64; 4],
    /// `alpha_i = sum_j alpha_ij`, `gamma_i = sum_{j<=i} gamma_ij`.
    pub alpha: [f64; 4],
    pub gamma: [f64; 4],
}

impl Tableau {
    #[allow(clippy::needless_range_loop)] // index notation of the formulas
    pub fn new() -> Self {
        // Gamma^-1 by forward substitution (lower triangular)
        let g = GAMMA_IJ;
        let mut gi = [[0.0; 4]; 4];
        for col in 0..4 {
            for i in col..4 {
                let rhs = if i == col { 1.0 } else { 0.0 };
                let s: f64 = (col..i).map(|k| g[i][k] * gi[k][col]).sum();
                gi[i][col] = (rhs - s) / g[i][i];
            }
        }
        let (mut a, mut c) = ([[0.0; 4]; 4], [[0.0; 4]; 4]);
        let (mut m, mut e, mut alpha, mut gamma) = ([0.0; 4], [0.0; 4], [0.0; 4], [0.0; 4]);
        for i in 0..4 {
            for j in 0..i {
                a[i][j] = (0..4).map(|k| ALPHA[i][k] * gi[k][j]).sum();
                c[i][j] = -gi[i][j];
            }
            m[i] = (0..4).map(|k| B[k] * gi[k][i]).sum();
            e[i] = (0..4).map(|k| (B[k] - B_HAT[k]) * gi[k][i]).sum();
            alpha[i] = ALPHA[i].iter().sum();
            gamma[i] = g[i][..=i].iter().sum();
        }
        Self {
            a,
            c,
            m,
            e,
            alpha,
            gamma,
        }
    }
}
