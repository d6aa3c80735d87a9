// ReSTIR pass 3: each resampling pixel takes K candidates and resamples one, combined
// with its own canonical candidate (paper §4.2; the canonical candidate comes on top of
// the K, not among them).
//
// With RestirParams.candidates = 0 it writes the canonical candidate alone as a reservoir
// (the temporal-first order, RestirSettings::reuse_order, reuses neighbours after the
// temporal merge instead: restir/entry_spatial.wgsl).
//
// Selection, by RestirParams.method (the draw: restir/block_reuse.wgsl; the choice:
// restir/resampling_core.wgsl):
//   strata      from its own cluster's run of the block's luminance-sorted list (the
//               histogram pass), at the K positions of RestirParams.sampler for this
//               pixel and frame (strata/selection.wgsl, spatial dimension pair; the
//               antithetic pattern of Fig. 3 by default); resampling by inverse CDF with
//               the pair's second number (strata/resampling.wgsl), no streaming reservoir.
//   restir      K uniformly random members of the same cluster (with replacement),
//               streaming weighted reservoir sampling.
//   restir-disc K uniformly random pixels in a disc of RestirParams.disc_radius pixels,
//               rejected unless their primary hit faces the same way (normals within
//               25 degrees) and lies at a similar depth (10 %); streaming reservoir.
//
// Weights: pairwise MIS between the canonical candidate c and each selected candidate j,
// each pair sharing 1/K and counting the neighbours as K samples against the canonical
// one (restir/resampling_core.wgsl, stream_neighbour, with every M = 1):
//   w_c = sum_j (1/K) p̂_i(x_c) / (p̂_i(x_c) + K p̂_j(x_c)) p̂_i(x_c) W_c
//   w_j = (1/K) K p̂_j(x_j) / (p̂_i(x_j) + K p̂_j(x_j)) p̂_i(x_j) W_j
// (with equal targets the canonical and each neighbour weigh 1 / (K + 1)). Every
// selection here draws each member of the run (or of the disc) with a probability that
// does not depend on the candidates' own paths given their keys' order: E[count_j |
// candidates] = K/n for the histogram patterns. So the sum of weights, and the RIS
// estimate f(Y)/p̂(Y) sum(w), are unbiased (derivation: docs/restir.md, "Why the
// selection stays unbiased").
//
// Bindings (group 0): 0-2 the scene (3-7 unused), 8 RestirParams, and
//   9  storage, read     array<Primary>        G-buffer
//   10 storage, read     array<PathCandidate>  every pixel's candidate
//   11 storage, read     array<u32>            the histogram's sorted_pixels
//   12 storage, read     array<ClusterSpan>    the histogram's per-pixel cluster run
//   13 storage, rw       array<Reservoir>      this frame's reservoir per pixel (M = 1)
//   14 storage, read     array<u32>            blue_noise (BlueNoiseTables::packed)
//
// Dispatch: 8 x 8 pixels per workgroup. Shadow rays: up to 2K per pixel; a replay pixel
// (reservoir.wgsl, "Random replay") traces up to 2K paths instead.

// #import render/scene.wgsl
// #import render/random.wgsl
// #import strata/candidate.wgsl
// #import strata/selection.wgsl
// #import restir/reservoir.wgsl
// #import restir/reuse_slot.wgsl
// #import restir/block_reuse.wgsl
// #import restir/resampling_core.wgsl

@group(0) @binding(9) var<storage, read> primaries: array<Primary>;
@group(0) @binding(10) var<storage, read> path_candidates: array<PathCandidate>;
@group(0) @binding(11) var<storage, read> sorted_pixels: array<u32>;
@group(0) @binding(12) var<storage, read> spans: array<ClusterSpan>;
@group(0) @binding(13) var<storage, read_write> reservoirs_out: array<Reservoir>;
@group(0) @binding(14) var<storage, read> blue_noise: array<u32>;

fn empty_reservoir() -> Reservoir {
    return Reservoir(PathCandidate(vec3<f32>(0.0), KIND_NONE, vec3<f32>(0.0), NO_LIGHT, vec3<f32>(0.0), 0.0), 0.0, 0.0, 0.0, 0u, vec3<f32>(0.0), 0.0);
}

// The reservoir `pixel` keeps from its own candidate and K selected ones; empty where it
// does not resample.
fn select_reservoir(id: vec3<u32>, pixel: u32, lane: u32) -> Reservoir {
    let p = primaries[pixel];
    if !begin_resampling(pixel, p, true, STREAM_SELECT) {
        return empty_reservoir();
    }
    let k = min(restir.candidates, MAX_SELECTED);
    var numbers = SelectionNumbers(vec4<f32>(0.0), 0.0);
    if restir.method == METHOD_STRATA {
        numbers = selection_numbers(id.xy, params.sample_index, params.seed, restir.sampler, k, 0u);
    }
    let positions = numbers.positions;
    let c = path_candidates[pixel];
    // p̂_i(x_c) W_c: the canonical candidate was found from y1, so it is visible. Every
    // candidate is a reservoir of M = 1, so the confidences of pairwise MIS are 1.
    let colour_c = integrand(p, c, lane);
    let canonical = CanonicalSample(c, luminance(colour_c), c.weight, 1.0, colour_c, reconnectable(p, c));
    var state = resampling_start(k, pixel);
    if k == 0u {
        // K = 0 (the temporal-first order's first pass, RestirSettings::reuse_order): the
        // canonical candidate alone, a reservoir of M = 1 that restir_temporal merges (from
        // the second frame; the renderer has the first frame's written to the merge's
        // output) and restir_spatial then reuses.
        state.canonical_weight = canonical.target_value * c.weight;
    }
    for (var slot = 0u; slot < k; slot++) {
        let q = block_slot_pixel(id.x, id.y, pixel, p, slot, positions);
        var neighbour = p;
        var x = c;
        if q != NO_PIXEL {
            neighbour = primaries[q];
            x = path_candidates[q];
        }
        // p̂_j(x_j) is evaluated at the neighbour (a candidate stores no target).
        state = stream_neighbour(state, slot, k, pixel, p, canonical, q, neighbour, x, x.weight, 1.0, 0.0, true, lane);
    }
    // Pick one of {c, samples...} in proportion to its weight.
    let total = resampling_total(state);
    if !(total > 0.0) || !(total < INFINITY) {
        var none = empty_reservoir();
        none.count = 1.0;
        return none;
    }
    var chosen = c;
    var chosen_target = canonical.target_value;
    let kept = chosen_slot(state, total, numbers.resample, restir.method == METHOD_STRATA);
    if kept != CANONICAL_KEPT {
        chosen = path_candidates[state.sources[kept]];
        chosen_target = state.targets[kept];
    }
    var result = empty_reservoir();
    result.count = 1.0;
    if chosen_target > 0.0 {
        result = Reservoir(chosen, total / chosen_target, 1.0, chosen_target, 0u, vec3<f32>(0.0), 0.0);
    }
    result.expected = resampling_expectation(state, canonical.target_value, colour_c);
    return result;
}

@compute @workgroup_size(8, 8)
fn restir_select(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let pixel = image_pixel(id);
    if pixel != NO_PIXEL {
        reservoirs_out[pixel] = select_reservoir(id, pixel, lane);
    }
}
