// ReSTIR pass 4d (temporal-first order only, RestirSettings::reuse_order): spatial reuse
// of the merged reservoirs. The standard ReSTIR order (Bitterli et al. 2020) merges the
// temporal history first (restir_temporal, on each pixel's M = 1 canonical reservoir)
// and then lets each pixel resample K neighbours' merged reservoirs; the histogram
// stratification (paper §4.1-4.2) then acts on reservoirs that already carry their
// history, sorted by their estimates p̂ W (restir_reservoir_keys), instead of on this
// frame's candidates alone, whose share of a merge fades as the history grows. The
// output is the pixel's final reservoir, which the next frame's temporal merge reuses.
//
// Selection, by RestirParams.method, as restir_select draws its K (restir/block_reuse.wgsl):
//   strata      the K stratified positions of the pixel's cluster run (spatial
//               dimension pair) and inverse-CDF resampling with the pair's second number
//   restir      K uniformly random members of the run, streaming reservoir
//   restir-disc K uniformly random disc pixels with similar normal and depth
//
// Weights: pairwise MIS with confidence weights between the canonical reservoir c (M_c)
// and each drawn reservoir j (M_j), each pair sharing 1/K and counting neighbour j as K
// copies of itself (with M = 1 everywhere this is restir_select's weighting), the
// targets as densities and W the reservoirs' unbiased contribution weights:
//   w_c = sum_j (1/K) M_c p̂_i(y_c) / (M_c p̂_i(y_c) + K M_j p̂_j(y_c)) p̂_i(y_c) W_c
//   w_j = (1/K) K M_j p̂_j(y_j) / (M_c p̂_i(y_j) + K M_j p̂_j(y_j)) p̂_i(y_j) W_j
// with p̂_j = 0 where pixel j cannot reconnect to y or resamples another kind of integral
// (reservoir.wgsl, may_share), visibility included. p̂_i(y_c) and p̂_j(y_j) are the
// reservoirs' stored targets (this frame's, from the merge). Each pair term depends on c
// and j only (M comes from earlier frames and the geometry, never from this frame's
// draws), and every drawing pattern gives each run member the expected count K/n
// whatever the keys' order, so the sum of weights and the RIS estimate stay unbiased as
// in restir_select (README, "Why the selection stays unbiased"). One sample is kept in
// proportion to w, W = sum(w) / p̂_i(Y), M = M_c + the sum of the merged M_j (Bitterli et
// al. 2020, Alg. 4; the next merge caps it at RestirParams.temporal_cap).
//
// Bindings (group 0): 0-7 the scene, 8 RestirParams, and
//   9  storage, read     array<Primary>        this frame's G-buffer
//   10 storage, read     array<Reservoir>      the merged reservoirs (restir_temporal)
//   11 storage, read     array<u32>            the histogram's sorted_pixels (of the merged reservoirs' keys)
//   12 storage, read     array<ClusterSpan>    the histogram's per-pixel cluster run
//   13 storage, rw       array<Reservoir>      this frame's final reservoirs
//   14 storage, read     array<u32>            blue_noise (BlueNoiseTables::packed)
//
// Dispatch: 8 x 8 pixels per workgroup. Shadow rays: up to 2K per pixel; a replay pixel
// traces up to 2K paths instead (and one for its own sample's colour when it holds
// another pixel's).

// #import render/scene.wgsl
// #import render/random.wgsl
// #import strata/candidate.wgsl
// #import strata/selection.wgsl
// #import restir/reservoir.wgsl
// #import restir/reuse_slot.wgsl
// #import restir/block_reuse.wgsl

@group(0) @binding(9) var<storage, read> primaries: array<Primary>;
@group(0) @binding(10) var<storage, read> reservoirs_in: array<Reservoir>;
@group(0) @binding(11) var<storage, read> sorted_pixels: array<u32>;
@group(0) @binding(12) var<storage, read> spans: array<ClusterSpan>;
@group(0) @binding(13) var<storage, read_write> reservoirs_out: array<Reservoir>;
@group(0) @binding(14) var<storage, read> blue_noise: array<u32>;

@compute @workgroup_size(8, 8)
fn restir_spatial(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let pixel = id.y * params.width + id.x;
    let p = primaries[pixel];
    let canonical = reservoirs_in[pixel];
    reservoirs_out[pixel] = canonical;
    if (p.flags & PRIMARY_RESAMPLE) == 0u {
        return;
    }
    rng_seed(pixel, params.sample_index, params.seed ^ 0x5fa71au);
    let k = min(restir.candidates, MAX_SELECTED);
    if k == 0u {
        return;
    }
    var numbers = SelectionNumbers(vec4<f32>(0.0), 0.0);
    if restir.method == METHOD_STRATA {
        numbers = selection_numbers(id.xy, params.sample_index, params.seed, restir.sampler, k, 0u);
    }
    let positions = numbers.positions;
    let c = canonical.sample;
    let m_c = canonical.count;
    // p̂_i(y_c) W_c, with p̂_i(y_c) the merge's (visibility included).
    var target_c = 0.0;
    if canonical.weight > 0.0 {
        target_c = canonical.target_value;
    }
    let c_shareable = target_c > 0.0 && reconnectable(p, c);
    // f(y_c) here, for the pixel's own reservoir drawn again and for the expectation: one
    // evaluation (a replayed candidate costs a traced path), compiled once.
    var colour_c = vec3<f32>(0.0);
    if target_c > 0.0 {
        colour_c = integrand(p, c, lane);
    }
    var weight_c = 0.0;
    var m_sum = 0.0;
    // Per slot: resampling weight, target p̂_i here, f here and the pixel it came from.
    var weights = vec4<f32>(0.0);
    var targets = vec4<f32>(0.0);
    var sources = vec4<u32>(pixel);
    // Written out element by element (see restir_select: naga's HLSL zero constructor).
    var colours = array<vec3<f32>, MAX_SELECTED>(vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
    for (var slot = 0u; slot < k; slot++) {
        let q = block_slot_pixel(id.x, id.y, pixel, p, slot, positions);
        var neighbour_reservoir = canonical;
        var neighbour = p;
        if q != NO_PIXEL {
            neighbour_reservoir = reservoirs_in[q];
            neighbour = primaries[q];
        }
        let m_j = neighbour_reservoir.count;
        if q == NO_PIXEL || !(m_j > 0.0) || !may_share(p, neighbour) {
            // Nothing to merge in this slot: the canonical reservoir covers its share,
            // and no confidence is added.
            weight_c += target_c * canonical.weight / f32(k);
            continue;
        }
        sources[slot] = q;
        m_sum += m_j;
        if q == pixel {
            // The pixel's own reservoir drawn again: both halves of the pair are c, its
            // share M_c / (M_c + K M_c) = 1 / (1 + K).
            if c_shareable {
                let share = 1.0 / (1.0 + f32(k));
                weight_c += share * target_c * canonical.weight / f32(k);
                weights[slot] = (1.0 - share) * target_c * canonical.weight / f32(k);
                targets[slot] = target_c;
                colours[slot] = colour_c;
            } else {
                weight_c += target_c * canonical.weight / f32(k);
            }
            continue;
        }
        // The pair's two evaluations in one loop whose branches choose what to evaluate
        // where, so that a driver compiles the integrand (which may re-trace a replayed
        // path) and the visibility test once: step 0, the canonical half, p̂_j(y_c) at the
        // neighbour's primary hit; step 1, the neighbour's half, y_j reconnected here
        // (p̂_j(y_j) is its stored target); both with visibility included.
        let y = neighbour_reservoir.sample;
        let there = neighbour_reservoir.target_value;
        var target_neighbour_c = 0.0;
        for (var step = 0u; step < 2u; step++) {
            var at = neighbour;
            var candidate = c;
            var wanted = c_shareable && reconnectable(neighbour, c);
            if step == 1u {
                at = p;
                candidate = y;
                wanted = neighbour_reservoir.weight > 0.0 && there > 0.0 && reconnectable(p, y)
                    && reconnectable(neighbour, y);
            }
            if !wanted {
                continue;
            }
            let colour = integrand(at, candidate, lane);
            var value = luminance(colour);
            if value > 0.0 && !candidate_visible(at, candidate, lane) {
                value = 0.0;
            }
            if step == 0u {
                target_neighbour_c = value;
            } else if value > 0.0 {
                let m = f32(k) * m_j * there / (m_c * value + f32(k) * m_j * there);
                weights[slot] = m * value * neighbour_reservoir.weight / f32(k);
                targets[slot] = value;
                colours[slot] = colour;
            }
        }
        if target_c > 0.0 {
            let m = m_c * target_c / (m_c * target_c + f32(k) * m_j * target_neighbour_c);
            weight_c += m * target_c * canonical.weight / f32(k);
        }
    }
    var total = weight_c;
    for (var slot = 0u; slot < k; slot++) {
        total += weights[slot];
    }
    var result = canonical;
    result.count = m_c + m_sum;
    if !(total > 0.0) || !(total < INFINITY) {
        result.weight = 0.0;
        result.target_value = 0.0;
        result.expected = vec3<f32>(0.0);
        reservoirs_out[pixel] = result;
        return;
    }
    let chosen = resampled_slot(weight_c, weights, k, total, numbers.resample);
    if chosen < MAX_SELECTED {
        result.sample = reservoirs_in[sources[chosen]].sample;
        result.target_value = targets[chosen];
    } else {
        result.target_value = target_c;
    }
    result.weight = total / result.target_value;
    // The expectation over the choice: sum_i w_i f(y_i) / p̂_i(y_i), each f here.
    var expected = vec3<f32>(0.0);
    if weight_c > 0.0 && target_c > 0.0 {
        expected += weight_c / target_c * colour_c;
    }
    for (var slot = 0u; slot < k; slot++) {
        if weights[slot] > 0.0 && targets[slot] > 0.0 {
            expected += weights[slot] / targets[slot] * colours[slot];
        }
    }
    result.expected = expected;
    reservoirs_out[pixel] = result;
}
