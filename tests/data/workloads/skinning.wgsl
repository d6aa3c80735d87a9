// Linear blend skinning of vertices by up to four of eight bone matrices: the skin
// matrix is ((bones[j.x] * w.x + bones[j.y] * w.y) + bones[j.z] * w.z) + bones[j.w] * w.w
// (mat4x4 times scalar, matrix sums), the position is skin * vec4(position.xyz, 1) and
// the normal normalize(mat3x3(skin[0].xyz, skin[1].xyz, skin[2].xyz) * normal.xyz).
// Bindings: 0 uniform bones (array<mat4x4<f32>, 8>), 1 vertices (read; { position,
// normal, weights: vec4<f32>, joints: vec4<u32> }), 2 out (read_write; { position,
// normal: vec4<f32> }, normal.w = 0).

struct Vertex { position: vec4<f32>, normal: vec4<f32>, weights: vec4<f32>, joints: vec4<u32> }
struct Skinned { position: vec4<f32>, normal: vec4<f32> }

@group(0) @binding(0) var<uniform> bones: array<mat4x4<f32>, 8>;
@group(0) @binding(1) var<storage, read> vertices: array<Vertex>;
@group(0) @binding(2) var<storage, read_write> out: array<Skinned>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= arrayLength(&vertices) {
        return;
    }
    let v = vertices[gid.x];
    let j = v.joints;
    let w = v.weights;
    let skin = bones[j.x] * w.x + bones[j.y] * w.y + bones[j.z] * w.z + bones[j.w] * w.w;
    let position = skin * vec4<f32>(v.position.xyz, 1.0);
    let linear = mat3x3<f32>(skin[0].xyz, skin[1].xyz, skin[2].xyz);
    let normal = normalize(linear * v.normal.xyz);
    out[gid.x] = Skinned(position, vec4<f32>(normal, 0.0));
}
