// BVH2 traversal shared by every kernel that traces rays (closest hit and any hit).
//
// Needs, from the including kernel: the storage arrays `nodes` (BvhNode) and `triangles`
// (Triangle), the workgroup array `trace_stack` with TRACE_STACK_DEPTH words per
// invocation, and `fn leaf_triangle(slot: u32) -> u32` mapping a leaf's primitive slot
// to an index into `triangles` (through obvhs' primitive_indices, or the identity when
// the triangles were reordered into leaf order on the host).

const TRACE_STACK_DEPTH: u32 = 48u;

// The closest hit in (ray.tmin, ray.tmax), or with `any_hit` the first hit found there
// (shadow rays: only primitive != MISS matters). `lane` picks this invocation's slice of
// `trace_stack`. primitive = STACK_OVERFLOW when the BVH is deeper than the stack.
fn traverse(ray: Ray, lane: u32, any_hit: bool) -> Hit {
    let shear = make_shear(ray.direction);
    let inv_dir = safe_inverse(ray.direction);
    var best = Hit(ray.tmax, 0.0, 0.0, MISS);
    let base = lane * TRACE_STACK_DEPTH;
    var depth = 0u;
    var node_index = 0u;
    if enter_box(nodes[0], ray.origin, inv_dir, ray.tmin, best.t) < 0.0 {
        return best;
    }
    loop {
        let node = nodes[node_index];
        if node.prim_count > 0u {
            for (var i = 0u; i < node.prim_count; i++) {
                let primitive = leaf_triangle(node.first_index + i);
                let hit = intersect_triangle(ray, shear, triangles[primitive]);
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
            let t_left = enter_box(nodes[left], ray.origin, inv_dir, ray.tmin, best.t);
            let t_right = enter_box(nodes[right], ray.origin, inv_dir, ray.tmin, best.t);
            let hit_left = t_left >= 0.0;
            let hit_right = t_right >= 0.0;
            if hit_left && hit_right {
                // Visit the nearer child first; the farther one waits on the stack.
                let near_is_left = t_left <= t_right;
                if depth == TRACE_STACK_DEPTH {
                    return Hit(ray.tmax, 0.0, 0.0, STACK_OVERFLOW);
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
    return best;
}
