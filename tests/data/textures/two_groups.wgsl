// An engine-style image pass over two bind groups with one skipped between them: the
// source and the pass's settings in group 0, the outputs in group 2 (group 1 is empty).
// It counts each texel's red channel into a 16-bin histogram with storage atomics and
// writes the texel times a gain. Written for strata's texture corpus (issue 42).
//
// Bindings: group 0: 0 `source` texture_2d<f32>, 1 `params` uniform Params;
// group 2: 0 `result` texture_storage_2d<rgba8unorm, write> of the source's size,
// 3 `histogram` 16 atomic u32. Dispatch: (ceil(width / 8), ceil(height / 8), 1).

struct Params {
    gain: f32,
    bins: u32,
}

@group(0) @binding(0) var source: texture_2d<f32>;
@group(0) @binding(1) var<uniform> params: Params;
@group(2) @binding(0) var result: texture_storage_2d<rgba8unorm, write>;
@group(2) @binding(3) var<storage, read_write> histogram: array<atomic<u32>, 16>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(source);
    if (any(id.xy >= size)) {
        return;
    }
    let texel = textureLoad(source, id.xy, 0);
    // c / 255 × bins is a whole number only for c = 0 and 255, so a device's one-ULP
    // difference in the unorm read never moves a texel to another bin.
    let bin = min(u32(texel.r * f32(params.bins)), params.bins - 1u);
    atomicAdd(&histogram[bin], 1u);
    textureStore(result, id.xy, vec4<f32>(texel.rgb * params.gain, 1.0));
}
