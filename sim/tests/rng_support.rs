//! The reproducible random draws the integration tests share (`hybrid_jacobian.rs`,
//! `current_columns.rs`, `targets.rs`): a 64-bit linear congruential generator with Knuth's MMIX
//! constants, its top 53 bits as a double.

/// A reproducible generator: the same seed gives the same draws on every machine.
pub struct Lcg(pub u64);

impl Lcg {
    /// A uniform draw in [0, 1).
    pub fn unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A uniform draw in [−1, 1).
    pub fn next(&mut self) -> f64 {
        self.unit() * 2.0 - 1.0
    }
}
