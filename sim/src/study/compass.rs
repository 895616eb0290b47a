//! Compass search, the local refinement of a design study (`crate::study`): from the best point
//! so far, try ± the step along every axis of [0, 1]^n (2n points, evaluated in parallel); move
//! to the best one that improves, else halve the step; stop when the step is below the
//! resolution asked for.
//!
//! Source: T. G. Kolda, R. M. Lewis, V. Torczon, "Optimization by direct search: new
//! perspectives on some classical and modern methods", SIAM Review 45(3), 2003, §3 (compass
//! search, its convergence for continuously differentiable objectives: Theorem 3.3). Chosen over
//! Nelder–Mead because its 2n trial points are independent (a generation runs in parallel and
//! as shards) and it converges on smooth functions, where Nelder–Mead can stall (McKinnon 1998).

use serde::{Deserialize, Serialize};

/// The state of a compass search on [0, 1]^n.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Compass {
    /// The centre: the best point so far.
    pub x: Vec<f64>,
    /// Its value.
    pub f: f64,
    /// The step along each axis.
    pub step: f64,
    /// The search stops when the step falls below this.
    pub min_step: f64,
}

impl Compass {
    pub fn done(&self) -> bool {
        self.step < self.min_step
    }

    /// The trial points: x ± step e_i, clamped to the box; a point equal to x (at a bound) is
    /// left out.
    pub fn ask(&self) -> Vec<Vec<f64>> {
        let mut out = Vec::with_capacity(2 * self.x.len());
        for i in 0..self.x.len() {
            for s in [1.0, -1.0] {
                let mut y = self.x.clone();
                y[i] = (y[i] + s * self.step).clamp(0.0, 1.0);
                if y[i] != self.x[i] {
                    out.push(y);
                }
            }
        }
        out
    }

    /// Move to the best trial point if it improves (the first of equals, in the order asked),
    /// else halve the step.
    pub fn tell(&mut self, xs: &[Vec<f64>], f: &[f64]) {
        let best = (0..xs.len()).filter(|&k| f[k] < self.f).min_by(|&a, &b| f[a].total_cmp(&f[b]).then(a.cmp(&b)));
        match best {
            Some(k) => {
                self.x = xs[k].clone();
                self.f = f[k];
            }
            None => self.step *= 0.5,
        }
    }
}
