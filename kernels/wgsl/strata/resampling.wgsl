// The last step of the stratified selection (paper §4.2): inverse-CDF resampling. Of the
// pixel's canonical sample and its selected samples, one is chosen in proportion to its
// resampling weight using the pixel's resampling number r (the second dimension of the
// sampler, strata/selection.wgsl) instead of a streaming reservoir's random numbers, so
// the choice is stratified across frames like the selection. Used by restir_select and
// restir_temporal (strata only) and by the embeddable strata_resample.
//
// Entries are visited in order with u = r * (total weight): the chosen entry is the first
// whose running sum exceeds u. Rounding may leave u past the last running sum; then the
// last entry of positive weight is kept. Start with inverse_cdf_first on the canonical
// entry, then call inverse_cdf_next on each other entry; `chosen` is the id given with
// the chosen entry.

struct InverseCdf {
    u: f32,
    running: f32,
    found: bool,
    chosen: u32,
}

fn inverse_cdf_first(u: f32, weight: f32, id: u32) -> InverseCdf {
    return InverseCdf(u, weight, u < weight, id);
}

fn inverse_cdf_next(state: InverseCdf, weight: f32, id: u32) -> InverseCdf {
    var next = state;
    if !next.found && weight > 0.0 {
        next.running += weight;
        next.chosen = id;
        next.found = next.u < next.running;
    }
    return next;
}
