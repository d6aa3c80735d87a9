// Progressive path tracing: one sample per pixel per dispatch, added to a running sum
// (the reference mode: N dispatches = N samples per pixel). The film position is uniform
// in the pixel (box filter, CONVENTIONS.md "Output").
//
// Bindings (group 0): 0-2 the scene (3-7 unused) (render/scene.wgsl), and
//   8 storage, rw        array<vec4<f32>>  per pixel: rgb = sum of samples, a = number of
//                                          samples dropped as invalid (non-finite radiance
//                                          or a traversal stack overflow)
//
// Dispatch: 8 x 8 pixels per workgroup, ceil(width / 8) x ceil(height / 8) workgroups.

// #import render/scene.wgsl
// #import render/random.wgsl
// #import render/path.wgsl

@group(0) @binding(8) var<storage, read_write> accumulation: array<vec4<f32>>;

fn is_finite(v: vec3<f32>) -> bool {
    let bits = bitcast<vec3<u32>>(v) & vec3<u32>(0x7f800000u);
    return all(bits != vec3<u32>(0x7f800000u));
}

@compute @workgroup_size(8, 8)
fn path_trace(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let pixel = id.y * params.width + id.x;
    rng_seed(pixel, params.sample_index, params.seed);
    let film = film_position(id.xy, random2());
    let sample = trace_path(camera_ray(film), lane);
    var total = accumulation[pixel];
    if sample.invalid || !is_finite(sample.radiance) {
        total.w += 1.0;
    } else {
        total = vec4<f32>(total.xyz + sample.radiance, total.w);
    }
    accumulation[pixel] = total;
}
