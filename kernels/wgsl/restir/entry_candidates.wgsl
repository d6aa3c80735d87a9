// ReSTIR pass 1 (paper §5.1 "candidate generation"): every pixel traces one path. Its
// primary hit y1 goes to the G-buffer, with the object id that the histogram clusters
// by (§4.3). The pixel draws two samples of the next vertex x2, one by BSDF sampling
// (the path's continuation, with the radiance the rest of the path brings back) and one
// by next-event estimation (a light point or environment direction), and keeps one by
// RIS with balance-heuristic weights p̂ / (p_bsdf + p_light): its candidate, with its
// unbiased contribution weight W, keyed for the histogram by the luminance of its own
// estimate f(Y) W (§4.1). `base_radiance` holds what is not resampled: the emission y1
// shows the camera. A pixel whose y1 is not rough enough to reconnect from (smooth
// dielectric, a conductor below RestirParams.min_roughness) or whose camera ray escaped
// does not resample: its whole path estimate goes to `base_radiance` and its histogram
// candidate is OBJECT_ID_NONE.
//
// Bindings (group 0): 0-7 the scene, 8 RestirParams (restir/reservoir.wgsl), and
//   9  storage, rw       array<Primary>        G-buffer, one per pixel
//   10 storage, rw       array<PathCandidate>  one per pixel
//   11 storage, rw       array<Candidate>      the histogram pass's input (key, object id)
//   12 storage, rw       array<vec4<f32>>      base radiance: rgb; a = 1 for an invalid sample
//
// Random numbers: PCG stream of (pixel, params.sample_index = frame, params.seed): film
// jitter, BSDF sampling and the rest of that path, the light sample, the RIS choice.
// Dispatch: 8 x 8 pixels per workgroup.

@group(0) @binding(9) var<storage, read_write> primary_out: array<Primary>;
@group(0) @binding(10) var<storage, read_write> candidates_out: array<PathCandidate>;
@group(0) @binding(11) var<storage, read_write> histogram_in: array<Candidate>;
@group(0) @binding(12) var<storage, read_write> base_radiance: array<vec4<f32>>;

fn no_candidate() -> PathCandidate {
    return PathCandidate(vec3<f32>(0.0), KIND_NONE, vec3<f32>(0.0), NO_LIGHT, vec3<f32>(0.0), 0.0);
}

// Area density with which next-event estimation picks a point on emissive triangle `light`.
fn light_area_density(light: u32) -> f32 {
    let entry = lights[light];
    return (1.0 - params.environment_probability) * entry.probability / entry.area;
}

// (p̂, RIS weight p̂ / (p_bsdf + p_light)) of `candidate` at `primary`, given the
// density with which next-event estimation draws it; zero for no candidate.
fn ris_weight(primary: Primary, candidate: PathCandidate, light_density: f32) -> vec2<f32> {
    if candidate.kind == KIND_NONE {
        return vec2<f32>(0.0);
    }
    let target_value = target_function(primary, candidate);
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
    let kind = select(KIND_PRIVATE, KIND_SURFACE, materials[vertex.material].kind == MATERIAL_DIFFUSE);
    return PathCandidate(
        vertex.position,
        kind,
        select(-vertex.normal, vertex.normal, seen_front),
        select(NO_LIGHT, vertex.light, seen_front),
        reflected,
        0.0,
    );
}


@compute @workgroup_size(8, 8)
fn restir_candidates(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let pixel = id.y * params.width + id.x;
    rng_seed(pixel, params.sample_index, params.seed);
    let ray = camera_ray(film_position(id.xy, random2()));
    var primary = Primary(vec3<f32>(0.0), OBJECT_ID_NONE, vec3<f32>(0.0, 0.0, 1.0), 0u, -ray.direction, 0u, vec3<f32>(0.0), 0.0);
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
        let surface = surface_at(hit);
        let material = materials[surface.material];
        let wo_world = -ray.direction;
        let cos_out = dot(surface.normal, wo_world);
        if surface.light != NO_LIGHT && cos_out > 0.0 {
            base = lights[surface.light].radiance;
        }
        var normal = surface.normal;
        if material.kind != MATERIAL_DIELECTRIC && cos_out < 0.0 && material.two_sided != 0u {
            normal = -normal;
        }
        let rough = material.kind == MATERIAL_DIFFUSE
            || (material.kind == MATERIAL_CONDUCTOR && material.alpha >= restir.min_roughness);
        let front = material.kind == MATERIAL_DIELECTRIC || cos_out > 0.0 || material.two_sided != 0u;
        let albedo = albedo_at(material, surface.uv);
        primary = Primary(surface.position, surface.object_id, normal, surface.material, wo_world, PRIMARY_HIT, albedo, hit.t);
        if !rough || !front {
            let rest = scatter_from(surface, wo_world, 1u, lane);
            base += rest.radiance;
            invalid = rest.invalid;
        } else {
            primary.flags |= PRIMARY_RESAMPLE;
            let frame = make_frame(normal);
            let wo = to_local(frame, wo_world);
            // Technique 1, BSDF sampling: the next vertex of the path.
            var bsdf_candidate = no_candidate();
            var bsdf_light_density = 0.0;
            let sample = bsdf_sample(material, albedo, wo, random2(), random());
            if any(sample.weight != vec3<f32>(0.0)) && sample.pdf > 0.0 {
                let direction = normalize(to_world(frame, sample.wi));
                let next = traverse(spawn_ray(surface.position, surface.normal, direction, INFINITY), lane, false);
                if next.primitive == STACK_OVERFLOW {
                    invalid = true;
                } else if next.primitive == MISS {
                    if params.env_width > 0u {
                        bsdf_candidate = PathCandidate(direction, KIND_ENVIRONMENT, vec3<f32>(0.0), NO_LIGHT, vec3<f32>(0.0), 0.0);
                        bsdf_light_density = environment_light_pdf(direction);
                    }
                } else {
                    let vertex = surface_at(next);
                    let rest = scatter_from(vertex, -direction, 2u, lane);
                    invalid = invalid || rest.invalid;
                    bsdf_candidate = vertex_candidate(vertex, surface.position, rest.radiance);
                    if vertex.light != NO_LIGHT {
                        bsdf_light_density = light_area_density(vertex.light);
                    }
                }
            }
            // Technique 2, next-event estimation: a point on a light or an environment
            // direction, drawn as render/lights.wgsl draws them.
            var light_candidate = no_candidate();
            var light_density = 0.0;
            let u_choice = random();
            let u_light = random2();
            if u_choice < params.environment_probability {
                let direction = sample_environment(u_light);
                light_density = environment_light_pdf(direction);
                if light_density > 0.0 && unoccluded(surface.position, normal, direction, lane) {
                    light_candidate = PathCandidate(direction, KIND_ENVIRONMENT, vec3<f32>(0.0), NO_LIGHT, vec3<f32>(0.0), 0.0);
                }
            } else if params.light_count > 0u {
                let light = find_light(random());
                let entry = lights[light];
                let tri = triangles[entry.triangle];
                let su = sqrt(u_light.x);
                let b1 = u_light.y * su;
                let b2 = su - u_light.y * su;
                let point = (1.0 - su) * tri.v0 + b1 * tri.v1 + b2 * tri.v2;
                let info = triangle_info[entry.triangle];
                var uv = vec2<f32>(b1, b2);
                if info.has_uv != 0u {
                    uv = (1.0 - su) * info.uv0 + b1 * info.uv1 + b2 * info.uv2;
                }
                let light_normal = normalize(cross(tri.v1 - tri.v0, tri.v2 - tri.v0));
                let light_surface = Surface(point, light_normal, uv, info.object_id, info.material, light);
                light_density = light_area_density(light);
                if visible(surface.position, normal, point, lane) {
                    // What the light reflects towards y1 (nothing for a black fixture).
                    var reflected = vec3<f32>(0.0);
                    let light_material = materials[info.material];
                    if light_material.kind != MATERIAL_DIFFUSE || any(albedo_at(light_material, uv) != vec3<f32>(0.0)) {
                        let rest = scatter_from(light_surface, normalize(surface.position - point), 2u, lane);
                        invalid = invalid || rest.invalid;
                        reflected = rest.radiance;
                    }
                    light_candidate = vertex_candidate(light_surface, surface.position, reflected);
                }
            }
            // RIS over the two samples, balance heuristic: w = p̂ / (p_bsdf + p_light).
            let bsdf_ris = ris_weight(primary, bsdf_candidate, bsdf_light_density);
            let light_ris = ris_weight(primary, light_candidate, light_density);
            let total = bsdf_ris.y + light_ris.y;
            if total > 0.0 && total < INFINITY {
                if random() * total < light_ris.y {
                    candidate = light_candidate;
                    candidate.weight = total / light_ris.x;
                } else {
                    candidate = bsdf_candidate;
                    candidate.weight = total / bsdf_ris.x;
                }
            }
        }
    }
    var key = 0.0;
    if candidate.kind != KIND_NONE && candidate.weight > 0.0 && finite3(candidate.reflected) {
        // The luminance of the pixel's own one-sample estimate f(Y) W.
        key = target_function(primary, candidate) * candidate.weight;
    } else {
        candidate = no_candidate();
    }
    if invalid || !finite3(base) {
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
