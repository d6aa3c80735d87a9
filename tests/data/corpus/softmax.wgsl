// Row-wise softmax, the shape of the ML samples of public WebGPU collections (written
// here): one workgroup of 64 per row; the row maximum and the sum of exp(x - max) are
// reduced in workgroup memory by a tree, then each element is exp(x - max) / sum.
// Bindings: 0 uniform shape (rows, columns), 1 logits (read, rows × columns f32),
// 2 probabilities (read_write, same shape). Dispatch: (rows, 1, 1).

struct Shape {
    rows: u32,
    columns: u32,
}

@group(0) @binding(0) var<uniform> shape: Shape;
@group(0) @binding(1) var<storage, read> logits: array<f32>;
@group(0) @binding(2) var<storage, read_write> probabilities: array<f32>;

var<workgroup> partial: array<f32, 64>;

@compute @workgroup_size(64)
fn main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let row = group.x;
    let base = row * shape.columns;
    var largest = -3.0e38;
    for (var c = lane; c < shape.columns; c += 64u) {
        largest = max(largest, logits[base + c]);
    }
    partial[lane] = largest;
    workgroupBarrier();
    for (var stride = 32u; stride > 0u; stride >>= 1u) {
        if lane < stride {
            partial[lane] = max(partial[lane], partial[lane + stride]);
        }
        workgroupBarrier();
    }
    let row_max = partial[0];
    workgroupBarrier();
    var sum = 0.0;
    for (var c = lane; c < shape.columns; c += 64u) {
        sum += exp(logits[base + c] - row_max);
    }
    partial[lane] = sum;
    workgroupBarrier();
    for (var stride = 32u; stride > 0u; stride >>= 1u) {
        if lane < stride {
            partial[lane] += partial[lane + stride];
        }
        workgroupBarrier();
    }
    let total = partial[0];
    for (var c = lane; c < shape.columns; c += 64u) {
        probabilities[base + c] = exp(logits[base + c] - row_max) / total;
    }
}
