// 256-bin histogram of u32 values plus max, min and (wrapping) sum. Each workgroup
// walks the input with a grid stride, counting bin (v >> 8) & 255 into workgroup
// atomics and folding max/min/sum into workgroup atomics; after a barrier it adds its
// counts to the global histogram and its max/min/sum to the global statistics with
// storage atomics.
// Bindings: 0 uniform params (count, unused x3), 1 values (read), 2 bins (read_write,
// 256 atomics, zeroed), 3 stats (read_write: max, min, sum, unused; min starts at
// 0xffffffff, the others at 0).

struct Params { count: u32, unused0: u32, unused1: u32, unused2: u32 }
struct Stats { max: atomic<u32>, min: atomic<u32>, sum: atomic<u32>, unused: u32 }

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> values: array<u32>;
@group(0) @binding(2) var<storage, read_write> bins: array<atomic<u32>, 256>;
@group(0) @binding(3) var<storage, read_write> stats: Stats;

var<workgroup> local_bins: array<atomic<u32>, 256>;
var<workgroup> local_max: atomic<u32>;
var<workgroup> local_min: atomic<u32>;
var<workgroup> local_sum: atomic<u32>;

@compute @workgroup_size(256)
fn main(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    atomicStore(&local_bins[li], 0u);
    if li == 0u {
        atomicStore(&local_max, 0u);
        atomicStore(&local_min, 0xffffffffu);
        atomicStore(&local_sum, 0u);
    }
    workgroupBarrier();
    let stride = groups.x * 256u;
    var hi = 0u;
    var lo = 0xffffffffu;
    var sum = 0u;
    for (var i = gid.x; i < params.count; i += stride) {
        let v = values[i];
        atomicAdd(&local_bins[(v >> 8u) & 255u], 1u);
        hi = max(hi, v);
        lo = min(lo, v);
        sum += v;
    }
    atomicMax(&local_max, hi);
    atomicMin(&local_min, lo);
    atomicAdd(&local_sum, sum);
    workgroupBarrier();
    let n = atomicLoad(&local_bins[li]);
    if n != 0u {
        atomicAdd(&bins[li], n);
    }
    if li == 0u {
        atomicMax(&stats.max, atomicLoad(&local_max));
        atomicMin(&stats.min, atomicLoad(&local_min));
        atomicAdd(&stats.sum, atomicLoad(&local_sum));
    }
}
