//! CMA-ES, the covariance matrix adaptation evolution strategy, as an ask/tell state on the unit
//! box [0, 1]^n: the global method of a design study (`crate::study`).
//!
//! Source: N. Hansen, "The CMA Evolution Strategy: A Tutorial", arXiv:1604.00772 (2016), the
//! default parameters of its Table 1 and the update of its Fig. 7 ((μ/μ_W, λ)-CMA-ES with
//! positive weights). Bounds: a sample outside the box is reflected into it (Hansen's
//! "repair", tutorial §B.3) and its step `y` recomputed from the repaired point, so that the
//! update learns from the points that were evaluated.
//!
//! The whole state is plain numbers ([`Cmaes`] serialises exactly with serde_json's
//! `float_roundtrip`): a study written to its state file and read back asks the same points.
//! The eigendecomposition of C is recomputed from C at every ask (nalgebra's
//! `SymmetricEigen`), not stored.

use nalgebra::{DMatrix, DVector, SymmetricEigen};
use serde::{Deserialize, Serialize};

use super::rng::Rng;

/// The state of one CMA-ES run on [0, 1]^n.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Cmaes {
    pub n: usize,
    /// Population size λ.
    pub lambda: usize,
    /// Mean m.
    pub mean: Vec<f64>,
    /// Step size σ.
    pub sigma: f64,
    /// Covariance C, row-major n × n.
    pub cov: Vec<f64>,
    /// Evolution path of σ, p_σ.
    pub path_sigma: Vec<f64>,
    /// Evolution path of C, p_c.
    pub path_c: Vec<f64>,
    /// Generations told so far.
    pub generation: usize,
}

/// The strategy parameters of Hansen's Table 1 for `n` and `lambda`.
struct Params {
    mu: usize,
    weights: Vec<f64>,
    mu_eff: f64,
    c_sigma: f64,
    d_sigma: f64,
    c_c: f64,
    c_1: f64,
    c_mu: f64,
    chi_n: f64,
}

impl Params {
    fn new(n: usize, lambda: usize) -> Params {
        let nf = n as f64;
        let mu = lambda / 2;
        let raw: Vec<f64> = (1..=mu).map(|i| ((lambda as f64 + 1.0) / 2.0).ln() - (i as f64).ln()).collect();
        let sum: f64 = raw.iter().sum();
        let weights: Vec<f64> = raw.iter().map(|w| w / sum).collect();
        let mu_eff = 1.0 / weights.iter().map(|w| w * w).sum::<f64>();
        let c_sigma = (mu_eff + 2.0) / (nf + mu_eff + 5.0);
        let d_sigma = 1.0 + 2.0 * (((mu_eff - 1.0) / (nf + 1.0)).sqrt() - 1.0).max(0.0) + c_sigma;
        let c_c = (4.0 + mu_eff / nf) / (nf + 4.0 + 2.0 * mu_eff / nf);
        let c_1 = 2.0 / ((nf + 1.3).powi(2) + mu_eff);
        let c_mu = (1.0 - c_1).min(2.0 * (mu_eff - 2.0 + 1.0 / mu_eff) / ((nf + 2.0).powi(2) + mu_eff));
        let chi_n = nf.sqrt() * (1.0 - 1.0 / (4.0 * nf) + 1.0 / (21.0 * nf * nf));
        Params { mu, weights, mu_eff, c_sigma, d_sigma, c_c, c_1, c_mu, chi_n }
    }
}

/// Hansen's default population, 4 + ⌊3 ln n⌋.
pub fn default_lambda(n: usize) -> usize {
    4 + (3.0 * (n as f64).ln()).floor() as usize
}

/// Reflect `x` into [0, 1] (a point far outside lands at the bound it crossed).
pub fn reflect(x: f64) -> f64 {
    let mut x = x;
    for _ in 0..4 {
        if x < 0.0 {
            x = -x;
        } else if x > 1.0 {
            x = 2.0 - x;
        } else {
            return x;
        }
    }
    x.clamp(0.0, 1.0)
}

impl Cmaes {
    /// A run started at `mean` (in [0, 1]^n) with step size `sigma`.
    pub fn new(mean: Vec<f64>, sigma: f64, lambda: usize) -> Cmaes {
        let n = mean.len();
        let mut cov = vec![0.0; n * n];
        for i in 0..n {
            cov[i * n + i] = 1.0;
        }
        Cmaes { n, lambda: lambda.max(2), mean, sigma, cov, path_sigma: vec![0.0; n], path_c: vec![0.0; n], generation: 0 }
    }

    fn eigen(&self) -> (DMatrix<f64>, DVector<f64>) {
        let c = DMatrix::from_row_slice(self.n, self.n, &self.cov);
        // C symmetrised against rounding; eigenvalues floored so that D is real
        let c = (&c + c.transpose()) * 0.5;
        let e = SymmetricEigen::new(c);
        let d = e.eigenvalues.map(|v| v.max(1e-300).sqrt());
        (e.eigenvectors, d)
    }

    /// The λ points of the next generation, each in [0, 1]^n; draws from `rng`.
    pub fn ask(&self, rng: &mut Rng) -> Vec<Vec<f64>> {
        let (b, d) = self.eigen();
        (0..self.lambda)
            .map(|_| {
                let z = DVector::from_iterator(self.n, (0..self.n).map(|_| rng.normal()));
                let y = &b * d.component_mul(&z);
                (0..self.n).map(|i| reflect(self.mean[i] + self.sigma * y[i])).collect()
            })
            .collect()
    }

    /// Update with the generation `xs` (as asked) and their values `f` (+∞ for an infeasible
    /// point: ranked last, ties kept in the order asked).
    pub fn tell(&mut self, xs: &[Vec<f64>], f: &[f64]) {
        let n = self.n;
        let p = Params::new(n, self.lambda);
        let mut order: Vec<usize> = (0..xs.len()).collect();
        order.sort_by(|&a, &b| f[a].total_cmp(&f[b]));
        let m_old = DVector::from_column_slice(&self.mean);
        let ys: Vec<DVector<f64>> = order[..p.mu].iter().map(|&k| (DVector::from_column_slice(&xs[k]) - &m_old) / self.sigma).collect();
        let mut y_w = DVector::zeros(n);
        for (w, y) in p.weights.iter().zip(&ys) {
            y_w += y * *w;
        }
        let m_new = &m_old + &y_w * self.sigma;
        // C^{-1/2} y_w = B D^{-1} Bᵀ y_w
        let (b, d) = self.eigen();
        let c_inv_half_yw = &b * (b.transpose() * &y_w).component_div(&d);
        let mut ps = DVector::from_column_slice(&self.path_sigma);
        ps = ps * (1.0 - p.c_sigma) + c_inv_half_yw * (p.c_sigma * (2.0 - p.c_sigma) * p.mu_eff).sqrt();
        let g = (self.generation + 1) as f64;
        let ps_norm = ps.norm();
        let h_sigma = ps_norm / (1.0 - (1.0 - p.c_sigma).powf(2.0 * g)).sqrt() < (1.4 + 2.0 / (n as f64 + 1.0)) * p.chi_n;
        let h = if h_sigma { 1.0 } else { 0.0 };
        let mut pc = DVector::from_column_slice(&self.path_c);
        pc = pc * (1.0 - p.c_c) + &y_w * (h * (p.c_c * (2.0 - p.c_c) * p.mu_eff).sqrt());
        let c_old = DMatrix::from_row_slice(n, n, &self.cov);
        let mut rank_mu = DMatrix::zeros(n, n);
        for (w, y) in p.weights.iter().zip(&ys) {
            rank_mu += y * y.transpose() * *w;
        }
        let delta = (1.0 - h) * p.c_c * (2.0 - p.c_c);
        let c_new = &c_old * (1.0 - p.c_1 - p.c_mu) + (&pc * pc.transpose() + &c_old * delta) * p.c_1 + rank_mu * p.c_mu;
        self.sigma *= ((p.c_sigma / p.d_sigma) * (ps_norm / p.chi_n - 1.0)).exp();
        // the box is the unit cube: a step beyond it searches nothing new
        self.sigma = self.sigma.min(1.0);
        self.mean = m_new.iter().map(|&x| x.clamp(0.0, 1.0)).collect();
        self.path_sigma = ps.iter().copied().collect();
        self.path_c = pc.iter().copied().collect();
        self.cov = (0..n * n).map(|k| c_new[(k / n, k % n)]).collect();
        self.generation += 1;
    }
}
