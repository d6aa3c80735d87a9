// One compare-and-swap step of a bitonic sort of `count` u32 keys (count a power of
// two) in storage memory: for stage k and distance j, element i and its partner
// i ^ j (i < partner) are put in ascending order when i & k == 0, descending
// otherwise. One invocation per element; only the lower of each pair does the work.
// Bindings: 0 uniform params (k, j, count, unused), 1 keys (read_write).

struct Params { k: u32, j: u32, count: u32, unused: u32 }

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read_write> keys: array<u32>;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    let partner = i ^ params.j;
    if i >= params.count || partner <= i {
        return;
    }
    let ascending = (i & params.k) == 0u;
    let a = keys[i];
    let b = keys[partner];
    if (a > b) == ascending {
        keys[i] = b;
        keys[partner] = a;
    }
}
