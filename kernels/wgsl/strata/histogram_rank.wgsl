// The block histogram by ranking (paper §4.1): the same order and the same outputs as
// the bitonic network of strata/histogram.wgsl (whose bindings, dispatch, element layout
// and finishing code it shares), found by counting instead of exchanging. Each element's
// sorted position is the number of elements of its block that precede it in the order
// (cluster, canonical key, pixel index); every invocation counts, for its 16 elements,
// over the block's slots read once from workgroup memory. That is n comparisons per
// element (n = B², 256 at B = 16) against the network's ~log²(n)/2 exchanges, but it
// needs three barriers instead of one pair per round trip, and every lane of a SIMD
// row reads the same slot: on a CPU device (lavapipe), where a round trip through
// workgroup memory costs one scalar access per lane and element, that is cheaper.

// #import strata/histogram.wgsl

// Count of (cluster, key) pairs `other` at or below / below each of q's four, as 0 or 1.
fn at_or_below(other: vec2<u32>, q: Quad) -> vec4<u32> {
    let c = vec4<u32>(other.x);
    return select(vec4(0u), vec4(1u), (c < q.cluster) | ((c == q.cluster) & (vec4<u32>(other.y) <= q.key)));
}

fn below(other: vec2<u32>, q: Quad) -> vec4<u32> {
    let c = vec4<u32>(other.x);
    return select(vec4(0u), vec4(1u), (c < q.cluster) | ((c == q.cluster) & (vec4<u32>(other.y) < q.key)));
}

// Whether `other` (with block position `local`) precedes each of q's four.
fn before(other: vec2<u32>, local: u32, q: Quad) -> vec4<u32> {
    let o = Quad(vec4<u32>(other.x), vec4<u32>(other.y), vec4<u32>(local));
    return select(vec4(0u), vec4(1u), precedes(o, q));
}

// The whole pass for one workgroup. Must be called in uniform control flow.
fn run_block_histogram_ranked(t: u32, workgroup_id: vec3<u32>) {
    let setup = setup_block_histogram(t, workgroup_id);
    let el = load_block_elements(setup);
    // The unsorted blocks in the natural layout: slot begin + p holds block position p.
    store_registers(el, t, 0u);
    workgroupBarrier();

    // Positions below this invocation's own come first in a tie of (cluster, key), those
    // above come after; its own 16 are compared with the position too.
    let begin = setup.base - setup.first;
    let end = begin + (1u << setup.log_n);
    var r0 = vec4(0u);
    var r1 = vec4(0u);
    var r2 = vec4(0u);
    var r3 = vec4(0u);
    for (var j = begin; j < setup.base; j++) {
        let other = shared_cluster_key[j];
        r0 += at_or_below(other, el.q0);
        r1 += at_or_below(other, el.q1);
        r2 += at_or_below(other, el.q2);
        r3 += at_or_below(other, el.q3);
    }
    for (var j = setup.base; j < setup.base + ELEMS; j++) {
        let other = shared_cluster_key[j];
        r0 += before(other, j - begin, el.q0);
        r1 += before(other, j - begin, el.q1);
        r2 += before(other, j - begin, el.q2);
        r3 += before(other, j - begin, el.q3);
    }
    for (var j = setup.base + ELEMS; j < end; j++) {
        let other = shared_cluster_key[j];
        r0 += below(other, el.q0);
        r1 += below(other, el.q1);
        r2 += below(other, el.q2);
        r3 += below(other, el.q3);
    }

    // Every element to its sorted slot, then this invocation's sorted slots back.
    workgroupBarrier();
    scatter_quad(el.q0, begin + r0);
    scatter_quad(el.q1, begin + r1);
    scatter_quad(el.q2, begin + r2);
    scatter_quad(el.q3, begin + r3);
    workgroupBarrier();
    finish_block_histogram(setup, load_registers(t, 0u));
}

fn scatter_quad(q: Quad, slots: vec4<u32>) {
    place(slots.x, q.cluster.x, q.key.x, q.local.x);
    place(slots.y, q.cluster.y, q.key.y, q.local.y);
    place(slots.z, q.cluster.z, q.key.z, q.local.z);
    place(slots.w, q.cluster.w, q.key.w, q.local.w);
}
