// SVGF pass 1, temporal accumulation (Schied et al. 2017, §4.1): each pixel's
// illumination (colour / albedo) averaged with its history, found where the pixel's
// surface was in the previous frame (its motion vector) by bilinear taps that each must
// show the same surface (same object, depth within depth_tolerance, normal within
// normal_tolerance); the valid taps' weights are renormalised, and with none the history
// starts again (SVGF then searches a 3 x 3 neighbourhood for a matching pixel; left out
// here: such a pixel is at a disocclusion or an edge, where a new history is the safe
// choice). Also the first two moments of the illumination's luminance, averaged the
// same way, for the variance (§4.2). Pixels without a surface pass their colour through.
//
// Bindings (group 0):
//   0  uniform           DenoiseParams
//   1  storage, read     array<vec4<f32>>      this frame's noisy colour (rgb; w unused)
//   2  storage, read     array<DenoiseGuide>   this frame's guide
//   3  storage, read     array<DenoiseGuide>   the previous frame's guide
//   4  storage, read     array<vec4<f32>>      the previous frame's history (rgb: its
//                                              illumination after the first à-trous level)
//   5  storage, read     array<vec4<f32>>      the previous frame's `integrated` (w: history length)
//   6  storage, read     array<vec2<f32>>      the previous frame's `moments`
//   7  storage, rw       array<vec4<f32>>      integrated illumination (rgb), history length (w)
//   8  storage, rw       array<vec2<f32>>      moments: mean luminance and mean squared luminance
//
// Dispatch: 8 x 8 pixels per workgroup.

// #import gpu/denoise.wgsl
// #import denoise/svgf.wgsl

@group(0) @binding(1) var<storage, read> colour: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> guides: array<DenoiseGuide>;
@group(0) @binding(3) var<storage, read> previous_guides: array<DenoiseGuide>;
@group(0) @binding(4) var<storage, read> history: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> previous_integrated: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read> previous_moments: array<vec2<f32>>;
@group(0) @binding(7) var<storage, read_write> integrated: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read_write> moments: array<vec2<f32>>;

// Whether the previous frame's guide `previous` shows the surface of `g`.
fn same_surface(g: DenoiseGuide, previous: DenoiseGuide) -> bool {
    return has_surface(previous) && previous.mesh == g.mesh
        && abs(previous.depth - g.depth) <= params.svgf.depth_tolerance * g.depth
        && g.normal.x * previous.normal.x + g.normal.y * previous.normal.y + g.normal.z * previous.normal.z
            >= params.svgf.normal_tolerance;
}

@compute @workgroup_size(8, 8)
fn svgf_temporal(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let pixel = pixel_of(id.x, id.y);
    let g = guides[pixel];
    let c = colour[pixel].xyz;
    if !has_surface(g) {
        integrated[pixel] = vec4<f32>(c, 0.0);
        moments[pixel] = vec2<f32>(0.0);
        return;
    }
    let illumination = c / demodulation(g.albedo);
    var weight_sum = 0.0;
    var previous_illumination = vec3<f32>(0.0);
    var previous_moment = vec2<f32>(0.0);
    var previous_length = 0.0;
    if params.history != 0u {
        // Pixel centres sit at integer + 0.5, so the previous image position is
        // id + 0.5 + motion and the four pixels around it start at
        // floor(id + 0.5 + motion - 0.5) = floor(id + motion).
        let position = vec2<f32>(id.xy) + g.motion;
        let corner = floor(position);
        let f = position - corner;
        for (var tap = 0u; tap < 4u; tap++) {
            let dx = tap & 1u;
            let dy = tap >> 1u;
            let qx = corner.x + f32(dx);
            let qy = corner.y + f32(dy);
            // Written so that a NaN motion fails it too.
            if !(qx >= 0.0 && qy >= 0.0 && qx < f32(params.width) && qy < f32(params.height)) {
                continue;
            }
            let w = select(1.0 - f.x, f.x, dx == 1u) * select(1.0 - f.y, f.y, dy == 1u);
            let q = pixel_of(u32(qx), u32(qy));
            if w > 0.0 && same_surface(g, previous_guides[q]) {
                weight_sum += w;
                previous_illumination += w * history[q].xyz;
                previous_moment += w * previous_moments[q];
                previous_length += w * previous_integrated[q].w;
            }
        }
    }
    var length = 1.0;
    // A history seen through less than a thousandth of a pixel's footprint is dropped.
    if weight_sum > 1e-3 {
        previous_illumination = previous_illumination / weight_sum;
        previous_moment = previous_moment / weight_sum;
        length = min(previous_length / weight_sum + 1.0, params.svgf.max_history);
    }
    // A history of n frames averages them uniformly until 1/n drops below alpha.
    let alpha_colour = max(params.svgf.alpha_colour, 1.0 / length);
    let alpha_moments = max(params.svgf.alpha_moments, 1.0 / length);
    let l = luminance(illumination);
    let moment = vec2<f32>(l, l * l);
    integrated[pixel] = vec4<f32>(previous_illumination * (1.0 - alpha_colour) + illumination * alpha_colour, length);
    moments[pixel] = previous_moment * (1.0 - alpha_moments) + moment * alpha_moments;
}
