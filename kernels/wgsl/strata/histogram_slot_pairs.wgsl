// The block histogram's (cluster, key) of each slot in workgroup memory, two slots a
// vec4 (slot 2i in .xy, slot 2i + 1 in .zw): the storage of the ranking
// (strata/histogram_rank.wgsl), whose counting loop reads every slot of its block in every
// lane. On a CPU driver such a read is one memory access per lane whatever its width
// (lavapipe cannot see that every lane reads the same slot), so reading two slots at a
// time halves the loop's accesses: the ranking at 1M candidates took 36 ms against 41 ms
// with one slot a read (docs/benchmarks/block_sort.md). The same 8 KiB as
// strata/histogram_slots.wgsl, whose reader slot_cluster_key this file declares too (for
// strata/histogram.wgsl's finishing code). It has no writer of one slot: translators may
// turn a store to one component of a vector in workgroup memory into a read-modify-write
// of the whole vector (Tint's HLSL for FXC does), so two invocations writing the two
// halves of one pair at once could lose one; the ranking writes whole pairs only.

// #import gpu/strata.wgsl

var<workgroup> shared_slot_pairs: array<vec4<u32>, HISTOGRAM_SLOTS_PER_WORKGROUP / 2u>;

// Component indices into the vec4 rather than a branch or a select on the slot's half:
// each is a single scalar access, as with strata/histogram_slots.wgsl's vec2.
fn slot_cluster_key(slot: u32) -> vec2<u32> {
    let pair = slot >> 1u;
    let half = (slot & 1u) << 1u;
    return vec2(shared_slot_pairs[pair][half], shared_slot_pairs[pair][half + 1u]);
}

// Slots 2 * pair and 2 * pair + 1: (cluster, key, cluster, key).
fn slot_pair(pair: u32) -> vec4<u32> {
    return shared_slot_pairs[pair];
}

fn set_slot_pair(pair: u32, value: vec4<u32>) {
    shared_slot_pairs[pair] = value;
}
