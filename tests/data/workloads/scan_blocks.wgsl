// Workgroup inclusive prefix sum (Hillis-Steele in workgroup memory), 256 elements per
// workgroup: out[i] = input[b*256] + ... + input[i] for i in block b (wrapping u32
// addition); elements past `count` read as 0 and are not written. The total of each
// block is written to block_sums[b].
// Bindings: 0 uniform params (count, unused x3), 1 input (read), 2 out (read_write),
// 3 block_sums (read_write).

struct Params { count: u32, unused0: u32, unused1: u32, unused2: u32 }

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> input: array<u32>;
@group(0) @binding(2) var<storage, read_write> out: array<u32>;
@group(0) @binding(3) var<storage, read_write> block_sums: array<u32>;

var<workgroup> tile: array<u32, 256>;

@compute @workgroup_size(256)
fn main(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
    @builtin(workgroup_id) wg: vec3<u32>,
) {
    let i = gid.x;
    var v = 0u;
    if i < params.count {
        v = input[i];
    }
    tile[li] = v;
    workgroupBarrier();
    for (var offset = 1u; offset < 256u; offset = offset * 2u) {
        var sum = tile[li];
        if li >= offset {
            sum = sum + tile[li - offset];
        }
        workgroupBarrier();
        tile[li] = sum;
        workgroupBarrier();
    }
    if i < params.count {
        out[i] = tile[li];
    }
    if li == 255u {
        block_sums[wg.x] = tile[255];
    }
}
