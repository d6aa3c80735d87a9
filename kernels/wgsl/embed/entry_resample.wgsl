// strata_resample: stratified resampling by inverse CDF (paper §4.2): one of the pixel's
// own canonical sample and its K selected samples, in proportion to the engine's
// resampling weights, using the pixel's resampling number from strata_select (the second
// dimension of the sampler) instead of a streaming reservoir's random numbers:
//   u = r * sum(w);  the first of (canonical, slot 0, ..., slot K-1) whose running sum
//   exceeds u; W = sum(w) / target(chosen).
// Rounding may leave u past the last running sum: then the last sample of positive weight
// is taken. A NaN, infinite or negative weight or target marks the pixel INVALID_SLOT.
//
// Bindings (group 0):
//   0 uniform            SelectionParams
//   1 storage, read      array<SelectedCandidates>  strata_select's output
//   2 storage, read      array<ResampleInput>       the engine's weights and targets
//   3 storage, rw        array<ResampleOutput>      one per pixel
//
// Dispatch: 8 x 8 pixels per workgroup, ceil(width / 8) x ceil(height / 8) workgroups.

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
    let selection = selections[pixel];
    let input = resample_inputs[pixel];
    let k = selection.selected;
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
    let u = selection.resample_number * total;
    var running = input.canonical_weight;
    var found = u < running;
    var slot_chosen = NO_SLOT;
    if input.canonical_weight > 0.0 {
        slot_chosen = CANONICAL_SLOT;
    }
    for (var slot = 0u; slot < k; slot++) {
        if !found && input.weights[slot] > 0.0 {
            running += input.weights[slot];
            slot_chosen = slot;
            found = u < running;
        }
    }
    var payload = input.canonical_payload;
    var target_value = input.canonical_target;
    if slot_chosen < MAX_SELECTED {
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
