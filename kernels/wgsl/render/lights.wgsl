// Next-event estimation (CONVENTIONS.md "Integrator"): one light sample per scattering
// vertex, either the environment (probability params.environment_probability, its own
// importance sampling) or an emissive triangle chosen in proportion to its power with a
// point uniform on it; combined with BSDF sampling by the power heuristic.

// #import trace/bvh.wgsl
// #import render/scene.wgsl
// #import render/random.wgsl
// #import render/bsdf.wgsl
// #import render/environment.wgsl

// Power heuristic for a sample drawn with density `a` against the other strategy's `b`.
fn mis_power(a: f32, b: f32) -> f32 {
    let a2 = a * a;
    let b2 = b * b;
    if a2 + b2 <= 0.0 || a2 + b2 > 3.0e38 {
        return select(0.0, 1.0, a >= b);
    }
    return a2 / (a2 + b2);
}

// The emissive triangle that u in [0, 1) selects through the lights' inclusive CDF.
fn find_light(u: f32) -> u32 {
    var low = 0u;
    var high = params.light_count - 1u;
    while low < high {
        let middle = (low + high) / 2u;
        if scene_light(middle).cdf > u {
            high = middle;
        } else {
            low = middle + 1u;
        }
    }
    return low;
}

// Solid-angle density with which NEE picks a point on emissive triangle `light` seen at
// `distance` under cosine `cos_light` at the light.
fn area_light_pdf(light: u32, distance: f32, cos_light: f32) -> f32 {
    let entry = scene_light(light);
    return (1.0 - params.environment_probability) * entry.probability / entry.area * distance * distance / cos_light;
}

// Solid-angle density with which NEE picks environment direction `direction`.
fn environment_light_pdf(direction: vec3<f32>) -> f32 {
    if params.environment_probability <= 0.0 {
        return 0.0;
    }
    return params.environment_probability * environment_pdf(direction);
}

// One light sample's contribution (f * cos * Le * MIS weight / density) at a surface
// point whose BSDF is `material` in `frame`.
fn direct_light(
    position: vec3<f32>,
    normal: vec3<f32>,
    frame: Frame,
    material: Material,
    albedo: vec3<f32>,
    wo: vec3<f32>,
    lane: u32,
) -> vec3<f32> {
    let u_choice = random();
    let u = random2();
    let weigh_against_bsdf = (params.flags & FLAG_HIT_LIGHTS) != 0u;
    // The branches only choose the light sample; the BSDF and the shadow ray are
    // evaluated once after them, so that a kernel holds one copy of each (a driver
    // inlines every call site).
    var direction: vec3<f32>;
    var pdf: f32;
    var emitted: vec3<f32>;
    var shadow: Ray;
    if u_choice < params.environment_probability {
        direction = sample_environment(u);
        pdf = environment_light_pdf(direction);
        if pdf <= 0.0 {
            return vec3<f32>(0.0);
        }
        emitted = environment_radiance(direction);
        shadow = shadow_ray_along(position, normal, direction);
    } else {
        if params.light_count == 0u {
            return vec3<f32>(0.0);
        }
        let light = find_light(random());
        let entry = scene_light(light);
        let tri = bvh_triangle(entry.triangle);
        let su = sqrt(u.x);
        let point = (1.0 - su) * tri.v0 + (u.y * su) * tri.v1 + (su - u.y * su) * tri.v2;
        let light_normal = normalize(cross(tri.v1 - tri.v0, tri.v2 - tri.v0));
        let to_light = point - position;
        let distance = length(to_light);
        direction = to_light / distance;
        let cos_light = -dot(light_normal, direction);
        if cos_light <= 0.0 || distance <= 0.0 {
            return vec3<f32>(0.0);
        }
        pdf = area_light_pdf(light, distance, cos_light);
        emitted = entry.radiance;
        shadow = shadow_ray_to(position, normal, point);
    }
    let wi = to_local(frame, direction);
    let f = bsdf_eval(material, albedo, wo, wi);
    if all(f == vec3<f32>(0.0)) || !ray_unblocked(shadow, lane) {
        return vec3<f32>(0.0);
    }
    var weight = 1.0;
    if weigh_against_bsdf {
        weight = mis_power(pdf, bsdf_pdf(material, wo, wi));
    }
    return f * emitted * (weight / pdf);
}
