// One step of an all-pairs n-body simulation (explicit Euler) over `count` bodies.
// Each 64-wide workgroup stages 64 source bodies at a time in workgroup memory; body i
// accumulates, over j = 0..count-1 in order, m_j * d / (r2 * sqrt(r2)) with
// d = pos_j - pos_i and r2 = d.x*d.x + d.y*d.y + d.z*d.z + softening, then
// vel += acc * dt and pos += vel * dt. pos.w holds the mass, vel.w is carried along.
// Bindings: 0 uniform params (count, dt, softening, unused), 1 src bodies (read),
// 2 dst bodies (read_write); a body is { pos: vec4<f32>, vel: vec4<f32> }.

struct Params { count: u32, dt: f32, softening: f32, unused: u32 }
struct Body { pos: vec4<f32>, vel: vec4<f32> }

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> src: array<Body>;
@group(0) @binding(2) var<storage, read_write> dst: array<Body>;

var<workgroup> shared_pos: array<vec4<f32>, 64>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let i = gid.x;
    var me = Body(vec4<f32>(0.0), vec4<f32>(0.0));
    if i < params.count {
        me = src[i];
    }
    var acc = vec3<f32>(0.0);
    let tiles = (params.count + 63u) / 64u;
    for (var t = 0u; t < tiles; t++) {
        let j = t * 64u + li;
        if j < params.count {
            shared_pos[li] = src[j].pos;
        } else {
            shared_pos[li] = vec4<f32>(0.0);
        }
        workgroupBarrier();
        let here = min(64u, params.count - t * 64u);
        for (var k = 0u; k < here; k++) {
            let other = shared_pos[k];
            let d = other.xyz - me.pos.xyz;
            let r2 = d.x * d.x + d.y * d.y + d.z * d.z + params.softening;
            let s = other.w / (r2 * sqrt(r2));
            acc = acc + d * s;
        }
        workgroupBarrier();
    }
    if i < params.count {
        let vel = me.vel.xyz + acc * params.dt;
        let pos = me.pos.xyz + vel * params.dt;
        dst[i] = Body(vec4<f32>(pos, me.pos.w), vec4<f32>(vel, me.vel.w));
    }
}
