// Builds per-pixel linked lists of fragments, as order-independent transparency does:
// fragment i allocates node n = atomicAdd(&counter[0], 1) and, when n < capacity,
// pushes it onto its pixel's list with next = atomicExchange(&heads[pixel], n).
// The order of each list depends on scheduling; only its contents are fixed.
// Bindings: 0 fragments (read; { pixel: u32, depth: f32, colour: u32, unused: u32 }),
// 1 counter (read_write, atomic), 2 heads (read_write, atomic per pixel, 0xffffffff =
// empty), 3 nodes (read_write; { depth: f32, colour: u32, next: u32, unused: u32 }).

struct Fragment { pixel: u32, depth: f32, colour: u32, unused: u32 }
struct Node { depth: f32, colour: u32, next: u32, unused: u32 }

@group(0) @binding(0) var<storage, read> fragments: array<Fragment>;
@group(0) @binding(1) var<storage, read_write> counter: array<atomic<u32>, 1>;
@group(0) @binding(2) var<storage, read_write> heads: array<atomic<u32>>;
@group(0) @binding(3) var<storage, read_write> nodes: array<Node>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= arrayLength(&fragments) {
        return;
    }
    let fragment = fragments[gid.x];
    let n = atomicAdd(&counter[0], 1u);
    if n >= arrayLength(&nodes) {
        return;
    }
    let next = atomicExchange(&heads[fragment.pixel], n);
    nodes[n] = Node(fragment.depth, fragment.colour, next, 0u);
}
