// A shift through workgroup memory that forgot its barrier: each invocation writes its
// slot, then reads its neighbour's, which another invocation writes with nothing
// between the two.
@group(0) @binding(0) var<storage, read_write> output: array<u32>;

var<workgroup> tile: array<u32, 64>;

@compute @workgroup_size(64)
fn main(@builtin(local_invocation_index) i: u32) {
    tile[i] = i * 7u;
    output[i] = tile[(i + 1u) % 64u]; // FINDING data race on workgroup memory
}
