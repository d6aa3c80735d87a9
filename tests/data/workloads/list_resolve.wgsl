// Resolves the per-pixel fragment lists built by list_build.wgsl: pixel p walks its
// list (at most 32 nodes) into a private array, insertion-sorts it by (depth, colour)
// ascending, and writes out[3p..3p+3] = (count, colour of the nearest fragment or 0,
// h) with h folded front to back as h = h * 31 + colour (wrapping) from h = 17.
// Bindings: 0 heads (read), 1 nodes (read), 2 out (read_write).

struct Node { depth: f32, colour: u32, next: u32, unused: u32 }

@group(0) @binding(0) var<storage, read> heads: array<u32>;
@group(0) @binding(1) var<storage, read> nodes: array<Node>;
@group(0) @binding(2) var<storage, read_write> out: array<u32>;

const MAX_LIST: u32 = 32u;

fn before(a: Node, b: Node) -> bool {
    return a.depth < b.depth || (a.depth == b.depth && a.colour < b.colour);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let p = gid.x;
    if p >= arrayLength(&heads) {
        return;
    }
    var list: array<Node, 32>;
    var count = 0u;
    var at = heads[p];
    while at != 0xffffffffu && count < MAX_LIST {
        let node = nodes[at];
        // Insertion: shift later entries up until node's place.
        var j = count;
        while j > 0u && before(node, list[j - 1u]) {
            list[j] = list[j - 1u];
            j -= 1u;
        }
        list[j] = node;
        count += 1u;
        at = node.next;
    }
    var h = 17u;
    for (var i = 0u; i < count; i++) {
        h = h * 31u + list[i].colour;
    }
    out[3u * p] = count;
    out[3u * p + 1u] = select(0u, list[0].colour, count > 0u);
    out[3u * p + 2u] = h;
}
