// ReSTIR pass 1 (paper §5.1 "candidate generation"): every pixel traces one path. Its
// resampling vertex y (the primary hit y1, see below) goes to the G-buffer, with the
// object id that the histogram clusters by (§4.3). The pixel draws two samples of the
// next vertex x after y, one by BSDF sampling (the path's continuation, with the
// radiance the rest of the path brings back) and one by next-event estimation (a light
// point or environment direction), and keeps one by RIS with balance-heuristic weights
// p̂ / (p_bsdf + p_light): its candidate, with its unbiased contribution weight W, keyed
// for the histogram by the luminance of its own estimate f(Y) W (§4.1). `base_radiance`
// holds what is not resampled: the emission y1 shows the camera.
//
// A glossy conductor (GGX alpha below RestirParams.min_roughness) with RestirParams.replay
// on resamples at its own vertex by random replay: its candidate is the random numbers of
// the rest of its path (kind REPLAY, restir/reservoir.wgsl derives why that is unbiased),
// and the key is the luminance of the estimate Ĉ(y, u) they give there.
//
// Other smooth primary hits (a dielectric; a conductor below min_roughness without replay)
// are too sharp to reconnect from. With RestirParams.specular_chain > 0 the path goes on
// through up to that many smooth vertices exactly as the path tracer would (BSDF
// sampling, next-event estimation at glossy conductors, MIS-weighted emission, Russian
// roulette; all of it into `base_radiance`, weighted by the throughput so far) and the
// first rough vertex it reaches becomes the pixel's resampling vertex, with the chain's
// throughput, the segment number that reached it and the camera ray's hit (for temporal
// reprojection) in its Primary. Why this stays unbiased: given the chain's random
// numbers, which no other pixel sees, the pixel's resampled part estimates the light the
// vertex reflects along the chain (every reuse rule below holds for any vertex, as for
// y1), and the chain's throughput is the path tracer's unbiased weight of that light. A
// pixel that reaches no rough vertex within the chain (the camera ray or the chain
// escaped, the limit, a one-sided back face, the last segment) does not resample: its
// whole path estimate goes to `base_radiance` and its histogram candidate is
// OBJECT_ID_NONE. With specular_chain = 0 every smooth primary hit path-traces alone.
//
// Bindings (group 0): 0-2 the scene (3-7 unused), 8 RestirParams (restir/reservoir.wgsl), and
//   9  storage, rw       array<Primary>        G-buffer, one per pixel
//   10 storage, rw       array<PathCandidate>  one per pixel
//   11 storage, rw       array<Candidate>      the histogram pass's input (key, object id)
//   12 storage, rw       array<vec4<f32>>      base radiance: rgb; a = 1 for an invalid sample
//
// Random numbers: PCG stream of (pixel, params.sample_index = frame, params.seed): film
// jitter, BSDF sampling and the rest of that path, the light sample, the RIS choice.
// Dispatch: 8 x 8 pixels per workgroup.

// #import trace/bvh.wgsl
// #import trace/traverse.wgsl
// #import render/scene.wgsl
// #import render/random.wgsl
// #import render/environment.wgsl
// #import render/albedo.wgsl
// #import render/bsdf.wgsl
// #import render/lights.wgsl
// #import render/path.wgsl
// #import strata/candidate.wgsl
// #import restir/reservoir.wgsl

@group(0) @binding(9) var<storage, read_write> primary_out: array<Primary>;
@group(0) @binding(10) var<storage, read_write> candidates_out: array<PathCandidate>;
@group(0) @binding(11) var<storage, read_write> histogram_in: array<Candidate>;
@group(0) @binding(12) var<storage, read_write> base_radiance: array<vec4<f32>>;

fn no_candidate() -> PathCandidate {
    return PathCandidate(vec3<f32>(0.0), KIND_NONE, vec3<f32>(0.0), NO_LIGHT, vec3<f32>(0.0), 0.0);
}

// Area density with which next-event estimation picks a point on emissive triangle `light`.
fn light_area_density(light: u32) -> f32 {
    let entry = scene_light(light);
    return (1.0 - params.environment_probability) * entry.probability / entry.area;
}

// (p̂, RIS weight p̂ / (p_bsdf + p_light)) of `candidate` at `primary`, given the
// density with which next-event estimation draws it; zero for no candidate. The
// candidate is a reconnection (never a replay, which draw_candidate does not draw).
fn ris_weight(primary: Primary, candidate: PathCandidate, light_density: f32) -> vec2<f32> {
    if candidate.kind == KIND_NONE {
        return vec2<f32>(0.0);
    }
    let target_value = luminance(reconnection_integrand(primary, candidate));
    let density = bsdf_density(primary, candidate) + light_density;
    if !(density > 0.0) {
        return vec2<f32>(target_value, 0.0);
    }
    return vec2<f32>(target_value, target_value / density);
}

// The candidate of surface point `vertex` seen from `origin`, reflecting `reflected`
// towards it: its normal flipped towards the origin, its light only when the origin sees
// the emitting side, shareable when Lambertian.
fn vertex_candidate(vertex: Surface, origin: vec3<f32>, reflected: vec3<f32>) -> PathCandidate {
    let seen_front = dot(vertex.normal, origin - vertex.position) > 0.0;
    let kind = select(KIND_PRIVATE, KIND_SURFACE, scene_material(vertex.material).kind == MATERIAL_DIFFUSE);
    return PathCandidate(
        vertex.position,
        kind,
        select(-vertex.normal, vertex.normal, seen_front),
        select(NO_LIGHT, vertex.light, seen_front),
        reflected,
        0.0,
    );
}

// What drawing the candidate of one resampling vertex gives.
struct Drawn {
    candidate: PathCandidate,
    // The traversal stack overflowed on one of its rays.
    invalid: bool,
}

// The candidate of resampling vertex `primary`, on `surface` (its geometric normal not
// flipped), drawn by BSDF sampling and next-event estimation and chosen by RIS. The
// vertex after it is path segment primary.segment + 1: the rest of the path there is
// estimated with the segments the path tracer would have left.
//
// Both techniques run in one loop whose branches only choose rays and vertices: its
// traversal, the path traced on from the vertex found and the RIS weight are each one
// call, so that a driver, which inlines every call site, compiles each once (BENCHMARKS
// "First run on a fresh machine"). The random numbers are drawn in the order of the two
// techniques one after the other.
fn draw_candidate(primary: Primary, surface: Surface, lane: u32) -> Drawn {
    let material = scene_material(primary.material);
    let albedo = primary.albedo;
    let normal = primary.normal;
    let next_segment = primary.segment + 1u;
    var invalid = false;
    let frame = make_frame(normal);
    let wo = to_local(frame, primary.wo);
    // Technique 0, BSDF sampling: the next vertex of the path. Technique 1, next-event
    // estimation: a point on a light or an environment direction, drawn as
    // render/lights.wgsl draws them. Each gives its candidate and the density with which
    // next-event estimation draws that candidate (for the balance heuristic).
    var bsdf_candidate = no_candidate();
    var bsdf_light_density = 0.0;
    var light_candidate = no_candidate();
    var light_density = 0.0;
    for (var technique = 0u; technique < 2u; technique++) {
        // The technique's ray (none: nothing to trace), whether only its being unblocked
        // matters (a shadow ray), and what it found.
        var ray = Ray();
        var traced = false;
        var shadow = false;
        var direction = vec3<f32>(0.0);
        var candidate = no_candidate();
        var density = 0.0;
        // The light point next-event estimation drew (unless it drew the environment).
        var light_surface = Surface();
        var to_environment = false;
        if technique == 0u {
            let sample = bsdf_sample(material, albedo, wo, random2(), random());
            if any(sample.weight != vec3<f32>(0.0)) && sample.pdf > 0.0 {
                direction = normalize(to_world(frame, sample.wi));
                ray = spawn_ray(surface.position, surface.normal, direction, INFINITY);
                traced = true;
            }
        } else {
            let u_choice = random();
            let u_light = random2();
            if u_choice < params.environment_probability {
                direction = sample_environment(u_light);
                density = environment_light_pdf(direction);
                to_environment = true;
                if density > 0.0 {
                    ray = shadow_ray_along(surface.position, normal, direction);
                    traced = true;
                    shadow = true;
                }
            } else if params.light_count > 0u {
                let light = find_light(random());
                let entry = scene_light(light);
                let tri = bvh_triangle(entry.triangle);
                let su = sqrt(u_light.x);
                let b1 = u_light.y * su;
                let b2 = su - u_light.y * su;
                let point = (1.0 - su) * tri.v0 + b1 * tri.v1 + b2 * tri.v2;
                let info = scene_triangle_info(entry.triangle);
                var uv = vec2<f32>(b1, b2);
                if info.has_uv != 0u {
                    uv = (1.0 - su) * info.uv0 + b1 * info.uv1 + b2 * info.uv2;
                }
                let light_normal = normalize(cross(tri.v1 - tri.v0, tri.v2 - tri.v0));
                light_surface = Surface(point, light_normal, uv, info.object_id, info.material, light);
                density = light_area_density(light);
                ray = shadow_ray_to(surface.position, normal, point);
                traced = true;
                shadow = true;
            }
        }
        var hit = Hit(0.0, 0.0, 0.0, MISS);
        // As ray_unblocked: a shadow ray with nothing left to test (tmax <= 0) is unblocked;
        // a NaN tmax is traced, as it always was.
        if traced && !(ray.tmax <= 0.0) {
            hit = traverse(ray, lane, shadow);
        }
        // The vertex the technique found, the direction towards the primary from it, and
        // whether the path is traced on from it (for the radiance it reflects).
        var found = false;
        var vertex = Surface();
        var to_primary = vec3<f32>(0.0);
        var scatters = false;
        if traced && !shadow {
            if hit.primitive == STACK_OVERFLOW {
                invalid = true;
            } else if hit.primitive == MISS {
                if params.env_width > 0u {
                    candidate = PathCandidate(direction, KIND_ENVIRONMENT, vec3<f32>(0.0), NO_LIGHT, vec3<f32>(0.0), 0.0);
                    density = environment_light_pdf(direction);
                }
            } else {
                vertex = surface_at(hit);
                to_primary = -direction;
                found = true;
                scatters = true;
                if vertex.light != NO_LIGHT {
                    density = light_area_density(vertex.light);
                }
            }
        } else if traced && hit.primitive == MISS {
            if to_environment {
                candidate = PathCandidate(direction, KIND_ENVIRONMENT, vec3<f32>(0.0), NO_LIGHT, vec3<f32>(0.0), 0.0);
            } else {
                vertex = light_surface;
                to_primary = normalize(surface.position - vertex.position);
                found = true;
                // What the light reflects towards y (nothing for a black fixture).
                let light_material = scene_material(vertex.material);
                scatters = light_material.kind != MATERIAL_DIFFUSE
                    || any(albedo_at(light_material, vertex.uv) != vec3<f32>(0.0));
            }
        }
        if found {
            var reflected = vec3<f32>(0.0);
            if scatters {
                let rest = scatter_from(vertex, to_primary, next_segment, lane);
                invalid = invalid || rest.invalid;
                reflected = rest.radiance;
            }
            candidate = vertex_candidate(vertex, surface.position, reflected);
        }
        if technique == 0u {
            bsdf_candidate = candidate;
            bsdf_light_density = density;
        } else {
            light_candidate = candidate;
            light_density = density;
        }
    }
    // RIS over the two samples, balance heuristic: w = p̂ / (p_bsdf + p_light); neither
    // sample is a replay, so the target is the reconnection's.
    var bsdf_ris = vec2<f32>(0.0);
    var light_ris = vec2<f32>(0.0);
    for (var technique = 0u; technique < 2u; technique++) {
        var candidate = bsdf_candidate;
        var density = bsdf_light_density;
        if technique == 1u {
            candidate = light_candidate;
            density = light_density;
        }
        let ris = ris_weight(primary, candidate, density);
        if technique == 0u {
            bsdf_ris = ris;
        } else {
            light_ris = ris;
        }
    }
    let total = bsdf_ris.y + light_ris.y;
    var candidate = no_candidate();
    if total > 0.0 && total < INFINITY {
        if random() * total < light_ris.y {
            candidate = light_candidate;
            candidate.weight = total / light_ris.x;
        } else {
            candidate = bsdf_candidate;
            candidate.weight = total / bsdf_ris.x;
        }
    } else if total != 0.0 {
        // Infinite or NaN: a radiance that overflowed. Flagged, so that the frame is
        // refused rather than scored with the sample silently dropped.
        invalid = true;
    }
    return Drawn(candidate, invalid);
}

// How the candidates pass's walk along the camera path ended (restir_candidates).
const EXIT_OTHER: u32 = 0u;
// At a glossy conductor that resamples by random replay.
const EXIT_REPLAY: u32 = 1u;
// Where no resampling happens: the rest of the path is path-traced into the base.
const EXIT_PATH_TRACE: u32 = 2u;

// p̂ of the pixel's own candidate `x` at its own resampling vertex `p`: target_function's
// value, without the re-trace it holds for replays. A replay candidate drawn at `p`
// carries Ĉ(y, u) itself, which `replayed` would read back (same vertex, same numbers);
// any other candidate is a reconnection. So the kernel holds no path loop it never runs.
fn own_target(p: Primary, x: PathCandidate) -> f32 {
    if x.kind == KIND_NONE || (p.flags & PRIMARY_RESAMPLE) == 0u {
        return 0.0;
    }
    if x.kind == KIND_REPLAY {
        return luminance(x.reflected);
    }
    return luminance(reconnection_integrand(p, x));
}

@compute @workgroup_size(8, 8)
fn restir_candidates(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let pixel = id.y * params.width + id.x;
    rng_seed(pixel, params.sample_index, params.seed);
    let ray = camera_ray(film_position(id.xy, random2()));
    var primary = Primary(
        vec3<f32>(0.0), OBJECT_ID_NONE, vec3<f32>(0.0, 0.0, 1.0), 0u, -ray.direction, 0u, vec3<f32>(0.0), 0.0,
        vec3<f32>(1.0), 1u, vec3<f32>(0.0), 0u,
    );
    var candidate = no_candidate();
    var base = vec3<f32>(0.0);
    var invalid = false;
    let hit = traverse(ray, lane, false);
    if hit.primitive == STACK_OVERFLOW {
        invalid = true;
    } else if hit.primitive == MISS {
        if params.env_width > 0u {
            base = environment_radiance(ray.direction);
        }
    } else {
        let sample_lights = (params.flags & FLAG_SAMPLE_LIGHTS) != 0u;
        let hit_lights = (params.flags & FLAG_HIT_LIGHTS) != 0u;
        // The path's current vertex, the segment that reached it and what it carries.
        var surface = surface_at(hit);
        var wo_world = -ray.direction;
        var cos_out = dot(surface.normal, wo_world);
        var segment = 1u;
        var length = hit.t;
        var throughput = vec3<f32>(1.0);
        var chain = 0u;
        // How the loop below left the path: EXIT_REPLAY and EXIT_PATH_TRACE trace the rest
        // of it from `surface` after the loop, in one call for both.
        var exit = EXIT_OTHER;
        let camera_hit = surface.position;
        if surface.light != NO_LIGHT && cos_out > 0.0 {
            base = scene_light(surface.light).radiance;
        }
        loop {
            let material = scene_material(surface.material);
            var normal = surface.normal;
            if material.kind != MATERIAL_DIELECTRIC && cos_out < 0.0 && material.two_sided != 0u {
                normal = -normal;
            }
            let rough = material.kind == MATERIAL_DIFFUSE
                || (material.kind == MATERIAL_CONDUCTOR && material.alpha >= restir.min_roughness);
            let replay = restir.replay != 0u && material.kind == MATERIAL_CONDUCTOR && !rough;
            let front = material.kind == MATERIAL_DIELECTRIC || cos_out > 0.0 || material.two_sided != 0u;
            let albedo = albedo_at(material, surface.uv);
            primary = Primary(
                surface.position, surface.object_id, normal, surface.material, wo_world, PRIMARY_HIT, albedo, length,
                throughput, segment, camera_hit, 0u,
            );
            if replay && front && segment < params.max_depth {
                // A glossy conductor with random replay on: the candidate is the rest of
                // the path's random numbers, u uniform (W = 1), and the estimate Ĉ(y, u)
                // they give here (restir/reservoir.wgsl, "Random replay").
                primary.flags |= PRIMARY_RESAMPLE | PRIMARY_REPLAY;
                exit = EXIT_REPLAY;
                break;
            }
            if rough && front && segment < params.max_depth {
                primary.flags |= PRIMARY_RESAMPLE;
                let drawn = draw_candidate(primary, surface, lane);
                candidate = drawn.candidate;
                invalid = invalid || drawn.invalid;
                break;
            }
            if rough || replay || !front || chain >= restir.specular_chain || segment >= params.max_depth {
                // No resampling from here: the rest of the path, as the path tracer does it.
                exit = EXIT_PATH_TRACE;
                break;
            }
            // One smooth vertex of the chain, exactly as render/path.wgsl's
            // trace_path_from treats vertex number `segment`.
            let frame = make_frame(normal);
            let wo = to_local(frame, wo_world);
            if sample_lights && !is_specular(material) {
                base += throughput * direct_light(surface.position, surface.normal, frame, material, albedo, wo, lane);
            }
            let u = random2();
            let sample = bsdf_sample(material, albedo, wo, u, random());
            if all(sample.weight == vec3<f32>(0.0)) {
                break;
            }
            throughput *= sample.weight;
            let direction = normalize(to_world(frame, sample.wi));
            let next_ray = spawn_ray(surface.position, surface.normal, direction, INFINITY);
            if (params.flags & FLAG_RUSSIAN_ROULETTE) != 0u && segment >= params.rr_depth {
                let survive = min(max(throughput.x, max(throughput.y, throughput.z)), 0.95);
                if random() >= survive {
                    break;
                }
                throughput /= survive;
            }
            segment += 1u;
            chain += 1u;
            let next = traverse(next_ray, lane, false);
            if next.primitive == STACK_OVERFLOW {
                invalid = true;
                break;
            }
            let counts_emission = hit_lights || sample.specular || !sample_lights;
            if next.primitive == MISS {
                if params.env_width > 0u && counts_emission {
                    var weight = 1.0;
                    if sample_lights && !sample.specular {
                        weight = mis_power(sample.pdf, environment_light_pdf(direction));
                    }
                    base += throughput * environment_radiance(direction) * weight;
                }
                break;
            }
            surface = surface_at(next);
            wo_world = -direction;
            cos_out = dot(surface.normal, wo_world);
            length += next.t;
            if surface.light != NO_LIGHT && cos_out > 0.0 && counts_emission {
                var weight = 1.0;
                if sample_lights && !sample.specular {
                    weight = mis_power(sample.pdf, area_light_pdf(surface.light, next.t, cos_out));
                }
                base += throughput * scene_light(surface.light).radiance * weight;
            }
        }
        if exit != EXIT_OTHER {
            // The rest of the path from the vertex the loop stopped at. For a replay it is
            // the estimate Ĉ(y, u) of the random numbers u the pixel's stream gives from
            // here (its state is the candidate), and the stream is left where it was, as
            // replayed_sample leaves it (restir/reservoir.wgsl, "Random replay").
            let seed = rng_state;
            let rest = scatter_from(surface, wo_world, segment, lane);
            invalid = invalid || rest.invalid;
            if exit == EXIT_REPLAY {
                rng_state = seed;
                candidate = PathCandidate(primary.position, KIND_REPLAY, primary.wo, seed, rest.radiance, 1.0);
            } else {
                base += throughput * rest.radiance;
            }
        }
    }
    var key = 0.0;
    if candidate.kind != KIND_NONE && candidate.weight > 0.0 && finite3(candidate.reflected) {
        // The luminance of the pixel's own one-sample estimate f(Y) W at its vertex.
        key = own_target(primary, candidate) * candidate.weight;
    } else {
        // A drawn candidate whose radiance overflowed is an invalid sample, not an
        // absent one.
        invalid = invalid || (candidate.kind != KIND_NONE && !finite3(candidate.reflected));
        candidate = no_candidate();
    }
    if invalid || !finite3(base) || !finite3(primary.throughput) {
        base = vec3<f32>(0.0);
        invalid = true;
        candidate = no_candidate();
        primary.flags &= ~PRIMARY_RESAMPLE;
    }
    var object = OBJECT_ID_NONE;
    if (primary.flags & PRIMARY_RESAMPLE) != 0u {
        object = primary.object_id;
    }
    primary_out[pixel] = primary;
    candidates_out[pixel] = candidate;
    histogram_in[pixel] = Candidate(key, object);
    base_radiance[pixel] = vec4<f32>(base, select(0.0, 1.0, invalid));
}
