//! The small deterministic generator the shader corpora draw their inputs from (an LCG,
//! high bits): the same inputs on every machine, so a case's numbers can be compared run
//! to run.

/// An LCG seeded with `.0`.
pub struct Rng(pub u64);

impl Rng {
    /// The next 32 random bits.
    #[allow(clippy::should_implement_trait)]
    pub fn next(&mut self) -> u32 {
        self.0 = self.0.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 32) as u32
    }

    /// A float in [lo, hi) (24 random bits).
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * ((self.next() >> 8) as f32 / (1u32 << 24) as f32)
    }
}
