// Collatz step counts: out[i] = number of steps n -> n/2 (even) or 3n+1 (odd, wrapping
// u32) taking input[i] to 1, stopping at 256 steps (0 and 1 take 0 steps).
// Bindings: 0 input (read), 1 out (read_write).

@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> out: array<u32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if i >= arrayLength(&input) {
        return;
    }
    var n = input[i];
    var steps = 0u;
    while n > 1u && steps < 256u {
        if (n & 1u) == 0u {
            n = n >> 1u;
        } else {
            n = 3u * n + 1u;
        }
        steps += 1u;
    }
    out[i] = steps;
}
