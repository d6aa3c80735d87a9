// The block histogram's (cluster, key) of each slot in workgroup memory, one vec2 a slot:
// the storage of the sorting network (strata/histogram_network.wgsl, run by
// strata/entry_histogram.wgsl and strata/entry_histogram_subgroup.wgsl), whose round trips
// read and write single slots in every layout. strata/histogram_slot_pairs.wgsl declares
// the reader over two slots a vec4, for the ranking (strata/histogram_rank.wgsl).
// strata/histogram.wgsl and the network reach the slots through these two functions only.

// #import gpu/strata.wgsl

var<workgroup> shared_cluster_key: array<vec2<u32>, HISTOGRAM_SLOTS_PER_WORKGROUP>;

fn slot_cluster_key(slot: u32) -> vec2<u32> {
    return shared_cluster_key[slot];
}

fn set_slot_cluster_key(slot: u32, value: vec2<u32>) {
    shared_cluster_key[slot] = value;
}
