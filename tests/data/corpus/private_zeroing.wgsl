// Private and function-local memory as outside kernels use it, trusting WGSL's promise
// that a `var` without an initialiser starts zeroed: a private 1-D array, a private
// non-square array of arrays, a private array of structs, a private struct with an array
// member, and function-local arrays of arrays (non-square, of vectors) in the entry point
// and in a helper. Each invocation writes a few elements, then sums everything, so a
// path that skips the zeroing (or refuses naga's zeroing) shows. The glslang HLSL path
// once refused naga's `(uint[4])0` for every such array and Slang the non-square ones.
struct Cell {
    weight: f32,
    hits: array<u32, 3>,
}

struct Bag {
    count: u32,
    slots: array<vec2<u32>, 5>,
}

var<private> flat: array<u32, 8>;
var<private> grid: array<array<u32, 5>, 3>;
var<private> cells: array<Cell, 4>;
var<private> bag: Bag;

@group(0) @binding(0) var<storage, read_write> sums: array<u32>;
@group(0) @binding(1) var<storage, read_write> weights: array<f32>;

fn helper(seed: u32) -> u32 {
    var scratch: array<array<u32, 2>, 7>;
    scratch[seed % 7u][1] = seed;
    var total = 0u;
    for (var r = 0u; r < 7u; r++) {
        for (var c = 0u; c < 2u; c++) {
            total += scratch[r][c];
        }
    }
    return total;
}

@compute @workgroup_size(16)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    var local: array<array<vec3<u32>, 3>, 2>;
    var wide: array<array<array<f32, 2>, 3>, 4>;
    let i = id.x;
    flat[i % 8u] = i + 1u;
    grid[i % 3u][i % 5u] = 2u;
    cells[i % 4u].hits[1] = 3u;
    cells[i % 4u].weight = 0.5;
    bag.slots[i % 5u].y = 4u;
    local[1][2].z = 6u;
    wide[3][i % 3u][1] = 1.25;
    var total = 0u;
    for (var k = 0u; k < 8u; k++) {
        total += flat[k];
    }
    for (var r = 0u; r < 3u; r++) {
        for (var c = 0u; c < 5u; c++) {
            total += grid[r][c];
        }
    }
    var weight = 0.0;
    for (var k = 0u; k < 4u; k++) {
        total += cells[k].hits[0] + cells[k].hits[1] + cells[k].hits[2];
        weight += cells[k].weight;
    }
    total += bag.count;
    for (var k = 0u; k < 5u; k++) {
        total += bag.slots[k].x + bag.slots[k].y;
    }
    for (var r = 0u; r < 2u; r++) {
        for (var c = 0u; c < 3u; c++) {
            total += local[r][c].x + local[r][c].y + local[r][c].z;
        }
    }
    for (var a = 0u; a < 4u; a++) {
        for (var b = 0u; b < 3u; b++) {
            weight += wide[a][b][0] + wide[a][b][1];
        }
    }
    sums[i] = total + helper(i);
    weights[i] = weight;
}
