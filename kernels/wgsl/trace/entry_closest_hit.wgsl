// Closest-hit query for a batch of rays through obvhs' BVH2 (bvh.wgsl, traverse.wgsl).
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
// params.workgroups_x. The traversal stack's newest REGISTER_STACK entries live in
// registers, the rest in workgroup memory (TRACE_STACK_DEPTH - REGISTER_STACK = 40
// entries per invocation): function-local arrays do not translate to every target.

// #import gpu/trace.wgsl
// #import trace/bvh.wgsl
// #import trace/traverse.wgsl

@group(0) @binding(0) var<uniform> trace_params: TraceParams;
@group(0) @binding(1) var<storage, read> nodes: array<BvhNode>;
@group(0) @binding(2) var<storage, read> primitive_indices: array<u32>;
@group(0) @binding(3) var<storage, read> triangles: array<Triangle>;
@group(0) @binding(4) var<storage, read> rays: array<Ray>;
@group(0) @binding(5) var<storage, read_write> hits: array<Hit>;

var<workgroup> trace_stack: array<u32, 2560>;

@compute @workgroup_size(64)
fn bvh_closest_hit(
    @builtin(local_invocation_index) lane: u32,
    @builtin(workgroup_id) workgroup: vec3<u32>,
) {
    let index = (workgroup.y * trace_params.workgroups_x + workgroup.x) * 64u + lane;
    if index >= trace_params.ray_count {
        return;
    }
    hits[index] = traverse(rays[index], lane, false);
}

fn leaf_triangle(slot: u32) -> u32 {
    return primitive_indices[slot];
}

fn bvh_node(index: u32) -> BvhNode {
    return nodes[index];
}

fn bvh_triangle(index: u32) -> Triangle {
    return triangles[index];
}
