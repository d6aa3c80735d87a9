// The numbers strata_select uses per pixel and frame, by sampler variant (the paper's
// Table 2): K selection positions and one resampling number, each exactly uniform on
// [0, 1) over independent renders. The WGSL counterpart of the renderer's host-side
// host/src/restir/selection_numbers.rs, with a PCG hash instead of the host's PCG stream.
//
// Needs, from the including kernel: `params: SelectionParams` and the blue-noise tables
// of restir/sampler.wgsl.

// PCG hash (Jarzynski and Olano 2020): the white noise of this module.
fn selection_hash(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// A number in [0, 1) from the top 24 bits of a hash.
fn unit_float(bits: u32) -> f32 {
    return f32(bits >> 8u) * (1.0 / 16777216.0);
}

// Largest f32 below 1: positions stay in [0, 1) after rounding.
const BELOW_ONE: f32 = 0.99999994;

// Per-pixel, per-frame white-noise stream.
var<private> white_state: u32;

fn white() -> f32 {
    white_state = selection_hash(white_state);
    return unit_float(white_state);
}

// Blue-noise value of `dimension` at `sample_index`, made exactly uniform over renders:
// the stratum k/256 is jittered within itself by white noise, and all pixels and frames
// of a render are shifted by one toroidal offset per seed and dimension.
fn blue(pixel: vec2<u32>, sample_index: u32, dimension: u32) -> f32 {
    let shift = unit_float(selection_hash(params.seed ^ selection_hash(0x5eedu + dimension)));
    let k = f32(blue_noise_stratum(pixel, sample_index, dimension));
    return min(fract((k + white()) / 256.0 + shift), BELOW_ONE);
}

// Positions in [0, 1) of the K selection slots (x: slot 0 ... w: slot 3) and, in the
// second value, the resampling number; per SelectionParams.sampler (Table 2).
struct SelectionNumbers {
    positions: vec4<f32>,
    resample: f32,
}

fn selection_numbers(pixel: vec2<u32>) -> SelectionNumbers {
    white_state = selection_hash(pixel.x ^ selection_hash(pixel.y ^ selection_hash(params.frame ^ selection_hash(params.seed))));
    let k = f32(clamp(params.candidates, 1u, MAX_SELECTED));
    let sample_index = params.frame & 255u;
    let steps = vec4<f32>(0.0, 1.0, 2.0, 3.0);
    switch params.sampler {
        case SAMPLER_RANDOM: {
            return SelectionNumbers(vec4<f32>(white(), white(), white(), white()), white());
        }
        case SAMPLER_HEITZ: {
            let first = 4u * params.frame;
            let positions = vec4<f32>(blue(pixel, first, 0u), blue(pixel, first + 1u, 0u), blue(pixel, first + 2u, 0u), blue(pixel, first + 3u, 0u));
            return SelectionNumbers(positions, blue(pixel, first, 1u));
        }
        case SAMPLER_RANDOM_OFFSET: {
            let u = white() / k;
            return SelectionNumbers(min(vec4<f32>(u) + steps / k, vec4<f32>(BELOW_ONE)), white());
        }
        case SAMPLER_RANDOM_OFFSET_BLUE_NOISE: {
            let u = blue(pixel, sample_index, 0u) / k;
            return SelectionNumbers(min(vec4<f32>(u) + steps / k, vec4<f32>(BELOW_ONE)), blue(pixel, sample_index, 1u));
        }
        default: {
            // Antithetic (Fig. 3): u in [0, 1/4), {u, 1/2 - u, 1/2 + u, 1 - u}.
            let u = blue(pixel, sample_index, 0u) * 0.25;
            let positions = vec4<f32>(u, 0.5 - u, 0.5 + u, 1.0 - u);
            return SelectionNumbers(min(positions, vec4<f32>(BELOW_ONE)), blue(pixel, sample_index, 1u));
        }
    }
}
