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
// copies of itself (restir/resampling_core.wgsl, stream_neighbour; with M = 1 everywhere
// this is restir_select's weighting), the targets as densities and W the reservoirs'
// unbiased contribution weights:
//   w_c = sum_j (1/K) M_c p̂_i(y_c) / (M_c p̂_i(y_c) + K M_j p̂_j(y_c)) p̂_i(y_c) W_c
//   w_j = (1/K) K M_j p̂_j(y_j) / (M_c p̂_i(y_j) + K M_j p̂_j(y_j)) p̂_i(y_j) W_j
// with p̂_j = 0 where pixel j cannot reconnect to y or resamples another kind of integral
// (reservoir.wgsl, may_share), visibility included. p̂_i(y_c) and p̂_j(y_j) are the
// reservoirs' stored targets (this frame's, from the merge). Each pair term depends on c
// and j only (M comes from earlier frames and the geometry, never from this frame's
// draws), and every drawing pattern gives each run member the expected count K/n
// whatever the keys' order, so the sum of weights and the RIS estimate stay unbiased as
// in restir_select (docs/restir.md, "Why the selection stays unbiased"). One sample is kept in
// proportion to w, W = sum(w) / p̂_i(Y), M = M_c + the sum of the merged M_j (Bitterli et
// al. 2020, Alg. 4; the next merge caps it at RestirParams.temporal_cap).
//
// Bindings (group 0): 0-2 the scene (3-7 unused), 8 RestirParams, and
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
// #import restir/resampling_core.wgsl

@group(0) @binding(9) var<storage, read> primaries: array<Primary>;
@group(0) @binding(10) var<storage, read> reservoirs_in: array<Reservoir>;
@group(0) @binding(11) var<storage, read> sorted_pixels: array<u32>;
@group(0) @binding(12) var<storage, read> spans: array<ClusterSpan>;
@group(0) @binding(13) var<storage, read_write> reservoirs_out: array<Reservoir>;
@group(0) @binding(14) var<storage, read> blue_noise: array<u32>;

// The reservoir of `pixel` after spatial reuse; its own where it does not resample or
// K = 0.
fn spatial_reuse(id: vec3<u32>, pixel: u32, lane: u32) -> Reservoir {
    let canonical = reservoirs_in[pixel];
    let p = primaries[pixel];
    let k = min(restir.candidates, MAX_SELECTED);
    if !begin_resampling(pixel, p, k > 0u, STREAM_SPATIAL) {
        return canonical;
    }
    var numbers = SelectionNumbers(vec4<f32>(0.0), 0.0);
    if restir.method == METHOD_STRATA {
        numbers = selection_numbers(id.xy, params.sample_index, params.seed, restir.sampler, k, 0u);
    }
    let positions = numbers.positions;
    // p̂_i(y_c) W_c, with p̂_i(y_c) the merge's (visibility included), and f(y_c) here, for
    // the pixel's own reservoir drawn again and for the expectation: one evaluation (a
    // replayed candidate costs a traced path), compiled once.
    var target_c = 0.0;
    if canonical.weight > 0.0 {
        target_c = canonical.target_value;
    }
    var colour_c = vec3<f32>(0.0);
    if target_c > 0.0 {
        colour_c = integrand(p, canonical.sample, lane);
    }
    let c = CanonicalSample(canonical.sample, target_c, canonical.weight, canonical.count, colour_c,
        target_c > 0.0 && reconnectable(p, canonical.sample));
    var state = resampling_start(k, pixel);
    for (var slot = 0u; slot < k; slot++) {
        let q = block_slot_pixel(id.x, id.y, pixel, p, slot, positions);
        var neighbour_reservoir = canonical;
        var neighbour = p;
        if q != NO_PIXEL {
            neighbour_reservoir = reservoirs_in[q];
            neighbour = primaries[q];
        }
        // p̂_j(y_j) is the neighbour's stored target (this frame's, from the merge).
        state = stream_neighbour(state, slot, k, pixel, p, c, q, neighbour, neighbour_reservoir.sample,
            neighbour_reservoir.weight, neighbour_reservoir.count, neighbour_reservoir.target_value, false, lane);
    }
    let total = resampling_total(state);
    var result = canonical;
    result.count = canonical.count + state.merged_count;
    if !(total > 0.0) || !(total < INFINITY) {
        result.weight = 0.0;
        result.target_value = 0.0;
        result.expected = vec3<f32>(0.0);
        return result;
    }
    let chosen = chosen_slot(state, total, numbers.resample, restir.method == METHOD_STRATA);
    if chosen != CANONICAL_KEPT {
        result.sample = reservoirs_in[state.sources[chosen]].sample;
        result.target_value = state.targets[chosen];
    } else {
        result.target_value = target_c;
    }
    result.weight = total / result.target_value;
    result.expected = resampling_expectation(state, target_c, colour_c);
    return result;
}

@compute @workgroup_size(8, 8)
fn restir_spatial(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let pixel = image_pixel(id);
    if pixel != NO_PIXEL {
        reservoirs_out[pixel] = spatial_reuse(id, pixel, lane);
    }
}
