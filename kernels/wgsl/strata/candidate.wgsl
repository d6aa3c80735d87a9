// A candidate's canonical sort key. The candidate records and the histogram pass's
// outputs (Candidate, ClusterSpan, BlockStats, HistogramParams, the OBJECT_ID_* and
// INVALID_KEY constants) are declared once in Rust, kernels/src/types.rs, which
// generates gpu/strata.wgsl. Paper §4.1 (candidate keys) and §4.3 (object-id masking).

// #import gpu/strata.wgsl

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
