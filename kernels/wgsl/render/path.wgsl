// The unidirectional path tracer of CONVENTIONS.md "Integrator": NEE and BSDF sampling
// combined by MIS, Russian roulette from rr_depth, at most max_depth segments including
// the camera ray (emission found at the last hit still counts; NEE at the vertex before
// it still runs). Mitsuba 3's `path` integrator computes the same expectation.

// #import trace/bvh.wgsl
// #import trace/traverse.wgsl
// #import render/scene.wgsl
// #import render/random.wgsl
// #import render/environment.wgsl
// #import render/albedo.wgsl
// #import render/bsdf.wgsl
// #import render/lights.wgsl

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
    return path_from(start, first_depth, start_pdf, start_specular, false, PathVertex(), lane);
}

// The radiance leaving `surface` (hit by path segment number `depth`) towards
// `wo_world` by reflection or refraction, emission excluded: next-event estimation there
// and one BSDF-sampled continuation, exactly as trace_path_from does at that vertex.
fn scatter_from(surface: Surface, wo_world: vec3<f32>, depth: u32, lane: u32) -> PathSample {
    let material = scene_material(surface.material);
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
    let vertex = PathVertex(position, normal, material, albedo, wo_world);
    return path_from(Ray(), depth, 0.0, false, true, vertex, lane);
}

// A scattering vertex found before path_from starts (scatter_at's arguments).
struct PathVertex {
    position: vec3<f32>,
    normal: vec3<f32>,
    material: Material,
    albedo: vec3<f32>,
    wo_world: vec3<f32>,
}

// The one path loop behind trace_path_from and scatter_at. A driver inlines every call
// site, and the loop (with its traversal, next-event estimation and BSDF sampling) is
// most of every kernel that traces paths: a kernel that reaches both entry points through
// one call holds one copy of it (BENCHMARKS "First run on a fresh machine").
//
// With `at_vertex` the path starts at `vertex` (segment number `first_depth`): its
// emission is left out, and its own part (next-event estimation there) is kept apart
// from what the rest of the path brings back, which is weighted by the vertex's BSDF
// sample at the end, so that the sum is the one scatter_at always computed; no Russian
// roulette there.
// Otherwise the path starts by tracing `start`, as trace_path_from describes.
fn path_from(
    start: Ray,
    first_depth: u32,
    start_pdf: f32,
    start_specular: bool,
    at_vertex: bool,
    vertex: PathVertex,
    lane: u32,
) -> PathSample {
    let sample_lights = (params.flags & FLAG_SAMPLE_LIGHTS) != 0u;
    let hit_lights = (params.flags & FLAG_HIT_LIGHTS) != 0u;
    if at_vertex && first_depth >= params.max_depth {
        return PathSample(vec3<f32>(0.0), false);
    }
    var ray = start;
    var throughput = vec3<f32>(1.0);
    var radiance = vec3<f32>(0.0);
    // Density of the BSDF sample that made `ray`, and whether it was specular.
    var previous_pdf = start_pdf;
    var previous_specular = start_specular;
    // The starting vertex's own part and BSDF weight, while it is to be (or was) scattered
    // at; the loop then estimates the rest of the path from throughput 1.
    var at_start_vertex = at_vertex;
    var vertex_radiance = vec3<f32>(0.0);
    var vertex_weight = vec3<f32>(0.0);
    for (var depth = first_depth; depth <= params.max_depth; depth++) {
        var position: vec3<f32>;
        // The geometric normal that ray offsets and shadow rays use, and the one the BSDF
        // frame is built on.
        var offset_normal: vec3<f32>;
        var shading_normal: vec3<f32>;
        var material: Material;
        var albedo: vec3<f32>;
        var wo_world: vec3<f32>;
        if at_start_vertex {
            position = vertex.position;
            offset_normal = vertex.normal;
            shading_normal = vertex.normal;
            material = vertex.material;
            albedo = vertex.albedo;
            wo_world = vertex.wo_world;
        } else {
            let hit = traverse(ray, lane, false);
            if hit.primitive == STACK_OVERFLOW {
                return finish_path(at_vertex, vertex_radiance, vertex_weight, PathSample(vec3<f32>(0.0), true));
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
            wo_world = -ray.direction;
            let cos_out = dot(surface.normal, wo_world);
            if surface.light != NO_LIGHT && cos_out > 0.0 && counts_emission {
                var weight = 1.0;
                if sample_lights && !previous_specular {
                    weight = mis_power(previous_pdf, area_light_pdf(surface.light, hit.t, cos_out));
                }
                radiance += throughput * scene_light(surface.light).radiance * weight;
            }
            if depth == params.max_depth {
                break;
            }
            material = scene_material(surface.material);
            shading_normal = surface.normal;
            if material.kind != MATERIAL_DIELECTRIC && cos_out < 0.0 {
                if material.two_sided == 0u {
                    break;
                }
                shading_normal = -shading_normal;
            }
            position = surface.position;
            offset_normal = surface.normal;
            albedo = albedo_at(material, surface.uv);
        }
        let frame = make_frame(shading_normal);
        let wo = to_local(frame, wo_world);
        if sample_lights && !is_specular(material) {
            let direct = direct_light(position, offset_normal, frame, material, albedo, wo, lane);
            if at_start_vertex {
                vertex_radiance = direct;
            } else {
                radiance += throughput * direct;
            }
        }
        let u = random2();
        let sample = bsdf_sample(material, albedo, wo, u, random());
        if all(sample.weight == vec3<f32>(0.0)) {
            if at_start_vertex {
                return PathSample(vertex_radiance, false);
            }
            break;
        }
        previous_pdf = sample.pdf;
        previous_specular = sample.specular;
        let direction = normalize(to_world(frame, sample.wi));
        ray = spawn_ray(position, offset_normal, direction, INFINITY);
        if at_start_vertex {
            vertex_weight = sample.weight;
            at_start_vertex = false;
            continue;
        }
        throughput *= sample.weight;
        if (params.flags & FLAG_RUSSIAN_ROULETTE) != 0u && depth >= params.rr_depth {
            let survive = min(max(throughput.x, max(throughput.y, throughput.z)), 0.95);
            if random() >= survive {
                break;
            }
            throughput /= survive;
        }
    }
    return finish_path(at_vertex, vertex_radiance, vertex_weight, PathSample(radiance, false));
}

// What path_from returns once the path ends with `rest`: that alone when it started with
// a ray, else the starting vertex's own part plus its BSDF weight times the rest.
fn finish_path(at_vertex: bool, vertex_radiance: vec3<f32>, vertex_weight: vec3<f32>, rest: PathSample) -> PathSample {
    if at_vertex {
        return PathSample(vertex_radiance + vertex_weight * rest.radiance, rest.invalid);
    }
    return rest;
}
