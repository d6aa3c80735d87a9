// BVH2 traversal shared by every kernel that traces rays (closest hit and any hit).
//
// Needs, from the including kernel: `fn bvh_node(index: u32) -> BvhNode` and
// `fn bvh_triangle(index: u32) -> Triangle` (from arrays of their own, or from the
// scene's one buffer of rows), the workgroup array `trace_stack` with TRACE_STACK_DEPTH -
// REGISTER_STACK words per invocation, and `fn leaf_triangle(slot: u32) -> u32` mapping a
// leaf's primitive slot to a triangle index (through obvhs' primitive_indices, or the
// identity when the triangles were reordered into leaf order on the host).

// #import gpu/trace.wgsl
// #import trace/bvh.wgsl
// #requires fn bvh_node(index: u32) -> BvhNode
// #requires fn bvh_triangle(index: u32) -> Triangle
// #requires var<workgroup> trace_stack: array<u32, 2560>
// #requires fn leaf_triangle(slot: u32) -> u32

// How many of the stack's newest entries are kept in registers (top0 .. top7).
const REGISTER_STACK: u32 = 8u;

// The closest hit in (ray.tmin, ray.tmax), or with `any_hit` the first hit found there
// (shadow rays: only primitive != MISS matters). `lane` picks this invocation's slice of
// `trace_stack`. primitive = STACK_OVERFLOW when the BVH is deeper than the stack.
fn traverse(ray: Ray, lane: u32, any_hit: bool) -> Hit {
    let shear = make_shear(ray.direction);
    let inv_dir = safe_inverse(ray.direction);
    var best = Hit(ray.tmax, 0.0, 0.0, MISS);
    let base = lane * (TRACE_STACK_DEPTH - REGISTER_STACK);
    // The stack's newest REGISTER_STACK entries live in registers (top0 the newest);
    // deeper entries spill to trace_stack. On lavapipe every per-lane access to
    // workgroup memory becomes scalar loads and stores, so most pushes and pops stay in
    // registers instead.
    var depth = 0u;
    var top0 = 0u;
    var top1 = 0u;
    var top2 = 0u;
    var top3 = 0u;
    var top4 = 0u;
    var top5 = 0u;
    var top6 = 0u;
    var top7 = 0u;
    var node_index = 0u;
    if enter_box(bvh_node(0u), ray.origin, inv_dir, ray.tmin, best.t) < 0.0 {
        return best;
    }
    loop {
        let node = bvh_node(node_index);
        if node.prim_count > 0u {
            for (var i = 0u; i < node.prim_count; i++) {
                let primitive = leaf_triangle(node.first_index + i);
                let hit = intersect_triangle(ray, shear, bvh_triangle(primitive));
                if hit.x > ray.tmin && hit.x < best.t {
                    best = Hit(hit.x, hit.y, hit.z, primitive);
                    if any_hit {
                        return best;
                    }
                }
            }
        } else {
            let left = node.first_index;
            let right = left + 1u;
            let t_left = enter_box(bvh_node(left), ray.origin, inv_dir, ray.tmin, best.t);
            let t_right = enter_box(bvh_node(right), ray.origin, inv_dir, ray.tmin, best.t);
            let hit_left = t_left >= 0.0;
            let hit_right = t_right >= 0.0;
            if hit_left && hit_right {
                // Visit the nearer child first; the farther one waits on the stack.
                let near_is_left = t_left <= t_right;
                if depth == TRACE_STACK_DEPTH {
                    return Hit(ray.tmax, 0.0, 0.0, STACK_OVERFLOW);
                }
                if depth >= REGISTER_STACK {
                    trace_stack[base + depth - REGISTER_STACK] = top7;
                }
                top7 = top6;
                top6 = top5;
                top5 = top4;
                top4 = top3;
                top3 = top2;
                top2 = top1;
                top1 = top0;
                top0 = select(left, right, near_is_left);
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
        node_index = top0;
        top0 = top1;
        top1 = top2;
        top2 = top3;
        top3 = top4;
        top4 = top5;
        top5 = top6;
        top6 = top7;
        if depth >= REGISTER_STACK {
            top7 = trace_stack[base + depth - REGISTER_STACK];
        }
    }
    return best;
}
