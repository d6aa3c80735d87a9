//! The per-pixel sampler: Heitz et al. 2019's blue-noise sampler ("A Low-Discrepancy
//! Sampler that Distributes Monte Carlo Errors as a Blue Noise in Screen Space"), one
//! Owen-scrambled Sobol sequence per pixel across frames, decorrelated between pixels by
//! an optimised XOR scrambling and ranking over a 128² tile. The tables come from the
//! `blue-noise-sampler` crate (MIT, the 256-spp variant); the GPU twin of
//! [`BlueNoiseTables::stratum`] is `blue_noise_stratum` in `kernels/wgsl/strata/blue_noise.wgsl`,
//! which reads the three tables from one buffer ([`BlueNoiseTables::packed`]).
//!
//! Only dimensions 0–7 are optimised, as the 2-D pairs (0, 1), (2, 3), (4, 5), (6, 7)
//! ("OptimizedFor_2d2d2d2d"): the ranking tile is shared within a pair, so a pair at one
//! pixel is the first 256 points of a 2-D Sobol net, and the scrambling is chosen so that
//! at a fixed sample index the error is distributed as blue noise over the tile.
//! The selection (Table 2's temporal blue noise) uses the pair (0, 1) for its spatial
//! slots and (2, 3) for its temporal ones, with sample index = frame mod 256.

/// Samples per pixel in the tables (sample indices wrap modulo it).
pub const SAMPLES: u32 = 256;
/// Dimensions of the Sobol table (dimensions wrap modulo it).
pub const DIMENSIONS: u32 = 256;

crate::gpu::gpu_constants! {
    fn constants;
    /// Side of the square pixel tile the tables cover (pixels wrap modulo it).
    pub const TILE_SIZE: u32 as "BLUE_NOISE_TILE" = 128;
    /// Dimensions with an optimised scrambling and ranking (the pairs (0, 1) ... (6, 7)):
    /// the entries per pixel of the scrambling and ranking tables.
    pub const OPTIMISED_DIMENSIONS: u32 as "BLUE_NOISE_DIMENSIONS_PER_PIXEL" = 8;
    /// Word offset of the Sobol table (entry dimension + sample * 256) in the packed
    /// tables (`BlueNoiseTables::packed`).
    pub const PACKED_SOBOL: u32 as "BLUE_NOISE_SOBOL" = 0;
    /// Word offset of the scrambling table (entry dimension + pixel * 8, pixel = x + y * 128).
    pub const PACKED_SCRAMBLING: u32 as "BLUE_NOISE_SCRAMBLING" = SAMPLES * DIMENSIONS;
    /// Word offset of the ranking table (laid out as the scrambling table).
    pub const PACKED_RANKING: u32 as "BLUE_NOISE_RANKING" = PACKED_SCRAMBLING + RANKING_WORDS;
    /// Words of the ranking (and of the scrambling) table: 128 * 128 * 8.
    pub const RANKING_WORDS: u32 as "BLUE_NOISE_RANKING_WORDS" = TILE_SIZE * TILE_SIZE * OPTIMISED_DIMENSIONS;
}
/// Words of [`BlueNoiseTables::packed`].
pub const PACKED_WORDS: u32 = PACKED_RANKING + RANKING_WORDS;
/// Name of the storage array `blue_noise.wgsl` reads the packed tables from.
pub const WGSL_BUFFER_NAME: &str = "blue_noise";

/// Heitz et al. 2019's three 256-spp tables, widened to `u32` so that they upload as
/// `array<u32>` as they are. Every entry is in 0..=255.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BlueNoiseTables {
    /// The Owen-scrambled Sobol sequence, sample-major: entry `dimension + sample * 256`
    /// (256 samples × 256 dimensions = 65 536 words). Each value v stands for
    /// (v + 0.5) / 256.
    pub sobol: Vec<u32>,
    /// Per-pixel XOR scrambling of the optimised dimensions: entry
    /// `(dimension % 8) + (x + y * 128) * 8` (128² pixels × 8 = 131 072 words).
    pub scrambling: Vec<u32>,
    /// Per-pixel XOR ranking of the sample index: entry `dimension + (x + y * 128) * 8`
    /// (131 072 words; the two dimensions of a pair hold the same value). The reference
    /// code indexes it without `% 8`, so dimensions ≥ 8 read a neighbouring pixel's
    /// entries; see [`BlueNoiseTables::stratum`] for the one place that leaves the table.
    pub ranking: Vec<u32>,
}

impl Default for BlueNoiseTables {
    fn default() -> Self {
        Self::new()
    }
}

impl BlueNoiseTables {
    /// Copies the crate's 256-spp tables.
    pub fn new() -> Self {
        use blue_noise_sampler::spp256::{RANKING_TILE, SCRAMBLING_TILE, SOBOL};
        let widen = |table: &[i32]| -> Vec<u32> {
            table.iter().map(|&v| u32::try_from(v).expect("blue-noise table entries are in 0..=255")).collect()
        };
        let tables = Self { sobol: widen(SOBOL), scrambling: widen(SCRAMBLING_TILE), ranking: widen(RANKING_TILE) };
        debug_assert_eq!(tables.sobol.len(), (SAMPLES * DIMENSIONS) as usize);
        debug_assert_eq!(tables.scrambling.len(), (TILE_SIZE * TILE_SIZE * OPTIMISED_DIMENSIONS) as usize);
        debug_assert_eq!(tables.ranking.len(), (TILE_SIZE * TILE_SIZE * OPTIMISED_DIMENSIONS) as usize);
        tables
    }

    /// The three tables in one buffer, as `blue_noise.wgsl` reads them: Sobol at
    /// [`PACKED_SOBOL`], scrambling at [`PACKED_SCRAMBLING`], ranking at
    /// [`PACKED_RANKING`] ([`PACKED_WORDS`] words, 1.25 MiB).
    pub fn packed(&self) -> Vec<u32> {
        [self.sobol.as_slice(), &self.scrambling, &self.ranking].concat()
    }

    /// The stratum k ∈ 0..=255 of a sample, the sample being (k + 0.5) / 256: the
    /// paper's reference code step by step. The pixel wraps to the 128² tile, the sample
    /// index and dimension to 0..=255; ranked index = sample ^ ranking[dimension +
    /// (x + y·128)·8]; k = sobol[dimension + ranked·256] ^ scrambling[dimension % 8 +
    /// (x + y·128)·8].
    ///
    /// The one departure: the reference reads past the ranking table for dimensions ≥ 8
    /// at the last pixels of the tile (index up to 131 319 of 131 072); here that index
    /// wraps modulo the table's length, which changes nothing wherever the reference
    /// stays inside the table. The WGSL twin wraps the same way.
    pub fn stratum(&self, pixel_x: u32, pixel_y: u32, sample_index: u32, dimension: u32) -> u32 {
        let pixel = (pixel_x % TILE_SIZE + (pixel_y % TILE_SIZE) * TILE_SIZE) as usize;
        let sample = (sample_index % SAMPLES) as usize;
        let dimension = (dimension % DIMENSIONS) as usize;
        let per_pixel = OPTIMISED_DIMENSIONS as usize;
        let ranking_index = (dimension + pixel * per_pixel) % self.ranking.len();
        let ranked = sample ^ self.ranking[ranking_index] as usize;
        let value = self.sobol[dimension + ranked * DIMENSIONS as usize];
        value ^ self.scrambling[dimension % per_pixel + pixel * per_pixel]
    }

    /// The sample in (0, 1) of `dimension` at `sample_index` for a pixel: (0.5 + k) / 256
    /// with k = [`Self::stratum`], exact in `f32`.
    pub fn sample(&self, pixel_x: u32, pixel_y: u32, sample_index: u32, dimension: u32) -> f32 {
        (0.5 + self.stratum(pixel_x, pixel_y, sample_index, dimension) as f32) / 256.0
    }
}

/// The WGSL module `gpu/blue_noise.wgsl`: where `strata/blue_noise.wgsl` finds each table
/// in the packed buffer ([`crate::gpu`]).
pub fn gpu_module() -> crate::gpu::GpuModule {
    crate::gpu::GpuModule {
        path: "gpu/blue_noise.wgsl",
        source: "kernels/src/blue_noise.rs",
        readers: None,
        constants: constants(),
        structs: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sampler_tables_have_the_reference_shape() {
        let tables = BlueNoiseTables::new();
        assert_eq!(tables.sobol.len(), 256 * 256);
        assert_eq!(tables.scrambling.len(), 128 * 128 * 8);
        assert_eq!(tables.ranking.len(), 128 * 128 * 8);
        let packed = tables.packed();
        assert_eq!(packed.len(), PACKED_WORDS as usize);
        assert!(packed.iter().all(|&v| v < 256));
        assert_eq!(packed[PACKED_SCRAMBLING as usize..PACKED_RANKING as usize], tables.scrambling[..]);
        assert_eq!(packed[PACKED_RANKING as usize..], tables.ranking[..]);
        // The ranking is shared within each optimised pair.
        assert!(tables.ranking.chunks_exact(2).all(|pair| pair[0] == pair[1]));
    }

    #[test]
    fn sampler_arguments_wrap() {
        let tables = BlueNoiseTables::new();
        for (x, y, s, d) in [(3, 5, 7, 1), (0, 127, 255, 0), (127, 127, 255, 255), (64, 0, 100, 9)] {
            let want = tables.sample(x, y, s, d);
            assert_eq!(tables.sample(x + 128, y + 256, s + 256, d + 256), want);
            assert!(want > 0.0 && want < 1.0);
        }
    }
}
