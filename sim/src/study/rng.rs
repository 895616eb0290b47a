//! The study's random numbers: SplitMix64 (G. Steele, D. Lea, C. Flood, "Fast splittable
//! pseudorandom number generators", OOPSLA 2014; the constants of Java's `SplittableRandom`)
//! and normal deviates by the Box–Muller transform (Box & Muller, Ann. Math. Stat. 29, 1958).
//! Written here rather than taken from `rand`: the state is one `u64` that the study's state
//! file carries exactly, and the sequence is fixed by this crate (the generator of
//! `dynamics::samples`), not by a dependency's version, so that
//! a seed gives the same study on every build.

use serde::{Deserialize, Serialize};

/// SplitMix64.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Rng(pub u64);

impl Rng {
    /// The next output of the benches' generator (`dynamics::samples::SplitMix64`), whose state
    /// this struct keeps in a form that serialises with the study.
    pub fn next_u64(&mut self) -> u64 {
        let mut g = crate::dynamics::samples::SplitMix64(self.0);
        let z = g.next_u64();
        self.0 = g.0;
        z
    }

    /// Uniform in (0, 1): 53 random bits, never 0.
    pub fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    /// A standard normal deviate (Box–Muller, one of the pair).
    pub fn normal(&mut self) -> f64 {
        let (u1, u2) = (self.uniform(), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_deviates_have_mean_0_and_variance_1() {
        // 10⁵ draws: standard errors 0.0032 (mean) and 0.0045 (variance); 5σ bounds
        let mut r = Rng(7);
        let n = 100_000;
        let xs: Vec<f64> = (0..n).map(|_| r.normal()).collect();
        let mean = xs.iter().sum::<f64>() / n as f64;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64;
        assert!(mean.abs() < 0.016, "mean {mean}");
        assert!((var - 1.0).abs() < 0.023, "variance {var}");
    }

    #[test]
    fn splitmix64_matches_the_reference_sequence() {
        // the first outputs for seed 0 of the reference implementation (Vigna's splitmix64.c)
        let mut r = Rng(0);
        assert_eq!(r.next_u64(), 0xE220_A839_7B1D_CDAF);
        assert_eq!(r.next_u64(), 0x6E78_9E6A_A1B9_65F4);
    }
}
