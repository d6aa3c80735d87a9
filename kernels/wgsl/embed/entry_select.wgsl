// strata_select: the stratified selection of the paper (§4.2, Fig. 3, Table 2) for an
// engine's own candidates. Each pixel with a candidate takes K <= 4 members of its
// cluster's run in its block's luminance-sorted list (the histogram pass's output) at the
// positions of the chosen sampler variant (strata/selection.wgsl: selection_numbers with
// the spatial dimension pair, run_member) and gets their payload indices. Every member of
// a run is selected K/n times in expectation over renders whatever the keys, for every K
// and sampler, so the engine's resampling stays unbiased with a fixed 1/K normalisation.
//
// Bindings (group 0):
//   0 uniform            SelectionParams
//   1 storage, read      array<Candidate>           the engine's candidates (the histogram's input)
//   2 storage, read      array<u32>                 the engine's payload per pixel (unread when
//                                                   identity_payload = 1; bind any buffer)
//   3 storage, read      array<u32>                 sorted_pixels (histogram output)
//   4 storage, read      array<ClusterSpan>         spans (histogram output)
//   5 storage, read      array<u32>                 blue_noise (BlueNoiseTables::packed)
//   6 storage, rw        array<SelectedCandidates>  one per pixel
//
// Dispatch: 8 x 8 pixels per workgroup, ceil(width / 8) x ceil(height / 8) workgroups.
// Every buffer access is guarded by the bound buffer's length (arrayLength): buffers too
// small for the image lose the pixels past their end, nothing outside them is touched.

// #import strata/candidate.wgsl
// #import strata/selection.wgsl
// #import embed/contract.wgsl

@group(0) @binding(0) var<uniform> params: SelectionParams;
@group(0) @binding(1) var<storage, read> candidates: array<Candidate>;
@group(0) @binding(2) var<storage, read> payloads: array<u32>;
@group(0) @binding(3) var<storage, read> sorted_pixels: array<u32>;
@group(0) @binding(4) var<storage, read> spans: array<ClusterSpan>;
@group(0) @binding(5) var<storage, read> blue_noise: array<u32>;
@group(0) @binding(6) var<storage, read_write> selections: array<SelectedCandidates>;

fn payload_of(pixel: u32) -> u32 {
    if params.identity_payload != 0u {
        return pixel;
    }
    if pixel < arrayLength(&payloads) {
        return payloads[pixel];
    }
    return NO_PAYLOAD;
}

// The pixel index at `entry` of the sorted list, or NO_PAYLOAD (past every image, so its
// payload is NO_PAYLOAD too) for an entry past the end of the bound buffer.
fn sorted_pixel(entry: u32) -> u32 {
    if entry < arrayLength(&sorted_pixels) {
        return sorted_pixels[entry];
    }
    return NO_PAYLOAD;
}

@compute @workgroup_size(8, 8)
fn strata_select(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let pixel = id.y * params.width + id.x;
    // Buffers too small for the image (an engine's mistake, named by the C ABI's
    // validation mode): the pixels past their end are left alone, nothing outside a
    // buffer is read or written.
    if pixel >= arrayLength(&selections) || pixel >= arrayLength(&candidates) || pixel >= arrayLength(&spans) {
        return;
    }
    let k = clamp(params.candidates, 1u, MAX_SELECTED);
    let numbers = selection_numbers(id.xy, params.frame, params.seed, params.sampler, k, 0u);
    var result = SelectedCandidates(vec4<u32>(NO_PAYLOAD), numbers.resample, 0u, 0u, 0u);
    let span = spans[pixel];
    if candidates[pixel].object_id == OBJECT_ID_NONE || span.length == 0u {
        selections[pixel] = result;
        return;
    }
    result.run_length = span.length;
    result.run_valid = span.valid;
    result.selected = k;
    for (var slot = 0u; slot < k; slot++) {
        result.payloads[slot] = payload_of(sorted_pixel(run_member(span, numbers.positions[slot])));
    }
    selections[pixel] = result;
}
