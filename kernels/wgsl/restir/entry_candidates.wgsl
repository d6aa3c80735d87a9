// ReSTIR pass 1 (paper §5.1 "candidate generation"): every pixel traces one path. Its
// primary hit y1 goes to the G-buffer, with the object id that the histogram clusters
// by (§4.3); what the pixel estimates on its own (emission at y1 and next-event
// estimation there) goes to `base_radiance`; the BSDF-sampled continuation from y1 is
// its candidate, keyed for the histogram by the luminance of its own one-sample
// estimate f/p (§4.1). A pixel whose y1 is not rough enough to reconnect from (smooth
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
// jitter, then next-event estimation, BSDF sampling and the rest of the path.
// Dispatch: 8 x 8 pixels per workgroup.

@group(0) @binding(9) var<storage, read_write> primary_out: array<Primary>;
@group(0) @binding(10) var<storage, read_write> candidates_out: array<PathCandidate>;
@group(0) @binding(11) var<storage, read_write> histogram_in: array<Candidate>;
@group(0) @binding(12) var<storage, read_write> base_radiance: array<vec4<f32>>;

fn no_candidate() -> PathCandidate {
    return PathCandidate(vec3<f32>(0.0), KIND_NONE, vec3<f32>(0.0), NO_LIGHT, vec3<f32>(0.0), 0.0);
}

@compute @workgroup_size(8, 8)
fn restir_candidates(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let pixel = id.y * params.width + id.x;
    rng_seed(pixel, params.sample_index, params.seed);
    let ray = camera_ray(vec2<f32>(f32(id.x), f32(id.y)) + random2());
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
            base += direct_light(surface.position, surface.normal, frame, material, albedo, wo, lane);
            let sample = bsdf_sample(material, albedo, wo, random2(), random());
            if any(sample.weight != vec3<f32>(0.0)) && sample.pdf > 0.0 {
                let direction = normalize(to_world(frame, sample.wi));
                let next = traverse(spawn_ray(surface.position, surface.normal, direction, INFINITY), lane, false);
                if next.primitive == STACK_OVERFLOW {
                    invalid = true;
                } else if next.primitive == MISS {
                    if params.env_width > 0u {
                        candidate = PathCandidate(direction, KIND_ENVIRONMENT, vec3<f32>(0.0), NO_LIGHT, vec3<f32>(0.0), sample.pdf);
                    }
                } else {
                    let vertex = surface_at(next);
                    let wo_vertex = -direction;
                    let seen_front = dot(vertex.normal, wo_vertex) > 0.0;
                    let kind = select(KIND_PRIVATE, KIND_SURFACE, materials[vertex.material].kind == MATERIAL_DIFFUSE);
                    let rest = scatter_from(vertex, wo_vertex, 2u, lane);
                    invalid = rest.invalid;
                    candidate = PathCandidate(
                        vertex.position,
                        kind,
                        select(-vertex.normal, vertex.normal, seen_front),
                        select(NO_LIGHT, vertex.light, seen_front),
                        rest.radiance,
                        sample.pdf,
                    );
                }
            }
        }
    }
    var key = 0.0;
    if candidate.kind != KIND_NONE {
        let density = source_density(primary, candidate);
        key = luminance(integrand(primary, candidate)) / density;
        if !(density > 0.0) || !finite3(candidate.reflected) {
            candidate = no_candidate();
            key = 0.0;
        }
    }
    if invalid || !finite3(base) {
        base = vec3<f32>(0.0);
        invalid = true;
        candidate = no_candidate();
        primary.flags &= ~PRIMARY_RESAMPLE;
    }
    var object = OBJECT_ID_NONE;
    if (primary.flags & PRIMARY_RESAMPLE) != 0u {
        object = select(0u, primary.object_id, restir.masking != 0u);
    }
    primary_out[pixel] = primary;
    candidates_out[pixel] = candidate;
    histogram_in[pixel] = Candidate(key, object);
    base_radiance[pixel] = vec4<f32>(base, select(0.0, 1.0, invalid));
}
