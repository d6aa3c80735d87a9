// A small ray tracer: one primary ray per pixel of a width x height image from `eye`
// through the pixel centre (direction normalize(vec3(u * width / height, -v, -1.5)),
// u, v in (-1, 1)), the nearest of `count` spheres hit at t > 0.001 (in sphere order,
// strictly nearer wins), Lambert shading towards `light` with a shadow ray from
// p + n * 0.001 against every sphere, colour albedo * (0.1 + 0.9 * diffuse); a miss
// gets the sky (1 - s) * (1, 1, 1) + s * (0.5, 0.7, 1) with s = 0.5 * (d.y + 1).
// out[y * width + x] = vec4(colour, t of the hit or -1).
// Bindings: 0 uniform camera (width, height, count, unused, eye: vec4, light: vec4),
// 1 spheres (read; { centre_radius: vec4, albedo: vec4 }), 2 out (read_write, vec4<f32>).

struct Camera { width: u32, height: u32, count: u32, unused: u32, eye: vec4<f32>, light: vec4<f32> }
struct Sphere { centre_radius: vec4<f32>, albedo: vec4<f32> }

@group(0) @binding(0) var<uniform> camera: Camera;
@group(0) @binding(1) var<storage, read> spheres: array<Sphere>;
@group(0) @binding(2) var<storage, read_write> out: array<vec4<f32>>;

fn hit(origin: vec3<f32>, dir: vec3<f32>, sphere: vec4<f32>) -> f32 {
    let oc = origin - sphere.xyz;
    let b = dot(oc, dir);
    let c = dot(oc, oc) - sphere.w * sphere.w;
    let disc = b * b - c;
    if disc < 0.0 {
        return -1.0;
    }
    let root = sqrt(disc);
    if -b - root > 0.001 {
        return -b - root;
    }
    if -b + root > 0.001 {
        return -b + root;
    }
    return -1.0;
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= camera.width || gid.y >= camera.height {
        return;
    }
    let u = (f32(gid.x) + 0.5) / f32(camera.width) * 2.0 - 1.0;
    let v = (f32(gid.y) + 0.5) / f32(camera.height) * 2.0 - 1.0;
    let aspect = f32(camera.width) / f32(camera.height);
    let dir = normalize(vec3<f32>(u * aspect, -v, -1.5));
    let origin = camera.eye.xyz;
    var best = 1.0e30;
    var nearest = -1;
    for (var i = 0u; i < camera.count; i++) {
        let t = hit(origin, dir, spheres[i].centre_radius);
        if t > 0.0 && t < best {
            best = t;
            nearest = i32(i);
        }
    }
    var colour: vec3<f32>;
    var depth = -1.0;
    if nearest < 0 {
        let s = 0.5 * (dir.y + 1.0);
        colour = (1.0 - s) * vec3<f32>(1.0, 1.0, 1.0) + s * vec3<f32>(0.5, 0.7, 1.0);
    } else {
        let sphere = spheres[nearest];
        let p = origin + dir * best;
        let n = (p - sphere.centre_radius.xyz) / sphere.centre_radius.w;
        let light = camera.light.xyz;
        var diffuse = max(dot(n, light), 0.0);
        let start = p + n * 0.001;
        for (var i = 0u; i < camera.count; i++) {
            if hit(start, light, spheres[i].centre_radius) > 0.0 {
                diffuse = 0.0;
            }
        }
        colour = sphere.albedo.xyz * (0.1 + 0.9 * diffuse);
        depth = best;
    }
    out[gid.y * camera.width + gid.x] = vec4<f32>(colour, depth);
}
