// Spatial reuse among this frame's block histogram, shared by restir_select (the K
// candidates of the paper's order, paper §4.2) and restir_spatial (the K merged
// reservoirs of the temporal-first order), so both draw their K and keep one sample the
// same way:
//   block_slot_pixel  the pixel that reuse slot `slot` takes: the histogram's run of the
//                     pixel's cluster at the slot's position (strata: stratified; restir:
//                     uniform), or a disc neighbour (restir-disc; restir/reuse_slot.wgsl)
//   resampled_slot    which of the canonical sample and the K slots is kept, in
//                     proportion to their resampling weights: by inverse CDF with the
//                     selection's second number for strata (strata/resampling.wgsl), by
//                     streaming weighted reservoir sampling in slot order for the baselines
//
// Needs from the kernel that includes it: `restir`, `spans` and `sorted_pixels` (the
// histogram's outputs, bindings 12 and 11), what restir/reuse_slot.wgsl needs, and
// `random()`, drawn only by the baselines' streaming choice (one number per slot with a
// positive weight, in slot order).

// #import render/random.wgsl
// #import strata/candidate.wgsl
// #import strata/selection.wgsl
// #import strata/resampling.wgsl
// #import restir/reservoir.wgsl
// #import restir/reuse_slot.wgsl
// #requires var<storage, read> sorted_pixels: array<u32>
// #requires var<storage, read> spans: array<ClusterSpan>

// The pixel that reuse slot `slot` of pixel (x, y) takes, or NO_PIXEL for none.
fn block_slot_pixel(x: u32, y: u32, pixel: u32, p: Primary, slot: u32, positions: vec4<f32>) -> u32 {
    if restir.method == METHOD_RESTIR_DISC {
        return disc_neighbour(x, y, p);
    }
    let index = run_index(spans[pixel], positions[slot]);
    if index == NO_PIXEL {
        return NO_PIXEL;
    }
    return sorted_pixels[index];
}

// The kept sample among the canonical one (weight `weight_c`; returned as MAX_SELECTED)
// and the first `k` slots (`weights`), `total` their sum and `resample` strata's
// resampling number in [0, 1).
fn resampled_slot(weight_c: f32, weights: vec4<f32>, k: u32, total: f32, resample: f32) -> u32 {
    if restir.method == METHOD_STRATA {
        var choice = inverse_cdf_first(resample * total, weight_c, MAX_SELECTED);
        for (var slot = 0u; slot < k; slot++) {
            choice = inverse_cdf_next(choice, weights[slot], slot);
        }
        return choice.chosen;
    }
    var chosen = MAX_SELECTED;
    var running = weight_c;
    for (var slot = 0u; slot < k; slot++) {
        if weights[slot] > 0.0 {
            running += weights[slot];
            if random() * running < weights[slot] {
                chosen = slot;
            }
        }
    }
    return chosen;
}
