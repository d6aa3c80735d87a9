// Closest-hit query for a batch of rays through obvhs' BVH2 (see bvh.wgsl).
//
// Bindings (group 0):
//   0 uniform            TraceParams     ray count, dispatch width
//   1 storage, read      array<BvhNode>  obvhs Bvh2::nodes (root at 0)
//   2 storage, read      array<u32>      obvhs Bvh2::primitive_indices
//   3 storage, read      array<Triangle> the triangles the BVH was built from
//   4 storage, read      array<Ray>      one ray per invocation
//   5 storage, rw        array<Hit>      one hit per ray
//
// Dispatch: 64 rays per workgroup, ceil(rays / 64) workgroups in rows of
// params.workgroups_x. The traversal stack lives in workgroup memory (TRACE_STACK_DEPTH
// entries per invocation): function-local arrays do not translate to every target.

struct TraceParams {
    ray_count: u32,
    workgroups_x: u32,
    _pad0: u32,
    _pad1: u32,
}

const TRACE_STACK_DEPTH: u32 = 48u;

@group(0) @binding(0) var<uniform> trace_params: TraceParams;
@group(0) @binding(1) var<storage, read> nodes: array<BvhNode>;
@group(0) @binding(2) var<storage, read> primitive_indices: array<u32>;
@group(0) @binding(3) var<storage, read> triangles: array<Triangle>;
@group(0) @binding(4) var<storage, read> rays: array<Ray>;
@group(0) @binding(5) var<storage, read_write> hits: array<Hit>;

var<workgroup> trace_stack: array<u32, 3072>;

@compute @workgroup_size(64)
fn bvh_closest_hit(
    @builtin(local_invocation_index) lane: u32,
    @builtin(workgroup_id) workgroup: vec3<u32>,
) {
    let index = (workgroup.y * trace_params.workgroups_x + workgroup.x) * 64u + lane;
    if index >= trace_params.ray_count {
        return;
    }
    let ray = rays[index];
    let shear = make_shear(ray.direction);
    let inv_dir = safe_inverse(ray.direction);
    var best = Hit(ray.tmax, 0.0, 0.0, MISS);
    let base = lane * TRACE_STACK_DEPTH;
    var depth = 0u;
    var node_index = 0u;
    var overflow = false;
    if enter_box(nodes[0], ray.origin, inv_dir, ray.tmin, best.t) > best.t {
        hits[index] = best;
        return;
    }
    loop {
        let node = nodes[node_index];
        if node.prim_count > 0u {
            for (var i = 0u; i < node.prim_count; i++) {
                let primitive = primitive_indices[node.first_index + i];
                let hit = intersect_triangle(ray, shear, triangles[primitive]);
                if hit.x > ray.tmin && hit.x < best.t {
                    best = Hit(hit.x, hit.y, hit.z, primitive);
                }
            }
        } else {
            let left = node.first_index;
            let right = left + 1u;
            let t_left = enter_box(nodes[left], ray.origin, inv_dir, ray.tmin, best.t);
            let t_right = enter_box(nodes[right], ray.origin, inv_dir, ray.tmin, best.t);
            let hit_left = t_left <= best.t;
            let hit_right = t_right <= best.t;
            if hit_left && hit_right {
                // Visit the nearer child first; the farther one waits on the stack.
                let near_is_left = t_left <= t_right;
                if depth == TRACE_STACK_DEPTH {
                    overflow = true;
                    break;
                }
                trace_stack[base + depth] = select(left, right, near_is_left);
                depth += 1u;
                node_index = select(right, left, near_is_left);
                continue;
            }
            if hit_left || hit_right {
                node_index = select(right, left, hit_left);
                continue;
            }
        }
        if depth == 0u {
            break;
        }
        depth -= 1u;
        node_index = trace_stack[base + depth];
    }
    if overflow {
        best = Hit(ray.tmax, 0.0, 0.0, STACK_OVERFLOW);
    }
    hits[index] = best;
}
