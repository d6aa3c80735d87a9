// The tail of one bitonic-sort stage in workgroup memory: each 128-invocation
// workgroup loads 256 consecutive keys, then for distances j = j_start, j_start / 2,
// ..., 1 (j_start <= 128) compare-and-swaps every pair (i, i | j) with bit j of i clear,
// ascending when (global index of i) & k == 0, with a workgroupBarrier after each
// distance, and writes the keys back.
// Bindings: 0 uniform params (k, j_start, count, unused), 1 keys (read_write).

struct Params { k: u32, j: u32, count: u32, unused: u32 }

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read_write> keys: array<u32>;

var<workgroup> tile: array<u32, 256>;

@compute @workgroup_size(128)
fn main(@builtin(local_invocation_index) li: u32, @builtin(workgroup_id) wg: vec3<u32>) {
    let base = wg.x * 256u;
    tile[li] = keys[base + li];
    tile[li + 128u] = keys[base + li + 128u];
    workgroupBarrier();
    for (var j = params.j; j > 0u; j = j >> 1u) {
        // The li-th pair: insert a 0 bit at j's position.
        let low = li & (j - 1u);
        let i = ((li - low) << 1u) | low;
        let partner = i | j;
        let ascending = ((base + i) & params.k) == 0u;
        let a = tile[i];
        let b = tile[partner];
        if (a > b) == ascending {
            tile[i] = b;
            tile[partner] = a;
        }
        workgroupBarrier();
    }
    keys[base + li] = tile[li];
    keys[base + li + 128u] = tile[li + 128u];
}
