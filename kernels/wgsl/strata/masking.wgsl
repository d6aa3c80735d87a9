// Object masking (paper §4.3): which cluster of its block a candidate joins.
//
// With masking, a block's candidates cluster by the object id of their pixel's first hit,
// so each object's candidates form their own run of the sorted list and a pixel draws
// only from pixels that see the same object: across object boundaries the engine's shift
// mapping mostly fails, and mixing objects would put unrelated luminances in one
// histogram. Without it, every candidate of the block joins one cluster (0): more
// candidates per stratum, across boundaries. Pixels without a candidate keep
// OBJECT_ID_NONE either way and form the block's last run, which nothing selects from.
//
// Used by strata/histogram.wgsl when it loads a candidate; host twin:
// strata_kernels::reference::block_histogram::cluster_of.

// #import strata/candidate.wgsl

fn cluster_of(candidate: Candidate, masking: bool) -> u32 {
    if masking || candidate.object_id == OBJECT_ID_NONE {
        return candidate.object_id;
    }
    return 0u;
}
