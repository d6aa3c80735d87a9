// Every texture shape: a 1-D, a 2-D array (textureNumLayers, a layer per z) and a 3-D
// texture read with textureLoad, and 1-D, 2-D array and 3-D storage textures written, on
// a 3-D dispatch. Written for strata's texture corpus (issue 42).
//
// Bindings (group 0): 0 `line` texture_1d<f32>; 1 `layers` texture_2d_array<f32>;
// 2 `volume` texture_3d<f32>; 3 `line_out` texture_storage_1d<r32uint, write>;
// 4 `layers_out` texture_storage_2d_array<rgba32float, write>; 5 `volume_out`
// texture_storage_3d<rgba32float, write>; 6 `counts` storage array<u32, 8>.
// The 2-D array and 3-D textures are 8 x 8 x 4; the 1-D one is 8 wide.
// Dispatch: (1, 1, 4) workgroups of 8 x 8 x 1.

@group(0) @binding(0) var line: texture_1d<f32>;
@group(0) @binding(1) var layers: texture_2d_array<f32>;
@group(0) @binding(2) var volume: texture_3d<f32>;
@group(0) @binding(3) var line_out: texture_storage_1d<r32uint, write>;
@group(0) @binding(4) var layers_out: texture_storage_2d_array<rgba32float, write>;
@group(0) @binding(5) var volume_out: texture_storage_3d<rgba32float, write>;
@group(0) @binding(6) var<storage, read_write> counts: array<u32, 8>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let from_line = textureLoad(line, id.x, 0);
    let from_layer = textureLoad(layers, id.xy, id.z, 0);
    let from_volume = textureLoad(volume, id, 0);
    textureStore(layers_out, id.xy, id.z, from_layer * from_line.x);
    textureStore(volume_out, id, from_volume + from_layer);
    if (id.y == 0u && id.z == 0u) {
        textureStore(line_out, id.x, vec4<u32>(u32(from_line.x * 1000.0)));
    }
    if (all(id == vec3<u32>(0u))) {
        counts[0] = textureDimensions(line);
        counts[1] = textureNumLayers(layers);
        counts[2] = textureDimensions(layers).x;
        counts[3] = textureDimensions(volume).z;
        counts[4] = textureNumLevels(volume);
        counts[5] = textureDimensions(layers_out).y;
        // Not textureNumLayers(layers_out): naga 30 writes it for a storage texture with a
        // level (SPIR-V OpImageQuerySizeLod, GLSL imageSize(image, lod)), which Vulkan and
        // GLSL forbid; the README lists it among the limits.
        counts[6] = textureDimensions(layers_out).x;
        counts[7] = textureDimensions(volume_out).z;
    }
}
