// Per-block histogram pass (paper §4.1 "histogram of candidates", §4.3 object masking).
//
// The image is cut into B x B blocks (B in {4, 8, 16, 32}; edge blocks are partial).
// Each block's candidates are ordered by (object id, canonical key, pixel index), so
// that every object's candidates form one contiguous run sorted by luminance: the
// histogram the stratified selection pass draws from. Invalid candidates (NaN, +-Inf,
// negative keys) sort last within their object's run, and pixels without a candidate
// (OBJECT_ID_NONE) form the block's last run; both are counted in BlockStats.
//
// Bindings (group 0):
//   0 uniform            HistogramParams   sizes of the dispatch
//   1 storage, read      array<Candidate>  one per pixel, row-major
//   2 storage, rw        array<u32>        sorted_pixels: per block, its pixel indices
//                                          in sorted order; block (bx, by) starts at
//                                          by*B*width + bx*B*bh (bh: the block's height)
//   3 storage, rw        array<ClusterSpan> per pixel: its own cluster's run
//   4 storage, rw        array<BlockStats> per block
//
// Dispatch: 64 invocations per workgroup sort SLOTS = 1024 slots, i.e. 1024 / (B*B) whole
// blocks; workgroups = ceil(blocks / (1024 / (B*B))) in rows of params.workgroups_x.
//
// Sorting: bitonic, ELEMS = 16 elements per invocation held in vector registers.
// Compare steps whose stride lies inside an invocation's elements run in registers;
// subgroup lanes (in the subgroup entry point) handle the next strides by shuffles;
// larger strides are brought into registers by re-reading the block from workgroup
// memory in a transposed order, ELEM_BITS = 4 steps per round trip. A 16 x 16 block takes
// 8 round trips (16 barriers) without subgroups and 2 with 8-wide subgroups, against 36
// barriers for the naive one-step-per-barrier network. Workgroup memory: 12.75 KiB.
//
// Invalid inputs: see canonical_key (common/candidate.wgsl). Every output element is
// written for every pixel; sentinel slots past a partial block's pixels write nothing.

const ELEMS: u32 = 16u;
const ELEM_BITS: u32 = 4u;
const SLOTS: u32 = 1024u;
const INVOCATIONS: u32 = 64u;
const MAX_SEGMENTS: u32 = 64u;

@group(0) @binding(0) var<uniform> params: HistogramParams;
@group(0) @binding(1) var<storage, read> candidates: array<Candidate>;
@group(0) @binding(2) var<storage, read_write> sorted_pixels: array<u32>;
@group(0) @binding(3) var<storage, read_write> spans: array<ClusterSpan>;
@group(0) @binding(4) var<storage, read_write> block_stats: array<BlockStats>;

// The block's elements between relayouts: (cluster, key) and local pixel index.
var<workgroup> shared_cluster_key: array<vec2<u32>, SLOTS>;
var<workgroup> shared_local: array<u32, SLOTS>;
// Per segment (block of this workgroup): clusters, invalid, empty.
var<workgroup> shared_stats: array<atomic<u32>, 192>;

// Four elements, one per vector lane.
struct Quad {
    cluster: vec4<u32>,
    key: vec4<u32>,
    local: vec4<u32>,
}

// An invocation's ELEMS = 16 elements: element 4q + i is lane i of quad q. Quads of
// vectors rather than arrays, so that every driver keeps them in registers (nothing is
// indexed dynamically) and every translation initialises them without array
// constructors (which glslang's HLSL front end rejects).
struct Elements {
    q0: Quad,
    q1: Quad,
    q2: Quad,
    q3: Quad,
}

// Strict total order on (cluster, key, local), lane by lane; locals are unique within a block.
fn precedes(a: Quad, b: Quad) -> vec4<bool> {
    return select(select(a.local < b.local, a.key < b.key, a.key != b.key), a.cluster < b.cluster, a.cluster != b.cluster);
}

fn pick(a: Quad, b: Quad, take_b: vec4<bool>) -> Quad {
    return Quad(select(a.cluster, b.cluster, take_b), select(a.key, b.key, take_b), select(a.local, b.local, take_b));
}

// Slot of element `e` of invocation `t` when the ELEM_BITS slot bits from `lo` up are
// the element index (lo = 0: the natural layout, slot = t * ELEMS + e).
fn slot_of(t: u32, e: u32, lo: u32) -> u32 {
    let low_mask = (1u << lo) - 1u;
    return ((t & ~low_mask) << ELEM_BITS) | (t & low_mask) | (e << lo);
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
    shared_cluster_key[slot] = vec2<u32>(cluster, key);
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
    let a = shared_cluster_key[slots.x];
    let b = shared_cluster_key[slots.y];
    let c = shared_cluster_key[slots.z];
    let d = shared_cluster_key[slots.w];
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

// First index in [begin, end) whose cluster is not below `cluster`
// (`inclusive`: not at or below it).
fn search_cluster(begin: u32, end: u32, cluster: u32, inclusive: bool) -> u32 {
    var lo = begin;
    var hi = end;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        let c = shared_cluster_key[mid].x;
        if c < cluster || (inclusive && c == cluster) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// First index in [begin, end) holding an invalid key (keys ascend within a run).
fn search_invalid(begin: u32, end: u32) -> u32 {
    var lo = begin;
    var hi = end;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        if shared_cluster_key[mid].y != INVALID_KEY {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// Geometry of one block of the image.
struct BlockRect {
    // Top-left pixel.
    x: u32,
    y: u32,
    width: u32,
    height: u32,
    // Index into sorted_pixels of the block's first entry.
    base: u32,
}

fn block_rect(block: u32) -> BlockRect {
    let b = params.block_size;
    let bx = block % params.blocks_x;
    let by = block / params.blocks_x;
    let x = bx * b;
    let y = by * b;
    let w = min(b, params.width - x);
    let h = min(b, params.height - y);
    return BlockRect(x, y, w, h, y * params.width + x * h);
}

fn pixel_of(rect: BlockRect, local: u32) -> u32 {
    return (rect.y + local / rect.width) * params.width + rect.x + local % rect.width;
}

// Dispatch-wide sizes derived from params, the same in every invocation.
struct Sizes {
    log_n: u32,
    n: u32,
    segments: u32,
    block_count: u32,
    first_block: u32,
}

// (cluster, canonical key, local) of the slot: the pixel's candidate, or a sentinel that
// sorts after every real element when the slot lies past its block's pixels.
fn load_element(slot: u32, sizes: Sizes) -> vec3<u32> {
    let block = sizes.first_block + (slot >> sizes.log_n);
    let local = slot & (sizes.n - 1u);
    if block < sizes.block_count {
        let rect = block_rect(block);
        if local < rect.width * rect.height {
            let candidate = candidates[pixel_of(rect, local)];
            return vec3<u32>(candidate.object_id, canonical_key(candidate), local);
        }
    }
    return vec3<u32>(OBJECT_ID_NONE, INVALID_KEY, local);
}

// Quad of the elements at slots first..first+3.
fn load_candidates(first: u32, sizes: Sizes) -> Quad {
    let a = load_element(first, sizes);
    let b = load_element(first + 1u, sizes);
    let c = load_element(first + 2u, sizes);
    let d = load_element(first + 3u, sizes);
    return Quad(vec4<u32>(a.x, b.x, c.x, d.x), vec4<u32>(a.y, b.y, c.y, d.y), vec4<u32>(a.z, b.z, c.z, d.z));
}

fn finish_quad(q: Quad, first: u32, sizes: Sizes) {
    finish_element(first, q.cluster.x, q.key.x, q.local.x, sizes);
    finish_element(first + 1u, q.cluster.y, q.key.y, q.local.y, sizes);
    finish_element(first + 2u, q.cluster.z, q.key.z, q.local.z, sizes);
    finish_element(first + 3u, q.cluster.w, q.key.w, q.local.w, sizes);
}

// Writes the outputs of the sorted element at `slot` (natural layout, after the sort,
// with the sorted block in workgroup memory).
fn finish_element(slot: u32, cluster: u32, key: u32, local: u32, sizes: Sizes) {
    let segment = slot >> sizes.log_n;
    let block = sizes.first_block + segment;
    let position = slot & (sizes.n - 1u);
    if block >= sizes.block_count {
        return;
    }
    let rect = block_rect(block);
    let count = rect.width * rect.height;
    if position >= count {
        return;
    }
    let begin = slot - position;
    let run_begin = search_cluster(begin, slot, cluster, false);
    let run_end = search_cluster(slot + 1u, begin + count, cluster, true);
    let valid_end = search_invalid(run_begin, run_end);
    let pixel = pixel_of(rect, local);
    sorted_pixels[rect.base + position] = pixel;
    spans[pixel] = ClusterSpan(rect.base + run_begin - begin, run_end - run_begin, valid_end - run_begin);
    if run_begin == slot {
        atomicAdd(&shared_stats[3u * segment], 1u);
    }
    if cluster == OBJECT_ID_NONE {
        atomicAdd(&shared_stats[3u * segment + 2u], 1u);
    } else if key == INVALID_KEY {
        atomicAdd(&shared_stats[3u * segment + 1u], 1u);
    }
}

// The whole pass for one workgroup; `lane_bits` = log2 of the subgroup size usable for
// shuffles (0: none). Must be called in uniform control flow.
fn run_block_histogram(t: u32, workgroup_id: vec3<u32>, lane_bits: u32) {
    let log_n = 2u * params.log2_block_size;
    let segments = SLOTS >> log_n;
    let sizes = Sizes(
        log_n,
        1u << log_n,
        segments,
        params.blocks_x * params.blocks_y,
        (workgroup_id.y * params.workgroups_x + workgroup_id.x) * segments,
    );

    for (var i = t; i < 3u * MAX_SEGMENTS; i += INVOCATIONS) {
        atomicStore(&shared_stats[i], 0u);
    }

    // Load in the natural layout.
    let base = slot_of(t, 0u, 0u);
    var el = Elements(load_candidates(base, sizes), load_candidates(base + 4u, sizes), load_candidates(base + 8u, sizes), load_candidates(base + 12u, sizes));

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

    // Runs, spans and counters.
    finish_quad(el.q0, base, sizes);
    finish_quad(el.q1, base + 4u, sizes);
    finish_quad(el.q2, base + 8u, sizes);
    finish_quad(el.q3, base + 12u, sizes);

    workgroupBarrier();
    for (var segment = t; segment < segments; segment += INVOCATIONS) {
        let block = sizes.first_block + segment;
        if block < sizes.block_count {
            block_stats[block] = BlockStats(
                atomicLoad(&shared_stats[3u * segment]),
                atomicLoad(&shared_stats[3u * segment + 1u]),
                atomicLoad(&shared_stats[3u * segment + 2u]),
            );
        }
    }
}
