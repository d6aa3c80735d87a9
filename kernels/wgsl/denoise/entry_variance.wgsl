// SVGF pass 2, variance estimation (Schied et al. 2017, §4.2): each pixel's luminance
// variance, the à-trous filter's guide. With SHORT_HISTORY frames or more of history it
// is the temporal moments' E[l²] - E[l]²; with fewer, the moments and the illumination
// are averaged over a 7 x 7 neighbourhood weighted by the depth, normal and luminance
// edge-stopping functions (the luminance one with σ_l alone, there being no variance
// yet; and the object weight with svgf.object_edges), and the variance so found is multiplied by SHORT_HISTORY / length: a short
// history is noisier than its neighbourhood says. Pixels without a surface pass through
// with variance 0.
//
// Bindings (group 0):
//   0  uniform           DenoiseParams
//   1  storage, read     array<DenoiseGuide>   the guide
//   2  storage, read     array<vec4<f32>>      integrated illumination (rgb), history length (w)
//   3  storage, read     array<vec2<f32>>      moments of its luminance
//   4  storage, rw       array<vec4<f32>>      illumination (rgb) and its variance (w)
//
// Dispatch: 8 x 8 pixels per workgroup.

// #import gpu/denoise.wgsl
// #import denoise/svgf.wgsl

@group(0) @binding(1) var<storage, read> guides: array<DenoiseGuide>;
@group(0) @binding(2) var<storage, read> integrated: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> moments: array<vec2<f32>>;
@group(0) @binding(4) var<storage, read_write> illumination_variance: array<vec4<f32>>;

@compute @workgroup_size(8, 8)
fn svgf_variance(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let pixel = pixel_of(id.x, id.y);
    let g = guides[pixel];
    let own = integrated[pixel];
    if !has_surface(g) {
        illumination_variance[pixel] = vec4<f32>(own.xyz, 0.0);
        return;
    }
    let length = own.w;
    if length >= SHORT_HISTORY {
        let m = moments[pixel];
        illumination_variance[pixel] = vec4<f32>(own.xyz, max(m.y - m.x * m.x, 0.0));
        return;
    }
    let x = i32(id.x);
    let y = i32(id.y);
    let slope = depth_slope(x, y, g.depth);
    let l = luminance(own.xyz);
    var weight_sum = 0.0;
    var illumination = vec3<f32>(0.0);
    var moment = vec2<f32>(0.0);
    for (var dy = -3; dy <= 3; dy++) {
        for (var dx = -3; dx <= 3; dx++) {
            let q = pixel_at(x + dx, y + dy);
            if q == NO_PIXEL || !has_surface(guides[q]) {
                continue;
            }
            let other = integrated[q];
            let exponent = depth_distance(g.depth, guides[q].depth, slope, vec2<f32>(f32(dx), f32(dy)))
                + abs(l - luminance(other.xyz)) / params.svgf.sigma_luminance;
            let w = object_weight(g, guides[q]) * normal_weight(g.normal, guides[q].normal) * exp(-exponent);
            weight_sum += w;
            illumination += w * other.xyz;
            moment += w * moments[q];
        }
    }
    // The pixel itself weighs about 1 (its normal's length may round below 1).
    weight_sum = max(weight_sum, 1e-20);
    illumination = illumination / weight_sum;
    moment = moment / weight_sum;
    let variance = max(moment.y - moment.x * moment.x, 0.0) * SHORT_HISTORY / max(length, 1.0);
    illumination_variance[pixel] = vec4<f32>(illumination, variance);
}
