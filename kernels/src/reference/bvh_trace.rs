//! What the BVH closest-hit kernel computes, stated in Rust with the same operations in
//! the same order (so results match bit for bit wherever the GPU does not contract
//! products into fused multiply-adds).

use crate::trace_types::{GpuBvhNode, GpuTriangle, Hit, MISS, Ray, STACK_OVERFLOW, TRACE_STACK_DEPTH};

type V3 = [f32; 3];

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

struct Shear {
    kx: usize,
    ky: usize,
    kz: usize,
    sx: f32,
    sy: f32,
    sz: f32,
}

fn max_dimension(v: V3) -> usize {
    let a = v.map(f32::abs);
    if a[0] >= a[1] && a[0] >= a[2] {
        0
    } else if a[1] >= a[2] {
        1
    } else {
        2
    }
}

fn make_shear(d: V3) -> Shear {
    let kz = max_dimension(d);
    let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
    if d[kz] < 0.0 {
        std::mem::swap(&mut kx, &mut ky);
    }
    let sz = 1.0 / d[kz];
    Shear { kx, ky, kz, sx: d[kx] * sz, sy: d[ky] * sz, sz }
}

/// (t, u, v) of the ray's hit with `tri`, t = -1 for none.
fn intersect_triangle(ray: &Ray, s: &Shear, tri: &GpuTriangle) -> V3 {
    let a = sub(tri.v0, ray.origin);
    let b = sub(tri.v1, ray.origin);
    let c = sub(tri.v2, ray.origin);
    let ax = a[s.kx] - s.sx * a[s.kz];
    let ay = a[s.ky] - s.sy * a[s.kz];
    let bx = b[s.kx] - s.sx * b[s.kz];
    let by = b[s.ky] - s.sy * b[s.kz];
    let cx = c[s.kx] - s.sx * c[s.kz];
    let cy = c[s.ky] - s.sy * c[s.kz];
    let u = cx * by - cy * bx;
    let v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return [-1.0, 0.0, 0.0];
    }
    let det = u + v + w;
    if det == 0.0 {
        return [-1.0, 0.0, 0.0];
    }
    let az = s.sz * a[s.kz];
    let bz = s.sz * b[s.kz];
    let cz = s.sz * c[s.kz];
    let t_scaled = u * az + v * bz + w * cz;
    let inv_det = 1.0 / det;
    [t_scaled * inv_det, v * inv_det, w * inv_det]
}

fn safe_inverse(d: V3) -> V3 {
    d.map(|x| {
        let tiny = if x < 0.0 { -1e-30 } else { 1e-30 };
        1.0 / if x.abs() < 1e-30 { tiny } else { x }
    })
}

fn enter_box(node: &GpuBvhNode, origin: V3, inv: V3, tmin: f32, limit: f32) -> f32 {
    let mut near = [0.0f32; 3];
    let mut far = [0.0f32; 3];
    for i in 0..3 {
        let t0 = (node.aabb_min[i] - origin[i]) * inv[i];
        let t1 = (node.aabb_max[i] - origin[i]) * inv[i];
        near[i] = t0.min(t1);
        far[i] = t0.max(t1);
    }
    let enter = near[0].max(near[1]).max(near[2].max(tmin));
    let leave = far[0].min(far[1]).min(far[2].min(limit));
    if enter <= leave { enter } else { -1.0 }
}

/// The closest hit of `ray` through the BVH (`nodes`, root at 0).
pub fn closest_hit(nodes: &[GpuBvhNode], primitive_indices: &[u32], triangles: &[GpuTriangle], ray: &Ray) -> Hit {
    let shear = make_shear(ray.direction);
    let inv = safe_inverse(ray.direction);
    let mut best = Hit { t: ray.tmax, u: 0.0, v: 0.0, primitive: MISS };
    if enter_box(&nodes[0], ray.origin, inv, ray.tmin, best.t) < 0.0 {
        return best;
    }
    let mut stack = Vec::with_capacity(TRACE_STACK_DEPTH as usize);
    let mut node_index = 0usize;
    loop {
        let node = &nodes[node_index];
        if node.prim_count > 0 {
            for i in 0..node.prim_count {
                let primitive = primitive_indices[(node.first_index + i) as usize];
                let [t, u, v] = intersect_triangle(ray, &shear, &triangles[primitive as usize]);
                if t > ray.tmin && t < best.t {
                    best = Hit { t, u, v, primitive };
                }
            }
        } else {
            let (left, right) = (node.first_index as usize, node.first_index as usize + 1);
            let t_left = enter_box(&nodes[left], ray.origin, inv, ray.tmin, best.t);
            let t_right = enter_box(&nodes[right], ray.origin, inv, ray.tmin, best.t);
            let (hit_left, hit_right) = (t_left >= 0.0, t_right >= 0.0);
            if hit_left && hit_right {
                let near_is_left = t_left <= t_right;
                if stack.len() == TRACE_STACK_DEPTH as usize {
                    return Hit { t: ray.tmax, u: 0.0, v: 0.0, primitive: STACK_OVERFLOW };
                }
                stack.push(if near_is_left { right } else { left });
                node_index = if near_is_left { left } else { right };
                continue;
            }
            if hit_left || hit_right {
                node_index = if hit_left { left } else { right };
                continue;
            }
        }
        match stack.pop() {
            Some(next) => node_index = next,
            None => return best,
        }
    }
}
