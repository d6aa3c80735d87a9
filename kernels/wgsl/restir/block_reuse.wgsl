// Spatial reuse among this frame's block histogram, shared by restir_select (the K
// candidates of the paper's order, paper §4.2) and restir_spatial (the K merged
// reservoirs of the temporal-first order), so both draw their K the same way (and keep
// one sample the same way: restir/resampling_core.wgsl):
//   block_slot_pixel  the pixel that reuse slot `slot` takes: the histogram's run of the
//                     pixel's cluster at the slot's position (strata: stratified; restir:
//                     uniform), or a disc neighbour (restir-disc; restir/reuse_slot.wgsl)
//
// Needs from the kernel that includes it: `restir`, `spans` and `sorted_pixels` (the
// histogram's outputs, bindings 12 and 11), and what restir/reuse_slot.wgsl needs.

// #import strata/candidate.wgsl
// #import strata/selection.wgsl
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
