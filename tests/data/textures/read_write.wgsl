// Read-write storage textures (r32uint, r32float) updated in place, beside a read-only
// storage texture (r32float) and out-of-range stores that must not land anywhere.
// Written for strata's texture corpus (issue 42).
//
// Bindings (group 0): 0 `counts` texture_storage_2d<r32uint, read_write>; 1 `sums`
// texture_storage_2d<r32float, read_write>; 2 `addends` texture_storage_2d<r32float,
// read>; all of one size. Dispatch: (ceil(width / 8), ceil(height / 8), 1).

@group(0) @binding(0) var counts: texture_storage_2d<r32uint, read_write>;
@group(0) @binding(1) var sums: texture_storage_2d<r32float, read_write>;
@group(0) @binding(2) var addends: texture_storage_2d<r32float, read>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(counts);
    if (any(id.xy >= size)) {
        return;
    }
    let at = vec2<i32>(id.xy);
    let count = textureLoad(counts, at).x;
    textureStore(counts, at, vec4<u32>(count * 3u + id.x, 0u, 0u, 0u));
    let sum = textureLoad(sums, at).x + textureLoad(addends, at).x;
    textureStore(sums, at, vec4<f32>(sum, 0.0, 0.0, 0.0));
    // Past the right edge: WGSL lets a store there be dropped; no texel may change.
    textureStore(sums, vec2<i32>(i32(size.x) + at.x, at.y), vec4<f32>(-1.0));
}
