// Entry point of the block histogram without subgroup operations (any adapter, the
// GL backend and the CPU interpreter included): paper §4.1. Bindings and dispatch:
// strata/histogram.wgsl; the sorting: strata/histogram_network.wgsl.

// #import strata/histogram_network.wgsl
// #import strata/histogram_slots.wgsl

// Never called: with zero lane bits every exchange stays in registers or workgroup memory.
fn lane_exchange(value: vec4<u32>, mask: u32) -> vec4<u32> {
    return value;
}

@compute @workgroup_size(64)
fn block_histogram(
    @builtin(local_invocation_index) local_index: u32,
    @builtin(workgroup_id) workgroup_id: vec3<u32>,
) {
    run_block_histogram(local_index, workgroup_id, 0u);
}
