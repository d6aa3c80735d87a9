// SVGF pass 4 (Schied et al. 2017, §4): the filtered illumination multiplied by the
// albedo it was divided by in the temporal pass; pixels without a surface keep their
// noisy colour.
//
// Bindings (group 0):
//   0  uniform           DenoiseParams
//   1  storage, read     array<vec4<f32>>      this frame's noisy colour (rgb)
//   2  storage, read     array<DenoiseGuide>   the guide
//   3  storage, read     array<vec4<f32>>      the last à-trous level's illumination (rgb)
//   4  storage, rw       array<vec4<f32>>      the denoised colour (rgb; w 0)
//
// Dispatch: 8 x 8 pixels per workgroup.

// #import gpu/denoise.wgsl
// #import denoise/svgf.wgsl

@group(0) @binding(1) var<storage, read> colour: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> guides: array<DenoiseGuide>;
@group(0) @binding(3) var<storage, read> filtered: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> denoised: array<vec4<f32>>;

@compute @workgroup_size(8, 8)
fn svgf_modulate(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let pixel = pixel_of(id.x, id.y);
    let g = guides[pixel];
    if !has_surface(g) {
        denoised[pixel] = vec4<f32>(colour[pixel].xyz, 0.0);
        return;
    }
    denoised[pixel] = vec4<f32>(filtered[pixel].xyz * demodulation(g.albedo), 0.0);
}
