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
    let sample_lights = (params.flags & FLAG_SAMPLE_LIGHTS) != 0u;
    let hit_lights = (params.flags & FLAG_HIT_LIGHTS) != 0u;
    var ray = camera;
    var throughput = vec3<f32>(1.0);
    var radiance = vec3<f32>(0.0);
    // Density of the BSDF sample that made `ray`, and whether it was specular (the camera
    // ray counts as specular: nothing else could have found what it hits).
    var previous_pdf = 0.0;
    var previous_specular = true;
    for (var depth = 1u; depth <= params.max_depth; depth++) {
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
