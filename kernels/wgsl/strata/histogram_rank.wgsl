// The block histogram by ranking (paper §4.1): the same order and the same outputs as
// the bitonic network (strata/histogram_network.wgsl), found by counting instead of
// exchanging; the bindings, dispatch, element layout and finishing code are
// strata/histogram.wgsl's, shared with the network. Each element's
// sorted position is the number of elements of its block that precede it in the order
// (cluster, canonical key, pixel index); every invocation counts, for its 16 elements,
// over the block's slots read from workgroup memory, two slots a read
// (strata/histogram_slot_pairs.wgsl). That is n comparisons per element (n = B², 256 at
// B = 16) against the network's ~log²(n)/2 exchanges, but it needs four barriers instead
// of one pair per round trip, and every lane of a SIMD row reads the same slots: on a CPU
// device (lavapipe), where a round trip through workgroup memory costs one scalar access
// per lane and element, that is cheaper.
//
// The counting loop runs over the whole block in every lane (the same trip count in a
// SIMD row) with one test, "below" in (cluster, key): a slot before the invocation's own
// 16 precedes an element it ties with, so its key is lowered by one first (keys are moved
// to 1 ..= 0x7f800002 for the count, so nothing wraps); ties among the invocation's own
// 16 are then counted by position. An element is counted as the two halves of the 63-bit
// number cluster * 2^31 + key, each offset so that a signed comparison orders it, and
// "below" is two signed comparisons and an add (the three unsigned comparisons of a
// lexicographic order cost two to three instructions each on x86). Measured on lavapipe
// at 1M candidates, B = 16 (docs/benchmarks/block_sort.md): 48 ms with three loops split
// at each invocation's own slots (a SIMD row ran its widest split) and one slot a read,
// 41 ms with this loop, 36 ms reading pairs, 33 ms with two pairs an iteration (four:
// 36 ms), 32 ms with the halves compared unsigned, 28 ms signed.

// #import strata/histogram.wgsl
// #import strata/histogram_slot_pairs.wgsl

// A canonical key moved into 1 ..= 0x7f800002 with its order kept: finite keys
// (0 ..= 0x7f7fffff, strata/candidate.wgsl) plus one, INVALID_KEY and SENTINEL_KEY just
// above them. So a key lowered by one stays within 31 bits (it does not borrow from the
// cluster's bit above it in counting_form), and a slot "at or below" an element is a slot
// whose key, lowered by one, is below the element's.
fn counting_keys(key: vec4<u32>) -> vec4<u32> {
    return select(key - vec4(0x807ffffdu), key + vec4(1u), key < vec4(0x80000000u));
}

// An element in the counting loop's form, in the quad's cluster and key fields: the high
// and low halves of the 63-bit number cluster * 2^31 + counting key (whose order is
// (cluster, key)'s), the high half (below 2^31) less 2^30 and the low half with its top
// bit flipped, so that both order as signed integers and the high half plus one cannot
// overflow.
fn counting_form(q: Quad) -> Quad {
    let high = (q.cluster >> vec4(1u)) + vec4(0xc0000000u);
    let low = ((q.cluster << vec4(31u)) | counting_keys(q.key)) ^ vec4(0x80000000u);
    return Quad(high, low, q.local);
}

// Whether `other` (a slot in counting form) lies below each of q's four, as 0 or 1: its
// high half below q's plus the borrow of the low halves.
fn below(other: vec2<u32>, q: Quad) -> vec4<u32> {
    let borrow = select(vec4(0i), vec4(1i), vec4<i32>(bitcast<i32>(other.y)) < bitcast<vec4<i32>>(q.key));
    return select(vec4(0u), vec4(1u), vec4<i32>(bitcast<i32>(other.x)) < bitcast<vec4<i32>>(q.cluster) + borrow);
}

// Whether `other` (at block position `position`) ties with each of q's four in
// (cluster, key) and comes first by position, as 0 or 1.
fn tie_before(other: vec2<u32>, position: u32, q: Quad) -> vec4<u32> {
    let same = (vec4<u32>(other.x) == q.cluster) & (vec4<u32>(other.y) == q.key);
    return select(vec4(0u), vec4(1u), same & (vec4<u32>(position) < q.local));
}

// This invocation's 16 slots (natural layout, from `base`) as 8 pairs.
fn store_pairs(el: Elements, base: u32) {
    let pair = base >> 1u;
    set_slot_pair(pair, vec4(el.q0.cluster.x, el.q0.key.x, el.q0.cluster.y, el.q0.key.y));
    set_slot_pair(pair + 1u, vec4(el.q0.cluster.z, el.q0.key.z, el.q0.cluster.w, el.q0.key.w));
    set_slot_pair(pair + 2u, vec4(el.q1.cluster.x, el.q1.key.x, el.q1.cluster.y, el.q1.key.y));
    set_slot_pair(pair + 3u, vec4(el.q1.cluster.z, el.q1.key.z, el.q1.cluster.w, el.q1.key.w));
    set_slot_pair(pair + 4u, vec4(el.q2.cluster.x, el.q2.key.x, el.q2.cluster.y, el.q2.key.y));
    set_slot_pair(pair + 5u, vec4(el.q2.cluster.z, el.q2.key.z, el.q2.cluster.w, el.q2.key.w));
    set_slot_pair(pair + 6u, vec4(el.q3.cluster.x, el.q3.key.x, el.q3.cluster.y, el.q3.key.y));
    set_slot_pair(pair + 7u, vec4(el.q3.cluster.z, el.q3.key.z, el.q3.cluster.w, el.q3.key.w));
}

// The whole pass for one workgroup. Must be called in uniform control flow.
fn run_block_histogram_ranked(t: u32, workgroup_id: vec3<u32>) {
    let setup = setup_block_histogram(t, workgroup_id);
    let el = load_block_elements(setup);
    let counted = Elements(counting_form(el.q0), counting_form(el.q1), counting_form(el.q2), counting_form(el.q3));
    // The unsorted blocks in the natural layout, in counting form: slot begin + p holds
    // block position p (blocks and an invocation's slots start at even slots).
    store_pairs(counted, setup.base);
    workgroupBarrier();

    let begin = setup.base - setup.first;
    let end = begin + (1u << setup.log_n);
    var r0 = vec4(0u);
    var r1 = vec4(0u);
    var r2 = vec4(0u);
    var r3 = vec4(0u);
    for (var j = begin; j < end; j += 4u) {
        let pair = slot_pair(j >> 1u);
        let next = slot_pair((j >> 1u) + 1u);
        // Before this invocation's slots: precedes the elements it ties with.
        let lower = select(0u, 1u, j < setup.base);
        let a = vec2(pair.x, pair.y - lower);
        let b = vec2(pair.z, pair.w - lower);
        let c = vec2(next.x, next.y - lower);
        let d = vec2(next.z, next.w - lower);
        r0 += below(a, counted.q0) + below(b, counted.q0) + below(c, counted.q0) + below(d, counted.q0);
        r1 += below(a, counted.q1) + below(b, counted.q1) + below(c, counted.q1) + below(d, counted.q1);
        r2 += below(a, counted.q2) + below(b, counted.q2) + below(c, counted.q2) + below(d, counted.q2);
        r3 += below(a, counted.q3) + below(b, counted.q3) + below(c, counted.q3) + below(d, counted.q3);
    }
    for (var j = setup.base; j < setup.base + ELEMS; j += 2u) {
        let pair = slot_pair(j >> 1u);
        let a = pair.xy;
        let b = pair.zw;
        r0 += tie_before(a, j - begin, counted.q0) + tie_before(b, j + 1u - begin, counted.q0);
        r1 += tie_before(a, j - begin, counted.q1) + tie_before(b, j + 1u - begin, counted.q1);
        r2 += tie_before(a, j - begin, counted.q2) + tie_before(b, j + 1u - begin, counted.q2);
        r3 += tie_before(a, j - begin, counted.q3) + tie_before(b, j + 1u - begin, counted.q3);
    }

    // Every element's block position to its sorted slot (shared_local, which the loops
    // above do not read); then each invocation pulls its own sorted slots' elements from
    // the pairs, still in counting form, and writes them back as whole pairs once every
    // pull is done. So no two invocations ever write the two halves of one vec4
    // (strata/histogram_slot_pairs.wgsl says why that matters).
    scatter_positions(el.q0.local, begin + r0);
    scatter_positions(el.q1.local, begin + r1);
    scatter_positions(el.q2.local, begin + r2);
    scatter_positions(el.q3.local, begin + r3);
    workgroupBarrier();
    let sorted = Elements(
        pull_quad(setup.base, begin),
        pull_quad(setup.base + 4u, begin),
        pull_quad(setup.base + 8u, begin),
        pull_quad(setup.base + 12u, begin),
    );
    workgroupBarrier();
    store_pairs(sorted, setup.base);
    workgroupBarrier();
    finish_block_histogram(setup, sorted);
}

fn scatter_positions(local: vec4<u32>, slots: vec4<u32>) {
    shared_local[slots.x] = local.x;
    shared_local[slots.y] = local.y;
    shared_local[slots.z] = local.z;
    shared_local[slots.w] = local.w;
}

// (cluster, canonical key) of a slot in counting form: counting_form undone.
fn from_counting_form(slot: vec2<u32>) -> vec2<u32> {
    let low = slot.y ^ 0x80000000u;
    let cluster = ((slot.x - 0xc0000000u) << 1u) | (low >> 31u);
    let key = low & 0x7fffffffu;
    return vec2(cluster, select(key + 0x807ffffdu, key - 1u, key <= 0x7f800000u));
}

// The elements that sorted slots first..first+3 of the block starting at slot `begin`
// hold: their block positions from shared_local, their (cluster, key) from the slots
// they came from, which still hold the natural layout in counting form.
fn pull_quad(first: u32, begin: u32) -> Quad {
    let local = vec4(shared_local[first], shared_local[first + 1u], shared_local[first + 2u], shared_local[first + 3u]);
    let a = from_counting_form(slot_cluster_key(begin + local.x));
    let b = from_counting_form(slot_cluster_key(begin + local.y));
    let c = from_counting_form(slot_cluster_key(begin + local.z));
    let d = from_counting_form(slot_cluster_key(begin + local.w));
    return Quad(vec4(a.x, b.x, c.x, d.x), vec4(a.y, b.y, c.y, d.y), local);
}
