// ReSTIR pass 4c (temporal-first order only, RestirSettings::reuse_order): the histogram
// input of the merged reservoirs. In the standard ReSTIR order (Bitterli et al. 2020:
// temporal merge first, then spatial reuse of the merged reservoirs) the spatial pass
// draws from reservoirs that already carry their history, so strata's block histogram
// (paper §4.1) sorts those instead of this frame's candidates: key = the luminance of the
// merged reservoir's own estimate, p̂ W (its f(Y) W), object id = the pixel's (clustered
// with masking on, §4.3). A pixel that does not resample, or whose reservoir holds
// nothing, gets key 0 (an empty reservoir estimates 0; it still takes part in its
// cluster's run, as a candidate that found nothing does in the paper's order). Only the
// keys' order matters: every selection draws each member of a run with the expected
// count K/n whatever the order (entry_spatial.wgsl), so the pass stays unbiased.
//
// Bindings (group 0): 0-2 the scene (3-7 unused), 8 RestirParams, and
//   9  storage, read     array<Primary>    this frame's G-buffer
//   10 storage, read     array<Reservoir>  the merged reservoirs (restir_temporal)
//   11 storage, rw       array<Candidate>  the block histogram's input
//
// Dispatch: 8 x 8 pixels per workgroup.

// #import render/scene.wgsl
// #import strata/candidate.wgsl
// #import restir/reservoir.wgsl

@group(0) @binding(9) var<storage, read> primaries: array<Primary>;
@group(0) @binding(10) var<storage, read> merged_reservoirs: array<Reservoir>;
@group(0) @binding(11) var<storage, read_write> histogram_in: array<Candidate>;

// The histogram's candidate of `pixel`: its merged reservoir's estimate p̂ W as the key
// (0 where it is not finite and non-negative) under its object id; no candidate where the
// pixel does not resample.
fn reservoir_key(pixel: u32) -> Candidate {
    let p = primaries[pixel];
    if (p.flags & PRIMARY_RESAMPLE) == 0u {
        return Candidate(0.0, OBJECT_ID_NONE);
    }
    let reservoir = merged_reservoirs[pixel];
    let estimate = reservoir.target_value * reservoir.weight;
    var key = 0.0;
    if estimate >= 0.0 && estimate < INFINITY {
        key = estimate;
    }
    return Candidate(key, p.object_id);
}

@compute @workgroup_size(8, 8)
fn restir_reservoir_keys(@builtin(global_invocation_id) id: vec3<u32>) {
    let pixel = image_pixel(id);
    if pixel != NO_PIXEL {
        histogram_in[pixel] = reservoir_key(pixel);
    }
}
