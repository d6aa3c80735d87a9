// The block histogram (paper §4.1, "histogram of candidates"): the stratification's
// ordering. What its three kernels share (bindings, dispatch, the element layout, loading
// the candidates and the finishing code once the blocks are sorted); the sorting itself is
// the bitonic network's (strata/histogram_network.wgsl: block_histogram,
// block_histogram_subgroup) or the ranking's (strata/histogram_rank.wgsl:
// block_histogram_rank). The renderer and the embeddable pass run the same entry points
// (strata/entry_histogram*.wgsl).
//
// The image is cut into B x B blocks (B in {4, 8, 16, 32}; edge blocks are partial),
// optionally shifted by (shift_x, shift_y) (§5.3 block shifting: the first row and
// column of blocks are then partial too). Each candidate joins a cluster of its block
// (strata/masking.wgsl, §4.3: its object id, or one cluster per block without masking).
// Each block's candidates are ordered by (cluster, canonical key, pixel index), so that
// every cluster's candidates form one contiguous run sorted by luminance: the histogram
// the stratified selection (strata/selection.wgsl, §4.2) draws from. Invalid candidates
// (NaN, +-Inf, negative keys) sort last within their cluster's run, and pixels without a
// candidate (OBJECT_ID_NONE) form the block's last run; both are counted in BlockStats.
//
// Bindings (group 0):
//   0 uniform            HistogramParams   sizes of the dispatch
//   1 storage, read      array<Candidate>  one per pixel, row-major
//   2 storage, rw        array<u32>        sorted_pixels: per block, its pixel indices
//                                          in sorted order; a block whose top-left pixel
//                                          is (x, y) starts at y*width + x*bh (bh: the
//                                          block's height)
//   3 storage, rw        array<ClusterSpan> per pixel: its own cluster's run
//   4 storage, rw        array<BlockStats> per block
//
// Dispatch: 64 invocations per workgroup sort HISTOGRAM_SLOTS_PER_WORKGROUP = 1024 slots, i.e. 1024 / (B*B) whole
// blocks; workgroups = ceil(blocks / (1024 / (B*B))) in rows of params.workgroups_x.
//
// Elements: ELEMS = 16 per invocation, held in vector registers (Elements), slots
// first..first+15 of one block. Workgroup memory: 12.75 KiB with the slots' storage.
//
// Invalid inputs: see canonical_key (strata/candidate.wgsl). Every output element is
// written for every pixel; sentinel slots past a partial block's pixels write nothing.
// Every buffer access is guarded by the buffer's bound length (arrayLength): a buffer
// too small for the image loses its entries past the end and nothing outside it is read
// or written (tests/tests/kernel_guards.rs), on GPUs without robustBufferAccess too.

// #import gpu/strata.wgsl
// #import strata/candidate.wgsl
// #import strata/masking.wgsl
// #requires fn slot_cluster_key(slot: u32) -> vec2<u32>

const ELEMS: u32 = 16u;
const ELEM_BITS: u32 = 4u;
const INVOCATIONS: u32 = 64u;
const MAX_SEGMENTS: u32 = 64u;
// Key of the padding slots past a partial block's pixels: after every real element.
const SENTINEL_KEY: u32 = 0xffffffffu;

@group(0) @binding(0) var<uniform> params: HistogramParams;
@group(0) @binding(1) var<storage, read> candidates: array<Candidate>;
@group(0) @binding(2) var<storage, read_write> sorted_pixels: array<u32>;
@group(0) @binding(3) var<storage, read_write> spans: array<ClusterSpan>;
@group(0) @binding(4) var<storage, read_write> block_stats: array<BlockStats>;

// The block's sorted elements: (cluster, key) through slot_cluster_key (the sorting's
// choice of storage: strata/histogram_slots.wgsl or strata/histogram_slot_pairs.wgsl),
// and here the local pixel index.
var<workgroup> shared_local: array<u32, HISTOGRAM_SLOTS_PER_WORKGROUP>;
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

// Slot of element `e` of invocation `t` when the ELEM_BITS slot bits from `lo` up are
// the element index (lo = 0: the natural layout, slot = t * ELEMS + e).
fn slot_of(t: u32, e: u32, lo: u32) -> u32 {
    let low_mask = (1u << lo) - 1u;
    return ((t & ~low_mask) << ELEM_BITS) | (t & low_mask) | (e << lo);
}

// First index in [begin, end) whose cluster is not below `cluster`
// (`inclusive`: not at or below it).
fn search_cluster(begin: u32, end: u32, cluster: u32, inclusive: bool) -> u32 {
    var lo = begin;
    var hi = end;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        let c = slot_cluster_key(mid).x;
        if c < cluster || (inclusive && c == cluster) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// First index in [begin, end) holding an invalid key (keys ascend within a run; invalid
// and sentinel keys are the two largest).
fn search_invalid(begin: u32, end: u32) -> u32 {
    var lo = begin;
    var hi = end;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        if slot_cluster_key(mid).y < INVALID_KEY {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// One block of the image. Elements carry their pixel's position in the full B x B block,
// local = row * B + column, so that finding a pixel needs shifts, not divisions; slots
// outside a partial block hold sentinels.
struct BlockRect {
    // Whether the block exists (the last workgroup may have spare segments).
    exists: bool,
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
    let exists = block < params.blocks_x * params.blocks_y;
    let bx = block % params.blocks_x;
    let by = block / params.blocks_x;
    // Virtual edges of the unshifted block, shifted and clipped to the image.
    let vx = bx * b;
    let vy = by * b;
    let x = max(vx, params.shift_x) - params.shift_x;
    let y = max(vy, params.shift_y) - params.shift_y;
    let w = select(0u, min(vx + b - params.shift_x, params.width) - x, exists);
    let h = select(0u, min(vy + b - params.shift_y, params.height) - y, exists);
    return BlockRect(exists, x, y, w, h, y * params.width + x * h);
}

fn column_of(local: u32) -> u32 {
    return local & (params.block_size - 1u);
}

fn row_of(local: u32) -> u32 {
    return local >> params.log2_block_size;
}

fn pixel_of(rect: BlockRect, local: u32) -> u32 {
    return (rect.y + row_of(local)) * params.width + rect.x + column_of(local);
}

// The candidate of `pixel`, or none past the end of the bound `candidates` (a buffer
// sized for a smaller image: the engine's mistake, which then reads as pixels without a
// candidate instead of whatever memory lies beyond; the C ABI's validation mode names it).
fn candidate_at(pixel: u32) -> Candidate {
    if pixel < arrayLength(&candidates) {
        return candidates[pixel];
    }
    return Candidate(0.0, OBJECT_ID_NONE);
}

// (cluster, canonical key, local) of a slot: the pixel's candidate, or a sentinel that
// sorts after every real element when the position lies outside the block.
fn load_element(rect: BlockRect, local: u32) -> vec3<u32> {
    if column_of(local) < rect.width && row_of(local) < rect.height {
        let candidate = candidate_at(pixel_of(rect, local));
        return vec3<u32>(cluster_of(candidate, params.masking != 0u), canonical_key(candidate), local);
    }
    return vec3<u32>(OBJECT_ID_NONE, SENTINEL_KEY, local);
}

// Quad of the elements at block positions first..first+3.
fn load_candidates(rect: BlockRect, first: u32) -> Quad {
    let a = load_element(rect, first);
    let b = load_element(rect, first + 1u);
    let c = load_element(rect, first + 2u);
    let d = load_element(rect, first + 3u);
    return Quad(vec4<u32>(a.x, b.x, c.x, d.x), vec4<u32>(a.y, b.y, c.y, d.y), vec4<u32>(a.z, b.z, c.z, d.z));
}

// Sixteen u32 values, element 4q + i in lane i of q<q>: one invocation's elements.
struct U16 {
    q0: vec4<u32>,
    q1: vec4<u32>,
    q2: vec4<u32>,
    q3: vec4<u32>,
}

// Element i takes element i - 1; element 0 takes `first`.
fn from_left(v: U16, first: u32) -> U16 {
    return U16(vec4(first, v.q0.xyz), vec4(v.q0.w, v.q1.xyz), vec4(v.q1.w, v.q2.xyz), vec4(v.q2.w, v.q3.xyz));
}

// Element i takes element i + 1; element 15 takes `last`.
fn from_right(v: U16, last: u32) -> U16 {
    return U16(vec4(v.q0.yzw, v.q1.x), vec4(v.q1.yzw, v.q2.x), vec4(v.q2.yzw, v.q3.x), vec4(v.q3.yzw, last));
}

fn prefix_max4(v: vec4<u32>, carry: u32) -> vec4<u32> {
    let a = max(v, vec4(0u, v.xyz));
    let b = max(a, vec4(0u, 0u, a.xy));
    return max(b, vec4(carry));
}

// Inclusive prefix maximum over the 16 elements.
fn prefix_max(v: U16) -> U16 {
    let q0 = prefix_max4(v.q0, 0u);
    let q1 = prefix_max4(v.q1, q0.w);
    let q2 = prefix_max4(v.q2, q1.w);
    return U16(q0, q1, q2, prefix_max4(v.q3, q2.w));
}

fn suffix_min4(v: vec4<u32>, carry: u32) -> vec4<u32> {
    let a = min(v, vec4(v.yzw, 0xffffffffu));
    let b = min(a, vec4(a.zw, 0xffffffffu, 0xffffffffu));
    return min(b, vec4(carry));
}

// Inclusive suffix minimum over the 16 elements.
fn suffix_min(v: U16) -> U16 {
    let q3 = suffix_min4(v.q3, 0xffffffffu);
    let q2 = suffix_min4(v.q2, q3.x);
    let q1 = suffix_min4(v.q1, q2.x);
    return U16(suffix_min4(v.q0, q1.x), q1, q2, q3);
}

// select(f, t, c) element-wise.
fn pick16(f: U16, t: U16, c: U16) -> U16 {
    let z = vec4(0u);
    return U16(select(f.q0, t.q0, c.q0 != z), select(f.q1, t.q1, c.q1 != z), select(f.q2, t.q2, c.q2 != z), select(f.q3, t.q3, c.q3 != z));
}

fn splat16(x: u32) -> U16 {
    return U16(vec4(x), vec4(x), vec4(x), vec4(x));
}

fn flag4(c: vec4<bool>) -> vec4<u32> {
    return select(vec4(0u), vec4(1u), c);
}

fn count16(v: U16) -> u32 {
    let s = v.q0 + v.q1 + v.q2 + v.q3;
    return s.x + s.y + s.z + s.w;
}

fn write_element(rect: BlockRect, begin: u32, position: u32, local: u32, run_begin: u32, run_end: u32, valid_end: u32) {
    if position < rect.width * rect.height {
        let pixel = pixel_of(rect, local);
        // Guarded: buffers smaller than the image (an engine's mistake) lose the entries
        // past their end rather than overwrite what lies beyond them.
        let entry = rect.base + position;
        if entry < arrayLength(&sorted_pixels) {
            sorted_pixels[entry] = pixel;
        }
        if pixel < arrayLength(&spans) {
            spans[pixel] = ClusterSpan(rect.base + run_begin - begin, run_end - run_begin, valid_end - run_begin);
        }
    }
}

fn write_quad(rect: BlockRect, begin: u32, position: u32, local: vec4<u32>, run_begin: vec4<u32>, run_end: vec4<u32>, valid_end: vec4<u32>) {
    write_element(rect, begin, position, local.x, run_begin.x, run_end.x, valid_end.x);
    write_element(rect, begin, position + 1u, local.y, run_begin.y, run_end.y, valid_end.y);
    write_element(rect, begin, position + 2u, local.z, run_begin.z, run_end.z, valid_end.z);
    write_element(rect, begin, position + 3u, local.w, run_begin.w, run_end.w, valid_end.w);
}

// Writes the outputs of this invocation's 16 sorted elements: sorted positions
// first..first+15 of the block whose first slot is `begin`, with the sorted block in
// workgroup memory. Runs are found from the neighbours in registers; only a run that
// crosses the invocation's edge costs a binary search (at most four per invocation).
fn finish_elements(rect: BlockRect, begin: u32, segment: u32, first: u32, el: Elements) {
    let count = rect.width * rect.height;
    if first >= count {
        return;
    }
    let base = begin + first;
    let i4 = vec4(0u, 1u, 2u, 3u);
    let slots = U16(vec4(base) + i4, vec4(base + 4u) + i4, vec4(base + 8u) + i4, vec4(base + 12u) + i4);
    let cluster = U16(el.q0.cluster, el.q1.cluster, el.q2.cluster, el.q3.cluster);
    let key = U16(el.q0.key, el.q1.key, el.q2.key, el.q3.key);
    let z = vec4(0u);
    let invalid = U16(flag4(key.q0 >= vec4(INVALID_KEY)), flag4(key.q1 >= vec4(INVALID_KEY)), flag4(key.q2 >= vec4(INVALID_KEY)), flag4(key.q3 >= vec4(INVALID_KEY)));
    let real = U16(flag4(slots.q0 < vec4(begin + count)), flag4(slots.q1 < vec4(begin + count)), flag4(slots.q2 < vec4(begin + count)), flag4(slots.q3 < vec4(begin + count)));

    // Neighbours just outside: the previous and next sorted elements of the block.
    var previous = vec2(~cluster.q0.x, 0u);
    if first > 0u {
        previous = slot_cluster_key(base - 1u);
    }
    var next_cluster = ~cluster.q3.w;
    if first + 16u < count {
        next_cluster = slot_cluster_key(base + 16u).x;
    }

    // Run starts and ends.
    let left = from_left(cluster, previous.x);
    let starts = U16(flag4(cluster.q0 != left.q0), flag4(cluster.q1 != left.q1), flag4(cluster.q2 != left.q2), flag4(cluster.q3 != left.q3));
    let right = from_right(cluster, next_cluster);
    let ends = U16(flag4(cluster.q0 != right.q0), flag4(cluster.q1 != right.q1), flag4(cluster.q2 != right.q2), flag4(cluster.q3 != right.q3));
    var begin_seed = base;
    if starts.q0.x == 0u {
        begin_seed = search_cluster(begin, base, cluster.q0.x, false);
    }
    var end_seed = base + 16u;
    if ends.q3.w == 0u {
        end_seed = search_cluster(base + 16u, begin + count, cluster.q3.w, true);
    }
    var begin_marks = pick16(splat16(0u), slots, starts);
    begin_marks.q0.x = begin_seed;
    let run_begin = prefix_max(begin_marks);
    let plus_one = U16(slots.q0 + 1u, slots.q1 + 1u, slots.q2 + 1u, slots.q3 + 1u);
    var end_marks = pick16(splat16(0xffffffffu), plus_one, ends);
    end_marks.q3.w = end_seed;
    let unclamped_end = suffix_min(end_marks);
    let limit = vec4(begin + count);
    let run_end = U16(min(unclamped_end.q0, limit), min(unclamped_end.q1, limit), min(unclamped_end.q2, limit), min(unclamped_end.q3, limit));

    // Valid/invalid boundaries: the first invalid element of each run. (WGSL's grammar
    // takes no comparison beside `&` or `|` without parentheses: naga did, Tint does not.)
    let invalid_left = from_left(invalid, select(0u, 1u, previous.y >= INVALID_KEY));
    let first_invalid = U16(
        flag4((invalid.q0 != z) & ((starts.q0 != z) | (invalid_left.q0 == z))),
        flag4((invalid.q1 != z) & ((starts.q1 != z) | (invalid_left.q1 == z))),
        flag4((invalid.q2 != z) & ((starts.q2 != z) | (invalid_left.q2 == z))),
        flag4((invalid.q3 != z) & ((starts.q3 != z) | (invalid_left.q3 == z))),
    );
    // Invalid elements: their run's boundary is the last one at or before them.
    var boundary_before = pick16(splat16(0u), slots, first_invalid);
    if invalid.q0.x != 0u && first_invalid.q0.x == 0u {
        boundary_before.q0.x = search_invalid(run_begin.q0.x, base);
    }
    let valid_end_invalid = prefix_max(boundary_before);
    // Valid elements: the first boundary after them, or their run's end.
    var boundary_after = pick16(splat16(0xffffffffu), slots, first_invalid);
    if invalid.q3.w == 0u && run_end.q3.w > base + 16u {
        boundary_after.q3.w = search_invalid(base + 16u, run_end.q3.w);
    }
    let after = suffix_min(boundary_after);
    let valid_end_valid = U16(min(after.q0, run_end.q0), min(after.q1, run_end.q1), min(after.q2, run_end.q2), min(after.q3, run_end.q3));
    let valid_end = pick16(valid_end_valid, valid_end_invalid, invalid);

    write_quad(rect, begin, first, el.q0.local, run_begin.q0, run_end.q0, valid_end.q0);
    write_quad(rect, begin, first + 4u, el.q1.local, run_begin.q1, run_end.q1, valid_end.q1);
    write_quad(rect, begin, first + 8u, el.q2.local, run_begin.q2, run_end.q2, valid_end.q2);
    write_quad(rect, begin, first + 12u, el.q3.local, run_begin.q3, run_end.q3, valid_end.q3);

    // Counters: one atomic each per invocation.
    let none = vec4(OBJECT_ID_NONE);
    let clusters = count16(U16(starts.q0 & real.q0, starts.q1 & real.q1, starts.q2 & real.q2, starts.q3 & real.q3));
    let empty = count16(U16(
        flag4(cluster.q0 == none) & real.q0,
        flag4(cluster.q1 == none) & real.q1,
        flag4(cluster.q2 == none) & real.q2,
        flag4(cluster.q3 == none) & real.q3,
    ));
    let invalid_keys = count16(U16(
        flag4((cluster.q0 != none) & (key.q0 == vec4(INVALID_KEY))) & real.q0,
        flag4((cluster.q1 != none) & (key.q1 == vec4(INVALID_KEY))) & real.q1,
        flag4((cluster.q2 != none) & (key.q2 == vec4(INVALID_KEY))) & real.q2,
        flag4((cluster.q3 != none) & (key.q3 == vec4(INVALID_KEY))) & real.q3,
    ));
    if clusters != 0u {
        atomicAdd(&shared_stats[3u * segment], clusters);
    }
    if invalid_keys != 0u {
        atomicAdd(&shared_stats[3u * segment + 1u], invalid_keys);
    }
    if empty != 0u {
        atomicAdd(&shared_stats[3u * segment + 2u], empty);
    }
}

// A workgroup's blocks and this invocation's place among them.
struct BlockSetup {
    // The workgroup's first block and its number of blocks (segments).
    first_block: u32,
    segments: u32,
    // log2 of the slots per block.
    log_n: u32,
    // This invocation's first slot, its block (segment) and that slot's position in the
    // block. An invocation's ELEMS consecutive slots lie in one block (blocks have at
    // least 16 slots), so the block geometry is computed once.
    base: u32,
    segment: u32,
    first: u32,
    rect: BlockRect,
}

// Clears the workgroup's counters and places this invocation.
fn setup_block_histogram(t: u32, workgroup_id: vec3<u32>) -> BlockSetup {
    let log_n = 2u * params.log2_block_size;
    let segments = HISTOGRAM_SLOTS_PER_WORKGROUP >> log_n;
    let first_block = (workgroup_id.y * params.workgroups_x + workgroup_id.x) * segments;
    for (var i = t; i < 3u * MAX_SEGMENTS; i += INVOCATIONS) {
        atomicStore(&shared_stats[i], 0u);
    }
    let base = slot_of(t, 0u, 0u);
    let segment = base >> log_n;
    let first = base & ((1u << log_n) - 1u);
    return BlockSetup(first_block, segments, log_n, base, segment, first, block_rect(first_block + segment));
}

// This invocation's elements in the natural layout (unsorted).
fn load_block_elements(setup: BlockSetup) -> Elements {
    return Elements(
        load_candidates(setup.rect, setup.first),
        load_candidates(setup.rect, setup.first + 4u),
        load_candidates(setup.rect, setup.first + 8u),
        load_candidates(setup.rect, setup.first + 12u),
    );
}

// Runs, spans and counters once the blocks are sorted: `el` holds this invocation's
// sorted positions first..first+15, and workgroup memory every sorted block in the
// natural layout. Must be called in uniform control flow.
fn finish_block_histogram(setup: BlockSetup, el: Elements) {
    if setup.rect.exists {
        finish_elements(setup.rect, setup.base - setup.first, setup.segment, setup.first, el);
    }
    workgroupBarrier();
    // Invocation t writes the counters of segments t, t + INVOCATIONS, ...
    let t = setup.base >> ELEM_BITS;
    for (var segment = t; segment < setup.segments; segment += INVOCATIONS) {
        let block = setup.first_block + segment;
        if block < params.blocks_x * params.blocks_y && block < arrayLength(&block_stats) {
            block_stats[block] = BlockStats(
                atomicLoad(&shared_stats[3u * segment]),
                atomicLoad(&shared_stats[3u * segment + 1u]),
                atomicLoad(&shared_stats[3u * segment + 2u]),
            );
        }
    }
}
