// A loop whose condition never changes: `x` is read once and never written in the
// loop. Every workgroup runs it (the interpreter runs several on parallel threads).
@group(0) @binding(0) var<storage, read_write> data: array<u32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let x = data[id.x];
    var steps = 0u;
    while (x < 10u) { // FINDING time limit
        steps += 1u;
    }
    data[id.x] = steps;
}
