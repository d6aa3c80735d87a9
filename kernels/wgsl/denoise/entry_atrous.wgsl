// SVGF pass 3, one level of the edge-avoiding à-trous wavelet filter (Schied et al.
// 2017, §4.3; Dammertz et al. 2010): a 5 x 5 B3-spline kernel (1/16, 1/4, 3/8, 1/4,
// 1/16 per axis) whose taps are params.step pixels apart, each weighted by
//   w_z = exp(-|z - z'| / (σ_z (|slope_x offset_x| + |slope_y offset_y|) + 1e-3 z)),
// (the paper: σ_z |∇z · offset| + ε with clip-space depth; here the slope is the smaller
// one-sided difference per axis of the guide's depth, and ε is relative to the depth),
//   w_n = max(0, n · n')^(2^normal_power_log2),
//   w_l = exp(-|l - l'| / (σ_l sqrt(g(var)) + ε)),
// and, with svgf.object_edges, 0 between different objects (not in SVGF: measured in
// BENCHMARKS.md),
// where g(var) is the pixel's variance blurred by a 3 x 3 Gaussian (1/4, 1/2, 1/4 per
// axis). The illumination is the weighted mean; the variance is filtered with the
// squared weights (Σ w² var / (Σ w)²), so that the next level, with taps twice as far
// apart, sees how much noise this one left. Neighbours without a surface do not count;
// pixels without one pass through.
//
// Bindings (group 0):
//   0  uniform           DenoiseParams (step: this level's tap distance)
//   1  storage, read     array<DenoiseGuide>   the guide
//   2  storage, read     array<vec4<f32>>      illumination (rgb) and variance (w) in
//   3  storage, rw       array<vec4<f32>>      the same, filtered
//
// Dispatch: 8 x 8 pixels per workgroup.

// #import gpu/denoise.wgsl
// #import denoise/svgf.wgsl

@group(0) @binding(1) var<storage, read> guides: array<DenoiseGuide>;
@group(0) @binding(2) var<storage, read> level_in: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> level_out: array<vec4<f32>>;

// The B3 spline's weight at tap -2..2 along one axis.
fn b3_spline(tap: i32) -> f32 {
    return select(select(1.0 / 16.0, 1.0 / 4.0, abs(tap) == 1), 3.0 / 8.0, tap == 0);
}

// The pixel's variance blurred by a 3 x 3 Gaussian over neighbours with a surface.
fn blurred_variance(x: i32, y: i32) -> f32 {
    var sum = 0.0;
    var weight_sum = 0.0;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let q = pixel_at(x + dx, y + dy);
            if q == NO_PIXEL || !has_surface(guides[q]) {
                continue;
            }
            let w = select(0.25, 0.5, dx == 0) * select(0.25, 0.5, dy == 0);
            sum += w * level_in[q].w;
            weight_sum += w;
        }
    }
    return sum / weight_sum;
}

@compute @workgroup_size(8, 8)
fn svgf_atrous(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let pixel = pixel_of(id.x, id.y);
    let g = guides[pixel];
    let own = level_in[pixel];
    if !has_surface(g) {
        level_out[pixel] = own;
        return;
    }
    let x = i32(id.x);
    let y = i32(id.y);
    let step = i32(params.step);
    let slope = depth_slope(x, y, g.depth);
    let l = luminance(own.xyz);
    let luminance_scale = params.svgf.sigma_luminance * sqrt(max(blurred_variance(x, y), 0.0)) + 1e-10;
    var weight_sum = 0.0;
    var illumination = vec3<f32>(0.0);
    var variance = 0.0;
    // Σ w σ, for the correlated part of the variance (svgf.error_correlation).
    var deviation = 0.0;
    for (var dy = -2; dy <= 2; dy++) {
        for (var dx = -2; dx <= 2; dx++) {
            let q = pixel_at(x + dx * step, y + dy * step);
            if q == NO_PIXEL || !has_surface(guides[q]) {
                continue;
            }
            let other = level_in[q];
            let offset = vec2<f32>(f32(dx * step), f32(dy * step));
            let exponent = depth_distance(g.depth, guides[q].depth, slope, offset)
                + abs(l - luminance(other.xyz)) / luminance_scale;
            let w = b3_spline(dx) * b3_spline(dy) * object_weight(g, guides[q]) * normal_weight(g.normal, guides[q].normal)
                * exp(-exponent);
            weight_sum += w;
            illumination += w * other.xyz;
            variance += w * w * other.w;
            // (A uniform test: SVGF's own configurations take no square root per tap.)
            if params.svgf.error_correlation > 0.0 {
                deviation += w * sqrt(max(other.w, 0.0));
            }
        }
    }
    // Neighbours' noise correlated with coefficient ρ: the filtered variance gains
    // ρ ((Σ w σ)² - Σ w² σ²), the covariances of every pair (an equicorrelated model). ρ = 0
    // leaves SVGF's formula (and its bits) unchanged.
    let rho = params.svgf.error_correlation;
    if rho > 0.0 {
        variance = (1.0 - rho) * variance + rho * deviation * deviation;
    }
    // The pixel itself weighs about (3/8)² (its normal's length may round below 1).
    weight_sum = max(weight_sum, 1e-20);
    level_out[pixel] = vec4<f32>(illumination / weight_sum, variance / (weight_sum * weight_sum));
}
