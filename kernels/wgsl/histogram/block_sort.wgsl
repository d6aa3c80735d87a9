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
// Dispatch: one workgroup sorts SLOTS = 1024 slots, i.e. 1024 / (B*B) whole blocks;
// workgroups = ceil(blocks / (1024 / (B*B))) laid out in rows of params.workgroups_x.
//
// Sorting: bitonic, ELEMS elements per invocation held in registers. Compare steps whose
// stride lies inside an invocation's elements run in registers; subgroup lanes (in the
// subgroup entry point) handle the next strides by shuffles; larger strides are
// brought into registers by re-reading the block from workgroup memory in a
// transposed order, ELEM_BITS steps per round trip. A 16 x 16 block takes 8 round
// trips without subgroups, 2 with 8-wide subgroups, against 36 barriers for the naive
// one-step-per-barrier network.

const ELEMS: u32 = 8u;
const ELEM_BITS: u32 = 3u;
const SLOTS: u32 = 1024u;
const INVOCATIONS: u32 = 128u;
const MAX_SEGMENTS: u32 = 64u;

@group(0) @binding(0) var<uniform> params: HistogramParams;
@group(0) @binding(1) var<storage, read> candidates: array<Candidate>;
@group(0) @binding(2) var<storage, read_write> sorted_pixels: array<u32>;
@group(0) @binding(3) var<storage, read_write> spans: array<ClusterSpan>;
@group(0) @binding(4) var<storage, read_write> block_stats: array<BlockStats>;

var<workgroup> shared_cluster: array<u32, SLOTS>;
var<workgroup> shared_key: array<u32, SLOTS>;
var<workgroup> shared_local: array<u32, SLOTS>;
// Per segment (block of this workgroup): clusters, invalid, empty.
var<workgroup> shared_stats: array<atomic<u32>, 192>;

// This invocation's elements: (cluster, key, local pixel index within its block).
var<private> reg_cluster: array<u32, ELEMS>;
var<private> reg_key: array<u32, ELEMS>;
var<private> reg_local: array<u32, ELEMS>;

// Strict total order on (cluster, key, local); locals are unique within a block.
fn precedes(c0: u32, k0: u32, l0: u32, c1: u32, k1: u32, l1: u32) -> bool {
    return select(select(l0 < l1, k0 < k1, k0 != k1), c0 < c1, c0 != c1);
}

// Slot of element `e` of invocation `t` when the ELEM_BITS slot bits from `lo` up are
// the element index (lo = 0: the natural layout, slot = t * ELEMS + e).
fn slot_of(t: u32, e: u32, lo: u32) -> u32 {
    let low_mask = (1u << lo) - 1u;
    return ((t & ~low_mask) << ELEM_BITS) | (t & low_mask) | (e << lo);
}

// Sort direction of the pair containing `slot` in merge stage 2^log_k. The last stage
// sorts every block ascending; earlier stages alternate to build bitonic sequences.
fn ascending(slot: u32, log_k: u32, log_n: u32) -> bool {
    return log_k == log_n || ((slot >> log_k) & 1u) == 0u;
}

// Compare-exchange of register elements a < b whose slots differ in one bit.
fn exchange_registers(a: u32, b: u32, up: bool) {
    let b_first = precedes(reg_cluster[b], reg_key[b], reg_local[b], reg_cluster[a], reg_key[a], reg_local[a]);
    if b_first == up {
        let c = reg_cluster[a];
        let k = reg_key[a];
        let l = reg_local[a];
        reg_cluster[a] = reg_cluster[b];
        reg_key[a] = reg_key[b];
        reg_local[a] = reg_local[b];
        reg_cluster[b] = c;
        reg_key[b] = k;
        reg_local[b] = l;
    }
}

// One compare step on register bit `bit` (0, 1 or 2) in the layout with window `lo`.
// Written out with constant indices so that drivers keep the elements in registers.
fn step_registers(t: u32, bit: u32, lo: u32, log_k: u32, log_n: u32) {
    if bit == 2u {
        exchange_registers(0u, 4u, ascending(slot_of(t, 0u, lo), log_k, log_n));
        exchange_registers(1u, 5u, ascending(slot_of(t, 1u, lo), log_k, log_n));
        exchange_registers(2u, 6u, ascending(slot_of(t, 2u, lo), log_k, log_n));
        exchange_registers(3u, 7u, ascending(slot_of(t, 3u, lo), log_k, log_n));
    } else if bit == 1u {
        exchange_registers(0u, 2u, ascending(slot_of(t, 0u, lo), log_k, log_n));
        exchange_registers(1u, 3u, ascending(slot_of(t, 1u, lo), log_k, log_n));
        exchange_registers(4u, 6u, ascending(slot_of(t, 4u, lo), log_k, log_n));
        exchange_registers(5u, 7u, ascending(slot_of(t, 5u, lo), log_k, log_n));
    } else {
        exchange_registers(0u, 1u, ascending(slot_of(t, 0u, lo), log_k, log_n));
        exchange_registers(2u, 3u, ascending(slot_of(t, 2u, lo), log_k, log_n));
        exchange_registers(4u, 5u, ascending(slot_of(t, 4u, lo), log_k, log_n));
        exchange_registers(6u, 7u, ascending(slot_of(t, 6u, lo), log_k, log_n));
    }
}

// One compare step across subgroup lanes: slot bit ELEM_BITS + lane_bit, natural layout.
fn step_lanes(t: u32, lane_bit: u32, log_k: u32, log_n: u32) {
    let mask = 1u << lane_bit;
    let lower = (t & mask) == 0u;
    for (var e = 0u; e < ELEMS; e++) {
        let c = lane_exchange(reg_cluster[e], mask);
        let k = lane_exchange(reg_key[e], mask);
        let l = lane_exchange(reg_local[e], mask);
        let up = ascending(slot_of(t, e, 0u), log_k, log_n);
        let other_first = precedes(c, k, l, reg_cluster[e], reg_key[e], reg_local[e]);
        if other_first == (lower == up) {
            reg_cluster[e] = c;
            reg_key[e] = k;
            reg_local[e] = l;
        }
    }
}

fn store_registers(t: u32, lo: u32) {
    for (var e = 0u; e < ELEMS; e++) {
        let slot = slot_of(t, e, lo);
        shared_cluster[slot] = reg_cluster[e];
        shared_key[slot] = reg_key[e];
        shared_local[slot] = reg_local[e];
    }
}

fn load_registers(t: u32, lo: u32) {
    for (var e = 0u; e < ELEMS; e++) {
        let slot = slot_of(t, e, lo);
        reg_cluster[e] = shared_cluster[slot];
        reg_key[e] = shared_key[slot];
        reg_local[e] = shared_local[slot];
    }
}

// Moves the elements from layout `old_lo` to layout `new_lo` through workgroup memory.
fn relayout(t: u32, old_lo: u32, new_lo: u32) {
    workgroupBarrier();
    store_registers(t, old_lo);
    workgroupBarrier();
    load_registers(t, new_lo);
}

// First index in [begin, end) whose cluster is not below `cluster`
// (`inclusive`: not at or below it).
fn search_cluster(begin: u32, end: u32, cluster: u32, inclusive: bool) -> u32 {
    var lo = begin;
    var hi = end;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        let c = shared_cluster[mid];
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
        if shared_key[mid] != INVALID_KEY {
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

// The whole pass for one workgroup; `lane_bits` = log2 of the subgroup size usable for
// shuffles (0: none). Must be called in uniform control flow.
fn run_block_histogram(t: u32, workgroup_id: vec3<u32>, lane_bits: u32) {
    let log_n = 2u * params.log2_block_size;
    let n = 1u << log_n;
    let segments = SLOTS >> log_n;
    let block_count = params.blocks_x * params.blocks_y;
    let first_block = (workgroup_id.y * params.workgroups_x + workgroup_id.x) * segments;

    for (var i = t; i < 3u * MAX_SEGMENTS; i += INVOCATIONS) {
        atomicStore(&shared_stats[i], 0u);
    }

    // Load: natural layout; slots past a block's pixels hold sentinels that sort last.
    for (var e = 0u; e < ELEMS; e++) {
        let slot = slot_of(t, e, 0u);
        let block = first_block + (slot >> log_n);
        let local = slot & (n - 1u);
        var cluster = OBJECT_ID_NONE;
        var key = INVALID_KEY;
        if block < block_count {
            let rect = block_rect(block);
            if local < rect.width * rect.height {
                let candidate = candidates[pixel_of(rect, local)];
                cluster = candidate.object_id;
                key = canonical_key(candidate);
            }
        }
        reg_cluster[e] = cluster;
        reg_key[e] = key;
        reg_local[e] = local;
    }

    // Bitonic sort of every n-slot segment.
    var current_lo = 0u;
    for (var log_k = 1u; log_k <= log_n; log_k++) {
        var top = log_k - 1u;
        loop {
            if top < ELEM_BITS + lane_bits {
                if current_lo != 0u {
                    relayout(t, current_lo, 0u);
                    current_lo = 0u;
                }
                for (var s = top + 1u; s > ELEM_BITS; s--) {
                    step_lanes(t, s - 1u - ELEM_BITS, log_k, log_n);
                }
                for (var s = min(top, ELEM_BITS - 1u) + 1u; s > 0u; s--) {
                    step_registers(t, s - 1u, 0u, log_k, log_n);
                }
                break;
            }
            let lo = top + 1u - ELEM_BITS;
            relayout(t, current_lo, lo);
            current_lo = lo;
            for (var s = ELEM_BITS; s > 0u; s--) {
                step_registers(t, s - 1u, lo, log_k, log_n);
            }
            top -= ELEM_BITS;
        }
    }

    workgroupBarrier();
    store_registers(t, 0u);
    workgroupBarrier();

    // Runs, spans and counters.
    for (var e = 0u; e < ELEMS; e++) {
        let slot = slot_of(t, e, 0u);
        let segment = slot >> log_n;
        let block = first_block + segment;
        let position = slot & (n - 1u);
        if block < block_count {
            let rect = block_rect(block);
            let count = rect.width * rect.height;
            if position < count {
                let begin = slot - position;
                let cluster = reg_cluster[e];
                let run_begin = search_cluster(begin, slot, cluster, false);
                let run_end = search_cluster(slot + 1u, begin + count, cluster, true);
                let valid_end = search_invalid(run_begin, run_end);
                let pixel = pixel_of(rect, reg_local[e]);
                sorted_pixels[rect.base + position] = pixel;
                spans[pixel] = ClusterSpan(rect.base + run_begin - begin, run_end - run_begin, valid_end - run_begin);
                if run_begin == slot {
                    atomicAdd(&shared_stats[3u * segment], 1u);
                }
                if cluster == OBJECT_ID_NONE {
                    atomicAdd(&shared_stats[3u * segment + 2u], 1u);
                } else if reg_key[e] == INVALID_KEY {
                    atomicAdd(&shared_stats[3u * segment + 1u], 1u);
                }
            }
        }
    }

    workgroupBarrier();
    for (var segment = t; segment < segments; segment += INVOCATIONS) {
        let block = first_block + segment;
        if block < block_count {
            block_stats[block] = BlockStats(
                atomicLoad(&shared_stats[3u * segment]),
                atomicLoad(&shared_stats[3u * segment + 1u]),
                atomicLoad(&shared_stats[3u * segment + 2u]),
            );
        }
    }
}
