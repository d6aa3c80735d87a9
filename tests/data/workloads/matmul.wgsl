// Tiled f32 matrix multiply C = A * B (A: M x K, B: K x N, all row-major).
// Each 16x16 workgroup computes a 16x16 block of C, staging 16x16 tiles of A and B in
// workgroup memory between workgroupBarrier()s. Sizes need not be multiples of 16:
// out-of-range tile elements are loaded as 0 and out-of-range outputs are not written.
// Each output is the sum over k = 0, 1, ..., K-1 (padded with zeros to a multiple of
// 16) of A[row][k] * B[k][col], accumulated in that order.
// Bindings: 0 uniform dims (m, k, n, unused), 1 A (read), 2 B (read), 3 C (read_write).

struct Dims { m: u32, k: u32, n: u32, unused: u32 }

@group(0) @binding(0) var<uniform> dims: Dims;
@group(0) @binding(1) var<storage, read> a: array<f32>;
@group(0) @binding(2) var<storage, read> b: array<f32>;
@group(0) @binding(3) var<storage, read_write> c: array<f32>;

const TILE: u32 = 16u;
var<workgroup> tile_a: array<array<f32, 16>, 16>;
var<workgroup> tile_b: array<array<f32, 16>, 16>;

@compute @workgroup_size(16, 16)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>) {
    let row = gid.y;
    let col = gid.x;
    var acc = 0.0;
    let tiles = (dims.k + TILE - 1u) / TILE;
    for (var t = 0u; t < tiles; t++) {
        let ka = t * TILE + lid.x;
        let kb = t * TILE + lid.y;
        var va = 0.0;
        if row < dims.m && ka < dims.k {
            va = a[row * dims.k + ka];
        }
        var vb = 0.0;
        if kb < dims.k && col < dims.n {
            vb = b[kb * dims.n + col];
        }
        tile_a[lid.y][lid.x] = va;
        tile_b[lid.y][lid.x] = vb;
        workgroupBarrier();
        for (var i = 0u; i < TILE; i++) {
            acc = acc + tile_a[lid.y][i] * tile_b[i][lid.x];
        }
        workgroupBarrier();
    }
    if row < dims.m && col < dims.n {
        c[row * dims.n + col] = acc;
    }
}
