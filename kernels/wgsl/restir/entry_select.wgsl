// ReSTIR pass 3: each resampling pixel takes K candidates and resamples one, combined
// with its own canonical candidate (paper §4.2; the canonical candidate comes on top of
// the K, not among them).
//
// With RestirParams.candidates = 0 it writes the canonical candidate alone as a reservoir
// (the temporal-first order, RestirSettings::reuse_order, reuses neighbours after the
// temporal merge instead: restir/entry_spatial.wgsl).
//
// Selection, by RestirParams.method (the draw and the choice: restir/block_reuse.wgsl):
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
// Weights: pairwise MIS between the canonical candidate c and each selected candidate j
// (Bitterli 2022, Lin et al. 2022), each pair sharing 1/K and counting the neighbours as
// K samples against the canonical one, with the target functions as densities and W the
// candidates' own unbiased contribution weights:
//   w_c = sum_j (1/K) p̂_i(x_c) / (p̂_i(x_c) + K p̂_j(x_c)) p̂_i(x_c) W_c
//   w_j = (1/K) K p̂_j(x_j) / (p̂_i(x_j) + K p̂_j(x_j)) p̂_i(x_j) W_j
// (with equal targets the canonical and each neighbour weigh 1 / (K + 1)).
// with p̂_j(x) = 0 where pixel j cannot reconnect to x or reaches its resampling vertex
// with another path segment (reservoir.wgsl, same_segment), visibility included (a shadow ray
// from j's primary hit to x_c, one from ours to x_j). Each pair term depends on c and j only, never on
// which other candidates were drawn, and every selection here draws each member of the
// run (or of the disc) with a probability that does not depend on the candidates' own
// paths given their keys' order: E[count_j | candidates] = K/n for the histogram
// patterns. So the sum of weights, and the RIS estimate f(Y)/p̂(Y) sum(w), are unbiased
// (derivation: host/src/estimator/mod.rs and README "Why the selection stays unbiased").
//
// Bindings (group 0): 0-7 the scene, 8 RestirParams, and
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

@group(0) @binding(9) var<storage, read> primaries: array<Primary>;
@group(0) @binding(10) var<storage, read> path_candidates: array<PathCandidate>;
@group(0) @binding(11) var<storage, read> sorted_pixels: array<u32>;
@group(0) @binding(12) var<storage, read> spans: array<ClusterSpan>;
@group(0) @binding(13) var<storage, read_write> reservoirs_out: array<Reservoir>;
@group(0) @binding(14) var<storage, read> blue_noise: array<u32>;

fn empty_reservoir() -> Reservoir {
    return Reservoir(PathCandidate(vec3<f32>(0.0), KIND_NONE, vec3<f32>(0.0), NO_LIGHT, vec3<f32>(0.0), 0.0), 0.0, 0.0, 0.0, 0u, vec3<f32>(0.0), 0.0);
}

@compute @workgroup_size(8, 8)
fn restir_select(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let pixel = id.y * params.width + id.x;
    let p = primaries[pixel];
    if (p.flags & PRIMARY_RESAMPLE) == 0u {
        reservoirs_out[pixel] = empty_reservoir();
        return;
    }
    rng_seed(pixel, params.sample_index, params.seed ^ 0x5e1ec7u);
    let k = min(restir.candidates, MAX_SELECTED);
    var numbers = SelectionNumbers(vec4<f32>(0.0), 0.0);
    if restir.method == METHOD_STRATA {
        numbers = selection_numbers(id.xy, params.sample_index, params.seed, restir.sampler, k, 0u);
    }
    let positions = numbers.positions;
    let c = path_candidates[pixel];
    // p̂_i(x_c) W_c: the canonical candidate was found from y1, so it is visible.
    let colour_c = integrand(p, c, lane);
    let target_c = luminance(colour_c);
    let c_shareable = reconnectable(p, c);
    var weight_c = 0.0;
    // Per slot: resampling weight, target p̂ here, and the pixel whose candidate it is.
    var weights = vec4<f32>(0.0);
    var targets = vec4<f32>(0.0);
    var sources = vec4<u32>(pixel);
    // Per slot f(x) here, for the expectation (a replayed candidate costs a traced path).
    // Written out element by element: naga turns the zero-value constructor
    // `array<vec3<f32>, 4>()` into an HLSL cast `(float3[4])0` that glslang's HLSL front
    // end rejects. MAX_SELECTED is 4.
    var colours = array<vec3<f32>, MAX_SELECTED>(vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
    if k == 0u {
        // K = 0 (the temporal-first order's first pass, RestirSettings::reuse_order): the
        // canonical candidate alone, a reservoir of M = 1 that restir_temporal merges and
        // restir_spatial then reuses.
        weight_c = target_c * c.weight;
    }
    for (var slot = 0u; slot < k; slot++) {
        let q = block_slot_pixel(id.x, id.y, pixel, p, slot, positions);
        if q == NO_PIXEL {
            // No candidate in this slot: the canonical sample alone covers its share.
            weight_c += target_c * c.weight / f32(k);
            continue;
        }
        let neighbour = primaries[q];
        let x = path_candidates[q];
        // Pixels reaching their resampling vertices with different segments share
        // nothing (reservoir.wgsl, may_share; nor do replay and reconnection pixels):
        // p̂_j = 0 both ways.
        let shares = may_share(p, neighbour);
        sources[slot] = q;
        if q == pixel {
            // The pixel's own candidate drawn again: both halves of the pair are c.
            if c_shareable {
                let share = 1.0 / (1.0 + f32(k));
                weight_c += share * target_c * c.weight / f32(k);
                weights[slot] = (1.0 - share) * target_c * c.weight / f32(k);
                targets[slot] = target_c;
                colours[slot] = colour_c;
            } else {
                weight_c += target_c * c.weight / f32(k);
            }
            continue;
        }
        // The pair's three evaluations in one loop whose branches choose what to evaluate
        // where, so that a driver compiles the integrand (which may re-trace a replayed
        // path) and the visibility test once:
        // - step 0, the canonical candidate's half: p̂_j(x_c) at the neighbour, visibility
        //   included, for m_c = p̂_i / (p̂_i + p̂_j) at x_c;
        // - step 1, the neighbour's half: x_j reconnected here, f and p̂_i, visibility
        //   included;
        // - step 2, for its m_j = p̂_j / (p̂_i + p̂_j) at x_j: p̂_j(x_j) at the neighbour
        //   (p̂_j(x_j) > 0 and visible wherever W_j > 0).
        var target_neighbour_c = 0.0;
        var colour = vec3<f32>(0.0);
        var value = 0.0;
        for (var step = 0u; step < 3u; step++) {
            var at = neighbour;
            var y = c;
            var wanted = target_c > 0.0 && shares && c_shareable && reconnectable(neighbour, c);
            if step == 1u {
                at = p;
                y = x;
                wanted = shares && x.weight > 0.0 && reconnectable(p, x) && reconnectable(neighbour, x);
            } else if step == 2u {
                y = x;
                wanted = value > 0.0;
            }
            if !wanted {
                continue;
            }
            let f = integrand(at, y, lane);
            var target_value = luminance(f);
            if step < 2u && target_value > 0.0 && !candidate_visible(at, y, lane) {
                target_value = 0.0;
            }
            if step == 0u {
                target_neighbour_c = target_value;
            } else if step == 1u {
                colour = f;
                value = target_value;
            } else {
                let there = target_value;
                weights[slot] = f32(k) * there / (value + f32(k) * there) * value * x.weight / f32(k);
                targets[slot] = value;
                colours[slot] = colour;
            }
        }
        if target_c > 0.0 {
            weight_c += target_c / (target_c + f32(k) * target_neighbour_c) * target_c * c.weight / f32(k);
        }
    }
    // Pick one of {c, samples...} in proportion to its weight.
    var total = weight_c;
    for (var slot = 0u; slot < k; slot++) {
        total += weights[slot];
    }
    if !(total > 0.0) || !(total < INFINITY) {
        reservoirs_out[pixel] = empty_reservoir();
        reservoirs_out[pixel].count = 1.0;
        return;
    }
    var chosen = c;
    var chosen_target = target_c;
    let kept = resampled_slot(weight_c, weights, k, total, numbers.resample);
    if kept < MAX_SELECTED {
        chosen = path_candidates[sources[kept]];
        chosen_target = targets[kept];
    }
    var result = empty_reservoir();
    result.count = 1.0;
    if chosen_target > 0.0 {
        result = Reservoir(chosen, total / chosen_target, 1.0, chosen_target, 0u, vec3<f32>(0.0), 0.0);
    }
    // The expectation over the choice: sum_i w_i f(x_i) / p̂(x_i), each candidate's f
    // here (visible wherever its weight is positive, as p̂ required).
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
