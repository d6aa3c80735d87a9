// Every workgroup writes the same summary word: the last one to run wins, and which is
// last differs between paths (nothing orders workgroups in a dispatch).
@group(0) @binding(0) var<storage, read_write> output: array<u32>;

@compute @workgroup_size(4)
fn main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) i: u32) {
    if (i == 0u) {
        output[0] = group.x + 1u; // FINDING data race on storage memory
    }
}
