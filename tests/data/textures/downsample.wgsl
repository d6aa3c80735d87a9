// A 2x downsample as engines write it: each output texel samples the source through a
// linear sampler at the centre of its 2 x 2 footprint and stores rgba8unorm.
// Written for strata's texture corpus (issue 42); `cargo xtask run` runs it on a PNG.
//
// Bindings (group 0): 0 `source` texture_2d<f32>; 1 `bilinear` sampler; 2 `half_size`
// texture_storage_2d<rgba8unorm, write>, half the source's size (rounded down).
// Dispatch: (ceil(width / 2 / 8), ceil(height / 2 / 8), 1).

@group(0) @binding(0) var source: texture_2d<f32>;
@group(0) @binding(1) var bilinear: sampler;
@group(0) @binding(2) var half_size: texture_storage_2d<rgba8unorm, write>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(half_size);
    if (any(id.xy >= size)) {
        return;
    }
    let uv = (vec2<f32>(id.xy) * 2.0 + 1.0) / vec2<f32>(textureDimensions(source));
    textureStore(half_size, id.xy, textureSampleLevel(source, bilinear, uv, 0.0));
}
