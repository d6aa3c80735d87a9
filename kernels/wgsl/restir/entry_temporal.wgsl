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
// With RestirParams.temporal = 0 every reservoir is copied unchanged and the boiling
// filter skipped; RestirRenderer never dispatches that (a frame without a merge has
// restir_select write the merge's output itself), but an engine driving the passes may.
//
// Bindings (group 0): 0-2 the scene (3-7 unused), 8 RestirParams, and
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
// Boiling filter (RestirParams.boiling_filter > 0; RTXDI's, biased): a sample found with a
// tiny source density carries a large W, and reuse spreads it over a neighbourhood, which
// flashes ("boiling"). After the merge, every pixel of an 8 x 8 workgroup compares its W
// with the mean W of the workgroup's nonzero reservoirs and empties its reservoir (no
// sample, M = 0, no expectation) when W exceeds it by the factor 10 / strength - 9. The
// sum runs over the workgroup in the same order on every lane (deterministic on every
// backend). It removes light wherever such samples are the right answer: biased, measured
// in BENCHMARKS.md ("What the viewer sees").
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
// #import restir/resampling_core.wgsl

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

// Merges the previous reservoir of source pixel `s` (NO_SOURCE: an empty slot) into
// `state` as slot `slot`: one pair (current c, previous j) of the merge, sharing `share`
// = 1/S, with confidences M_c and the capped M_j (C_j = M_j). Slot 0 is the pixel's own
// temporal source, slots 1..T the drawn ones. An empty slot, or a source reaching its
// resampling vertex with another path segment or kind of shift (reservoir.wgsl,
// may_share: p̂ is 0 both ways), gives c its share and merges nothing, so adds no M.
fn merge_previous(state: Resampling, slot: u32, p: Primary, current: Reservoir, s: u32, share: f32, lane: u32) -> Resampling {
    var next = state;
    next.sources[slot] = s;
    var m_previous = 0.0;
    var previous = current;
    if s != NO_SOURCE {
        previous = previous_reservoirs[s];
        m_previous = min(previous.count, restir.temporal_cap);
    }
    let target_current = current.target_value;
    if !(m_previous > 0.0) {
        next.canonical_weight += share * target_current * current.weight;
        return next;
    }
    let previous_primary = previous_primaries[s];
    if !may_share(p, previous_primary) {
        next.canonical_weight += share * target_current * current.weight;
        return next;
    }
    next.merged_count += m_previous;
    // The current sample's target here is stored; the previous sample's there is too.
    let e = pair_evaluations(p, previous_primary, current.sample, target_current > 0.0, previous.sample,
        previous.target_value > 0.0, previous.target_value, false, lane);
    if target_current > 0.0 {
        let m = canonical_mis(current.count, target_current, m_previous, e.target_neighbour_at_c);
        next.canonical_weight += share * m * target_current * current.weight;
    }
    if e.target_here > 0.0 {
        let m = neighbour_mis(current.count, e.target_here, m_previous, previous.target_value);
        next.weights[slot] = share * m * e.target_here * previous.weight;
        next.targets[slot] = e.target_here;
        next.colours[slot] = e.colour_here;
    }
    return next;
}

// This frame's reservoir of `pixel` merged with previous frames'; as it is without
// temporal reuse or where the pixel does not resample.
fn temporal_merge(id: vec3<u32>, pixel: u32, lane: u32) -> Reservoir {
    let current = current_reservoirs[pixel];
    let p = primaries[pixel];
    if !begin_resampling(pixel, p, restir.temporal != 0u, STREAM_TEMPORAL) {
        return current;
    }
    let drawn = min(restir.temporal_candidates, MAX_SELECTED);
    let share = 1.0 / f32(1u + drawn);
    var numbers = SelectionNumbers(vec4<f32>(0.0), 0.0);
    if restir.method == METHOD_STRATA && drawn > 0u {
        numbers = selection_numbers(id.xy, params.sample_index, params.seed, restir.sampler, drawn, 1u);
    }
    let positions = numbers.positions;
    // Slot 0 is the pixel's own reprojected reservoir, slots 1 to `drawn` the drawn ones:
    // one loop, so that merge_previous is compiled once.
    var state = resampling_start(1u + drawn, NO_SOURCE);
    for (var slot = 0u; slot <= drawn; slot++) {
        var s = temporal_sources[pixel];
        if slot > 0u {
            s = drawn_source(id.x, id.y, pixel, p, slot - 1u, positions);
        }
        state = merge_previous(state, slot, p, current, s, share, lane);
    }
    let total = resampling_total(state);
    var merged = current;
    merged.count = current.count + state.merged_count * share;
    if !(total > 0.0) || !(total < INFINITY) {
        merged.weight = 0.0;
        merged.expected = vec3<f32>(0.0);
        return merged;
    }
    // The expectation over this merge's choice: what SHADING_EXPECTATION adds in place of
    // f(Y) V W. The current reservoir's part uses its kept sample, not select's own
    // expectation: its MIS weight depends on which sample select kept.
    var colour_current = vec3<f32>(0.0);
    if state.canonical_weight > 0.0 && current.target_value > 0.0 {
        colour_current = integrand(p, current.sample, lane);
    }
    merged.expected = resampling_expectation(state, current.target_value, colour_current);
    // Strata with T > 0 chooses by inverse CDF with the temporal resampling number.
    let chosen = chosen_slot(state, total, numbers.resample, restir.method == METHOD_STRATA && drawn > 0u);
    if chosen != CANONICAL_KEPT {
        merged.sample = previous_reservoirs[state.sources[chosen]].sample;
        merged.target_value = state.targets[chosen];
    }
    merged.weight = total / merged.target_value;
    return merged;
}

// The W of each lane's merged reservoir (0: none), for the boiling filter.
var<workgroup> boiling_weights: array<f32, 64>;

// `merged` as the boiling filter leaves it (see the header): emptied when its W exceeds
// the workgroup's mean nonzero W by the strength's factor. Called by every lane of the
// workgroup (it synchronizes them); `weight` is this lane's W, 0 past the image's edge.
fn boiling_filter(merged: Reservoir, weight: f32, lane: u32) -> Reservoir {
    boiling_weights[lane] = weight;
    workgroupBarrier();
    var sum = 0.0;
    var nonzero = 0u;
    for (var i = 0u; i < 64u; i++) {
        let w = boiling_weights[i];
        if w > 0.0 {
            sum += w;
            nonzero += 1u;
        }
    }
    let factor = 10.0 / clamp(restir.boiling_filter, 1e-6, 1.0) - 9.0;
    if nonzero == 0u || !(weight > factor * sum / f32(nonzero)) {
        return merged;
    }
    var empty = merged;
    empty.weight = 0.0;
    empty.count = 0.0;
    empty.target_value = 0.0;
    empty.expected = vec3<f32>(0.0);
    return empty;
}

@compute @workgroup_size(8, 8)
fn restir_temporal(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let pixel = image_pixel(id);
    var merged: Reservoir;
    var weight = 0.0;
    if pixel != NO_PIXEL {
        merged = temporal_merge(id, pixel, lane);
        if merged.weight > 0.0 && merged.weight < INFINITY {
            weight = merged.weight;
        }
    }
    // A uniform condition: every lane of the workgroup reaches the filter's barrier.
    if restir.temporal != 0u && restir.boiling_filter > 0.0 {
        merged = boiling_filter(merged, weight, lane);
    }
    if pixel != NO_PIXEL {
        merged_reservoirs[pixel] = merged;
    }
}
