// The block histogram's bitonic sorting network (paper §4.1), the sorting of
// block_histogram and block_histogram_subgroup (strata/entry_histogram.wgsl,
// strata/entry_histogram_subgroup.wgsl; bindings, dispatch and the finishing code:
// strata/histogram.wgsl). The ranking (strata/histogram_rank.wgsl) gives the same order
// without any of this file.
//
// Each invocation holds ELEMS = 16 elements in vector registers. Compare steps whose
// stride lies inside an invocation's elements run in registers; subgroup lanes (in the
// subgroup entry point, through lane_exchange) handle the next strides by shuffles;
// larger strides are brought into registers by re-reading the block from workgroup
// memory in a transposed order, ELEM_BITS = 4 steps per round trip. A 16 x 16 block takes
// 8 round trips (16 barriers) without subgroups and 2 with 8-wide subgroups, against 36
// barriers for the naive one-step-per-barrier network. The round trips read and write
// single slots in every layout (strata/histogram_slots.wgsl, one vec2 a slot).

// #import strata/histogram.wgsl
// #requires fn lane_exchange(value: vec4<u32>, mask: u32) -> vec4<u32>
// #requires fn set_slot_cluster_key(slot: u32, value: vec2<u32>)

// Strict total order on (cluster, key, local), lane by lane; locals are unique within a block.
fn precedes(a: Quad, b: Quad) -> vec4<bool> {
    return select(select(a.local < b.local, a.key < b.key, a.key != b.key), a.cluster < b.cluster, a.cluster != b.cluster);
}

fn pick(a: Quad, b: Quad, take_b: vec4<bool>) -> Quad {
    return Quad(select(a.cluster, b.cluster, take_b), select(a.key, b.key, take_b), select(a.local, b.local, take_b));
}

// Sort direction of the pairs whose lower elements are `lower` (element indices) in
// merge stage 2^log_k. The last stage sorts every block ascending; earlier stages
// alternate to build bitonic sequences.
fn ascending(t: u32, lower: vec4<u32>, lo: u32, log_k: u32, log_n: u32) -> vec4<bool> {
    let slots = vec4<u32>(slot_of(t, 0u, lo)) | (lower << vec4<u32>(lo));
    return vec4<bool>(log_k == log_n) | (((slots >> vec4<u32>(log_k)) & vec4<u32>(1u)) == vec4<u32>(0u));
}

// Compare-exchange of four pairs: returns (first, second) ordered as `up` asks.
struct QuadPair {
    first: Quad,
    second: Quad,
}

fn exchange(a: Quad, b: Quad, up: vec4<bool>) -> QuadPair {
    let swap = precedes(b, a) == up;
    return QuadPair(pick(a, b, swap), pick(b, a, swap));
}

// Compare step on element bit 3 or 2: pairs of whole quads (q, q + 2) or (q, q + 1).
fn step_quads(a: Quad, b: Quad, first: u32, t: u32, lo: u32, log_k: u32, log_n: u32) -> QuadPair {
    return exchange(a, b, ascending(t, vec4<u32>(first) + vec4<u32>(0u, 1u, 2u, 3u), lo, log_k, log_n));
}

// Compare step on element bit 1 inside quads a (elements first..first+3) and b (next 4):
// pairs (0,2) (1,3) of each.
fn step_bit1(a: Quad, b: Quad, first: u32, t: u32, lo: u32, log_k: u32, log_n: u32) -> QuadPair {
    let x = Quad(vec4(a.cluster.xy, b.cluster.xy), vec4(a.key.xy, b.key.xy), vec4(a.local.xy, b.local.xy));
    let y = Quad(vec4(a.cluster.zw, b.cluster.zw), vec4(a.key.zw, b.key.zw), vec4(a.local.zw, b.local.zw));
    let r = exchange(x, y, ascending(t, vec4<u32>(first) + vec4<u32>(0u, 1u, 4u, 5u), lo, log_k, log_n));
    return QuadPair(
        Quad(vec4(r.first.cluster.xy, r.second.cluster.xy), vec4(r.first.key.xy, r.second.key.xy), vec4(r.first.local.xy, r.second.local.xy)),
        Quad(vec4(r.first.cluster.zw, r.second.cluster.zw), vec4(r.first.key.zw, r.second.key.zw), vec4(r.first.local.zw, r.second.local.zw)),
    );
}

// Compare step on element bit 0: pairs (0,1) (2,3) of quads a and b.
fn step_bit0(a: Quad, b: Quad, first: u32, t: u32, lo: u32, log_k: u32, log_n: u32) -> QuadPair {
    let x = Quad(vec4(a.cluster.xz, b.cluster.xz), vec4(a.key.xz, b.key.xz), vec4(a.local.xz, b.local.xz));
    let y = Quad(vec4(a.cluster.yw, b.cluster.yw), vec4(a.key.yw, b.key.yw), vec4(a.local.yw, b.local.yw));
    let r = exchange(x, y, ascending(t, vec4<u32>(first) + vec4<u32>(0u, 2u, 4u, 6u), lo, log_k, log_n));
    return QuadPair(
        Quad(
            vec4(r.first.cluster.x, r.second.cluster.x, r.first.cluster.y, r.second.cluster.y),
            vec4(r.first.key.x, r.second.key.x, r.first.key.y, r.second.key.y),
            vec4(r.first.local.x, r.second.local.x, r.first.local.y, r.second.local.y),
        ),
        Quad(
            vec4(r.first.cluster.z, r.second.cluster.z, r.first.cluster.w, r.second.cluster.w),
            vec4(r.first.key.z, r.second.key.z, r.first.key.w, r.second.key.w),
            vec4(r.first.local.z, r.second.local.z, r.first.local.w, r.second.local.w),
        ),
    );
}

// The register steps from element bit `top` (<= 3) down to 0, in the layout with window `lo`.
fn steps_registers(el: Elements, t: u32, top: u32, lo: u32, log_k: u32, log_n: u32) -> Elements {
    var e = el;
    if top >= 3u {
        let r02 = step_quads(e.q0, e.q2, 0u, t, lo, log_k, log_n);
        let r13 = step_quads(e.q1, e.q3, 4u, t, lo, log_k, log_n);
        e = Elements(r02.first, r13.first, r02.second, r13.second);
    }
    if top >= 2u {
        let r01 = step_quads(e.q0, e.q1, 0u, t, lo, log_k, log_n);
        let r23 = step_quads(e.q2, e.q3, 8u, t, lo, log_k, log_n);
        e = Elements(r01.first, r01.second, r23.first, r23.second);
    }
    if top >= 1u {
        let r01 = step_bit1(e.q0, e.q1, 0u, t, lo, log_k, log_n);
        let r23 = step_bit1(e.q2, e.q3, 8u, t, lo, log_k, log_n);
        e = Elements(r01.first, r01.second, r23.first, r23.second);
    }
    let r01 = step_bit0(e.q0, e.q1, 0u, t, lo, log_k, log_n);
    let r23 = step_bit0(e.q2, e.q3, 8u, t, lo, log_k, log_n);
    return Elements(r01.first, r01.second, r23.first, r23.second);
}

// Keeps, per element, this lane's or the partner lane's element (lanes differing in
// the shuffle mask), as the compare step on that slot bit asks; natural layout.
fn keep_lane(mine: Quad, mask: u32, lower: bool, first: u32, t: u32, log_k: u32, log_n: u32) -> Quad {
    let other = Quad(lane_exchange(mine.cluster, mask), lane_exchange(mine.key, mask), lane_exchange(mine.local, mask));
    let up = ascending(t, vec4<u32>(first) + vec4<u32>(0u, 1u, 2u, 3u), 0u, log_k, log_n);
    return pick(mine, other, precedes(other, mine) == (vec4<bool>(lower) == up));
}

// One compare step across subgroup lanes: slot bit ELEM_BITS + lane_bit, natural layout.
fn step_lanes(el: Elements, t: u32, lane_bit: u32, log_k: u32, log_n: u32) -> Elements {
    let mask = 1u << lane_bit;
    let lower = (t & mask) == 0u;
    return Elements(
        keep_lane(el.q0, mask, lower, 0u, t, log_k, log_n),
        keep_lane(el.q1, mask, lower, 4u, t, log_k, log_n),
        keep_lane(el.q2, mask, lower, 8u, t, log_k, log_n),
        keep_lane(el.q3, mask, lower, 12u, t, log_k, log_n),
    );
}

fn place(slot: u32, cluster: u32, key: u32, local: u32) {
    set_slot_cluster_key(slot, vec2<u32>(cluster, key));
    shared_local[slot] = local;
}

// Stores quad q (elements first..first+3) at its slots in layout `lo`.
fn store_quad(q: Quad, first: u32, t: u32, lo: u32) {
    let base = slot_of(t, 0u, lo);
    place(base | (first << lo), q.cluster.x, q.key.x, q.local.x);
    place(base | ((first + 1u) << lo), q.cluster.y, q.key.y, q.local.y);
    place(base | ((first + 2u) << lo), q.cluster.z, q.key.z, q.local.z);
    place(base | ((first + 3u) << lo), q.cluster.w, q.key.w, q.local.w);
}

fn store_registers(el: Elements, t: u32, lo: u32) {
    store_quad(el.q0, 0u, t, lo);
    store_quad(el.q1, 4u, t, lo);
    store_quad(el.q2, 8u, t, lo);
    store_quad(el.q3, 12u, t, lo);
}

// Quad of elements first..first+3 from their slots in layout `lo`.
fn load_quad(first: u32, t: u32, lo: u32) -> Quad {
    let slots = vec4<u32>(slot_of(t, 0u, lo)) | ((vec4<u32>(first) + vec4<u32>(0u, 1u, 2u, 3u)) << vec4<u32>(lo));
    let a = slot_cluster_key(slots.x);
    let b = slot_cluster_key(slots.y);
    let c = slot_cluster_key(slots.z);
    let d = slot_cluster_key(slots.w);
    return Quad(
        vec4<u32>(a.x, b.x, c.x, d.x),
        vec4<u32>(a.y, b.y, c.y, d.y),
        vec4<u32>(shared_local[slots.x], shared_local[slots.y], shared_local[slots.z], shared_local[slots.w]),
    );
}

fn load_registers(t: u32, lo: u32) -> Elements {
    return Elements(load_quad(0u, t, lo), load_quad(4u, t, lo), load_quad(8u, t, lo), load_quad(12u, t, lo));
}

// Moves the elements from layout `old_lo` to layout `new_lo` through workgroup memory.
fn relayout(el: Elements, t: u32, old_lo: u32, new_lo: u32) -> Elements {
    workgroupBarrier();
    store_registers(el, t, old_lo);
    workgroupBarrier();
    return load_registers(t, new_lo);
}

// The whole pass for one workgroup with the bitonic network; `lane_bits` = log2 of the
// subgroup size usable for shuffles (0: none). Must be called in uniform control flow.
fn run_block_histogram(t: u32, workgroup_id: vec3<u32>, lane_bits: u32) {
    let setup = setup_block_histogram(t, workgroup_id);
    // From the uniform itself, not `setup.log_n`: WGSL's uniformity analysis does not
    // follow a struct's fields, and `setup` holds per-invocation values, so a loop bound
    // read from it is not uniform to Tint, which then refuses the barriers below.
    let log_n = 2u * params.log2_block_size;
    var el = load_block_elements(setup);

    // Bitonic sort of every n-slot segment.
    var current_lo = 0u;
    for (var log_k = 1u; log_k <= log_n; log_k++) {
        var top = log_k - 1u;
        loop {
            if top < ELEM_BITS + lane_bits {
                if current_lo != 0u {
                    el = relayout(el, t, current_lo, 0u);
                    current_lo = 0u;
                }
                for (var s = top + 1u; s > ELEM_BITS; s--) {
                    el = step_lanes(el, t, s - 1u - ELEM_BITS, log_k, log_n);
                }
                el = steps_registers(el, t, min(top, ELEM_BITS - 1u), 0u, log_k, log_n);
                break;
            }
            let lo = top + 1u - ELEM_BITS;
            el = relayout(el, t, current_lo, lo);
            current_lo = lo;
            el = steps_registers(el, t, ELEM_BITS - 1u, lo, log_k, log_n);
            top -= ELEM_BITS;
        }
    }

    workgroupBarrier();
    store_registers(el, t, 0u);
    workgroupBarrier();
    finish_block_histogram(setup, el);
}
