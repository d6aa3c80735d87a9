// An outside-style kernel reading a fixed-size array of rows in a buffer (as a uniform
// block of records is read) with an off-by-one: three rows, indexed by every invocation
// of a 16-wide workgroup. The interpreter loads such an element in one instruction
// (element_load.rs) and clamps the index to the last row; the sanitizer reports it.
struct Rows {
    rows: array<vec4<u32>, 3>,
}

@group(0) @binding(0) var<storage, read> table: Rows;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;

@compute @workgroup_size(16)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let row = table.rows[id.x]; // FINDING out-of-range index
    output[id.x] = row.x + row.w;
}
