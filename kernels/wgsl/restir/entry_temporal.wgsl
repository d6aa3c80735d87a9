// ReSTIR pass 4: temporal reuse. Each resampling pixel merges this frame's reservoir
// with the previous frame's reservoir of the pixel its primary hit reprojects to
// (RestirParams.previous_* camera), unless that pixel saw another object, faces another
// way (normals beyond 25 degrees) or lies at another depth (10 %): a disocclusion keeps
// the current reservoir alone. The previous M is capped first, M_prev <- min(M_prev,
// temporal_cap) (paper §5.1: cap 20); merging with weights M_prev and M_cur = 1 then makes
// the history an exponential moving average with factor cap / (cap + 1) once the cap is
// reached, which is the paper's EMA beyond the cap.
//
// Weights: generalized balance heuristic with the targets as densities (Lin et al. 2022):
//   m_cur(y)  = M_cur p̂_cur(y) / (M_cur p̂_cur(y) + M_prev p̂_prev(y))
//   m_prev(y) = M_prev p̂_prev(y) / (M_cur p̂_cur(y) + M_prev p̂_prev(y))
// with p̂_prev evaluated at the previous frame's primary hit (visibility included);
// w = m(y) p̂_cur(y) W; one sample is kept in proportion to w; W = sum(w) / p̂_cur(Y).
// The shift is the identity on x2 (area measure) or on the direction (environment).
//
// Bindings (group 0): 0-7 the scene, 8 RestirParams, and
//   9  storage, read     array<Primary>    this frame's G-buffer
//   10 storage, read     array<Primary>    the previous frame's G-buffer
//   11 storage, read     array<Reservoir>  this frame's reservoirs (restir_select)
//   12 storage, read     array<Reservoir>  the previous frame's final reservoirs
//   13 storage, rw       array<Reservoir>  this frame's final reservoirs
//
// Dispatch: 8 x 8 pixels per workgroup. Shadow rays: 2 per merging pixel.

@group(0) @binding(9) var<storage, read> primaries: array<Primary>;
@group(0) @binding(10) var<storage, read> previous_primaries: array<Primary>;
@group(0) @binding(11) var<storage, read> current_reservoirs: array<Reservoir>;
@group(0) @binding(12) var<storage, read> previous_reservoirs: array<Reservoir>;
@group(0) @binding(13) var<storage, read_write> merged_reservoirs: array<Reservoir>;

// The previous frame's pixel that saw `position`, or 0xffffffff outside its image.
fn reproject(position: vec3<f32>) -> u32 {
    let d = position - restir.previous_origin;
    let z = dot(d, restir.previous_forward);
    if z <= 0.0 {
        return 0xffffffffu;
    }
    let sx = dot(d, restir.previous_right) / (z * restir.previous_tan_half_x);
    let sy = dot(d, restir.previous_up) / (z * restir.previous_tan_half_y);
    let px = (sx + 1.0) * 0.5 * f32(params.width);
    let py = (1.0 - sy) * 0.5 * f32(params.height);
    if !(px >= 0.0 && py >= 0.0 && px < f32(params.width) && py < f32(params.height)) {
        return 0xffffffffu;
    }
    return u32(py) * params.width + u32(px);
}

// p̂ of `y` at primary hit `p`: luminance of its contribution, visibility included.
fn target_at(p: Primary, y: PathCandidate, lane: u32) -> f32 {
    if !reconnectable(p, y) {
        return 0.0;
    }
    let value = luminance(integrand(p, y));
    if value > 0.0 && candidate_visible(p, y, lane) {
        return value;
    }
    return 0.0;
}

@compute @workgroup_size(8, 8)
fn restir_temporal(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let pixel = id.y * params.width + id.x;
    let p = primaries[pixel];
    let current = current_reservoirs[pixel];
    merged_reservoirs[pixel] = current;
    if restir.temporal == 0u || (p.flags & PRIMARY_RESAMPLE) == 0u {
        return;
    }
    let q = reproject(p.position);
    if q == 0xffffffffu {
        return;
    }
    let previous_primary = previous_primaries[q];
    if (previous_primary.flags & PRIMARY_RESAMPLE) == 0u || previous_primary.object_id != p.object_id
        || dot(previous_primary.normal, p.normal) < 0.906 || abs(previous_primary.depth - p.depth) > 0.1 * p.depth {
        return;
    }
    let previous = previous_reservoirs[q];
    let m_previous = min(previous.count, restir.temporal_cap);
    let m_current = current.count;
    if !(m_previous > 0.0) {
        return;
    }
    rng_seed(pixel, params.sample_index, params.seed ^ 0x7e3907u);
    // The current sample: its target here is stored; there, evaluate it.
    var weight_current = 0.0;
    if current.target_value > 0.0 {
        let there = target_at(previous_primary, current.sample, lane);
        let m = m_current * current.target_value / (m_current * current.target_value + m_previous * there);
        weight_current = m * current.target_value * current.weight;
    }
    // The previous sample shifted here.
    var weight_previous = 0.0;
    var target_previous_here = 0.0;
    if previous.target_value > 0.0 {
        target_previous_here = target_at(p, previous.sample, lane);
        if target_previous_here > 0.0 {
            let m = m_previous * previous.target_value
                / (m_current * target_previous_here + m_previous * previous.target_value);
            weight_previous = m * target_previous_here * previous.weight;
        }
    }
    let total = weight_current + weight_previous;
    var merged = current;
    merged.count = m_current + m_previous;
    if !(total > 0.0) || !(total < INFINITY) {
        merged.weight = 0.0;
        merged_reservoirs[pixel] = merged;
        return;
    }
    if random() * total < weight_previous {
        merged.sample = previous.sample;
        merged.target_value = target_previous_here;
    }
    merged.weight = total / merged.target_value;
    merged_reservoirs[pixel] = merged;
}
