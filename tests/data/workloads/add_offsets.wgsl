// Second pass of a two-level prefix sum: adds the inclusive scan of the block totals of
// all earlier blocks to every element of block b > 0 (out[i] += scanned_sums[b - 1]).
// Bindings: 0 uniform params (count, unused x3), 1 scanned_sums (read),
// 2 out (read_write).

struct Params { count: u32, unused0: u32, unused1: u32, unused2: u32 }

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> scanned_sums: array<u32>;
@group(0) @binding(2) var<storage, read_write> out: array<u32>;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(workgroup_id) wg: vec3<u32>) {
    let i = gid.x;
    if wg.x > 0u && i < params.count {
        out[i] = out[i] + scanned_sums[wg.x - 1u];
    }
}
