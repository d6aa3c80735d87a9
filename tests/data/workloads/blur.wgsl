// One pass of a separable Gaussian blur (radius 4, binomial weights 1 8 28 56 70 56 28
// 8 1 over 256, exact in f32) of a width x height f32 image, clamp-to-edge. The pass
// runs along rows (direction 0) or columns (direction 1): each 64-wide workgroup loads
// 64 + 2*4 samples of one row (or column), apron included, into workgroup memory,
// then each invocation sums weight[j] * tile[x + j] for j = 0..8 in that order.
// Dispatch: [ceil(along / 64), across, 1].
// Bindings: 0 uniform params (width, height, direction, unused), 1 src (read),
// 2 dst (read_write).

struct Params { width: u32, height: u32, direction: u32, unused: u32 }

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> src: array<f32>;
@group(0) @binding(2) var<storage, read_write> dst: array<f32>;

const RADIUS: i32 = 4;
const GROUP: u32 = 64u;

var<workgroup> tile: array<f32, 72>;

fn pixel(along: u32, across: u32) -> u32 {
    if params.direction == 0u {
        return across * params.width + along;
    }
    return along * params.width + across;
}

@compute @workgroup_size(64)
fn main(@builtin(local_invocation_index) li: u32, @builtin(workgroup_id) wg: vec3<u32>) {
    var length = params.width;
    if params.direction != 0u {
        length = params.height;
    }
    let across = wg.y;
    let start = i32(wg.x * GROUP) - RADIUS;
    for (var i = li; i < GROUP + 2u * u32(RADIUS); i += GROUP) {
        let a = clamp(start + i32(i), 0, i32(length) - 1);
        tile[i] = src[pixel(u32(a), across)];
    }
    workgroupBarrier();
    let along = wg.x * GROUP + li;
    if along < length {
        var weights = array<f32, 9>(
            0.00390625, 0.03125, 0.109375, 0.21875, 0.2734375, 0.21875, 0.109375, 0.03125, 0.00390625,
        );
        var sum = 0.0;
        for (var j = 0u; j < 9u; j++) {
            sum = sum + weights[j] * tile[li + j];
        }
        dst[pixel(along, across)] = sum;
    }
}
