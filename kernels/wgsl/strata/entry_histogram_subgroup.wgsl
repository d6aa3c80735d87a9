// Entry point of the block histogram (paper §4.1; bindings and dispatch:
// strata/histogram.wgsl; the sorting: strata/histogram_network.wgsl) that exchanges
// elements between subgroup lanes
// with subgroupShuffleXor instead of workgroup memory (needs the SUBGROUP feature).
// The lanes are used only if every lane's id is its local index modulo the subgroup
// size (true of 1-D workgroups on the drivers we know; checked here, not assumed) and
// the size is a power of two no larger than the workgroup; otherwise this entry point
// sorts exactly like the portable one.

// #import strata/histogram_network.wgsl
// #import strata/histogram_slots.wgsl

var<workgroup> lane_mismatch: atomic<u32>;
var<workgroup> lane_bits_chosen: u32;

fn lane_exchange(value: vec4<u32>, mask: u32) -> vec4<u32> {
    return subgroupShuffleXor(value, mask);
}

@compute @workgroup_size(64)
fn block_histogram_subgroup(
    @builtin(local_invocation_index) local_index: u32,
    @builtin(workgroup_id) workgroup_id: vec3<u32>,
    @builtin(subgroup_invocation_id) lane: u32,
    @builtin(subgroup_size) lanes: u32,
) {
    if local_index == 0u {
        atomicStore(&lane_mismatch, 0u);
    }
    workgroupBarrier();
    if lanes == 0u || lane != local_index % lanes {
        atomicOr(&lane_mismatch, 1u);
    }
    workgroupBarrier();
    if local_index == 0u {
        let usable = atomicLoad(&lane_mismatch) == 0u && lanes > 1u && (lanes & (lanes - 1u)) == 0u && lanes <= INVOCATIONS;
        lane_bits_chosen = select(0u, countTrailingZeros(lanes), usable);
    }
    run_block_histogram(local_index, workgroup_id, workgroupUniformLoad(&lane_bits_chosen));
}
