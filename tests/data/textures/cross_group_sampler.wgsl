// A horizontal blur laid out as engines lay out image passes: the sampler in a bind group
// of shared state (group 0), the image and the result in the pass's own group (group 1),
// and a depth texture read with textureLoad in a third (group 2). wgpu once decided
// filterability per group and refused it ("Non-filterable float textures can't be sampled
// with a filtering sampler"); it is decided per texture across groups now. The r32float
// depth stays unfilterable (only loaded), as devices without float32 filtering need.
// Written for strata's texture corpus (issue 58).
//
// Bindings: group 0: 0 `linear_clamp` sampler; group 1: 0 `image` texture_2d<f32>,
// 1 `result` texture_storage_2d<rgba8unorm, write> of the image's size;
// group 2: 0 `depth` texture_2d<f32> (r32float) of the image's size.
// Dispatch: (ceil(width / 8), ceil(height / 8), 1).

@group(0) @binding(0) var linear_clamp: sampler;
@group(1) @binding(0) var image: texture_2d<f32>;
@group(1) @binding(1) var result: texture_storage_2d<rgba8unorm, write>;
@group(2) @binding(0) var depth: texture_2d<f32>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(image);
    if (any(id.xy >= size)) {
        return;
    }
    let texel = 1.0 / vec2<f32>(size);
    let centre = (vec2<f32>(id.xy) + 0.5) * texel;
    var sum = vec4<f32>(0.0);
    for (var i = -2; i <= 2; i++) {
        sum += textureSampleLevel(image, linear_clamp, centre + vec2<f32>(f32(i) * texel.x, 0.0), 0.0);
    }
    let near = textureLoad(depth, id.xy, 0).r;
    textureStore(result, id.xy, vec4<f32>(sum.rgb / 5.0 * (0.5 + 0.5 * near), 1.0));
}
