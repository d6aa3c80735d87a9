// Candidate records and the histogram pass's outputs: the WGSL twins of the
// `#[repr(C)]` structs in `strata_kernels::types` (a test checks every offset).
// Paper §4.1 (candidate keys) and §4.3 (object-id masking).

// One candidate per pixel, written by the candidate pass or by an embedding engine.
struct Candidate {
    // Luminance of the candidate's own one-sample estimate f/p at its own pixel.
    // NaN, +-Inf and negative values mark the candidate invalid (weight 0).
    key: f32,
    // Object id of the pixel's first hit; OBJECT_ID_ENVIRONMENT for a camera ray that
    // escaped to the environment, OBJECT_ID_NONE for a pixel without a candidate.
    object_id: u32,
}

// The pixel has no candidate (no hit and no environment, or no valid path).
const OBJECT_ID_NONE: u32 = 0xffffffffu;
// The camera ray escaped: the environment is one cluster of its own.
const OBJECT_ID_ENVIRONMENT: u32 = 0xfffffffeu;
// Canonical sort key of an invalid candidate: above every finite non-negative key
// (0xffffffff is left to padding).
const INVALID_KEY: u32 = 0xfffffffeu;

// Where a pixel's cluster lies in the block's sorted candidate list.
struct ClusterSpan {
    // Index into `sorted_pixels` of the run's first candidate.
    offset: u32,
    // Candidates in the run, valid and invalid.
    length: u32,
    // The first `valid` candidates of the run are valid; the rest have weight 0.
    valid: u32,
}

// Per-block counters of the histogram pass.
struct BlockStats {
    // Distinct object ids (clusters) in the block, the no-candidate cluster included.
    clusters: u32,
    // Candidates with an object id but a NaN, infinite or negative key.
    invalid: u32,
    // Pixels without a candidate (OBJECT_ID_NONE).
    empty: u32,
}

// Sizes of one histogram dispatch, filled by the host (kernels never use num_workgroups).
struct HistogramParams {
    width: u32,
    height: u32,
    // B: blocks are B x B pixels, B in {4, 8, 16, 32}.
    block_size: u32,
    log2_block_size: u32,
    blocks_x: u32,
    blocks_y: u32,
    // Workgroups per row of the 2-D dispatch grid.
    workgroups_x: u32,
    // Block grid shift (paper §5.3) in 0..B: block edges at x = -shift_x, y = -shift_y
    // (mod B); blocks_x, blocks_y count the shifted grid.
    shift_x: u32,
    shift_y: u32,
    // 1: cluster by object id (§4.3); 0: one cluster per block.
    masking: u32,
    _pad0: u32,
    _pad1: u32,
}

// Canonical (cluster, key) of a candidate. Decided on the bit pattern alone, so every
// backend agrees whatever its denormal and NaN handling: -0 becomes +0, denormals keep
// their order, NaN / +-Inf / negative keys become INVALID_KEY.
fn canonical_key(candidate: Candidate) -> u32 {
    let bits = bitcast<u32>(candidate.key);
    let magnitude = bits & 0x7fffffffu;
    if candidate.object_id == OBJECT_ID_NONE {
        return INVALID_KEY;
    }
    if magnitude == 0u {
        return 0u;
    }
    if (bits >> 31u) != 0u || magnitude >= 0x7f800000u {
        return INVALID_KEY;
    }
    return bits;
}
