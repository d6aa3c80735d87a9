// textureLoad of unsigned and signed integer textures (rgba8uint or r32uint; r32sint),
// with unsigned coordinates and level, and their sizes.
// Written for strata's texture corpus (issue 42).
//
// Bindings (group 0): 0 `unsigned_texels` texture_2d<u32>; 1 `signed_texels`
// texture_2d<i32> (same size); 2 `out_unsigned` one vec4<u32> per texel; 3 `out_signed`
// one vec4<i32> per texel. Dispatch: (ceil(width / 8), ceil(height / 8), 1).

@group(0) @binding(0) var unsigned_texels: texture_2d<u32>;
@group(0) @binding(1) var signed_texels: texture_2d<i32>;
@group(0) @binding(2) var<storage, read_write> out_unsigned: array<vec4<u32>>;
@group(0) @binding(3) var<storage, read_write> out_signed: array<vec4<i32>>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(unsigned_texels);
    if (any(id.xy >= size)) {
        return;
    }
    let index = id.y * size.x + id.x;
    out_unsigned[index] = textureLoad(unsigned_texels, id.xy, 0u);
    out_signed[index] = textureLoad(signed_texels, id.xy, 0u);
}
