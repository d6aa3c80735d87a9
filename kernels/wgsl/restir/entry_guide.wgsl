// ReSTIR pass 6 (only when a denoiser runs): the denoiser's guide (DenoiseGuide of
// kernels/src/denoise_types.rs)
// from the G-buffer, what an engine's G-buffer pass would give it. The surface is the
// pixel's resampling vertex (through a smooth chain, the first rough vertex behind it,
// as engines substitute the surface seen in a mirror), its albedo the vertex's times the
// chain's throughput; the motion vector follows the camera ray's first hit from the
// previous frame's camera (RestirParams.previous_*) to this one's, both without the
// sub-pixel jitter. Pixels whose camera ray hit nothing get depth 0.
//
// Bindings (group 0): 0-2 the scene (3-7 unused), 8 RestirParams, and
//   9  storage, read     array<Primary>        this frame's G-buffer
//   10 storage, rw       array<DenoiseGuide>   the denoiser's guide
//
// Dispatch: 8 x 8 pixels per workgroup.

// #import render/scene.wgsl
// #import strata/candidate.wgsl
// #import gpu/denoise.wgsl
// #import restir/reservoir.wgsl

@group(0) @binding(9) var<storage, read> primaries: array<Primary>;
@group(0) @binding(10) var<storage, read_write> guides_out: array<DenoiseGuide>;

// The denoiser's guide of `pixel`: albedo, depth, normal and object id of its primary
// hit, and its motion since the previous frame's camera.
fn guide_of(pixel: u32) -> DenoiseGuide {
    let p = primaries[pixel];
    if (p.flags & PRIMARY_HIT) == 0u {
        return DenoiseGuide(vec3<f32>(1.0), 0.0, vec3<f32>(0.0, 0.0, 1.0), OBJECT_ID_NONE, vec2<f32>(0.0), vec2<u32>(0u));
    }
    let now = image_position(
        p.camera_hit, params.camera_origin, params.camera_forward, params.camera_right, params.camera_up,
        params.tan_half_x, params.tan_half_y,
    );
    let before = image_position(
        p.camera_hit, restir.previous_origin, restir.previous_forward, restir.previous_right, restir.previous_up,
        restir.previous_tan_half_x, restir.previous_tan_half_y,
    );
    // Behind the previous camera: a motion that leaves the image, so no history.
    var motion = vec2<f32>(-1e30);
    if before.z > 0.0 && now.z > 0.0 {
        motion = before.xy - now.xy;
    }
    return DenoiseGuide(p.albedo * p.throughput, p.depth, p.normal, p.object_id, motion, vec2<u32>(0u));
}

@compute @workgroup_size(8, 8)
fn restir_guide(@builtin(global_invocation_id) id: vec3<u32>) {
    let pixel = image_pixel(id);
    if pixel != NO_PIXEL {
        guides_out[pixel] = guide_of(pixel);
    }
}
