// The resampling core of ReSTIR, written once for its three passes: restir_select (this
// frame's candidates, paper §4.2), restir_spatial (merged reservoirs, the temporal-first
// order) and restir_temporal (previous frames' reservoirs, paper §5.1 and Fig. 11).
// One resampling keeps one sample among a pixel's canonical sample c (its own) and up to
// MAX_SLOTS samples y_j of other pixels or frames, with pairwise MIS (Bitterli 2022,
// §9.1.2; Lin et al. 2022, "Generalized resampled importance sampling", §6): every pair
// (c, y_j) is weighed by the targets of its two pixels only, never by which other samples
// were drawn, which is what keeps the stratified selection unbiased (docs/restir.md, "Why
// the selection stays unbiased"). With M_c and M_j the reservoirs' confidences and C_j
// the confidence the pass gives slot j (K M_j when each of K spatial neighbours stands
// for K copies of itself, M_j for a temporal pair):
//   m_c = M_c p̂_i(c) / (M_c p̂_i(c) + C_j p̂_j(c))              canonical_mis
//   m_j = C_j p̂_j(y_j) / (M_c p̂_i(y_j) + C_j p̂_j(y_j))        neighbour_mis
//   w_c = sum_j share_j m_c p̂_i(c) W_c,   w_j = share_j m_j p̂_i(y_j) W_j
// with p̂_j = 0 where pixel j cannot reconnect to a sample or resamples another kind of
// integral (reservoir.wgsl, may_share and reconnectable), visibility included. The kept
// sample Y is chosen in proportion to w (chosen_slot), W = sum(w) / p̂_i(Y), and
// resampling_expectation gives sum_i w_i f(y_i) / p̂_i(y_i), what SHADING_EXPECTATION
// shades instead of f(Y) V W.
//
//   Resampling          the running state: w_c, and per slot w_j, p̂_i(y_j), f(y_j) here,
//                       the pixel (or reservoir) y_j came from, and the confidence merged
//   pair_evaluations    the target evaluations one pair needs, in one loop
//   stream_neighbour    one of K spatial slots (share 1/K, C_j = K M_j): select, spatial
//   canonical_mis, neighbour_mis   the two weights above (restir_temporal applies its own
//                       share 1/S to them, S = 1 + T pairs, C_j = M_j)
//   chosen_slot         the choice: inverse CDF with strata's resampling number
//                       (strata/resampling.wgsl), streaming weighted reservoir sampling
//                       in slot order for the baselines
//   resampling_expectation
//   begin_resampling    each pass's start at a pixel: whether it resamples, its random stream
//
// Needs from the kernel that includes it what reservoir.wgsl needs, and `random()`, drawn
// only by the streaming choice (one number per slot with a positive weight, in slot order).
// The arithmetic is written so that each pass computes exactly what it computed before
// this core existed (host/tests/golden.rs reproduces their outputs byte for byte).

// #import render/random.wgsl
// #import strata/selection.wgsl
// #import strata/resampling.wgsl
// #import restir/reservoir.wgsl

// Slots of one resampling: the K <= MAX_SELECTED spatial neighbours, or the temporal
// pass's own previous reservoir and its T <= MAX_SELECTED drawn ones.
const MAX_SLOTS: u32 = 5u;

// The id chosen_slot returns for the canonical sample.
const CANONICAL_KEPT: u32 = MAX_SLOTS;

// The random stream of each pass, XORed into the render seed (begin_resampling), so that
// the numbers one pass draws for a pixel are independent of the other passes'.
const STREAM_SELECT: u32 = 0x5e1ec7u;
const STREAM_SPATIAL: u32 = 0x5fa71au;
const STREAM_TEMPORAL: u32 = 0x7e3907u;

// Whether `pixel`, with primary `p`, resamples in a pass that is `enabled`: only a pixel
// whose primary hit can hold a reservoir does (PRIMARY_RESAMPLE); for the others the pass
// returns what it gives a pixel that does not resample (its reservoir as it is, or an
// empty one). A pixel that resamples has its random numbers seeded from the pass's own
// `stream`.
fn begin_resampling(pixel: u32, p: Primary, enabled: bool, stream: u32) -> bool {
    if !enabled || (p.flags & PRIMARY_RESAMPLE) == 0u {
        return false;
    }
    rng_seed(pixel, params.sample_index, params.seed ^ stream);
    return true;
}

// The running state of one resampling (see the top of the file). `slots` is how many of
// the arrays are in use; `merged_count` the sum of M_j over the slots that merged.
struct Resampling {
    canonical_weight: f32,
    slots: u32,
    merged_count: f32,
    weights: array<f32, MAX_SLOTS>,
    targets: array<f32, MAX_SLOTS>,
    sources: array<u32, MAX_SLOTS>,
    colours: array<vec3<f32>, MAX_SLOTS>,
}

// An empty resampling of `slots` slots whose sources default to `source`. Written out
// element by element: naga turns zero-value array constructors into HLSL casts
// (`(float3[5])0`) that glslang's HLSL front end rejects.
fn resampling_start(slots: u32, source: u32) -> Resampling {
    let zero3 = vec3<f32>(0.0);
    return Resampling(
        0.0,
        slots,
        0.0,
        array<f32, MAX_SLOTS>(0.0, 0.0, 0.0, 0.0, 0.0),
        array<f32, MAX_SLOTS>(0.0, 0.0, 0.0, 0.0, 0.0),
        array<u32, MAX_SLOTS>(source, source, source, source, source),
        array<vec3<f32>, MAX_SLOTS>(zero3, zero3, zero3, zero3, zero3),
    );
}

// m_c: the canonical sample's pairwise MIS weight against slot j, from M_c, p̂_i(c),
// C_j and p̂_j(c). Needs p̂_i(c) > 0.
fn canonical_mis(confidence_c: f32, target_c: f32, confidence_j: f32, target_j_at_c: f32) -> f32 {
    return confidence_c * target_c / (confidence_c * target_c + confidence_j * target_j_at_c);
}

// m_j: slot j's pairwise MIS weight against the canonical sample, from M_c, p̂_i(y_j),
// C_j and p̂_j(y_j). Needs p̂_i(y_j) > 0.
fn neighbour_mis(confidence_c: f32, target_here: f32, confidence_j: f32, target_j: f32) -> f32 {
    return confidence_j * target_j / (confidence_c * target_here + confidence_j * target_j);
}

// What one pair (c, y_j) evaluates: p̂_j(c) at pixel j's primary hit, p̂_i(y_j) and
// f(y_j) here (both with visibility), and p̂_j(y_j) (stored, or evaluated without
// visibility: p̂_j(y_j) > 0 and visible wherever W_j > 0). Each is 0 where not wanted.
struct PairEvaluations {
    target_neighbour_at_c: f32,
    target_here: f32,
    colour_here: vec3<f32>,
    target_neighbour: f32,
}

// The evaluations of the pair of canonical sample `c` (wanted when `c_usable`) and
// neighbour sample `y` (wanted when `y_usable`), pixel i's primary hit `p`, pixel j's
// `neighbour`. `target_neighbour` is p̂_j(y_j) when `evaluate_target_neighbour` is false,
// evaluated at `neighbour` otherwise. One loop whose branches choose what to evaluate
// where, so that a driver compiles the integrand (which may re-trace a replayed path)
// and the visibility test once:
// - step 0, the canonical half: p̂_j(c) at the neighbour, visibility included;
// - step 1, the neighbour's half: y reconnected here, f and p̂_i, visibility included;
// - step 2, only when evaluated: p̂_j(y) at the neighbour.
fn pair_evaluations(
    p: Primary,
    neighbour: Primary,
    c: PathCandidate,
    c_usable: bool,
    y: PathCandidate,
    y_usable: bool,
    target_neighbour: f32,
    evaluate_target_neighbour: bool,
    lane: u32,
) -> PairEvaluations {
    var out = PairEvaluations(0.0, 0.0, vec3<f32>(0.0), target_neighbour);
    var steps = 2u;
    if evaluate_target_neighbour {
        steps = 3u;
    }
    for (var step = 0u; step < steps; step++) {
        var at = neighbour;
        var sample = c;
        var wanted = c_usable && reconnectable(neighbour, c);
        if step == 1u {
            at = p;
            sample = y;
            wanted = y_usable && reconnectable(p, y);
        } else if step == 2u {
            sample = y;
            wanted = out.target_here > 0.0;
        }
        if !wanted {
            continue;
        }
        let f = integrand(at, sample, lane);
        var value = luminance(f);
        if step < 2u && value > 0.0 && !candidate_visible(at, sample, lane) {
            value = 0.0;
        }
        if step == 0u {
            out.target_neighbour_at_c = value;
        } else if step == 1u {
            out.target_here = value;
            out.colour_here = f;
        } else {
            out.target_neighbour = value;
        }
    }
    return out;
}

// The canonical sample of a resampling at pixel i: the sample, p̂_i(c) (0 when its
// reservoir is empty), W_c, M_c and f(c) here, and whether pixel i may share it with its
// neighbours (`shareable`: reconnectable from its own primary hit).
struct CanonicalSample {
    sample: PathCandidate,
    target_value: f32,
    weight: f32,
    count: f32,
    colour: vec3<f32>,
    shareable: bool,
}

// Streams spatial slot `slot` of K = `k` into `state`: pixel `q` (NO_PIXEL for none) with
// primary hit `neighbour` offers sample `y` with W_j `weight_j`, M_j `count_j` and
// p̂_j(y) `target_neighbour` (evaluated here instead when `evaluate_target_neighbour`).
// Each slot stands for K copies of itself against c (C_j = K M_j, share 1/K); an empty
// slot, or one that cannot share with pixel i, gives c its share and merges nothing.
// `pixel` is pixel i's index: drawing itself, both halves of the pair are c, its share
// M_c / (M_c + K M_c) = 1 / (1 + K).
fn stream_neighbour(
    state: Resampling,
    slot: u32,
    k: u32,
    pixel: u32,
    p: Primary,
    c: CanonicalSample,
    q: u32,
    neighbour: Primary,
    y: PathCandidate,
    weight_j: f32,
    count_j: f32,
    target_neighbour: f32,
    evaluate_target_neighbour: bool,
    lane: u32,
) -> Resampling {
    var s = state;
    if q == NO_PIXEL || !(count_j > 0.0) || !may_share(p, neighbour) {
        s.canonical_weight += c.target_value * c.weight / f32(k);
        return s;
    }
    s.sources[slot] = q;
    s.merged_count += count_j;
    if q == pixel {
        if c.shareable {
            let share = 1.0 / (1.0 + f32(k));
            s.canonical_weight += share * c.target_value * c.weight / f32(k);
            s.weights[slot] = (1.0 - share) * c.target_value * c.weight / f32(k);
            s.targets[slot] = c.target_value;
            s.colours[slot] = c.colour;
        } else {
            s.canonical_weight += c.target_value * c.weight / f32(k);
        }
        return s;
    }
    let y_usable = weight_j > 0.0 && (evaluate_target_neighbour || target_neighbour > 0.0)
        && reconnectable(neighbour, y);
    let c_usable = c.target_value > 0.0 && c.shareable;
    let e = pair_evaluations(p, neighbour, c.sample, c_usable, y, y_usable, target_neighbour,
        evaluate_target_neighbour, lane);
    let confidence_j = f32(k) * count_j;
    if e.target_here > 0.0 {
        let m = neighbour_mis(c.count, e.target_here, confidence_j, e.target_neighbour);
        s.weights[slot] = m * e.target_here * weight_j / f32(k);
        s.targets[slot] = e.target_here;
        s.colours[slot] = e.colour_here;
    }
    if c.target_value > 0.0 {
        let m = canonical_mis(c.count, c.target_value, confidence_j, e.target_neighbour_at_c);
        s.canonical_weight += m * c.target_value * c.weight / f32(k);
    }
    return s;
}

// w_c plus every slot's w_j, summed in slot order.
fn resampling_total(state: Resampling) -> f32 {
    var total = state.canonical_weight;
    for (var slot = 0u; slot < state.slots; slot++) {
        total += state.weights[slot];
    }
    return total;
}

// The kept sample: CANONICAL_KEPT or a slot, in proportion to the weights, `total` their
// sum. `stratified`: by inverse CDF with strata's resampling number `resample` in [0, 1);
// otherwise by streaming weighted reservoir sampling in slot order (random()).
fn chosen_slot(state: Resampling, total: f32, resample: f32, stratified: bool) -> u32 {
    if stratified {
        var choice = inverse_cdf_first(resample * total, state.canonical_weight, CANONICAL_KEPT);
        for (var slot = 0u; slot < state.slots; slot++) {
            choice = inverse_cdf_next(choice, state.weights[slot], slot);
        }
        return choice.chosen;
    }
    var chosen = CANONICAL_KEPT;
    var running = state.canonical_weight;
    for (var slot = 0u; slot < state.slots; slot++) {
        if state.weights[slot] > 0.0 {
            running += state.weights[slot];
            if random() * running < state.weights[slot] {
                chosen = slot;
            }
        }
    }
    return chosen;
}

// The expectation over the choice, sum_i w_i f(y_i) / p̂_i(y_i), with the canonical
// sample's p̂_i(c) `target_c` and f(c) here `colour_c` (each f visible wherever its weight
// is positive, as p̂ required).
fn resampling_expectation(state: Resampling, target_c: f32, colour_c: vec3<f32>) -> vec3<f32> {
    var expected = vec3<f32>(0.0);
    if state.canonical_weight > 0.0 && target_c > 0.0 {
        expected += state.canonical_weight / target_c * colour_c;
    }
    for (var slot = 0u; slot < state.slots; slot++) {
        if state.weights[slot] > 0.0 && state.targets[slot] > 0.0 {
            expected += state.weights[slot] / state.targets[slot] * state.colours[slot];
        }
    }
    return expected;
}
