// BVH2 closest-hit traversal with watertight ray-triangle intersection (the path
// tracer's visibility query). The BVH is obvhs' Bvh2, uploaded as-is: its nodes and
// triangles use glam's 16-byte Vec3A, hence the pad after every vec3 of BvhNode and
// Triangle (declared with Ray, Hit and the traversal's constants in
// kernels/src/trace_types.rs, which generates gpu/trace.wgsl).
//
// Determinism across backends: no division by a zero direction component (a tiny
// signed substitute keeps every slab product finite, so min/max never see NaN), and
// every float operation is written out in a fixed order. Backends may still contract
// a * b + c into fused multiply-adds, so hits are compared with a ULP bound.

// #import gpu/trace.wgsl

// Per-ray constants of the watertight test (Woop, Benthin and Wald 2013).
struct Shear {
    kx: u32,
    ky: u32,
    kz: u32,
    sx: f32,
    sy: f32,
    sz: f32,
}

fn max_dimension(v: vec3<f32>) -> u32 {
    let a = abs(v);
    if a.x >= a.y && a.x >= a.z {
        return 0u;
    }
    if a.y >= a.z {
        return 1u;
    }
    return 2u;
}

fn make_shear(direction: vec3<f32>) -> Shear {
    let kz = max_dimension(direction);
    var kx = (kz + 1u) % 3u;
    var ky = (kx + 1u) % 3u;
    // Keep the winding: swap kx and ky when the major component is negative.
    if direction[kz] < 0.0 {
        let swap = kx;
        kx = ky;
        ky = swap;
    }
    let sz = 1.0 / direction[kz];
    return Shear(kx, ky, kz, direction[kx] * sz, direction[ky] * sz, sz);
}

// t along the ray of the hit with triangle `tri` and its barycentrics, or t = -1.
fn intersect_triangle(ray: Ray, shear: Shear, tri: Triangle) -> vec3<f32> {
    let a = tri.v0 - ray.origin;
    let b = tri.v1 - ray.origin;
    let c = tri.v2 - ray.origin;
    let ax = a[shear.kx] - shear.sx * a[shear.kz];
    let ay = a[shear.ky] - shear.sy * a[shear.kz];
    let bx = b[shear.kx] - shear.sx * b[shear.kz];
    let by = b[shear.ky] - shear.sy * b[shear.kz];
    let cx = c[shear.kx] - shear.sx * c[shear.kz];
    let cy = c[shear.ky] - shear.sy * c[shear.kz];
    let u = cx * by - cy * bx;
    let v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return vec3<f32>(-1.0, 0.0, 0.0);
    }
    let det = u + v + w;
    if det == 0.0 {
        return vec3<f32>(-1.0, 0.0, 0.0);
    }
    let az = shear.sz * a[shear.kz];
    let bz = shear.sz * b[shear.kz];
    let cz = shear.sz * c[shear.kz];
    let t_scaled = u * az + v * bz + w * cz;
    let inv_det = 1.0 / det;
    return vec3<f32>(t_scaled * inv_det, v * inv_det, w * inv_det);
}

// 1 / d with a zero component replaced by a tiny value of the same sign.
fn safe_inverse(d: vec3<f32>) -> vec3<f32> {
    let tiny = select(vec3<f32>(1e-30), vec3<f32>(-1e-30), d < vec3<f32>(0.0));
    return 1.0 / select(d, tiny, abs(d) < vec3<f32>(1e-30));
}

// Entry distance of the ray into the node's box within [tmin, limit], or -1 if the ray
// misses the box there (entry distances are never negative: tmin >= 0). A sentinel above
// `limit` would not do: limit + 1 == limit for rays with an unbounded tmax.
fn enter_box(node: BvhNode, origin: vec3<f32>, inv_dir: vec3<f32>, tmin: f32, limit: f32) -> f32 {
    let t0 = (node.aabb_min - origin) * inv_dir;
    let t1 = (node.aabb_max - origin) * inv_dir;
    let near = min(t0, t1);
    let far = max(t0, t1);
    let enter = max(max(near.x, near.y), max(near.z, tmin));
    let leave = min(min(far.x, far.y), min(far.z, limit));
    return select(-1.0, enter, enter <= leave);
}
