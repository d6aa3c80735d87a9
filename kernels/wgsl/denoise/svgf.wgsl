// SVGF, what its passes share (Schied et al. 2017, "Spatiotemporal Variance-Guided
// Filtering: Real-Time Reconstruction for Path-Traced Global Illumination"): the
// settings, and the edge-stopping functions of §4.2-4.3, written here from the paper.
//
//   temporal (entry_temporal.wgsl)  colour / albedo accumulated with its reprojected
//                                   history, and the first two moments of its luminance
//   variance (entry_variance.wgsl)  per pixel the luminance variance: from the moments,
//                                   or spatially where the history is short
//   à-trous  (entry_atrous.wgsl)    five levels of the edge-avoiding wavelet filter,
//                                   taps 1, 2, 4, 8, 16 pixels apart; the first level's
//                                   output is the next frame's history
//   modulate (entry_modulate.wgsl)  times the albedo again
//
// Left out: the paper's final temporal anti-aliasing pass (the frames are scored as
// modulated), and its 3 x 3 search for a history when no bilinear tap matches.
//
// Every pass: 8 x 8 pixels per workgroup, one invocation per pixel, binding 0 the
// DenoiseParams (declared with DenoiseGuide in kernels/src/denoise_types.rs, which
// generates gpu/denoise.wgsl), buffers indexed y * width + x.

// #import gpu/denoise.wgsl
// #requires var<storage, read> guides: array<DenoiseGuide>

@group(0) @binding(0) var<uniform> params: DenoiseParams;

// No pixel (outside the image).
const NO_PIXEL: u32 = 0xffffffffu;

fn pixel_of(x: u32, y: u32) -> u32 {
    return y * params.width + x;
}

fn has_surface(g: DenoiseGuide) -> bool {
    return g.depth > 0.0;
}

// What the colour is divided by and multiplied by again.
fn demodulation(albedo: vec3<f32>) -> vec3<f32> {
    return select(vec3<f32>(1.0), albedo, albedo > vec3<f32>(MIN_ALBEDO));
}

// Rec. 709 luminance.
fn luminance(c: vec3<f32>) -> f32 {
    return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
}

// w_n (§4.3): max(0, n·n')^(2^normal_power_log2).
fn normal_weight(a: vec3<f32>, b: vec3<f32>) -> f32 {
    var w = max(a.x * b.x + a.y * b.y + a.z * b.z, 0.0);
    for (var i = 0u; i < params.svgf.normal_power_log2; i++) {
        w = w * w;
    }
    return w;
}

// The pixel at (x, y), or NO_PIXEL outside the image.
fn pixel_at(x: i32, y: i32) -> u32 {
    if x < 0 || y < 0 || x >= i32(params.width) || y >= i32(params.height) {
        return NO_PIXEL;
    }
    return pixel_of(u32(x), u32(y));
}

// The depth's slope at (x, y) along each axis: the smaller of the differences to the two
// neighbours with a surface (so that a silhouette next to the pixel does not count as
// slope), 0 where neither has one. Stands in for SVGF's screen-space derivative.
fn depth_slope(x: i32, y: i32, depth: f32) -> vec2<f32> {
    var slope = vec2<f32>(0.0);
    for (var axis = 0; axis < 2; axis++) {
        var smallest = -1.0;
        for (var side = -1; side <= 1; side += 2) {
            let q = pixel_at(x + select(0, side, axis == 0), y + select(0, side, axis == 1));
            if q != NO_PIXEL && has_surface(guides[q]) {
                let d = abs(guides[q].depth - depth);
                if smallest < 0.0 || d < smallest {
                    smallest = d;
                }
            }
        }
        slope[axis] = max(smallest, 0.0);
    }
    return slope;
}

// 0 between pixels of different objects when object_edges is on, 1 otherwise. A pixel at
// the rim of a light sees it in some frames and the ceiling in others: its luminance
// variance is then so large that w_l lets the light's radiance bleed into the ceiling.
fn object_weight(a: DenoiseGuide, b: DenoiseGuide) -> f32 {
    return select(1.0, 0.0, params.svgf.object_edges != 0u && a.mesh != b.mesh);
}

// The exponent of w_z (§4.3): |z - z'| over σ_z times the depth's change along the offset
// predicted by its slope, plus a thousandth of the depth (SVGF's ε, made relative so
// that it means the same at any scene scale).
fn depth_distance(depth: f32, other: f32, slope: vec2<f32>, offset: vec2<f32>) -> f32 {
    let expected = params.svgf.sigma_depth * (abs(slope.x * offset.x) + abs(slope.y * offset.y)) + 1e-3 * depth;
    return abs(depth - other) / expected;
}
