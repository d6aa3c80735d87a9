// A reduction that forgets half its tile: only even slots are written before the
// barrier, and every invocation reads its odd neighbour. WGSL zero-initialises the
// tile, so the result is defined, but a path that skips the zeroing reads garbage. (Its
// first draft wrote output[i] from both workgroups: the sanitizer found that race.)
@group(0) @binding(0) var<storage, read_write> output: array<u32>;

var<workgroup> tile: array<u32, 64>;

@compute @workgroup_size(64)
fn main(@builtin(local_invocation_index) i: u32, @builtin(global_invocation_id) id: vec3<u32>) {
    if (i % 2u == 0u) {
        tile[i] = i * 3u;
    }
    workgroupBarrier();
    output[id.x] = tile[i] + tile[i | 1u]; // FINDING read of workgroup memory no invocation wrote
}
