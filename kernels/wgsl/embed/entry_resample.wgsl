// strata_resample: stratified resampling by inverse CDF (paper §4.2): one of the pixel's
// own canonical sample and its K selected samples, in proportion to the engine's
// resampling weights, using the pixel's resampling number from strata_select (the second
// dimension of the sampler) instead of a streaming reservoir's random numbers
// (strata/resampling.wgsl: inverse_cdf_first / inverse_cdf_next over (canonical, slot 0,
// ..., slot K-1) with u = r * sum(w)); W = sum(w) / target(chosen).
// A NaN, infinite or negative weight or target marks the pixel INVALID_SLOT.
//
// Bindings (group 0):
//   0 uniform            SelectionParams
//   1 storage, read      array<SelectedCandidates>  strata_select's output
//   2 storage, read      array<ResampleInput>       the engine's weights and targets
//   3 storage, rw        array<ResampleOutput>      one per pixel
//
// Dispatch: 8 x 8 pixels per workgroup, ceil(width / 8) x ceil(height / 8) workgroups.
// Every buffer access is guarded by the bound buffer's length (arrayLength): buffers too
// small for the image lose the pixels past their end, nothing outside them is touched.

// #import gpu/selection.wgsl
// #import strata/resampling.wgsl
// #import embed/contract.wgsl

@group(0) @binding(0) var<uniform> params: SelectionParams;
@group(0) @binding(1) var<storage, read> selections: array<SelectedCandidates>;
@group(0) @binding(2) var<storage, read> resample_inputs: array<ResampleInput>;
@group(0) @binding(3) var<storage, read_write> resampled: array<ResampleOutput>;

// Finite and non-negative, decided on the bits so every backend agrees.
fn usable(value: f32) -> bool {
    let bits = bitcast<u32>(value);
    return (bits & 0x7fffffffu) == 0u || ((bits >> 31u) == 0u && bits < 0x7f800000u);
}

@compute @workgroup_size(8, 8)
fn strata_resample(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let pixel = id.y * params.width + id.x;
    // Buffers too small for the image (an engine's mistake, named by the C ABI's
    // validation mode): the pixels past their end are left alone, nothing outside a
    // buffer is read or written.
    if pixel >= arrayLength(&resampled) || pixel >= arrayLength(&selections) || pixel >= arrayLength(&resample_inputs) {
        return;
    }
    let selection = selections[pixel];
    let input = resample_inputs[pixel];
    // At most MAX_SELECTED: a selection left unwritten (an engine's too-small buffers,
    // whose pixels strata_select skips) must not make the loops below run for whatever
    // its word holds.
    let k = min(selection.selected, MAX_SELECTED);
    var ok = usable(input.canonical_weight) && usable(input.canonical_target);
    var total = input.canonical_weight;
    for (var slot = 0u; slot < k; slot++) {
        ok = ok && usable(input.weights[slot]) && usable(input.targets[slot]);
        total += input.weights[slot];
    }
    if !ok || !usable(total) {
        resampled[pixel] = ResampleOutput(NO_PAYLOAD, INVALID_SLOT, 0.0, 0.0);
        return;
    }
    if !(total > 0.0) {
        resampled[pixel] = ResampleOutput(NO_PAYLOAD, NO_SLOT, 0.0, 0.0);
        return;
    }
    let first = select(NO_SLOT, CANONICAL_SLOT, input.canonical_weight > 0.0);
    var choice = inverse_cdf_first(selection.resample_number * total, input.canonical_weight, first);
    for (var slot = 0u; slot < k; slot++) {
        choice = inverse_cdf_next(choice, input.weights[slot], slot);
    }
    let slot_chosen = choice.chosen;
    var payload = input.canonical_payload;
    var target_value = input.canonical_target;
    if slot_chosen < k {
        payload = selection.payloads[slot_chosen];
        target_value = input.targets[slot_chosen];
    }
    if !(target_value > 0.0) {
        // A positive weight with a zero target: the engine's weights are inconsistent.
        resampled[pixel] = ResampleOutput(NO_PAYLOAD, INVALID_SLOT, 0.0, total);
        return;
    }
    resampled[pixel] = ResampleOutput(payload, slot_chosen, total / target_value, total);
}
