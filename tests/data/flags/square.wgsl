// A one-line kernel for the tests of xtask run's flags (xtask/src/tests.rs,
// tests/tests/run_kernel_hostile.rs): each output word is its input squared plus its index.
@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    output[id.x] = input[id.x] * input[id.x] + id.x;
}
