// Workgroup memory as outside kernels use it, trusting WGSL's promise that it starts
// zeroed: a counter nobody initialises, a 2-D array of vectors of which only some
// elements are written, and a struct with an array member. Each workgroup writes what it
// counted and read; every path must give 64 and zeros (the glslang HLSL path once gave
// garbage, and Slang refused naga's zeroing of the 2-D array).
struct Totals {
    seen: u32,
    bins: array<u32, 4>,
}

var<workgroup> counter: atomic<u32>;
var<workgroup> tile: array<array<vec3<f32>, 16>, 4>;
var<workgroup> totals: Totals;

@group(0) @binding(0) var<storage, read_write> counts: array<u32>;
@group(0) @binding(1) var<storage, read_write> untouched: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(local_invocation_index) local: u32, @builtin(workgroup_id) group: vec3<u32>) {
    atomicAdd(&counter, 1u);
    // Only the first row of the tile is written; the other rows must read as zero.
    if (local < 16u) {
        tile[0][local] = vec3<f32>(f32(local) + 1.0);
    }
    workgroupBarrier();
    if (local == 0u) {
        var sum = vec3<f32>(0.0);
        for (var row = 1u; row < 4u; row++) {
            for (var column = 0u; column < 16u; column++) {
                sum += tile[row][column];
            }
        }
        counts[group.x * 3u] = atomicLoad(&counter);
        counts[group.x * 3u + 1u] = totals.seen + totals.bins[0] + totals.bins[3];
        counts[group.x * 3u + 2u] = u32(tile[0][15].x);
        untouched[group.x] = sum.x + sum.y + sum.z;
    }
}
