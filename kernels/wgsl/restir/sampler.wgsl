// Heitz et al. 2019's blue-noise sampler (scrambled and ranked Owen-scrambled Sobol, 256
// samples over a 128² pixel tile), the GPU twin of host/src/sampler.rs: the same integer
// steps, so every backend returns the same bits as BlueNoiseTables::sample.
//
// Needs, from the including kernel: the storage arrays `blue_noise_sobol`,
// `blue_noise_scrambling` and `blue_noise_ranking`, each array<u32>, holding
// BlueNoiseTables' `sobol` (65 536 words, entry dimension + sample * 256),
// `scrambling` and `ranking` (131 072 words each, entry dimension + pixel * 8 with
// pixel = x + y * 128) as they are; binding numbers are the kernel's choice.
//
// Only dimensions 0-7 are optimised, as the pairs (0, 1), (2, 3), (4, 5), (6, 7);
// ReSTIR's selection uses (0, 1) with sample_index = frame (mod 256 is applied here).

const BLUE_NOISE_TILE: u32 = 128u;
const BLUE_NOISE_DIMENSIONS_PER_PIXEL: u32 = 8u;
const BLUE_NOISE_RANKING_WORDS: u32 = 131072u; // 128 * 128 * 8

// The stratum k in 0..=255 of the sample of `dimension` at `sample_index` for `pixel`
// (the sample is (0.5 + k) / 256). The pixel wraps to the tile, the sample index and
// dimension to 0..=255. For dimensions >= 8 the reference code reads a neighbouring
// pixel's ranking and, at the tile's last pixels, past the table: that index wraps modulo
// the table (the host does the same).
fn blue_noise_stratum(pixel: vec2<u32>, sample_index: u32, dimension: u32) -> u32 {
    let tile_pixel = (pixel.x & 127u) + (pixel.y & 127u) * BLUE_NOISE_TILE;
    let sample = sample_index & 255u;
    let dim = dimension & 255u;
    let ranking_index = (dim + tile_pixel * BLUE_NOISE_DIMENSIONS_PER_PIXEL) % BLUE_NOISE_RANKING_WORDS;
    let ranked = sample ^ blue_noise_ranking[ranking_index];
    return blue_noise_sobol[dim + ranked * 256u]
        ^ blue_noise_scrambling[(dim & 7u) + tile_pixel * BLUE_NOISE_DIMENSIONS_PER_PIXEL];
}

// The sample in (0, 1): (0.5 + k) / 256 with k = blue_noise_stratum(...).
fn blue_noise_sample(pixel: vec2<u32>, sample_index: u32, dimension: u32) -> f32 {
    return (0.5 + f32(blue_noise_stratum(pixel, sample_index, dimension))) / 256.0;
}
