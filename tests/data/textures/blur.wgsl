// A separable box blur, one pass per entry point, through workgroup memory: each
// workgroup loads its row (or column) segment and a border of RADIUS texels into a
// workgroup array (coordinates clamped to the image by the shader itself), waits at a
// barrier, averages, and writes an rgba16float storage texture.
// Written for strata's texture corpus (issue 42).
//
// Bindings (group 0): 0 `source` texture_2d<f32>; 1 `blurred`
// texture_storage_2d<rgba16float, write> of the same size.
// Dispatch: blur_x (ceil(width / 64), height, 1); blur_y (width, ceil(height / 64), 1).

@group(0) @binding(0) var source: texture_2d<f32>;
@group(0) @binding(1) var blurred: texture_storage_2d<rgba16float, write>;

const TILE: u32 = 64u;
const RADIUS: u32 = 4u;
var<workgroup> segment: array<vec4<f32>, 72>;

fn load_clamped(at: vec2<i32>) -> vec4<f32> {
    let size = vec2<i32>(textureDimensions(source));
    return textureLoad(source, clamp(at, vec2<i32>(0), size - 1), 0);
}

fn blur(origin: vec2<i32>, step: vec2<i32>, lane: u32) {
    // TILE + 2 * RADIUS texels: each lane loads one, the first 2 * RADIUS lanes two.
    segment[lane] = load_clamped(origin + step * (i32(lane) - i32(RADIUS)));
    if (lane < 2u * RADIUS) {
        segment[lane + TILE] = load_clamped(origin + step * (i32(lane + TILE) - i32(RADIUS)));
    }
    workgroupBarrier();
    var sum = vec4<f32>(0.0);
    for (var i = 0u; i <= 2u * RADIUS; i++) {
        sum += segment[lane + i];
    }
    let at = origin + step * i32(lane);
    let size = vec2<i32>(textureDimensions(blurred));
    if (all(at < size)) {
        textureStore(blurred, at, sum / f32(2u * RADIUS + 1u));
    }
}

@compute @workgroup_size(64, 1, 1)
fn blur_x(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    blur(vec2<i32>(i32(group.x * TILE), i32(group.y)), vec2<i32>(1, 0), lane);
}

@compute @workgroup_size(64, 1, 1)
fn blur_y(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    blur(vec2<i32>(i32(group.x), i32(group.y * TILE)), vec2<i32>(0, 1), lane);
}
