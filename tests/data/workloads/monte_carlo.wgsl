// Integer Monte Carlo estimate of pi with a hash-based generator, plus signed integer
// arithmetic on the generated words. Invocation g starts from h = hash(g ^ seed) and
// draws `samples` points: x = hash(h) >> 20 and y = hash(hash(h)) >> 20 (12 bits each),
// inside the quarter circle when x*x + y*y < 4096*4096. Inside counts are summed in a
// workgroup atomic, then into total[0] with a storage atomic. Along the way it folds
// v = bitcast<i32>(h) into acc = acc + v / 7 - v % 13 + (v >> 3) (wrapping, truncating
// division, arithmetic shift) and tracks min/max/abs of v.
// hash(s): t = s * 747796405 + 2891336453; w = ((t >> ((t >> 28) + 4)) ^ t) * 277803737;
// return (w >> 22) ^ w (all u32, wrapping).
// Bindings: 0 uniform params (samples, seed, unused x2), 1 total (read_write, atomic),
// 2 signed (read_write, 4 x i32 per invocation: acc, min, max, sum of abs).

struct Params { samples: u32, seed: u32, unused0: u32, unused1: u32 }

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read_write> total: array<atomic<u32>, 1>;
@group(0) @binding(2) var<storage, read_write> signed: array<i32>;

var<workgroup> inside_here: atomic<u32>;

fn hash(s: u32) -> u32 {
    let t = s * 747796405u + 2891336453u;
    let w = ((t >> ((t >> 28u) + 4u)) ^ t) * 277803737u;
    return (w >> 22u) ^ w;
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    if li == 0u {
        atomicStore(&inside_here, 0u);
    }
    workgroupBarrier();
    var h = hash(gid.x ^ params.seed);
    var inside = 0u;
    var acc = 0i;
    var lo = 2147483647i;
    var hi = -2147483647i - 1i;
    var magnitude = 0i;
    for (var s = 0u; s < params.samples; s++) {
        h = hash(h);
        let x = h >> 20u;
        h = hash(h);
        let y = h >> 20u;
        if x * x + y * y < 4096u * 4096u {
            inside += 1u;
        }
        let v = bitcast<i32>(h);
        acc = acc + v / 7i - v % 13i + (v >> 3u);
        lo = min(lo, v);
        hi = max(hi, v);
        magnitude = magnitude + abs(v);
    }
    atomicAdd(&inside_here, inside);
    let base = gid.x * 4u;
    signed[base] = acc;
    signed[base + 1u] = lo;
    signed[base + 2u] = hi;
    signed[base + 3u] = magnitude;
    workgroupBarrier();
    if li == 0u {
        atomicAdd(&total[0], atomicLoad(&inside_here));
    }
}
