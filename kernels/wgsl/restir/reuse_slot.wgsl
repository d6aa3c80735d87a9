// Where a reuse slot of a pixel looks, by RestirParams.method: shared by restir_select
// (the K spatial candidates, paper §4.2) and restir_temporal (the T extra previous-frame
// reservoirs of Fig. 11), so both draw their neighbours the same way.
//   strata      position `pos` in [0, 1) of the pixel's sorted cluster run (the
//               stratified positions of strata/selection.wgsl, run_member)
//   restir      the same run at a uniformly random position
//   restir-disc a uniformly random pixel of the disc of RestirParams.disc_radius pixels,
//               kept only if it resamples, with the same path segment and kind of
//               shift (reservoir.wgsl, may_share), faces the same way (normals
//               within 25 degrees) and lies at a similar depth (10 %)
//
// Needs from the kernel that includes it: `params`, `restir`, `primaries` (this frame's
// G-buffer, binding 9) and `random()`; random() is drawn only where the method needs it
// (two numbers for the disc, one for restir), in that order.

// #import strata/selection.wgsl
// #import restir/reservoir.wgsl
// #import render/turns.wgsl
// #requires var<storage, read> primaries: array<Primary>

// The disc neighbour of pixel (x, y) with primary hit `p` (restir-disc), or NO_PIXEL.
fn disc_neighbour(x: u32, y: u32, p: Primary) -> u32 {
    let r = restir.disc_radius * sqrt(random());
    let phi = sin_cos_turns(random());
    let qx = i32(floor(f32(x) + 0.5 + r * phi.y));
    let qy = i32(floor(f32(y) + 0.5 + r * phi.x));
    if qx < 0 || qy < 0 || qx >= i32(params.width) || qy >= i32(params.height) {
        return NO_PIXEL;
    }
    let q = u32(qy) * params.width + u32(qx);
    let n = primaries[q];
    if (n.flags & PRIMARY_RESAMPLE) == 0u || !may_share(n, p) || dot(n.normal, p.normal) < 0.906
        || abs(n.depth - p.depth) > 0.1 * p.depth {
        return NO_PIXEL;
    }
    return q;
}

// The index into a sorted list that a slot with position `position` takes in the run
// `span` (strata: the stratified position, strata/selection.wgsl; restir: a uniform draw
// instead), or NO_PIXEL for an empty run.
fn run_index(span: ClusterSpan, position: f32) -> u32 {
    if span.length == 0u {
        return NO_PIXEL;
    }
    var pos = position;
    if restir.method == METHOD_RESTIR {
        pos = random();
    }
    return run_member(span, pos);
}
