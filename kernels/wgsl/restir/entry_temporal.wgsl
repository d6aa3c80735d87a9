// ReSTIR pass 4b: temporal reuse. Each resampling pixel merges this frame's reservoir c
// (restir_select) with the previous reservoir of its own temporal source
// (restir_temporal_keys: the reprojected pixel, unless disoccluded) and, with
// T = RestirParams.temporal_candidates of 1 to 4 (paper Fig. 11), T more previous
// reservoirs drawn like the spatial candidates: strata from its cluster's run of the
// temporal histogram (the block's reprojected reservoirs sorted by p̂ W) at the temporal
// sampler positions (strata/selection.wgsl, temporal dimension pair), restir uniformly
// from the same run, restir-disc from random pixels
// within disc_radius with a similar normal and depth; each drawn pixel contributes its
// temporal source's reservoir (none: an empty slot). The own reservoir stays in: in a
// static view it is the best-matched history, and replacing it by neighbours' raised the
// error (measured, BENCHMARKS.md).
// Each previous M is capped first, M_j <- min(M_j, temporal_cap) (paper §5.1: cap 20);
// with M_c = 1 the history becomes an exponential moving average with factor
// cap / (cap + 1) once the cap is reached (the paper's EMA beyond the cap).
//
// Weights: pairwise MIS with confidence weights between c and each of the S = 1 + T
// previous reservoirs j, the targets as densities, each pair sharing 1/S (Lin et al.
// 2022; with T = 0 this is the generalized balance heuristic):
//   w_c = sum_j (1/S) M_c p̂_c(y_c) / (M_c p̂_c(y_c) + M_j p̂_j(y_c)) p̂_c(y_c) W_c
//   w_j = (1/S) M_j p̂_j(y_j) / (M_c p̂_c(y_j) + M_j p̂_j(y_j)) p̂_c(y_j) W_j
// with p̂_j evaluated at the source's previous primary hit (visibility included; 0 for
// a source reaching its resampling vertex with another path segment) and an empty slot
// giving c its whole share. Each pair term depends on c and j only, the own
// pair is always there and every drawing pattern gives each run member the expected count
// T/n, so the merge stays unbiased whatever the sort did (as for the spatial selection).
// One sample is kept in proportion to w: by inverse CDF with the temporal resampling
// number for strata with T > 0 (strata/resampling.wgsl), by a streaming reservoir
// otherwise; W = sum(w) / p̂_c(Y);
// M = M_c + mean_j M_j.
// The shift is the identity on x2 (area measure) or on the direction (environment).
//
// Bindings (group 0): 0-7 the scene, 8 RestirParams, and
//   9  storage, read     array<Primary>      this frame's G-buffer
//   10 storage, read     array<Primary>      the previous frame's G-buffer
//   11 storage, read     array<Reservoir>    this frame's reservoirs (restir_select)
//   12 storage, read     array<Reservoir>    the previous frame's final reservoirs
//   13 storage, rw       array<Reservoir>    this frame's final reservoirs
//   14 storage, read     array<u32>          the temporal histogram's sorted_pixels
//   15 storage, read     array<ClusterSpan>  the temporal histogram's spans
//   16 storage, read     array<u32>          temporal sources (restir_temporal_keys)
//   17 storage, read     array<u32>          blue_noise (BlueNoiseTables::packed)
//
// Dispatch: 8 x 8 pixels per workgroup. Shadow rays: 2 per merged previous reservoir; a
// replay pixel traces 2 paths per merged reservoir instead, and one more for the
// expectation when select kept another pixel's sample.

// #import render/scene.wgsl
// #import render/random.wgsl
// #import strata/candidate.wgsl
// #import strata/selection.wgsl
// #import strata/resampling.wgsl
// #import restir/reservoir.wgsl
// #import restir/reuse_slot.wgsl

@group(0) @binding(9) var<storage, read> primaries: array<Primary>;
@group(0) @binding(10) var<storage, read> previous_primaries: array<Primary>;
@group(0) @binding(11) var<storage, read> current_reservoirs: array<Reservoir>;
@group(0) @binding(12) var<storage, read> previous_reservoirs: array<Reservoir>;
@group(0) @binding(13) var<storage, read_write> merged_reservoirs: array<Reservoir>;
@group(0) @binding(14) var<storage, read> temporal_sorted_pixels: array<u32>;
@group(0) @binding(15) var<storage, read> temporal_spans: array<ClusterSpan>;
@group(0) @binding(16) var<storage, read> temporal_sources: array<u32>;
@group(0) @binding(17) var<storage, read> blue_noise: array<u32>;

const NO_SOURCE: u32 = 0xffffffffu;

// The contribution of `y` at primary hit `p`, visibility included.
fn contribution_at(p: Primary, y: PathCandidate, lane: u32) -> vec3<f32> {
    if !reconnectable(p, y) {
        return vec3<f32>(0.0);
    }
    let value = integrand(p, y, lane);
    if luminance(value) > 0.0 && candidate_visible(p, y, lane) {
        return value;
    }
    return vec3<f32>(0.0);
}

// p̂ of `y` at primary hit `p`: luminance of its contribution, visibility included.
fn target_at(p: Primary, y: PathCandidate, lane: u32) -> f32 {
    return luminance(contribution_at(p, y, lane));
}

// The previous frame's pixel whose reservoir drawn temporal slot `slot` of pixel (x, y)
// merges, or NO_SOURCE for an empty slot (restir/reuse_slot.wgsl draws it like a
// spatial candidate).
fn drawn_source(x: u32, y: u32, pixel: u32, p: Primary, slot: u32, positions: vec4<f32>) -> u32 {
    if restir.method == METHOD_RESTIR_DISC {
        let q = disc_neighbour(x, y, p);
        if q == NO_PIXEL {
            return NO_SOURCE;
        }
        return temporal_sources[q];
    }
    let index = run_index(temporal_spans[pixel], positions[slot]);
    if index == NO_PIXEL {
        return NO_SOURCE;
    }
    return temporal_sources[temporal_sorted_pixels[index]];
}

// One pair (current c, previous reservoir of source s) of the merge, each pair sharing
// `share`: c's half goes to `current_part`, the previous sample's resampling weight and
// target here to `weight` and `target_here` (its contribution here to `colour_here`), its
// capped M to `m`.
struct PairTerms {
    current_part: f32,
    weight: f32,
    target_here: f32,
    m: f32,
    colour_here: vec3<f32>,
}

fn pair_terms(p: Primary, current: Reservoir, s: u32, share: f32, lane: u32) -> PairTerms {
    var terms = PairTerms(0.0, 0.0, 0.0, 0.0, vec3<f32>(0.0));
    var m_previous = 0.0;
    var previous = current;
    if s != NO_SOURCE {
        previous = previous_reservoirs[s];
        m_previous = min(previous.count, restir.temporal_cap);
    }
    let target_current = current.target_value;
    if !(m_previous > 0.0) {
        // An empty slot: the current reservoir alone covers its share.
        terms.current_part = share * target_current * current.weight;
        return terms;
    }
    let m_current = current.count;
    let previous_primary = previous_primaries[s];
    if !may_share(p, previous_primary) {
        // Another path segment or kind of shift (reservoir.wgsl, may_share): p̂ is 0 both ways, and c
        // alone covers the pair, which merges nothing and so adds no confidence M.
        terms.current_part = share * target_current * current.weight;
        return terms;
    }
    terms.m = m_previous;
    // The two halves in one loop whose branches choose what to evaluate where, so that a
    // driver compiles contribution_at (which may re-trace a replayed path) once: half 0
    // the current sample there (its target here is stored), half 1 the previous sample
    // shifted here.
    for (var half = 0u; half < 2u; half++) {
        var at = previous_primary;
        var y = current.sample;
        var wanted = target_current > 0.0;
        if half == 1u {
            at = p;
            y = previous.sample;
            wanted = previous.target_value > 0.0;
        }
        if !wanted {
            continue;
        }
        let colour = contribution_at(at, y, lane);
        let value = luminance(colour);
        if half == 0u {
            let m = m_current * target_current / (m_current * target_current + m_previous * value);
            terms.current_part = share * m * target_current * current.weight;
        } else if value > 0.0 {
            let m = m_previous * previous.target_value / (m_current * value + m_previous * previous.target_value);
            terms.weight = share * m * value * previous.weight;
            terms.target_here = value;
            terms.colour_here = colour;
        }
    }
    return terms;
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
    rng_seed(pixel, params.sample_index, params.seed ^ 0x7e3907u);
    let drawn = min(restir.temporal_candidates, MAX_SELECTED);
    let share = 1.0 / f32(1u + drawn);
    // The drawn previous reservoirs: per slot resampling weight, target here, source pixel.
    var numbers = SelectionNumbers(vec4<f32>(0.0), 0.0);
    if restir.method == METHOD_STRATA && drawn > 0u {
        numbers = selection_numbers(id.xy, params.sample_index, params.seed, restir.sampler, drawn, 1u);
    }
    let positions = numbers.positions;
    var weights = vec4<f32>(0.0);
    var targets = vec4<f32>(0.0);
    var sources = vec4<u32>(NO_SOURCE);
    // Per slot the previous sample's contribution here, for the expectation.
    // Written out element by element: naga turns the zero-value constructor
    // `array<vec3<f32>, 4>()` into an HLSL cast `(float3[4])0` that glslang's HLSL front
    // end rejects. MAX_SELECTED is 4.
    var colours = array<vec3<f32>, MAX_SELECTED>(vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
    // Pair 0 is the pixel's own reprojected reservoir, pairs 1 to `drawn` the drawn slots:
    // one loop, so that pair_terms is compiled once.
    let own_source = temporal_sources[pixel];
    var own = PairTerms(0.0, 0.0, 0.0, 0.0, vec3<f32>(0.0));
    var weight_current = 0.0;
    var m_sum = 0.0;
    for (var pair = 0u; pair <= drawn; pair++) {
        var s = own_source;
        if pair > 0u {
            s = drawn_source(id.x, id.y, pixel, p, pair - 1u, positions);
        }
        let terms = pair_terms(p, current, s, share, lane);
        if pair == 0u {
            own = terms;
            weight_current = terms.current_part;
            m_sum = terms.m;
            continue;
        }
        let slot = pair - 1u;
        weight_current += terms.current_part;
        m_sum += terms.m;
        weights[slot] = terms.weight;
        targets[slot] = terms.target_here;
        colours[slot] = terms.colour_here;
        sources[slot] = s;
    }
    var total = weight_current + own.weight;
    for (var slot = 0u; slot < drawn; slot++) {
        total += weights[slot];
    }
    var merged = current;
    merged.count = current.count + m_sum * share;
    if !(total > 0.0) || !(total < INFINITY) {
        merged.weight = 0.0;
        merged.expected = vec3<f32>(0.0);
        merged_reservoirs[pixel] = merged;
        return;
    }
    // The expectation over this merge's choice, sum_i w_i f(y_i) / p̂(y_i) (each y_i's f
    // here; p̂ > 0 means it was visible): what SHADING_EXPECTATION adds in place of
    // f(Y) V W. The current reservoir's part uses its kept sample, not select's own
    // expectation: its MIS weight depends on which sample select kept.
    var expected = vec3<f32>(0.0);
    if weight_current > 0.0 && current.target_value > 0.0 {
        expected += weight_current / current.target_value * integrand(p, current.sample, lane);
    }
    if own.weight > 0.0 && own.target_here > 0.0 {
        expected += own.weight / own.target_here * own.colour_here;
    }
    for (var slot = 0u; slot < drawn; slot++) {
        if weights[slot] > 0.0 && targets[slot] > 0.0 {
            expected += weights[slot] / targets[slot] * colours[slot];
        }
    }
    merged.expected = expected;
    // Choice among (current, own, drawn 0..T-1): OWN or a drawn slot, or none for current.
    let OWN = MAX_SELECTED;
    let NONE = MAX_SELECTED + 1u;
    var chosen = NONE;
    if restir.method == METHOD_STRATA && drawn > 0u {
        // Inverse CDF with the temporal resampling number.
        var choice = inverse_cdf_first(numbers.resample * total, weight_current, NONE);
        choice = inverse_cdf_next(choice, own.weight, OWN);
        for (var slot = 0u; slot < drawn; slot++) {
            choice = inverse_cdf_next(choice, weights[slot], slot);
        }
        chosen = choice.chosen;
    } else {
        // Streaming weighted reservoir sampling: current, own, then the drawn slots.
        var running = weight_current;
        if own.weight > 0.0 {
            running += own.weight;
            if random() * running < own.weight {
                chosen = OWN;
            }
        }
        for (var slot = 0u; slot < drawn; slot++) {
            if weights[slot] > 0.0 {
                running += weights[slot];
                if random() * running < weights[slot] {
                    chosen = slot;
                }
            }
        }
    }
    if chosen == OWN {
        merged.sample = previous_reservoirs[own_source].sample;
        merged.target_value = own.target_here;
    } else if chosen < MAX_SELECTED {
        merged.sample = previous_reservoirs[sources[chosen]].sample;
        merged.target_value = targets[chosen];
    }
    merged.weight = total / merged.target_value;
    merged_reservoirs[pixel] = merged;
}
