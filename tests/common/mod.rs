//! Shared test helpers.

/// A deterministic pseudo-random sequence in [-1, 1) (no extra dependency).
pub struct Lcg(pub u64);

impl Lcg {
    /// Next value.
    pub fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}
