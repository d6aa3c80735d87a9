// One texel of a sampled texture loaded into a buffer, for the tests of xtask run's
// texture flags (xtask/src/tests.rs, tests/tests/run_kernel_hostile.rs).
@group(0) @binding(0) var picture: texture_2d<f32>;
@group(0) @binding(1) var<storage, read_write> output: array<f32>;
@compute @workgroup_size(1)
fn main() {
    output[0] = textureLoad(picture, vec2<i32>(1, 0), 0).x;
}
