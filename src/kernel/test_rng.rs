//! The seeded generator of the kernel's unit tests: reproducible sequences without a dependency
//! (Knuth's MMIX linear congruential step, high bits).

/// A linear congruential generator.
pub(crate) struct TestRng(u64);

impl TestRng {
    /// The generator started at `seed`.
    pub(crate) fn new(seed: u64) -> Self {
        TestRng(seed)
    }

    /// Uniform in `0..m` (`m ≤ 2^31`).
    pub(crate) fn below(&mut self, m: u64) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 33) % m
    }
}
