//! The per-pixel sampler: Heitz et al. 2019's blue-noise sampler ("A Low-Discrepancy
//! Sampler that Distributes Monte Carlo Errors as a Blue Noise in Screen Space"), one
//! Owen-scrambled Sobol sequence per pixel across frames, decorrelated between pixels by
//! an optimised XOR scrambling and ranking over a 128² tile. The tables come from the
//! `blue-noise-sampler` crate (MIT, the 256-spp variant); the GPU twin of
//! [`BlueNoiseTables::sample`] is `blue_noise_sample` in `kernels/wgsl/restir/sampler.wgsl`.
//!
//! Only dimensions 0–7 are optimised, as the 2-D pairs (0, 1), (2, 3), (4, 5), (6, 7)
//! ("OptimizedFor_2d2d2d2d"): the ranking tile is shared within a pair, so a pair at one
//! pixel is the first 256 points of a 2-D Sobol net, and the scrambling is chosen so that
//! at a fixed sample index the error is distributed as blue noise over the tile.
//! ReSTIR's selection uses the pair (0, 1) with sample index = frame mod 256.

/// Side of the square pixel tile the tables cover (pixels wrap modulo it).
pub const TILE_SIZE: u32 = 128;
/// Samples per pixel in the tables (sample indices wrap modulo it).
pub const SAMPLES: u32 = 256;
/// Dimensions of the Sobol table (dimensions wrap modulo it).
pub const DIMENSIONS: u32 = 256;
/// Dimensions with an optimised scrambling and ranking (the pairs (0, 1) … (6, 7)).
pub const OPTIMISED_DIMENSIONS: u32 = 8;

/// Names of the storage arrays `sampler.wgsl` expects, in the order of
/// [`BlueNoiseTables::buffers`].
pub const WGSL_BUFFER_NAMES: [&str; 3] = ["blue_noise_sobol", "blue_noise_scrambling", "blue_noise_ranking"];

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

    /// The three tables with the names `sampler.wgsl` gives their storage arrays.
    pub fn buffers(&self) -> [(&'static str, &[u32]); 3] {
        [
            (WGSL_BUFFER_NAMES[0], &self.sobol),
            (WGSL_BUFFER_NAMES[1], &self.scrambling),
            (WGSL_BUFFER_NAMES[2], &self.ranking),
        ]
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

/// How ReSTIR's selection draws its random numbers and places its K = 4 candidates: the
/// variants of the paper's Table 2 (ablation of histogram sampling strategies). The
/// selection kernel reads this; "temporal blue noise" means one sample of
/// [`BlueNoiseTables`] per pixel and frame, sample index = frame mod 256, dimension 0 for
/// the candidates and dimension 1 for resampling.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum SamplerVariant {
    /// Uncorrelated candidates (Table 2's "ReSTIR"): K independent uniform positions from
    /// a per-pixel, per-frame PCG stream, and a PCG number for resampling; white noise,
    /// no stratification within or across frames.
    Random,
    /// Heitz et al. 2019 with 4 samples per frame: candidate j ∈ 0..4 takes its position
    /// from dimension 0 at sample index (4·frame + j) mod 256, so a frame's 4 candidates
    /// are 4 consecutive points of the pixel's Sobol sequence (the 256-sample sequence
    /// lasts 64 frames); resampling uses dimension 1 at sample index (4·frame) mod 256.
    Heitz,
    /// Random-offset stratification with white noise: one PCG number u per pixel and
    /// frame, positions (u + j) / 4; resampling from PCG. Stratified within a frame,
    /// uncorrelated across frames.
    RandomOffset,
    /// Random offset + temporal blue noise: positions (u + j) / 4 with u from dimension 0
    /// of the blue-noise sampler at sample index frame mod 256, resampling from
    /// dimension 1.
    RandomOffsetBlueNoise,
    /// Antithetic + temporal blue noise (the paper's method, the default): u from
    /// dimension 0 at sample index frame mod 256 scaled into [0, ¼), positions
    /// {u, ½ − u, ½ + u, 1 − u} (Fig. 3); resampling from dimension 1.
    #[default]
    Antithetic,
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
        for (_, table) in tables.buffers() {
            assert!(table.iter().all(|&v| v < 256));
        }
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
