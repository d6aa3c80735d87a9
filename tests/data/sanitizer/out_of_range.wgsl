// An outside-style kernel with an off-by-one: a lookup table of 8 entries indexed by
// every invocation of a 16-wide workgroup, and a neighbour read one past the input's
// end. The interpreter clamps both indices, GPU paths read 0: WGSL allows either.
@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;

const TABLE = array<u32, 8>(1u, 2u, 3u, 5u, 8u, 13u, 21u, 34u);

@compute @workgroup_size(16)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    var table = TABLE;
    let weight = table[id.x]; // FINDING out-of-range index
    let next = input[id.x + 1u]; // FINDING out-of-range index
    output[id.x] = weight * next;
}
