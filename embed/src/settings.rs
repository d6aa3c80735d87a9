//! [`SelectionSettings`]: every knob of the pass in one struct, each field with its
//! quality/cost trade-off and the paper's default.

use crate::error::EmbedError;
pub use strata_kernels::blue_noise::SamplerVariant;
use strata_kernels::types::BLOCK_SIZES;

/// Configuration of the stratified selection. `Default` is the paper's setting (§5:
/// 16 × 16 blocks, object masking, four antithetic candidates, temporal blue noise).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SelectionSettings {
    /// B: candidates are sorted per B × B block of pixels; one of 4, 8, 16, 32.
    /// Larger blocks give each cluster more candidates, hence finer strata and less
    /// noise, but join less similar pixels and cost more sorting (paper Table 1: the
    /// histogram pass is 3–10 % of the frame; Fig. 9: 16 is the best trade-off, 4 leaves
    /// blocky low-frequency error, 32 degrades slightly). Default 16.
    pub block_size: u32,
    /// K: candidates selected per pixel, 1 to 4. The antithetic pattern (Fig. 3) needs 4
    /// for its mirror pairs; fewer cost fewer shift mappings and shadow rays in the
    /// engine. Default 4.
    pub candidates: u32,
    /// Object masking (§4.3): candidates cluster by the engine's cluster id within a
    /// block, so a pixel only draws from pixels of the same object. Off, each block is
    /// one cluster: more candidates per stratum but across object boundaries, where the
    /// engine's shift mapping mostly fails. Free either way. Default on.
    pub masking: bool,
    /// Shift the block grid by a per-frame offset (the paper's limitations section: it
    /// averages block-shaped error patterns out over time). Costs nothing; changes which
    /// pixels share a histogram each frame, so the temporal history mixes blocks.
    /// Default off, as in the paper's measurements.
    pub block_shift: bool,
    /// Where in a cluster's sorted run the K candidates are taken (Table 2). Antithetic
    /// with temporal blue noise (the paper's method) has the lowest error; `Random` is
    /// plain ReSTIR's uncorrelated selection, for comparisons. Default antithetic.
    pub sampler: SamplerVariant,
    /// Seed of the render: independent renders (for example of an unbiasedness test)
    /// need different seeds; frames of one render share it. Default 0.
    pub seed: u32,
}

impl Default for SelectionSettings {
    fn default() -> Self {
        Self {
            block_size: 16,
            candidates: 4,
            masking: true,
            block_shift: false,
            sampler: SamplerVariant::Antithetic,
            seed: 0,
        }
    }
}

impl SelectionSettings {
    /// Checks every field; the error names the field and the value.
    pub fn validate(&self) -> Result<(), EmbedError> {
        if !BLOCK_SIZES.contains(&self.block_size) {
            return Err(EmbedError::Setting {
                field: "block_size",
                value: self.block_size.to_string(),
                expected: "a power of two from 4 to 32 (4, 8, 16 or 32)",
            });
        }
        if !(1..=4).contains(&self.candidates) {
            return Err(EmbedError::Setting {
                field: "candidates",
                value: self.candidates.to_string(),
                expected: "1, 2, 3 or 4",
            });
        }
        Ok(())
    }
}
