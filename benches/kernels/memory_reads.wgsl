// What one vec4 read costs a kernel, by where it reads from (benches/benches/memory_reads.rs).
// Every entry point runs the same chain of 64 dependent steps per invocation: read one
// vec4<u32> of a 4096-entry table (64 KiB), fold it into a hash that picks the next entry.
// Only the memory the table lives in and whether the lanes read the same entry differ, so
// the difference from `no_reads` (the same chain with the vec4 computed instead of read) is
// the reads' own cost. Each entry point writes the chain out: with one step function shared
// by all (the index and total as a vec2 state), the chain itself took lavapipe twice as long
// (no_reads 1.72 ms against 0.83), which blurs the reads' cost.
//
// Bindings (group 0):
//   0 storage, read   array<vec4<u32>>          table_storage: the table
//   1 uniform         array<vec4<u32>, 4096>    table_uniform: the same table
//   2 texture_2d<f32>                           table_texture: the same table, 64 x 64 rgba32float texels (read as bits)
//   3 storage, rw     array<u32>                sink: one word per invocation, so nothing is optimised away
//
// Dispatch: 64 invocations per workgroup, one-dimensional.

@group(0) @binding(0) var<storage, read> table_storage: array<vec4<u32>>;
@group(0) @binding(1) var<uniform> table_uniform: array<vec4<u32>, 4096>;
@group(0) @binding(2) var table_texture: texture_2d<f32>;
@group(0) @binding(3) var<storage, read_write> sink: array<u32>;

// The table in workgroup memory (filled from the storage table first).
var<workgroup> table_shared: array<vec4<u32>, 1024>;

const STEPS: u32 = 64u;

// The next entry's index from the current one and what was read there (PCG's output mix).
fn next_index(index: u32, value: vec4<u32>) -> u32 {
    var v = (index ^ value.y) * 747796405u + 2891336453u;
    v = ((v >> ((v >> 28u) + 4u)) ^ v) * 277803737u;
    return ((v >> 22u) ^ v) + value.z;
}

// Each lane its own entries (as rays traversing a BVH read their own nodes).
@compute @workgroup_size(64)
fn storage_divergent(@builtin(global_invocation_id) id: vec3<u32>) {
    var index = id.x;
    var total = 0u;
    for (var step = 0u; step < STEPS; step++) {
        let value = table_storage[index & 4095u];
        total += value.x ^ value.w;
        index = next_index(index, value);
    }
    sink[id.x] = total;
}

// Every lane the same entry: the index depends on the step alone.
@compute @workgroup_size(64)
fn storage_same_entry(@builtin(global_invocation_id) id: vec3<u32>) {
    var index = id.x;
    var total = 0u;
    for (var step = 0u; step < STEPS; step++) {
        let value = table_storage[(step * 97u) & 4095u];
        total += value.x ^ value.w;
        index = next_index(index, value);
    }
    sink[id.x] = total + index;
}

@compute @workgroup_size(64)
fn uniform_divergent(@builtin(global_invocation_id) id: vec3<u32>) {
    var index = id.x;
    var total = 0u;
    for (var step = 0u; step < STEPS; step++) {
        let value = table_uniform[index & 4095u];
        total += value.x ^ value.w;
        index = next_index(index, value);
    }
    sink[id.x] = total;
}

@compute @workgroup_size(64)
fn texture_divergent(@builtin(global_invocation_id) id: vec3<u32>) {
    var index = id.x;
    var total = 0u;
    for (var step = 0u; step < STEPS; step++) {
        let entry = index & 4095u;
        let value = bitcast<vec4<u32>>(textureLoad(table_texture, vec2<u32>(entry & 63u, entry >> 6u), 0));
        total += value.x ^ value.w;
        index = next_index(index, value);
    }
    sink[id.x] = total;
}

// The first 1024 entries copied to workgroup memory, then read as storage_divergent reads.
@compute @workgroup_size(64)
fn workgroup_divergent(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    for (var entry = lane; entry < 1024u; entry += 64u) {
        table_shared[entry] = table_storage[entry];
    }
    workgroupBarrier();
    var index = id.x;
    var total = 0u;
    for (var step = 0u; step < STEPS; step++) {
        let value = table_shared[index & 1023u];
        total += value.x ^ value.w;
        index = next_index(index, value);
    }
    sink[id.x] = total;
}

// As workgroup_divergent, every lane the same entry (as the block histogram's ranking reads).
@compute @workgroup_size(64)
fn workgroup_same_entry(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    for (var entry = lane; entry < 1024u; entry += 64u) {
        table_shared[entry] = table_storage[entry];
    }
    workgroupBarrier();
    var index = id.x;
    var total = 0u;
    for (var step = 0u; step < STEPS; step++) {
        let value = table_shared[(step * 97u) & 1023u];
        total += value.x ^ value.w;
        index = next_index(index, value);
    }
    sink[id.x] = total + index;
}

// The same chain with the vec4 computed from the index: the steps' own cost.
@compute @workgroup_size(64)
fn no_reads(@builtin(global_invocation_id) id: vec3<u32>) {
    var index = id.x;
    var total = 0u;
    for (var step = 0u; step < STEPS; step++) {
        let value = vec4<u32>(index, index * 3u, index + 7u, index ^ 5u);
        total += value.x ^ value.w;
        index = next_index(index, value);
    }
    sink[id.x] = total;
}

// The workgroup entries' fill followed by no_reads' chain: what the two workgroup entry
// points cost besides their reads.
@compute @workgroup_size(64)
fn workgroup_fill(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    for (var entry = lane; entry < 1024u; entry += 64u) {
        table_shared[entry] = table_storage[entry];
    }
    workgroupBarrier();
    var index = id.x;
    var total = table_shared[lane].x;
    for (var step = 0u; step < STEPS; step++) {
        let value = vec4<u32>(index, index * 3u, index + 7u, index ^ 5u);
        total += value.x ^ value.w;
        index = next_index(index, value);
    }
    sink[id.x] = total;
}
