// A candidate's canonical sort key. The candidate records and the histogram pass's
// outputs (Candidate, ClusterSpan, BlockStats, HistogramParams, the OBJECT_ID_* and
// INVALID_KEY constants) are declared once in Rust, kernels/src/types.rs, which
// generates gpu/strata.wgsl. Paper §4.1 (candidate keys) and §4.3 (object-id masking).

// #import gpu/strata.wgsl

// Canonical (cluster, key) of a candidate. Decided on the bit pattern alone, so every
// backend agrees whatever its denormal and NaN handling: -0 becomes +0, denormals keep
// their order, NaN / +-Inf / negative keys become INVALID_KEY. Without a branch (`&` and
// `|` on bools evaluate both sides, and `select` takes one of two values): the lanes of a
// SIMD row whose candidates are invalid, empty or zero do not diverge from the others.
// Measured against the same rules as early returns (docs/benchmarks/interpreter.md,
// sixteenth session): the interpreter's histogram bench 3.24 -> 3.05 ms; lavapipe the
// same within its noise (1M candidates: the ranking 27.6-28.3 ms either way).
fn canonical_key(candidate: Candidate) -> u32 {
    let bits = bitcast<u32>(candidate.key);
    let magnitude = bits & 0x7fffffffu;
    let negative_or_not_finite = ((bits >> 31u) != 0u) | (magnitude >= 0x7f800000u);
    let invalid = (candidate.object_id == OBJECT_ID_NONE) | ((magnitude != 0u) & negative_or_not_finite);
    return select(select(bits, 0u, magnitude == 0u), INVALID_KEY, invalid);
}
