// textureStore into a storage texture of each format, with values that need Vulkan's
// output conversions: unorm clamping and rounding, f16 rounding, 8-bit integers, and
// the 32-bit formats' first component alone.
// Written for strata's texture corpus (issue 42).
//
// Bindings (group 0): 0-6 write-only storage textures of one size (rgba8unorm,
// rgba8uint, rgba16float, rgba32float, r32float, r32uint, r32sint); 7 `values` one
// vec4<f32> per texel, row by row. Dispatch: (ceil(width / 8), ceil(height / 8), 1).

@group(0) @binding(0) var unorm8: texture_storage_2d<rgba8unorm, write>;
@group(0) @binding(1) var uint8: texture_storage_2d<rgba8uint, write>;
@group(0) @binding(2) var half4: texture_storage_2d<rgba16float, write>;
@group(0) @binding(3) var float4: texture_storage_2d<rgba32float, write>;
@group(0) @binding(4) var float1: texture_storage_2d<r32float, write>;
@group(0) @binding(5) var uint1: texture_storage_2d<r32uint, write>;
@group(0) @binding(6) var sint1: texture_storage_2d<r32sint, write>;
@group(0) @binding(7) var<storage, read> values: array<vec4<f32>>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(unorm8);
    if (any(id.xy >= size)) {
        return;
    }
    let at = vec2<i32>(id.xy);
    let v = values[id.y * size.x + id.x];
    textureStore(unorm8, at, v);
    textureStore(uint8, at, vec4<u32>(abs(v) * 100.0) % vec4<u32>(256u));
    textureStore(half4, at, v * 1000.0);
    textureStore(float4, at, v);
    textureStore(float1, at, v.yxzw);
    textureStore(uint1, at, bitcast<vec4<u32>>(v));
    textureStore(sint1, at, vec4<i32>(v * 1.0e6));
}
