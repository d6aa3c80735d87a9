// The three BSDFs of CONVENTIONS.md "Materials", in a local frame whose z axis is the
// shading normal: Lambertian diffuse, the GGX rough conductor with exact conductor
// Fresnel (visible-normal sampling, Heitz 2018), and the smooth dielectric with exact
// dielectric Fresnel. `wo` points to the previous vertex, `wi` to the next; eval returns
// f * |cos(wi)|, and sample returns that over the density (the path throughput factor).

// #import render/scene.wgsl
// #import render/turns.wgsl

struct Frame {
    tangent: vec3<f32>,
    bitangent: vec3<f32>,
    normal: vec3<f32>,
}

// Orthonormal basis around a unit normal (Duff et al. 2017).
fn make_frame(n: vec3<f32>) -> Frame {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    return Frame(vec3<f32>(1.0 + s * n.x * n.x * a, s * b, -s * n.x), vec3<f32>(b, s + n.y * n.y * a, -n.y), n);
}

fn to_local(frame: Frame, v: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(v, frame.tangent), dot(v, frame.bitangent), dot(v, frame.normal));
}

fn to_world(frame: Frame, v: vec3<f32>) -> vec3<f32> {
    return v.x * frame.tangent + v.y * frame.bitangent + v.z * frame.normal;
}

// GGX / Trowbridge-Reitz normal distribution (isotropic, no roughness remapping).
fn ggx_d(m: vec3<f32>, alpha: f32) -> f32 {
    if m.z <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let t = (m.x * m.x + m.y * m.y) / a2 + m.z * m.z;
    return 1.0 / (PI * a2 * t * t);
}

// Smith's masking for GGX.
fn ggx_g1(v: vec3<f32>, m: vec3<f32>, alpha: f32) -> f32 {
    if dot(v, m) * v.z <= 0.0 {
        return 0.0;
    }
    let tan2 = (alpha * alpha) * (v.x * v.x + v.y * v.y) / (v.z * v.z);
    return 2.0 / (1.0 + sqrt(1.0 + tan2));
}

// A microfacet normal drawn from the visible normals seen from `wo` (Heitz 2018).
fn sample_ggx_visible(wo: vec3<f32>, alpha: f32, u: vec2<f32>) -> vec3<f32> {
    let vh = normalize(vec3<f32>(alpha * wo.x, alpha * wo.y, wo.z));
    let length2 = vh.x * vh.x + vh.y * vh.y;
    var t1 = vec3<f32>(1.0, 0.0, 0.0);
    if length2 > 0.0 {
        t1 = vec3<f32>(-vh.y, vh.x, 0.0) / sqrt(length2);
    }
    let t2 = cross(vh, t1);
    let r = sqrt(u.x);
    let phi = sin_cos_turns(u.y);
    let p1 = r * phi.y;
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * sqrt(max(0.0, 1.0 - p1 * p1)) + s * r * phi.x;
    let nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
    return normalize(vec3<f32>(alpha * nh.x, alpha * nh.y, max(1e-6, nh.z)));
}

// Exact unpolarised Fresnel reflectance of a conductor with IOR eta + i k (per channel).
fn fresnel_conductor(cos_i: f32, eta: vec3<f32>, k: vec3<f32>) -> vec3<f32> {
    let c2 = cos_i * cos_i;
    let s2 = 1.0 - c2;
    let s4 = s2 * s2;
    let t1 = eta * eta - k * k - vec3<f32>(s2);
    let a2pb2 = sqrt(max(vec3<f32>(0.0), t1 * t1 + 4.0 * k * k * eta * eta));
    let a = sqrt(max(vec3<f32>(0.0), 0.5 * (a2pb2 + t1)));
    let term1 = a2pb2 + vec3<f32>(c2);
    let term2 = 2.0 * cos_i * a;
    let rs = (term1 - term2) / (term1 + term2);
    let term3 = a2pb2 * c2 + vec3<f32>(s4);
    let term4 = term2 * s2;
    let rp = rs * (term3 - term4) / (term3 + term4);
    return 0.5 * (rs + rp);
}

// Exact dielectric Fresnel for relative IOR `eta` (inside over outside): x = reflectance,
// y = cos of the refracted direction (signed, opposite to cos_i), z = eta_ti (the ratio
// that scales the tangential components on refraction).
fn fresnel_dielectric(cos_i: f32, eta: f32) -> vec3<f32> {
    let outside = cos_i >= 0.0;
    let eta_it = select(1.0 / eta, eta, outside);
    let eta_ti = select(eta, 1.0 / eta, outside);
    let cos_t2 = 1.0 - eta_ti * eta_ti * (1.0 - cos_i * cos_i);
    let cos_i_abs = abs(cos_i);
    let cos_t_abs = sqrt(max(0.0, cos_t2));
    let a_s = (cos_i_abs - eta_it * cos_t_abs) / (cos_i_abs + eta_it * cos_t_abs);
    let a_p = (cos_t_abs - eta_it * cos_i_abs) / (cos_t_abs + eta_it * cos_i_abs);
    var r = 0.5 * (a_s * a_s + a_p * a_p);
    if eta == 1.0 {
        r = 0.0;
    } else if cos_i_abs == 0.0 || cos_t2 <= 0.0 {
        r = 1.0;
    }
    let cos_t = select(cos_t_abs, -cos_t_abs, cos_i >= 0.0);
    return vec3<f32>(r, cos_t, eta_ti);
}

fn is_specular(material: Material) -> bool {
    return material.kind == MATERIAL_DIELECTRIC;
}

// f * cos(wi); zero for the specular dielectric.
fn bsdf_eval(material: Material, albedo: vec3<f32>, wo: vec3<f32>, wi: vec3<f32>) -> vec3<f32> {
    if wo.z <= 0.0 || wi.z <= 0.0 || material.kind == MATERIAL_DIELECTRIC {
        return vec3<f32>(0.0);
    }
    if material.kind == MATERIAL_CONDUCTOR {
        let m = normalize(wo + wi);
        let d = ggx_d(m, material.alpha);
        let g = ggx_g1(wo, m, material.alpha) * ggx_g1(wi, m, material.alpha);
        let f = fresnel_conductor(dot(wi, m), material.color0, material.color1);
        return f * (d * g / (4.0 * wo.z));
    }
    return albedo * (wi.z / PI);
}

// Solid-angle density with which bsdf_sample draws wi; zero for the dielectric.
fn bsdf_pdf(material: Material, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    if wo.z <= 0.0 || wi.z <= 0.0 || material.kind == MATERIAL_DIELECTRIC {
        return 0.0;
    }
    if material.kind == MATERIAL_CONDUCTOR {
        let m = normalize(wo + wi);
        let visible = ggx_g1(wo, m, material.alpha) * max(dot(wo, m), 0.0) * ggx_d(m, material.alpha) / wo.z;
        return visible / (4.0 * dot(wi, m));
    }
    return wi.z / PI;
}

struct BsdfSample {
    wi: vec3<f32>,
    // f * |cos(wi)| / pdf; zero when the sample failed.
    weight: vec3<f32>,
    // Solid-angle density (the discrete probability for the dielectric's two lobes).
    pdf: f32,
    specular: bool,
}

fn bsdf_sample(material: Material, albedo: vec3<f32>, wo: vec3<f32>, u: vec2<f32>, u_lobe: f32) -> BsdfSample {
    if material.kind == MATERIAL_DIELECTRIC {
        let fresnel = fresnel_dielectric(wo.z, material.eta);
        if u_lobe <= fresnel.x {
            return BsdfSample(vec3<f32>(-wo.x, -wo.y, wo.z), vec3<f32>(1.0), fresnel.x, true);
        }
        // Radiance is scaled by eta_ti^2 on refraction (Mitsuba's radiance mode).
        let wi = vec3<f32>(-fresnel.z * wo.x, -fresnel.z * wo.y, fresnel.y);
        return BsdfSample(wi, vec3<f32>(fresnel.z * fresnel.z), 1.0 - fresnel.x, true);
    }
    let none = BsdfSample(vec3<f32>(0.0, 0.0, 1.0), vec3<f32>(0.0), 0.0, false);
    if wo.z <= 0.0 {
        return none;
    }
    if material.kind == MATERIAL_CONDUCTOR {
        let m = sample_ggx_visible(wo, material.alpha, u);
        let wi = 2.0 * dot(wo, m) * m - wo;
        if wi.z <= 0.0 {
            return none;
        }
        let f = fresnel_conductor(dot(wo, m), material.color0, material.color1);
        return BsdfSample(wi, f * ggx_g1(wi, m, material.alpha), bsdf_pdf(material, wo, wi), false);
    }
    let r = sqrt(u.x);
    let phi = sin_cos_turns(u.y);
    let wi = vec3<f32>(r * phi.y, r * phi.x, sqrt(max(0.0, 1.0 - u.x)));
    if wi.z <= 0.0 {
        return none;
    }
    return BsdfSample(wi, albedo, wi.z / PI, false);
}
