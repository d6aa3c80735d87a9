// ReSTIR pass 4a: the temporal candidates. Each resampling pixel finds the previous
// frame's pixel its camera ray's hit reprojects to (RestirParams.previous_* camera) and
// keeps it as its temporal source unless that pixel resampled at another object, with
// another path segment (through another smooth chain), facing another way (normals
// beyond 25 degrees) or at another depth (10 %): a disocclusion. For the
// multiple-temporal-reservoir mode (paper Fig. 11: "sampling temporal reservoirs
// similarly to spatial candidates"), it also writes the histogram input of the temporal
// candidates: key = luminance of the source reservoir's own estimate p̂ W (its f(Y) W),
// object id = the pixel's (the histogram clusters by it with masking on, §4.3). A pixel without a source keeps its cluster with
// an invalid key (it sorts last in the run; drawing it gives an empty slot), so a
// disoccluded pixel can still draw its neighbours' histories.
//
// Permutation sampling (RestirParams.permutation_sampling; RTXDI's decorrelation of the
// history): the reprojected pixel is replaced by its mirror image within an aligned 4 x 4
// group of pixels (x -> x XOR 3, y -> y XOR 3), the groups shifted by an offset of 0-3
// pixels per axis that changes every frame, so a pixel's history comes from 1 or 3
// pixels away on each axis. Within a frame `permuted` is a permutation of the image
// (mirroring is its own inverse; pixels whose mirror image would leave the image stay
// where they are), so each previous reservoir feeds one pixel, no longer the pixel at the
// same place: the chains of history that make neighbouring pixels' errors alike are
// broken up frame by frame. The permuted pixel must pass the same similarity test;
// otherwise the reprojected one is used (then a previous pixel may feed two, and its
// mirror image none: a few per cent of the pixels on the default scene). Unbiased:
// which source a pixel takes depends on the G-buffers alone, and the temporal merge
// weighs whatever source it is given by pairwise MIS with targets evaluated at both ends.
//
// Bindings (group 0): 0-2 the scene (3-7 unused), 8 RestirParams, and
//   9  storage, read     array<Primary>    this frame's G-buffer
//   10 storage, read     array<Primary>    the previous frame's G-buffer
//   11 storage, read     array<Reservoir>  the previous frame's final reservoirs
//   12 storage, rw       array<Candidate>  the temporal histogram's input
//   13 storage, rw       array<u32>        per pixel its temporal source pixel (0xffffffff: none)
//
// Dispatch: 8 x 8 pixels per workgroup.

// #import render/scene.wgsl
// #import render/random.wgsl
// #import strata/candidate.wgsl
// #import restir/reservoir.wgsl

@group(0) @binding(9) var<storage, read> primaries: array<Primary>;
@group(0) @binding(10) var<storage, read> previous_primaries: array<Primary>;
@group(0) @binding(11) var<storage, read> previous_reservoirs: array<Reservoir>;
@group(0) @binding(12) var<storage, read_write> temporal_keys: array<Candidate>;
@group(0) @binding(13) var<storage, read_write> temporal_sources: array<u32>;

const NO_SOURCE: u32 = 0xffffffffu;

// The previous frame's pixel that saw `position`, or NO_SOURCE outside its image.
fn reproject(position: vec3<f32>) -> u32 {
    let q = image_position(
        position, restir.previous_origin, restir.previous_forward, restir.previous_right, restir.previous_up,
        restir.previous_tan_half_x, restir.previous_tan_half_y,
    );
    if q.z <= 0.0 {
        return NO_SOURCE;
    }
    let px = q.x;
    let py = q.y;
    if !(px >= 0.0 && py >= 0.0 && px < f32(params.width) && py < f32(params.height)) {
        return NO_SOURCE;
    }
    return u32(py) * params.width + u32(px);
}

// Whether the previous frame's pixel `q` saw the same surface as `p` (not a disocclusion).
fn same_surface(p: Primary, q: u32) -> bool {
    let previous = previous_primaries[q];
    return (previous.flags & PRIMARY_RESAMPLE) != 0u && previous.object_id == p.object_id && may_share(previous, p)
        && dot(previous.normal, p.normal) >= 0.906 && abs(previous.depth - p.depth) <= 0.1 * p.depth;
}

// Pixel `q` of the previous frame permuted (see the header): mirrored within its 4 x 4
// group, the groups shifted by this frame's offset; `q` itself where the mirror image
// falls outside the image.
fn permuted(q: u32) -> u32 {
    let frame_bits = pcg_hash(params.seed ^ pcg_hash(params.sample_index + 0x9e3779b9u));
    let offset = vec2<u32>(frame_bits & 3u, (frame_bits >> 2u) & 3u);
    let position = vec2<u32>(q % params.width, q / params.width);
    // Shift, mirror, shift back: + 4 keeps the shifted position from wrapping below 0. The
    // result wraps (to about 2^32) where the mirror image falls left of or above the image,
    // and the test below catches it with those past the right and bottom edges.
    let mirrored = (((position + 4u - offset) ^ vec2<u32>(3u)) + offset) - vec2<u32>(4u);
    if mirrored.x >= params.width || mirrored.y >= params.height {
        return q;
    }
    return mirrored.y * params.width + mirrored.x;
}

@compute @workgroup_size(8, 8)
fn restir_temporal_keys(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let pixel = id.y * params.width + id.x;
    let p = primaries[pixel];
    var source = NO_SOURCE;
    var key = -1.0;
    var object = OBJECT_ID_NONE;
    if restir.temporal != 0u && (p.flags & PRIMARY_RESAMPLE) != 0u {
        object = p.object_id;
        // The point the pixel sees: its resampling vertex, or the smooth surface in front
        // of it (Primary.camera_hit).
        var q = reproject(p.camera_hit);
        if q != NO_SOURCE && restir.permutation_sampling != 0u {
            let swapped = permuted(q);
            if same_surface(p, swapped) {
                q = swapped;
            }
        }
        if q != NO_SOURCE {
            if same_surface(p, q) {
                source = q;
                let reservoir = previous_reservoirs[q];
                let estimate = reservoir.target_value * reservoir.weight;
                if estimate >= 0.0 && estimate < INFINITY {
                    key = estimate;
                }
            }
        }
    }
    temporal_keys[pixel] = Candidate(key, object);
    temporal_sources[pixel] = source;
}
