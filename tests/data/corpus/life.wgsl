// One generation of a cellular automaton on a wrapping grid, with pipeline-overridable
// constants as public samples use them (written here): `tile` sets both dimensions of
// @workgroup_size, and `birth` / `survive_low` / `survive_high` enter expressions (the
// rule; defaults give Conway's B3/S23). 2-D dispatch of tile × tile invocations.
// Bindings: 0 uniform size (width, height), 1 cells_in (read, one u32 per cell: 0 or
// 1), 2 cells_out (read_write), 3 live_count (one atomic<u32>: live cells after the
// step, summed first in workgroup memory).

override tile: u32 = 8u;
override birth: u32 = 3u;
override survive_low: u32 = 2u;
override survive_high: u32 = 3u;

struct Size {
    width: u32,
    height: u32,
}

@group(0) @binding(0) var<uniform> size: Size;
@group(0) @binding(1) var<storage, read> cells_in: array<u32>;
@group(0) @binding(2) var<storage, read_write> cells_out: array<u32>;
@group(0) @binding(3) var<storage, read_write> live_count: atomic<u32>;

var<workgroup> tile_live: atomic<u32>;

fn cell(x: i32, y: i32) -> u32 {
    let w = i32(size.width);
    let h = i32(size.height);
    let wx = u32((x + w) % w);
    let wy = u32((y + h) % h);
    return cells_in[wy * size.width + wx];
}

@compute @workgroup_size(tile, tile)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    if local == 0u {
        atomicStore(&tile_live, 0u);
    }
    workgroupBarrier();
    let inside = gid.x < size.width && gid.y < size.height;
    if inside {
        let x = i32(gid.x);
        let y = i32(gid.y);
        var neighbours = 0u;
        for (var dy = -1; dy <= 1; dy++) {
            for (var dx = -1; dx <= 1; dx++) {
                if dx != 0 || dy != 0 {
                    neighbours += cell(x + dx, y + dy);
                }
            }
        }
        let alive = cell(x, y) == 1u;
        let next = select(u32(neighbours == birth), u32(neighbours >= survive_low && neighbours <= survive_high), alive);
        cells_out[gid.y * size.width + gid.x] = next;
        atomicAdd(&tile_live, next);
    }
    workgroupBarrier();
    if local == 0u {
        atomicAdd(&live_count, atomicLoad(&tile_live));
    }
}
