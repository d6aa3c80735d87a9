// Per-invocation random numbers: a PCG32 stream (O'Neill 2014, RXS-M-XS output) seeded
// by hashing (pixel, sample index, seed) with the PCG hash of Jarzynski and Olano 2020,
// so every backend draws the same numbers for the same pixel and sample.

var<private> rng_state: u32;

fn pcg_hash(value: u32) -> u32 {
    let state = value * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

fn rng_seed(pixel: u32, sample_index: u32, seed: u32) {
    rng_state = pcg_hash(pcg_hash(pcg_hash(seed) ^ pixel) ^ (sample_index * 0x9e3779b9u));
}

// Uniform in [0, 1) from the top 24 bits of the next output.
fn random() -> f32 {
    rng_state = rng_state * 747796405u + 2891336453u;
    let state = rng_state;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return f32(((word >> 22u) ^ word) >> 8u) * (1.0 / 16777216.0);
}

fn random2() -> vec2<f32> {
    let a = random();
    return vec2<f32>(a, random());
}
