// The unidirectional path tracer of CONVENTIONS.md "Integrator": NEE and BSDF sampling
// combined by MIS, Russian roulette from rr_depth, at most max_depth segments including
// the camera ray (emission found at the last hit still counts; NEE at the vertex before
// it still runs). Mitsuba 3's `path` integrator computes the same expectation.

// One path's radiance estimate; invalid = the traversal stack overflowed.
struct PathSample {
    radiance: vec3<f32>,
    invalid: bool,
}

fn trace_path(camera: Ray, lane: u32) -> PathSample {
    // The camera ray counts as specular: nothing else could have found what it hits.
    return trace_path_from(camera, 1u, 0.0, true, lane);
}

// The radiance arriving along `start`, the path's segment number `first_depth`, made by
// a BSDF sample of density `start_pdf` (`start_specular` for a specular one), estimated
// by continuing the path to params.max_depth segments in all.
fn trace_path_from(start: Ray, first_depth: u32, start_pdf: f32, start_specular: bool, lane: u32) -> PathSample {
    let sample_lights = (params.flags & FLAG_SAMPLE_LIGHTS) != 0u;
    let hit_lights = (params.flags & FLAG_HIT_LIGHTS) != 0u;
    var ray = start;
    var throughput = vec3<f32>(1.0);
    var radiance = vec3<f32>(0.0);
    // Density of the BSDF sample that made `ray`, and whether it was specular.
    var previous_pdf = start_pdf;
    var previous_specular = start_specular;
    for (var depth = first_depth; depth <= params.max_depth; depth++) {
        let hit = traverse(ray, lane, false);
        if hit.primitive == STACK_OVERFLOW {
            return PathSample(vec3<f32>(0.0), true);
        }
        let counts_emission = hit_lights || previous_specular || !sample_lights;
        if hit.primitive == MISS {
            if params.env_width > 0u && counts_emission {
                var weight = 1.0;
                if sample_lights && !previous_specular {
                    weight = mis_power(previous_pdf, environment_light_pdf(ray.direction));
                }
                radiance += throughput * environment_radiance(ray.direction) * weight;
            }
            break;
        }
        let surface = surface_at(hit);
        let wo_world = -ray.direction;
        let cos_out = dot(surface.normal, wo_world);
        if surface.light != NO_LIGHT && cos_out > 0.0 && counts_emission {
            var weight = 1.0;
            if sample_lights && !previous_specular {
                weight = mis_power(previous_pdf, area_light_pdf(surface.light, hit.t, cos_out));
            }
            radiance += throughput * lights[surface.light].radiance * weight;
        }
        if depth == params.max_depth {
            break;
        }
        let material = materials[surface.material];
        var shading_normal = surface.normal;
        if material.kind != MATERIAL_DIELECTRIC && cos_out < 0.0 {
            if material.two_sided == 0u {
                break;
            }
            shading_normal = -shading_normal;
        }
        let frame = make_frame(shading_normal);
        let wo = to_local(frame, wo_world);
        let albedo = albedo_at(material, surface.uv);
        if sample_lights && !is_specular(material) {
            radiance += throughput * direct_light(surface.position, surface.normal, frame, material, albedo, wo, lane);
        }
        let u = random2();
        let sample = bsdf_sample(material, albedo, wo, u, random());
        if all(sample.weight == vec3<f32>(0.0)) {
            break;
        }
        throughput *= sample.weight;
        previous_pdf = sample.pdf;
        previous_specular = sample.specular;
        let direction = normalize(to_world(frame, sample.wi));
        ray = spawn_ray(surface.position, surface.normal, direction, INFINITY);
        if (params.flags & FLAG_RUSSIAN_ROULETTE) != 0u && depth >= params.rr_depth {
            let survive = min(max(throughput.x, max(throughput.y, throughput.z)), 0.95);
            if random() >= survive {
                break;
            }
            throughput /= survive;
        }
    }
    return PathSample(radiance, false);
}

// The radiance leaving `surface` (hit by path segment number `depth`) towards
// `wo_world` by reflection or refraction, emission excluded: next-event estimation there
// and one BSDF-sampled continuation, exactly as trace_path_from does at that vertex.
fn scatter_from(surface: Surface, wo_world: vec3<f32>, depth: u32, lane: u32) -> PathSample {
    let material = materials[surface.material];
    let cos_out = dot(surface.normal, wo_world);
    var shading_normal = surface.normal;
    if material.kind != MATERIAL_DIELECTRIC && cos_out < 0.0 {
        if material.two_sided == 0u {
            return PathSample(vec3<f32>(0.0), false);
        }
        shading_normal = -shading_normal;
    }
    return scatter_at(surface.position, shading_normal, material, albedo_at(material, surface.uv), wo_world, depth, lane);
}

// scatter_from at a point whose side is already settled: `normal` is the geometric normal
// on the side the BSDF is evaluated from (flipped towards `wo_world` at the back of a
// two-sided surface; ray offsets and shadow rays depend only on the line it spans).
fn scatter_at(
    position: vec3<f32>,
    normal: vec3<f32>,
    material: Material,
    albedo: vec3<f32>,
    wo_world: vec3<f32>,
    depth: u32,
    lane: u32,
) -> PathSample {
    if depth >= params.max_depth {
        return PathSample(vec3<f32>(0.0), false);
    }
    let frame = make_frame(normal);
    let wo = to_local(frame, wo_world);
    var radiance = vec3<f32>(0.0);
    if (params.flags & FLAG_SAMPLE_LIGHTS) != 0u && !is_specular(material) {
        radiance = direct_light(position, normal, frame, material, albedo, wo, lane);
    }
    let u = random2();
    let sample = bsdf_sample(material, albedo, wo, u, random());
    if all(sample.weight == vec3<f32>(0.0)) {
        return PathSample(radiance, false);
    }
    let direction = normalize(to_world(frame, sample.wi));
    let ray = spawn_ray(position, normal, direction, INFINITY);
    let rest = trace_path_from(ray, depth + 1u, sample.pdf, sample.specular, lane);
    return PathSample(radiance + sample.weight * rest.radiance, rest.invalid);
}
