// textureLoad, textureDimensions and textureNumLevels of a mipmapped 2-D float texture
// (any float format: rgba8unorm, rgba16float, rgba32float, r32float), over a window two
// texels wider than level 0 on every side, at every level and one past the last.
// Loads inside the level go to `texels`, the others to `outside`: WGSL lets an
// out-of-range load return any texel of the texture, (0, 0, 0, 0) or (0, 0, 0, 1), so
// backends may differ there and the test judges `outside` by that rule.
// Written for strata's texture corpus (issue 42).
//
// Bindings (group 0): 0 `source` texture_2d<f32>; 1 `texels` and 3 `outside` one
// vec4<f32> per (level, y, x) of the window (the other one's slot stays zero);
// 2 `sizes` the level count, then width and height per level.
// Dispatch: (ceil(window.x / 8), ceil(window.y / 8), levels + 1).

@group(0) @binding(0) var source: texture_2d<f32>;
@group(0) @binding(1) var<storage, read_write> texels: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> sizes: array<u32>;
@group(0) @binding(3) var<storage, read_write> outside: array<vec4<f32>>;

const MARGIN: i32 = 2;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<i32>(textureDimensions(source));
    let window = size + 2 * MARGIN;
    if (id.x >= u32(window.x) || id.y >= u32(window.y)) {
        return;
    }
    let at = vec2<i32>(id.xy) - MARGIN;
    let index = (id.z * u32(window.y) + id.y) * u32(window.x) + id.x;
    let texel = textureLoad(source, at, i32(id.z));
    let levels = textureNumLevels(source);
    var inside = id.z < levels;
    if (inside) {
        let level = vec2<i32>(textureDimensions(source, id.z));
        inside = all(at >= vec2<i32>(0)) && all(at < level);
    }
    if (inside) {
        texels[index] = texel;
    } else {
        outside[index] = texel;
    }
    if (all(id.xy == vec2<u32>(0u)) && id.z < levels) {
        sizes[0] = levels;
        let level = textureDimensions(source, id.z);
        sizes[1u + 2u * id.z] = level.x;
        sizes[2u + 2u * id.z] = level.y;
    }
}
