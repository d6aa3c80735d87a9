// The stratified selection (paper §4.2, Fig. 3, Table 2): where in its cluster's sorted
// run (strata/histogram.wgsl) a pixel takes its K candidates, and the numbers that place
// them and drive the final resampling, for every sampler variant. The one statement of
// §4.2's selection on the GPU: the renderer's restir_select and restir_temporal and the
// embeddable strata_select call these functions. The resampling step that uses the second
// number, an inverse-CDF choice, is strata/resampling.wgsl.
//
// Positions. A pixel takes slot j of K at position p_j in [0, 1) of its run of n sorted
// candidates: index offset + min(floor(p_j n), n - 1). The sampler variants (Table 2):
//   random           K independent white-noise positions (plain ReSTIR's selection)
//   heitz            K consecutive samples of the pixel's blue-noise sequence per frame
//   random-offset    (j + b) / K, b white noise: one position per stratum of width 1/K
//   random-offset-blue-noise  the same with b from the temporal blue noise
//   quad-antithetic  antithetic, b = b_q + q/4 mod 1: the 2 x 2 quad's blue noise b_q,
//                    q the pixel's place in the quad turned by one each frame, so the
//                    quad's pixels take complementary quarters of every stratum
//   antithetic       b from the temporal blue noise, mirrored pairs (Fig. 3):
//                      K = 4: {b, 2 - b, 2 + b, 4 - b} / 4 (u, 1/2 - u, 1/2 + u, 1 - u)
//                      K = 3: {b, 1 + b, 3 - b} / 3   (one pair on the outer strata,
//                                                      the middle stratum by offset)
//                      K = 2: {b, 2 - b} / 2          (v, 1 - v)
//                      K = 1: {b}
// Every stratified pattern is position_j = (offset_j + sign_j b) / K with each
// position sweeping its own stratum [j/K, (j+1)/K) as b sweeps [0, 1) (the host's
// statement of this table: strata_kernels::selection::patterns).
//
// Why it stays unbiased. Each position is uniform on [0, 1) over independent renders:
// blue-noise values (k + 0.5)/256 become (k + xi)/256 with xi white per pixel and frame,
// and all pixels and frames of a render are shifted by one toroidal offset per seed and
// dimension. The K positions of a stratified pattern tile [0, 1) exactly once, and the
// independent ones are each uniform, so every member of a run of n is selected K/n times
// in expectation whatever the order of the keys: a resampling that normalises by a fixed
// 1/K with pair terms depending only on (canonical, neighbour) stays unbiased. (The
// first K of the 4-slot antithetic pattern would not: K = 2 would never reach the upper
// half of a run.)
//
// Dimensions. The spatial slots use the sampler's dimension pair (0, 1) (position,
// resampling number), the temporal slots of the paper's Fig. 11 the pair (2, 3): pass
// `pair` 0 or 1. Blue-noise sample index: frame mod 256 (heitz: K frame + j).
//
// Needs, from the including kernel: `blue_noise: array<u32>` (strata/blue_noise.wgsl).

// #import gpu/selection.wgsl
// #import strata/candidate.wgsl
// #import strata/blue_noise.wgsl
// #import strata/resampling.wgsl

// PCG hash (Jarzynski and Olano 2020): the white noise of the selection.
fn selection_hash(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// A number in [0, 1) from the top 24 bits of a hash.
fn unit_float(bits: u32) -> f32 {
    return f32(bits >> 8u) * (1.0 / 16777216.0);
}

// The white-noise stream of one pixel, frame, render and dimension pair.
var<private> selection_white_state: u32;

fn selection_white() -> f32 {
    selection_white_state = selection_hash(selection_white_state);
    return unit_float(selection_white_state);
}

// Blue-noise value of `dimension` at `sample_index`, made exactly uniform over renders:
// the stratum k/256 is jittered within itself by white noise, and all pixels and frames
// of the render `seed` are shifted by one toroidal offset per dimension.
fn selection_blue(pixel: vec2<u32>, sample_index: u32, dimension: u32, seed: u32) -> f32 {
    let shift = unit_float(selection_hash(seed ^ selection_hash(0x5eedu + dimension)));
    let k = f32(blue_noise_stratum(pixel, sample_index, dimension));
    return min(fract((k + selection_white()) / 256.0 + shift), BELOW_ONE);
}

// The K positions of a stratified pattern from its one number b in [0, 1):
// (offset_j + sign_j b) / K per slot (slots >= K are unused). `sampler` is
// SAMPLER_ANTITHETIC (mirrored pairs) or one of the random offsets.
fn stratified_positions(b: f32, sampler: u32, count: u32) -> vec4<f32> {
    var offsets = vec4<f32>(0.0, 1.0, 2.0, 3.0);
    var signs = vec4<f32>(1.0);
    if sampler == SAMPLER_ANTITHETIC || sampler == SAMPLER_QUAD_ANTITHETIC {
        switch count {
            case 4u: {
                offsets = vec4<f32>(0.0, 2.0, 2.0, 4.0);
                signs = vec4<f32>(1.0, -1.0, 1.0, -1.0);
            }
            case 3u: {
                offsets = vec4<f32>(0.0, 1.0, 3.0, 0.0);
                signs = vec4<f32>(1.0, 1.0, -1.0, 0.0);
            }
            case 2u: {
                offsets = vec4<f32>(0.0, 2.0, 0.0, 0.0);
                signs = vec4<f32>(1.0, -1.0, 0.0, 0.0);
            }
            default: {
                offsets = vec4<f32>(0.0);
                signs = vec4<f32>(1.0, 0.0, 0.0, 0.0);
            }
        }
    }
    // signs * b is exact, so a fused multiply-add gives the same bits.
    return min((offsets + signs * b) / f32(count), vec4<f32>(BELOW_ONE));
}

// What one pixel uses in one frame: the positions of its K slots (x: slot 0 ... w:
// slot 3) and its resampling number, each in [0, 1).
struct SelectionNumbers {
    positions: vec4<f32>,
    resample: f32,
}

// The selection numbers of `count` slots (clamped to 1..=4) of `pixel` in frame `frame`
// of the render `seed`, for sampler variant `sampler`, from the sampler's dimension pair
// `pair` (0: spatial, 1: temporal).
fn selection_numbers(pixel: vec2<u32>, frame: u32, seed: u32, sampler: u32, count: u32, pair: u32) -> SelectionNumbers {
    selection_white_state = selection_hash(pixel.x ^ selection_hash(pixel.y ^ selection_hash(frame ^ selection_hash(seed + pair * 0x9e3779b9u))));
    let k = clamp(count, 1u, MAX_SELECTED);
    let position_dimension = 2u * pair;
    let resample_dimension = position_dimension + 1u;
    let sample_index = frame & 255u;
    switch sampler {
        case SAMPLER_RANDOM: {
            return SelectionNumbers(vec4<f32>(selection_white(), selection_white(), selection_white(), selection_white()), selection_white());
        }
        case SAMPLER_HEITZ: {
            let first = k * frame;
            let positions = vec4<f32>(
                selection_blue(pixel, first, position_dimension, seed),
                selection_blue(pixel, first + 1u, position_dimension, seed),
                selection_blue(pixel, first + 2u, position_dimension, seed),
                selection_blue(pixel, first + 3u, position_dimension, seed),
            );
            return SelectionNumbers(positions, selection_blue(pixel, first, resample_dimension, seed));
        }
        case SAMPLER_RANDOM_OFFSET: {
            let b = selection_white();
            return SelectionNumbers(stratified_positions(b, sampler, k), selection_white());
        }
        case SAMPLER_QUAD_ANTITHETIC: {
            let quad = pixel / 2u;
            let place = ((pixel.x & 1u) + 2u * (pixel.y & 1u) + frame) & 3u;
            let b = min(fract(selection_blue(quad, sample_index, position_dimension, seed) + f32(place) * 0.25), BELOW_ONE);
            return SelectionNumbers(stratified_positions(b, sampler, k), selection_blue(pixel, sample_index, resample_dimension, seed));
        }
        default: {
            // SAMPLER_RANDOM_OFFSET_BLUE_NOISE and SAMPLER_ANTITHETIC.
            let b = selection_blue(pixel, sample_index, position_dimension, seed);
            return SelectionNumbers(stratified_positions(b, sampler, k), selection_blue(pixel, sample_index, resample_dimension, seed));
        }
    }
}

// Index into the sorted list of the member at `position` in [0, 1) of the run `span`
// (which must not be empty).
fn run_member(span: ClusterSpan, position: f32) -> u32 {
    let n = span.length;
    return span.offset + min(u32(floor(position * f32(n))), n - 1u);
}
