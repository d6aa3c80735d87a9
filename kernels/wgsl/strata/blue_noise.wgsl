// Heitz et al. 2019's blue-noise sampler (scrambled and ranked Owen-scrambled Sobol, 256
// samples over a 128² pixel tile): the temporal blue noise of the paper's Table 2. The
// GPU twin of strata_kernels::blue_noise::BlueNoiseTables::stratum: the same integer
// steps, so every backend returns the same bits as the host.
//
// Needs, from the including kernel: `blue_noise: array<u32>`, BlueNoiseTables::packed()
// as it is: the Sobol table (65 536 words, entry dimension + sample * 256) at
// BLUE_NOISE_SOBOL, the scrambling and ranking tables (131 072 words each, entry
// dimension + pixel * 8 with pixel = x + y * 128) at BLUE_NOISE_SCRAMBLING and
// BLUE_NOISE_RANKING. One buffer rather than three keeps the renderer's largest pass
// within 16 storage buffers (OpenGL's usual per-stage limit).
//
// Only dimensions 0-7 are optimised, as the pairs (0, 1), (2, 3), (4, 5), (6, 7); the
// selection uses (0, 1) for its spatial slots and (2, 3) for its temporal ones.

// #import gpu/blue_noise.wgsl
// #requires var<storage, read> blue_noise: array<u32>


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
    let ranked = sample ^ blue_noise_word(BLUE_NOISE_RANKING + ranking_index);
    return blue_noise_word(BLUE_NOISE_SOBOL + dim + ranked * 256u)
        ^ blue_noise_word(BLUE_NOISE_SCRAMBLING + (dim & 7u) + tile_pixel * BLUE_NOISE_DIMENSIONS_PER_PIXEL);
}

// Word `index` of the tables, or 0 past the end of a truncated buffer (an engine's
// mistake: the samples are then wrong but nothing outside the buffer is read).
fn blue_noise_word(index: u32) -> u32 {
    if index < arrayLength(&blue_noise) {
        return blue_noise[index];
    }
    return 0u;
}

// The sample in (0, 1): (0.5 + k) / 256 with k = blue_noise_stratum(...).
fn blue_noise_sample(pixel: vec2<u32>, sample_index: u32, dimension: u32) -> f32 {
    return (0.5 + f32(blue_noise_stratum(pixel, sample_index, dimension))) / 256.0;
}
