// Tree reduction of f32 values to (sum, min, max, sum of squares), 256 per workgroup.
// Mode 0: invocation i loads values[i] as vec4(v, v, v, v * v). Mode 1 (the second
// pass): it loads an earlier pass's partial, values[4i..4i+4], as is. Past `count` it
// loads the identity (0, 3e38, -3e38, 0). Then for s = 128, 64, ..., 1 invocations
// li < s combine tile[li] with tile[li + s] as (a.x + b.x, min, max, a.w + b.w), with a
// workgroupBarrier after each level, and partials[workgroup] = tile[0].
// Bindings: 0 uniform params (count, mode, unused x2), 1 values (read),
// 2 partials (read_write, one vec4<f32> per workgroup).

struct Params { count: u32, mode: u32, unused0: u32, unused1: u32 }

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> values: array<f32>;
@group(0) @binding(2) var<storage, read_write> partials: array<vec4<f32>>;

var<workgroup> tile: array<vec4<f32>, 256>;

const BIG: f32 = 3.0e38;

@compute @workgroup_size(256)
fn main(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
    @builtin(workgroup_id) wg: vec3<u32>,
) {
    let i = gid.x;
    var t = vec4<f32>(0.0, BIG, -BIG, 0.0);
    if i < params.count {
        if params.mode == 0u {
            let v = values[i];
            t = vec4<f32>(v, v, v, v * v);
        } else {
            t = vec4<f32>(values[4u * i], values[4u * i + 1u], values[4u * i + 2u], values[4u * i + 3u]);
        }
    }
    tile[li] = t;
    workgroupBarrier();
    for (var s = 128u; s > 0u; s = s >> 1u) {
        if li < s {
            let a = tile[li];
            let b = tile[li + s];
            tile[li] = vec4<f32>(a.x + b.x, min(a.y, b.y), max(a.z, b.z), a.w + b.w);
        }
        workgroupBarrier();
    }
    if li == 0u {
        partials[wg.x] = tile[0];
    }
}
