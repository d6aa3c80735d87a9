// Entry point of the block histogram by ranking (paper §4.1; strata/histogram_rank.wgsl):
// the same outputs as block_histogram, no subgroup operations. Bindings and dispatch:
// strata/histogram.wgsl.

// #import strata/histogram.wgsl
// #import strata/histogram_rank.wgsl

@compute @workgroup_size(64)
fn block_histogram_rank(
    @builtin(local_invocation_index) local_index: u32,
    @builtin(workgroup_id) workgroup_id: vec3<u32>,
) {
    run_block_histogram_ranked(local_index, workgroup_id);
}
