// Atomics on storage and workgroup memory (written here): a 64-bin histogram of the
// inputs' high bits counted first per workgroup (workgroup atomicAdd), then added to
// the global bins (storage atomicAdd); the global min, max, OR and XOR of all inputs;
// and, per workgroup, a slot claimed by atomicAdd on a counter and filled with the
// workgroup's local count of odd values (the order of claims differs between
// backends, the multiset of values must not: the test sorts them).
// Bindings: 0 values (read, u32), 1 bins (read_write, 64 atomic<u32>), 2 summary
// (read_write: min, max, or, xor, claimed slots), 3 slots (read_write, one u32 per
// workgroup).

struct Summary {
    lowest: atomic<u32>,
    highest: atomic<u32>,
    any_bits: atomic<u32>,
    parity: atomic<u32>,
    claimed: atomic<u32>,
}

@group(0) @binding(0) var<storage, read> values: array<u32>;
@group(0) @binding(1) var<storage, read_write> bins: array<atomic<u32>, 64>;
@group(0) @binding(2) var<storage, read_write> summary: Summary;
@group(0) @binding(3) var<storage, read_write> slots: array<u32>;

var<workgroup> local_bins: array<atomic<u32>, 64>;
var<workgroup> local_odd: atomic<u32>;

@compute @workgroup_size(128)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    if lane < 64u {
        atomicStore(&local_bins[lane], 0u);
    }
    if lane == 0u {
        atomicStore(&local_odd, 0u);
    }
    workgroupBarrier();
    if gid.x < arrayLength(&values) {
        let v = values[gid.x];
        atomicAdd(&local_bins[v >> 26u], 1u);
        atomicAdd(&local_odd, v & 1u);
        atomicMin(&summary.lowest, v);
        atomicMax(&summary.highest, v);
        atomicOr(&summary.any_bits, v & 0x0f0f0f0fu);
        atomicXor(&summary.parity, v);
    }
    workgroupBarrier();
    if lane < 64u {
        let here = atomicLoad(&local_bins[lane]);
        if here > 0u {
            atomicAdd(&bins[lane], here);
        }
    }
    if lane == 0u {
        let slot = atomicAdd(&summary.claimed, 1u);
        slots[slot] = atomicLoad(&local_odd);
    }
}
