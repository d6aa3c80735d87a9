// Primary rays of the pinhole camera, one per pixel (CONVENTIONS.md "Camera"):
// dir = normalize(forward + (2px - 1) tan_x right - (2py - 1) tan_y up), film position
// (px, py) = ((x + jx) / width, (y + jy) / height) with (0, 0) the top-left corner, the
// ray starting on the near plane. The jitter (jx, jy) is the pixel centre (0.5, 0.5) or
// two uniform numbers from a PCG hash of (pixel, seed), the same on every backend.
//
// Bindings (group 0):
//   0 uniform            CameraParams  the camera frame and image size
//   1 storage, rw        array<Ray>    one ray per pixel, row-major
//
// Dispatch: 8 x 8 pixels per workgroup, ceil(width / 8) x ceil(height / 8) workgroups.

// #import gpu/trace.wgsl
// #import trace/bvh.wgsl

@group(0) @binding(0) var<uniform> camera: CameraParams;
@group(0) @binding(1) var<storage, read_write> camera_rays: array<Ray>;

// PCG hash (Jarzynski and Olano 2020).
fn pcg_hash(value: u32) -> u32 {
    let state = value * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// Uniform in [0, 1) from the top 24 bits.
fn unit_float(bits: u32) -> f32 {
    return f32(bits >> 8u) * (1.0 / 16777216.0);
}

@compute @workgroup_size(8, 8)
fn camera_rays_main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= camera.width || id.y >= camera.height {
        return;
    }
    let pixel = id.y * camera.width + id.x;
    var jitter = vec2<f32>(0.5, 0.5);
    if camera.jitter_seed != 0u {
        let a = pcg_hash(pixel ^ pcg_hash(camera.jitter_seed));
        jitter = vec2<f32>(unit_float(a), unit_float(pcg_hash(a)));
    }
    let px = (f32(id.x) + jitter.x) / f32(camera.width);
    let py = (f32(id.y) + jitter.y) / f32(camera.height);
    let sx = (2.0 * px - 1.0) * camera.tan_half_x;
    let sy = (2.0 * py - 1.0) * camera.tan_half_y;
    let direction = normalize(camera.forward + sx * camera.right - sy * camera.up);
    let start = camera.origin + direction * (camera.near_clip / dot(direction, camera.forward));
    camera_rays[pixel] = Ray(start, 0.0, direction, camera.far_clip);
}
