// The buffer contract of the embeddable selection (strata-embed): the records an engine
// and the strata_select / strata_resample kernels exchange, the WGSL twins of
// strata_kernels::embed_types (a test checks every offset and constant). An engine that
// owns its candidates, reservoirs, shift mapping and shading writes one Candidate per
// pixel (strata/candidate.wgsl: luminance key + cluster id) and optionally one payload
// index per pixel; the histogram pass sorts each block; strata_select gives every pixel K
// payload indices of its own cluster's run at stratified positions; strata_resample,
// given the engine's resampling weights, picks one by inverse CDF (paper §4.2, whose
// functions are in strata/selection.wgsl). Self-contained with strata/candidate.wgsl, so
// that an engine can prepend both to its own shaders (strata_embed::wgsl::contract_source).

// #import strata/candidate.wgsl

// A slot without a candidate, or a pixel without a selection.
const NO_PAYLOAD: u32 = 0xffffffffu;
// ResampleOutput.slot: the pixel's own (canonical) sample was chosen (the slot after the
// most selected ones, MAX_SELECTED of strata/selection.wgsl).
const CANONICAL_SLOT: u32 = 4u;
// ResampleOutput.slot: every weight was zero; nothing chosen.
const NO_SLOT: u32 = 0xffffffffu;
// ResampleOutput.slot: a weight or target was NaN, infinite or negative; nothing chosen.
const INVALID_SLOT: u32 = 0xfffffffeu;

// Per-frame settings of strata_select and strata_resample (a uniform).
struct SelectionParams {
    width: u32,
    height: u32,
    // Frame index: the blue-noise sample index is frame mod 256.
    frame: u32,
    // Render seed: decorrelates independent renders (white jitter, one toroidal shift).
    seed: u32,
    // K in 1..=4.
    candidates: u32,
    // The sampler variant (SAMPLER_* of strata/selection.wgsl: 0 random, 1 heitz,
    // 2 random offset, 3 random offset + blue noise, 4 antithetic).
    sampler: u32,
    // 1: payload = pixel index (the payloads buffer is not read).
    identity_payload: u32,
    _pad: u32,
}

// What strata_select gives each pixel.
struct SelectedCandidates {
    // The K selected payloads (slots >= K and empty runs: NO_PAYLOAD).
    payloads: vec4<u32>,
    // The pixel's resampling number in [0, 1) for this frame (used by strata_resample).
    resample_number: f32,
    // n: candidates in the pixel's cluster run (0 for a pixel without a candidate).
    run_length: u32,
    // Valid candidates of the run (finite, non-negative keys), which come first.
    run_valid: u32,
    // Slots filled: K, or 0.
    selected: u32,
}

// What the engine gives strata_resample per pixel: resampling weights (MIS weight times
// target times unbiased contribution weight, from its own shift mapping) and target values
// at this pixel of each selected sample and of its own canonical sample.
struct ResampleInput {
    weights: vec4<f32>,
    targets: vec4<f32>,
    canonical_weight: f32,
    canonical_target: f32,
    canonical_payload: u32,
    _pad: u32,
}

// What strata_resample gives each pixel.
struct ResampleOutput {
    // The chosen sample's payload (NO_PAYLOAD when nothing was chosen).
    payload: u32,
    // Its slot 0..K-1, CANONICAL_SLOT, NO_SLOT or INVALID_SLOT.
    slot: u32,
    // Unbiased contribution weight W = (sum of weights) / target of the chosen sample.
    weight: f32,
    // Sum of the weights.
    weight_sum: f32,
}
