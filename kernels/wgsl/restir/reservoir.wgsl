// Records shared by the ReSTIR passes (paper §4; reconnection shift of ReSTIR GI /
// ReSTIR PT, Lin et al. 2022) and the functions every pass evaluates the same way.
// The records (RestirParams, Primary, PathCandidate, Reservoir) and their constants are
// declared once in Rust, kernels/src/restir_types.rs, which generates gpu/restir.wgsl.
//
// A pixel's candidate is the vertex x2 after its primary hit y1, with the radiance x2
// emits and reflects towards y1: either the BSDF-sampled continuation of its path or its
// next-event light sample, one of the two chosen by RIS (balance heuristic over the two
// techniques), with its unbiased contribution weight. x2 is a surface point (kind
// SURFACE, shared with other pixels by reconnecting their own y1 to x2), an environment
// direction (kind ENVIRONMENT), or, when x2 is not Lambertian (its reflected radiance
// depends on the direction it is seen from), a point only its own pixel may use (kind
// PRIVATE). Surface candidates live in area measure at x2, environment candidates in
// solid angle: the reconnection shift then has Jacobian 1.
//
// Random replay (RestirParams.replay, the other half of ReSTIR PT's hybrid shift, Lin et
// al. 2022): a glossy conductor (GGX alpha below min_roughness) is too sharp to reconnect
// from, and with replay on it resamples at its own vertex all the same. Its candidate
// (kind REPLAY) is the random numbers of the rest of its path, a PCG state: the path
// tracer's estimate from the vertex, Ĉ(y, u) = next-event estimation plus one
// BSDF-sampled continuation and everything after it (render/path.wgsl, scatter_at), is a
// deterministic function of the vertex y and the numbers u. Another replay pixel uses the
// candidate by re-tracing its own path from its own vertex with the same numbers. The
// candidates then live in primary sample space, where u is uniform (density 1): the
// shift is the identity on u, its Jacobian 1, a pixel's own candidate has W = 1, and the
// integrand is f_y(u) = Ĉ(y, u), whose integral over u is the radiance y reflects towards
// the previous vertex (the path tracer is unbiased). p̂ is its luminance as for every
// other kind, visibility included by the tracing. Replay pixels and reconnection pixels
// share nothing (p̂ = 0 both ways), like pixels of different path segments, so each kind
// of pixel resamples its own integral with the same GRIS weights.
//
// Bindings used with this fragment (group 0): 0-2 the scene (render/scene.wgsl) and
//   8 uniform            RestirParams      the method and its settings

// #import gpu/restir.wgsl
// #import render/path.wgsl
// #import strata/candidate.wgsl

// Whether this pipeline can meet replay pixels and candidates (RestirParams.replay set:
// RestirSettings::glossy_replay). strata's renderer makes its pipelines for settings
// without random replay with `false` (Registry::specialised), and a driver then
// drops the path re-trace of `replayed` as dead code from the passes that weigh
// candidates (select, spatial, temporal, shade; the others never reach `integrand`, so
// naga's specialisation drops the override there). Why it matters: a CPU driver that runs
// a workgroup's invocations side by side in SIMD lanes (lavapipe, Mesa 22.3) executes the
// body of every `if` under a mask, taken by no lane or not, and the first iteration of
// every loop: with the re-trace in, restir_select took 4.5-4.8 ms of a 32 x 32 frame
// without one replay pixel, 2.5 ms without it (2026-11-30, docs/benchmarks/ci-time.md).
// The default, `true`, is the general kernel every registry pipeline was before.
override random_replay: bool = true;

// No pixel for a reuse slot (restir/reuse_slot.wgsl): the slot stays empty.
const NO_PIXEL: u32 = 0xffffffffu;

@group(0) @binding(8) var<uniform> restir: RestirParams;

// Where `point` lands on a camera's film in pixels (x right, y down; pixel centres at
// integer + 0.5), and its depth along the camera's axis in z (divided by when not
// positive: callers test z first). The temporal reprojection (entry_temporal_keys.wgsl)
// and the denoiser's motion vectors (entry_guide.wgsl) both project with it.
fn image_position(
    point: vec3<f32>,
    origin: vec3<f32>,
    forward: vec3<f32>,
    right: vec3<f32>,
    up: vec3<f32>,
    tan_half_x: f32,
    tan_half_y: f32,
) -> vec3<f32> {
    let d = point - origin;
    let z = dot(d, forward);
    let sx = dot(d, right) / (z * tan_half_x);
    let sy = dot(d, up) / (z * tan_half_y);
    return vec3<f32>((sx + 1.0) * 0.5 * f32(params.width), (1.0 - sy) * 0.5 * f32(params.height), z);
}

// The index of invocation `id`'s pixel in the image (rows of params.width), or NO_PIXEL
// for an invocation past the image's edge (the last workgroups of a row or column).
fn image_pixel(id: vec3<u32>) -> u32 {
    if id.x >= params.width || id.y >= params.height {
        return NO_PIXEL;
    }
    return id.y * params.width + id.x;
}

fn luminance(c: vec3<f32>) -> f32 {
    return dot(c, vec3<f32>(0.2126, 0.7152, 0.0722));
}

fn finite3(v: vec3<f32>) -> bool {
    let bits = bitcast<vec3<u32>>(v) & vec3<u32>(0x7f800000u);
    return all(bits != vec3<u32>(0x7f800000u));
}

// Direction from y1 to the candidate and the area-to-solid-angle factor |cos x2| / d²
// (1 for an environment candidate); w = distance (0 for the environment).
fn towards(p: Primary, x: PathCandidate) -> vec4<f32> {
    if x.kind == KIND_ENVIRONMENT {
        return vec4<f32>(x.position, 0.0);
    }
    let to = x.position - p.position;
    let distance = length(to);
    return vec4<f32>(to / distance, distance);
}

fn geometry_factor(x: PathCandidate, direction: vec3<f32>, distance: f32) -> f32 {
    if x.kind == KIND_ENVIRONMENT {
        return 1.0;
    }
    return abs(dot(x.normal, direction)) / (distance * distance);
}

// Ĉ(p, u): the path tracer's estimate of the radiance resampling vertex `p` reflects
// towards p.wo, with the random numbers of PCG state `seed`, traced from the vertex
// (visibility included). The caller's own random stream is left where it was. A
// traversal stack overflow gives nothing.
fn replayed_sample(p: Primary, seed: u32, lane: u32) -> PathSample {
    let saved = rng_state;
    rng_state = seed;
    let sample = scatter_at(p.position, p.normal, scene_material(p.material), p.albedo, p.wo, p.segment, lane);
    rng_state = saved;
    return sample;
}

// The contribution of replay candidate `x` to replay pixel `p`: Ĉ(p, u), read from the
// candidate where `p` is the vertex it was drawn at (the replay is deterministic: same
// vertex, same numbers, same path), re-traced otherwise.
fn replayed(p: Primary, x: PathCandidate, lane: u32) -> vec3<f32> {
    if all(p.position == x.position) && all(p.wo == x.normal) {
        return x.reflected;
    }
    let sample = replayed_sample(p, x.light, lane);
    // As the candidates pass drops a non-finite own estimate, so a replay gives nothing
    // (an infinite value would turn a merge's total into NaN and empty the reservoir).
    if sample.invalid || !finite3(sample.radiance) {
        return vec3<f32>(0.0);
    }
    return sample.radiance;
}

// The contribution of candidate `x` to the pixel whose primary hit is `p`, in the
// candidate's measure, visibility excluded: f(y1) cos (Le(x2) + Lr(x2)) |cos x2| / d².
// Emission and reflection are both resampled: nothing of the first bounce is left to
// the pixel alone but the emission it sees directly. A replay candidate's contribution
// is the replayed path's (visibility included).
fn integrand(p: Primary, x: PathCandidate, lane: u32) -> vec3<f32> {
    if x.kind == KIND_NONE || (p.flags & PRIMARY_RESAMPLE) == 0u {
        return vec3<f32>(0.0);
    }
    let replay_pixel = (p.flags & PRIMARY_REPLAY) != 0u;
    if replay_pixel != (x.kind == KIND_REPLAY) {
        return vec3<f32>(0.0);
    }
    if replay_pixel {
        if !random_replay {
            // Never met: a pipeline without random replay runs with RestirParams.replay
            // off, where no pixel replays (and gives nothing if one did).
            return vec3<f32>(0.0);
        }
        return replayed(p, x, lane);
    }
    return reconnection_integrand(p, x);
}

// `integrand` for a candidate `x` that is no replay (of a pixel `p` that resamples and
// does not replay): the reconnection's f(y1) cos (Le(x2) + Lr(x2)) |cos x2| / d², which
// traces nothing.
fn reconnection_integrand(p: Primary, x: PathCandidate) -> vec3<f32> {
    let t = towards(p, x);
    let direction = t.xyz;
    let material = scene_material(p.material);
    let frame = make_frame(p.normal);
    let f = bsdf_eval(material, p.albedo, to_local(frame, p.wo), to_local(frame, direction));
    if all(f == vec3<f32>(0.0)) {
        return vec3<f32>(0.0);
    }
    var emitted = vec3<f32>(0.0);
    if x.kind == KIND_ENVIRONMENT {
        if params.env_width > 0u {
            emitted = environment_radiance(direction);
        }
    } else if x.light != NO_LIGHT && -dot(x.normal, direction) > 0.0 {
        emitted = scene_light(x.light).radiance;
    }
    return f * (emitted + x.reflected) * geometry_factor(x, direction, t.w);
}

// p̂: the luminance of `integrand`.
fn target_function(p: Primary, x: PathCandidate, lane: u32) -> f32 {
    return luminance(integrand(p, x, lane));
}

// Density with which the BSDF sampling at `p` finds candidate `x`, in the candidate's
// measure (visibility not included).
fn bsdf_density(p: Primary, x: PathCandidate) -> f32 {
    let t = towards(p, x);
    let frame = make_frame(p.normal);
    let pdf = bsdf_pdf(scene_material(p.material), to_local(frame, p.wo), to_local(frame, t.xyz));
    return pdf * geometry_factor(x, t.xyz, t.w);
}

// Whether pixels whose resampling vertices are `a` and `b` may share candidates: their
// paths reach them with the same segment, so a candidate's reflected radiance, estimated
// with the segments left after it, is the same integrand at both (reservoirs only ever
// hold samples of their own segment, so this is a property of each sample too).
fn same_segment(a: Primary, b: Primary) -> bool {
    return a.segment == b.segment;
}

// Whether pixels whose resampling vertices are `a` and `b` resample the same kind of
// integral and so may share candidates and histories: the same segment, and both
// reconnection pixels or both replay pixels (p̂ is 0 across the kinds; a merge with the
// other kind would merge nothing yet count its confidence M).
fn may_share(a: Primary, b: Primary) -> bool {
    return same_segment(a, b) && (a.flags & PRIMARY_REPLAY) == (b.flags & PRIMARY_REPLAY);
}

// Whether the pixel of `p` may reconnect to candidate `x`: both rough, x shareable,
// x2 far enough from y1 and seen from the side its reflected radiance was computed for.
// A replay pixel takes replay candidates only, and every one of them (by replaying it).
fn reconnectable(p: Primary, x: PathCandidate) -> bool {
    if (p.flags & PRIMARY_RESAMPLE) == 0u {
        return false;
    }
    let replay_pixel = (p.flags & PRIMARY_REPLAY) != 0u;
    if replay_pixel || x.kind == KIND_REPLAY {
        return replay_pixel && x.kind == KIND_REPLAY;
    }
    if x.kind == KIND_ENVIRONMENT {
        return true;
    }
    if x.kind != KIND_SURFACE {
        return false;
    }
    let to_primary = p.position - x.position;
    return length(to_primary) >= restir.min_distance && dot(x.normal, to_primary) > 0.0;
}

// Visibility between y1 and the candidate (a replayed path carries its own).
fn candidate_visible(p: Primary, x: PathCandidate, lane: u32) -> bool {
    if x.kind == KIND_REPLAY {
        return true;
    }
    var ray = shadow_ray_to(p.position, p.normal, x.position);
    if x.kind == KIND_ENVIRONMENT {
        ray = shadow_ray_along(p.position, p.normal, x.position);
    }
    return ray_unblocked(ray, lane);
}
